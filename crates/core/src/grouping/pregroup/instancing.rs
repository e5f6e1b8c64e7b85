//! Instancing: finding parts that are rigid copies of an earlier part (§1.3 (2): "repeated
//! component groups are processed separately and then copy-moved").
//!
//! Part `q` is a copy of part `p` when
//! 1. they have the same structure: as many primitives, each with the same vertex-index
//!    pattern (vertices numbered by first appearance within the part), so their vertices
//!    correspond one to one; and
//! 2. one proper rotation R (det R = +1, so no mirror image) and translation t, the
//!    least-squares fit (Kabsch), map every vertex of `p` onto its counterpart in `q` within
//!    [`COPY_TOLERANCE`] × `p`'s radius (largest vertex distance from the centroid).
//!
//! [`find`] tries the earlier representatives of a part's structure whose radius of gyration is
//! within reach, by that radius then by discovery, and the part copies the first that fits (none:
//! a new representative). The search is sequential: the same for any thread count.

use crate::geom::{P3, V3};
use crate::scene::Scene;
use crate::scene::components::Components;
use foldhash::HashMap;
use nalgebra::Matrix3;
use std::collections::BTreeSet;

/// Largest vertex misfit of a copy, as a fraction of the representative's radius.
pub const COPY_TOLERANCE: f64 = 1e-6;

/// How a part copies its representative.
#[derive(Clone, Copy, Debug)]
pub(super) struct CopyOf {
    /// Index (in part order) of the representative.
    pub of: usize,
    /// Rotation taking the representative onto the copy.
    pub rotation: Matrix3<f64>,
    /// Translation applied after the rotation.
    pub translation: V3,
}

/// The unique vertices of a part (first-appearance order) and its structure key. `local` has
/// one entry per scene point, all `u32::MAX`, and is left so.
fn structure(scene: &Scene, prims: &[u32], local: &mut [u32]) -> (Vec<u32>, Vec<u32>) {
    let mut verts = Vec::new();
    let mut key = Vec::with_capacity(prims.len() * 5);
    for &i in prims {
        let p = scene.prim(i as usize);
        key.push(p.len() as u32);
        for &v in p {
            let slot = &mut local[v as usize];
            if *slot == u32::MAX {
                *slot = verts.len() as u32;
                verts.push(v);
            }
            key.push(*slot);
        }
    }
    for &v in &verts {
        local[v as usize] = u32::MAX;
    }
    (verts, key)
}

/// The rigid motion (R, t) with R proper that best maps `a` onto `b` (Kabsch), and the largest
/// distance between a mapped point and its partner.
pub fn kabsch(a: &[P3], b: &[P3]) -> (Matrix3<f64>, V3, f64) {
    let k = a.len().max(1) as f64;
    let ca = a.iter().fold(V3::zeros(), |s, p| s + p.coords) / k;
    let cb = b.iter().fold(V3::zeros(), |s, p| s + p.coords) / k;
    let mut h = Matrix3::zeros();
    for (p, q) in a.iter().zip(b) {
        h += (p.coords - ca) * (q.coords - cb).transpose();
    }
    let svd = h.svd(true, true);
    let (u, vt) = (
        svd.u.expect("SVD computed with U"),
        svd.v_t.expect("SVD computed with V^T"),
    );
    let d = (vt.transpose() * u.transpose()).determinant().signum();
    let fix = Matrix3::from_diagonal(&V3::new(1.0, 1.0, if d < 0.0 { -1.0 } else { 1.0 }));
    let r = vt.transpose() * fix * u.transpose();
    let t = cb - r * ca;
    let misfit = a
        .iter()
        .zip(b)
        .map(|(p, q)| (r * p.coords + t - q.coords).norm())
        .fold(0.0, f64::max);
    (r, t, misfit)
}

/// The radius of gyration of `points` (root mean square distance from their centroid) and
/// their largest distance from it: both unchanged by a rigid motion.
fn radii(points: &[P3]) -> (f64, f64) {
    let k = points.len().max(1) as f64;
    let c = points.iter().fold(V3::zeros(), |s, p| s + p.coords) / k;
    let (mut sq, mut max) = (0.0, 0.0f64);
    for p in points {
        let d2 = (p.coords - c).norm_squared();
        sq += d2;
        max = max.max(d2);
    }
    ((sq / k).sqrt(), max.sqrt())
}

