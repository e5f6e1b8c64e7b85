//! The solid convex hull in exact orientation: Quickhull (Barber, Dobkin and Huhdanpaa) whose
//! every "is this point above that face" is decided by Shewchuk's adaptive `orient3d` (the
//! `robust` crate) on the input's own `f64` coordinates.
//!
//! Exact decisions make the hull a closed, convex, consistently oriented surface on any input
//! that spans a tetrahedron, whatever its scales: a point is visible from a face only when it is
//! strictly above it, the visible faces then form a disc, and a new face joins a horizon edge to
//! a point off that edge's line, so no step can fold the surface or fail. Floating point only
//! orders the work (the farthest point of a face comes first), which changes speed, not the
//! result's correctness. Each point is tested against the faces it may see (conflict lists), so
//! the work grows with the points and the faces they replace, never with points × faces.

use crate::geom::P3;
use robust::{Coord3D, orient3d};
use std::collections::HashMap;

/// A face `[a, b, c]`, counter-clockwise seen from outside, with the points it alone sees.
struct Face {
    v: [u32; 3],
    alive: bool,
    /// Points strictly above this face not yet on the hull.
    outside: Vec<u32>,
}

/// `orient3d`'s argument for `p`.
fn coord(p: &P3) -> Coord3D<f64> {
    Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// Positive exactly when `q` lies strictly above the plane of the counter-clockwise triangle
/// `a, b, c` (on the side it faces).
fn above(points: &[P3], [a, b, c]: [u32; 3], q: &P3) -> f64 {
    let p = |i: u32| coord(&points[i as usize]);
    -orient3d(p(a), p(b), p(c), coord(q))
}

/// Whether `q` lies on or below the plane of the counter-clockwise triangle `v`, exactly.
pub(super) fn behind(points: &[P3], v: [u32; 3], q: &P3) -> bool {
    above(points, v, q) <= 0.0
}

/// An approximate height of `q` above face `v`, used only to pick the farthest point.
fn height(points: &[P3], [a, b, c]: [u32; 3], q: &P3) -> f64 {
    let [a, b, c] = [a, b, c].map(|i| points[i as usize]);
    (b - a).cross(&(c - a)).dot(&(q - a))
}

/// Vertex indices into `points` (ascending) and outward triangles indexing those vertices, or
/// `None` when every point lies exactly in one plane.
pub(super) fn hull(points: &[P3]) -> Option<(Vec<usize>, Vec<[u32; 3]>)> {
    let n = points.len();
    if n < 4 || n > u32::MAX as usize {
        return None;
    }
    let tet = initial_tetrahedron(points)?;
    let mut faces: Vec<Face> = Vec::new();
    // Directed edge (a, b) → the face that has it.
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    let add = |faces: &mut Vec<Face>, edges: &mut HashMap<(u32, u32), u32>, v: [u32; 3]| {
        let id = faces.len() as u32;
        for k in 0..3 {
            edges.insert((v[k], v[(k + 1) % 3]), id);
        }
        faces.push(Face {
            v,
            alive: true,
            outside: Vec::new(),
        });
        id
    };
    let [i0, i1, i2, i3] = tet;
    for v in [[i0, i1, i2], [i0, i3, i1], [i1, i3, i2], [i2, i3, i0]] {
        add(&mut faces, &mut edges, v);
    }
    // Each remaining point goes to the first face that sees it; points no face sees are inside.
    for q in 0..n as u32 {
        if tet.contains(&q) {
            continue;
        }
        if let Some(f) = (0..4).find(|&f| above(points, faces[f].v, &points[q as usize]) > 0.0) {
            faces[f].outside.push(q);
        }
    }
    let mut pending: Vec<u32> = (0..4)
        .filter(|&f| !faces[f as usize].outside.is_empty())
        .collect();
    let mut visible: Vec<u32> = Vec::new();
    let mut horizon: Vec<(u32, u32)> = Vec::new();
    let mut stack: Vec<u32> = Vec::new();
    let mut orphans: Vec<u32> = Vec::new();
    while let Some(f) = pending.pop() {
        let face = &faces[f as usize];
        if !face.alive || face.outside.is_empty() {
            continue;
        }
        let eye = *face
            .outside
            .iter()
            .max_by(|&&a, &&b| {
                let h = |q: u32| height(points, face.v, &points[q as usize]);
                h(a).total_cmp(&h(b)).then(b.cmp(&a))
            })
            .expect("non-empty");
        let e = points[eye as usize];
        // The faces the eye sees: a connected disc around `f`, found by walking across edges.
        visible.clear();
        horizon.clear();
        faces[f as usize].alive = false;
        stack.push(f);
        while let Some(g) = stack.pop() {
            visible.push(g);
            let v = faces[g as usize].v;
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                let h = edges[&(b, a)];
                let other = &faces[h as usize];
                if !other.alive {
                    continue;
                }
                if above(points, other.v, &e) > 0.0 {
                    faces[h as usize].alive = false;
                    stack.push(h);
                } else {
                    horizon.push((a, b));
                }
            }
        }
        orphans.clear();
        for &g in &visible {
            let v = faces[g as usize].v;
            for k in 0..3 {
                edges.remove(&(v[k], v[(k + 1) % 3]));
            }
            orphans.append(&mut faces[g as usize].outside);
        }
        let first = faces.len() as u32;
        for &(a, b) in &horizon {
            add(&mut faces, &mut edges, [a, b, eye]);
        }
        for &q in &orphans {
            if q == eye {
                continue;
            }
            let p = points[q as usize];
            if let Some(g) =
                (first..faces.len() as u32).find(|&g| above(points, faces[g as usize].v, &p) > 0.0)
            {
                faces[g as usize].outside.push(q);
            }
        }
        pending
            .extend((first..faces.len() as u32).filter(|&g| !faces[g as usize].outside.is_empty()));
    }
    let alive: Vec<[u32; 3]> = faces.iter().filter(|f| f.alive).map(|f| f.v).collect();
    let mut used: Vec<usize> = alive.iter().flatten().map(|&i| i as usize).collect();
    used.sort_unstable();
    used.dedup();
    let at = |i: u32| {
        used.binary_search(&(i as usize))
            .expect("a vertex of the hull") as u32
    };
    let triangles = alive.iter().map(|v| v.map(at)).collect();
    Some((used, triangles))
}

