//! The Rerun `.rrd` recorder: the grouping run as a file for the Rerun viewer (SDK 0.36.3). Its
//! timelines, entities and layout are listed in `docs/recordings.md`, "`.rrd` (Rerun)".
//!
//! [`RrdRecorder`] is an [`Observer`]. It saves through a sink of its own (`sink.rs`: the SDK's
//! encoder on a thread that bypasses the page cache, the file checked complete at the end),
//! writes what precedes the events (`header.rs`) and embeds a blueprint (`blueprint.rs`).
//!
//! - Only the timelines `merge`, `round`, `level` and `refine`: `log_time` is switched off and
//!   temporal rows go through `send_columns`, which adds no `log_time`/`log_tick`.
//! - Positions are `f32` relative to the scene's AABB centre, moved back by a static
//!   `Transform3D`, so that scenes far from the origin keep their precision.
//! - Per-merge rows are buffered as columns, `columns::BATCH` merges per batch. Written to a
//!   file alone (no live viewer) a run of at most [`HOLD_MAX`] primitives keeps its batches of
//!   per-merge series and boxes until the end and sends them after the tree levels, so that a
//!   viewer reading the file shows the round log and the levels first and the plots fill
//!   afterwards; the round log and active sets go out with every batch. Larger or live runs send
//!   each batch as it fills (memory stays bounded, the live view follows the run). A stopped run has no levels and the
//!   property `wraptree_outcome`. The recording id comes from the scene's SHA-256 and the
//!   parameters (not the detail), so recordings of one run open as one.

mod blueprint;
mod columns;
mod compare;
mod envelope;
mod header;
mod levels;
mod mesh;
mod parts;
mod refine;
mod series_file;
mod sink;
pub(crate) mod spherize;

pub use compare::write_comparison_rrd;
pub use series_file::SeriesFile;

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail};
use rerun::external::arrow::array::Array as _;
use rerun::{AsComponents, RecordingStream, SerializedComponentColumn, TimeColumn};

use crate::events::Step;
use crate::geom::{Aabb, P3};
use crate::grouping::{Event, Merge, Observer};
use crate::record::live::Live;
use crate::record::{ACTIVE_CAP, Detail, Outcome, RunInfo, boxes_drawn};
use columns::Columns;
use mesh::PrimMesh;

/// The level of every log line but a stopped run's warning.
const INFO: &str = rerun::TextLogLevel::INFO;
/// Light grey of the input primitives.
const SCENE_GREY: u32 = 0xC8C8C8FF;
/// Blue of the active bodies' boxes.
const ACTIVE_BLUE: u32 = 0x3C78D8A0;
/// Runs of at most this many primitives, written to a file alone, hold their per-merge batches
/// until the levels are written (about 72 bytes per merge held).
pub const HOLD_MAX: usize = 2_000_000;

/// Records a grouping run to a Rerun `.rrd` file, laid out as `docs/recordings.md` lists.
pub struct RrdRecorder {
    rec: Option<RecordingStream>,
    /// How the file's writer ended.
    status: sink::Status,
    /// The file written.
    path: PathBuf,
    /// The path named in errors.
    name: PathBuf,
    detail: Detail,
    /// Primitives in the scene (N).
    primitives: usize,
    origin: P3,
    /// Box of every body so far, relative to `origin` (only when per-merge geometry is written).
    boxes: Vec<BoxF32>,
    columns: Columns,
    /// The per-merge batches held back until the levels are written ([`HOLD_MAX`]), when held.
    held: Option<Vec<Columns>>,
    /// The refinement's rows (`record --refine`).
    refine: refine::RefineColumns,
    /// The part lines, small chunks summarised.
    parts: parts::PartLines,
    round: u32,
    dlimit: f64,
    glimit: f64,
    /// Merges seen so far: the `merge` tick of the next merge.
    merges: u32,
    /// The primitives' mesh, kept for the levels written by `finish`.
    mesh: Option<PrimMesh>,
    /// The thread sending the first blueprint (joined before the file is closed).
    blueprint: Option<std::thread::JoinHandle<anyhow::Result<()>>>,
    /// What the layout is fitted to; its ranges are filled in as the merges come.
    fit: blueprint::Fit,
    /// Per plot of the merge series, the largest value so far ([`blueprint::Fit::ranges`]).
    maxima: [f64; 4],
    /// The recording id, the seed of the blueprints' ids.
    id: String,
    refined: bool,
    error: Option<anyhow::Error>,
}

