//! Seeded scenes on which bounding-volume builders fail or slow down: the "pathological" inputs
//! of the paper's §2.3 ("a box of spaghetti", where the number k of eligible partners per body
//! becomes N and the grouping phase O(N² log N)) and §4 (long thin and large flat primitives),
//! plus numerical edge cases (coincident, coplanar and collinear primitives, far offsets, huge
//! size ranges, many-vertex polygons, far-apart clusters).
//!
//! Every scene is made of convex polygons (`PrimitiveKind::Polygon`, drawn as fans), built
//! directly (not through the OBJ loader, which would drop the zero-area primitives that some of
//! these scenes exist to test). Randomness is `ChaCha8Rng::seed_from_u64(seed)`, so a seed fixes
//! the scene on every platform. [`by_name`] makes each with its default size for the
//! `wraptree scene` command and the `wraptree stress` study.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::soup::soup;
use super::{PrimitiveKind, Scene};
use crate::geom::{P3, V3};

/// The scene kinds [`by_name`] knows.
pub const KINDS: [&str; 12] = [
    "spaghetti-parallel",
    "spaghetti-random",
    "slabs",
    "coincident",
    "duplicates",
    "coplanar",
    "collinear",
    "offset",
    "scales",
    "ngons",
    "two-clusters",
    "thin-triangles",
];

/// Default primitive count of [`by_name`] (the `ngons` default is 200 polygons).
pub const DEFAULT_N: usize = 2_000;

/// Default aspect ratio (length / width) of the spaghetti strands and slab stacks.
pub const DEFAULT_ASPECT: f64 = 64.0;

/// How spaghetti strands are laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// All along the x axis, packed side by side in the y–z cross-section like a box of
    /// uncooked spaghetti.
    Parallel,
    /// Uniformly random directions, centres in a cube sized so that the strands fill it about
    /// as densely as the parallel box.
    Random,
}

/// Pushes the convex polygon `pts` (in order) as new vertices.
fn polygon(s: &mut Scene, pts: &[P3]) {
    let base = s.points.len() as u32;
    s.points.extend_from_slice(pts);
    let v: Vec<u32> = (base..base + pts.len() as u32).collect();
    let tris: Vec<[u32; 3]> = (1..v.len() - 1).map(|k| [v[0], v[k], v[k + 1]]).collect();
    s.push(PrimitiveKind::Polygon, &v, &tris);
}

/// A unit vector uniformly distributed on the sphere.
fn random_direction(rng: &mut ChaCha8Rng) -> V3 {
    let z: f64 = rng.random::<f64>() * 2.0 - 1.0;
    let a = std::f64::consts::TAU * rng.random::<f64>();
    let r = (1.0 - z * z).max(0.0).sqrt();
    V3::new(r * a.cos(), r * a.sin(), z)
}

/// A unit vector perpendicular to the unit vector `d`.
fn perpendicular(d: &V3) -> V3 {
    let helper = if d.x.abs() < 0.9 { V3::x() } else { V3::y() };
    helper.cross(d).normalize()
}

/// `n` strands of length 1 and width 1 / `aspect`: even-numbered ones are rectangles, odd ones
/// isosceles thin triangles (base = width, height = length).
///
/// Each strand lies in a plane through its long axis turned by a random angle about that axis.
/// [`Layout::Parallel`] packs the strands on a square grid of pitch 1.5 × width in the y–z
/// cross-section (x jittered by ±0.05), so for `aspect` ≳ 1.5·√n the whole bundle is narrower
/// than one voxel of the first round and every strand is eligible to merge with every other:
/// k = N. [`Layout::Random`] puts centres uniformly in a cube of side
/// (4 n / aspect²)^(1/3) (at least 1) with random directions.
pub fn spaghetti(n: usize, aspect: f64, layout: Layout, seed: u64) -> Scene {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let aspect = aspect.max(1.0);
    let w = 1.0 / aspect;
    let name = match layout {
        Layout::Parallel => "spaghetti-parallel",
        Layout::Random => "spaghetti-random",
    };
    let mut s = Scene::new(format!("{name}-a{aspect}"));
    let side = (n.max(1) as f64).sqrt().ceil() as usize;
    let cube = (4.0 * n as f64 / (aspect * aspect)).cbrt().max(1.0);
    for i in 0..n {
        let (c, d) = match layout {
            Layout::Parallel => {
                let (gy, gz) = ((i % side) as f64, (i / side) as f64);
                let x = (rng.random::<f64>() - 0.5) * 0.1;
                (P3::new(x, gy * 1.5 * w, gz * 1.5 * w), V3::x())
            }
            Layout::Random => {
                let c: [f64; 3] = rng.random();
                (P3::from(V3::from(c) * cube), random_direction(&mut rng))
            }
        };
        let turn = std::f64::consts::TAU * rng.random::<f64>();
        let u = perpendicular(&d);
        let across = (u * turn.cos() + d.cross(&u) * turn.sin()) * (w / 2.0);
        let (a, b) = (c - d * 0.5, c + d * 0.5);
        if i % 2 == 0 {
            polygon(&mut s, &[a - across, b - across, b + across, a + across]);
        } else {
            polygon(&mut s, &[a - across, b, a + across]);
        }
    }
    s
}

