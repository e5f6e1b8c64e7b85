//! Seeded, reproducible synthetic scenes standing in for the paper's inputs.
//!
//! - [`robot_base`]: a robot-base-like part of exactly 276 convex polygons (Figure 1);
//! - [`lamp`]: a desk lamp of exactly 626 convex polygons (Figure 2), with long thin arm rods;
//! - [`replicate`]: copies randomly rotated and moved so that they overlap somewhat
//!   (Figure 3: lamp × 5 = 3,130 polygons; Figure 4: robot base × 44 = 12,144 polygons);
//! - [`soup`]: N random triangles uniformly in the unit cube.
//!
//! Every polygon is planar and convex (cylinder sides are rectangles, frustum and annulus
//! pieces isosceles trapezoids, caps regular n-gons) and wound counter-clockwise seen from
//! outside. Randomness is `ChaCha8Rng::seed_from_u64(seed)`, so a seed fixes the scene on
//! every platform. Units are metres.

use nalgebra::{Quaternion, UnitQuaternion};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub use super::soup::soup;
use super::{PrimitiveKind, Scene};
use crate::geom::{P3, V3};

/// The kinds [`by_name`] knows.
pub const KINDS: [&str; 5] = ["robot-base", "lamp", "lamps", "robot-bases", "soup"];

/// Builds a polygon scene piece by piece.
struct Builder {
    scene: Scene,
}

impl Builder {
    fn new(name: &str) -> Builder {
        Builder {
            scene: Scene::new(name),
        }
    }

    fn point(&mut self, p: P3) -> u32 {
        self.scene.points.push(p);
        (self.scene.points.len() - 1) as u32
    }

    fn polygon(&mut self, v: &[u32]) {
        let tris: Vec<[u32; 3]> = (1..v.len() - 1).map(|k| [v[0], v[k], v[k + 1]]).collect();
        self.scene.push(PrimitiveKind::Polygon, v, &tris);
    }

    /// `n` points on the circle of radius `r` about `c` in the plane spanned by `u`, `v`.
    fn circle(&mut self, c: P3, u: V3, v: V3, r: f64, n: usize) -> Vec<u32> {
        (0..n)
            .map(|j| {
                let a = std::f64::consts::TAU * j as f64 / n as f64;
                self.point(c + (u * a.cos() + v * a.sin()) * r)
            })
            .collect()
    }

    /// Closes the quads between two rings of equal length (`outward` picks the winding).
    fn band(&mut self, lo: &[u32], hi: &[u32], outward: bool) {
        let n = lo.len();
        for j in 0..n {
            let k = (j + 1) % n;
            if outward {
                self.polygon(&[lo[j], lo[k], hi[k], hi[j]]);
            } else {
                self.polygon(&[lo[j], hi[j], hi[k], lo[k]]);
            }
        }
    }

    /// A frustum from `a` (radius `ra`) to `b` (radius `rb`) with `n` sides and `rings` bands;
    /// `caps` closes the `a` and `b` ends. `n · rings` sides plus the caps.
    #[allow(clippy::too_many_arguments)]
    fn frustum(&mut self, a: P3, b: P3, ra: f64, rb: f64, n: usize, rings: usize, caps: [bool; 2]) {
        let (u, v, _) = frame(b - a);
        let ring: Vec<Vec<u32>> = (0..=rings)
            .map(|i| {
                let t = i as f64 / rings as f64;
                self.circle(a + (b - a) * t, u, v, ra + (rb - ra) * t, n)
            })
            .collect();
        for i in 0..rings {
            self.band(&ring[i], &ring[i + 1], true);
        }
        if caps[0] {
            let rev: Vec<u32> = ring[0].iter().rev().copied().collect();
            self.polygon(&rev);
        }
        if caps[1] {
            self.polygon(&ring[rings]);
        }
    }

    /// A cylinder of radius `r` from `a` to `b` with `n` sides: `n` rectangles plus the caps.
    fn cylinder(&mut self, a: P3, b: P3, r: f64, n: usize, caps: [bool; 2]) {
        self.frustum(a, b, r, r, n, 1, caps);
    }

