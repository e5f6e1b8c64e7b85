//! Polygon mode: one OBJ face becomes one convex planar polygon, or the triangles of its split.
//!
//! For each face (vertex order kept from the file, consecutive repeats removed):
//! - **degenerate** — fewer than 3 distinct vertices, or an area negligible against the face's
//!   own diameter² or below the rounding of its own corners ([`AREA_EPS`]: a needle or a point,
//!   whatever its size and wherever it lies): dropped and counted;
//! - **non-planar** — a vertex further than [`PLANAR_EPS`] × face diameter (the diagonal of the
//!   face's AABB) from the plane through the vertex centroid with the Newell normal: split;
//! - **non-convex** — in that plane, a reflex corner or a boundary winding more than once: split;
//! - otherwise kept as one [`PrimitiveKind::Polygon`] drawn as a fan.
//!
//! A split is an ear-clipping triangulation in the face's plane, so the triangles lie inside the
//! polygon; if no ear exists (a self-intersecting outline) the remaining corners are clipped in
//! order anyway. Split triangles that are degenerate by the same rule are dropped silently.

use crate::geom::{Aabb, P3, V3};
use crate::scene::{PrimitiveKind, Scene};

/// A face is degenerate when twice its area is at most `AREA_EPS` × D² or [`ROUNDING_ULPS`] ε
/// × M × D, D its diameter (the diagonal of its own AABB), M its largest absolute coordinate,
/// ε = 2⁻⁵² ≈ 2.2e-16: its own shape and the precision of its own corners, never the rest of the
/// scene.
///
/// Edge vectors are differences of stored `f64` coordinates, each rounded to a relative ε, so
/// twice the area computed from them is off by a few ε × D² (n ε for n corners) wherever the face
/// lies; 1e-12 ≈ 4500 ε sits far above that, so a face kept has a plane known to about
/// ε / `AREA_EPS` ≈ 2e-4 rad. The second term is the area a needle gains when its corners are
/// rounded, by a few operations (parse, scale, rotation, translation) each within an ulp of M,
/// to the coordinate grid of its position: a line placed far from the origin stays a needle,
/// while a well-shaped face (twice the area ~ D²) is kept down to D ~ 1e-13 × M.
pub const AREA_EPS: f64 = 1e-12;
/// Rounding allowance of the degenerate test, in ulps of a face's largest coordinate
/// ([`AREA_EPS`]).
pub const ROUNDING_ULPS: f64 = 8.0;
/// Relative distance from the face plane above which a face is non-planar (times its diameter).
pub const PLANAR_EPS: f64 = 1e-6;

/// Counts of repaired faces, reported as warnings.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PolygonStats {
    /// Faces dropped as degenerate (including faces with fewer than 3 vertices).
    pub degenerate: usize,
    /// Faces split because they were not planar.
    pub non_planar: usize,
    /// Planar faces split because they were not convex.
    pub non_convex: usize,
    /// Triangles made by the splits.
    pub pieces: usize,
}

impl PolygonStats {
    /// One line per kind of repair (without the file name).
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        if self.degenerate > 0 {
            w.push(format!(
                "dropped {} degenerate faces (fewer than 3 distinct vertices or zero area)",
                self.degenerate
            ));
        }
        if self.non_planar + self.non_convex > 0 {
            w.push(format!(
                "split {} non-planar and {} non-convex faces into {} triangles",
                self.non_planar, self.non_convex, self.pieces
            ));
        }
        w
    }
}

/// Buffers reused from face to face.
#[derive(Debug, Default)]
pub struct Scratch {
    verts: Vec<u32>,
    flat: Vec<[f64; 2]>,
    ears: Vec<[usize; 3]>,
}

