//! One scene, every hierarchy × wrapper: build times, quality, tightness and query cost in rows
//! ready for a CSV and charts (`wraptree bench SCENE… -o DIR`).
//!
//! The hierarchies are built in rounds of every [`Method`] in turn, the fastest build of each
//! kept ([`super::timing`]), then each [`Wrapper`] is built on each and timed. Rows carry:
//! - the hierarchy's [`Quality`] (same for every wrapper on it);
//! - the wrapper's tightness: mean over interior nodes of the sampled surface-to-geometry
//!   distance divided by the node box's diagonal, estimated from at most
//!   [`Options::tightness_nodes`] nodes per depth ([`crate::wrap::DepthSample`]), skipped above
//!   [`Options::tightness_max_n`] primitives;
//! - for box and sphere wrappers, the cost of the standard query workload
//!   ([`crate::query::Workload::standard`]) with those wrappers as bounding volumes.

use super::timing::fastest_builds;
use super::{Quality, quality};
use crate::grouping::{Params, SubsetTree};
use crate::peers::{self, Method};
use crate::query::{self, Bv, QueryCost, Workload};
use crate::scene::Scene;
use crate::stop::{Interrupted, Stop};
use crate::wrap::{
    DepthSample, Hull, MAX_VISITS, NODES_PER_DEPTH, Sphere, SphereMethod, WrapperTree,
    hull_tree_until, nodes_tightness, obb_tree_until, sphere_tree_until,
};
use anyhow::Result;
use std::time::Instant;

/// A wrapper built on a hierarchy for the comparison.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Wrapper {
    /// The hierarchy's own boxes (built with it: no extra time).
    Box,
    /// Spheres with the given method.
    Sphere(SphereMethod),
    /// Oriented boxes by PCA.
    Obb,
    /// Convex hulls.
    Hull,
}

impl Wrapper {
    /// What a bench builds by default: a box, the smallest sphere, an oriented box and a
    /// convex hull, one of each kind (the other sphere constructions on request: with all four,
    /// their queries were four fifths of a default bench of a 35,902-polygon assembly).
    pub const DEFAULT: [Wrapper; 4] = [
        Wrapper::Box,
        Wrapper::Sphere(SphereMethod::Minimum),
        Wrapper::Obb,
        Wrapper::Hull,
    ];

    /// Every wrapper (`--wrappers all`).
    pub const ALL: [Wrapper; 7] = [
        Wrapper::Box,
        Wrapper::Sphere(SphereMethod::Merged),
        Wrapper::Sphere(SphereMethod::AabbCenter),
        Wrapper::Sphere(SphereMethod::Ritter),
        Wrapper::Sphere(SphereMethod::Minimum),
        Wrapper::Obb,
        Wrapper::Hull,
    ];

    /// Name in tables and CSV.
    pub fn name(self) -> &'static str {
        match self {
            Wrapper::Box => "box",
            Wrapper::Sphere(SphereMethod::Merged) => "sphere-merged",
            Wrapper::Sphere(SphereMethod::AabbCenter) => "sphere-aabb-center",
            Wrapper::Sphere(SphereMethod::Ritter) => "sphere-ritter",
            Wrapper::Sphere(SphereMethod::Minimum) => "sphere-min",
            Wrapper::Obb => "obb",
            Wrapper::Hull => "hull",
        }
    }

    /// Parses a name as printed by [`Wrapper::name`].
    pub fn parse(s: &str) -> Result<Wrapper, String> {
        Wrapper::ALL
            .into_iter()
            .find(|w| w.name() == s.trim())
            .ok_or_else(|| {
                let names: Vec<&str> = Wrapper::ALL.iter().map(|w| w.name()).collect();
                format!("unknown wrapper '{s}' (valid: {})", names.join(", "))
            })
    }
}

/// What to run.
#[derive(Clone, Debug)]
pub struct Options {
    /// Hierarchy builders.
    pub methods: Vec<Method>,
    /// Wrappers built on each hierarchy.
    pub wrappers: Vec<Wrapper>,
    /// Grouping parameters.
    pub params: Params,
    /// Rounds of builds, every method once per round (the fastest build of each is kept;
    /// [`super::timing`]), and timed repetitions of each wrapper (the best is kept; see
    /// [`REPEAT_BUDGET_S`] and [`REPEAT_FLOOR_S`]).
    pub repeat: u32,
    /// Tightness is measured only up to this many primitives.
    pub tightness_max_n: usize,
    /// Interior nodes per depth whose tightness is measured (0: every node, each distance
    /// query exact).
    pub tightness_nodes: usize,
    /// Surface samples per wrapper for tightness.
    pub samples: usize,
    /// Seed of the query workload.
    pub seed: u64,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            methods: Method::DEFAULT.to_vec(),
            wrappers: Wrapper::DEFAULT.to_vec(),
            params: Params::default(),
            repeat: super::timing::ROUNDS,
            tightness_max_n: 1_000_000,
            tightness_nodes: NODES_PER_DEPTH,
            samples: 16,
            seed: 1,
        }
    }
}

