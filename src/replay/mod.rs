//! Replaying a run from its `.mcap` recording: [`open`] reads it and loads the embedded scene,
//! [`Replay::tree`] rebuilds the Subset Tree from the recorded merges alone, [`verify`] re-runs
//! the grouping and compares it merge by merge, [`reweight`] re-runs it with other Cost weights
//! and records the new run (`wraptree replay`); [`report`] words what they find as
//! `wraptree replay` prints it.
//!
//! ```no_run
//! use wraptree::grouping::Limits;
//! let replay = wraptree::replay::open("recordings/lamp.mcap".as_ref())?;
//! let stop = wraptree::stop::Stop::new();
//! match wraptree::replay::verify(&replay, &Limits::default(), &stop) {
//!     Ok(v) => println!("{v:?}"),
//!     Err(stopped) => println!("re-run stopped: {stopped:?}"),
//! }
//! # Ok::<(), anyhow::Error>(())
//! ```

pub mod report;

use crate::grouping::{
    self, Event, EventLog, Limits, Merge, Observer, Part, ResolvedParams, StopReason, Stopped,
    SubsetTree, Weights,
};
use crate::output::with_ext;
use crate::record::compare::{CompareRun, divergence, write_comparison};
use crate::record::mcap::{Recorded, read_with_scene_until};
use crate::record::{RecordOptions, Written, record};
use crate::refine::{self, Step};
use crate::scene::Loaded;
use crate::stop::{Interrupted, Stop};
use anyhow::{Result, bail};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// The magic bytes that open every Rerun `.rrd` stream, and the 8 bytes before the entry count
/// that close a finished one (`RRF2FOOT`).
const RRD_MAGIC: &[u8; 4] = b"RRF2";
const RRD_FOOTER: &[u8; 8] = b"RRF2FOOT";
/// The magic bytes that open an MCAP file.
const MCAP_MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

/// Why `path` cannot be what `replay` reads, when its first and last bytes say so: a Rerun
/// `.rrd` file (finished, truncated or with a bad magic) or an empty file. `None` for anything
/// else, which the MCAP reader then judges.
pub fn not_an_mcap(path: &Path) -> Option<String> {
    use std::io::{Read, Seek, SeekFrom};
    let mut f = std::fs::File::open(path).ok()?;
    let len = f.metadata().ok()?.len();
    let name = path.display();
    if len == 0 {
        return Some(format!("{name}: empty file (not a recording)"));
    }
    let mut head = [0u8; 8];
    let n = f.read(&mut head).ok()?;
    let head = &head[..n];
    let is_rrd = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("rrd"));
    let mcap = path.with_extension("mcap");
    let hint = if mcap != path && mcap.is_file() {
        format!("replay reads the .mcap beside it ({})", mcap.display())
    } else {
        "replay reads the .mcap that `record` writes beside the .rrd".to_string()
    };
    if head.starts_with(RRD_MAGIC) {
        let mut tail = [0u8; 12];
        let finished = len >= 24
            && f.seek(SeekFrom::End(-12)).is_ok()
            && f.read_exact(&mut tail).is_ok()
            && tail.starts_with(RRD_FOOTER);
        let what = if finished {
            "a Rerun .rrd recording"
        } else {
            "a truncated Rerun .rrd recording (no footer)"
        };
        return Some(format!("{name}: {what}, not an MCAP file; {hint}"));
    }
    if is_rrd && !head.starts_with(MCAP_MAGIC) {
        return Some(format!(
            "{name}: not a Rerun recording (bad magic, expected RRF2) nor an MCAP file"
        ));
    }
    None
}

/// A recording read back with its embedded scene loaded.
#[derive(Debug)]
pub struct Replay {
    /// What the `.mcap` holds.
    pub rec: Recorded,
    /// The embedded scene, loaded with the recorded options.
    pub loaded: Loaded,
}

/// Reads the `.mcap` recording at `path` and loads its embedded scene. Err: not an MCAP file
/// (a `.rrd`, an empty file: [`not_an_mcap`]), an unreadable recording, or an embedded scene
/// that does not load or does not match the metadata.
pub fn open(path: &Path) -> Result<Replay> {
    open_until(path, &Stop::new())
}

/// [`open`], its passes checking `stop` (Err: [`Interrupted`]).
pub fn open_until(path: &Path, stop: &Stop) -> Result<Replay> {
    if let Some(why) = not_an_mcap(path) {
        bail!("{why}");
    }
    let (rec, loaded) = read_with_scene_until(path, stop)?;
    Ok(Replay { rec, loaded })
}