    /// A thick ring (washer) on axis `a → b`: outer, inner, top and bottom faces, `4 n` quads.
    fn washer(&mut self, a: P3, b: P3, r_in: f64, r_out: f64, n: usize) {
        let (u, v, _) = frame(b - a);
        let (ai, ao) = (
            self.circle(a, u, v, r_in, n),
            self.circle(a, u, v, r_out, n),
        );
        let (bi, bo) = (
            self.circle(b, u, v, r_in, n),
            self.circle(b, u, v, r_out, n),
        );
        self.band(&ao, &bo, true);
        self.band(&ai, &bi, false);
        self.band(&bi, &bo, false);
        self.band(&ai, &ao, true);
    }

    /// A box centred at `c` with half-extents `h` along the frame of `axis`: 6 quads.
    fn cuboid(&mut self, c: P3, axis: V3, h: [f64; 3]) {
        let (u, v, w) = frame(axis);
        let (lo, hi): (Vec<u32>, Vec<u32>) = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .map(|&(x, y)| {
                let base = c + u * (x * h[0]) + v * (y * h[1]);
                (self.point(base - w * h[2]), self.point(base + w * h[2]))
            })
            .unzip();
        self.band(&lo, &hi, true);
        let rev: Vec<u32> = lo.iter().rev().copied().collect();
        self.polygon(&rev);
        self.polygon(&hi);
    }
}

/// A right-handed orthonormal frame `(u, v, w)` with `w` along `axis`.
fn frame(axis: V3) -> (V3, V3, V3) {
    let w = axis.normalize();
    let helper = if w.x.abs() < 0.9 { V3::x() } else { V3::y() };
    let u = helper.cross(&w).normalize();
    (u, w.cross(&u), w)
}

/// A robot-base-like part of 276 convex polygons (the paper's Figure 1).
///
/// A 40-sided cylinder (42), a flange washer (160), a boss (26), six hexagonal bolt heads
/// (42) and a connector box (6).
pub fn robot_base() -> Scene {
    let mut b = Builder::new("robot-base");
    let z = V3::z();
    let at = |h: f64| P3::new(0.0, 0.0, h);
    b.cylinder(at(0.02), at(0.20), 0.10, 40, [true, true]);
    b.washer(at(0.0), at(0.02), 0.06, 0.16, 40);
    b.cylinder(at(0.20), at(0.26), 0.05, 24, [true, true]);
    for k in 0..6 {
        let a = std::f64::consts::TAU * (k as f64 + 0.5) / 6.0;
        let c = P3::new(0.13 * a.cos(), 0.13 * a.sin(), 0.02);
        b.cylinder(c, c + z * 0.01, 0.008, 6, [false, true]);
    }
    b.cuboid(P3::new(0.115, 0.0, 0.07), V3::x(), [0.025, 0.02, 0.015]);
    b.scene
}

/// A desk lamp of 626 convex polygons (the paper's Figure 2).
///
/// A base disc (50), a switch (7), three joints (54), two arms of two long thin rods each (56),
/// a conical shade of 9 bands (433) and a bulb socket (26).
pub fn lamp() -> Scene {
    let mut b = Builder::new("lamp");
    let (y, z) = (V3::y(), V3::z());
    b.cylinder(
        P3::origin(),
        P3::origin() + z * 0.025,
        0.09,
        48,
        [true, true],
    );
    let sw = P3::new(0.05, 0.03, 0.025);
    b.cylinder(sw, sw + z * 0.01, 0.01, 5, [true, true]);
    let joints = [
        P3::new(0.0, 0.0, 0.04),
        P3::new(0.10, 0.0, 0.36),
        P3::new(0.36, 0.0, 0.40),
    ];
    for j in joints {
        b.cylinder(j - y * 0.02, j + y * 0.02, 0.015, 16, [true, true]);
    }
    for arm in joints.windows(2) {
        for side in [-1.0, 1.0] {
            let off = y * (0.012 * side);
            b.cylinder(arm[0] + off, arm[1] + off, 0.005, 12, [true, true]);
        }
    }
    let d = V3::new(0.35, 0.0, -0.6).normalize();
    let top = joints[2] + d * 0.02;
    b.frustum(top, top + d * 0.16, 0.03, 0.10, 48, 9, [true, false]);
    b.cylinder(top + d * 0.005, top + d * 0.05, 0.016, 24, [true, true]);
    b.scene
}