/// `n` thin triangles only (sharp apex angle ≈ 1 / `aspect`), random directions as in
/// [`spaghetti`] with [`Layout::Random`]: the case where cutting across the long axis cannot
/// lower the apex piece's aspect (see [`crate::scene::split`]).
pub fn thin_triangles(n: usize, aspect: f64, seed: u64) -> Scene {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let aspect = aspect.max(1.0);
    let w = 1.0 / aspect;
    let cube = (4.0 * n as f64 / (aspect * aspect)).cbrt().max(1.0);
    let mut s = Scene::new(format!("thin-triangles-a{aspect}"));
    for _ in 0..n {
        let c = P3::from(V3::from(rng.random::<[f64; 3]>()) * cube);
        let d = random_direction(&mut rng);
        let across = perpendicular(&d) * (w / 2.0);
        polygon(
            &mut s,
            &[c - d * 0.5 - across, c + d * 0.5, c - d * 0.5 + across],
        );
    }
    s
}

/// `n` unit squares in the x–y plane stacked along z with spacing 1 / `aspect` (a stack of
/// thin plates: large and flat, §4), each shifted by up to ±0.05 in x and y. The stack is
/// n / aspect high, so for large `aspect` most plates share a voxel.
pub fn slabs(n: usize, aspect: f64, seed: u64) -> Scene {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let gap = 1.0 / aspect.max(1.0);
    let mut s = Scene::new(format!("slabs-a{aspect}"));
    for i in 0..n {
        let (x, y) = (
            (rng.random::<f64>() - 0.5) * 0.1,
            (rng.random::<f64>() - 0.5) * 0.1,
        );
        let z = i as f64 * gap;
        let q = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        let pts: Vec<P3> = q.iter().map(|&(a, b)| P3::new(x + a, y + b, z)).collect();
        polygon(&mut s, &pts);
    }
    s
}

/// `n` exact copies of one triangle (every primitive has its own, bit-identical vertices):
/// every diameter is equal, every gap 0 and every cost ties.
pub fn coincident(n: usize) -> Scene {
    let mut s = Scene::new(format!("coincident{n}"));
    let t = [
        P3::new(0.1, 0.2, 0.3),
        P3::new(1.1, 0.25, 0.3),
        P3::new(0.4, 0.9, 0.35),
    ];
    for _ in 0..n {
        polygon(&mut s, &t);
    }
    s
}

/// A random soup of `n` / `copies` triangles ([`soup`]) repeated `copies` times
/// without moving it: every primitive has `copies − 1` exact duplicates.
pub fn duplicates(n: usize, copies: usize, seed: u64) -> Scene {
    let copies = copies.max(1);
    let base = soup((n / copies).max(1), seed);
    let mut s = Scene::new(format!("duplicates{}x{copies}", base.len()));
    for _ in 0..copies {
        for i in 0..base.len() {
            let pts: Vec<P3> = base.prim_vertices(i).copied().collect();
            polygon(&mut s, &pts);
        }
    }
    s
}

/// A random soup of `n` triangles flattened into the plane z = 0 (every AABB is flat, every
/// hull two-dimensional).
pub fn coplanar(n: usize, seed: u64) -> Scene {
    let mut s = soup(n, seed);
    for p in &mut s.points {
        p.z = 0.0;
    }
    s.name = format!("coplanar{n}");
    s
}

/// `n` degenerate "triangles" whose three vertices lie on the x axis (segments of length up to
/// 3 / n^(1/3) in [0, 1]): zero area, every box and hull one-dimensional.
pub fn collinear(n: usize, seed: u64) -> Scene {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let e = 3.0 / (n.max(1) as f64).cbrt();
    let mut s = Scene::new(format!("collinear{n}"));
    for _ in 0..n {
        let c: f64 = rng.random();
        let xs: [f64; 3] = rng.random::<[f64; 3]>().map(|x| c + (x - 0.5) * e);
        let pts = xs.map(|x| P3::new(x, 0.0, 0.0));
        polygon(&mut s, &pts);
    }
    s
}

/// `scene` moved by `by` (e.g. 1e7 on every axis, where the ulp of a coordinate is 1.9e-9).
pub fn translated(scene: &Scene, by: V3) -> Scene {
    let mut s = scene.clone();
    for p in &mut s.points {
        *p += by;
    }
    s
}