impl Replay {
    /// The Subset Tree rebuilt from the recorded merges alone (leaf boxes from the embedded
    /// scene).
    pub fn tree(&self) -> Result<SubsetTree> {
        self.rec
            .tree(&self.loaded.scene)
            .map_err(anyhow::Error::msg)
    }
}

/// An observer that keeps the event log and sets `stop` once `limit` merges are made, so a
/// re-run of an incomplete recording ends where the recording did, or once `user` is requested.
struct UpTo<'a> {
    log: EventLog,
    limit: Option<usize>,
    stop: &'a AtomicBool,
    user: &'a Stop,
}

impl Observer for UpTo<'_> {
    fn on_event(&mut self, event: &Event<'_>) {
        self.log.on_event(event);
        if self.limit.is_some_and(|k| self.log.merges.len() >= k) || self.user.is_requested() {
            self.stop.store(true, Ordering::Relaxed);
        }
    }
}

/// Re-runs the grouping of `loaded` within `limits`, up to `merges` merges when given (the
/// length of an incomplete recording), and returns its events. Err: the stop, when a limit of
/// `limits` or `stop` ended the re-run first.
pub fn rerun(
    loaded: &Loaded,
    params: &ResolvedParams,
    limits: &Limits,
    merges: Option<usize>,
    stop: &Stop,
) -> Result<EventLog, Stopped> {
    // A whole re-run obeys `stop` itself; one up to a recorded length has a flag of its own,
    // which the observer also sets once `stop` is requested.
    let own = AtomicBool::new(merges == Some(0));
    let flag = if merges.is_some() { &own } else { stop.flag() };
    let mut obs = UpTo {
        log: EventLog::default(),
        limit: merges,
        stop: &own,
        user: stop,
    };
    let budget = limits.budget(Some(flag));
    match grouping::group_within(&loaded.scene, params, &mut obs, &budget) {
        Ok(_) => Ok(obs.log),
        // Our own flag, set at the recorded length: the re-run went as far as the recording.
        Err(s) if s.reason == StopReason::Interrupted && !stop.is_requested() => Ok(obs.log),
        Err(s) => Err(s),
    }
}

/// A merge without `queue_len`, which depends on how MPairs stores pairs (recordings made by
/// other versions may differ), not on which pair merges.
fn decision(m: &Merge) -> Merge {
    Merge { queue_len: 0, ..*m }
}

/// Index of the first merge where two timelines make a different decision, if any.
pub fn first_divergence(a: &[Merge], b: &[Merge]) -> Option<usize> {
    (0..a.len().max(b.len())).find(|&i| a.get(i).map(decision) != b.get(i).map(decision))
}

/// Mean and largest Balance over a run's merges.
pub fn balance_stats(m: &[Merge]) -> (f64, f64) {
    let mean = m.iter().map(|x| x.balance).sum::<f64>() / m.len().max(1) as f64;
    (mean, m.iter().map(|x| x.balance).fold(1.0, f64::max))
}

/// What [`verify`] found.
#[derive(Clone, Debug, PartialEq)]
pub enum Verified {
    /// The re-run made the same decisions at every merge.
    Identical {
        /// Merges compared.
        merges: usize,
        /// Whether MPairs queue lengths differ (the queue's storage can differ between versions).
        queue_lengths_differ: bool,
    },
    /// The recording is incomplete and its merges are the re-run's first ones.
    Prefix {
        /// Merges recorded.
        merges: usize,
    },
    /// The parts of the run (chunks, components, copies) differ at this index.
    PartDiffers {
        /// Index of the first differing part.
        index: usize,
        /// The recorded part there, if any.
        recorded: Option<Part>,
        /// The re-run's part there, if any.
        rerun: Option<Part>,
    },
    /// The first merge step where the two differ, and the re-run's events.
    Diverged {
        /// Merge step.
        step: usize,
        /// The re-run's events.
        rerun: EventLog,
    },
}

