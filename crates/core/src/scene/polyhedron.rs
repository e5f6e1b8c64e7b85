//! Polyhedra mode (`--polyhedra`): one OBJ object/group becomes one convex polyhedron.
//!
//! The primitive's vertices are the distinct vertices its faces use (in first-use order) and its
//! triangles are the faces, each drawn as a fan. Then:
//! - **flat or collinear** groups (fewer than 4 distinct vertices, or a smallest covariance
//!   eigenvalue ≤ [`FLAT_EPS`] × diameter², the point where parry's hull treats input as
//!   lower-dimensional) are kept as drawn, without a convexity check, and listed in a warning;
//! - otherwise the convex hull is computed (parry3d `try_convex_hull`, `f32`, relative to the
//!   group's centroid). The group is **not in convex position** when a vertex or the centroid of a
//!   face lies strictly inside the hull, i.e. more than [`CONVEX_EPS`] × diameter below every hull
//!   plane (planes are rebuilt in `f64` from the original points). Such a group is replaced by
//!   its hull, whose vertices are original points, and named in a warning; with `strict` it is
//!   an error naming the group;
//! - if the hull cannot be computed the group is kept as drawn and named in a warning.

use std::collections::{HashMap, HashSet};

use crate::geom::{Aabb, P3, V3, to_glam_local};
use crate::scene::{PrimitiveKind, Scene};

/// Relative depth inside the hull beyond which a point is "strictly inside" (times diameter).
pub const CONVEX_EPS: f64 = 1e-5;
/// Relative variance below which a group is flat or collinear (times diameter²).
pub const FLAT_EPS: f64 = 2e-7;

/// Groups that needed a repair, by name, reported as warnings.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PolyhedronStats {
    /// Groups not in convex position, replaced by their hulls.
    pub hulled: Vec<String>,
    /// Flat or collinear groups kept as drawn.
    pub flat: Vec<String>,
    /// Groups whose hull could not be computed, kept as drawn.
    pub hull_failed: Vec<String>,
}

impl PolyhedronStats {
    /// One line per kind of repair (without the file name).
    pub fn warnings(&self) -> Vec<String> {
        let list = |names: &[String]| {
            let shown: Vec<String> = names.iter().take(10).map(|n| format!("'{n}'")).collect();
            let more = names.len().saturating_sub(10);
            let tail = if more > 0 {
                format!(" and {more} more")
            } else {
                String::new()
            };
            format!("{}{tail}", shown.join(", "))
        };
        let mut w = Vec::new();
        if !self.hulled.is_empty() {
            w.push(format!(
                "{} groups not in convex position, replaced by their convex hulls: {}",
                self.hulled.len(),
                list(&self.hulled)
            ));
        }
        if !self.flat.is_empty() {
            w.push(format!(
                "{} flat or collinear groups kept as drawn: {}",
                self.flat.len(),
                list(&self.flat)
            ));
        }
        if !self.hull_failed.is_empty() {
            w.push(format!(
                "could not compute the convex hull of {} groups, kept as drawn: {}",
                self.hull_failed.len(),
                list(&self.hull_failed)
            ));
        }
        w
    }
}

/// Adds the group `name` made of `faces` (indices into `scene.points`) as one polyhedron.
///
/// Errors (only with `strict`) name the group that is not in convex position. Cost: the hull
/// plus one pass over vertices and faces per hull plane (stopping at the first point found
/// inside).
pub fn add(
    scene: &mut Scene,
    name: &str,
    faces: &[&[u32]],
    strict: bool,
    stats: &mut PolyhedronStats,
) -> Result<(), String> {
    let mut seen = HashSet::new();
    let verts: Vec<u32> = faces
        .iter()
        .flat_map(|f| f.iter().copied())
        .filter(|&i| seen.insert(i))
        .collect();
    let tris: Vec<[u32; 3]> = faces
        .iter()
        .flat_map(|f| (1..f.len() - 1).map(move |k| [f[0], f[k], f[k + 1]]))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .collect();
    let pts: Vec<P3> = verts.iter().map(|&i| scene.points[i as usize]).collect();
    let diag = Aabb::from_points(&pts).diameter();
    let centroid = mean(pts.iter().copied());
    let keep = |scene: &mut Scene| {
        scene.push(PrimitiveKind::Polyhedron, &verts, &tris);
        scene.labels.push(name.to_string());
    };
    if pts.len() < 4 || is_flat(&pts, &centroid, diag) {
        stats.flat.push(name.to_string());
        keep(scene);
        return Ok(());
    }
    let Some((hull_verts, hull_tris)) = hull(&pts, &verts, &centroid) else {
        stats.hull_failed.push(name.to_string());
        keep(scene);
        return Ok(());
    };
    let planes: Vec<(V3, P3)> = hull_tris
        .iter()
        .filter_map(|t| {
            let [a, b, c] = t.map(|i| scene.points[i as usize]);
            let n = (b - a).cross(&(c - a));
            let n = n.try_normalize(0.0)?;
            Some(if n.dot(&(centroid - a)) > 0.0 {
                (-n, a)
            } else {
                (n, a)
            })
        })
        .collect();
    let tol = CONVEX_EPS * diag;
    let inside = |q: &P3| planes.iter().all(|(n, a)| n.dot(&(q - a)) < -tol);
    // A face centroid's height over a plane is the mean of its vertices' heights: no centroid
    // is rounded to the (possibly far coarser) grid of absolute coordinates.
    let centroid_inside = |f: &[u32]| {
        planes.iter().all(|(n, a)| {
            let h: f64 = f
                .iter()
                .map(|&i| n.dot(&(scene.points[i as usize] - a)))
                .sum();
            h / (f.len() as f64) < -tol
        })
    };
    let convex = !pts.iter().any(inside) && !faces.iter().any(|f| centroid_inside(f));
    if convex {
        keep(scene);
        return Ok(());
    }
    if strict {
        return Err(format!(
            "group '{name}' is not in convex position (a vertex or face lies inside its convex hull)"
        ));
    }
    stats.hulled.push(name.to_string());
    scene.push(PrimitiveKind::Polyhedron, &hull_verts, &hull_tris);
    scene.labels.push(name.to_string());
    Ok(())
}

