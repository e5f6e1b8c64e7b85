//! Minimum enclosing spheres: Welzl's algorithm (E. Welzl, "Smallest enclosing disks (balls
//! and ellipsoids)", 1991) in Gärtner's move-to-front form (B. Gärtner, "Fast and robust
//! smallest enclosing balls", ESA 1999), and Ritter's approximation (J. Ritter, "An efficient
//! bounding sphere", Graphics Gems, 1990). Both in `f64`.
//!
//! The points are first put in a fixed pseudo-random order (a seeded Fisher–Yates shuffle), so
//! the expected running time is O(n) and the result is deterministic. The recursion only runs
//! over the support set (at most 4 deep); the point loop is iterative. Degenerate supports
//! (collinear triples, coplanar quadruples, duplicates) fall back to the smallest ball of the
//! support found by trying its pairs and triples. As a last guard the radius is finally set to
//! the largest distance from the centre to any input point, so containment never depends on
//! rounding.

use crate::geom::Sphere;
use crate::geom::{P3, V3};
use std::cmp::Ordering::Greater;

/// Relative slack of the "is outside" test while iterating.
const SLACK: f64 = 1e-12;

/// The exact minimum enclosing sphere of `points` (radius 0 for one point or duplicates;
/// a zero sphere at the origin for no points).
pub fn min_sphere(points: &[P3]) -> Sphere {
    if points.is_empty() {
        return Sphere {
            center: P3::origin(),
            radius: 0.0,
        };
    }
    // Work relative to the first point so far-off scenes keep their precision, with an
    // absolute slack of SLACK × the local extent.
    let o = points[0];
    let mut p: Vec<P3> = points.iter().map(|q| P3::from(q - o)).collect();
    let scale = p.iter().map(|q| q.coords.amax()).fold(0.0, f64::max);
    shuffle(&mut p);
    let mut support = Vec::with_capacity(4);
    let ball = mtf(&mut p, &mut support, SLACK * scale);
    finalize(o + ball.center.coords, points)
}

/// Ritter's approximate bounding sphere of `points`: start from the farthest pair found by two
/// sweeps, then grow to take in every point outside.
pub fn ritter_sphere(points: &[P3]) -> Sphere {
    let Some(first) = points.first() else {
        return Sphere {
            center: P3::origin(),
            radius: 0.0,
        };
    };
    let far = |from: &P3| {
        *points
            .iter()
            .max_by(|a, b| {
                (*a - from)
                    .norm_squared()
                    .total_cmp(&(*b - from).norm_squared())
            })
            .unwrap_or(from)
    };
    let y = far(first);
    let z = far(&y);
    let mut c = nalgebra::center(&y, &z);
    let mut r = (z - y).norm() / 2.0;
    for p in points {
        let d = (p - c).norm();
        if d > r {
            let nr = (r + d) / 2.0;
            c += (p - c) * ((nr - r) / d);
            r = nr;
        }
    }
    finalize(c, points)
}

/// The sphere at `center` whose radius reaches the farthest point.
fn finalize(center: P3, points: &[P3]) -> Sphere {
    let radius = points
        .iter()
        .map(|p| (p - center).norm())
        .fold(0.0, f64::max);
    Sphere { center, radius }
}

/// Deterministic Fisher–Yates shuffle driven by a fixed 64-bit LCG.
fn shuffle(p: &mut [P3]) {
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    for i in (1..p.len()).rev() {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let j = ((s >> 33) % (i as u64 + 1)) as usize;
        p.swap(i, j);
    }
}

/// A ball that contains nothing (radius < 0).
const EMPTY: Sphere = Sphere {
    center: P3::new(0.0, 0.0, 0.0),
    radius: -1.0,
};

fn outside(b: &Sphere, p: &P3, eps: f64) -> bool {
    b.radius < 0.0 || (p - b.center).norm() > b.radius * (1.0 + SLACK) + eps
}

/// Smallest ball holding `p` with every point of `support` on its boundary (move-to-front).
fn mtf(p: &mut [P3], support: &mut Vec<P3>, eps: f64) -> Sphere {
    let mut ball = boundary_ball(support);
    if support.len() == 4 {
        return ball;
    }
    for i in 0..p.len() {
        if outside(&ball, &p[i], eps) {
            let q = p[i];
            support.push(q);
            ball = mtf(&mut p[..i], support, eps);
            support.pop();
            p[..=i].rotate_right(1);
        }
    }
    ball
}

/// The ball with all of `r` (≤ 4 points) on its boundary, or the smallest ball holding `r`
/// when `r` is degenerate.
fn boundary_ball(r: &[P3]) -> Sphere {
    match r {
        [] => EMPTY,
        [a] => Sphere {
            center: *a,
            radius: 0.0,
        },
        [a, b] => pair(a, b),
        [a, b, c] => circum3(a, b, c).unwrap_or_else(|| smallest_of(r)),
        [a, b, c, d] => circum4(a, b, c, d).unwrap_or_else(|| smallest_of(r)),
        _ => smallest_of(r),
    }
}

fn pair(a: &P3, b: &P3) -> Sphere {
    Sphere {
        center: nalgebra::center(a, b),
        radius: (b - a).norm() / 2.0,
    }
}

