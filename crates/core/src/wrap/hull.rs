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
use crate::stop::{Interrupted, Stop};

/// One hull per Subset Tree node (index = node id).
pub fn hull_tree(tree: &SubsetTree, scene: &Scene) -> Vec<Hull> {
    match hull_tree_until(tree, scene, &Stop::new()) {
        Ok(hulls) => hulls,
        Err(Interrupted) => unreachable!("a new stop token is never set"),
    }
}

/// [`hull_tree`], checking `stop` before each interior node and every [`STRIDE`](crate::stop::STRIDE) leaves.
pub fn hull_tree_until(
    tree: &SubsetTree,
    scene: &Scene,
    stop: &Stop,
) -> Result<Vec<Hull>, Interrupted> {
    let n = tree.leaves();
    let mut hulls: Vec<Hull> = Vec::with_capacity(tree.len());
    for leaf in 0..n {
        stop.check_every(leaf)?;
        hulls.push(hull_of(scene.prim_vertices(leaf).copied().collect()));
    }
    for [a, b] in &tree.children {
        stop.check()?;
        let [ha, hb] = [*a, *b].map(|c| &hulls[c as usize].vertices);
        let pts: Vec<P3> = ha.iter().chain(hb).copied().collect();
        hulls.push(hull_of(pts));
    }
    Ok(hulls)
}
