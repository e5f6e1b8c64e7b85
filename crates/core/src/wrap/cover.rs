//! Covers: the fewest wrappers that model a scene within an error (§4 of the paper: "a
//! near-optimal collection of wrappers that cover the input, given a limit on the size");
//! `docs/method.md`, "Covers".
//!
//! A **cover** is a cut of the Subset Tree — a set of nodes such that every leaf has exactly one
//! ancestor-or-self in the set — with one wrapper kind per chosen node ([`Fits::choose`]). A
//! node's error is the sphere-tree toolkit's measure from [`node_tightness`]: the largest
//! sampled distance from the wrapper's surface to the geometry below the node. A leaf may also
//! be drawn as its own primitive ([`CoverKind::Primitive`]), error 0, so every leaf qualifies.
//! [`min_cut`] finds the smallest cover within a tolerance and [`budget_tolerance`] the smallest
//! error for a budget of wrappers, both exactly. [`export`] writes a cover as JSON and OBJ;
//! [`solve`] computes one end to end.

pub mod export;
pub mod solve;

use super::hull::{Hull, hull_tree_until};
use super::kind::{WrapperKind, Wrappers};
use super::tightness::node_tightness;
use crate::grouping::SubsetTree;
use crate::scene::Scene;
use crate::stop::{Interrupted, Stop};

/// Kinds within this fraction of the smallest error count as tied (then the cheapest wins).
pub const TIE_REL: f64 = 0.10;
/// Absolute tie slack, times the scene diagonal (sampling rounding on exact fits).
pub const TIE_ABS_REL: f64 = 1e-9;

/// What a cover draws for one node: a wrapper kind, or a leaf's own primitive.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CoverKind {
    /// The leaf's primitive itself (error 0; leaves only).
    Primitive,
    /// Bounding sphere.
    Sphere,
    /// Axis-aligned box.
    Box,
    /// Oriented box.
    Obb,
    /// Convex hull.
    Hull,
}

impl CoverKind {
    /// The name used in JSON and OBJ group names.
    pub fn name(self) -> &'static str {
        match self {
            CoverKind::Primitive => "primitive",
            CoverKind::Sphere => "sphere",
            CoverKind::Box => "box",
            CoverKind::Obb => "obb",
            CoverKind::Hull => "hull",
        }
    }

    fn of(k: WrapperKind) -> CoverKind {
        match k {
            WrapperKind::Sphere => CoverKind::Sphere,
            WrapperKind::Box => CoverKind::Box,
            WrapperKind::Obb => CoverKind::Obb,
            WrapperKind::Hull => CoverKind::Hull,
        }
    }

    /// Order among equal costs: sphere, box, obb, primitive, hull.
    fn rank(self) -> u8 {
        match self {
            CoverKind::Sphere => 0,
            CoverKind::Box => 1,
            CoverKind::Obb => 2,
            CoverKind::Primitive => 3,
            CoverKind::Hull => 4,
        }
    }
}

/// Relative cost of one query against a wrapper: sphere 1, box 2, obb 3, hull or primitive
/// 4 + vertices / 16 (`vertices` is ignored for the others).
pub fn query_cost(kind: CoverKind, vertices: usize) -> f64 {
    match kind {
        CoverKind::Sphere => 1.0,
        CoverKind::Box => 2.0,
        CoverKind::Obb => 3.0,
        CoverKind::Hull | CoverKind::Primitive => 4.0 + vertices as f64 / 16.0,
    }
}

/// One way to draw a node: its kind, sampled error and query cost.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Candidate {
    /// Kind.
    pub kind: CoverKind,
    /// Largest sampled surface-to-geometry distance.
    pub error: f64,
    /// [`query_cost`].
    pub cost: f64,
}

/// One node of a cover.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct CoverNode {
    /// Subset Tree node id.
    pub node: u32,
    /// The chosen kind, its error and cost.
    #[serde(flatten)]
    pub choice: Candidate,
}

/// A cut of the Subset Tree with a kind per node, sorted by node id.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Cover {
    /// The tolerance the cut was built for (every node's error is ≤ it).
    pub tolerance: f64,
    /// The chosen nodes.
    pub nodes: Vec<CoverNode>,
}

impl Cover {
    /// Largest error over the cover's nodes.
    pub fn max_error(&self) -> f64 {
        self.nodes
            .iter()
            .map(|n| n.choice.error)
            .fold(0.0, f64::max)
    }

