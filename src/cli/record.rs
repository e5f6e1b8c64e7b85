//! `wraptree record`: group a scene step by step and write `PREFIX.rrd` and `PREFIX.mcap`.

use super::cover::{Tolerance, parse_tolerance};
use super::group::{BudgetArgs, Progress};
use super::{GroupArgs, SceneArgs};
use anyhow::{Context, Result, anyhow, bail};
use clap::Args;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;
use wraptree::grouping::SubsetTree;
use wraptree::grouping::{self, Grouping, ResolvedParams, Stopped, Tee};
use wraptree::record::mcap::McapRecorder;
use wraptree::record::output::Pending;
use wraptree::record::rrd::RrdRecorder;
use wraptree::record::{CoverLevel, Detail, Outcome, RunInfo, background};
use wraptree::scene::{Scene, SceneSource};
use wraptree::wrap::cover::export::{self, WrapperRecord};
use wraptree::wrap::cover::{Cover, Fits};
use wraptree::wrap::{DEFAULT_SAMPLES, Sphere, SphereMethod, WrapperKind, Wrappers};

/// Arguments of `wraptree record`.
#[derive(Args, Debug)]
pub struct RecordCmd {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    group: GroupArgs,
    #[command(flatten)]
    limits: BudgetArgs,
    /// Output prefix: writes PREFIX.rrd and PREFIX.mcap [default: recordings/<scene stem>].
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// What to write: levels, merges, or full.
    #[arg(long, value_enum, default_value_t = Detail::Full)]
    detail: Detail,
    /// Replace existing recordings.
    #[arg(long)]
    force: bool,
    /// Leave wall-clock timing out of the .mcap so identical runs give identical bytes.
    #[arg(long)]
    reproducible: bool,
    /// Write every level to the .mcap (default: from the root down to the first level whose cut
    /// is half leaves or more; the .rrd always has every level).
    #[arg(long)]
    all_levels: bool,
    /// Wrapper Trees logged with the levels, comma-separated: sphere, hull, box (aabb), obb.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "sphere")]
    wrapper: Vec<WrapperKind>,
    /// Also log the cover within this error (as `cover --tolerance`: a length, or P% of the
    /// scene diagonal) as one more level.
    #[arg(long, value_parser = parse_tolerance, allow_negative_numbers = true, conflicts_with = "cover_budget")]
    cover_tolerance: Option<Tolerance>,
    /// Also log the best cover with at most K wrappers as one more level.
    #[arg(long, value_name = "K")]
    cover_budget: Option<usize>,
    /// Wrapper kinds the cover chooses from, comma-separated: sphere, box (or aabb), obb, hull.
    #[arg(long, default_value = "sphere,box,hull", value_delimiter = ',', value_parser = WrapperKind::parse)]
    cover_kinds: Vec<WrapperKind>,
}

/// How a recording is made, besides what it holds.
#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    /// Replace existing recordings.
    pub force: bool,
    /// Leave wall-clock timing out of the `.mcap`.
    pub reproducible: bool,
    /// Write every level to the `.mcap`, not only down to the first cut of half leaves.
    pub all_levels: bool,
    /// Limits on the grouping (Ctrl-C/SIGTERM always stop it).
    pub limits: BudgetArgs,
}

/// How the logged cover is bounded.
#[derive(Clone, Copy, Debug)]
pub enum CoverLimit {
    /// Largest error per wrapper.
    Tolerance(Tolerance),
    /// Largest number of wrappers.
    Budget(usize),
}

/// What is logged with the levels besides the scene and the grouping.
#[derive(Clone, Copy, Debug)]
pub struct Logged<'a> {
    /// Wrapper Trees drawn at every level.
    pub kinds: &'a [WrapperKind],
    /// The cover logged as one more level, from these kinds, when asked for.
    pub cover: Option<(CoverLimit, &'a [WrapperKind])>,
}

