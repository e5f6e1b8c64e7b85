//! Hierarchy queries: what the trees are for (§1.2, eq. (1)). A branch-and-bound query visits
//! part of a tree and makes a local query at each node it reaches, so its cost is
//! `N_v·C_v + N_p·C_p`: `N_v` bounding-volume tests at cost `C_v` and `N_p` primitive tests at
//! cost `C_p`. Every query here counts both in [`Counts`].
//!
//! - [`point_distance`] ([`point`]) — distance from a point to a scene, best-first;
//! - [`scene_distance`], [`overlap`] ([`pair`]) — scene–scene distance by branch and bound on
//!   the bounding-volume test tree (BVTT), and overlap with an early exit at the first touching
//!   primitive pair;
//! - [`fn@moved`] ([`mod@moved`]) — a rigidly moved copy of a tree and scene;
//! - [`mod@reference`] — brute force over all primitives, the exact answers the tests compare
//!   with;
//! - [`Workload`] and [`measure`] ([`workload`]) — a seeded standard workload and its mean cost
//!   ([`measure_until`] also obeys a stop request between queries).
//!
//! Primitives are their surfaces ([`prim`]); bounds are lowered by a slack ([`SLACK_ULPS`]), so
//! rounding never prunes the true answer. The `…_within` forms stop a query after a number of
//! tests ([`MAX_TESTS_PER_PRIM`] per primitive in the workload) and count it in [`Counts::capped`]: exact ties (stacked
//! coincident copies of a part) make a scene–scene query test every tied pair, up to `n²`.

pub mod moved;
pub mod pair;
pub mod point;
pub mod prim;
pub mod reference;
pub mod workload;

pub use moved::{moved, moved_spheres};
pub use pair::{
    contacts, contacts_within, overlap, overlap_within, scene_distance, scene_distance_within,
};
pub use point::{point_distance, point_distance_within};
pub use workload::{
    C_P, C_V, MAX_TESTS_PER_PAIR, MAX_TESTS_PER_PRIM, MIN_MAX_TESTS, MeanCost, QueryCost, Workload,
    measure, measure_until,
};

use crate::geom::{Aabb, P3};
use crate::grouping::SubsetTree;
use crate::scene::Scene;
use crate::wrap::Sphere;
use crate::wrap::distance::point_aabb;
use std::cmp::Ordering;

/// Slack subtracted from every bound, in ulps (`f64::EPSILON`) of the larger of the root box's
/// largest absolute coordinate and its diagonal.
///
/// Boxes hold their vertices exactly (min/max), spheres up to rounding (the Wrapper Tree tests
/// allow 1e-9 × the scene diagonal, hence [`SPHERE_SLACK_REL`]). With the slack every bound is a
/// safe lower bound, so rounding never prunes the true answer; the cost is a few more tests on
/// near-ties.
pub const SLACK_ULPS: f64 = 64.0;

/// Extra slack for sphere bounds, relative to the root box diagonal: the containment tolerance
/// the sphere Wrapper Trees are tested to.
pub const SPHERE_SLACK_REL: f64 = 1e-9;

/// The bounding volume every node (interior or leaf) is tested with.
#[derive(Clone, Copy, Debug)]
pub enum Bv<'a> {
    /// The Subset Tree's own AABBs.
    Aabb,
    /// One sphere per node id, e.g. from [`crate::wrap::sphere_tree`]; must have
    /// `tree.len()` entries (indexing panics otherwise).
    Sphere(&'a [Sphere]),
}

/// A tree over a scene's primitives (leaf `i` = primitive `i`) with the BV its nodes are
/// tested with.
#[derive(Clone, Copy, Debug)]
pub struct Hierarchy<'a> {
    /// The Subset Tree (topology and AABBs).
    pub tree: &'a SubsetTree,
    /// The primitives.
    pub scene: &'a Scene,
    /// Which bounding volume bounds a node.
    pub bv: Bv<'a>,
}

/// Work done by queries: eq. (1)'s `N_v` and `N_p`.
///
/// A BV test is one node–point or node–node bound: point–AABB, point–sphere, AABB–AABB,
/// sphere–sphere (or AABB–sphere when the two hierarchies use different [`Bv`]s), on interior
/// nodes and leaves alike, the root included. A primitive test is one point–primitive or
/// primitive–primitive distance.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Counts {
    /// Bounding-volume tests (node–point or node–node bounds evaluated).
    pub bv_tests: u64,
    /// Primitive tests (point–primitive or primitive–primitive distances evaluated).
    pub prim_tests: u64,
    /// Queries stopped at their test cap (the `…_within` forms) before their answer was
    /// proven: a distance is then an upper bound, an overlap `false` unproven.
    pub capped: u64,
}

impl Counts {
    /// Adds `o` to these counts.
    pub fn add(&mut self, o: &Counts) {
        self.bv_tests += o.bv_tests;
        self.prim_tests += o.prim_tests;
        self.capped += o.capped;
    }

