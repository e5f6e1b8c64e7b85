//! Stress runs (`wraptree stress`, `docs/stability.md`): every builder on every pathological
//! scene ([`pathological`]), each case under a time budget, and sweeps of parallel spaghetti
//! (the §2.3 worst case) with and without `--split-aspect` (the §4 mitigation).
//!
//! Per case: whether the build finished within the budget, whether the tree is valid (every leaf
//! once under the root, boxes nested, depths consistent; for Wrapper Trees every vertex inside
//! its node's wrapper), time, depth, and for groupings k = eligible pairs per body (the paper's
//! k of §2.3) and candidates examined per body.
//!
//! A case runs on its own thread. Groupings get a stop flag set when the budget runs out or a
//! [`Stop`] is requested (they return within one merge or scan block); other builders cannot
//! be stopped, so a case past its budget is a timeout and its thread is left to finish in the
//! background. A requested [`Stop`] ends the run after the case at hand, without a report.
//! The sweeps run
//! against the aspect ratio at fixed N (`spaghetti.{svg,png}`) and against N at aspect 64
//! (`spaghetti-n.{svg,png}`); their rows are also in `stress.csv`.

use super::report::{StressRow as Row, stress_csv, stress_sweep_chart};
use crate::grouping::{self, Grouping, PSet, Params, SubsetTree};
use crate::output::write_atomic;
use crate::peers;
use crate::scene::pathological::{self, Layout};
use crate::scene::{Scene, split};
use crate::stop::{Interrupted, Stop};
use crate::wrap::{
    HULL_TOL_REL, SphereMethod, WrapperTree, containment_excess, hull_tree, obb_tree, sphere_tree,
};
use anyhow::{Result, bail};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, mpsc};
use std::time::{Duration, Instant};

/// How a stress run is made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StressOptions {
    /// Small scenes (300 primitives, 10 n-gons) and three aspect ratios: seconds, not minutes.
    pub quick: bool,
    /// Time budget per case.
    pub budget: Duration,
    /// Aspect limit R of the split runs (`--split-aspect R`), ≥ [`split::MIN_ASPECT_LIMIT`].
    pub split: f64,
}

impl Default for StressOptions {
    /// The full run: 5 s per case, split at aspect 8.
    fn default() -> Self {
        StressOptions {
            quick: false,
            budget: Duration::from_secs(5),
            split: 8.0,
        }
    }
}

/// What a stress run is about to measure, for progress reports.
#[derive(Clone, Copy, Debug)]
pub enum Step<'a> {
    /// Every builder on this pathological scene.
    Scene(&'a Scene),
    /// The spaghetti sweep's grouping of this scene, as it is and split.
    Sweep(&'a Scene),
}

/// How a case on a thread ended.
enum Outcome<T> {
    Done(T, f64),
    Timeout,
    Panicked,
}

/// Runs `f` on a thread; `Timeout` if it takes longer than `budget` (after setting `stop`, if
/// given, and allowing the run another second to notice it). A request of `halt` counts as the
/// budget running out; the caller then checks `halt` itself.
fn on_thread<T: Send + 'static>(
    budget: Duration,
    halt: &Stop,
    stop: Option<Arc<AtomicBool>>,
    f: impl FnOnce() -> T + Send + 'static,
) -> Outcome<T> {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let t = Instant::now();
        let r = f();
        let _ = tx.send((r, t.elapsed().as_secs_f64()));
    });
    let deadline = Instant::now() + budget;
    let first = loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left.min(Duration::from_millis(100))) {
            Err(mpsc::RecvTimeoutError::Timeout) if !left.is_zero() && !halt.is_requested() => {}
            r => break r,
        }
    };
    let got = match first {
        Err(mpsc::RecvTimeoutError::Timeout) => match &stop {
            Some(s) => {
                s.store(true, Ordering::Relaxed);
                rx.recv_timeout(Duration::from_secs(1))
            }
            None => Err(mpsc::RecvTimeoutError::Timeout),
        },
        r => r,
    };
    match got {
        Ok((r, s)) => Outcome::Done(r, s),
        Err(mpsc::RecvTimeoutError::Timeout) => Outcome::Timeout,
        Err(mpsc::RecvTimeoutError::Disconnected) => Outcome::Panicked,
    }
}

