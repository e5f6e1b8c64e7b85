//! Recording a grouping run to both files: the scene is grouped on the calling thread while
//! the Rerun and MCAP recorders each consume the events on their own thread; the files appear
//! only when complete (`wraptree record`, `replay --a/--b/--c`, `bench --record`).
//!
//! ```no_run
//! use wraptree::grouping::Params;
//! use wraptree::record::{RecordOptions, record};
//! let loaded = wraptree::scene::load_path("scenes/lamp.obj".as_ref(), &Default::default())?;
//! let params = Params::default().resolve(&loaded.scene);
//! let w = record(&loaded, &params, "/tmp/lamp".as_ref(), &RecordOptions::default(), ())?;
//! println!("{} and {}", w.rrd.display(), w.mcap.display());
//! # Ok::<(), anyhow::Error>(())
//! ```

use super::direct::DirectWriter;
use super::live::Live;
use super::mcap::{Compression, McapRecorder};
use super::rrd::RrdRecorder;
use super::{CoverLevel, Detail, Outcome, RunInfo, background};
use crate::grouping::{self, Grouping, Limits, Observer, ResolvedParams, Stopped, Tee};
use crate::output::{Pending, with_ext};
use crate::scene::{Loaded, Scene};
use crate::stop::Stop;
use crate::wrap::cover::Cover;
use crate::wrap::cover::export::WrapperRecord;
use crate::wrap::cover::solve::{CoverLimit, solve};
use crate::wrap::{Sphere, SphereMethod, WrapperKind, Wrappers};
use anyhow::{Context, Result, anyhow, bail};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::thread::{Scope, ScopedJoinHandle};
use std::time::Instant;

/// How a recording is made and what it holds besides the scene and the grouping.
#[derive(Clone, Debug)]
pub struct RecordOptions {
    /// What to write.
    pub detail: Detail,
    /// Replace existing recordings.
    pub force: bool,
    /// Leave wall-clock timing out of the `.mcap` so identical runs give identical bytes.
    pub reproducible: bool,
    /// Limits on the grouping.
    pub limits: Limits,
    /// Stops the grouping when set (e.g. by Ctrl-C); the files are then set aside as
    /// incomplete.
    pub stop: Option<Arc<AtomicBool>>,
    /// Wrapper Trees drawn at every level.
    pub wrappers: Vec<WrapperKind>,
    /// A cover logged as one more level, within this limit, from these kinds (needs `detail`
    /// with levels).
    pub cover: Option<(CoverLimit, Vec<WrapperKind>)>,
    /// Write every level to the `.mcap`, not only down to the last cut of less than half
    /// leaves.
    pub all_levels: bool,
    /// Refine the finished tree with these parameters ([`crate::refine`]), recording each
    /// move; the levels are then the refined tree's.
    pub refine: Option<crate::refine::RefineParams>,
    /// How the `.mcap`'s chunks and attached scene are compressed.
    pub mcap_compression: Compression,
    /// Live streams that see the run as it is recorded (`--connect`, `--serve`, `--spawn`,
    /// `--foxglove-ws`), started with [`Live::start`]; the files are the same with or without.
    pub live: Live,
}

impl Default for RecordOptions {
    /// Full detail, sphere Wrapper Trees, no cover, no limits, existing files kept,
    /// `.mcap` chunks and attached scene compressed with Zstandard.
    fn default() -> Self {
        RecordOptions {
            detail: Detail::Full,
            force: false,
            reproducible: false,
            limits: Limits::default(),
            stop: None,
            wrappers: vec![WrapperKind::Sphere],
            cover: None,
            all_levels: false,
            refine: None,
            mcap_compression: Compression::default(),
            live: Live::default(),
        }
    }
}

/// Where a pair of recordings went, and the outcome of the run.
#[derive(Debug)]
pub struct Written {
    /// The `.rrd` path.
    pub rrd: PathBuf,
    /// The `.mcap` path.
    pub mcap: PathBuf,
    /// The grouping, unless stopped.
    pub grouping: Option<Grouping>,
    /// Why the grouping stopped before the root, if it did.
    pub stopped: Option<Stopped>,
    /// The limits the grouping ran under.
    pub limits: Limits,
    /// Grouping + recording wall time.
    pub seconds: f64,
}

