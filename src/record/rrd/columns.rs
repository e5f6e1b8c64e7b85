//! Data buffered as columns and sent with `send_columns` in batches: per merge, the scalar
//! series (always; the rows [`Envelope`] keeps) and the merged pair's and new body's boxes (with per-merge geometry); per
//! round start, doubling and finish, the text log lines and the active bodies' boxes.
//!
//! Every `send_columns` call becomes one chunk, and the SDK has a fixed cost per chunk whatever
//! its size, so rows are sent together, one chunk per entity per batch.

use std::fmt::Write as _;
use std::sync::Arc;

use rerun::external::arrow::array::StringBuilder;
use rerun::{RecordingStream, SerializedComponentBatch, TimeColumn};

use super::BoxF32;
use super::envelope::Envelope;
use crate::grouping::Merge;

/// Merges buffered before their columns are sent.
pub(super) const BATCH: usize = 4096;

/// The per-merge series, one entity per plot of the blueprint: its path and the legend name of
/// each scalar in its rows, in [`Columns::push`] order. (One entity per plot rather than
/// per series: every entity costs the SDK two chunks, a row-id column and a time column.)
pub(super) const SERIES: [(&str, &[&str]); 4] = [
    ("series/cost", &["Cost"]),
    ("series/limits", &["diameter", "DLimit", "GLimit"]),
    ("series/fill_balance", &["Fill", "Balance"]),
    ("series/queue_len", &["MPairs length"]),
];

/// Line colours of [`SERIES`], one per name (scalars of one entity would otherwise share a
/// hue).
pub(super) const SERIES_COLORS: [&[u32]; 4] = [
    &[0x2EB82EFF],
    &[0xE6A700FF, 0xD62728FF, 0x1F77B4FF],
    &[0x9467BDFF, 0x17BECFFF],
    &[0xE377C2FF],
];

/// Orange of the merged pair's boxes.
const PAIR_ORANGE: u32 = 0xFF8C00FF;
/// Green of the new body's box.
const NEW_GREEN: u32 = 0x2EB82EFF;

/// Logs at `path` the static colours and line widths of the per-merge boxes: the pair's two,
/// then the new body's (Rerun pairs the i-th colour and radius with the i-th box of each row).
pub(super) fn log_styles(rec: &RecordingStream, path: &str) -> anyhow::Result<()> {
    use rerun::components::{FillMode, Radius};
    let (pair, new) = (Radius::new_ui_points(2.0), Radius::new_ui_points(2.5));
    super::send_static(
        rec,
        path,
        &rerun::Boxes3D::update_fields()
            .with_colors([PAIR_ORANGE, PAIR_ORANGE, NEW_GREEN])
            .with_radii([pair, pair, new])
            .with_fill_mode(FillMode::MajorWireframe),
    )
}

/// Column buffers of the rows not sent yet: merges, text lines and active sets.
#[derive(Default)]
pub(super) struct Columns {
    /// Merges buffered since the last flush.
    merges: usize,
    /// Per [`SERIES`] entity, the rows kept.
    series: [Envelope; 4],
    /// (merge, round) ticks of the merges drawn as boxes (`record::BODIES_CAP`).
    box_ticks: Vec<(i64, i64)>,
    /// Per merge drawn, the pair's two boxes then the new body's.
    box_centers: Vec<[f32; 3]>,
    box_halves: Vec<[f32; 3]>,
    /// `log/doublings` rows: (merge, round) ticks, then lines and levels written straight into
    /// the Arrow string columns sent (no `String` per line: a partitioned run logs one line per
    /// part, hundreds of thousands at 10^6 primitives).
    text_ticks: Vec<(i64, i64)>,
    text: StringBuilder,
    text_levels: StringBuilder,
    /// `grouping/active` rows: (merge, round) ticks and box count, then every row's boxes.
    active_rows: Vec<(i64, i64, usize)>,
    active_centers: Vec<[f32; 3]>,
    active_halves: Vec<[f32; 3]>,
}

impl Columns {
    /// Empty buffers for a run of at most `merges` merges.
    pub(super) fn new(merges: usize) -> Columns {
        Columns {
            series: SERIES.map(|(_, names)| Envelope::new(names.len(), merges)),
            ..Columns::default()
        }
    }

    /// Buffers one merge; `boxes` are the pair's and the new body's boxes when this merge is
    /// drawn.
    pub(super) fn push(
        &mut self,
        m: &Merge,
        dlimit: f64,
        glimit: f64,
        boxes: Option<([BoxF32; 2], BoxF32)>,
    ) {
        self.merges += 1;
        let values: [&[f64]; 4] = [
            &[m.cost],
            &[m.diameter, dlimit, glimit],
            &[m.fill, m.balance],
            &[m.queue_len as f64],
        ];
        for (rows, v) in self.series.iter_mut().zip(values) {
            rows.push(m.step as i64, v);
        }
        if let Some(([a, b], new)) = boxes {
            self.box_ticks.push((m.step as i64, m.round as i64));
            self.box_centers.extend([a.center, b.center, new.center]);
            self.box_halves.extend([a.half, b.half, new.half]);
        }
    }

    /// Buffers one `log/doublings` line at the given `merge` and `round` ticks.
    pub(super) fn push_text(
        &mut self,
        merge: u32,
        round: u32,
        line: std::fmt::Arguments<'_>,
        level: &str,
    ) {
        self.text_ticks.push((i64::from(merge), i64::from(round)));
        // Writing to a `StringBuilder` only appends bytes and cannot fail; `append_value` then
        // ends the row.
        let _ = self.text.write_fmt(line);
        self.text.append_value("");
        self.text_levels.append_value(level);
    }