    /// Sum of the query costs.
    pub fn cost(&self) -> f64 {
        self.nodes.iter().map(|n| n.choice.cost).sum()
    }
}

/// Every node's candidates (index = node id) and best error.
#[derive(Clone, Debug)]
pub struct Fits {
    /// Candidates of every node.
    pub options: Vec<Vec<Candidate>>,
    /// Smallest candidate error of every node (0 for leaves).
    pub best: Vec<f64>,
    /// Absolute tie slack ([`TIE_ABS_REL`] × scene diagonal).
    pub tie_abs: f64,
}

impl Fits {
    /// Measures every kind of `wrappers` on every node with `samples` surface samples
    /// ([`node_tightness`]); leaves also get [`CoverKind::Primitive`]. `hulls` are the hulls of
    /// the same tree (reference volumes, hull vertex counts); built when `None`. `stop` is
    /// obeyed throughout.
    pub fn measure(
        tree: &SubsetTree,
        scene: &Scene,
        wrappers: &Wrappers,
        hulls: Option<&[Hull]>,
        samples: usize,
        stop: &Stop,
    ) -> Result<Fits, Interrupted> {
        let built;
        let hulls = match hulls.or(wrappers.hulls.as_deref()) {
            Some(h) => h,
            None => {
                built = hull_tree_until(tree, scene, stop)?;
                &built
            }
        };
        let mut options: Vec<Vec<Candidate>> = (0..tree.len())
            .map(|x| {
                if x < tree.leaves() {
                    let v = scene.prim(x).len();
                    vec![Candidate {
                        kind: CoverKind::Primitive,
                        error: 0.0,
                        cost: query_cost(CoverKind::Primitive, v),
                    }]
                } else {
                    Vec::new()
                }
            })
            .collect();
        for w in wrappers.trees() {
            stop.check()?;
            let kind = CoverKind::of(w.kind());
            let stats = node_tightness(tree, scene, w, hulls, samples, stop)?;
            for (x, s) in stats.iter().enumerate() {
                let error = if s.error.is_finite() {
                    s.error
                } else {
                    f64::MAX
                };
                options[x].push(Candidate {
                    kind,
                    error,
                    cost: query_cost(kind, hulls[x].vertices.len()),
                });
            }
        }
        Ok(Fits::from_options(
            options,
            scene.aabb().diameter() * TIE_ABS_REL,
        ))
    }

    /// Fits from given candidates (each node needs at least one; leaves are always taken).
    pub fn from_options(options: Vec<Vec<Candidate>>, tie_abs: f64) -> Fits {
        let best = options
            .iter()
            .map(|o| o.iter().map(|c| c.error).fold(f64::INFINITY, f64::min))
            .collect();
        Fits {
            options,
            best,
            tie_abs: tie_abs.max(0.0),
        }
    }

    /// The kind drawn for node `x` under tolerance `cap`: among candidates with error ≤ `cap`
    /// within 10 % (+ the absolute slack) of the best error, the cheapest (then sphere, box,
    /// obb, primitive, hull); when none is ≤ `cap` (a leaf over a negative cap), the best.
    pub fn choose(&self, x: u32, cap: f64) -> Candidate {
        let o = &self.options[x as usize];
        let best = self.best[x as usize];
        let limit = (best * (1.0 + TIE_REL) + self.tie_abs).min(cap.max(best));
        o.iter()
            .filter(|c| c.error <= limit)
            .min_by(|a, b| {
                a.cost
                    .total_cmp(&b.cost)
                    .then(a.kind.rank().cmp(&b.kind.rank()))
            })
            .or_else(|| o.iter().min_by(|a, b| a.error.total_cmp(&b.error)))
            .copied()
            .expect("every node has a candidate")
    }

    /// The smallest cover with every error ≤ `t` ([`min_cut`]).
    pub fn cover_tolerance(&self, tree: &SubsetTree, t: f64) -> Cover {
        let nodes = min_cut(tree, &self.best, t)
            .into_iter()
            .map(|node| CoverNode {
                node,
                choice: self.choose(node, t),
            })
            .collect();
        Cover {
            tolerance: t,
            nodes,
        }
    }

    /// The cover of at most `k` nodes with the smallest largest error ([`budget_tolerance`]);
    /// fails for `k = 0`.
    pub fn cover_budget(&self, tree: &SubsetTree, k: usize) -> Result<Cover, String> {
        let t = budget_tolerance(tree, &self.best, k).ok_or_else(|| {
            "a budget of 0 wrappers cannot cover the scene (want ≥ 1)".to_string()
        })?;
        Ok(self.cover_tolerance(tree, t))
    }
}

