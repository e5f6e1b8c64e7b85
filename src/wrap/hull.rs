//! Convex-hull Wrapper Trees.
//!
//! A leaf's hull is the hull of its primitive's vertices; an interior node's hull is the hull of
//! its children's hull vertices (the hull of a union is the hull of the hulls, §2.4), so every
//! vertex is visited O(depth) times. The point-set hull itself, with its degenerate cases and
//! tolerance, is [`crate::geom::hull`].

use crate::geom::P3;
pub use crate::geom::hull::{BOX_TRIANGLES, FLAT_REL, HULL_TOL_REL, Hull, hull_of};
use crate::grouping::SubsetTree;
use crate::scene::Scene;

/// One hull per Subset Tree node (index = node id).
pub fn hull_tree(tree: &SubsetTree, scene: &Scene) -> Vec<Hull> {
    let n = tree.leaves();
    let mut hulls = Vec::with_capacity(tree.len());
    // Points whose hull is the node's exact hull, kept only where the hull is a fallback box.
    let mut support: Vec<Option<Vec<P3>>> = Vec::with_capacity(tree.len());
    for leaf in 0..n {
        let pts: Vec<P3> = scene.prim_vertices(leaf).copied().collect();
        let (h, s) = hull_of(pts);
        hulls.push(h);
        support.push(s);
    }
    for [a, b] in &tree.children {
        let mut pts = Vec::new();
        for c in [*a as usize, *b as usize] {
            match support[c].take() {
                Some(s) => pts.extend(s),
                None => pts.extend_from_slice(&hulls[c].vertices),
            }
        }
        let (h, s) = hull_of(pts);
        hulls.push(h);
        support.push(s);
    }
    hulls
}
