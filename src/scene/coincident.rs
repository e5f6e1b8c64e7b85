//! Primitives that coincide with another one (the same vertices, in any order): double-sided
//! faces (each written twice, once per winding) or duplicated parts, as exports often write
//! them. Such pairs tie in every Cost and every query,
//! so the hull p-set and the query workload test far more pairs on them; the loaders say so.

use super::Scene;
use rayon::prelude::*;

/// The number of primitives whose vertex set (coordinates bit for bit, in any order) is also
/// another primitive's.
pub fn count(scene: &Scene) -> usize {
    let mut keys: Vec<(Vec<[u64; 3]>, u32)> = (0..scene.len())
        .into_par_iter()
        .map(|i| {
            let mut v: Vec<[u64; 3]> = scene
                .prim_vertices(i)
                .map(|p| [p.x, p.y, p.z].map(|c| (c + 0.0).to_bits()))
                .collect();
            v.sort_unstable();
            (v, i as u32)
        })
        .collect();
    keys.par_sort_unstable();
    let mut coincident = 0;
    let mut run = 1;
    for k in 1..=keys.len() {
        if k < keys.len() && keys[k].0 == keys[k - 1].0 {
            run += 1;
            continue;
        }
        if run > 1 {
            coincident += run;
        }
        run = 1;
    }
    coincident
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
    use crate::scene::pathological::coincident;
    use crate::scene::soup;

    #[test]
    fn stacked_copies_count_and_distinct_triangles_do_not() {
        assert_eq!(count(&coincident(50)), 50);
        let s = soup::soup(200, 3);
        assert_eq!(count(&s), 0);
    }
}
