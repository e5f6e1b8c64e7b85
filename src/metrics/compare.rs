//! One scene, every hierarchy × wrapper: build times, quality, tightness and query cost in rows
//! ready for a CSV and charts (`wraptree bench SCENE… -o DIR`).
//!
//! For each [`Method`] the hierarchy is built once per repetition (best time kept), then each
//! [`Wrapper`] is built on it and timed. Rows carry:
//! - the hierarchy's [`Quality`] (same for every wrapper on it);
//! - the wrapper's tightness: mean over interior nodes of the sampled surface-to-geometry
//!   distance divided by the node box's diagonal ([`crate::wrap::node_tightness`]), skipped
//!   above [`Options::tightness_max_n`] primitives because it costs far more than the build;
//! - for box and sphere wrappers, the cost of the standard query workload
//!   ([`crate::query::Workload::standard`]) with those wrappers as bounding volumes.

use super::{Quality, quality};
use crate::grouping::{Params, SubsetTree};
use crate::peers::{self, Method};
use crate::query::{self, Bv, QueryCost, Workload};
use crate::scene::Scene;
use crate::wrap::{
    Hull, Sphere, SphereMethod, WrapperTree, hull_tree, node_tightness, obb_tree, sphere_tree,
};
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
    /// Every wrapper compared by default.
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
    /// Timed repetitions of each build (the best is kept).
    pub repeat: u32,
    /// Tightness is measured only up to this many primitives.
    pub tightness_max_n: usize,
    /// Surface samples per wrapper for tightness.
    pub samples: usize,
    /// Seed of the query workload.
    pub seed: u64,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            methods: Method::ALL.to_vec(),
            wrappers: Wrapper::ALL.to_vec(),
            params: Params::default(),
            repeat: 3,
            tightness_max_n: 50_000,
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
}

