//! Convex hulls of point sets ([`hull_of`]), shared by the hull p-set of the grouping phase and
//! the hull Wrapper Trees. Vertices are always input points, in `f64`.
//!
//! Degenerate input is normal here (one polygon is flat; duplicates; collinear points), so the
//! dimension is decided first, from the extents along the principal axes. Solids are built by
//! Quickhull with exact orientation tests (`quickhull`), which gives a closed convex surface
//! on any input, at any mix of scales, in time that grows with the points, not points × faces.
//! Nothing here panics.

use super::{P3, V3};
use crate::geom::pca::Frame;
use std::cmp::Ordering::Greater;
use std::collections::HashMap;

mod quickhull;

/// Containment tolerance of hulls, relative to the node's AABB diameter. Hull faces are exact;
/// this covers the rounding of the face planes that tests and the excess measure compute.
pub const HULL_TOL_REL: f64 = 1e-5;
/// Extents below this fraction of the largest extent count as zero (flat or collinear).
pub const FLAT_REL: f64 = 1e-9;

/// A convex hull: `f64` vertices (input points) and triangles; flat hulls are one-sided
/// triangulated polygons, segments and points have no triangles.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Hull {
    /// Hull vertices.
    pub vertices: Vec<P3>,
    /// Triangles indexing `vertices`, outward-facing for solids.
    pub triangles: Vec<[u32; 3]>,
    /// 0 point, 1 segment, 2 flat polygon, 3 solid.
    pub dim: u8,
}

impl Hull {
    /// Enclosed volume (divergence theorem; 0 unless solid).
    pub fn volume(&self) -> f64 {
        if self.dim < 3 {
            return 0.0;
        }
        let o = self.vertices[0];
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize] - o);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum::<f64>()
            .abs()
    }

    /// How far `p` lies outside (≤ 0 inside). For solids: the largest signed distance to the
    /// planes of the well-shaped faces (twice the area ≥ 1e-3 × the longest edge²; slivers
    /// have ill-defined planes) when that is ≤ 0, else the distance to the surface. For flat hulls,
    /// segments and points: the distance to them. [`Hull::excess_test`] answers the same for
    /// many points, the face planes computed once.
    pub fn excess(&self, p: &P3) -> f64 {
        self.excess_test().excess(p)
    }

    /// [`Hull::excess`] for many points: the well-shaped faces' unit normals and corners,
    /// computed once.
    pub fn excess_test(&self) -> ExcessTest<'_> {
        let v = |i: u32| &self.vertices[i as usize];
        let planes = match self.dim {
            3 => self
                .triangles
                .iter()
                .filter_map(|t| {
                    let [a, b, c] = t.map(v);
                    let n = (b - a).cross(&(c - a));
                    let e = [b - a, c - b, a - c].map(|e| e.norm());
                    let longest = e[0].max(e[1]).max(e[2]);
                    let shortest = e[0].min(e[1]).min(e[2]);
                    (n.norm() >= 1e-3 * longest * longest && shortest > 0.0)
                        .then(|| (n.normalize(), *a))
                })
                .collect(),
            _ => Vec::new(),
        };
        ExcessTest { hull: self, planes }
    }
}

/// A hull with its face planes ready for [`ExcessTest::excess`] ([`Hull::excess_test`]).
#[derive(Clone, Debug)]
pub struct ExcessTest<'a> {
    hull: &'a Hull,
    /// Unit normal and a corner of each well-shaped face (solids only).
    planes: Vec<(V3, P3)>,
}

impl ExcessTest<'_> {
    /// How far `p` lies outside the hull, exactly as [`Hull::excess`].
    pub fn excess(&self, p: &P3) -> f64 {
        let h = self.hull;
        let v = |i: u32| &h.vertices[i as usize];
        let surface = || {
            h.triangles
                .iter()
                .map(|t| super::distance::point_triangle(p, v(t[0]), v(t[1]), v(t[2])))
                .fold(f64::INFINITY, f64::min)
        };
        match h.dim {
            3 => {
                let planes = self
                    .planes
                    .iter()
                    .map(|(n, a)| n.dot(&(p - a)))
                    .fold(f64::NEG_INFINITY, f64::max);
                if planes <= 0.0 { planes } else { surface() }
            }
            2 => surface(),
            _ => match h.vertices.as_slice() {
                [a, b] => super::distance::point_segment(p, a, b),
                [a] => (p - a).norm(),
                _ => f64::INFINITY,
            },
        }
    }
}