/// One hierarchy × wrapper on one scene.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Row {
    /// Scene name.
    pub scene: String,
    /// Number of primitives.
    pub n: usize,
    /// Hierarchy builder.
    pub method: &'static str,
    /// Wrapper.
    pub wrapper: &'static str,
    /// Hierarchy build seconds (best of the repetitions); for a refined method the total,
    /// base build + refinement.
    pub build_s: f64,
    /// Seconds of `build_s` spent refining (0 for an unrefined method).
    pub refine_s: f64,
    /// Wrapper build seconds on top of the hierarchy (best of the repetitions).
    pub wrapper_s: f64,
    /// The hierarchy's quality.
    pub quality: Quality,
    /// Mean relative surface-to-geometry distance of interior wrappers (`None`: not measured).
    pub tightness: Option<f64>,
    /// The same per level, depth 0 first (empty: not measured).
    pub tightness_levels: Vec<f64>,
    /// Query cost with this wrapper as bounding volume (`None`: not a query volume).
    pub query: Option<QueryCost>,
    /// The partitioned schedule's chunks the method grouped with ([`Method::chunking`];
    /// empty for the methods that do not run it).
    pub chunking: String,
}

/// Seconds after which a wrapper is not repeated further: a run this long is timed well enough
/// by itself, and repeating it would multiply the time of a bench.
pub const REPEAT_BUDGET_S: f64 = 0.1;

/// Seconds a wrapper with more than one repetition is repeated to at least: a build of well
/// under a millisecond is timed over many runs, whose best a busy machine is unlikely to have
/// slowed in every one (`docs/benchmarks.md`).
pub const REPEAT_FLOOR_S: f64 = 0.02;

/// The most runs of one wrapper.
pub const REPEAT_MAX: u32 = 200;

/// Whether a wrapper is run again after `runs` runs that took `spent` seconds in all: while
/// fewer than `repeat` runs took less than [`REPEAT_BUDGET_S`], or, when `repeat` > 1, less
/// than [`REPEAT_FLOOR_S`]; never more than [`REPEAT_MAX`] runs.
fn run_again(runs: u32, spent: f64, repeat: u32) -> bool {
    repeat > 1
        && runs < REPEAT_MAX
        && ((runs < repeat && spent < REPEAT_BUDGET_S) || spent < REPEAT_FLOOR_S)
}

/// The output and time of the fastest run of `f` (at least one), run again as long as
/// [`run_again`] says.
fn best_of<T>(repeat: u32, mut f: impl FnMut() -> (T, f64)) -> (T, f64) {
    let (mut out, mut best) = f();
    let (mut runs, mut spent) = (1, best);
    while run_again(runs, spent, repeat) {
        let (o, s) = f();
        runs += 1;
        spent += s;
        if s < best {
            (out, best) = (o, s);
        }
    }
    (out, best)
}

fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t = Instant::now();
    let out = f();
    (out, t.elapsed().as_secs_f64())
}

/// Mean over interior nodes of each node's sampled error over its box diagonal, and the
/// same per level (the cut at each depth, its interior nodes only; 0 for a cut of leaves),
/// from at most `per_depth` nodes per depth (0: every node, exact queries). Err: `stop`.
fn tightness(
    tree: &SubsetTree,
    scene: &Scene,
    w: WrapperTree<'_>,
    hulls: &[Hull],
    (k, per_depth, seed): (usize, usize, u64),
    stop: &Stop,
) -> Result<(f64, Vec<f64>), Interrupted> {
    let (per_depth, max_visits) = match per_depth {
        0 => (usize::MAX, usize::MAX),
        m => (m, MAX_VISITS),
    };
    let sample = DepthSample::new(tree, per_depth, seed);
    let nodes = sample.flat();
    let stats = nodes_tightness(tree, scene, w, hulls, k, &nodes, max_visits, stop)?;
    let rel: Vec<Option<f64>> = nodes
        .iter()
        .zip(&stats)
        .map(|(&x, s)| {
            let d = tree.aabb[x as usize].diameter();
            (d > 0.0).then(|| s.error / d)
        })
        .collect();
    let (all, per_level) = sample.means(&rel);
    // Depths below the deepest interior node are cuts of leaves.
    let levels = tree.depth_max() as usize + 1;
    let mut per_level = per_level;
    per_level.resize(levels, 0.0);
    Ok((all, per_level))
}

