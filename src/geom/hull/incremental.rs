//! The `f64` fallback of [`super::hull_of`]: an incremental (beneath–beyond) convex hull, O(n·f)
//! for n points and f faces. It is only used when parry's `f32` hull fails the `f64` check, so
//! simplicity beats speed. A point within `eps` of the current hull's face planes is treated as
//! inside (it is within the hull's tolerance), which keeps near-coplanar input from creating
//! slivers; the caller checks the result ([`super::is_convex_cover`]) like parry's.

use crate::geom::{P3, V3};
use std::collections::BTreeSet;

/// Face `[a, b, c]` (counter-clockwise seen from outside) with its unit normal and offset.
struct Face {
    v: [usize; 3],
    n: V3,
    d: f64,
}

impl Face {
    fn new(points: &[P3], v: [usize; 3]) -> Option<Face> {
        let [a, b, c] = v.map(|i| points[i]);
        let n = (b - a).cross(&(c - a)).try_normalize(0.0)?;
        Some(Face {
            v,
            n,
            d: n.dot(&a.coords),
        })
    }

    fn height(&self, p: &P3) -> f64 {
        self.n.dot(&p.coords) - self.d
    }
}

/// Vertex indices into `points` and outward triangles (indexing those vertices) of their hull;
/// `None` when the points span no tetrahedron taller than `eps` or a face degenerates.
pub(super) fn hull(points: &[P3], eps: f64) -> Option<(Vec<usize>, Vec<[u32; 3]>)> {
    let far = |from: &dyn Fn(&P3) -> f64| {
        (0..points.len()).max_by(|&a, &b| from(&points[a]).total_cmp(&from(&points[b])))
    };
    let i0 = far(&|p| -p.x)?;
    let i1 = far(&|p| (p - points[i0]).norm())?;
    let axis = (points[i1] - points[i0]).try_normalize(0.0)?;
    let i2 = far(&|p| {
        let d = p - points[i0];
        (d - axis * axis.dot(&d)).norm()
    })?;
    let base = Face::new(points, [i0, i1, i2])?;
    let i3 = far(&|p| base.height(p).abs())?;
    if base.height(&points[i3]).abs() <= eps {
        return None;
    }
    let tet = [i0, i1, i2, i3];
    let inside = P3::from(tet.iter().map(|&i| points[i].coords).sum::<V3>() / 4.0);
    let mut faces = Vec::new();
    for [a, b, c] in [[i0, i1, i2], [i0, i3, i1], [i1, i3, i2], [i2, i3, i0]] {
        let f = Face::new(points, [a, b, c])?;
        faces.push(if f.height(&inside) > 0.0 {
            Face::new(points, [a, c, b])?
        } else {
            f
        });
    }
    for (i, p) in points.iter().enumerate() {
        if tet.contains(&i) {
            continue;
        }
        let (visible, kept): (Vec<Face>, Vec<Face>) =
            faces.into_iter().partition(|f| f.height(p) > eps);
        faces = kept;
        if visible.is_empty() {
            continue;
        }
        let edges: BTreeSet<(usize, usize)> = visible
            .iter()
            .flat_map(|f| [(f.v[0], f.v[1]), (f.v[1], f.v[2]), (f.v[2], f.v[0])])
            .collect();
        for &(a, b) in &edges {
            if !edges.contains(&(b, a)) {
                faces.push(Face::new(points, [a, b, i])?);
            }
        }
    }
    let mut used: Vec<usize> = faces.iter().flat_map(|f| f.v).collect();
    used.sort_unstable();
    used.dedup();
    let at = |i: usize| used.binary_search(&i).unwrap_or(0) as u32;
    let triangles = faces.iter().map(|f| f.v.map(at)).collect();
    Some((used, triangles))
}
