//! Computing a cover end to end, as `wraptree cover` and `record --cover-*` do: build the
//! Wrapper Trees the kinds need, measure every node's [`Fits`], cut the tree within a
//! [`CoverLimit`], and (for [`cover_scene`]) the summary `wraptree cover` writes as JSON and
//! prints ([`CoverSummary::text`]).

use super::export::{self, WrapperRecord};
use super::{Cover, Fits, LevelRow, compare_levels};
use crate::grouping::{self, Params, SubsetTree};
use crate::scene::Scene;
use crate::stop::{Interrupted, Stop};
use crate::wrap::{DEFAULT_SAMPLES, SphereMethod, WrapperKind, Wrappers};
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// A tolerance: a length in scene units, or a fraction of the scene diagonal.
///
/// ```
/// use wraptree_core::wrap::cover::solve::Tolerance;
/// assert_eq!(Tolerance::parse("2%").unwrap().length(10.0), 0.2);
/// assert_eq!(Tolerance::parse("0.5").unwrap().length(10.0), 0.5);
/// assert!(Tolerance::parse("-1").is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tolerance {
    /// A length in scene units.
    Abs(f64),
    /// A fraction of the scene diagonal.
    Rel(f64),
}

impl Tolerance {
    /// The length for a scene of diagonal `diagonal`.
    pub fn length(self, diagonal: f64) -> f64 {
        match self {
            Tolerance::Abs(t) => t,
            Tolerance::Rel(r) => r * diagonal,
        }
    }

    /// Parses a length ≥ 0, or `P%` of the scene diagonal (`--tolerance`).
    pub fn parse(s: &str) -> Result<Tolerance, String> {
        let bad = || format!("invalid tolerance '{s}' (want a length ≥ 0, or P% of the diagonal)");
        let t = s.trim();
        let (num, rel) = match t.strip_suffix('%') {
            Some(n) => (n, true),
            None => (t, false),
        };
        let v: f64 = num.trim().parse().map_err(|_| bad())?;
        if !(v.is_finite() && v >= 0.0) {
            return Err(bad());
        }
        Ok(if rel {
            Tolerance::Rel(v / 100.0)
        } else {
            Tolerance::Abs(v)
        })
    }
}

/// How a cover is bounded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CoverLimit {
    /// Largest error per wrapper: the fewest wrappers within it ([`Fits::cover_tolerance`]).
    Tolerance(Tolerance),
    /// Largest number of wrappers: the smallest largest error ([`Fits::cover_budget`]).
    Budget(usize),
}

/// A cover with what it was chosen from.
#[derive(Debug)]
pub struct Solved {
    /// The chosen cut and kinds.
    pub cover: Cover,
    /// Every node's candidates and best error.
    pub fits: Fits,
    /// The Wrapper Trees measured (hulls included only when `kinds` has them).
    pub wrappers: Wrappers,
    /// One record per cover node, with its geometry.
    pub records: Vec<WrapperRecord>,
}

/// The cover of `tree` within `limit`, choosing among `kinds` (spheres by
/// [`SphereMethod::Minimum`], [`DEFAULT_SAMPLES`] surface samples per wrapper). Hulls are always
/// built, as the reference the errors need. Err: a budget of 0, or [`Interrupted`] when `stop`
/// is requested (checked throughout).
pub fn solve(
    tree: &SubsetTree,
    scene: &Scene,
    limit: CoverLimit,
    kinds: &[WrapperKind],
    stop: &Stop,
) -> Result<Solved> {
    let mut build = kinds.to_vec();
    if !build.contains(&WrapperKind::Hull) {
        build.push(WrapperKind::Hull);
    }
    let mut wrappers = Wrappers::build_until(tree, scene, &build, SphereMethod::Minimum, stop)?;
    let hulls = if kinds.contains(&WrapperKind::Hull) {
        None
    } else {
        wrappers.hulls.take()
    };
    let fits = Fits::measure(
        tree,
        scene,
        &wrappers,
        hulls.as_deref(),
        DEFAULT_SAMPLES,
        stop,
    )?;
    let cover = match limit {
        CoverLimit::Tolerance(t) => fits.cover_tolerance(tree, t.length(scene.aabb().diameter())),
        CoverLimit::Budget(k) => fits.cover_budget(tree, k).map_err(anyhow::Error::msg)?,
    };
    let records = export::records(&cover, tree, scene, &wrappers);
    Ok(Solved {
        cover,
        fits,
        wrappers,
        records,
    })
}