    /// BV and primitive tests together.
    pub fn tests(&self) -> u64 {
        self.bv_tests + self.prim_tests
    }

    /// Eq. (1): `N_v·c_v + N_p·c_p`.
    pub fn cost(&self, c_v: f64, c_p: f64) -> f64 {
        self.bv_tests as f64 * c_v + self.prim_tests as f64 * c_p
    }

    /// Means per query over `queries` queries: `(bv_tests, prim_tests)` (zeros for none).
    pub fn per_query(&self, queries: usize) -> (f64, f64) {
        if queries == 0 {
            return (0.0, 0.0);
        }
        let q = queries as f64;
        (self.bv_tests as f64 / q, self.prim_tests as f64 / q)
    }
}

impl Hierarchy<'_> {
    /// The slack subtracted from this hierarchy's bounds (see [`SLACK_ULPS`]).
    fn slack(&self) -> f64 {
        let root = &self.tree.aabb[self.tree.root() as usize];
        let diag = root.diameter();
        let coord = root.min.coords.abs().max().max(root.max.coords.abs().max());
        let mut s = SLACK_ULPS * f64::EPSILON * coord.max(diag);
        if let Bv::Sphere(_) = self.bv {
            s += SPHERE_SLACK_REL * diag;
        }
        if s.is_finite() { s } else { 0.0 }
    }

    /// Size of a node's BV (box diagonal or sphere diameter): the larger side is split.
    fn size(&self, node: u32) -> f64 {
        match self.bv {
            Bv::Aabb => self.tree.aabb[node as usize].diameter(),
            Bv::Sphere(s) => 2.0 * s[node as usize].radius,
        }
    }

    /// Lower bound on the distance from `p` to the primitives under `node`, before slack.
    fn point_bound(&self, node: u32, p: &P3) -> f64 {
        match self.bv {
            Bv::Aabb => point_aabb(p, &self.tree.aabb[node as usize]),
            Bv::Sphere(s) => {
                let s = &s[node as usize];
                (p - s.center).norm() - s.radius
            }
        }
    }
}

/// Euclidean distance between two boxes (0 when they touch or overlap).
fn aabb_aabb(a: &Aabb, b: &Aabb) -> f64 {
    let gap = (a.min - b.max)
        .sup(&(b.min - a.max))
        .sup(&nalgebra::Vector3::zeros());
    gap.norm()
}

/// Lower bound on the distance between the primitives under `x` in `a` and under `y` in `b`,
/// before slack.
fn pair_bound(a: &Hierarchy, x: u32, b: &Hierarchy, y: u32) -> f64 {
    let (x, y) = (x as usize, y as usize);
    match (a.bv, b.bv) {
        (Bv::Aabb, Bv::Aabb) => aabb_aabb(&a.tree.aabb[x], &b.tree.aabb[y]),
        (Bv::Sphere(s), Bv::Sphere(t)) => {
            (s[x].center - t[y].center).norm() - s[x].radius - t[y].radius
        }
        (Bv::Aabb, Bv::Sphere(t)) => point_aabb(&t[y].center, &a.tree.aabb[x]) - t[y].radius,
        (Bv::Sphere(s), Bv::Aabb) => point_aabb(&s[x].center, &b.tree.aabb[y]) - s[x].radius,
    }
}

/// How deeply the BVs of `x` in `a` and `y` in `b` overlap (larger: deeper), given their
/// [`pair_bound`] `bound`: for two boxes the sum over the axes of the overlap of their extents
/// (which separates boxes that touch in a face, where every bound is 0); otherwise `−bound`.
fn pair_depth(a: &Hierarchy, x: u32, b: &Hierarchy, y: u32, bound: f64) -> f64 {
    match (a.bv, b.bv) {
        (Bv::Aabb, Bv::Aabb) => {
            let (p, q) = (&a.tree.aabb[x as usize], &b.tree.aabb[y as usize]);
            (0..3)
                .map(|k| p.max[k].min(q.max[k]) - p.min[k].max(q.min[k]))
                .sum()
        }
        _ => -bound,
    }
}

/// A pending node (or node pair) of a best-first search, popped smallest bound first; ties go
/// to the deeper entry (so zero-bound runs descend rather than fan out), then to smaller ids.
#[derive(Clone, Copy, Debug)]
struct Entry {
    bound: f64,
    depth: u32,
    a: u32,
    b: u32,
}

impl PartialEq for Entry {
    fn eq(&self, o: &Entry) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}

impl Eq for Entry {}

impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Entry) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl Ord for Entry {
    /// "Greater" pops first from `BinaryHeap` (a max-heap).
    fn cmp(&self, o: &Entry) -> Ordering {
        o.bound
            .total_cmp(&self.bound)
            .then(self.depth.cmp(&o.depth))
            .then(o.a.cmp(&self.a))
            .then(o.b.cmp(&self.b))
    }
}
