//! Exact `f64` distances from a point to a segment and to a triangle.

use super::P3;
use std::cmp::Ordering::Greater;

/// Distance from `p` to the segment `a`–`b`.
pub fn point_segment(p: &P3, a: &P3, b: &P3) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

/// Distance from `p` to the triangle `a b c` (Ericson, "Real-Time Collision Detection" §5.1.5);
/// degenerate triangles are measured as their edges.
pub fn point_triangle(p: &P3, a: &P3, b: &P3, c: &P3) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let n2 = ab.cross(&ac).norm_squared();
    if n2.partial_cmp(&(1e-24 * ab.norm_squared() * ac.norm_squared())) != Some(Greater) {
        return point_segment(p, a, b)
            .min(point_segment(p, b, c))
            .min(point_segment(p, a, c));
    }
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.norm();
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return bp.norm();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (p - (a + ab * (d1 / (d1 - d3)))).norm();
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return cp.norm();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (p - (a + ac * (d2 / (d2 - d6)))).norm();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (p - (b + (c - b) * w)).norm();
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (p - (a + ab * v + ac * w)).norm()
}

/// Distance between the segments `p1`–`q1` and `p2`–`q2` (Ericson §5.1.9); zero-length
/// segments are points. The closed form is then compared with the four endpoint–segment
/// distances, so near-parallel segments (where the closed form loses precision) still get the
/// exact minimum, which for parallel segments lies at an endpoint.
pub fn segment_segment(p1: &P3, q1: &P3, p2: &P3, q2: &P3) -> f64 {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let (s, t) = if a == 0.0 && e == 0.0 {
        (0.0, 0.0)
    } else if a == 0.0 {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e == 0.0 {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let s = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t = (b * s + f) / e;
            if t < 0.0 {
                ((-c / a).clamp(0.0, 1.0), 0.0)
            } else if t > 1.0 {
                (((b - c) / a).clamp(0.0, 1.0), 1.0)
            } else {
                (s, t)
            }
        }
    };
    let closed = ((p1 + d1 * s) - (p2 + d2 * t)).norm();
    closed
        .min(point_segment(p1, p2, q2))
        .min(point_segment(q1, p2, q2))
        .min(point_segment(p2, p1, q1))
        .min(point_segment(q2, p1, q1))
}

/// Signed volume (×6) of the tetrahedron `a b c d`: positive when `d` lies on the side of
/// plane `a b c` that its normal `(b − a) × (c − a)` points to.
fn orient(a: &P3, b: &P3, c: &P3, d: &P3) -> f64 {
    (b - a).cross(&(c - a)).dot(&(d - a))
}

/// Whether triangle `a b c` is degenerate (collinear or coincident corners), by the same test
/// as [`point_triangle`].
fn degenerate(a: &P3, b: &P3, c: &P3) -> bool {
    let (ab, ac) = (b - a, c - a);
    let n2 = ab.cross(&ac).norm_squared();
    n2.partial_cmp(&(1e-24 * ab.norm_squared() * ac.norm_squared())) != Some(Greater)
}

/// Whether the segment `p`–`q` crosses the non-degenerate triangle `a b c` transversally:
/// `p` and `q` strictly on opposite sides of its plane and the crossing point inside the
/// closed triangle (the three signed volumes of `p q` with the edges agree in sign).
///
/// Segments that merely touch the plane at an endpoint, or lie in it, are not crossings:
/// for those the endpoint–triangle and segment–edge distances are already 0. Degenerate
/// triangles never cross (they are measured as their edges).
pub fn segment_crosses_triangle(p: &P3, q: &P3, a: &P3, b: &P3, c: &P3) -> bool {
    if degenerate(a, b, c) {
        return false;
    }
    let (sp, sq) = (orient(a, b, c, p), orient(a, b, c, q));
    if !((sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0)) {
        return false;
    }
    let v = [orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a)];
    v.iter().all(|&x| x >= 0.0) || v.iter().all(|&x| x <= 0.0)
}

/// Distance between the segment `p`–`q` and the triangle `a b c`: 0 if the segment crosses it,
/// else the least of the two endpoint–triangle and three segment–edge distances (which covers
/// touching, in-plane and degenerate cases).
pub fn segment_triangle(p: &P3, q: &P3, a: &P3, b: &P3, c: &P3) -> f64 {
    if segment_crosses_triangle(p, q, a, b, c) {
        return 0.0;
    }
    point_triangle(p, a, b, c)
        .min(point_triangle(q, a, b, c))
        .min(segment_segment(p, q, a, b))
        .min(segment_segment(p, q, b, c))
        .min(segment_segment(p, q, c, a))
}

/// Exact `f64` distance between two closed triangles `t` and `u`.
///
/// 0 when an edge of one crosses the other (a transversal intersection); otherwise the
/// minimum of the 6 vertex–triangle and 9 edge–edge distances, which is the distance between
/// disjoint triangles and 0 for touching, coplanar-overlapping and nested ones. Degenerate
/// triangles (segments, points) are handled by measuring them as their edges.
pub fn triangle_triangle(t: [&P3; 3], u: [&P3; 3]) -> f64 {
    let edge = |k: usize| (k, (k + 1) % 3);
    for k in 0..3 {
        let (i, j) = edge(k);
        if segment_crosses_triangle(t[i], t[j], u[0], u[1], u[2])
            || segment_crosses_triangle(u[i], u[j], t[0], t[1], t[2])
        {
            return 0.0;
        }
    }
    let mut best = f64::INFINITY;
    for k in 0..3 {
        best = best
            .min(point_triangle(t[k], u[0], u[1], u[2]))
            .min(point_triangle(u[k], t[0], t[1], t[2]));
        let (i, j) = edge(k);
        for m in 0..3 {
            let (x, y) = edge(m);
            best = best.min(segment_segment(t[i], t[j], u[x], u[y]));
        }
    }
    best
}
