//! How tightly a Wrapper Tree fits, level by level (cut [`SubsetTree::level`]):
//!
//! - total wrapper volume of the cut;
//! - its ratio to the covered geometry's volume: the sum over the cut's nodes of the volume of
//!   the convex hull of the primitives under the node, or of the node's AABB where that hull is
//!   flat (a single polygon, coplanar sets); `None` when that sum is 0;
//! - the sphere-tree toolkit's error (Bradshaw & O'Sullivan): the largest distance from a
//!   wrapper's surface to the geometry it covers, worst and mean over the cut's nodes.
//!
//! The error is sampled: [`DEFAULT_SAMPLES`] points per wrapper — a Fibonacci lattice on
//! spheres; on hulls and boxes, one point per equal share of the surface area (stratified by
//! cumulative triangle area, placed inside the triangle by an R2 low-discrepancy sequence);
//! evenly spaced on segment hulls. Each sample's distance to the node's primitives is exact in
//! `f64` (point–triangle), found by descending the Subset Tree with AABB bounds, so the cost is
//! a fixed number of tree queries per node. Sampling can only under-estimate the true maximum.

use super::distance::point_node;
use super::hull::{BOX_TRIANGLES, Hull};
use super::kind::WrapperTree;
use super::obb::Obb;
use crate::geom::{P3, Sphere, V3};
use crate::grouping::SubsetTree;
use crate::scene::Scene;
use std::cmp::Ordering::Greater;

/// Surface samples per wrapper for the error measure.
pub const DEFAULT_SAMPLES: usize = 64;

/// Tightness of one level's cut.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LevelStats {
    /// Depth d of the cut.
    pub depth: u32,
    /// Nodes in the cut.
    pub nodes: usize,
    /// Interior nodes among them.
    pub interior: usize,
    /// Sum of the wrappers' volumes.
    pub volume: f64,
    /// Sum of the covered geometry's hull volumes (AABB volume where the hull is flat).
    pub reference_volume: f64,
    /// `volume / reference_volume`, `None` when the reference is 0.
    pub volume_ratio: Option<f64>,
    /// Largest sampled surface-to-geometry distance over the cut.
    pub error_max: f64,
    /// Mean over the cut's nodes of each node's largest sampled distance.
    pub error_mean: f64,
}

/// Per-node tightness: wrapper volume, reference volume and sampled error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeStats {
    /// Wrapper volume.
    pub volume: f64,
    /// Covered geometry's hull volume (AABB volume where the hull is flat).
    pub reference_volume: f64,
    /// Largest sampled distance from the wrapper's surface to the node's primitives.
    pub error: f64,
}

/// Tightness of every node of `w`; `hulls` is the hull Wrapper Tree of the same tree (the
/// reference volumes).
pub fn node_tightness(
    tree: &SubsetTree,
    scene: &Scene,
    w: WrapperTree<'_>,
    hulls: &[Hull],
    samples: usize,
) -> Vec<NodeStats> {
    let mut pts = Vec::with_capacity(samples);
    let mut stack = Vec::new();
    (0..tree.len() as u32)
        .map(|x| {
            let i = x as usize;
            pts.clear();
            let volume = surface_samples(w, i, samples, &mut pts);
            let error = pts
                .iter()
                .map(|p| point_node(tree, scene, x, p, &mut stack))
                .fold(0.0, f64::max);
            let h = &hulls[i];
            let reference_volume = if h.dim == 3 {
                h.volume()
            } else {
                tree.aabb[i].volume()
            };
            NodeStats {
                volume,
                reference_volume,
                error,
            }
        })
        .collect()
}

/// Tightness of the cuts at depths 0..=depth max (see the [module docs](self)).
pub fn level_tightness(
    tree: &SubsetTree,
    scene: &Scene,
    w: WrapperTree<'_>,
    hulls: &[Hull],
    samples: usize,
) -> Vec<LevelStats> {
    let nodes = node_tightness(tree, scene, w, hulls, samples);
    (0..=tree.depth_max())
        .map(|d| levels_of(tree, &nodes, d))
        .collect()
}

/// Aggregates per-node stats over the cut at depth `d`.
pub fn levels_of(tree: &SubsetTree, nodes: &[NodeStats], d: u32) -> LevelStats {
    let cut = tree.level(d);
    let (mut volume, mut reference_volume, mut error_max, mut sum) = (0.0, 0.0, 0.0f64, 0.0);
    for &x in &cut {
        let s = &nodes[x as usize];
        volume += s.volume;
        reference_volume += s.reference_volume;
        error_max = error_max.max(s.error);
        sum += s.error;
    }
    LevelStats {
        depth: d,
        nodes: cut.len(),
        interior: cut.iter().filter(|&&x| !tree.is_leaf(x)).count(),
        volume,
        reference_volume,
        volume_ratio: (reference_volume > 0.0).then(|| volume / reference_volume),
        error_max,
        error_mean: sum / cut.len().max(1) as f64,
    }
}