/// Adds `face` (indices into `scene.points`) as a polygon, its split triangles, or nothing.
pub fn add(scene: &mut Scene, face: &[u32], stats: &mut PolygonStats, s: &mut Scratch) {
    s.verts.clear();
    for &i in face {
        if s.verts.last() != Some(&i) {
            s.verts.push(i);
        }
    }
    while s.verts.len() > 1 && s.verts.first() == s.verts.last() {
        s.verts.pop();
    }
    let v = &s.verts;
    let n = v.len();
    if n < 3 || !three_distinct(v) {
        stats.degenerate += 1;
        return;
    }
    let p = |k: usize| scene.points[v[k % n] as usize];
    let o = p(0);
    let normal: V3 = (0..n).map(|k| (p(k) - o).cross(&(p(k + 1) - o))).sum();
    let bounds = Aabb::from_points(v.iter().map(|&i| &scene.points[i as usize]));
    if is_negligible(normal.norm(), &bounds) {
        stats.degenerate += 1;
        return;
    }
    let nh = normal / normal.norm();
    if n == 3 {
        push_polygon(scene, &s.verts);
        return;
    }
    let planar = is_planar(n, p, bounds.diameter(), &nh);
    if planar && is_convex(n, p, &nh) {
        push_polygon(scene, &s.verts);
        return;
    }
    if planar {
        stats.non_convex += 1;
    } else {
        stats.non_planar += 1;
    }
    let u = nh.cross(&any_perpendicular(&nh)).normalize();
    let w = nh.cross(&u);
    s.flat.clear();
    s.flat.extend((0..n).map(|k| {
        let d = p(k) - o;
        [d.dot(&u), d.dot(&w)]
    }));
    ear_clip(&s.flat, &mut s.ears);
    for &[a, b, c] in &s.ears {
        let tri = [s.verts[a], s.verts[b], s.verts[c]];
        let [pa, pb, pc] = tri.map(|i| scene.points[i as usize]);
        let bounds = Aabb::from_points(&[pa, pb, pc]);
        if !is_negligible((pb - pa).cross(&(pc - pa)).norm(), &bounds) {
            push_polygon(scene, &tri);
            stats.pieces += 1;
        }
    }
}

/// Pushes a convex polygon drawn as a fan.
fn push_polygon(scene: &mut Scene, v: &[u32]) {
    let tris: Vec<[u32; 3]> = (1..v.len() - 1).map(|k| [v[0], v[k], v[k + 1]]).collect();
    scene.push(PrimitiveKind::Polygon, v, &tris);
}

/// Whether a face with twice the area `twice_area` and corners bounded by `bounds` is
/// degenerate ([`AREA_EPS`]); also for a non-finite area.
pub fn is_negligible(twice_area: f64, bounds: &Aabb) -> bool {
    let d = bounds.diameter();
    let m = bounds.min.coords.amax().max(bounds.max.coords.amax());
    let floor = (AREA_EPS * d).max(ROUNDING_ULPS * f64::EPSILON * m) * d;
    !(twice_area > floor && twice_area.is_finite())
}

/// Whether `v` holds at least three distinct indices.
fn three_distinct(v: &[u32]) -> bool {
    let a = v[0];
    match v.iter().find(|&&x| x != a) {
        Some(&b) => v.iter().any(|&x| x != a && x != b),
        None => false,
    }
}

/// A unit vector not parallel to `n`.
fn any_perpendicular(n: &V3) -> V3 {
    if n.x.abs() < 0.9 { V3::x() } else { V3::y() }
}

/// Whether every vertex of `p(0..n)` lies within `PLANAR_EPS` × `diameter` of the plane through
/// the vertex centroid with normal `nh` (offsets from `p(0)`, as accurate far from the origin as
/// near it).
fn is_planar(n: usize, p: impl Fn(usize) -> P3, diameter: f64, nh: &V3) -> bool {
    let o = p(0);
    let c = (0..n).map(|k| p(k) - o).sum::<V3>() / n as f64;
    let tol = PLANAR_EPS * diameter;
    (0..n).all(|k| ((p(k) - o) - c).dot(nh).abs() <= tol)
}

/// Whether the planar polygon `p(0..n)` (counter-clockwise about `nh`) is convex: no reflex
/// corner and a total turn of one full circle.
fn is_convex(n: usize, p: impl Fn(usize) -> P3, nh: &V3) -> bool {
    let mut turn = 0.0;
    for k in 0..n {
        let e1 = p(k + 1) - p(k);
        let e2 = p(k + 2) - p(k + 1);
        let cross = e1.cross(&e2).dot(nh);
        if cross < -1e-9 * e1.norm() * e2.norm() {
            return false;
        }
        turn += cross.atan2(e1.dot(&e2));
    }
    (turn - std::f64::consts::TAU).abs() < 1e-6
}

