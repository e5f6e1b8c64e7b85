//! Random triangle soups: the synthetic scene both `generate.rs` and `pathological.rs` build
//! on.

use super::{PrimitiveKind, Scene};
use crate::geom::{P3, V3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `n` random triangles uniformly in the unit cube, named `soup{n}`.
///
/// Each triangle's corners are drawn in a cube of side 1.5 / n^(1/3) around a uniform centre
/// (mean edge ≈ 1 / n^(1/3)); corners are redrawn until the area is at least 1% of the
/// squared edge scale, so no triangle is degenerate.
pub fn soup(n: usize, seed: u64) -> Scene {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let e = 1.5 / (n.max(1) as f64).cbrt();
    let mut s = Scene::new(format!("soup{n}"));
    s.points.reserve(3 * n);
    for _ in 0..n {
        let c = V3::from(rng.random::<[f64; 3]>());
        loop {
            let mut corner =
                || P3::from(c + V3::from(rng.random::<[f64; 3]>().map(|x| (x - 0.5) * e)));
            let (a, b, d) = (corner(), corner(), corner());
            if (b - a).cross(&(d - a)).norm() / 2.0 >= 0.01 * e * e {
                s.points.extend([a, b, d]);
                break;
            }
        }
    }
    let n32 = n as u32;
    s.prim_points = (0..3 * n32).collect();
    s.prim_start = (0..=n32).map(|i| 3 * i).collect();
    s.tris = (0..n32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    s.tri_start = (0..=n32).collect();
    s.kind = (n > 0).then_some(PrimitiveKind::Polygon);
    s
}