/// The cover of `tree` within `limit` from `kinds` (as `wraptree cover` computes it), with its
/// wrappers' geometry.
fn compute_cover(
    tree: &SubsetTree,
    scene: &Scene,
    limit: CoverLimit,
    kinds: &[WrapperKind],
) -> Result<(Cover, Vec<WrapperRecord>)> {
    let mut build = kinds.to_vec();
    if !build.contains(&WrapperKind::Hull) {
        build.push(WrapperKind::Hull);
    }
    let mut wrappers = Wrappers::build(tree, scene, &build, SphereMethod::Minimum);
    let hulls = if kinds.contains(&WrapperKind::Hull) {
        None
    } else {
        wrappers.hulls.take()
    };
    let fits = Fits::measure(tree, scene, &wrappers, hulls.as_deref(), DEFAULT_SAMPLES);
    let cover = match limit {
        CoverLimit::Tolerance(t) => fits.cover_tolerance(tree, t.length(scene.aabb().diameter())),
        CoverLimit::Budget(k) => fits.cover_budget(tree, k).map_err(anyhow::Error::msg)?,
    };
    let records = export::records(&cover, tree, scene, &wrappers);
    Ok((cover, records))
}

/// Where a pair of recordings goes, and the outcome of writing it.
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
    pub limits: BudgetArgs,
    /// Grouping + recording wall time.
    pub seconds: f64,
}

/// The output prefix: `given`, or `recordings/<stem of scene_file><suffix>` (creating
/// `recordings/`, the one directory wraptree makes itself).
pub fn output_prefix(given: Option<&Path>, scene_file: &str, suffix: &str) -> Result<PathBuf> {
    if let Some(p) = given {
        return Ok(p.to_path_buf());
    }
    let stem = Path::new(scene_file)
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "scene".into());
    std::fs::create_dir_all("recordings")
        .context("recordings: cannot create the default output directory")?;
    Ok(PathBuf::from("recordings").join(format!("{stem}{suffix}")))
}

/// `prefix` with `ext` appended (`recordings/lamp` + `.rrd`).
pub fn with_ext(prefix: &Path, ext: &str) -> PathBuf {
    let mut s = prefix.as_os_str().to_owned();
    s.push(ext);
    PathBuf::from(s)
}

/// [`record_with`] logging sphere Wrapper Trees, stopped only by Ctrl-C/SIGTERM.
pub fn record(
    scene: &Scene,
    source: &SceneSource,
    params: &ResolvedParams,
    detail: Detail,
    prefix: &Path,
    force: bool,
    reproducible: bool,
) -> Result<Written> {
    let kinds = [WrapperKind::Sphere];
    record_with(
        scene,
        source,
        params,
        detail,
        prefix,
        Options {
            force,
            reproducible,
            all_levels: false,
            limits: BudgetArgs::default(),
        },
        Logged {
            kinds: &kinds,
            cover: None,
        },
    )
}