/// Twice the signed area of triangle `abc`.
fn cross2(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Ear-clipping triangulation of the counter-clockwise polygon `pts` into `out` (corner indices).
fn ear_clip(pts: &[[f64; 2]], out: &mut Vec<[usize; 3]>) {
    out.clear();
    let n = pts.len();
    let mut prev: Vec<usize> = (0..n).map(|i| (i + n - 1) % n).collect();
    let mut next: Vec<usize> = (0..n).map(|i| (i + 1) % n).collect();
    let is_ear = |prev: &[usize], next: &[usize], b: usize| {
        let (a, c) = (prev[b], next[b]);
        let (pa, pb, pc) = (pts[a], pts[b], pts[c]);
        if cross2(pa, pb, pc) <= 0.0 {
            return false;
        }
        let mut q = next[c];
        while q != a {
            let pq = pts[q];
            let corner = pq == pa || pq == pb || pq == pc;
            if !corner
                && cross2(pa, pb, pq) >= 0.0
                && cross2(pb, pc, pq) >= 0.0
                && cross2(pc, pa, pq) >= 0.0
            {
                return false;
            }
            q = next[q];
        }
        true
    };
    let (mut left, mut b, mut misses) = (n, 0, 0);
    while left > 3 {
        if is_ear(&prev, &next, b) || misses > left {
            let (a, c) = (prev[b], next[b]);
            out.push([a, b, c]);
            next[a] = c;
            prev[c] = a;
            left -= 1;
            misses = 0;
            b = c;
        } else {
            misses += 1;
            b = next[b];
        }
    }
    out.push([prev[b], b, next[b]]);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// How many primitives `add` makes of the face with corners `corners`, and the stats.
    fn added(corners: &[P3], face: &[u32]) -> (usize, PolygonStats) {
        let mut scene = Scene::new("t");
        scene.points = corners.to_vec();
        let mut stats = PolygonStats::default();
        add(&mut scene, face, &mut stats, &mut Scratch::default());
        (scene.len(), stats)
    }

    const SCALES: [f64; 6] = [1e-9, 1e-6, 1e-3, 1.0, 1e3, 1e6];
    const OFFSETS: [f64; 4] = [0.0, 60.0, -1e6, 1e9];

    #[test]
    fn needles_and_repeated_vertices_are_dropped_at_any_scale_and_position() {
        for s in SCALES {
            for o in OFFSETS {
                let at = |x: f64, y: f64, z: f64| P3::new(o + x * s, y * s, o + z * s);
                // Collinear corners, a sliver of twice the area 1e-14 × diameter², a repeated
                // index and a repeated position.
                let needle = [at(0.0, 0.0, 0.0), at(1.0, 0.0, 0.0), at(3.0, 0.0, 0.0)];
                let sliver = [at(0.0, 0.0, 0.0), at(1.0, 0.0, 0.0), at(0.5, 1e-14, 0.0)];
                let twice = [at(0.0, 0.0, 0.0), at(1.0, 0.0, 1.0), at(0.0, 0.0, 0.0)];
                for (what, pts, face) in [
                    ("needle", &needle, [0, 1, 2]),
                    ("sliver", &sliver, [0, 1, 2]),
                    ("repeated index", &needle, [0, 1, 0]),
                    ("repeated position", &twice, [0, 1, 2]),
                ] {
                    let (n, stats) = added(pts, &face);
                    assert_eq!(
                        (n, stats.degenerate),
                        (0, 1),
                        "{what} at scale {s}, offset {o}"
                    );
                }
            }
        }
        // A needle along a diagonal, its corners rounded to the grid of where it lies.
        let d = V3::new(1.0, 2.0, 3.0).normalize();
        for s in SCALES {
            for o in OFFSETS {
                let c = P3::new(o, -o, o / 3.0);
                let pts = [c + d * s, c + d * (2.0 * s), c + d * (5.0 * s)];
                let (n, _) = added(&pts, &[0, 1, 2]);
                assert_eq!(n, 0, "diagonal needle at scale {s}, offset {o}");
            }
        }
    }

    #[test]
    fn tiny_well_shaped_faces_far_from_the_origin_are_kept() {
        for s in SCALES {
            // Offsets at which the face's corners are still stored to 1e-3 of its size.
            for o in OFFSETS
                .into_iter()
                .filter(|o| o.abs() * f64::EPSILON * 1e3 < s)
            {
                let c = P3::new(o, -o, o / 3.0);
                let tri = [
                    c,
                    c + V3::new(s, 0.0, 0.0),
                    c + V3::new(0.3 * s, 0.8 * s, 0.1 * s),
                ];
                let (n, stats) = added(&tri, &[0, 1, 2]);
                assert_eq!((n, stats.degenerate), (1, 0), "scale {s}, offset {o}");
                // A non-convex quad is split into its two triangles, none dropped.
                let dart = [
                    c,
                    c + V3::new(2.0 * s, 0.0, 0.0),
                    c + V3::new(0.5 * s, 0.5 * s, 0.0),
                    c + V3::new(0.0, 2.0 * s, 0.0),
                ];
                let (n, stats) = added(&dart, &[0, 1, 2, 3]);
                assert_eq!(
                    (n, stats.non_convex, stats.pieces),
                    (2, 1, 2),
                    "dart {s}, {o}"
                );
            }
        }
    }
}
