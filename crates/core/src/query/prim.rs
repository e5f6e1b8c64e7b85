//! Primitive tests: exact `f64` distances between two primitives' surfaces.
//!
//! A primitive is its triangles ([`Scene::prim_tris`]), or when it has none the closed polygon
//! through its vertices ([`Scene::prim`]), as in [`crate::wrap::distance::point_prim`] (the
//! point–primitive distance). Two triangles are 0 apart when an edge of one crosses the other,
//! otherwise the minimum of 6 vertex–triangle and 9 edge–edge distances
//! ([`triangle_triangle`]); degenerate triangles and segments are measured as their edges and
//! points. Two primitives *touch* when their distance is 0; scenes overlap when some pair
//! touches.

use crate::geom::P3;
use crate::geom::distance::{segment_segment, segment_triangle, triangle_triangle};
use crate::scene::Scene;

/// The surface pieces of one primitive.
enum Surface<'a> {
    /// Triangles (vertex indices).
    Tris(&'a [[u32; 3]]),
    /// The closed polygon through these vertex indices, as segments.
    Edges(&'a [u32]),
}

impl Surface<'_> {
    fn of(scene: &Scene, i: usize) -> Surface<'_> {
        let tris = scene.prim_tris(i);
        if tris.is_empty() {
            Surface::Edges(scene.prim(i))
        } else {
            Surface::Tris(tris)
        }
    }
}

/// The `k`-th edge of the closed polygon `v` (a point when `v` has one vertex).
fn edge<'a>(scene: &'a Scene, v: &[u32], k: usize) -> (&'a P3, &'a P3) {
    let pt = |i: u32| &scene.points[i as usize];
    (pt(v[k]), pt(v[(k + 1) % v.len()]))
}

/// The corners of triangle `t` of `s`.
fn tri<'a>(s: &'a Scene, t: &[u32; 3]) -> [&'a P3; 3] {
    [
        &s.points[t[0] as usize],
        &s.points[t[1] as usize],
        &s.points[t[2] as usize],
    ]
}

/// Exact distance between primitive `i` of `a` and primitive `j` of `b` (their surfaces);
/// stops at the first piece pair at distance 0. A primitive with neither triangles nor
/// vertices is infinitely far.
pub fn prim_prim(a: &Scene, i: usize, b: &Scene, j: usize) -> f64 {
    let mut best = f64::INFINITY;
    match (Surface::of(a, i), Surface::of(b, j)) {
        (Surface::Tris(t), Surface::Tris(u)) => {
            for x in t {
                let tx = tri(a, x);
                for y in u {
                    best = best.min(triangle_triangle(tx, tri(b, y)));
                    if best == 0.0 {
                        return 0.0;
                    }
                }
            }
        }
        (Surface::Tris(t), Surface::Edges(v)) => return tris_edges(a, t, b, v),
        (Surface::Edges(v), Surface::Tris(t)) => return tris_edges(b, t, a, v),
        (Surface::Edges(v), Surface::Edges(w)) => {
            for k in 0..v.len() {
                let (p, q) = edge(a, v, k);
                for m in 0..w.len() {
                    let (r, s) = edge(b, w, m);
                    best = best.min(segment_segment(p, q, r, s));
                    if best == 0.0 {
                        return 0.0;
                    }
                }
            }
        }
    }
    best
}

/// Distance between triangles `t` of scene `a` and the polygon edges `v` of scene `b`.
fn tris_edges(a: &Scene, t: &[[u32; 3]], b: &Scene, v: &[u32]) -> f64 {
    let mut best = f64::INFINITY;
    for x in t {
        let [p0, p1, p2] = x.map(|k| &a.points[k as usize]);
        for k in 0..v.len() {
            let (p, q) = edge(b, v, k);
            best = best.min(segment_triangle(p, q, p0, p1, p2));
            if best == 0.0 {
                return 0.0;
            }
        }
    }
    best
}

/// Whether primitive `i` of `a` touches primitive `j` of `b`: [`prim_prim`] is 0, with the
/// triangle pairs that either triangle's plane clearly separates skipped first (the other's
/// corners all on one side of it by more than 1e-9 of the pair's extent, far beyond the
/// distance's rounding), so most pairs that do not touch cost three dot products, not the
/// distance.
pub fn prims_touch(a: &Scene, i: usize, b: &Scene, j: usize) -> bool {
    let (Surface::Tris(t), Surface::Tris(u)) = (Surface::of(a, i), Surface::of(b, j)) else {
        return prim_prim(a, i, b, j) == 0.0;
    };
    t.iter().any(|x| {
        let tx = tri(a, x);
        u.iter().any(|y| {
            let uy = tri(b, y);
            !separated(tx, uy) && !separated(uy, tx) && triangle_triangle(tx, uy) == 0.0
        })
    })
}

/// Whether the plane of triangle `t` has every corner of `u` strictly on one side, each at
/// least 1e-9 of the pair's largest coordinate extent from it (false for a degenerate `t`).
fn separated(t: [&P3; 3], u: [&P3; 3]) -> bool {
    let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
    let s = u.map(|p| n.dot(&(p - t[0])));
    // The corner nearest the plane, if all are on one side (×|n|).
    let near = if s.iter().all(|&v| v > 0.0) {
        s[0].min(s[1]).min(s[2])
    } else if s.iter().all(|&v| v < 0.0) {
        -s[0].max(s[1]).max(s[2])
    } else {
        return false;
    };
    let (mut lo, mut hi) = (*t[0], *t[0]);
    for p in t.iter().chain(&u) {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let ext = (hi - lo).amax();
    // near / |n| > 1e-9 · ext, squared (false for a degenerate `t`: |n| = 0, or NaN).
    near * near > 1e-18 * ext * ext * n.norm_squared() && n.norm_squared() > 0.0
}