/// The mean of `pts` (at least one), summed as offsets from the first so that a small group far
/// from the origin is not moved by the rounding of large coordinates.
fn mean(mut pts: impl Iterator<Item = P3>) -> P3 {
    let base = pts.next().expect("a point");
    let (sum, n) = pts.fold((V3::zeros(), 1.0), |(s, n), p| (s + (p - base), n + 1.0));
    base + sum / n
}

/// Whether the points' smallest covariance eigenvalue is ≤ `FLAT_EPS` × `diag`².
fn is_flat(pts: &[P3], centroid: &P3, diag: f64) -> bool {
    let cov = pts
        .iter()
        .map(|p| {
            let d = p - centroid;
            d * d.transpose()
        })
        .sum::<nalgebra::Matrix3<f64>>()
        / pts.len() as f64;
    let min = cov.symmetric_eigenvalues().min();
    min.is_nan() || min <= FLAT_EPS * diag * diag
}

/// The convex hull of `pts` (whose scene indices are `ids`) as scene indices and triangles.
///
/// parry works in `f32` relative to `origin` and returns copies of its input points, which are
/// mapped back to the original indices by their bits. `None` if parry fails (or panics, which
/// is caught as a last resort) or returns a hull with no volume.
fn hull(pts: &[P3], ids: &[u32], origin: &P3) -> Option<(Vec<u32>, Vec<[u32; 3]>)> {
    let local: Vec<_> = pts.iter().map(|p| to_glam_local(p, origin)).collect();
    let (hv, ht) = std::panic::catch_unwind(|| parry3d::transformation::try_convex_hull(&local))
        .ok()?
        .ok()?;
    let by_bits: HashMap<[u32; 3], u32> = local
        .iter()
        .zip(ids)
        .map(|(l, &g)| (l.to_array().map(f32::to_bits), g))
        .collect();
    let hv: Vec<u32> = hv
        .iter()
        .map(|l| by_bits.get(&l.to_array().map(f32::to_bits)).copied())
        .collect::<Option<_>>()?;
    let ht: Vec<[u32; 3]> = ht
        .iter()
        .map(|t| {
            Some([
                *hv.get(t[0] as usize)?,
                *hv.get(t[1] as usize)?,
                *hv.get(t[2] as usize)?,
            ])
        })
        .collect::<Option<_>>()?;
    (hv.len() >= 4 && !ht.is_empty()).then_some((hv, ht))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed octahedron of radius `r` centred at `c`, tilted so that no coordinate is round.
    fn octahedron(r: f64, c: P3) -> (Scene, Vec<[u32; 3]>) {
        let mut s = Scene::new("t");
        let rot = nalgebra::Rotation3::from_euler_angles(0.3, -0.2, 1.1);
        for d in [V3::x(), -V3::x(), V3::y(), -V3::y(), V3::z(), -V3::z()] {
            s.points.push(c + rot * d * r);
        }
        let faces = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        (s, faces)
    }

    #[test]
    fn a_tiny_convex_group_far_from_the_origin_is_kept_as_drawn() {
        for (r, o) in [(1.0, 0.0), (2e-6, 60.0), (1e-6, 1e6), (1e-3, -1e9)] {
            let (mut scene, faces) = octahedron(r, P3::new(o, -o, 0.7 * o));
            let faces: Vec<&[u32]> = faces.iter().map(|f| &f[..]).collect();
            let mut stats = PolyhedronStats::default();
            add(&mut scene, "oct", &faces, true, &mut stats).unwrap();
            assert_eq!(scene.len(), 1);
            assert_eq!(scene.prim(0).len(), 6, "radius {r} at {o}");
            assert_eq!(stats, PolyhedronStats::default(), "radius {r} at {o}");
        }
    }
}
