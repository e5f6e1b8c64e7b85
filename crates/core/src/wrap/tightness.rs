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
//!
//! Measuring every node costs far more than building the tree, so summaries over a whole tree
//! ([`DepthSample`]) measure at most [`NODES_PER_DEPTH`] interior nodes per depth, drawn by a
//! seeded hash of their ids, each query stopping after [`MAX_VISITS`] node visits: a bounded
//! cost, and the same result for any thread count.

use super::distance::point_node_within;
use super::hull::{BOX_TRIANGLES, Hull};
use super::kind::WrapperTree;
use super::obb::Obb;
use crate::geom::{P3, Sphere, V3};
use crate::grouping::SubsetTree;
use crate::scene::Scene;
use crate::stop::{Interrupted, Stop};
use rayon::prelude::*;
use std::cmp::Ordering::Greater;

/// Surface samples per wrapper for the error measure.
pub const DEFAULT_SAMPLES: usize = 64;

/// Interior nodes per depth whose error a [`DepthSample`] measures.
pub const NODES_PER_DEPTH: usize = 64;

/// Node visits after which one sample's distance query of a [`DepthSample`] measurement keeps
/// the nearest primitive found so far (an upper bound, nearly always the exact distance).
pub const MAX_VISITS: usize = 4096;

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
/// reference volumes). [`Interrupted`] once `stop` is requested.
pub fn node_tightness(
    tree: &SubsetTree,
    scene: &Scene,
    w: WrapperTree<'_>,
    hulls: &[Hull],
    samples: usize,
    stop: &Stop,
) -> Result<Vec<NodeStats>, Interrupted> {
    let all: Vec<u32> = (0..tree.len() as u32).collect();
    nodes_tightness(tree, scene, w, hulls, samples, &all, usize::MAX, stop)
}

/// Tightness of the nodes `nodes` of `w`, in that order, each sample's query stopping after
/// `max_visits` node visits (see [`point_node_within`]); the nodes are measured in parallel,
/// with the same result for any thread count. `stop` is checked before each node.
#[allow(clippy::too_many_arguments)]
pub fn nodes_tightness(
    tree: &SubsetTree,
    scene: &Scene,
    w: WrapperTree<'_>,
    hulls: &[Hull],
    samples: usize,
    nodes: &[u32],
    max_visits: usize,
    stop: &Stop,
) -> Result<Vec<NodeStats>, Interrupted> {
    nodes
        .par_iter()
        .map_init(
            || (Vec::with_capacity(samples), Vec::new()),
            |(pts, stack), &x| {
                stop.check()?;
                let i = x as usize;
                pts.clear();
                let volume = surface_samples(w, i, samples, pts);
                let error = pts
                    .iter()
                    .map(|p| point_node_within(tree, scene, x, p, stack, max_visits))
                    .fold(0.0, f64::max);
                Ok(NodeStats {
                    volume,
                    reference_volume: reference_volume(tree, hulls, i),
                    error,
                })
            },
        )
        .collect()
}

/// The interior nodes a sampled tightness measurement visits, depth by depth: at each depth
/// every interior node when there are at most `per_depth`, else the `per_depth` whose
/// seeded hash of the id is smallest. The depths are the strata of a stratified estimate: a
/// mean over all interior nodes is the depths' sample means weighted by [`DepthSample::interior`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DepthSample {
    /// Interior nodes at each depth (index = depth).
    pub interior: Vec<usize>,
    /// The sampled interior nodes at each depth, ascending ids.
    pub nodes: Vec<Vec<u32>>,
}