fn best_of<T>(repeat: u32, mut f: impl FnMut() -> (T, f64)) -> (T, f64) {
    let (mut out, mut best) = f();
    for _ in 1..repeat.max(1) {
        let (o, s) = f();
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
/// same per level (the cut at each depth, its interior nodes only; 0 for a cut of leaves).
fn tightness(
    tree: &SubsetTree,
    scene: &Scene,
    w: WrapperTree<'_>,
    hulls: &[Hull],
    k: usize,
) -> (f64, Vec<f64>) {
    let stats = node_tightness(tree, scene, w, hulls, k);
    let n = tree.leaves();
    let rel = |x: usize| {
        let d = tree.aabb[x].diameter();
        (d > 0.0).then(|| stats[x].error / d)
    };
    let mean = |v: Vec<f64>| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let all = mean((n..tree.len()).filter_map(rel).collect());
    let per_level = (0..=tree.depth_max())
        .map(|d| {
            let cut = tree.level(d);
            mean(
                cut.into_iter()
                    .filter(|&x| x as usize >= n)
                    .filter_map(|x| rel(x as usize))
                    .collect(),
            )
        })
        .collect();
    (all, per_level)
}

/// Runs every method × wrapper of `opts` on `scene`, calling `progress` before each method.
pub fn evaluate(
    scene: &Scene,
    opts: &Options,
    mut progress: impl FnMut(Method),
) -> Result<Vec<Row>, String> {
    let workload = Workload::standard(scene, opts.seed);
    let measure_tightness = scene.len() <= opts.tightness_max_n;
    let mut rows = Vec::new();
    for &method in &opts.methods {
        progress(method);
        let (built, build_s) = build_best(method, scene, opts)?;
        let tree = &built.tree;
        let q = quality(tree);
        // Reference hulls for tightness (and the hull wrapper itself).
        let need_hulls = measure_tightness || opts.wrappers.contains(&Wrapper::Hull);
        let hulls = if need_hulls {
            best_of(opts.repeat, || timed(|| hull_tree(tree, scene)))
        } else {
            (Vec::new(), 0.0)
        };
        for &wrapper in &opts.wrappers {
            let w = measure_wrapper(scene, opts, &workload, tree, &hulls, wrapper);
            rows.push(Row {
                scene: scene.name.clone(),
                n: scene.len(),
                method: method.name(),
                wrapper: wrapper.name(),
                build_s,
                refine_s: built.refine_seconds,
                wrapper_s: w.seconds,
                quality: q,
                tightness: w.tightness,
                tightness_levels: w.tightness_levels,
                query: w.query,
            });
        }
    }
    Ok(rows)
}

/// The best of `opts.repeat` builds of `method`'s hierarchy, and its time. Err: why a build
/// failed.
fn build_best(
    method: Method,
    scene: &Scene,
    opts: &Options,
) -> Result<(peers::Built, f64), String> {
    let mut failed = None;
    let (built, build_s) = best_of(opts.repeat, || {
        match peers::build(method, scene, &opts.params) {
            Ok(b) => {
                let s = b.seconds;
                (Some(b), s)
            }
            Err(e) => {
                failed = Some(e);
                (None, f64::INFINITY)
            }
        }
    });
    let built = built.ok_or_else(|| failed.unwrap_or_default())?;
    Ok((built, build_s))
}

/// What one wrapper on a hierarchy measured.
struct WrapperMeasure {
    /// Build time on top of the hierarchy (best of the repetitions).
    seconds: f64,
    tightness: Option<f64>,
    tightness_levels: Vec<f64>,
    query: Option<QueryCost>,
}

/// Builds `wrapper` on `tree` (the hull tree is `hulls`: the hulls and their time) and
/// measures its tightness (up to [`Options::tightness_max_n`] primitives) and, for boxes and
/// spheres, its query cost.
fn measure_wrapper(
    scene: &Scene,
    opts: &Options,
    workload: &Workload,
    tree: &SubsetTree,
    (hulls, hull_s): &(Vec<Hull>, f64),
    wrapper: Wrapper,
) -> WrapperMeasure {
    let mut spheres: Vec<Sphere> = Vec::new();
    let mut obbs = Vec::new();
    let seconds = match wrapper {
        Wrapper::Box => 0.0,
        Wrapper::Hull => *hull_s,
        Wrapper::Sphere(m) => {
            let (s, t) = best_of(opts.repeat, || timed(|| sphere_tree(tree, scene, m)));
            spheres = s;
            t
        }
        Wrapper::Obb => {
            let (o, t) = best_of(opts.repeat, || timed(|| obb_tree(tree, scene, None)));
            obbs = o;
            t
        }
    };
    let view = match wrapper {
        Wrapper::Box => WrapperTree::Boxes(&tree.aabb),
        Wrapper::Hull => WrapperTree::Hulls(hulls),
        Wrapper::Sphere(_) => WrapperTree::Spheres(&spheres),
        Wrapper::Obb => WrapperTree::Obbs(&obbs),
    };
    let measure_tightness = scene.len() <= opts.tightness_max_n;
    let tight = measure_tightness.then(|| tightness(tree, scene, view, hulls, opts.samples));
    let (tightness, tightness_levels) = match tight {
        Some((t, l)) => (Some(t), l),
        None => (None, Vec::new()),
    };
    let query = match wrapper {
        Wrapper::Box => Some(query::measure(tree, scene, Bv::Aabb, workload)),
        Wrapper::Sphere(_) => Some(query::measure(tree, scene, Bv::Sphere(&spheres), workload)),
        _ => None,
    };
    WrapperMeasure {
        seconds,
        tightness,
        tightness_levels,
        query,
    }
}

/// A query cost as the CSV's query columns: BV and primitive tests per query for point,
/// distance and overlap queries; node (BV) tests per query over the whole workload; eq. (1)
/// cost per query over the whole workload; seconds for the workload.
pub fn query_values(q: &QueryCost) -> [f64; 9] {
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
    ]
}