/// What `bench` is measuring, for progress reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Building a method's hierarchy (once per round).
    Build(Method),
    /// Building a wrapper on it.
    Wrapper(Method, Wrapper),
    /// The wrapper's tightness.
    Tightness(Method, Wrapper),
    /// The query workload with the wrapper as bounding volume.
    Query(Method, Wrapper),
}

impl std::fmt::Display for Step {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Step::Build(m) => write!(f, "{} build", m.name()),
            Step::Wrapper(m, w) => write!(f, "{} {} wrapper", m.name(), w.name()),
            Step::Tightness(m, w) => write!(f, "{} {} tightness", m.name(), w.name()),
            Step::Query(m, w) => write!(f, "{} {} queries", m.name(), w.name()),
        }
    }
}

/// Runs every method × wrapper of `opts` on `scene`: first the builds, `opts.repeat` rounds of
/// every method in turn ([`fastest_builds`]), then on each method's fastest tree its wrappers,
/// tightness and queries; calls `progress` before each step (each build of each round too) and
/// checks `stop` before it (Err: [`Interrupted`], or why a build
/// failed).
pub fn evaluate(
    scene: &Scene,
    opts: &Options,
    stop: &Stop,
    progress: &mut (dyn FnMut(Step) + Send),
) -> Result<Vec<Row>> {
    let workload = Workload::standard(scene, opts.seed);
    let measure_tightness = scene.len() <= opts.tightness_max_n;
    let built = fastest_builds(&opts.methods, opts.repeat, stop, |m| {
        progress(Step::Build(m));
        peers::build_until(m, scene, &opts.params, stop)
    })?;
    let mut rows = Vec::new();
    for (&method, built) in opts.methods.iter().zip(&built) {
        let tree = &built.tree;
        let q = quality(tree);
        // Reference hulls for tightness (and the hull wrapper itself).
        let need_hulls = measure_tightness || opts.wrappers.contains(&Wrapper::Hull);
        let hulls = if need_hulls {
            stop.check()?;
            progress(Step::Wrapper(method, Wrapper::Hull));
            let (h, t) = best_of(opts.repeat, || timed(|| hull_tree_until(tree, scene, stop)));
            (h?, t)
        } else {
            (Vec::new(), 0.0)
        };
        for &wrapper in &opts.wrappers {
            let on = Measuring {
                scene,
                opts,
                workload: &workload,
                tree,
                hulls: &hulls,
                stop,
            };
            let w = on.wrapper(wrapper, &mut |step: StepOf| progress(step(method, wrapper)))?;
            rows.push(Row {
                scene: scene.name.clone(),
                n: scene.len(),
                method: method.name(),
                wrapper: wrapper.name(),
                build_s: built.seconds,
                refine_s: built.refine_seconds,
                wrapper_s: w.seconds,
                quality: q,
                tightness: w.tightness,
                tightness_levels: w.tightness_levels,
                query: w.query,
                chunking: method
                    .chunking(&opts.params, scene.len())
                    .unwrap_or_default(),
            });
        }
    }
    Ok(rows)
}

/// What one wrapper on a hierarchy measured.
struct WrapperMeasure {
    /// Build time on top of the hierarchy (best of the repetitions).
    seconds: f64,
    tightness: Option<f64>,
    tightness_levels: Vec<f64>,
    query: Option<QueryCost>,
}

/// One hierarchy being measured: its scene, options, workload, tree and hull tree (the hulls
/// and their time).
struct Measuring<'a> {
    scene: &'a Scene,
    opts: &'a Options,
    workload: &'a Workload,
    tree: &'a SubsetTree,
    hulls: &'a (Vec<Hull>, f64),
    stop: &'a Stop,
}

/// A step of one wrapper on one method, as [`Step`]'s constructors.
type StepOf = fn(Method, Wrapper) -> Step;

