//! Per-merge data buffered as columns and sent with `send_columns` in batches: the scalar
//! series (always) and the merged pair's and new body's boxes (with per-merge geometry).

use rerun::{RecordingStream, TimeColumn};

use super::BoxF32;
use crate::grouping::Merge;

/// Merges buffered before their columns are sent.
pub(super) const BATCH: usize = 4096;

/// Entity path and legend name of each per-merge series, in [`MergeColumns::push`] order.
pub(super) const SERIES: [(&str, &str); 7] = [
    ("series/cost", "Cost"),
    ("series/diameter", "diameter"),
    ("series/fill", "Fill"),
    ("series/balance", "Balance"),
    ("series/dlimit", "DLimit"),
    ("series/glimit", "GLimit"),
    ("series/queue_len", "MPairs length"),
];

/// Orange of the merged pair's boxes.
const PAIR_ORANGE: u32 = 0xFF8C00FF;
/// Green of the new body's box.
const NEW_GREEN: u32 = 0x2EB82EFF;

/// Logs the static colours and line widths of the per-merge boxes.
pub(super) fn log_styles(rec: &RecordingStream) -> anyhow::Result<()> {
    use rerun::components::{FillMode, Radius};
    for (path, color, radius) in [
        ("grouping/merge/pair", PAIR_ORANGE, 2.0),
        ("grouping/merge/new", NEW_GREEN, 2.5),
    ] {
        rec.log_static(
            path,
            &rerun::Boxes3D::update_fields()
                .with_colors([color])
                .with_radii([Radius::new_ui_points(radius)])
                .with_fill_mode(FillMode::MajorWireframe),
        )?;
    }
    Ok(())
}

/// Column buffers of the merges not sent yet.
#[derive(Default)]
pub(super) struct MergeColumns {
    step: Vec<i64>,
    round: Vec<i64>,
    series: [Vec<f64>; 7],
    pair_centers: Vec<[f32; 3]>,
    pair_halves: Vec<[f32; 3]>,
    new_centers: Vec<[f32; 3]>,
    new_halves: Vec<[f32; 3]>,
}

impl MergeColumns {
    /// Buffers one merge; `boxes` are the pair's and the new body's boxes when per-merge
    /// geometry is written.
    pub(super) fn push(
        &mut self,
        m: &Merge,
        dlimit: f64,
        glimit: f64,
        boxes: Option<([BoxF32; 2], BoxF32)>,
    ) {
        self.step.push(m.step as i64);
        self.round.push(m.round as i64);
        let values = [
            m.cost,
            m.diameter,
            m.fill,
            m.balance,
            dlimit,
            glimit,
            m.queue_len as f64,
        ];
        for (column, v) in self.series.iter_mut().zip(values) {
            column.push(v);
        }
        if let Some((pair, new)) = boxes {
            for b in pair {
                self.pair_centers.push(b.center);
                self.pair_halves.push(b.half);
            }
            self.new_centers.push(new.center);
            self.new_halves.push(new.half);
        }
    }

    /// Number of buffered merges.
    pub(super) fn len(&self) -> usize {
        self.step.len()
    }

    /// Sends every buffered merge and empties the buffers.
    pub(super) fn flush(&mut self, rec: &RecordingStream) -> anyhow::Result<()> {
        let result = self.send(rec);
        self.step.clear();
        self.round.clear();
        self.series.iter_mut().for_each(Vec::clear);
        self.pair_centers.clear();
        self.pair_halves.clear();
        self.new_centers.clear();
        self.new_halves.clear();
        result
    }

    fn send(&mut self, rec: &RecordingStream) -> anyhow::Result<()> {
        let k = self.len();
        if k == 0 {
            return Ok(());
        }
        let merge = || TimeColumn::new_sequence("merge", self.step.iter().copied());
        let round = || TimeColumn::new_sequence("round", self.round.iter().copied());
        for ((path, _), values) in SERIES.iter().zip(&self.series) {
            let scalars = rerun::Scalars::new(values.iter().copied()).columns_of_unit_batches()?;
            rec.send_columns(*path, [merge()], scalars)?;
        }
        if !self.new_centers.is_empty() {
            let pair = rerun::Boxes3D::update_fields()
                .with_centers(self.pair_centers.iter().copied())
                .with_half_sizes(self.pair_halves.iter().copied())
                .columns(std::iter::repeat_n(2, k))?;
            rec.send_columns("grouping/merge/pair", [merge(), round()], pair)?;
            let new = rerun::Boxes3D::update_fields()
                .with_centers(self.new_centers.iter().copied())
                .with_half_sizes(self.new_halves.iter().copied())
                .columns(std::iter::repeat_n(1, k))?;
            rec.send_columns("grouping/merge/new", [merge(), round()], new)?;
        }
        Ok(())
    }
}