/// Groups `loaded.scene` with `params` while both recorders listen, writing `PREFIX.rrd` and
/// `PREFIX.mcap`; `progress` sees every event too. The levels show the Wrapper Trees of
/// `opts.wrappers`, and the cover of `opts.cover`, computed after a finished grouping, as one
/// more level.
///
/// The files are committed when the grouping finishes, or set aside as `PREFIX.incomplete.*`
/// when `opts.stop` or a limit of `opts.limits` stops it (an existing recording is never
/// replaced by a partial one; the partial files say why they stopped). Err: an existing file
/// without `opts.force`, a missing directory, a cover without levels, a write error.
pub fn record<O: Observer>(
    loaded: &Loaded,
    params: &ResolvedParams,
    prefix: &Path,
    opts: &RecordOptions,
    progress: O,
) -> Result<Written> {
    let (scene, detail) = (&loaded.scene, opts.detail);
    if opts.cover.is_some() && !detail.levels() {
        bail!(
            "--cover-tolerance/--cover-budget need --detail levels or full (the cover is a level)"
        );
    }
    let rrd_file = Pending::create(&with_ext(prefix, ".rrd"), opts.force)?;
    let mcap_file = Pending::create(&with_ext(prefix, ".mcap"), opts.force)?;
    let info = RunInfo {
        scene,
        source: &loaded.source,
        params,
        detail,
    };
    let mcap_out = DirectWriter::open(mcap_file.path())
        .with_context(|| format!("{}: cannot open for writing", mcap_file.dest().display()))?;
    let never = AtomicBool::new(false);
    let stop = opts.stop.as_deref().unwrap_or(&never);
    let start = Instant::now();
    // Each recorder runs on its own thread: it starts its file while the grouping starts here,
    // consumes the events as they come, then writes its tail (levels, footer, sync) at the
    // same time as the other. The grouping thread only copies events into shared batches.
    let (rrd_done, mcap_done, grouping, stopped) = std::thread::scope(|s| -> Result<_> {
        let (mut events, workers) = background::fan_out(2);
        let [rrd_worker, mcap_worker]: [background::Worker; 2] = workers
            .try_into()
            .map_err(|_| anyhow!("two event channels"))?;
        let rrd_thread = spawn_rrd(s, rrd_worker, &rrd_file, &info, opts)?;
        let mcap_thread = spawn_mcap(s, mcap_worker, mcap_out, &info, opts)?;
        // The grouping starts without waiting for either recorder: a recorder that fails to
        // start drops its worker (the grouping stops sending to it) and its error is reported
        // after the grouping, like a write error during the run. Missing or unwritable
        // destinations were already refused by `Pending::create`.
        let result = group_and_refine(scene, params, opts, stop, &mut events, progress);
        events.close();
        let seconds = start.elapsed().as_secs_f64();
        let (grouping, stopped, merges, rounds) = match result {
            Ok(g) => {
                let m = g.tree.leaves() as u32 - 1;
                let r = g.rounds;
                (Some(g), None, m, r)
            }
            Err(s) => (None, Some(s), s.merges, s.rounds),
        };
        let token = opts.stop.clone().map(Stop::from).unwrap_or_default();
        let extras = Extras::build(scene, grouping.as_ref(), opts, &token)?;
        let outcome = extras.outcome(grouping.as_ref(), merges, rounds, seconds, stopped);
        let (rrd_done, mcap_done) =
            finish_both(rrd_thread, mcap_thread, &outcome, &rrd_file, &mcap_file);
        Ok((rrd_done, mcap_done, grouping, stopped))
    })?;
    rrd_done?;
    mcap_done?;
    let (rrd, mcap) = commit_both(rrd_file, mcap_file, prefix, grouping.is_some())?;
    Ok(Written {
        rrd,
        mcap,
        grouping,
        stopped,
        limits: opts.limits,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Starts the Rerun recorder on its own thread, writing `file` as `worker`'s events come.
fn spawn_rrd<'scope, 'a: 'scope>(
    s: &'scope Scope<'scope, '_>,
    worker: background::Worker,
    file: &'scope Pending,
    info: &'scope RunInfo<'a>,
    opts: &'scope RecordOptions,
) -> Result<ScopedJoinHandle<'scope, Result<RrdRecorder>>> {
    let (refined, live) = (opts.refine.is_some(), &opts.live);
    std::thread::Builder::new()
        .name("rrd-recorder".into())
        .spawn_scoped(s, move || {
            let (path, name) = (file.path(), file.dest());
            let mut rrd = RrdRecorder::with_live(path, name, info, refined, live)?;
            worker.run(&mut rrd);
            Ok(rrd)
        })
        .context("cannot start the Rerun recorder thread")
}

/// Starts the MCAP recorder on its own thread: the scene first, then `worker`'s events.
fn spawn_mcap<'scope, 'a: 'scope>(
    s: &'scope Scope<'scope, '_>,
    worker: background::Worker,
    out: DirectWriter,
    info: &'scope RunInfo<'a>,
    opts: &'scope RecordOptions,
) -> Result<ScopedJoinHandle<'scope, Result<McapRecorder<'a, DirectWriter>>>> {
    std::thread::Builder::new()
        .name("mcap-recorder".into())
        .spawn_scoped(s, move || {
            let live = opts.live.mcap_tee();
            let mut mcap = McapRecorder::start_live(out, info, opts.mcap_compression, live)?;
            mcap.set_reproducible(opts.reproducible);
            mcap.set_stop(opts.stop.clone().map(Stop::from).unwrap_or_default());
            mcap.set_all_levels(opts.all_levels);
            mcap.write_scene();
            worker.run(&mut mcap);
            Ok(mcap)
        })
        .context("cannot start the MCAP recorder thread")
}