impl Measuring<'_> {
    /// Builds `wrapper` on the tree and measures its tightness (up to
    /// [`Options::tightness_max_n`] primitives) and, for boxes and spheres, its query cost,
    /// telling `progress` each step and checking the stop request before it.
    fn wrapper(
        &self,
        wrapper: Wrapper,
        progress: &mut dyn FnMut(StepOf),
    ) -> Result<WrapperMeasure> {
        let (scene, opts, tree) = (self.scene, self.opts, self.tree);
        let (hulls, hull_s) = self.hulls;
        let mut spheres: Vec<Sphere> = Vec::new();
        let mut obbs = Vec::new();
        self.stop.check()?;
        progress(Step::Wrapper);
        let seconds = match wrapper {
            Wrapper::Box => 0.0,
            Wrapper::Hull => *hull_s,
            Wrapper::Sphere(m) => {
                let stop = self.stop;
                let (s, t) = best_of(opts.repeat, || {
                    timed(|| sphere_tree_until(tree, scene, m, stop))
                });
                spheres = s?;
                t
            }
            Wrapper::Obb => {
                let stop = self.stop;
                let (o, t) = best_of(opts.repeat, || {
                    timed(|| obb_tree_until(tree, scene, None, stop))
                });
                obbs = o?;
                t
            }
        };
        let view = match wrapper {
            Wrapper::Box => WrapperTree::Boxes(&tree.aabb),
            Wrapper::Hull => WrapperTree::Hulls(hulls),
            Wrapper::Sphere(_) => WrapperTree::Spheres(&spheres),
            Wrapper::Obb => WrapperTree::Obbs(&obbs),
        };
        let (mut tightness_value, mut tightness_levels) = (None, Vec::new());
        if scene.len() <= opts.tightness_max_n {
            self.stop.check()?;
            progress(Step::Tightness);
            let how = (opts.samples, opts.tightness_nodes, opts.seed);
            let (t, l) = tightness(tree, scene, view, hulls, how, self.stop)?;
            (tightness_value, tightness_levels) = (Some(t), l);
        }
        let bv = match wrapper {
            Wrapper::Box => Some(Bv::Aabb),
            Wrapper::Sphere(_) => Some(Bv::Sphere(&spheres)),
            _ => None,
        };
        let query = match bv {
            Some(bv) => {
                self.stop.check()?;
                progress(Step::Query);
                Some(query::measure_until(
                    tree,
                    scene,
                    bv,
                    self.workload,
                    self.stop,
                )?)
            }
            None => None,
        };
        Ok(WrapperMeasure {
            seconds,
            tightness: tightness_value,
            tightness_levels,
            query,
        })
    }
}

/// A query cost as the CSV's query columns: BV and primitive tests per query for point,
/// distance and overlap queries; node (BV) tests per query over those three kinds; eq. (1)
/// cost per query over them; seconds for the workload (contact queries included); BV and
/// primitive tests per contact query (kept apart: [`QueryCost::contact`]).
pub fn query_values(q: &QueryCost) -> [f64; 11] {
    let kinds = [&q.point, &q.distance, &q.overlap];
    let queries: f64 = kinds.iter().map(|k| k.queries as f64).sum::<f64>().max(1.0);
    let bv: f64 = kinds.iter().map(|k| k.bv_tests * k.queries as f64).sum();
    let cost: f64 = kinds.iter().map(|k| k.cost * k.queries as f64).sum();
    [
        q.point.bv_tests,
        q.point.prim_tests,
        q.distance.bv_tests,
        q.distance.prim_tests,
        q.overlap.bv_tests,
        q.overlap.prim_tests,
        bv / queries,
        cost / queries,
        q.seconds,
        q.contact.bv_tests,
        q.contact.prim_tests,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cases_run_repeat_times_within_the_budget_and_short_ones_up_to_the_floor() {
        // One repetition: one run, however short.
        assert!(!run_again(1, 1e-6, 1));
        // Long runs: the budget ends them before `repeat`.
        assert!(run_again(1, 0.05, 3));
        assert!(!run_again(2, 0.1, 3));
        assert!(!run_again(1, 0.5, 3));
        // Mid-length runs: `repeat` of them.
        assert!(run_again(2, 0.04, 3));
        assert!(!run_again(3, 0.06, 3));
        // Short runs: past `repeat` until the floor, at most REPEAT_MAX.
        assert!(run_again(3, 0.001, 3));
        assert!(!run_again(3, REPEAT_FLOOR_S, 3));
        assert!(!run_again(REPEAT_MAX, 0.0, 3));
        // A short case: runs of 1/1024 s (the fifth half that) pass the floor on the 21st
        // (20 of them take 0.0190 s, 21 take 0.0200), and the fastest run's output is kept.
        let mut runs = 0;
        let (out, best) = best_of(3, || {
            runs += 1;
            let s = if runs == 5 {
                1.0 / 2048.0
            } else {
                1.0 / 1024.0
            };
            (runs, s)
        });
        assert_eq!(runs, 21);
        assert_eq!((out, best), (5, 1.0 / 2048.0));
    }
}
