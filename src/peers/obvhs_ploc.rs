//! obvhs's PLOC builder (Meister and Bittner, "Parallel Locally-Ordered Clustering for Bounding
//! Volume Hierarchy Construction", 2018), optionally followed by its SAH reinsertion optimiser
//! (Meister and Bittner, "Parallel Reinsertion for Bounding Volume Hierarchy Optimization",
//! 2018), with one primitive per leaf, built with obvhs's `parallel` feature on the current rayon
//! pool (one thread in a one-thread pool).

use super::topology::Node;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::ploc::{PlocBuilder, PlocSearchDistance, SortPrecision};

/// PLOC search radius: obvhs's default (`Medium`, 14 neighbours each side).
pub const SEARCH: PlocSearchDistance = PlocSearchDistance::Medium;

/// Fraction of nodes reinserted per pass: obvhs's `medium_build` preset.
pub const REINSERTION_RATIO: f32 = 0.05;

/// Builds the BVH (the timed part); `reinsert` runs the reinsertion optimiser afterwards.
pub fn build(boxes: &[([f32; 3], [f32; 3])], reinsert: bool) -> Bvh2 {
    let aabbs: Vec<Aabb> = boxes
        .iter()
        .map(|(lo, hi)| Aabb::new((*lo).into(), (*hi).into()))
        .collect();
    let indices = (0..aabbs.len() as u32).collect();
    let mut bvh = PlocBuilder::with_capacity(aabbs.len()).build(
        SEARCH,
        &aabbs,
        indices,
        SortPrecision::U64,
        0,
    );
    if reinsert {
        ReinsertionOptimizer::default().run(&mut bvh, REINSERTION_RATIO, None);
    }
    bvh
}

/// Reads `bvh`'s topology as [`Node`]s (node 0 is the root). A leaf holding several primitives
/// (not produced with these settings) becomes a left-deep chain over them.
pub fn topology(bvh: &Bvh2) -> (Vec<Node>, u32) {
    let mut nodes: Vec<Node> = Vec::with_capacity(bvh.nodes.len());
    let mut extra = Vec::new();
    for n in &bvh.nodes {
        let first = n.first_index;
        if n.is_leaf() {
            let prims = &bvh.primitive_indices[first as usize..(first + n.prim_count) as usize];
            let mut cur = Node::Leaf(prims[0]);
            for &p in &prims[1..] {
                let base = (bvh.nodes.len() + extra.len()) as u32;
                extra.push(cur);
                extra.push(Node::Leaf(p));
                cur = Node::Inner(base, base + 1);
            }
            nodes.push(cur);
        } else {
            nodes.push(Node::Inner(first, first + 1));
        }
    }
    nodes.extend(extra);
    (nodes, 0)
}
