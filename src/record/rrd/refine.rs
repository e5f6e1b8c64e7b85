//! The refinement's rows (`record --refine`), on their own `refine` timeline: tick 0 is the
//! grouping's tree (its SAH), tick k the tree after the k-th kept step (a rebuilt treelet or a
//! move). The same rows continue the `merge` timeline after the last merge (refine tick k at
//! merge tick last + k), so the layout's `merge` cursor reaches them too.
//!
//! | entity | archetype | content |
//! |---|---|---|
//! | `series/refine_sah` | `Scalars` (1) | SAH of the tree at each tick |
//! | `refine/move` | `Boxes3D` (2) | with per-merge geometry (`--detail merges`, `full`): the moved subtree's box (orange), then its new parent's (green); for a rebuilt treelet its root's box twice |
//! | `log/refine` | `TextLog` | the start (parameters, SAH) and the end (moves, SAH) |
//!
//! Rows are buffered and sent as columns every [`super::columns::BATCH`] steps and at the end.

use rerun::{RecordingStream, TimeColumn};

use super::BoxF32;
use crate::refine::{RefineParams, Step};

/// Entity of the SAH series.
pub(super) const SAH: &str = "series/refine_sah";
/// Colour of the SAH series.
const SAH_COLOR: u32 = 0x1F77B4FF;
/// Orange of the moved subtree's box.
const MOVED_ORANGE: u32 = 0xFF8C00FF;
/// Green of the new parent's box.
const PARENT_GREEN: u32 = 0x2EB82EFF;

/// Buffered refinement rows.
#[derive(Default)]
pub(super) struct RefineColumns {
    /// Whether the static styling was sent.
    started: bool,
    tick: Vec<i64>,
    sah: Vec<f64>,
    centers: Vec<[f32; 3]>,
    halves: Vec<[f32; 3]>,
    text_ticks: Vec<i64>,
    text: Vec<String>,
    /// SAH at the start, and of the last step seen.
    first_sah: f64,
    last_sah: f64,
    steps: u32,
    /// The last merge's tick: refine tick k is `merge` tick `merge_offset + k`.
    merge_offset: i64,
}

impl RefineColumns {
    /// The start after the merge at tick `last_merge`: styling (once), the starting SAH at tick
    /// 0 and a log line.
    pub(super) fn start(
        &mut self,
        rec: &RecordingStream,
        params: &RefineParams,
        sah: f64,
        boxes: bool,
        last_merge: i64,
    ) -> anyhow::Result<()> {
        self.merge_offset = last_merge;
        if !self.started {
            self.started = true;
            super::send_static(
                rec,
                SAH,
                &rerun::SeriesLines::new()
                    .with_names(["SAH"])
                    .with_colors([SAH_COLOR]),
            )?;
            if boxes {
                use rerun::components::{FillMode, Radius};
                let r = Radius::new_ui_points(2.0);
                super::send_static(
                    rec,
                    "refine/move",
                    &rerun::Boxes3D::update_fields()
                        .with_colors([MOVED_ORANGE, PARENT_GREEN])
                        .with_radii([r, r])
                        .with_fill_mode(FillMode::MajorWireframe),
                )?;
            }
        }
        (self.first_sah, self.last_sah) = (sah, sah);
        self.tick.push(0);
        self.sah.push(sah);
        self.text_ticks.push(0);
        let roots = match params.treelet_min {
            0 => "roots by the tree's size".to_string(),
            g => format!("roots of at least {g} leaves"),
        };
        let treelets = match params.treelet_passes {
            0 => "no treelet pass".to_string(),
            1 => format!("1 treelet pass ({} leaves, {roots})", params.treelet),
            p => format!("{p} treelet passes ({} leaves, {roots})", params.treelet),
        };
        self.text.push(format!(
            "refinement: {treelets}, then up to {} reinsertion passes, first batch {} of the nodes; SAH {sah:.6}",
            params.passes, params.batch
        ));
        Ok(())
    }

    /// One kept step; `boxes` = the moved subtree's and its new parent's (a treelet root's box
    /// twice), with geometry.
    pub(super) fn push(&mut self, s: &Step, boxes: Option<[BoxF32; 2]>) {
        self.tick.push(i64::from(s.step) + 1);
        self.sah.push(s.sah);
        if let Some(b) = boxes {
            self.centers.extend(b.map(|x| x.center));
            self.halves.extend(b.map(|x| x.half));
        }
        self.last_sah = s.sah;
        self.steps = s.step + 1;
    }

    /// Kept steps so far.
    pub(super) fn steps(&self) -> u32 {
        self.steps
    }

    /// Buffered steps.
    pub(super) fn len(&self) -> usize {
        self.tick.len()
    }

    /// Adds the closing log line (when a refinement ran) and sends everything buffered.
    pub(super) fn finish(&mut self, rec: &RecordingStream) -> anyhow::Result<()> {
        if self.started {
            self.text_ticks.push(i64::from(self.steps));
            self.text.push(format!(
                "refinement done: {} steps, SAH {:.6} → {:.6}",
                self.steps, self.first_sah, self.last_sah
            ));
        }
        self.flush(rec)
    }

    /// Sends the buffered rows, one chunk per entity, and empties the buffers.
    pub(super) fn flush(&mut self, rec: &RecordingStream) -> anyhow::Result<()> {
        let result = self.send(rec);
        self.tick.clear();
        self.sah.clear();
        self.centers.clear();
        self.halves.clear();
        self.text_ticks.clear();
        self.text.clear();
        result
    }

    /// The `refine` and `merge` time columns of refine ticks `ticks`.
    fn times(&self, ticks: &[i64]) -> [TimeColumn; 2] {
        let offset = self.merge_offset;
        [
            TimeColumn::new_sequence("refine", ticks.iter().copied()),
            TimeColumn::new_sequence("merge", ticks.iter().map(|t| t + offset)),
        ]
    }

    fn send(&self, rec: &RecordingStream) -> anyhow::Result<()> {
        let k = self.tick.len();
        if k > 0 {
            let scalars =
                rerun::Scalars::new(self.sah.iter().copied()).columns(std::iter::repeat_n(1, k))?;
            rec.send_columns(SAH, self.times(&self.tick), scalars)?;
            if !self.centers.is_empty() {
                // Tick 0 (the start) has no move: the boxes belong to ticks 1.. of this batch.
                let moved: Vec<i64> = self.tick.iter().copied().filter(|&t| t > 0).collect();
                let boxes = rerun::Boxes3D::update_fields()
                    .with_centers(self.centers.iter().copied())
                    .with_half_sizes(self.halves.iter().copied())
                    .columns(std::iter::repeat_n(2, moved.len()))?;
                rec.send_columns("refine/move", self.times(&moved), boxes)?;
            }
        }
        if !self.text.is_empty() {
            let info = rerun::components::TextLogLevel::from(rerun::TextLogLevel::INFO);
            let log = rerun::TextLog::update_fields()
                .with_many_text(self.text.iter().map(String::as_str))
                .with_many_level(std::iter::repeat_n(info, self.text.len()))
                .columns_of_unit_batches()?;
            rec.send_columns("log/refine", self.times(&self.text_ticks), log)?;
        }
        Ok(())
    }
}
