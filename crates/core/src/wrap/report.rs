//! The report of `wraptree wrap`: each Wrapper Tree's build time, containment check (every
//! vertex below a node inside its wrapper, within a tolerance) and per-level tightness (the
//! error measured on a seeded sample of interior nodes per depth, or on every node), and the
//! same as text ([`report_text`]) or JSON ([`report_json`]).
//!
//! ```no_run
//! use wraptree_core::wrap::report::{Measured, report};
//! use wraptree_core::wrap::{DEFAULT_SAMPLES, NODES_PER_DEPTH, SphereMethod, WrapperKind};
//! # fn demo(tree: &wraptree_core::grouping::SubsetTree, scene: &wraptree_core::scene::Scene) {
//! let kinds = [WrapperKind::Sphere, WrapperKind::Obb];
//! let how = Measured {
//!     method: SphereMethod::Minimum,
//!     samples: DEFAULT_SAMPLES,
//!     per_depth: NODES_PER_DEPTH,
//! };
//! let stop = wraptree_core::stop::Stop::new();
//! for r in report(tree, scene, &kinds, how, &stop).expect("nobody asked to stop") {
//!     println!("{}: containment holds: {}", r.kind.name(), r.containment.holds);
//! }
//! # }
//! ```

use super::{
    HULL_TOL_REL, Hull, LevelStats, Obb, Sphere, SphereMethod, WrapperKind, WrapperTree,
    containment_excess_until, hull_tree_until, level_tightness_sampled, obb_tree_until,
    sphere_tree_until,
};
use crate::geom::Aabb;
use crate::grouping::SubsetTree;
use crate::scene::Scene;
use crate::stop::{Interrupted, Stop};
use std::fmt::Write as _;
use std::time::Instant;

/// Containment tolerance of spheres, boxes and oriented boxes, relative to the scene diagonal.
pub const TOL_REL: f64 = 1e-9;

/// Seed of the node sample whose error [`report`] measures.
pub const SAMPLE_SEED: u64 = 1;

/// The containment check of one Wrapper Tree.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Containment {
    /// Largest excess of a vertex outside its node's wrapper (≤ 0: all strictly inside).
    pub max_excess: f64,
    /// The tolerance rule.
    pub tolerance_rule: &'static str,
    /// The tolerance of the node with the largest excess over its tolerance.
    pub tolerance_at_worst: f64,
    /// Excess of that node.
    pub excess_at_worst: f64,
    /// Whether every node's excess is within its tolerance.
    pub holds: bool,
}

/// One Wrapper Tree's report.
#[derive(Clone, Debug, serde::Serialize)]
pub struct KindReport {
    /// The kind of wrapper.
    pub kind: WrapperKind,
    /// Build time of the Wrapper Tree.
    pub build_seconds: f64,
    /// Its containment check.
    pub containment: Containment,
    /// Its per-level tightness.
    pub levels: Vec<LevelStats>,
}

/// The Wrapper Trees built for one tree, each with its build time.
#[derive(Default)]
struct Built {
    spheres: Option<(Vec<Sphere>, f64)>,
    hulls: Option<(Vec<Hull>, f64)>,
    boxes: Option<(Vec<Aabb>, f64)>,
    obbs: Option<(Vec<Obb>, f64)>,
}

/// Runs `f`, returning its value and wall time in seconds.
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let start = Instant::now();
    let v = f();
    (v, start.elapsed().as_secs_f64())
}

impl Built {
    /// Builds the trees of `kinds` (OBB axes from the hulls when hulls are built too, as
    /// [`Wrappers::build`](super::Wrappers::build) does), checking `stop` before and within each.
    fn new(
        tree: &SubsetTree,
        scene: &Scene,
        kinds: &[WrapperKind],
        method: SphereMethod,
        stop: &Stop,
    ) -> Result<Built, Interrupted> {
        let want = |k| kinds.contains(&k);
        let mut b = Built::default();
        if want(WrapperKind::Sphere) {
            stop.check()?;
            let (spheres, t) = timed(|| sphere_tree_until(tree, scene, method, stop));
            b.spheres = Some((spheres?, t));
        }
        if want(WrapperKind::Hull) {
            stop.check()?;
            let (hulls, t) = timed(|| hull_tree_until(tree, scene, stop));
            b.hulls = Some((hulls?, t));
        }
        if want(WrapperKind::Box) {
            b.boxes = Some(timed(|| tree.aabb.clone()));
        }
        if want(WrapperKind::Obb) {
            stop.check()?;
            let hulls = b.hulls.as_ref().map(|(h, _)| h.as_slice());
            let (obbs, t) = timed(|| obb_tree_until(tree, scene, hulls, stop));
            b.obbs = Some((obbs?, t));
        }
        Ok(b)
    }