/// Checks a Subset Tree over `scene` ([`SubsetTree::validate`]); returns its depth or the
/// first violation.
fn check_tree(scene: &Scene, t: &SubsetTree) -> Result<u32, String> {
    t.validate(scene).map(|()| t.depth_max())
}

/// A row for a grouping of `scene` with `pset`, and the grouping if it finished.
fn group_case(
    scene: &Arc<Scene>,
    pset: PSet,
    split_r: Option<f64>,
    budget: Duration,
    halt: &Stop,
) -> (Row, Option<Grouping>) {
    let name = match pset {
        PSet::Aabb => "group-aabb",
        PSet::Hull => "group-hull",
    };
    let mut row = Row {
        scene: scene.name.clone(),
        n: scene.len(),
        method: name.into(),
        split_r,
        ..Row::default()
    };
    let params = Params {
        pset,
        ..Params::default()
    }
    .resolve(scene);
    let stop = Arc::new(AtomicBool::new(false));
    let (s, flag) = (Arc::clone(scene), Arc::clone(&stop));
    let out = on_thread(budget, halt, Some(stop), move || {
        grouping::group_until(&s, &params, (), &flag)
    });
    let n = scene.len() as f64;
    match out {
        Outcome::Done(Ok(g), secs) => {
            row.finished = true;
            row.seconds = Some(secs);
            row.k_eligible = Some(g.stats.eligible_pairs as f64 / n);
            row.k_candidates = Some(g.stats.candidates as f64 / n);
            validity(&mut row, check_tree(scene, &g.tree));
            return (row, Some(g));
        }
        Outcome::Done(Err(stopped), _) => {
            row.note = format!("over budget: stopped after {} merges", stopped.merges);
        }
        Outcome::Timeout => row.note = "over budget (did not stop)".into(),
        Outcome::Panicked => row.note = "panicked".into(),
    }
    (row, None)
}

/// Fills `valid`, `depth` and `note` from a tree check.
fn validity(row: &mut Row, check: Result<u32, String>) {
    match check {
        Ok(d) => {
            row.valid = Some(true);
            row.depth = Some(d);
        }
        Err(e) => {
            row.valid = Some(false);
            row.note = e;
        }
    }
}

/// The Wrapper Trees built on `tree`: which, and how to build each.
const WRAPPERS: [&str; 6] = [
    "sphere-merged",
    "sphere-aabb-center",
    "sphere-ritter",
    "sphere-minimum",
    "hull",
    "obb",
];

