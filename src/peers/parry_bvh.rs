//! parry3d's `Bvh`, built with its binned SAH strategy (Wald, "On fast Construction of SAH-based
//! Bounding Volume Hierarchies", 2007) or its sequential PLOC (Meister and Bittner, 2018).
//!
//! parry keeps its nodes private, so the topology is read back through its public depth-first
//! traversal (`Bvh::traverse_indexed`), which visits both children of every wide node before
//! descending into the left one and then the right one: a pre-order over sibling pairs.

use super::topology::Node;
use parry3d::bounding_volume::Aabb;
use parry3d::math::Vector;
use parry3d::partitioning::{Bvh, BvhBuildStrategy, TraversalAction};

/// Builds parry's BVH over the primitive boxes (the timed part).
pub fn build(boxes: &[([f32; 3], [f32; 3])], strategy: BvhBuildStrategy) -> Bvh {
    let leaves: Vec<Aabb> = boxes
        .iter()
        .map(|(lo, hi)| Aabb::new(Vector::from_array(*lo), Vector::from_array(*hi)))
        .collect();
    Bvh::from_leaves(strategy, &leaves)
}

/// Reads `bvh`'s topology as [`Node`]s; returns the nodes and the root's index.
pub fn topology(bvh: &Bvh) -> (Vec<Node>, u32) {
    let mut visits: Vec<Option<u32>> = Vec::new();
    bvh.traverse_indexed(None, |node, _| {
        visits.push(node.leaf_data());
        TraversalAction::Continue
    });
    let mut nodes = Vec::with_capacity(visits.len() + 1);
    if visits.len() == 1 {
        nodes.push(Node::Leaf(visits[0].unwrap_or(0)));
        return (nodes, 0);
    }
    // Each visited pair is one interior node; its internal children's pairs follow in
    // pre-order, so the holes to fill form a stack (left child's hole on top).
    let mut holes: Vec<(u32, usize)> = Vec::new();
    let mut root = u32::MAX;
    for pair in visits.chunks(2) {
        let me = nodes.len() as u32;
        nodes.push(Node::Inner(u32::MAX, u32::MAX));
        match holes.pop() {
            Some((parent, slot)) => set_child(&mut nodes, parent, slot, me),
            None => root = me,
        }
        let mut pending = Vec::new();
        for (slot, leaf) in pair.iter().enumerate() {
            match leaf {
                Some(p) => {
                    let l = nodes.len() as u32;
                    nodes.push(Node::Leaf(*p));
                    set_child(&mut nodes, me, slot, l);
                }
                None => pending.push((me, slot)),
            }
        }
        holes.extend(pending.into_iter().rev());
    }
    (nodes, root)
}

fn set_child(nodes: &mut [Node], parent: u32, slot: usize, child: u32) {
    if let Node::Inner(a, b) = &mut nodes[parent as usize] {
        *[a, b][slot] = child;
    }
}