    /// Buffers one `grouping/active` row: the boxes of the bodies active at a round start.
    pub(super) fn push_active(&mut self, merge: u32, round: u32, boxes: &[BoxF32]) {
        self.active_rows
            .push((i64::from(merge), i64::from(round), boxes.len()));
        self.active_centers.extend(boxes.iter().map(|b| b.center));
        self.active_halves.extend(boxes.iter().map(|b| b.half));
    }

    /// Number of buffered merges.
    pub(super) fn len(&self) -> usize {
        self.merges
    }

    /// Ends the series' open buckets: the run has no more merges.
    pub(super) fn close_series(&mut self) {
        self.series.iter_mut().for_each(Envelope::close);
    }

    /// Sends every buffered merge and empties the buffers.
    pub(super) fn flush(&mut self, rec: &RecordingStream) -> anyhow::Result<()> {
        let result = self.send(rec);
        self.clear();
        result
    }

    /// Empties every buffer.
    fn clear(&mut self) {
        self.merges = 0;
        self.box_ticks.clear();
        self.box_centers.clear();
        self.box_halves.clear();
        self.text_ticks.clear();
        self.text = StringBuilder::new();
        self.text_levels = StringBuilder::new();
        self.active_rows.clear();
        self.active_centers.clear();
        self.active_halves.clear();
    }

    fn send(&mut self, rec: &RecordingStream) -> anyhow::Result<()> {
        self.send_rounds(rec)?;
        self.send_merges(rec)
    }

    /// Sends the buffered text lines and active sets now, and returns the buffered merges' rows
    /// as a batch to send later with [`Columns::send_held`]; empties the buffers.
    pub(super) fn flush_rounds(&mut self, rec: &RecordingStream) -> anyhow::Result<Columns> {
        let sent = self.send_rounds(rec);
        let held = Columns {
            merges: self.merges,
            series: self.series.each_mut().map(Envelope::split_off),
            box_ticks: std::mem::take(&mut self.box_ticks),
            box_centers: std::mem::take(&mut self.box_centers),
            box_halves: std::mem::take(&mut self.box_halves),
            ..Columns::default()
        };
        self.clear();
        sent.map(|()| held)
    }

    /// Sends a batch of merges held back by [`Columns::flush_rounds`].
    pub(super) fn send_held(mut self, rec: &RecordingStream) -> anyhow::Result<()> {
        self.send_merges(rec)
    }

    /// Sends the buffered text lines and active sets, one chunk each.
    fn send_rounds(&mut self, rec: &RecordingStream) -> anyhow::Result<()> {
        let ticks = |rows: &mut dyn Iterator<Item = (i64, i64)>| {
            let (merge, round): (Vec<i64>, Vec<i64>) = rows.unzip();
            [
                TimeColumn::new_sequence("merge", merge),
                TimeColumn::new_sequence("round", round),
            ]
        };
        if !self.text_ticks.is_empty() {
            // The same columns as `TextLog::update_fields().with_many_text(..)
            // .with_many_level(..).columns_of_unit_batches()`, built without a `Text` per line.
            let rows = self.text_ticks.len();
            let column = |builder: &mut StringBuilder, descriptor| {
                SerializedComponentBatch::new(Arc::new(builder.finish()), descriptor)
                    .partitioned(std::iter::repeat_n(1, rows))
            };
            let log = [
                column(&mut self.text, rerun::TextLog::descriptor_text())?,
                column(&mut self.text_levels, rerun::TextLog::descriptor_level())?,
            ];
            rec.send_columns(
                "log/doublings",
                ticks(&mut self.text_ticks.iter().copied()),
                log,
            )?;
        }
        if !self.active_rows.is_empty() {
            let boxes = rerun::Boxes3D::update_fields()
                .with_centers(self.active_centers.iter().copied())
                .with_half_sizes(self.active_halves.iter().copied())
                .columns(self.active_rows.iter().map(|&(_, _, n)| n))?;
            let rows = &mut self.active_rows.iter().map(|&(m, r, _)| (m, r));
            rec.send_columns("grouping/active", ticks(rows), boxes)?;
        }
        Ok(())
    }

    fn send_merges(&mut self, rec: &RecordingStream) -> anyhow::Result<()> {
        for ((path, _), rows) in SERIES.iter().zip(&mut self.series) {
            let scalars = rows.scalars();
            let (ticks, values) = rows.take();
            if ticks.is_empty() {
                continue;
            }
            let k = ticks.len();
            let scalars = rerun::Scalars::new(values).columns(std::iter::repeat_n(scalars, k))?;
            rec.send_columns(*path, [TimeColumn::new_sequence("merge", ticks)], scalars)?;
        }
        if !self.box_ticks.is_empty() {
            let boxes = rerun::Boxes3D::update_fields()
                .with_centers(self.box_centers.iter().copied())
                .with_half_sizes(self.box_halves.iter().copied())
                .columns(std::iter::repeat_n(3, self.box_ticks.len()))?;
            let (merge, round): (Vec<i64>, Vec<i64>) = self.box_ticks.iter().copied().unzip();
            let ticks = [
                TimeColumn::new_sequence("merge", merge),
                TimeColumn::new_sequence("round", round),
            ];
            rec.send_columns("grouping/merge", ticks, boxes)?;
        }
        Ok(())
    }
}