impl DepthSample {
    /// Draws the sample of `tree` with `per_depth` nodes per depth and `seed`.
    pub fn new(tree: &SubsetTree, per_depth: usize, seed: u64) -> DepthSample {
        let depths = tree.depth_max() as usize + 1;
        let mut by_depth: Vec<Vec<u32>> = vec![Vec::new(); depths];
        for x in tree.leaves() as u32..tree.len() as u32 {
            by_depth[tree.depth[x as usize] as usize].push(x);
        }
        let interior = by_depth.iter().map(Vec::len).collect();
        let nodes = by_depth
            .into_iter()
            .map(|mut ids| {
                if ids.len() > per_depth {
                    ids.sort_unstable_by_key(|&x| (mix(seed ^ u64::from(x)), x));
                    ids.truncate(per_depth);
                    ids.sort_unstable();
                }
                ids
            })
            .collect();
        DepthSample { interior, nodes }
    }

    /// Every sampled node, depth by depth.
    pub fn flat(&self) -> Vec<u32> {
        self.nodes.concat()
    }

    /// `values` (one per node of [`DepthSample::flat`], `None` where a node has no value)
    /// summarised: the stratified mean over all interior nodes, and each depth's sample mean
    /// (0 for a depth without values).
    pub fn means(&self, values: &[Option<f64>]) -> (f64, Vec<f64>) {
        let mut rest = values;
        let (mut sum, mut weight) = (0.0, 0.0);
        let per_depth = self
            .nodes
            .iter()
            .zip(&self.interior)
            .map(|(ids, &count)| {
                let (here, next) = rest.split_at(ids.len());
                rest = next;
                let got: Vec<f64> = here.iter().flatten().copied().collect();
                if got.is_empty() {
                    return 0.0;
                }
                let mean = got.iter().sum::<f64>() / got.len() as f64;
                // Nodes without a value are as frequent among the unsampled ones.
                let w = count as f64 * got.len() as f64 / ids.len() as f64;
                sum += w * mean;
                weight += w;
                mean
            })
            .collect();
        (if weight > 0.0 { sum / weight } else { 0.0 }, per_depth)
    }
}

/// splitmix64: a well-mixed 64-bit hash of `x`.
fn mix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Volume of wrapper `i` of `w`.
fn wrapper_volume(w: WrapperTree<'_>, i: usize) -> f64 {
    match w {
        WrapperTree::Spheres(s) => s[i].volume(),
        WrapperTree::Hulls(h) => h[i].volume(),
        WrapperTree::Boxes(b) => Obb::from_aabb(&b[i]).volume(),
        WrapperTree::Obbs(b) => b[i].volume(),
    }
}

/// [`level_tightness`] with the error measured on a [`DepthSample`] of at most `per_depth`
/// interior nodes per depth (drawn with `seed`, each sample's query stopping after
/// [`MAX_VISITS`] node visits) and on every leaf; `per_depth` 0 measures every node exactly
/// ([`level_tightness`]). Volumes and nodes are exact; a level's error mean is the leaves' mean
/// and its depth's sample mean weighted by their counts, its error max the largest measured.
/// [`Interrupted`] once `stop` is requested.
pub fn level_tightness_sampled(
    tree: &SubsetTree,
    scene: &Scene,
    w: WrapperTree<'_>,
    hulls: &[Hull],
    samples: usize,
    (per_depth, seed): (usize, u64),
    stop: &Stop,
) -> Result<Vec<LevelStats>, Interrupted> {
    if per_depth == 0 {
        return level_tightness(tree, scene, w, hulls, samples, stop);
    }
    let sample = DepthSample::new(tree, per_depth, seed);
    let mut measured: Vec<u32> = (0..tree.leaves() as u32).collect();
    measured.extend(sample.flat());
    let stats = nodes_tightness(tree, scene, w, hulls, samples, &measured, MAX_VISITS, stop)?;
    let mut error = vec![None; tree.len()];
    for (&x, s) in measured.iter().zip(&stats) {
        error[x as usize] = Some(s.error);
    }
    let nodes: Vec<NodeStats> = (0..tree.len())
        .map(|i| NodeStats {
            volume: wrapper_volume(w, i),
            reference_volume: reference_volume(tree, hulls, i),
            error: error[i].unwrap_or(0.0),
        })
        .collect();
    Ok((0..=tree.depth_max())
        .map(|d| {
            let mut level = levels_of(tree, &nodes, d);
            let cut = tree.level(d);
            let (mut leaf_sum, mut inner_sum, mut inner_n) = (0.0, 0.0, 0usize);
            let mut error_max = 0.0f64;
            for &x in &cut {
                let Some(e) = error[x as usize] else { continue };
                error_max = error_max.max(e);
                if tree.is_leaf(x) {
                    leaf_sum += e;
                } else {
                    inner_sum += e;
                    inner_n += 1;
                }
            }
            let inner = match inner_n {
                0 => 0.0,
                k => level.interior as f64 * inner_sum / k as f64,
            };
            level.error_max = error_max;
            level.error_mean = (leaf_sum + inner) / cut.len().max(1) as f64;
            level
        })
        .collect())
}

