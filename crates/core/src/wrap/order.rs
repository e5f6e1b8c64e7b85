//! Leaves in depth-first order, so every node's leaves (and their vertices) are one contiguous
//! slice: the per-node builders then visit each leaf vertex once per ancestor, O(N log N) for a
//! tree of depth O(log N) (§2.4).

use crate::geom::P3;
use crate::grouping::SubsetTree;
use crate::scene::Scene;

/// The leaves of a tree in depth-first order with their vertices laid out the same way.
#[derive(Clone, Debug)]
pub struct LeafOrder {
    /// Leaf ids in depth-first (left child first) order.
    pub leaves: Vec<u32>,
    /// Position in `leaves` of every node's first leaf.
    start: Vec<u32>,
    /// Number of leaves under every node.
    count: Vec<u32>,
    /// Vertex positions of the leaves, in `leaves` order (with repeats across primitives).
    points: Vec<P3>,
    /// Offsets into `points` per position in `leaves`, length N + 1.
    point_start: Vec<u32>,
}

impl LeafOrder {
    /// Lays out the leaves and vertices of `tree` (whose leaves are the primitives of `scene`).
    pub fn new(tree: &SubsetTree, scene: &Scene) -> LeafOrder {
        let n = tree.leaves();
        let total = tree.len();
        let mut count = vec![1u32; total];
        for (i, [a, b]) in tree.children.iter().enumerate() {
            count[n + i] = count[*a as usize] + count[*b as usize];
        }
        let mut start = vec![0u32; total];
        for (i, [a, b]) in tree.children.iter().enumerate().rev() {
            let s = start[n + i];
            start[*a as usize] = s;
            start[*b as usize] = s + count[*a as usize];
        }
        let mut leaves = vec![0u32; n];
        for leaf in 0..n {
            leaves[start[leaf] as usize] = leaf as u32;
        }
        let mut points = Vec::with_capacity(scene.vertex_refs());
        let mut point_start = Vec::with_capacity(n + 1);
        point_start.push(0);
        for &leaf in &leaves {
            points.extend(scene.prim_vertices(leaf as usize).copied());
            point_start.push(points.len() as u32);
        }
        LeafOrder {
            leaves,
            start,
            count,
            points,
            point_start,
        }
    }

    /// The leaves under `node`.
    pub fn node_leaves(&self, node: u32) -> &[u32] {
        let s = self.start[node as usize] as usize;
        &self.leaves[s..s + self.count[node as usize] as usize]
    }

    /// Every vertex of every primitive under `node` (with repeats).
    pub fn node_points(&self, node: u32) -> &[P3] {
        let s = self.start[node as usize] as usize;
        let e = s + self.count[node as usize] as usize;
        &self.points[self.point_start[s] as usize..self.point_start[e] as usize]
    }
}