/// Whether an error is within the tolerance (NaN never is).
fn qualifies(e: f64, t: f64) -> bool {
    e.partial_cmp(&t).is_some_and(|o| o.is_le())
}

/// Size of the smallest cut of every subtree with each node's `err ≤ t` (leaves always
/// qualify); index = node id, the root's entry is the answer. O(N), bottom-up over the ids.
pub fn min_cut_sizes(tree: &SubsetTree, err: &[f64], t: f64) -> Vec<usize> {
    let mut size = vec![1usize; tree.len()];
    for x in tree.leaves()..tree.len() {
        if !qualifies(err[x], t) {
            let [a, b] = tree.children_of(x as u32).expect("interior node");
            size[x] = size[a as usize] + size[b as usize];
        }
    }
    size
}

/// The smallest cut with each node's `err ≤ t` (leaves always qualify), sorted by id: a node is
/// taken when it qualifies, else its children are searched.
///
/// Optimal, by one bottom-up pass ([`min_cut_sizes`]), `size(x) = 1` if `err(x) ≤ t` (always
/// for leaves), else `size(a) + size(b)`. Any cut of a subtree has at least one node, so when
/// the subtree's root qualifies, `{x}` is optimal; when it does not, every cut of the subtree is
/// a cut of the left subtree joined with one of the right, chosen independently, so the sum of
/// the two optimal sizes is optimal. Error need not be monotone along the tree (it is sampled,
/// and a parent's sphere can fit better than a child's box).
pub fn min_cut(tree: &SubsetTree, err: &[f64], t: f64) -> Vec<u32> {
    let mut out = Vec::new();
    let mut stack = vec![tree.root()];
    while let Some(x) = stack.pop() {
        match tree.children_of(x) {
            Some([a, b]) if !qualifies(err[x as usize], t) => stack.extend([b, a]),
            _ => out.push(x),
        }
    }
    out.sort_unstable();
    out
}

/// The smallest largest error achievable by a cut of at most `k` nodes (leaves count as
/// error 0), by binary search over the distinct interior errors; `None` for `k = 0`.
///
/// Exact, in O(N log N): the smallest cut's size under tolerance T is non-increasing in T and
/// the optimal largest error is one of the nodes' errors, so the smallest such error with a cut
/// of at most `k` nodes is the answer; the cut for it is then the smallest one with that error.
pub fn budget_tolerance(tree: &SubsetTree, err: &[f64], k: usize) -> Option<f64> {
    if k == 0 {
        return None;
    }
    let mut values: Vec<f64> = err[tree.leaves()..]
        .iter()
        .copied()
        .filter(|e| e.is_finite() && *e >= 0.0)
        .collect();
    values.push(0.0);
    values.sort_by(f64::total_cmp);
    values.dedup();
    let fits = |t: f64| min_cut_sizes(tree, err, t)[tree.root() as usize] <= k;
    // The root alone (size 1 ≤ k) is feasible at its own error, so the largest value is.
    let i = values.partition_point(|&t| !fits(t));
    Some(values[i.min(values.len() - 1)])
}

/// One uniform depth cut against the cover of the same error.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LevelRow {
    /// Depth d of the cut [`SubsetTree::level`].
    pub depth: u32,
    /// Nodes in the level's cut.
    pub level_nodes: usize,
    /// Largest best error over the level's nodes.
    pub level_max_error: f64,
    /// Size of the smallest cover with every error ≤ that.
    pub cover_nodes: usize,
}

/// For every depth, the level's size and largest error, and the smallest cover's size at that
/// error (never larger: the level is itself such a cut).
pub fn compare_levels(tree: &SubsetTree, err: &[f64]) -> Vec<LevelRow> {
    (0..=tree.depth_max())
        .map(|d| {
            let cut = tree.level(d);
            let level_max_error = cut
                .iter()
                .filter(|&&x| !tree.is_leaf(x))
                .map(|&x| err[x as usize])
                .fold(0.0, f64::max);
            LevelRow {
                depth: d,
                level_nodes: cut.len(),
                level_max_error,
                cover_nodes: min_cut_sizes(tree, err, level_max_error)[tree.root() as usize],
            }
        })
        .collect()
}