/// Circumcircle of a triangle (as a sphere); `None` when the points are (nearly) collinear.
fn circum3(a: &P3, b: &P3, c: &P3) -> Option<Sphere> {
    let (u, v) = (b - a, c - a);
    let w = u.cross(&v);
    let w2 = w.norm_squared();
    if w2.partial_cmp(&(1e-20 * u.norm_squared() * v.norm_squared())) != Some(Greater) {
        return None;
    }
    let off: V3 = (v.cross(&w) * u.norm_squared() + w.cross(&u) * v.norm_squared()) / (2.0 * w2);
    let center = a + off;
    Some(Sphere {
        center,
        radius: off.norm(),
    })
    .filter(|s| s.center.iter().all(|x| x.is_finite()))
}

/// Circumsphere of a tetrahedron; `None` when the points are (nearly) coplanar.
fn circum4(a: &P3, b: &P3, c: &P3, d: &P3) -> Option<Sphere> {
    let (u, v, w) = (b - a, c - a, d - a);
    let m = nalgebra::Matrix3::from_rows(&[u.transpose(), v.transpose(), w.transpose()]);
    let det = m.determinant();
    if det
        .abs()
        .partial_cmp(&(1e-12 * u.norm() * v.norm() * w.norm()))
        != Some(Greater)
    {
        return None;
    }
    let rhs = V3::new(u.norm_squared(), v.norm_squared(), w.norm_squared()) / 2.0;
    let off = m.lu().solve(&rhs)?;
    let center = a + off;
    center.iter().all(|x| x.is_finite()).then(|| Sphere {
        center,
        radius: off.norm(),
    })
}

/// The smallest of the pair and triple balls of `r` that holds all of `r` (brute force; `r` has
/// at most 4 points).
fn smallest_of(r: &[P3]) -> Sphere {
    let holds = |s: &Sphere| {
        r.iter()
            .all(|p| (p - s.center).norm() <= s.radius * (1.0 + 1e-9) + 1e-300)
    };
    let mut best: Option<Sphere> = None;
    let mut consider = |s: Sphere| {
        if holds(&s) && best.is_none_or(|b| s.radius < b.radius) {
            best = Some(s);
        }
    };
    for i in 0..r.len() {
        for j in i + 1..r.len() {
            consider(pair(&r[i], &r[j]));
            for k in j + 1..r.len() {
                if let Some(s) = circum3(&r[i], &r[j], &r[k]) {
                    consider(s);
                }
            }
        }
    }
    best.unwrap_or_else(|| {
        let c = P3::from(r.iter().map(|p| p.coords).sum::<V3>() / r.len().max(1) as f64);
        finalize(c, r)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: the smallest pair, triple or quadruple ball holding every point.
    fn brute(p: &[P3]) -> f64 {
        let mut best = f64::INFINITY;
        let n = p.len();
        let holds = |s: &Sphere| {
            p.iter()
                .all(|q| (q - s.center).norm() <= s.radius * (1.0 + 1e-9) + 1e-9)
        };
        for i in 0..n {
            for j in i..n {
                let mut c = vec![pair(&p[i], &p[j])];
                for k in j + 1..n {
                    c.extend(circum3(&p[i], &p[j], &p[k]));
                    for l in k + 1..n {
                        c.extend(circum4(&p[i], &p[j], &p[k], &p[l]));
                    }
                }
                for s in c {
                    if holds(&s) {
                        best = best.min(s.radius);
                    }
                }
            }
        }
        best
    }

    #[test]
    fn matches_brute_force() {
        let mut s: u64 = 7;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 40) % 7) as f64 - 3.0
        };
        for case in 0..3000 {
            let n = 1 + case % 9;
            let off = if case % 2 == 0 { 1e6 } else { 0.0 };
            let pts: Vec<P3> = (0..n)
                .map(|_| P3::new(rnd() + off, rnd(), if case % 3 == 0 { 0.0 } else { rnd() }))
                .collect();
            let w = min_sphere(&pts).radius;
            let b = brute(&pts);
            assert!(
                (w - b).abs() <= 1e-7 * (1.0 + b),
                "case {case}: welzl {w}, brute {b}, {pts:?}"
            );
        }
    }

    #[test]
    fn known_spheres() {
        let sq = [
            P3::new(0.0, 0.0, 0.0),
            P3::new(2.0, 0.0, 0.0),
            P3::new(0.0, 2.0, 0.0),
            P3::new(2.0, 2.0, 0.0),
            P3::new(1.0, 1.0, 0.0),
        ];
        let s = min_sphere(&sq);
        assert!((s.radius - 2f64.sqrt()).abs() < 1e-12);
        assert!((s.center - P3::new(1.0, 1.0, 0.0)).norm() < 1e-12);
        let line: Vec<P3> = (0..10).map(|i| P3::new(i as f64, 0.0, 0.0)).collect();
        assert!((min_sphere(&line).radius - 4.5).abs() < 1e-12);
        let dup = [P3::new(1.0, 2.0, 3.0); 5];
        assert_eq!(min_sphere(&dup).radius, 0.0);
        let r = ritter_sphere(&sq);
        assert!(r.radius >= s.radius - 1e-12);
    }
}