    /// The trees built, in [`WrapperKind`] order, with their build times.
    fn trees(&self) -> Vec<(WrapperTree<'_>, f64)> {
        let mut v = Vec::new();
        if let Some((w, s)) = &self.spheres {
            v.push((WrapperTree::Spheres(w), *s));
        }
        if let Some((w, s)) = &self.hulls {
            v.push((WrapperTree::Hulls(w), *s));
        }
        if let Some((w, s)) = &self.boxes {
            v.push((WrapperTree::Boxes(w), *s));
        }
        if let Some((w, s)) = &self.obbs {
            v.push((WrapperTree::Obbs(w), *s));
        }
        v
    }
}

/// Checks that every vertex below each node is inside its wrapper: hulls within
/// [`HULL_TOL_REL`] × the node's AABB diameter, the others within [`TOL_REL`] × the scene
/// diagonal. [`Interrupted`] once `stop` is requested.
pub fn containment(
    tree: &SubsetTree,
    scene: &Scene,
    w: WrapperTree<'_>,
    stop: &Stop,
) -> Result<Containment, Interrupted> {
    let excess = containment_excess_until(tree, scene, w, stop)?;
    let diagonal = scene.aabb().diameter();
    let (rule, tol): (&str, Box<dyn Fn(usize) -> f64>) = match w {
        WrapperTree::Hulls(_) => (
            "1e-5 x node AABB diameter",
            Box::new(|i| HULL_TOL_REL * tree.aabb[i].diameter()),
        ),
        _ => ("1e-9 x scene diagonal", Box::new(|_| TOL_REL * diagonal)),
    };
    let worst =
        (0..excess.len()).max_by(|&a, &b| (excess[a] - tol(a)).total_cmp(&(excess[b] - tol(b))));
    let max_excess = excess.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Ok(match worst {
        Some(i) => Containment {
            max_excess,
            tolerance_rule: rule,
            tolerance_at_worst: tol(i),
            excess_at_worst: excess[i],
            holds: excess[i] <= tol(i),
        },
        None => Containment {
            max_excess,
            tolerance_rule: rule,
            tolerance_at_worst: 0.0,
            excess_at_worst: max_excess,
            holds: true,
        },
    })
}

/// Builds the Wrapper Trees of `kinds` (each once, in [`WrapperKind`] order) over `tree` and
/// reports each one's build time, containment (every node) and tightness per level from
/// `how.samples` surface samples per wrapper, the error measured on every leaf and at most
/// `how.per_depth` interior nodes per depth ([`level_tightness_sampled`], seed
/// [`SAMPLE_SEED`]; 0: every node), spheres by `how.method`. The reference volumes are the
/// hulls', built untimed when not asked for. `stop` is obeyed throughout (every builder and
/// measure checks it as it goes).
pub fn report(
    tree: &SubsetTree,
    scene: &Scene,
    kinds: &[WrapperKind],
    how: Measured,
    stop: &Stop,
) -> Result<Vec<KindReport>, Interrupted> {
    let Measured {
        method,
        samples,
        per_depth,
    } = how;
    let mut kinds = kinds.to_vec();
    kinds.sort();
    kinds.dedup();
    let built = Built::new(tree, scene, &kinds, method, stop)?;
    let own_hulls;
    let hulls = match &built.hulls {
        Some((h, _)) => h.as_slice(),
        None => {
            own_hulls = hull_tree_until(tree, scene, stop)?;
            own_hulls.as_slice()
        }
    };
    built
        .trees()
        .into_iter()
        .map(|(w, build_seconds)| {
            let containment = containment(tree, scene, w, stop)?;
            Ok(KindReport {
                kind: w.kind(),
                build_seconds,
                containment,
                levels: level_tightness_sampled(
                    tree,
                    scene,
                    w,
                    hulls,
                    samples,
                    (per_depth, SAMPLE_SEED),
                    stop,
                )?,
            })
        })
        .collect()
}