/// The hull of `points`.
///
/// The dimension is decided from the extents along the principal axes ([`Frame::principal`]):
/// a point, a segment, a flat polygon (Andrew's monotone chain in the plane of best fit,
/// fan-triangulated, one side), or a solid by exact Quickhull (`quickhull`). A set that is
/// not flat by its extents yet lies exactly in one plane gets the flat hull.
pub fn hull_of(mut points: Vec<P3>) -> Hull {
    dedup(&mut points);
    let one = |vertices: Vec<P3>, dim| Hull {
        vertices,
        triangles: Vec::new(),
        dim,
    };
    if points.len() <= 1 {
        return one(points, 0);
    }
    let frame = Frame::principal(&points);
    let (lo, hi) = frame.bounds(&points);
    let ext = hi - lo;
    let mut axes = [0usize, 1, 2];
    axes.sort_by(|&a, &b| ext[b].total_cmp(&ext[a]));
    let [big, mid, small] = axes;
    if ext[mid].partial_cmp(&(FLAT_REL * ext[big])) != Some(Greater) {
        let along = |p: &P3| frame.local(p)[big];
        let lo = points.iter().min_by(|a, b| along(a).total_cmp(&along(b)));
        let hi = points.iter().max_by(|a, b| along(a).total_cmp(&along(b)));
        return match (lo, hi) {
            (Some(a), Some(b)) => one(vec![*a, *b], 1),
            _ => one(points, 0),
        };
    }
    if ext[small].partial_cmp(&(FLAT_REL * ext[big])) != Some(Greater) {
        return flat_hull(&points, &frame, big, mid);
    }
    match quickhull::hull(&points) {
        Some((used, triangles)) => Hull {
            vertices: used.iter().map(|&i| points[i]).collect(),
            triangles,
            dim: 3,
        },
        None => flat_hull(&points, &frame, big, mid),
    }
}

/// Whether `h` is a solid whose surface is closed (every directed edge once, its reverse once)
/// and has all `points` behind or at most `tol` in front of every face: then `h` is convex and
/// holds every point within `tol`. "Behind" is decided exactly (`orient3d`), since the `f64`
/// normal of a sliver face can point anywhere; "at most `tol` in front" uses that normal.
/// "Every point lies on or inside the mesh" would not be enough: a folded mesh through all the
/// hull's vertices passes it.
pub fn is_convex_cover(h: &Hull, points: &[P3], tol: f64) -> bool {
    if h.dim != 3 || h.triangles.len() < 4 {
        return false;
    }
    let mut edges = HashMap::with_capacity(3 * h.triangles.len());
    for &[a, b, c] in &h.triangles {
        for e in [(a, b), (b, c), (c, a)] {
            if edges.insert(e, ()).is_some() {
                return false;
            }
        }
    }
    if edges.keys().any(|&(a, b)| !edges.contains_key(&(b, a))) {
        return false;
    }
    h.triangles.iter().all(|&t| {
        let [a, b, c] = t.map(|i| h.vertices[i as usize]);
        let n = (b - a).cross(&(c - a)).try_normalize(0.0);
        points.iter().all(|p| {
            quickhull::behind(&h.vertices, t, p) || n.is_some_and(|n| n.dot(&(p - a)) <= tol)
        })
    })
}

/// Removes exact duplicates (by bits), keeping the first of each.
fn dedup(points: &mut Vec<P3>) {
    let mut seen = std::collections::HashSet::with_capacity(points.len());
    points.retain(|p| seen.insert(p.coords.map(f64::to_bits)));
}

/// The 2D hull in the plane of axes `u`, `v` (monotone chain, collinear points dropped),
/// fan-triangulated.
fn flat_hull(points: &[P3], frame: &Frame, u: usize, v: usize) -> Hull {
    let mut pts: Vec<(f64, f64, usize)> = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let l = frame.local(p);
            (l[u], l[v], i)
        })
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let cross = |o: &(f64, f64, usize), a: &(f64, f64, usize), b: &(f64, f64, usize)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut chain: Vec<(f64, f64, usize)> = Vec::with_capacity(pts.len() + 1);
    for half in [pts.clone(), pts.iter().rev().copied().collect()] {
        let floor = chain.len();
        for p in half {
            while chain.len() >= floor + 2
                && cross(&chain[chain.len() - 2], &chain[chain.len() - 1], &p) <= 0.0
            {
                chain.pop();
            }
            chain.push(p);
        }
        chain.pop();
    }
    let vertices: Vec<P3> = chain.iter().map(|c| points[c.2]).collect();
    if vertices.len() < 3 {
        let ends = [pts[0], pts[pts.len() - 1]].map(|c| points[c.2]);
        return Hull {
            vertices: ends.to_vec(),
            triangles: Vec::new(),
            dim: 1,
        };
    }
    let triangles = (1..vertices.len() as u32 - 1)
        .map(|i| [0, i, i + 1])
        .collect();
    Hull {
        vertices,
        triangles,
        dim: 2,
    }
}

/// Outward triangles of a box whose corner `k` has bit `a` set when it is at the top of axis
/// `a` (for a right-handed frame).
pub const BOX_TRIANGLES: [[u32; 3]; 12] = [
    [0, 2, 1],
    [1, 2, 3],
    [4, 5, 6],
    [5, 7, 6],
    [0, 1, 4],
    [1, 5, 4],
    [2, 6, 3],
    [3, 6, 7],
    [0, 4, 2],
    [2, 4, 6],
    [1, 3, 5],
    [3, 7, 5],
];

#[cfg(test)]
mod tests {
    use super::*;