/// Appends `n` samples on the surface of wrapper `i` to `out`; returns its volume.
fn surface_samples(w: WrapperTree<'_>, i: usize, n: usize, out: &mut Vec<P3>) -> f64 {
    match w {
        WrapperTree::Spheres(s) => {
            sphere_samples(&s[i], n, out);
            s[i].volume()
        }
        WrapperTree::Hulls(h) => {
            let h = &h[i];
            match h.vertices.as_slice() {
                [a] => out.push(*a),
                [a, b] if h.triangles.is_empty() => {
                    out.extend((0..n).map(|k| a + (b - a) * ((k as f64 + 0.5) / n as f64)))
                }
                _ => triangle_samples(&h.vertices, &h.triangles, n, out),
            }
            h.volume()
        }
        WrapperTree::Boxes(b) => box_samples(&Obb::from_aabb(&b[i]), n, out),
        WrapperTree::Obbs(b) => box_samples(&b[i], n, out),
    }
}

fn box_samples(b: &Obb, n: usize, out: &mut Vec<P3>) -> f64 {
    let corners: Vec<P3> = (0..8).map(|k| b.corner(k)).collect();
    triangle_samples(&corners, &BOX_TRIANGLES, n, out);
    b.volume()
}

/// `n` points of a Fibonacci lattice on the sphere (the centre for radius 0).
fn sphere_samples(s: &Sphere, n: usize, out: &mut Vec<P3>) {
    if s.radius <= 0.0 {
        out.push(s.center);
        return;
    }
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    out.extend((0..n).map(|k| {
        let z = 1.0 - (2.0 * k as f64 + 1.0) / n as f64;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = golden * k as f64;
        s.center + V3::new(r * phi.cos(), r * phi.sin(), z) * s.radius
    }));
}

/// `n` area-stratified points on the triangles (their vertices when the area is 0).
fn triangle_samples(v: &[P3], tris: &[[u32; 3]], n: usize, out: &mut Vec<P3>) {
    let corner = |t: &[u32; 3]| t.map(|i| v[i as usize]);
    let mut cum = Vec::with_capacity(tris.len());
    let mut total = 0.0;
    for t in tris {
        let [a, b, c] = corner(t);
        total += (b - a).cross(&(c - a)).norm() / 2.0;
        cum.push(total);
    }
    if total.partial_cmp(&0.0) != Some(Greater) {
        out.extend_from_slice(v);
        return;
    }
    // R2 sequence (Roberts 2018): plastic-number increments.
    let (a1, a2) = (0.754_877_666_246_692_7, 0.569_840_290_998_053_3);
    for k in 0..n {
        let target = (k as f64 + 0.5) / n as f64 * total;
        let t = cum.partition_point(|&c| c < target).min(tris.len() - 1);
        let [a, b, c] = corner(&tris[t]);
        let r1 = (0.5 + a1 * k as f64).fract();
        let r2 = (0.5 + a2 * k as f64).fract();
        let s = r1.sqrt();
        out.push(P3::from(
            a.coords * (1.0 - s) + b.coords * (s * (1.0 - r2)) + c.coords * (s * r2),
        ));
    }
}

/// How far the farthest vertex below each node lies outside its wrapper (≤ 0 when all are
/// inside; spheres and boxes report distance beyond the surface, hulls the largest face-plane
/// excess, see [`Hull::excess`]).
pub fn containment_excess(tree: &SubsetTree, scene: &Scene, w: WrapperTree<'_>) -> Vec<f64> {
    let order = super::order::LeafOrder::new(tree, scene);
    (0..tree.len() as u32)
        .map(|x| {
            let i = x as usize;
            let pts = order.node_points(x);
            let f = |p: &P3| match w {
                WrapperTree::Spheres(s) => (p - s[i].center).norm() - s[i].radius,
                WrapperTree::Hulls(h) => h[i].excess(p),
                WrapperTree::Boxes(b) => Obb::from_aabb(&b[i]).excess(p),
                WrapperTree::Obbs(b) => b[i].excess(p),
            };
            pts.iter().map(f).fold(f64::NEG_INFINITY, f64::max)
        })
        .collect()
}
