//! Brute-force answers: every primitive (pair) tested, no hierarchy. O(N) per point query and
//! O(N·M) per scene–scene query; the exact values the branch-and-bound queries must match.

use super::prim::prim_prim;
use crate::geom::P3;
use crate::scene::Scene;
use crate::wrap::distance::point_prim;

/// Distance from `p` to the nearest primitive surface of `scene`.
pub fn point_distance(scene: &Scene, p: &P3) -> f64 {
    (0..scene.len())
        .map(|i| point_prim(scene, i, p))
        .fold(f64::INFINITY, f64::min)
}

/// Distance between the primitive surfaces of `a` and `b` (stops early at 0).
pub fn scene_distance(a: &Scene, b: &Scene) -> f64 {
    let mut best = f64::INFINITY;
    for i in 0..a.len() {
        for j in 0..b.len() {
            best = best.min(prim_prim(a, i, b, j));
            if best == 0.0 {
                return 0.0;
            }
        }
    }
    best
}

/// Whether some primitive of `a` touches (is at distance 0 from) some primitive of `b`.
pub fn overlap(a: &Scene, b: &Scene) -> bool {
    scene_distance(a, b) == 0.0
}

/// How many primitive pairs of `a` and `b` touch (are at distance 0).
pub fn contacts(a: &Scene, b: &Scene) -> u64 {
    let touch = |i: usize| {
        (0..b.len())
            .filter(|&j| prim_prim(a, i, b, j) == 0.0)
            .count()
    };
    (0..a.len()).map(touch).sum::<usize>() as u64
}