/// An AABB as (centre, half size) in `f32` relative to the scene origin.
#[derive(Clone, Copy, Debug)]
struct BoxF32 {
    center: [f32; 3],
    half: [f32; 3],
}

impl BoxF32 {
    fn new(b: &Aabb, origin: &P3) -> BoxF32 {
        let e = b.extents() / 2.0;
        BoxF32 {
            center: rel(&b.center(), origin),
            half: [e.x as f32, e.y as f32, e.z as f32],
        }
    }
}

/// The first 16 bytes of `digest` as a UUID-shaped id (`8-4-4-4-12` hex digits).
fn uuid_text(digest: &[u8]) -> String {
    let hex: String = digest[..16].iter().map(|b| format!("{b:02x}")).collect();
    format!(
        "{}-{}-{}-{}-{}",
        &hex[..8],
        &hex[8..12],
        &hex[12..16],
        &hex[16..20],
        &hex[20..]
    )
}

/// Where positions are measured from: the centre of the scene's box `bbox`, or the world origin
/// when it is not finite (an empty scene).
fn origin_of(bbox: &Aabb) -> P3 {
    let c = bbox.center();
    if c.iter().all(|x| x.is_finite()) {
        c
    } else {
        P3::origin()
    }
}

/// `p` relative to `origin`, as `f32`.
fn rel(p: &P3, origin: &P3) -> [f32; 3] {
    let d = p - origin;
    [d.x as f32, d.y as f32, d.z as f32]
}

/// Sends one row of `arch` as static data. Unlike `log_static`, whose rows wait in the SDK's
/// batcher until the stream is flushed or dropped, the chunk goes straight to the file writer,
/// which encodes it while the grouping runs.
fn send_static(rec: &RecordingStream, entity: &str, arch: &dyn AsComponents) -> anyhow::Result<()> {
    send_at(rec, entity, &[], arch)
}