/// The covered geometry's volume at node `i`: its hull's, or its AABB's where the hull is flat.
fn reference_volume(tree: &SubsetTree, hulls: &[Hull], i: usize) -> f64 {
    let h = &hulls[i];
    if h.dim == 3 {
        h.volume()
    } else {
        tree.aabb[i].volume()
    }
}

/// Tightness of the cuts at depths 0..=depth max (see the [module docs](self)).
/// [`Interrupted`] once `stop` is requested.
pub fn level_tightness(
    tree: &SubsetTree,
    scene: &Scene,
    w: WrapperTree<'_>,
    hulls: &[Hull],
    samples: usize,
    stop: &Stop,
) -> Result<Vec<LevelStats>, Interrupted> {
    let nodes = node_tightness(tree, scene, w, hulls, samples, stop)?;
    Ok((0..=tree.depth_max())
        .map(|d| levels_of(tree, &nodes, d))
        .collect())
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
///
/// Hulls test each distinct vertex once per node (a vertex shared by several primitives counts
/// once), as their test costs a pass over the faces.
pub fn containment_excess(tree: &SubsetTree, scene: &Scene, w: WrapperTree<'_>) -> Vec<f64> {
    match containment_excess_until(tree, scene, w, &Stop::new()) {
        Ok(excess) => excess,
        Err(Interrupted) => unreachable!("a new stop token is never set"),
    }
}

/// [`containment_excess`], checking `stop` before each node.
pub fn containment_excess_until(
    tree: &SubsetTree,
    scene: &Scene,
    w: WrapperTree<'_>,
    stop: &Stop,
) -> Result<Vec<f64>, Interrupted> {
    let order = super::order::LeafOrder::new(tree, scene);
    let max = |pts: &mut dyn Iterator<Item = &P3>, f: &dyn Fn(&P3) -> f64| {
        pts.map(f).fold(f64::NEG_INFINITY, f64::max)
    };
    (0..tree.len() as u32)
        .into_par_iter()
        .map_init(
            || vec![u32::MAX; scene.points.len()],
            |seen, x| {
                stop.check()?;
                let i = x as usize;
                let mut pts = order.node_points(x).iter();
                Ok(match w {
                    WrapperTree::Spheres(s) => {
                        max(&mut pts, &|p| (p - s[i].center).norm() - s[i].radius)
                    }
                    WrapperTree::Hulls(h) => {
                        let test = h[i].excess_test();
                        let mut distinct = order
                            .node_leaves(x)
                            .iter()
                            .flat_map(|&leaf| scene.prim(leaf as usize))
                            .filter(|&&k| std::mem::replace(&mut seen[k as usize], x) != x)
                            .map(|&k| &scene.points[k as usize]);
                        max(&mut distinct, &|p| test.excess(p))
                    }
                    WrapperTree::Boxes(b) => {
                        let b = Obb::from_aabb(&b[i]);
                        max(&mut pts, &|p| b.excess(p))
                    }
                    WrapperTree::Obbs(b) => max(&mut pts, &|p| b[i].excess(p)),
                })
            },
        )
        .collect()
}
