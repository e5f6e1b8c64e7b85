//! Exact `f64` point distances to triangles, segments and a node's primitives, with the Subset
//! Tree itself as the bounding-volume hierarchy (branch and bound on the nodes' AABBs).

use crate::geom::{Aabb, P3};
use crate::grouping::SubsetTree;
use crate::scene::Scene;
use std::cmp::Ordering::Greater;

/// Distance from `p` to the segment `a`–`b`.
pub fn point_segment(p: &P3, a: &P3, b: &P3) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

/// Distance from `p` to the triangle `a b c` (Ericson, "Real-Time Collision Detection" §5.1.5);
/// degenerate triangles are measured as their edges.
pub fn point_triangle(p: &P3, a: &P3, b: &P3, c: &P3) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let n2 = ab.cross(&ac).norm_squared();
    if n2.partial_cmp(&(1e-24 * ab.norm_squared() * ac.norm_squared())) != Some(Greater) {
        return point_segment(p, a, b)
            .min(point_segment(p, b, c))
            .min(point_segment(p, a, c));
    }
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.norm();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.norm();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (p - (a + ab * (d1 / (d1 - d3)))).norm();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.norm();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (p - (a + ac * (d2 / (d2 - d6)))).norm();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (p - (b + (c - b) * w)).norm();
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (p - (a + ab * v + ac * w)).norm()
}

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
    let mut best = f64::INFINITY;
    stack.clear();
    stack.push(node);
    while let Some(x) = stack.pop() {
        if point_aabb(p, &tree.aabb[x as usize]) >= best {
            continue;
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