/// A uniformly random rotation (Shoemake's method), drawn from `rng`.
pub fn random_rotation(rng: &mut ChaCha8Rng) -> UnitQuaternion<f64> {
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let (s1, s2) = ((1.0 - u1).sqrt(), u1.sqrt());
    let (t2, t3) = (std::f64::consts::TAU * u2, std::f64::consts::TAU * u3);
    UnitQuaternion::from_quaternion(Quaternion::new(
        s2 * t3.cos(),
        s1 * t2.sin(),
        s1 * t2.cos(),
        s2 * t3.sin(),
    ))
}

/// `copies` copies of `scene`, each but the first randomly rotated about its box centre and
/// moved within a cube of side 0.6 × diameter × copies^(1/3), so that neighbours overlap
/// somewhat. Named `{name}s{copies}` (e.g. `lamps5`); labels get a `#k` copy suffix and the
/// primitives of copy `k` have object id `k` (so `--pregroup objects` finds the copies).
pub fn replicate(scene: &Scene, copies: usize, seed: u64) -> Scene {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let bbox = scene.aabb();
    let (c, diam) = if scene.is_empty() {
        (P3::origin(), 0.0)
    } else {
        (bbox.center(), bbox.diameter())
    };
    let side = 0.6 * diam * (copies as f64).cbrt();
    let mut out = Scene::new(format!("{}s{copies}", scene.name));
    out.kind = scene.kind;
    for k in 0..copies {
        let moved = (k > 0).then(|| {
            let rot = random_rotation(&mut rng);
            let t: [f64; 3] = rng.random();
            (rot, V3::from(t.map(|x| (x - 0.5) * side)))
        });
        let place = |p: &P3| match moved {
            Some((rot, shift)) => c + rot * (p - c) + shift,
            None => *p,
        };
        out.append_copy(scene, place, k as u32);
        out.labels
            .extend(scene.labels.iter().map(|l| format!("{l}#{k}")));
    }
    out
}

/// The scene for `wraptree scene KIND`: `robot-base`, `lamp`, `lamps` (`copies`, default 5),
/// `robot-bases` (`copies`, default 44), `soup` (`n` triangles, default 10,000) or one of the
/// [`pathological`](super::pathological) kinds (`n` primitives).
///
/// `copies` and `n` are errors where they do not apply, and must be at least 1.
pub fn by_name(
    kind: &str,
    copies: Option<usize>,
    n: Option<usize>,
    seed: u64,
) -> Result<Scene, String> {
    let takes_copies = matches!(kind, "lamps" | "robot-bases");
    if copies.is_some() && !takes_copies {
        return Err(format!(
            "scene kind '{kind}' takes no copies (only lamps and robot-bases do)"
        ));
    }
    if n.is_some() && kind != "soup" && !super::pathological::KINDS.contains(&kind) {
        return Err(format!(
            "scene kind '{kind}' takes no triangle count (only soup does)"
        ));
    }
    if copies == Some(0) || n == Some(0) {
        return Err("copies and triangle counts must be at least 1".to_string());
    }
    // Vertex indices are u32: refuse sizes whose points would not fit.
    let too_big = |points: usize| {
        (points > u32::MAX as usize).then(|| format!("scene too large ({points} vertices)"))
    };
    let copied = |base: Scene, default: usize| {
        let k = copies.unwrap_or(default);
        match too_big(base.points.len().saturating_mul(k)) {
            Some(e) => Err(e),
            None => Ok(replicate(&base, k, seed)),
        }
    };
    match kind {
        "robot-base" => Ok(robot_base()),
        "lamp" => Ok(lamp()),
        "lamps" => copied(lamp(), 5),
        "robot-bases" => copied(robot_base(), 44),
        "soup" => {
            let n = n.unwrap_or(10_000);
            too_big(n.saturating_mul(3)).map_or_else(|| Ok(soup(n, seed)), Err)
        }
        _ => super::pathological::by_name(kind, n, seed).ok_or_else(|| {
            format!(
                "unknown scene kind '{kind}' (expected one of: {}, {})",
                KINDS.join(", "),
                super::pathological::KINDS.join(", ")
            )
        }),
    }
}