/// A representative: its part index, points and radius.
struct Rep {
    part: usize,
    points: Vec<P3>,
    radius: f64,
}

/// For each part (component indices `parts` of `comps`), the part it copies, if any.
///
/// Candidates are narrowed before Kabsch by the radius of gyration g: a copy within tolerance
/// τ moves every vertex by at most τ, so g moves by at most 2τ. Representatives of one
/// structure are kept ordered by g, and only those within that window are fitted, so a scene
/// of thousands of distinct pieces of one structure (a soup of triangle pairs) costs
/// O(P log P), not O(P²).
pub(super) fn find(scene: &Scene, comps: &Components, parts: &[u32]) -> Vec<Option<CopyOf>> {
    let mut out = vec![None; parts.len()];
    let mut reps: Vec<Rep> = Vec::new();
    // Representatives by structure key, ordered by (g bits, index into `reps`).
    let mut by_key: HashMap<Vec<u32>, BTreeSet<(u64, u32)>> = HashMap::default();
    let mut local = vec![u32::MAX; scene.points.len()];
    for (j, &c) in parts.iter().enumerate() {
        let (verts, key) = structure(scene, comps.get(c as usize), &mut local);
        let points: Vec<P3> = verts.iter().map(|&v| scene.points[v as usize]).collect();
        let (g, radius) = radii(&points);
        let set = by_key.entry(key).or_default();
        // Every representative whose tolerance could admit this part: τ ≤ COPY_TOLERANCE ×
        // its radius ≤ COPY_TOLERANCE × (radius + 2τ).
        let window = 2.0 * COPY_TOLERANCE * (radius * 1.01) + f64::MIN_POSITIVE;
        let lo = (g - window).max(0.0).to_bits();
        let hi = (g + window).to_bits();
        let found = set.range((lo, 0)..=(hi, u32::MAX)).find_map(|&(_, r)| {
            let rep = &reps[r as usize];
            let tol = COPY_TOLERANCE * rep.radius;
            let (rotation, translation, misfit) = kabsch(&rep.points, &points);
            (misfit <= tol && rotation.determinant() > 0.0).then_some(CopyOf {
                of: rep.part,
                rotation,
                translation,
            })
        });
        match found {
            Some(copy) => out[j] = Some(copy),
            None => {
                set.insert((g.to_bits(), reps.len() as u32));
                reps.push(Rep {
                    part: j,
                    points,
                    radius,
                });
            }
        }
    }
    out
}

/// The row-major entries of `m`.
pub(super) fn row_major(m: &Matrix3<f64>) -> [f64; 9] {
    [
        m[(0, 0)],
        m[(0, 1)],
        m[(0, 2)],
        m[(1, 0)],
        m[(1, 1)],
        m[(1, 2)],
        m[(2, 0)],
        m[(2, 1)],
        m[(2, 2)],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Vector3};

    #[test]
    fn kabsch_recovers_a_motion_and_refuses_a_mirror() {
        let a: Vec<P3> = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
            [0.0, 0.0, 3.0],
        ]
        .iter()
        .map(|c| P3::new(c[0], c[1], c[2]))
        .collect();
        let r = Rotation3::from_axis_angle(&Vector3::y_axis(), 0.7);
        let t = V3::new(5.0, -1.0, 2.0);
        let b: Vec<P3> = a.iter().map(|p| r * p + t).collect();
        let (rr, tt, misfit) = kabsch(&a, &b);
        assert!(misfit < 1e-12);
        assert!((rr - r.matrix()).norm() < 1e-12 && (tt - t).norm() < 1e-12);
        let m: Vec<P3> = b.iter().map(|p| P3::new(-p.x, p.y, p.z)).collect();
        let (rm, _, misfit) = kabsch(&a, &m);
        assert!(rm.determinant() > 0.0);
        assert!(misfit > 0.1, "a mirror image is not a rigid copy");
    }
}
