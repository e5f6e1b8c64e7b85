//! Exact `f64` point distances to triangles, segments and a node's primitives, with the Subset
//! Tree itself as the bounding-volume hierarchy (branch and bound on the nodes' AABBs).

pub use crate::geom::distance::{point_segment, point_triangle};
use crate::geom::{Aabb, P3};
use crate::grouping::SubsetTree;
use crate::scene::Scene;

/// Distance from `p` to the surface of primitive `i` (its triangles; its vertices and edges
/// when it has none). For a `p` outside a polyhedron this is the distance to the solid.
pub fn point_prim(scene: &Scene, i: usize, p: &P3) -> f64 {
    let pt = |v: u32| &scene.points[v as usize];
    let tris = scene.prim_tris(i);
    if !tris.is_empty() {
        return tris
            .iter()
            .map(|t| point_triangle(p, pt(t[0]), pt(t[1]), pt(t[2])))
            .fold(f64::INFINITY, f64::min);
    }
    let v = scene.prim(i);
    (0..v.len())
        .map(|k| point_segment(p, pt(v[k]), pt(v[(k + 1) % v.len()])))
        .fold(f64::INFINITY, f64::min)
}

/// Euclidean distance from `p` to a box (0 inside).
pub fn point_aabb(p: &P3, b: &Aabb) -> f64 {
    let d = (b.min - p)
        .sup(&(p - b.max))
        .sup(&nalgebra::Vector3::zeros());
    d.norm()
}

/// Distance from `p` to the nearest primitive under `node`, descending the Subset Tree and
/// skipping subtrees whose AABB is farther than the best distance so far.
pub fn point_node(
    tree: &SubsetTree,
    scene: &Scene,
    node: u32,
    p: &P3,
    stack: &mut Vec<u32>,
) -> f64 {
    point_node_within(tree, scene, node, p, stack, usize::MAX)
}

/// [`point_node`] that stops after `max_visits` node visits, once some primitive has been
/// reached: the distance to the nearest primitive found by then (the nearer child is searched
/// first, so usually the exact distance; never less than it).
pub fn point_node_within(
    tree: &SubsetTree,
    scene: &Scene,
    node: u32,
    p: &P3,
    stack: &mut Vec<u32>,
    max_visits: usize,
) -> f64 {
    let mut best = f64::INFINITY;
    let mut visits = 0usize;
    stack.clear();
    stack.push(node);
    while let Some(x) = stack.pop() {
        if point_aabb(p, &tree.aabb[x as usize]) >= best {
            continue;
        }
        visits += 1;
        if visits > max_visits && best.is_finite() {
            break;
        }
        match tree.children_of(x) {
            None => best = best.min(point_prim(scene, x as usize, p)),
            Some([a, b]) => {
                let da = point_aabb(p, &tree.aabb[a as usize]);
                let db = point_aabb(p, &tree.aabb[b as usize]);
                if da < db {
                    stack.extend([b, a]);
                } else {
                    stack.extend([a, b]);
                }
            }
        }
    }
    best
}
