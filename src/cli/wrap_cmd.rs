//! `wraptree wrap`: group a scene, build the chosen Wrapper Trees and report how tightly each
//! fits, level by level, and whether it contains every vertex below each node.

use super::{GroupArgs, SceneArgs};
use anyhow::Result;
use clap::{Args, ValueEnum};
use std::process::ExitCode;
use std::time::Instant;
use wraptree::geom::Aabb;
use wraptree::grouping::{self, SubsetTree};
use wraptree::scene::Scene;
use wraptree::wrap::{
    DEFAULT_SAMPLES, HULL_TOL_REL, Hull, LevelStats, Obb, Sphere, SphereMethod, WrapperKind,
    WrapperTree, containment_excess, hull_tree, level_tightness, obb_tree, sphere_tree,
};

/// Containment tolerance of spheres, boxes and oriented boxes, relative to the scene diagonal.
const TOL_REL: f64 = 1e-9;

/// Arguments of `wraptree wrap`.
#[derive(Args, Debug)]
pub struct WrapCmd {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    group: GroupArgs,
    /// Wrapper Trees to build, comma-separated: sphere, hull, box (or aabb), obb.
    #[arg(long, default_value = "sphere,hull,box,obb", value_delimiter = ',', value_parser = WrapperKind::parse)]
    wrapper: Vec<WrapperKind>,
    /// How spheres are computed.
    #[arg(long, value_enum, default_value_t = SphereMethod::AabbCenter)]
    sphere_method: SphereMethod,
    /// Surface samples per wrapper for the error measure.
    #[arg(long, default_value_t = DEFAULT_SAMPLES as u32, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    samples: u32,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

/// The containment check of one Wrapper Tree.
#[derive(serde::Serialize)]
struct Containment {
    /// Largest excess of a vertex outside its node's wrapper (≤ 0: all strictly inside).
    max_excess: f64,
    /// The tolerance rule.
    tolerance_rule: &'static str,
    /// The tolerance of the node with the largest excess over its tolerance.
    tolerance_at_worst: f64,
    /// Excess of that node.
    excess_at_worst: f64,
    /// Whether every node's excess is within its tolerance.
    holds: bool,
}

/// One Wrapper Tree's report.
#[derive(serde::Serialize)]
struct KindReport {
    kind: WrapperKind,
    build_seconds: f64,
    containment: Containment,
    levels: Vec<LevelStats>,
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
    /// [`wraptree::wrap::Wrappers::build`] does).
    fn new(tree: &SubsetTree, scene: &Scene, kinds: &[WrapperKind], method: SphereMethod) -> Built {
        let want = |k| kinds.contains(&k);
        let mut b = Built::default();
        if want(WrapperKind::Sphere) {
            b.spheres = Some(timed(|| sphere_tree(tree, scene, method)));
        }
        if want(WrapperKind::Hull) {
            b.hulls = Some(timed(|| hull_tree(tree, scene)));
        }
        if want(WrapperKind::Box) {
            b.boxes = Some(timed(|| tree.aabb.clone()));
        }
        if want(WrapperKind::Obb) {
            let hulls = b.hulls.as_ref().map(|(h, _)| h.as_slice());
            b.obbs = Some(timed(|| obb_tree(tree, scene, hulls)));
        }
        b
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
/// diagonal.
fn containment(tree: &SubsetTree, scene: &Scene, w: WrapperTree<'_>) -> Containment {
    let excess = containment_excess(tree, scene, w);
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
    match worst {
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
    }
}

/// The command-line name of `m`, e.g. `aabb-center`.
fn method_name(m: SphereMethod) -> String {
    m.to_possible_value()
        .map_or_else(|| format!("{m:?}"), |v| v.get_name().to_string())
}

/// Prints one kind's report as text.
fn print_kind(r: &KindReport, method: SphereMethod) {
    let name = match r.kind {
        WrapperKind::Sphere => format!("sphere ({})", method_name(method)),
        k => k.name().to_string(),
    };
    let c = &r.containment;
    println!(
        "\n{name}: built in {:.3} s; containment {}: max excess {:.3e} (worst node {:.3e} vs tolerance {:.3e}, {})",
        r.build_seconds,
        if c.holds { "holds" } else { "FAILS" },
        c.max_excess,
        c.excess_at_worst,
        c.tolerance_at_worst,
        c.tolerance_rule
    );
    println!(
        "{:>5} {:>7} {:>8} {:>12} {:>8} {:>11} {:>11}",
        "depth", "nodes", "interior", "volume", "ratio", "error max", "error mean"
    );
    for l in &r.levels {
        let ratio = l
            .volume_ratio
            .map_or_else(|| "-".to_string(), |v| format!("{v:.3}"));
        println!(
            "{:>5} {:>7} {:>8} {:>12.4e} {:>8} {:>11.4e} {:>11.4e}",
            l.depth, l.nodes, l.interior, l.volume, ratio, l.error_max, l.error_mean
        );
    }
}

impl WrapCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        let loaded = self.scene.load()?;
        let params = self.group.params()?;
        let scene = &loaded.scene;
        let mut kinds = self.wrapper.clone();
        kinds.sort();
        kinds.dedup();
        let (g, group_seconds) = timed(|| grouping::group(scene, &params, ()));
        let tree = &g.tree;
        let built = Built::new(tree, scene, &kinds, self.sphere_method);
        // The reference volumes of the tightness table are the hulls' (built untimed if not
        // asked for).
        let own_hulls;
        let hulls = match &built.hulls {
            Some((h, _)) => h.as_slice(),
            None => {
                own_hulls = hull_tree(tree, scene);
                own_hulls.as_slice()
            }
        };
        let samples = self.samples as usize;
        let reports: Vec<KindReport> = built
            .trees()
            .into_iter()
            .map(|(w, build_seconds)| KindReport {
                kind: w.kind(),
                build_seconds,
                containment: containment(tree, scene, w),
                levels: level_tightness(tree, scene, w, hulls, samples),
            })
            .collect();
        if self.json {
            let out = serde_json::json!({
                "scene": scene.name,
                "primitives": scene.len(),
                "depth_max": tree.depth_max(),
                "grouping_seconds": group_seconds,
                "sphere_method": method_name(self.sphere_method),
                "samples": samples,
                "wrappers": reports,
            });
            println!("{out}");
        } else {
            println!(
                "{}: {} primitives, depth {}, grouped in {:.3} s; error from {samples} surface samples per wrapper",
                scene.name,
                scene.len(),
                tree.depth_max(),
                group_seconds
            );
            for r in &reports {
                print_kind(r, self.sphere_method);
            }
        }
        let failed: Vec<&str> = reports
            .iter()
            .filter(|r| !r.containment.holds)
            .map(|r| r.kind.name())
            .collect();
        if !failed.is_empty() {
            anyhow::bail!(
                "{}: containment fails for {} (a vertex lies outside its node's wrapper beyond the tolerance)",
                self.scene.scene.display(),
                failed.join(", ")
            );
        }
        Ok(ExitCode::SUCCESS)
    }
}