/// Builds wrapper `kind` over `tree` and returns how far the worst vertex lies outside its
/// node's wrapper beyond the tolerance (≤ 0: every vertex inside). Tolerances: 1e-9 × scene
/// diagonal plus 16 ulps of the largest coordinate for spheres and OBBs (`f64` throughout),
/// plus [`HULL_TOL_REL`] × the node's box diameter for hulls (the rounding of their face planes).
fn wrapper_excess(kind: &str, tree: &SubsetTree, scene: &Scene) -> f64 {
    let far = scene
        .points
        .iter()
        .flat_map(|p| p.iter().map(|c| c.abs()))
        .fold(0.0, f64::max);
    let base = 1e-9 * scene.aabb().diameter() + 16.0 * f64::EPSILON * far;
    let sphere = |m| {
        let s = sphere_tree(tree, scene, m);
        containment_excess(tree, scene, WrapperTree::Spheres(&s))
    };
    let (ex, hull) = match kind {
        "sphere-merged" => (sphere(SphereMethod::Merged), false),
        "sphere-aabb-center" => (sphere(SphereMethod::AabbCenter), false),
        "sphere-ritter" => (sphere(SphereMethod::Ritter), false),
        "sphere-minimum" => (sphere(SphereMethod::Minimum), false),
        "hull" => {
            let h = hull_tree(tree, scene);
            (
                containment_excess(tree, scene, WrapperTree::Hulls(&h)),
                true,
            )
        }
        _ => {
            let o = obb_tree(tree, scene, None);
            (
                containment_excess(tree, scene, WrapperTree::Obbs(&o)),
                false,
            )
        }
    };
    ex.iter()
        .enumerate()
        .map(|(x, e)| {
            let tol = base
                + if hull {
                    HULL_TOL_REL * tree.aabb[x].diameter()
                } else {
                    0.0
                };
            e - tol
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// Every case on one scene: both groupings, the split grouping, the wrappers on the AABB
/// grouping's tree and the peers.
fn scene_cases(scene: Scene, r: f64, budget: Duration, halt: &Stop) -> Result<Vec<Row>> {
    let scene = Arc::new(scene);
    let mut rows = Vec::new();
    let (row, g) = group_case(&scene, PSet::Aabb, None, budget, halt);
    halt.check()?;
    rows.push(row);
    rows.push(group_case(&scene, PSet::Hull, None, budget, halt).0);
    halt.check()?;
    let (s, _) = split::split_aspect(&scene, r);
    rows.push(group_case(&Arc::new(s), PSet::Aabb, Some(r), budget, halt).0);
    halt.check()?;
    if let Some(g) = g {
        let tree = Arc::new(g.tree);
        for kind in WRAPPERS {
            let (t, s) = (Arc::clone(&tree), Arc::clone(&scene));
            let mut row = Row {
                scene: scene.name.clone(),
                n: scene.len(),
                method: format!("wrap-{kind}"),
                depth: Some(tree.depth_max()),
                ..Row::default()
            };
            let out = on_thread(budget, halt, None, move || wrapper_excess(kind, &t, &s));
            halt.check()?;
            match out {
                Outcome::Done(ex, secs) => {
                    row.finished = true;
                    row.seconds = Some(secs);
                    row.valid = Some(ex <= 0.0);
                    if ex > 0.0 {
                        row.note = format!("a vertex lies {ex:.3e} outside beyond tolerance");
                    }
                }
                Outcome::Timeout => row.note = "over budget".into(),
                Outcome::Panicked => row.note = "panicked".into(),
            }
            rows.push(row);
        }
    }
    for m in peers::Method::ALL.into_iter().filter(|m| !m.is_grouping()) {
        let s = Arc::clone(&scene);
        let mut row = Row {
            scene: scene.name.clone(),
            n: scene.len(),
            method: m.name().into(),
            ..Row::default()
        };
        let h = halt.clone();
        let out = on_thread(budget, halt, None, move || {
            peers::build_until(m, &s, &Params::default(), &h)
        });
        halt.check()?;
        match out {
            Outcome::Done(Ok(b), _) => {
                row.finished = true;
                row.seconds = Some(b.seconds);
                validity(&mut row, check_tree(&scene, &b.tree));
            }
            Outcome::Done(Err(e), _) => row.note = e,
            Outcome::Timeout => row.note = "over budget".into(),
            Outcome::Panicked => row.note = "panicked".into(),
        }
        rows.push(row);
    }
    Ok(rows)
}

/// Groups every `(x, scene)` with the AABB p-set, as it is and split at aspect `r`.
fn sweep(
    cases: Vec<(f64, Scene)>,
    r: f64,
    budget: Duration,
    halt: &Stop,
    progress: &mut dyn FnMut(Step<'_>),
) -> Result<Vec<(f64, Row)>, Interrupted> {
    let mut out = Vec::new();
    for (x, scene) in cases {
        progress(Step::Sweep(&scene));
        let (split, _) = split::split_aspect(&scene, r);
        for (sc, r) in [(scene, None), (split, Some(r))] {
            out.push((x, group_case(&Arc::new(sc), PSet::Aabb, r, budget, halt).0));
            halt.check()?;
        }
    }
    Ok(out)
}

/// The files `stress` writes into its output directory.
pub const OUTPUTS: [&str; 5] = [
    "stress.csv",
    "spaghetti.svg",
    "spaghetti.png",
    "spaghetti-n.svg",
    "spaghetti-n.png",
];

/// Fails if a file of [`OUTPUTS`] exists in `dir` and `force` is false (checked before a run,
/// so that it does not end in that error).
pub fn check_outputs(dir: &Path, force: bool) -> Result<()> {
    for name in OUTPUTS {
        let p = dir.join(name);
        if !force && p.exists() {
            bail!(
                "{}: already exists (use --force to replace it)",
                p.display()
            );
        }
    }
    Ok(())
}

/// The rows of a stress run and its two spaghetti sweeps.
#[derive(Clone, Debug)]
pub struct StressReport {
    /// Every case (the sweeps' rows included, last).
    pub rows: Vec<Row>,
    /// The sweep over the strand aspect ratio at fixed N: (aspect, row).
    pub by_aspect: Vec<(f64, Row)>,
    /// The sweep over N at aspect 64: (N, row).
    pub by_n: Vec<(f64, Row)>,
    /// Strands in the aspect sweep.
    pub n: usize,
    /// The split's aspect limit R.
    pub split: f64,
}

/// Runs every builder on every pathological scene and both spaghetti sweeps; `progress` hears
/// of each scene before it runs. Err: a budget that is not a finite duration > 0 or a split
/// limit below [`split::MIN_ASPECT_LIMIT`] (named as the flags `--budget`, `--split`), or
/// [`Interrupted`] once `halt` is requested (after the case at hand).
pub fn run(
    opts: &StressOptions,
    halt: &Stop,
    progress: &mut dyn FnMut(Step<'_>),
) -> Result<StressReport> {
    if opts.budget.is_zero() {
        bail!("--budget must be a finite number > 0, got 0");
    }
    if opts.split.is_nan() || opts.split < split::MIN_ASPECT_LIMIT {
        bail!("--split must be a number ≥ 2, got {}", opts.split);
    }
    let budget = opts.budget;
    let (n, aspects, sizes): (usize, &[f64], &[usize]) = if opts.quick {
        (300, &[1.0, 16.0, 256.0], &[100, 200, 400])
    } else {
        (
            2_000,
            &[1.0, 4.0, 16.0, 64.0, 256.0, 1024.0],
            &[500, 1_000, 2_000, 4_000, 8_000],
        )
    };
    let mut rows = Vec::new();
    for kind in pathological::KINDS {
        // 1,024-vertex polygons: hulling them is slow (their hull Wrapper Tree can outrun the
        // budget, the only default case that does).
        let n = if kind == "ngons" { n / 30 } else { n };
        let scene = pathological::by_name(kind, Some(n), 1).expect("a known kind");
        progress(Step::Scene(&scene));
        rows.extend(scene_cases(scene, opts.split, budget, halt)?);
    }
    let parallel = |n, a| pathological::spaghetti(n, a, Layout::Parallel, 1);
    let by_aspect = sweep(
        aspects.iter().map(|&a| (a, parallel(n, a))).collect(),
        opts.split,
        budget,
        halt,
        progress,
    )?;
    let by_n = sweep(
        sizes
            .iter()
            .map(|&m| (m as f64, parallel(m, 64.0)))
            .collect(),
        opts.split,
        budget,
        halt,
        progress,
    )?;
    rows.extend(by_aspect.iter().chain(&by_n).map(|(_, r)| r.clone()));
    Ok(StressReport {
        rows,
        by_aspect,
        by_n,
        n,
        split: opts.split,
    })
}

impl StressReport {
    /// The files of [`OUTPUTS`] with their contents: `stress.csv` and the two sweep charts as
    /// SVG and PNG.
    pub fn files(&self) -> Result<Vec<(String, Vec<u8>)>> {
        let charts = [
            (
                "spaghetti",
                stress_sweep_chart(
                    &self.by_aspect,
                    format!("Box of spaghetti: {} parallel strands, AABB p-set", self.n),
                    "strand aspect ratio (length / width)",
                    self.split,
                ),
            ),
            (
                "spaghetti-n",
                stress_sweep_chart(
                    &self.by_n,
                    "Box of spaghetti: parallel strands of aspect 64, AABB p-set".into(),
                    "strands N",
                    self.split,
                ),
            ),
        ];
        let mut files = vec![("stress.csv".to_string(), stress_csv(&self.rows)?)];
        for (name, chart) in charts {
            let svg = chart.to_svg(900, 600).map_err(anyhow::Error::msg)?;
            let png = crate::render::svg_to_png(&svg).map_err(anyhow::Error::msg)?;
            files.push((format!("{name}.svg"), svg.into_bytes()));
            files.push((format!("{name}.png"), png));
        }
        Ok(files)
    }

    /// Writes [`StressReport::files`] into `dir`, each atomically; returns their paths.
    pub fn write(&self, dir: &Path, force: bool) -> Result<Vec<PathBuf>> {
        let mut written = Vec::new();
        for (name, bytes) in self.files()? {
            let p = dir.join(name);
            write_atomic(&p, &bytes, force)?;
            written.push(p);
        }
        Ok(written)
    }
}