    /// The children's hull vertices of node 862 of `scene::pathological::scales(500, 1)`: two
    /// pairs of points 1e-2 apart in a set 6e5 wide round to the same `f32`, and parry's hull
    /// came back folded (every point a vertex or near one, yet 1.2e4 short of the true hull).
    const NODE_862: [[f64; 3]; 12] = [
        [369458.36569001165, 1441229.5701129083, 1940021.1926272416],
        [369458.3644717401, 1441229.5563249202, 1940021.1922192422],
        [369458.36532453017, 1441229.5662261187, 1940021.184069588],
        [78933.97771045874, 1602711.6276975274, 1877795.1842322976],
        [260709.21310348198, 1973355.6764059889, 1874952.0446192918],
        [78937.15843661095, 1602712.3143425295, 1877789.8111794712],
        [260710.07872047534, 1973354.788537742, 1874953.505605709],
        [265306.48234324006, 1606691.5358718918, 1873738.3459693824],
        [265307.5352089172, 1606692.1801468453, 1873739.3000611947],
        [260710.44969918678, 1973354.7082750804, 1874951.9135727389],
        [172315.30573832418, 1903546.6442138744, 1796111.8685013761],
        [112294.06050034064, 1930642.4275062277, 1819438.9695206604],
    ];

    #[test]
    fn twelve_decade_node_gets_its_true_hull() {
        let pts: Vec<P3> = NODE_862.iter().map(|&c| P3::from(c)).collect();
        let h = hull_of(pts.clone());
        assert_eq!(h.dim, 3);
        let tol = HULL_TOL_REL * 6.3e5;
        assert!(is_convex_cover(&h, &pts, tol));
        // A vertex of the scene 1.56e4 inside the true hull; the folded hull had it 1.2e4 out.
        let inside = P3::new(194725.00379737755, 1758694.4144158948, 1850553.5737965864);
        assert!(h.excess(&inside) < -1e4, "{}", h.excess(&inside));
        for p in &pts {
            assert!(h.excess(p) <= tol);
        }
    }

    #[test]
    fn folded_or_open_meshes_are_not_covers() {
        let pts: Vec<P3> = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]]
            .map(P3::from)
            .to_vec();
        let tet = Hull {
            vertices: pts.clone(),
            triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
            dim: 3,
        };
        assert!(is_convex_cover(&tet, &pts, 0.0));
        let outside = [P3::new(1.0, 1.0, 1.0)];
        assert!(!is_convex_cover(&tet, &outside, 0.1));
        let mut open = tet.clone();
        open.triangles.pop();
        assert!(!is_convex_cover(&open, &pts, 0.0));
        let mut flipped = tet;
        flipped.triangles[0] = [0, 1, 2];
        assert!(!is_convex_cover(&flipped, &pts, 0.0));
    }

    #[test]
    fn cube_with_inner_and_face_points_has_its_corners() {
        let mut pts: Vec<P3> = (0..8)
            .map(|k| P3::new((k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2 & 1) as f64))
            .collect();
        // Inner points, and points exactly on faces and edges: none may become a vertex.
        pts.extend(
            [
                [0.5, 0.5, 0.5],
                [0.2, 0.7, 0.1],
                [0.5, 0.5, 1.0],
                [0.0, 0.3, 0.0],
            ]
            .map(P3::from),
        );
        let h = hull_of(pts.clone());
        assert_eq!(h.vertices.len(), 8);
        assert!(is_convex_cover(&h, &pts, 0.0));
        assert!((h.volume() - 1.0).abs() < 1e-12);
    }

    /// Points of a sphere of radius `r` about `c`, from a fixed sequence.
    fn sphere(c: [f64; 3], r: f64, n: usize) -> Vec<P3> {
        (0..n)
            .map(|i| {
                let t = (i as f64 + 0.5) / n as f64;
                let (z, phi) = (1.0 - 2.0 * t, i as f64 * 2.399_963_229_728_653);
                let s = (1.0 - z * z).sqrt();
                P3::new(
                    c[0] + r * s * phi.cos(),
                    c[1] + r * s * phi.sin(),
                    c[2] + r * z,
                )
            })
            .collect()
    }

    /// A part a thousandth of its neighbour's size beside it, far from the origin: the
    /// mixed-scale unions that made the `f32` hull fold. The hull is closed and convex, holds
    /// every point, and keeps the small part's outer points as vertices.
    #[test]
    fn mixed_scales_give_a_closed_convex_hull() {
        for (small, far) in [(1e-3, 60.0), (1e-6, 60.0), (2e-3, 1e4)] {
            let mut pts = sphere([far, far, 0.0], 15.0, 2000);
            pts.extend(sphere([far + 15.5, far, 0.0], small, 500));
            // Duplicated surface points and near-coplanar noise on one great circle.
            pts.extend(pts[..100].to_vec());
            let h = hull_of(pts.clone());
            assert_eq!(h.dim, 3);
            assert!(is_convex_cover(&h, &pts, 1e-9 * far), "{small} {far}");
            // The small part's cap outside the tangent cone: about 1.6 % of its 500 points.
            let small_part = h.vertices.iter().filter(|v| v.x > far + 15.2).count();
            assert!(small_part >= 5, "{small} {far}: {small_part}");
        }
    }
}