/// Re-runs the grouping from the embedded scene and recorded parameters within `limits` (up to
/// the recorded length when the recording is incomplete) and compares it merge by merge. Err:
/// the stop, when a limit or `stop` ended the re-run first.
pub fn verify(replay: &Replay, limits: &Limits, stop: &Stop) -> Result<Verified, Stopped> {
    let rec = &replay.rec;
    let upto = (!rec.complete).then_some(rec.merges.len());
    let log = rerun(&replay.loaded, &rec.params, limits, upto, stop)?;
    let k = rec.parts.len();
    if log.parts.get(..k) != Some(&rec.parts[..]) || (rec.complete && log.parts.len() != k) {
        let index = (0..k)
            .find(|&i| log.parts.get(i) != Some(&rec.parts[i]))
            .unwrap_or(k);
        return Ok(Verified::PartDiffers {
            index,
            recorded: rec.parts.get(index).copied(),
            rerun: log.parts.get(index).copied(),
        });
    }
    Ok(match first_divergence(&rec.merges, &log.merges) {
        None if !rec.complete => Verified::Prefix {
            merges: rec.merges.len(),
        },
        None => Verified::Identical {
            merges: log.merges.len(),
            queue_lengths_differ: rec
                .merges
                .iter()
                .zip(&log.merges)
                .any(|(r, l)| r.queue_len != l.queue_len),
        },
        Some(step) => Verified::Diverged { step, rerun: log },
    })
}

/// What [`verify_refinement`] found: the moves re-run from the recorded tree and refinement
/// parameters, or the first move where they differ from the recorded ones.
#[derive(Clone, Debug, PartialEq)]
pub enum RefineVerified {
    /// Every move is identical.
    Identical {
        /// Moves compared.
        moves: usize,
    },
    /// The first differing move.
    Diverged {
        /// Move index.
        step: usize,
        /// The recorded move there, if any.
        recorded: Option<Box<Step>>,
        /// The re-run's move there, if any.
        rerun: Option<Box<Step>>,
    },
}

/// The Subset Tree the recording's levels show: the grouping's, refined again with the
/// recorded refinement parameters when the recording was refined (`record --refine`).
pub fn final_tree(replay: &Replay) -> Result<SubsetTree> {
    let t = replay.tree()?;
    Ok(match &replay.rec.refine {
        Some(r) => refine::refine_owned(t, &r.params, ()).tree,
        None => t,
    })
}

/// Re-runs the recorded refinement on the grouping's tree rebuilt from the merges and compares
/// the moves; `None` when the recording is incomplete or was not refined.
pub fn verify_refinement(replay: &Replay) -> Result<Option<RefineVerified>> {
    let rec = &replay.rec;
    let Some(r) = rec.refine.filter(|_| rec.complete) else {
        return Ok(None);
    };
    let mut log = EventLog::default();
    refine::refine_owned(replay.tree()?, &r.params, &mut log);
    let n = rec.refine_steps.len().max(log.refine.len());
    Ok(Some(
        match (0..n).find(|&i| rec.refine_steps.get(i) != log.refine.get(i)) {
            None => RefineVerified::Identical {
                moves: log.refine.len(),
            },
            Some(step) => RefineVerified::Diverged {
                step,
                recorded: rec.refine_steps.get(step).copied().map(Box::new),
                rerun: log.refine.get(step).copied().map(Box::new),
            },
        },
    ))
}

/// The recorded weights with `a`, `b`, `c` replaced where given. Err: a weight that is not a
/// finite number ≥ 0 (named as the flag, e.g. `--a must be …`).
pub fn weights(rec: &Recorded, a: Option<f64>, b: Option<f64>, c: Option<f64>) -> Result<Weights> {
    let w = rec.params.weights;
    let weights = Weights {
        a: a.unwrap_or(w.a),
        b: b.unwrap_or(w.b),
        c: c.unwrap_or(w.c),
    };
    weights.check().map_err(|e| anyhow::anyhow!("--{e}"))?;
    Ok(weights)
}

/// A re-weighted run: its recordings and, when it finished, its events and the comparison.
#[derive(Debug)]
pub struct Reweighted {
    /// The recordings of the re-weighted run.
    pub written: Written,
    /// The re-weighted run's events (`None` when it was stopped).
    pub log: Option<EventLog>,
    /// The `.rrd` and `.mcap` with the recorded and the re-weighted run side by side (when it
    /// finished).
    pub comparison: Option<[PathBuf; 2]>,
}

/// How a run is named in a comparison: its weights, and its size measure unless it is the
/// diameter.
pub fn run_label(params: &ResolvedParams) -> String {
    let w = params.weights;
    let measure = match params.mode.cost {
        grouping::CostMeasure::Diameter => String::new(),
        other => format!(" {}", format!("{other:?}").to_lowercase()),
    };
    format!("A{} B{} C{}{measure}", w.a, w.b, w.c)
}

