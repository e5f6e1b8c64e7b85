//! The convex-hull p-set (§2.2's slower variant): a body is the convex hull of its primitives'
//! vertices, its diameter the largest distance between two of them, and the gap between two
//! bodies their L2 distance (GJK on the two vertex sets, via parry).
//!
//! Vertices stay `f64`; parry (`f32`) sees them relative to the pair's AABB centre. A merged
//! body keeps the vertices of the hull of both vertex sets, from [`crate::geom::hull::hull_of`]
//! (the same exact hull the Wrapper Trees use). Sets flat or collinear to within
//! [`crate::geom::hull::FLAT_REL`] of their extent are hulled as polygons or segments, so a
//! body may drop points that far from its hull; a merge's own diameter is always computed from
//! both children's full vertex sets.

use super::pset::PSetBodies;
use crate::geom::hull::hull_of;
use crate::geom::{Aabb, P3, to_glam_local};
use crate::scene::Scene;
use parry3d::math::{Pose, Vector};
use parry3d::shape::SupportMap;
use std::cell::RefCell;

/// A vertex set seen as its convex hull through the support function.
struct Cloud<'a>(&'a [Vector]);

impl SupportMap for Cloud<'_> {
    fn local_support_point(&self, dir: Vector) -> Vector {
        let mut best = self.0[0];
        let mut best_dot = best.dot(dir);
        for p in &self.0[1..] {
            let d = p.dot(dir);
            if d > best_dot {
                best_dot = d;
                best = *p;
            }
        }
        best
    }
}

/// Hull vertex sets of every body.
pub(super) struct HullBodies {
    points: Vec<Vec<P3>>,
    diameter: Vec<f64>,
    scratch: RefCell<(Vec<Vector>, Vec<Vector>)>,
}

/// Largest distance between two points of `p` (exact, O(n²)).
fn diameter_of(p: &[P3]) -> f64 {
    let mut d2: f64 = 0.0;
    for i in 0..p.len() {
        for j in i + 1..p.len() {
            d2 = d2.max((p[i] - p[j]).norm_squared());
        }
    }
    d2.sqrt()
}

/// Largest distance between a point of `a` and a point of `b`.
fn cross_diameter(a: &[P3], b: &[P3]) -> f64 {
    let mut d2: f64 = 0.0;
    for p in a {
        for q in b {
            d2 = d2.max((p - q).norm_squared());
        }
    }
    d2.sqrt()
}

impl HullBodies {
    /// One body per primitive: its distinct vertices.
    pub(super) fn new(scene: &Scene) -> HullBodies {
        let mut points: Vec<Vec<P3>> = (0..scene.len())
            .map(|i| {
                let mut v: Vec<P3> = Vec::new();
                for p in scene.prim_vertices(i) {
                    if !v.contains(p) {
                        v.push(*p);
                    }
                }
                v
            })
            .collect();
        points.reserve(scene.len().saturating_sub(1));
        let diameter = points.iter().map(|p| diameter_of(p)).collect();
        HullBodies {
            points,
            diameter,
            scratch: RefCell::new((Vec::new(), Vec::new())),
        }
    }

    /// Exact diameter of every leaf.
    pub(super) fn leaf_diameters(&self) -> Vec<f64> {
        self.diameter.clone()
    }

    /// L2 distance between the hulls of bodies `x` and `y`.
    fn gap(&self, x: u32, y: u32, origin: &P3) -> f64 {
        let mut s = self.scratch.borrow_mut();
        let (a, b) = &mut *s;
        a.clear();
        a.extend(
            self.points[x as usize]
                .iter()
                .map(|p| to_glam_local(p, origin)),
        );
        b.clear();
        b.extend(
            self.points[y as usize]
                .iter()
                .map(|p| to_glam_local(p, origin)),
        );
        parry3d::query::details::distance_support_map_support_map(
            &Pose::IDENTITY,
            &Cloud(a),
            &Cloud(b),
        ) as f64
    }
}

impl PSetBodies for HullBodies {
    fn eligible(&self, x: u32, y: u32, merged: &Aabb, glimit: f64) -> Option<f64> {
        // GJK in f32 need not give the same distance with the bodies swapped: they go in the
        // order of their vertices, so a pair is eligible from both of its bodies or from
        // neither, and a body's pairs are those of any body with the same vertices.
        let (a, b) = if self.vertices_first(x, y) {
            (x, y)
        } else {
            (y, x)
        };
        if self.gap(a, b, &merged.center()) > glimit {
            return None;
        }
        Some(self.union_diameter(x, y))
    }

    fn merge(&mut self, x: u32, y: u32, new: u32, _: &Aabb) -> f64 {
        debug_assert_eq!(new as usize, self.points.len());
        let d = self.union_diameter(x, y);
        let mut union = std::mem::take(&mut self.points[x as usize]);
        union.append(&mut std::mem::take(&mut self.points[y as usize]));
        self.points.push(hull_of(union).vertices);
        self.diameter.push(d);
        d
    }

    fn same(&self, x: u32, y: u32) -> bool {
        self.vertex_bits(x).eq(self.vertex_bits(y))
    }
}

impl HullBodies {
    /// Whether `x`'s vertices come before (or are) `y`'s, in the order of their coordinates'
    /// bits.
    fn vertices_first(&self, x: u32, y: u32) -> bool {
        self.vertex_bits(x).le(self.vertex_bits(y))
    }

    /// The coordinates' bits of body `x`'s vertices, in order.
    fn vertex_bits(&self, x: u32) -> impl Iterator<Item = u64> + '_ {
        self.points[x as usize]
            .iter()
            .flat_map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
    }

    fn union_diameter(&self, x: u32, y: u32) -> f64 {
        let (a, b) = (&self.points[x as usize], &self.points[y as usize]);
        let (da, db) = (self.diameter[x as usize], self.diameter[y as usize]);
        da.max(db).max(cross_diameter(a, b))
    }
}