/// Sends one row of `arch` at the given sequence times (static without times), without
/// `log_time`.
fn send_at(
    rec: &RecordingStream,
    entity: &str,
    times: &[(&'static str, i64)],
    arch: &dyn AsComponents,
) -> anyhow::Result<()> {
    let columns = arch
        .as_serialized_batches()
        .into_iter()
        .map(|batch| {
            let n = batch.array.len();
            batch.partitioned([n])
        })
        .collect::<Result<Vec<SerializedComponentColumn>, _>>()?;
    let index = times
        .iter()
        .map(|&(name, t)| TimeColumn::new_sequence(name, [t]));
    rec.send_columns(entity, index, columns)?;
    Ok(())
}

impl RrdRecorder {
    /// Creates `path` (replacing it) and writes the run metadata and the static scene; the
    /// blueprint is sent from a thread of its own.
    ///
    /// Fails when the file cannot be created or the first writes fail.
    pub fn new(path: &Path, info: &RunInfo<'_>) -> anyhow::Result<Self> {
        Self::with_name(path, path, info)
    }

    /// As [`RrdRecorder::new`], but errors name `name` instead of `path`: the destination that
    /// a temporary `path` will be renamed to.
    pub fn with_name(path: &Path, name: &Path, info: &RunInfo<'_>) -> anyhow::Result<Self> {
        Self::with_refine(path, name, info, false)
    }

    /// As [`RrdRecorder::with_name`], for a run whose tree is then `refined` (`record
    /// --refine`): the layout then has the refinement's SAH plot.
    pub fn with_refine(
        path: &Path,
        name: &Path,
        info: &RunInfo<'_>,
        refined: bool,
    ) -> anyhow::Result<Self> {
        Self::with_live(path, name, info, refined, &Live::default())
    }

    /// As [`RrdRecorder::with_refine`], also streaming every message to `live`'s Rerun viewer or
    /// server, if it has one: the recording stream sends each message to the file and to the
    /// live stream, which never holds the file up ([`crate::record::live`]).
    pub fn with_live(
        path: &Path,
        name: &Path,
        info: &RunInfo<'_>,
        refined: bool,
        live: &Live,
    ) -> anyhow::Result<Self> {
        let scene = info.scene;
        let id = header::recording_id(info);
        let builder = rerun::RecordingStreamBuilder::new("wraptree").recording_id(id.clone());
        let live_sink = live.rerun_sink();
        let hold = live_sink.is_none() && scene.len() <= HOLD_MAX;
        let (rec, status) = sink::save(builder, path, live_sink)
            .map_err(|e| file_error(name, "cannot create the Rerun recording", e))?;
        let bbox = scene.aabb();
        let fit = blueprint::Fit {
            eye: blueprint::framing(&bbox),
            last_merge: scene.len().saturating_sub(2) as i64,
            ranges: None,
            refine_steps: 0,
        };
        // The SDK builds a blueprint through a stream of its own (two threads); a thread of
        // ours does it while this one writes the header and the events.
        let (layout, bp_rec) = (blueprint::layout(info.detail, refined, &fit), rec.clone());
        let seed = format!("{id}/start");
        let blueprint = std::thread::Builder::new()
            .name("rrd-blueprint".into())
            .spawn(move || layout.send(&bp_rec, &seed))
            .map_err(|e| file_error(name, "cannot start the blueprint thread", e))?;

        let origin = origin_of(&bbox);
        let boxes = if info.detail.merges() {
            let mut b = Vec::with_capacity(2 * scene.len());
            b.extend((0..scene.len()).map(|i| BoxF32::new(&scene.prim_aabb(i), &origin)));
            b
        } else {
            Vec::new()
        };
        let mut recorder = RrdRecorder {
            rec: Some(rec),
            status,
            path: path.to_path_buf(),
            name: name.to_path_buf(),
            detail: info.detail,
            primitives: scene.len(),
            origin,
            boxes,
            columns: Columns::new(scene.len().saturating_sub(1)),
            held: hold.then(Vec::new),
            refine: refine::RefineColumns::default(),
            parts: parts::PartLines::default(),
            round: 0,
            dlimit: info.params.dlimit0,
            glimit: info.params.glimit0,
            merges: 0,
            mesh: None,
            blueprint: Some(blueprint),
            fit,
            maxima: [0.0; 4],
            id,
            refined,
            error: None,
        };
        let mesh = PrimMesh::new(scene, &origin);
        recorder
            .write_header(info, &mesh)
            .map_err(|e| file_error(name, "cannot write the Rerun recording", e))?;
        if info.detail.levels() {
            recorder.mesh = Some(mesh);
        }
        Ok(recorder)
    }

    fn rec(&self) -> anyhow::Result<&RecordingStream> {
        self.rec.as_ref().ok_or_else(closed)
    }

    fn text(&mut self, round: u32, line: std::fmt::Arguments<'_>) {
        self.columns.push_text(self.merges, round, line, INFO);
    }

    fn handle(&mut self, event: &Event<'_>) -> anyhow::Result<()> {
        match *event {
            Event::RoundStart {
                round,
                dlimit,
                glimit,
                active,
                dormant,
                pairs,
            } => self.round_start(round, dlimit, glimit, active, dormant, pairs)?,
            Event::Merge(m) => self.merge(&m)?,
            Event::Dormant { .. } => {}
            Event::RefineStart { params, sah } => {
                let rec = self.rec.as_ref().ok_or_else(closed)?;
                let last_merge = i64::from(self.merges) - 1;
                self.refine
                    .start(rec, &params, sah, self.detail.merges(), last_merge)?;
            }
            Event::Refine(s) => self.refine_step(&s)?,
            Event::Part(p) => {
                let lines = part_lines(&mut self.columns, self.round);
                self.parts.part(&p, self.merges, lines);
            }
            Event::Doubling {
                round,
                merges,
                dlimit,
                glimit,
            } => {
                let limits = format!("DLimit → {dlimit:.6e}, GLimit → {glimit:.6e}");
                let line = format_args!("doubling after round {round} ({merges} merges): {limits}");
                self.text(round, line);
            }
            Event::Finish {
                root,
                rounds,
                merges,
            } => {
                self.end_parts();
                let line =
                    format_args!("finished: root {root} after {rounds} rounds and {merges} merges");
                self.text(self.round, line);
            }
        }
        Ok(())
    }

    /// A round starts: its limits are kept for the merges, its log line written and, with
    /// per-merge geometry, its active bodies' boxes.
    fn round_start(
        &mut self,
        round: u32,
        dlimit: f64,
        glimit: f64,
        active: &[u32],
        dormant: u32,
        pairs: u64,
    ) -> anyhow::Result<()> {
        self.round = round;
        self.dlimit = dlimit;
        self.glimit = glimit;
        let n = active.len();
        let limits = format!("DLimit {dlimit:.6e}, GLimit {glimit:.6e}");
        let sets = format!("{n} active, {dormant} dormant, {pairs} pairs");
        let capped = self.detail.merges() && n > ACTIVE_CAP;
        let note = if capped {
            format!(" (active boxes not drawn above {ACTIVE_CAP})")
        } else {
            String::new()
        };
        self.text(round, format_args!("round {round}: {limits}, {sets}{note}"));
        if self.detail.merges() {
            // Above the cap the row is empty: it still clears the previous round's boxes.
            let drawn = if capped { &active[..0] } else { active };
            let boxes = drawn
                .iter()
                .map(|&b| self.body(b))
                .collect::<anyhow::Result<Vec<_>>>()?;
            self.columns.push_active(self.merges, round, &boxes);
        }
        Ok(())
    }

    /// A merge's row of the series (and of its boxes, see [`RrdRecorder::merge_boxes`]); the
    /// columns are sent every [`columns::BATCH`] merges.
    fn merge(&mut self, m: &Merge) -> anyhow::Result<()> {
        let boxes = if self.detail.merges() {
            self.merge_boxes(m)?
        } else {
            None
        };
        self.columns.push(m, self.dlimit, self.glimit, boxes);
        let values = [
            m.cost,
            m.diameter.max(self.dlimit).max(self.glimit),
            m.fill.max(m.balance),
            f64::from(m.queue_len),
        ];
        for (max, v) in self.maxima.iter_mut().zip(values) {
            if v.is_finite() {
                *max = max.max(v);
            }
        }
        self.merges = m.step + 1;
        if self.columns.len() >= columns::BATCH {
            self.flush_columns()?;
        }
        Ok(())
    }

    /// Sends the buffered columns, or with held batches the rounds' now and the merges' later.
    fn flush_columns(&mut self) -> anyhow::Result<()> {
        let rec = self.rec.as_ref().ok_or_else(closed)?;
        match &mut self.held {
            Some(held) => held.push(self.columns.flush_rounds(rec)?),
            None => self.columns.flush(rec)?,
        }
        Ok(())
    }

    /// Keeps the new body's box; returns the merged pair's and the new body's boxes when the
    /// merge is drawn ([`boxes_drawn`]). Err: a merge whose ids do not follow the events so far.
    fn merge_boxes(&mut self, m: &Merge) -> anyhow::Result<Option<([BoxF32; 2], BoxF32)>> {
        let new = BoxF32::new(&m.aabb, &self.origin);
        let expected = self.boxes.len();
        if m.new as usize != expected {
            bail!(
                "merge {} creates body {}, expected {expected}",
                m.step,
                m.new
            );
        }
        // Only the drawn merges read their pair's boxes (a random access into every body's
        // box); the others check that the pair exists.
        let drawn = boxes_drawn(m.step, self.primitives);
        let pair = if drawn {
            Some([self.body(m.a)?, self.body(m.b)?])
        } else if m.a.max(m.b) as usize >= expected {
            let id = m.a.max(m.b);
            bail!("event names body {id}, which does not exist yet");
        } else {
            None
        };
        self.boxes.push(new);
        Ok(pair.map(|pair| (pair, new)))
    }

    /// A kept refinement step's row (with per-merge geometry, the moved subtree's and its new
    /// parent's boxes); the rows are sent every [`columns::BATCH`] steps.
    fn refine_step(&mut self, s: &Step) -> anyhow::Result<()> {
        let boxes = self.detail.merges().then(|| {
            [
                BoxF32::new(&s.aabb, &self.origin),
                BoxF32::new(&s.parent_aabb, &self.origin),
            ]
        });
        self.refine.push(s, boxes);
        if self.refine.len() >= columns::BATCH {
            let rec = self.rec.as_ref().ok_or_else(closed)?;
            self.refine.flush(rec)?;
        }
        Ok(())
    }

    fn body(&self, id: u32) -> anyhow::Result<BoxF32> {
        self.boxes
            .get(id as usize)
            .copied()
            .ok_or_else(|| anyhow!("event names body {id}, which does not exist yet"))
    }

    /// Flushes the series, writes the tree levels (when the detail asks for them and the run
    /// finished), then ends the file with the RRD footer and checks that it is complete.
    ///
    /// Returns the first error met while recording, if any.
    pub fn finish(mut self, outcome: &Outcome<'_>) -> anyhow::Result<()> {
        let what = "cannot write the Rerun recording";
        let (path, name) = (self.path.clone(), self.name.clone());
        let fail = |e: anyhow::Error| file_error(&name, what, e);
        if let Some(err) = self.error.take() {
            return Err(fail(err));
        }
        self.write_tail(outcome).map_err(fail)?;
        if let Some(handle) = self.blueprint.take() {
            match handle.join() {
                Ok(sent) => sent.map_err(fail)?,
                Err(_) => return Err(fail(anyhow!("the blueprint thread failed"))),
            }
        }
        let rec = self.rec.take().ok_or_else(closed).map_err(fail)?;
        // The layout again, fitted to the whole run: the viewer switches to it once loaded.
        let fit = blueprint::Fit {
            last_merge: i64::from(self.merges.max(1)) - 1,
            ranges: Some(self.maxima),
            refine_steps: self.refine.steps(),
            ..self.fit.clone()
        };
        blueprint::layout(self.detail, self.refined, &fit)
            .send(&rec, &format!("{}/end", self.id))
            .map_err(fail)?;
        sink::close(rec, &self.status, &path).map_err(fail)
    }

    /// Logs the small chunks' run not yet logged ([`parts`]).
    fn end_parts(&mut self) {
        let lines = part_lines(&mut self.columns, self.round);
        self.parts.end(lines);
    }

    fn write_tail(&mut self, outcome: &Outcome<'_>) -> anyhow::Result<()> {
        self.end_parts();
        if outcome.grouping.is_none() {
            self.mark_incomplete(outcome)?;
        }
        self.columns.close_series();
        self.flush_columns()?;
        let rec = self.rec.as_ref().ok_or_else(closed)?;
        self.refine.finish(rec)?;
        if let (Some(mesh), Some(grouping), Some(spheres)) =
            (&self.mesh, outcome.grouping, outcome.spheres)
        {
            let tree = &grouping.tree;
            levels::log_levels(rec, mesh, tree, spheres, outcome.wrappers, &self.origin)?;
            if let Some(cover) = &outcome.cover {
                levels::log_cover(rec, tree, cover, &self.origin)?;
            }
        }
        for batch in self.held.take().unwrap_or_default() {
            batch.send_held(rec)?;
        }
        Ok(())
    }
}

impl Observer for RrdRecorder {
    fn on_event(&mut self, event: &Event<'_>) {
        if self.error.is_none()
            && let Err(err) = self.handle(event)
        {
            self.error = Some(err);
        }
    }
}

/// Where [`parts::PartLines`] writes: each line into `columns` at its merge tick and `round`.
fn part_lines(columns: &mut Columns, round: u32) -> impl FnMut(u32, &str) + '_ {
    move |merge, line| columns.push_text(merge, round, format_args!("{line}"), INFO)
}

fn closed() -> anyhow::Error {
    anyhow!("the recording is closed")
}

/// One line `PATH: WHAT: cause`, with only the root cause (the SDK's errors repeat their
/// sources in their own messages).
fn file_error(path: &Path, what: &str, err: impl Into<anyhow::Error>) -> anyhow::Error {
    let err = err.into();
    anyhow!("{}: {what}: {}", path.display(), err.root_cause())
}