/// What `wraptree cover` reports and writes to `OUT.json`: the run, the cover and its
/// wrappers, and each tree level against the cover of the same error.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CoverSummary {
    /// Scene name.
    pub scene: String,
    /// Primitives in the scene.
    pub primitives: usize,
    /// Scene diagonal (the unit of relative tolerances).
    pub diagonal: f64,
    /// Kinds chosen from.
    pub kinds: Vec<&'static str>,
    /// How spheres were computed.
    pub sphere_method: SphereMethod,
    /// Surface samples per wrapper.
    pub samples: usize,
    /// The query-cost rule that breaks ties.
    pub query_costs: &'static str,
    /// The absolute error bound used.
    pub tolerance: f64,
    /// The wrapper budget, when asked for by budget.
    pub budget: Option<usize>,
    /// Wrappers in the cover.
    pub size: usize,
    /// Largest error of the cover.
    pub max_error: f64,
    /// Sum of the cover's query costs.
    pub total_cost: f64,
    /// Grouping + cover wall time.
    pub seconds: f64,
    /// Each uniform level against the cover of the same error.
    pub levels: Vec<LevelRow>,
    /// The cover's wrappers with their geometry.
    pub wrappers: Vec<WrapperRecord>,
}

/// Groups `scene` with `params` and computes its cover within `limit` from `kinds`; stops with
/// [`Interrupted`] when `stop` is requested (the grouping obeys it too).
pub fn cover_scene(
    scene: &Scene,
    params: &Params,
    limit: CoverLimit,
    kinds: &[WrapperKind],
    stop: &Stop,
) -> Result<CoverSummary> {
    let start = Instant::now();
    let resolved = params.resolve(scene);
    let g = grouping::group_until(scene, &resolved, (), stop.flag()).map_err(|_| Interrupted)?;
    let tree = &g.tree;
    let s = solve(tree, scene, limit, kinds, stop)?;
    let levels = compare_levels(tree, &s.fits.best);
    let seconds = start.elapsed().as_secs_f64();
    let c = &s.cover;
    Ok(CoverSummary {
        scene: scene.name.clone(),
        primitives: scene.len(),
        diagonal: scene.aabb().diameter(),
        kinds: kinds.iter().map(|k| k.name()).collect(),
        sphere_method: SphereMethod::Minimum,
        samples: DEFAULT_SAMPLES,
        query_costs: "sphere 1, box 2, obb 3, hull/primitive 4 + vertices/16",
        tolerance: c.tolerance,
        budget: match limit {
            CoverLimit::Budget(k) => Some(k),
            CoverLimit::Tolerance(_) => None,
        },
        size: c.nodes.len(),
        max_error: c.max_error(),
        total_cost: c.cost(),
        seconds,
        levels,
        wrappers: s.records,
    })
}

impl CoverLimit {
    /// The limit of a `--tolerance`/`--budget` flag pair (a tolerance wins), `None` for neither.
    pub fn from_flags(tolerance: Option<Tolerance>, budget: Option<usize>) -> Option<CoverLimit> {
        match (tolerance, budget) {
            (Some(t), _) => Some(CoverLimit::Tolerance(t)),
            (None, Some(k)) => Some(CoverLimit::Budget(k)),
            (None, None) => None,
        }
    }
}

impl CoverSummary {
    /// The summary as one JSON object without the wrappers, naming the files written instead
    /// (`cover --json`).
    pub fn to_json(&self, json: &Path, obj: &Path) -> Result<serde_json::Value> {
        let mut v = serde_json::to_value(self).context("cover: cannot serialise")?;
        if let Some(m) = v.as_object_mut() {
            m.remove("wrappers");
            m.insert("json".into(), json.display().to_string().into());
            m.insert("obj".into(), obj.display().to_string().into());
        }
        Ok(v)
    }

    /// The summary as the lines `wraptree cover` prints: the scene, the bound, the cover and a
    /// table of each level against the cover of the same error.
    pub fn text(&self) -> String {
        let mut count = std::collections::BTreeMap::new();
        for w in &self.wrappers {
            *count.entry(w.node.choice.kind.name()).or_insert(0usize) += 1;
        }
        let kinds: Vec<String> = count.iter().map(|(k, n)| format!("{n} {k}")).collect();
        let mut s = format!(
            "{}: {} primitives, diagonal {:.4e}; kinds {}\n",
            self.scene,
            self.primitives,
            self.diagonal,
            self.kinds.join(",")
        );
        let _ = match self.budget {
            Some(k) => writeln!(
                s,
                "budget {k}: smallest achievable max error {:.4e}",
                self.tolerance
            ),
            None => writeln!(s, "tolerance {:.4e}", self.tolerance),
        };
        let _ = writeln!(
            s,
            "cover       {} wrappers ({}), max error {:.4e}, query cost {:.1}",
            self.size,
            kinds.join(", "),
            self.max_error,
            self.total_cost
        );
        s.push_str("depth  level nodes  level max error  cover nodes  ratio\n");
        for r in &self.levels {
            let _ = writeln!(
                s,
                "{:>5}  {:>11}  {:>15.4e}  {:>11}  {:>5.1}",
                r.depth,
                r.level_nodes,
                r.level_max_error,
                r.cover_nodes,
                r.level_nodes as f64 / r.cover_nodes.max(1) as f64
            );
        }
        s
    }
}