/// What [`compare`] wrote and found.
#[derive(Debug)]
pub struct Compared {
    /// The comparison's `.rrd` and `.mcap`.
    pub paths: [PathBuf; 2],
    /// The runs' labels, in order.
    pub labels: Vec<String>,
    /// The first merge where the second run merges another pair than the first, if any.
    pub divergence: Option<usize>,
}

/// Writes `PREFIX.rrd` and `PREFIX.mcap`, the runs of `replays` (recordings of one scene) side
/// by side ([`write_comparison`]); `labels` name them. Replaces existing files only with
/// `force`. Err: recordings of different scenes, a write that fails (old files are kept), or
/// [`Interrupted`] when `stop` is requested before both files are
/// complete (none written).
pub fn compare(
    replays: &[&Replay],
    labels: &[String],
    prefix: &Path,
    force: bool,
    stop: &crate::stop::Stop,
) -> Result<Compared> {
    let Some(first) = replays.first() else {
        bail!("{}: nothing to compare", prefix.display());
    };
    for r in &replays[1..] {
        if r.rec.metadata.get("scene_sha256") != first.rec.metadata.get("scene_sha256")
            || r.rec.primitives != first.rec.primitives
        {
            bail!(
                "{} and {} record different scenes (their scene hashes differ)",
                first.rec.scene_file_name,
                r.rec.scene_file_name
            );
        }
    }
    let trees = replays
        .iter()
        .map(|r| r.rec.complete.then(|| r.tree()).transpose())
        .collect::<Result<Vec<_>>>()?;
    let runs: Vec<CompareRun<'_>> = replays
        .iter()
        .zip(&trees)
        .zip(labels)
        .map(|((r, t), label)| CompareRun {
            label: label.clone(),
            merges: &r.rec.merges,
            tree: t.as_ref(),
        })
        .collect();
    let scene = &first.loaded.scene;
    let name = &first.rec.scene_file_name;
    let paths = write_comparison(prefix, scene, name, &runs, force, stop)?;
    let divergence = runs
        .get(1)
        .and_then(|b| divergence(runs[0].merges, b.merges));
    Ok(Compared {
        paths,
        labels: labels.to_vec(),
        divergence,
    })
}

/// Re-runs the recording with `weights` (other parameters as recorded) and records the new run
/// to `prefix` with `opts` (see [`record`]); `progress` sees the recorded run's events. A stop
/// (`opts.stop`) while the comparison is written takes the new recording away again
/// ([`Interrupted`]: a stopped run leaves nothing).
pub fn reweight<O: Observer>(
    replay: &Replay,
    weights: Weights,
    prefix: &Path,
    opts: &RecordOptions,
    progress: O,
) -> Result<Reweighted> {
    let params = ResolvedParams {
        weights,
        ..replay.rec.params
    };
    let mut events = EventLog::default();
    let written = record(
        &replay.loaded,
        &params,
        prefix,
        opts,
        grouping::Tee(&mut events, progress),
    )?;
    let log = written.grouping.as_ref().map(|_| events);
    let comparison = match (&log, &written.grouping) {
        (Some(log), Some(g)) => {
            let old = replay.rec.complete.then(|| replay.tree()).transpose()?;
            let runs = [
                CompareRun {
                    label: run_label(&replay.rec.params),
                    merges: &replay.rec.merges,
                    tree: old.as_ref(),
                },
                CompareRun {
                    label: run_label(&params),
                    merges: &log.merges,
                    tree: Some(&g.tree),
                },
            ];
            let scene = &replay.loaded.scene;
            let name = &replay.rec.scene_file_name;
            let prefix = with_ext(prefix, ".compare");
            let stop = opts.stop.clone().map(Stop::from).unwrap_or_default();
            match write_comparison(&prefix, scene, name, &runs, opts.force, &stop) {
                Err(e) if crate::stop::is_interrupted(&e) => {
                    // Failing only when already gone: nothing is left either way.
                    let _ = std::fs::remove_file(&written.rrd);
                    let _ = std::fs::remove_file(&written.mcap);
                    return Err(Interrupted.into());
                }
                c => Some(c?),
            }
        }
        _ => None,
    };
    Ok(Reweighted {
        written,
        log,
        comparison,
    })
}
