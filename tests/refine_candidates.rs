//! The reinsertion candidates, selected from one key per interior slot, are exactly the first
//! `count` non-root nodes of the documented ranking (A(p)² / min(A(x), A(s)) descending, then id
//! ascending), ties included: a grid of copies of one triangle has many slots of equal key.

use wraptree::geom::area;
use wraptree::geom::{P3, V3};
use wraptree::grouping::{NONE, Params, group};
use wraptree::refine::reinsert;
use wraptree::refine::work::WorkTree;
use wraptree::scene::{PrimitiveKind, Scene, generate};

/// The first `count` non-root nodes of the ranking, by sorting all of them, in id order.
fn by_sorting(w: &WorkTree, count: usize) -> Vec<u32> {
    let mut ranked: Vec<(f64, u32)> = (0..w.parent.len() as u32)
        .filter(|&x| w.parent[x as usize] != NONE)
        .map(|x| {
            let p = w.parent[x as usize];
            let s = w.sibling(x);
            let ap = area(&w.aabb[p as usize]);
            let small = area(&w.aabb[x as usize]).min(area(&w.aabb[s as usize]));
            (ap * ap / small.max(f64::MIN_POSITIVE), x)
        })
        .collect();
    ranked.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut ids: Vec<u32> = ranked.iter().take(count).map(|r| r.1).collect();
    ids.sort_unstable();
    ids
}

fn check(scene: &Scene) {
    let w = WorkTree::of(&group(scene, &Params::default(), ()).tree);
    let nodes = w.parent.len() - 1;
    for count in [
        1,
        2,
        3,
        7,
        nodes / 10,
        nodes / 3 + 1,
        nodes - 1,
        nodes,
        nodes + 5,
    ] {
        let mut set = reinsert::candidates(&w, count);
        set.sort_unstable();
        assert_eq!(set, by_sorting(&w, count), "count {count}");
    }
}

#[test]
fn candidates_are_the_first_of_the_ranking_on_a_soup() {
    check(&generate::soup(5_000, 11));
}

/// One triangle copied to every point of a 12 × 12 × 12 integer grid: boxes differ by whole
/// translations, so many slots have exactly equal keys.
fn grid() -> Scene {
    let mut s = Scene::new("grid");
    for i in 0..12 * 12 * 12u32 {
        let c = V3::new((i % 12) as f64, (i / 12 % 12) as f64, (i / 144) as f64);
        s.points.extend([
            P3::from(c),
            P3::from(c + V3::new(0.5, 0.25, 0.0)),
            P3::from(c + V3::new(0.0, 0.5, 0.25)),
        ]);
    }
    let n = 12 * 12 * 12u32;
    s.prim_points = (0..3 * n).collect();
    s.prim_start = (0..=n).map(|i| 3 * i).collect();
    s.tris = (0..n).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    s.tri_start = (0..=n).collect();
    s.kind = Some(PrimitiveKind::Polygon);
    s
}

#[test]
fn candidates_break_ties_by_id_on_a_grid() {
    let scene = grid();
    check(&scene);
    // The scene does have slots of equal key.
    let w = WorkTree::of(&group(&scene, &Params::default(), ()).tree);
    let mut keys: Vec<u64> = (0..w.children.len())
        .map(|i| {
            let [a, b] = w.children[i];
            let ap = w.area[w.n as usize + i];
            (ap * ap / w.area[a as usize].min(w.area[b as usize])).to_bits()
        })
        .collect();
    let all = keys.len();
    keys.sort_unstable();
    keys.dedup();
    assert!(keys.len() * 4 < all, "{} keys over {all} slots", keys.len());
}
