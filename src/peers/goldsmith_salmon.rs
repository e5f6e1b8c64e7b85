//! Goldsmith–Salmon incremental insertion (Goldsmith and Salmon, "Automatic Creation of Object
//! Hierarchies for Ray Tracing", IEEE CG&A 1987): the method the paper compares itself with.
//!
//! Primitives are inserted one at a time in a seeded random order (Goldsmith and Salmon found
//! random order better than input order). Each insertion walks down from the root: at a node it
//! compares the surface-area cost of making the new leaf that node's sibling with the cheaper
//! cost of descending into a child (the area the ancestors grow by is inherited), stops where
//! becoming a sibling is cheapest, and refits the ancestors' boxes on the way back up. This is
//! the greedy descent in Catto's formulation ("Dynamic Bounding Volume Hierarchies", GDC 2019).

use super::topology::Node;
use crate::geom::{Aabb, area};
use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;

/// Seed of the insertion order.
pub const ORDER_SEED: u64 = 0x6753_3187;

/// Builds the tree over primitive boxes `boxes`; returns the nodes and the root index.
pub fn build(boxes: &[Aabb]) -> (Vec<Node>, u32) {
    let n = boxes.len();
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.shuffle(&mut ChaCha8Rng::seed_from_u64(ORDER_SEED));
    let mut nodes: Vec<Node> = Vec::with_capacity(2 * n);
    let mut bbox: Vec<Aabb> = Vec::with_capacity(2 * n);
    let mut parent: Vec<u32> = Vec::with_capacity(2 * n);
    let mut root = 0u32;
    for (k, &p) in order.iter().enumerate() {
        let leaf = nodes.len() as u32;
        let lb = boxes[p as usize];
        nodes.push(Node::Leaf(p));
        bbox.push(lb);
        parent.push(u32::MAX);
        if k == 0 {
            root = leaf;
            continue;
        }
        // Descend to the best sibling.
        let mut x = root;
        let mut inherited = 0.0;
        while let Node::Inner(a, b) = nodes[x as usize] {
            let merged = area(&bbox[x as usize].merge(&lb));
            let here = 2.0 * merged + inherited;
            let grow = inherited + 2.0 * (merged - area(&bbox[x as usize]));
            let child_cost = |c: u32| {
                let m = area(&bbox[c as usize].merge(&lb));
                match nodes[c as usize] {
                    Node::Leaf(_) => m + grow,
                    Node::Inner(..) => m - area(&bbox[c as usize]) + grow,
                }
            };
            let (ca, cb) = (child_cost(a), child_cost(b));
            if here <= ca && here <= cb {
                break;
            }
            inherited = grow;
            x = if ca <= cb { a } else { b };
        }
        // New parent of `x` and the leaf.
        let new = nodes.len() as u32;
        let old_parent = parent[x as usize];
        nodes.push(Node::Inner(x, leaf));
        bbox.push(bbox[x as usize].merge(&lb));
        parent.push(old_parent);
        parent[x as usize] = new;
        parent[leaf as usize] = new;
        if old_parent == u32::MAX {
            root = new;
        } else if let Node::Inner(a, b) = &mut nodes[old_parent as usize] {
            if *a == x {
                *a = new;
            } else {
                *b = new;
            }
        }
        let mut up = old_parent;
        while up != u32::MAX {
            bbox[up as usize] = bbox[up as usize].merge(&lb);
            up = parent[up as usize];
        }
    }
    (nodes, root)
}