/// The grouping, within `opts.limits` and `stop`, then the refinement if `opts.refine` asks:
/// its events follow the grouping's on the same channels, and the levels are the refined
/// tree's.
fn group_and_refine<O: Observer>(
    scene: &Scene,
    params: &ResolvedParams,
    opts: &RecordOptions,
    stop: &AtomicBool,
    events: &mut background::Background,
    progress: O,
) -> Result<Grouping, Stopped> {
    let result = grouping::group_within(
        scene,
        params,
        Tee(&mut *events, progress),
        &opts.limits.budget(Some(stop)),
    );
    match (result, &opts.refine) {
        (Ok(g), Some(rp)) => Ok(Grouping {
            tree: crate::refine::refine_owned(g.tree, rp, events).tree,
            ..g
        }),
        (result, _) => result,
    }
}

/// Waits for both recorders and writes their tails with `outcome` at the same time (the
/// `.mcap`'s on a thread of its own), each file synced after its tail.
fn finish_both(
    rrd_thread: ScopedJoinHandle<'_, Result<RrdRecorder>>,
    mcap_thread: ScopedJoinHandle<'_, Result<McapRecorder<'_, DirectWriter>>>,
    outcome: &Outcome<'_>,
    rrd_file: &Pending,
    mcap_file: &Pending,
) -> (Result<()>, Result<()>) {
    let (rrd_path, mcap_path) = (rrd_file.dest(), mcap_file.dest());
    std::thread::scope(|t| {
        let mcap_tail = std::thread::Builder::new()
            .name("mcap-tail".into())
            .spawn_scoped(t, || {
                let mcap = mcap_thread
                    .join()
                    .unwrap_or_else(|_| Err(anyhow!("the MCAP recorder failed")))
                    .with_context(|| mcap_path.display().to_string())?;
                mcap.finish(outcome)
                    .with_context(|| mcap_path.display().to_string())?;
                mcap_file.sync()
            });
        let rrd_done = rrd_thread
            .join()
            .unwrap_or_else(|_| bail!("{}: the Rerun recorder failed", rrd_path.display()))
            .and_then(|rrd| rrd.finish(outcome))
            .and_then(|()| rrd_file.sync());
        let mcap_done = match mcap_tail {
            Ok(h) => h
                .join()
                .unwrap_or_else(|_| bail!("{}: the MCAP recorder failed", mcap_path.display())),
            Err(e) => Err(anyhow!(
                "{}: cannot start a thread: {e}",
                mcap_path.display()
            )),
        };
        (rrd_done, mcap_done)
    })
}

/// Moves both files into place when the grouping `finished`, else sets them aside as
/// `PREFIX.incomplete.*`; returns where they went.
fn commit_both(
    rrd_file: Pending,
    mcap_file: Pending,
    prefix: &Path,
    finished: bool,
) -> Result<(PathBuf, PathBuf)> {
    if finished {
        return Ok((rrd_file.commit()?, mcap_file.commit()?));
    }
    let r = with_ext(prefix, ".incomplete.rrd");
    let m = with_ext(prefix, ".incomplete.mcap");
    Ok((
        rrd_file.commit_to(Some(&r))?,
        mcap_file.commit_to(Some(&m))?,
    ))
}

/// What the levels show besides the tree, built after the grouping: the Wrapper Trees and the
/// cover.
struct Extras {
    wrappers: Option<Wrappers>,
    /// Spheres travel in `Outcome::spheres`; empty = levels without spheres.
    spheres: Option<Vec<Sphere>>,
    cover: Option<(Cover, Vec<WrapperRecord>)>,
    budget: Option<usize>,
}

impl Extras {
    /// The extras of a finished grouping; a stop requested meanwhile ends the recording
    /// ([`Interrupted`](crate::stop::Interrupted), no files written).
    fn build(
        scene: &Scene,
        grouping: Option<&Grouping>,
        opts: &RecordOptions,
        stop: &Stop,
    ) -> Result<Extras> {
        let mut wrappers = match (grouping, opts.detail.levels()) {
            (Some(g), true) => Some(Wrappers::build_until(
                &g.tree,
                scene,
                &opts.wrappers,
                SphereMethod::AabbCenter,
                stop,
            )?),
            _ => None,
        };
        let spheres = wrappers
            .as_mut()
            .map(|w| w.spheres.take().unwrap_or_default());
        let cover = match (grouping, &opts.cover) {
            (Some(g), Some((limit, kinds))) => {
                let s = solve(&g.tree, scene, *limit, kinds, stop)?;
                Some((s.cover, s.records))
            }
            _ => None,
        };
        let budget = match opts.cover {
            Some((CoverLimit::Budget(k), _)) => Some(k),
            _ => None,
        };
        Ok(Extras {
            wrappers,
            spheres,
            cover,
            budget,
        })
    }

    fn outcome<'a>(
        &'a self,
        grouping: Option<&'a Grouping>,
        merges: u32,
        rounds: u32,
        seconds: f64,
        stopped: Option<Stopped>,
    ) -> Outcome<'a> {
        Outcome {
            grouping,
            spheres: self.spheres.as_deref(),
            wrappers: self.wrappers.as_ref(),
            cover: self.cover.as_ref().map(|(cover, wrappers)| CoverLevel {
                cover,
                wrappers,
                budget: self.budget,
            }),
            merges,
            rounds,
            seconds,
            stopped,
        }
    }
}