/// A random soup of `n` triangles moved by (1e7, −1e7, 1e7).
pub fn offset(n: usize, seed: u64) -> Scene {
    let mut s = translated(&soup(n, seed), V3::new(1e7, -1e7, 1e7));
    s.name = format!("offset{n}");
    s
}

/// `n` random triangles whose sizes are log-uniform over 12 orders of magnitude (1e-6 to 1e6),
/// centres uniform in a cube of side 2e6.
pub fn scales(n: usize, seed: u64) -> Scene {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut s = Scene::new(format!("scales{n}"));
    for _ in 0..n {
        let size = 10f64.powf(-6.0 + 12.0 * rng.random::<f64>());
        let c = P3::from(V3::from(rng.random::<[f64; 3]>()) * 2e6);
        let u = random_direction(&mut rng);
        let v = perpendicular(&u);
        let a = 0.3 + 0.7 * rng.random::<f64>();
        polygon(&mut s, &[c, c + u * size, c + (u * 0.3 + v * a) * size]);
    }
    s
}

/// `n` regular polygons of `vertices` corners each (radius 0.5 / n^(1/3)), centres uniform in
/// the unit cube, random orientations: primitives far beyond the constant vertex bound the
/// paper assumes.
pub fn ngons(n: usize, vertices: usize, seed: u64) -> Scene {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let vertices = vertices.max(3);
    let r = 0.5 / (n.max(1) as f64).cbrt();
    let mut s = Scene::new(format!("ngons{n}x{vertices}"));
    for _ in 0..n {
        let c = P3::from(V3::from(rng.random::<[f64; 3]>()));
        let d = random_direction(&mut rng);
        let u = perpendicular(&d);
        let v = d.cross(&u);
        let pts: Vec<P3> = (0..vertices)
            .map(|j| {
                let a = std::f64::consts::TAU * j as f64 / vertices as f64;
                c + (u * a.cos() + v * a.sin()) * r
            })
            .collect();
        polygon(&mut s, &pts);
    }
    s
}

/// Two random soups of `n` / 2 triangles each in unit cubes 1e6 apart along x: the grouping
/// must double GLimit about twenty times before the clusters can join.
pub fn two_clusters(n: usize, seed: u64) -> Scene {
    let half = (n / 2).max(1);
    let a = soup(half, seed);
    let b = translated(&soup(n - half, seed + 1), V3::new(1e6, 0.0, 0.0));
    let mut s = Scene::new(format!("two-clusters{n}"));
    for src in [&a, &b] {
        for i in 0..src.len() {
            let pts: Vec<P3> = src.prim_vertices(i).copied().collect();
            polygon(&mut s, &pts);
        }
    }
    s
}

/// The scene `kind` (one of [`KINDS`]) with `n` primitives (default [`DEFAULT_N`], 200 for
/// `ngons`), aspect [`DEFAULT_ASPECT`] where it applies, and `seed`; `None` for other kinds.
pub fn by_name(kind: &str, n: Option<usize>, seed: u64) -> Option<Scene> {
    let n = n.unwrap_or(if kind == "ngons" { 200 } else { DEFAULT_N });
    let a = DEFAULT_ASPECT;
    Some(match kind {
        "spaghetti-parallel" => spaghetti(n, a, Layout::Parallel, seed),
        "spaghetti-random" => spaghetti(n, a, Layout::Random, seed),
        "thin-triangles" => thin_triangles(n, a, seed),
        "slabs" => slabs(n, 1000.0, seed),
        "coincident" => coincident(n),
        "duplicates" => duplicates(n, 4, seed),
        "coplanar" => coplanar(n, seed),
        "collinear" => collinear(n, seed),
        "offset" => offset(n, seed),
        "scales" => scales(n, seed),
        "ngons" => ngons(n, 1024, seed),
        "two-clusters" => two_clusters(n, seed),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_has_n_polygons_and_is_seeded() {
        for kind in KINDS {
            let a = by_name(kind, Some(40), 3).unwrap();
            let b = by_name(kind, Some(40), 3).unwrap();
            assert_eq!(a.len(), 40, "{kind}");
            assert_eq!(a.points, b.points, "{kind} is deterministic");
            assert_eq!(a.kind, Some(PrimitiveKind::Polygon));
            assert!(a.points.iter().all(|p| p.iter().all(|c| c.is_finite())));
        }
        assert!(by_name("nope", None, 0).is_none());
    }

    #[test]
    fn spaghetti_strands_have_the_asked_aspect() {
        let s = spaghetti(10, 50.0, Layout::Parallel, 1);
        let b = s.prim_aabb(0);
        assert!((b.extents().x - 1.0).abs() < 1e-12);
        assert!(b.extents().y.max(b.extents().z) <= 1.0 / 50.0 + 1e-12);
    }
}
