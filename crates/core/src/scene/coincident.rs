//! Primitives that coincide with another one (the same vertices, in any order): double-sided
//! faces (each written twice, once per winding) or duplicated parts, as exports often write
//! them. Such pairs tie in every Cost and every query,
//! so the hull p-set and the query workload test far more pairs on them; the loaders say so.

use super::Scene;
use crate::geom::P3;
use rayon::prelude::*;

/// The number of primitives whose vertex set (coordinates bit for bit, in any order) is also
/// another primitive's. Primitives are sorted by an order-free hash of their vertices (no
/// allocation per primitive); only the few that share a hash are compared exactly.
pub fn count(scene: &Scene) -> usize {
    let mut keys: Vec<(u64, u32)> = (0..scene.len())
        .into_par_iter()
        .map(|i| {
            let h = scene
                .prim_vertices(i)
                .fold(0u64, |h, p| h.wrapping_add(mix(&bits(p))));
            (h, i as u32)
        })
        .collect();
    keys.par_sort_unstable();
    keys.chunk_by(|a, b| a.0 == b.0)
        .filter(|run| run.len() > 1)
        .map(|run| {
            let mut sets: Vec<Vec<[u64; 3]>> = run
                .iter()
                .map(|&(_, i)| {
                    let mut v: Vec<[u64; 3]> = scene.prim_vertices(i as usize).map(bits).collect();
                    v.sort_unstable();
                    v
                })
                .collect();
            sets.sort_unstable();
            sets.chunk_by(|a, b| a == b)
                .filter(|same| same.len() > 1)
                .map(<[_]>::len)
                .sum::<usize>()
        })
        .sum()
}

/// A vertex's coordinates as bits, −0 as 0.
fn bits(p: &P3) -> [u64; 3] {
    [p.x, p.y, p.z].map(|c| (c + 0.0).to_bits())
}

/// A well-mixed hash of a vertex's bits, summed over a primitive's vertices (any order).
fn mix(b: &[u64; 3]) -> u64 {
    b.iter().fold(0x9e37_79b9_7f4a_7c15u64, |h, &x| {
        let mut z = (h ^ x).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 31)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 29)
    })
}

/// The loader's warning for `scene` read from `file_name`, if some primitives coincide.
pub fn warning(file_name: &str, scene: &Scene) -> Option<String> {
    let n = count(scene);
    (n > 0).then(|| {
        format!(
            "{file_name}: {n} of {} primitives have the same vertices as another \
             (double-sided faces or duplicated parts); such pairs tie in every Cost and query, \
             which slows the hull p-set and bench's queries",
            scene.len()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::count;
    use crate::geom::P3;
    use crate::scene::pathological::{coincident, duplicates};
    use crate::scene::{PrimitiveKind, Scene, soup};

    #[test]
    fn stacked_copies_count_and_distinct_triangles_do_not() {
        assert_eq!(count(&coincident(50)), 50);
        assert_eq!(count(&duplicates(300, 3, 5)), 300);
        let s = soup::soup(200, 3);
        assert_eq!(count(&s), 0);
    }

    #[test]
    fn either_winding_coincides_and_a_shared_edge_does_not() {
        let mut s = Scene::new("faces");
        s.points = vec![
            P3::new(0.0, 0.0, 0.0),
            P3::new(1.0, 0.0, 0.0),
            P3::new(0.0, 1.0, -0.0),
            P3::new(1.0, 1.0, 0.0),
            P3::new(0.0, 1.0, 0.0),
        ];
        // A face, its back face (other winding, −0 for 0), and a neighbour on the shared edge.
        s.push(PrimitiveKind::Polygon, &[0, 1, 2], &[[0, 1, 2]]);
        s.push(PrimitiveKind::Polygon, &[4, 1, 0], &[[4, 1, 0]]);
        s.push(PrimitiveKind::Polygon, &[1, 3, 2], &[[1, 3, 2]]);
        assert_eq!(count(&s), 2);
    }
}