/// The command-line name of `m`, e.g. `aabb-center`.
pub fn method_name(m: SphereMethod) -> String {
    use clap::ValueEnum;
    m.to_possible_value()
        .map_or_else(|| format!("{m:?}"), |v| v.get_name().to_string())
}

/// How the report was measured: sphere method, surface samples per wrapper and interior nodes
/// per depth whose error is measured (0: every node).
#[derive(Clone, Copy, Debug)]
pub struct Measured {
    /// How spheres were computed.
    pub method: SphereMethod,
    /// Surface samples per wrapper.
    pub samples: usize,
    /// Interior nodes per depth whose error was measured (0: every node).
    pub per_depth: usize,
}

/// Which nodes' error was measured, as the text report says it.
fn nodes_measured(per_depth: usize) -> String {
    match per_depth {
        0 => "on every node".to_string(),
        k => format!("on every leaf and at most {k} interior nodes per depth (seeded sample)"),
    }
}

/// What `wraptree wrap` prints for `reports` of `scene`'s tree (grouped in `group_seconds`,
/// measured as `how` says).
pub fn report_text(
    scene: &Scene,
    tree: &SubsetTree,
    group_seconds: f64,
    how: Measured,
    reports: &[KindReport],
) -> String {
    let mut s = format!(
        "{}: {} primitives, depth {}, grouped in {:.3} s; error from {} surface samples per wrapper {}\n",
        scene.name,
        scene.len(),
        tree.depth_max(),
        group_seconds,
        how.samples,
        nodes_measured(how.per_depth)
    );
    let method = how.method;
    for r in reports {
        s.push_str(&kind_text(r, method));
    }
    s
}

/// One kind's report as text: a blank line, the build time and containment, and the level
/// table.
fn kind_text(r: &KindReport, method: SphereMethod) -> String {
    let name = match r.kind {
        WrapperKind::Sphere => format!("sphere ({})", method_name(method)),
        k => k.name().to_string(),
    };
    let c = &r.containment;
    let mut s = format!(
        "\n{name}: built in {:.3} s; containment {}: max excess {:.3e} (worst node {:.3e} vs tolerance {:.3e}, {})\n",
        r.build_seconds,
        if c.holds { "holds" } else { "FAILS" },
        c.max_excess,
        c.excess_at_worst,
        c.tolerance_at_worst,
        c.tolerance_rule
    );
    let _ = writeln!(
        s,
        "{:>5} {:>7} {:>8} {:>12} {:>8} {:>11} {:>11}",
        "depth", "nodes", "interior", "volume", "ratio", "error max", "error mean"
    );
    for l in &r.levels {
        let ratio = l
            .volume_ratio
            .map_or_else(|| "-".to_string(), |v| format!("{v:.3}"));
        let _ = writeln!(
            s,
            "{:>5} {:>7} {:>8} {:>12.4e} {:>8} {:>11.4e} {:>11.4e}",
            l.depth, l.nodes, l.interior, l.volume, ratio, l.error_max, l.error_mean
        );
    }
    s
}

/// The same as one JSON object (`wrap --json`; `tightness_nodes` 0: every node measured).
pub fn report_json(
    scene: &Scene,
    tree: &SubsetTree,
    group_seconds: f64,
    how: Measured,
    reports: &[KindReport],
) -> serde_json::Value {
    serde_json::json!({
        "scene": scene.name,
        "primitives": scene.len(),
        "depth_max": tree.depth_max(),
        "grouping_seconds": group_seconds,
        "sphere_method": method_name(how.method),
        "samples": how.samples,
        "tightness_nodes": how.per_depth,
        "wrappers": reports,
    })
}