/// Four points spanning a tetrahedron, ordered so that `[0, 1, 2]` faces away from `3`; `None`
/// when all points lie exactly in one plane.
fn initial_tetrahedron(points: &[P3]) -> Option<[u32; 4]> {
    let far = |from: &dyn Fn(&P3) -> f64| {
        (0..points.len()).max_by(|&a, &b| {
            from(&points[a])
                .total_cmp(&from(&points[b]))
                .then(b.cmp(&a))
        })
    };
    let i0 = far(&|p| -p.x)?;
    let i1 = far(&|p| (p - points[i0]).norm_squared())?;
    let axis = (points[i1] - points[i0]).try_normalize(0.0)?;
    let i2 = far(&|p| {
        let d = p - points[i0];
        (d - axis * axis.dot(&d)).norm_squared()
    })?;
    let [a, b, c] = [i0, i1, i2].map(|i| coord(&points[i]));
    let i3 = far(&|p| orient3d(a, b, c, coord(p)).abs())?;
    // Whatever the floating-point choice said, an exact witness may still exist.
    let i3 = if orient3d(a, b, c, coord(&points[i3])) == 0.0 {
        (0..points.len()).find(|&i| orient3d(a, b, c, coord(&points[i])) != 0.0)?
    } else {
        i3
    };
    tetrahedron(points, [i0, i1, i2, i3])
}

/// `[a, b, c, d]` ordered so that `d` lies below the counter-clockwise `[a, b, c]`; `None` when
/// the four are coplanar or `a, b, c` collinear.
fn tetrahedron(points: &[P3], [a, b, c, d]: [usize; 4]) -> Option<[u32; 4]> {
    let p = |i: usize| coord(&points[i]);
    let o = orient3d(p(a), p(b), p(c), p(d));
    let [a, b, c, d] = [a, b, c, d].map(|i| i as u32);
    if o > 0.0 {
        Some([a, b, c, d])
    } else if o < 0.0 {
        Some([a, c, b, d])
    } else {
        None
    }
}