/// Groups `scene` while both recorders listen, logging the levels with the Wrapper Trees of
/// `kinds`; commits the files when complete, or sets them aside as `PREFIX.incomplete.*` when
/// stopped by Ctrl-C/SIGTERM or a limit of `limits` (an existing recording is never replaced by
/// a partial one; the partial files say why they stopped). A cover in `logged` is computed after a finished grouping
/// and logged as one more level (it needs `detail` with levels).
pub fn record_with(
    scene: &Scene,
    source: &SceneSource,
    params: &ResolvedParams,
    detail: Detail,
    prefix: &Path,
    opts: Options,
    logged: Logged<'_>,
) -> Result<Written> {
    let Options {
        force,
        reproducible,
        all_levels,
        limits,
    } = opts;
    if logged.cover.is_some() && !detail.levels() {
        bail!(
            "--cover-tolerance/--cover-budget need --detail levels or full (the cover is a level)"
        );
    }
    let (rrd_path, mcap_path) = (with_ext(prefix, ".rrd"), with_ext(prefix, ".mcap"));
    let rrd_file = Pending::create(&rrd_path, force)?;
    let mcap_file = Pending::create(&mcap_path, force)?;
    let info = RunInfo {
        scene,
        source,
        params,
        detail,
    };
    let mcap_out = mcap_file.file()?;
    let stop = stop_flag();
    let start = Instant::now();
    let progress = Progress::for_merges(scene.len() as u64);
    // Each recorder runs on its own thread: it starts its file while the grouping starts here,
    // consumes the events as they come, then writes its tail (levels, footer, sync) at the
    // same time as the other. The grouping thread only copies events into shared batches.
    let (rrd_done, mcap_done, grouping, stopped) = std::thread::scope(|s| -> Result<_> {
        let (mut events, workers) = background::fan_out(2);
        let [rrd_worker, mcap_worker]: [background::Worker; 2] = workers
            .try_into()
            .map_err(|_| anyhow!("two event channels"))?;
        let info = &info;
        let (rrd_tmp, rrd_name) = (rrd_file.path(), rrd_path.as_path());
        let rrd_thread = std::thread::Builder::new()
            .name("rrd-recorder".into())
            .spawn_scoped(s, move || {
                let mut rrd = RrdRecorder::with_name(rrd_tmp, rrd_name, info)?;
                rrd_worker.run(&mut rrd);
                Ok::<_, anyhow::Error>(rrd)
            })
            .context("cannot start the Rerun recorder thread")?;
        let mcap_thread = std::thread::Builder::new()
            .name("mcap-recorder".into())
            .spawn_scoped(s, move || {
                let writer = std::io::BufWriter::new(mcap_out);
                let mut mcap = McapRecorder::start(writer, info)?;
                mcap.set_reproducible(reproducible);
                mcap.set_all_levels(all_levels);
                mcap.write_scene();
                mcap_worker.run(&mut mcap);
                Ok::<_, anyhow::Error>(mcap)
            })
            .context("cannot start the MCAP recorder thread")?;
        // The grouping starts without waiting for either recorder: a recorder that fails to
        // start drops its worker (the grouping stops sending to it) and its error is reported
        // after the grouping, like a write error during the run. Missing or unwritable
        // destinations were already refused by `Pending::create`.
        let result = grouping::group_within(
            scene,
            params,
            Tee(&mut events, progress),
            &limits.budget(Some(&stop)),
        );
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
        let extras = Extras::build(scene, grouping.as_ref(), detail, &logged)?;
        let outcome = extras.outcome(grouping.as_ref(), merges, rounds, seconds, stopped);
        let (rrd_done, mcap_done) = std::thread::scope(|t| {
            let mcap_tail = std::thread::Builder::new()
                .name("mcap-tail".into())
                .spawn_scoped(t, || {
                    let mcap = mcap_thread
                        .join()
                        .unwrap_or_else(|_| Err(anyhow!("the MCAP recorder failed")))
                        .with_context(|| mcap_path.display().to_string())?;
                    mcap.finish(&outcome)
                        .with_context(|| mcap_path.display().to_string())?;
                    mcap_file.sync()
                });
            let rrd_done = rrd_thread
                .join()
                .unwrap_or_else(|_| bail!("{}: the Rerun recorder failed", rrd_path.display()))
                .and_then(|rrd| rrd.finish(&outcome))
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
        });
        Ok((rrd_done, mcap_done, grouping, stopped))
    })?;
    rrd_done?;
    mcap_done?;
    let (rrd_dest, mcap_dest) = if grouping.is_some() {
        (rrd_file.commit()?, mcap_file.commit()?)
    } else {
        let r = with_ext(prefix, ".incomplete.rrd");
        let m = with_ext(prefix, ".incomplete.mcap");
        (
            rrd_file.commit_to(Some(&r))?,
            mcap_file.commit_to(Some(&m))?,
        )
    };
    Ok(Written {
        rrd: rrd_dest,
        mcap: mcap_dest,
        grouping,
        stopped,
        limits,
        seconds: start.elapsed().as_secs_f64(),
    })
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
    fn build(
        scene: &Scene,
        grouping: Option<&Grouping>,
        detail: Detail,
        logged: &Logged<'_>,
    ) -> Result<Extras> {
        let mut wrappers = match (grouping, detail.levels()) {
            (Some(g), true) => Some(Wrappers::build(
                &g.tree,
                scene,
                logged.kinds,
                SphereMethod::AabbCenter,
            )),
            _ => None,
        };
        let spheres = wrappers
            .as_mut()
            .map(|w| w.spheres.take().unwrap_or_default());
        let cover = match (grouping, logged.cover) {
            (Some(g), Some((limit, kinds))) => Some(compute_cover(&g.tree, scene, limit, kinds)?),
            _ => None,
        };
        let budget = match logged.cover {
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

/// Success for a finished grouping, else the stop's exit code (3 for a limit, 130 for
/// Ctrl-C/SIGTERM).
pub fn exit_code(w: &Written) -> ExitCode {
    match (&w.grouping, &w.stopped) {
        (Some(_), _) => ExitCode::SUCCESS,
        (None, Some(s)) => BudgetArgs::exit_code(s.reason),
        (None, None) => ExitCode::from(super::group::EXIT_INTERRUPTED),
    }
}

/// A flag set by the first Ctrl-C or SIGTERM (installed once per process).
pub fn stop_flag() -> Arc<AtomicBool> {
    static FLAG: std::sync::OnceLock<Arc<AtomicBool>> = std::sync::OnceLock::new();
    FLAG.get_or_init(|| {
        let f = Arc::new(AtomicBool::new(false));
        let g = f.clone();
        let _ = ctrlc::set_handler(move || g.store(true, Ordering::Relaxed));
        f
    })
    .clone()
}

/// Prints what was written.
pub fn report(w: &Written, scene: &Scene) {
    let size = |p: &Path| {
        std::fs::metadata(p)
            .map(|m| m.len() as f64 / 1e6)
            .unwrap_or(0.0)
    };
    match &w.grouping {
        Some(g) => println!(
            "{}: {} primitives, {} rounds, depth {} (mean {:.2}); recorded in {:.3} s",
            scene.name,
            scene.len(),
            g.rounds,
            g.tree.depth_max(),
            g.tree.depth_mean(),
            w.seconds
        ),
        None => {
            let why = match &w.stopped {
                Some(s) => w.limits.message(s, scene.len()),
                None => "grouping stopped".to_string(),
            };
            eprintln!(
                "incomplete: {}: {why}; wrote what was recorded, marked incomplete",
                scene.name
            );
        }
    }
    println!("  {} ({:.2} MB)", w.rrd.display(), size(&w.rrd));
    println!("  {} ({:.2} MB)", w.mcap.display(), size(&w.mcap));
}

impl RecordCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        // Installed before loading so an early Ctrl-C still ends in readable, incomplete files.
        stop_flag();
        self.limits.check()?;
        if self.cover_budget == Some(0) {
            bail!("--cover-budget must be ≥ 1 (a cover needs at least one wrapper)");
        }
        let limit = match (self.cover_tolerance, self.cover_budget) {
            (Some(t), _) => Some(CoverLimit::Tolerance(t)),
            (None, Some(k)) => Some(CoverLimit::Budget(k)),
            (None, None) => None,
        };
        if limit.is_some() && !self.detail.levels() {
            bail!(
                "--cover-tolerance/--cover-budget need --detail levels or full (the cover is a level)"
            );
        }
        let loaded = self.scene.load()?;
        let params = self.group.params()?.resolve(&loaded.scene);
        let prefix = output_prefix(self.output.as_deref(), &loaded.source.file_name, "")?;
        let w = record_with(
            &loaded.scene,
            &loaded.source,
            &params,
            self.detail,
            &prefix,
            Options {
                force: self.force,
                reproducible: self.reproducible,
                all_levels: self.all_levels,
                limits: self.limits,
            },
            Logged {
                kinds: &self.wrapper,
                cover: limit.map(|l| (l, self.cover_kinds.as_slice())),
            },
        )?;
        report(&w, &loaded.scene);
        Ok(exit_code(&w))
    }
}
