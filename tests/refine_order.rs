//! The orders the refinement works in for speed change its time, never its result: the
//! reinsertion search in Z-order finds the same moves as in candidate order, and treelet
//! heights from the Subset Tree's slot order equal those of a depth-first walk; and the
//! treelet γ follows its documented size rule.

use wraptree::grouping::{Params, group};
use wraptree::refine::reinsert::{self, Move};
use wraptree::refine::treelet;
use wraptree::refine::work::WorkTree;
use wraptree::refine::{RefineParams, Tuning, refine_tuned};
use wraptree::scene::generate;

fn work_tree(n: usize, seed: u64) -> WorkTree {
    let scene = generate::soup(n, seed);
    WorkTree::of(&group(&scene, &Params::default(), ()).tree)
}

#[test]
fn the_search_in_z_order_finds_the_moves_of_the_search_in_candidate_order() {
    let w = work_tree(20_000, 3);
    let candidates = reinsert::candidates(&w, 8_000);
    assert!(candidates.len() >= reinsert::SPATIAL_MIN);
    let min_gain = 1e-12;
    let mut stack = Vec::new();
    let mut plain: Vec<Move> = candidates
        .iter()
        .filter_map(|&c| reinsert::find_best(&w, c, min_gain, &mut stack))
        .collect();
    let mut ordered = reinsert::find_all(&w, &candidates, min_gain);
    assert!(plain.len() > 100, "{} moves found", plain.len());
    // Z-order is a different order of the same candidates...
    let z = reinsert::spatial_order(&w, &candidates);
    assert_ne!(z, candidates);
    let mut sorted = z.clone();
    sorted.sort_unstable();
    let mut set = candidates.clone();
    set.sort_unstable();
    assert_eq!(sorted, set);
    // ...and gives the same moves, ranked the same.
    reinsert::sort_best_first(&mut plain);
    reinsert::sort_best_first(&mut ordered);
    assert_eq!(plain, ordered);
}

#[test]
fn a_batch_searched_on_several_threads_finds_the_moves_of_one_thread() {
    // Between the parallel and the spatial thresholds: candidate order on one thread, Z-order
    // on rayon's threads on two.
    let w = work_tree(3_000, 5);
    let candidates = reinsert::candidates(&w, 600);
    assert!((reinsert::PARALLEL_MIN..reinsert::SPATIAL_MIN).contains(&candidates.len()));
    let search = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut moves = pool.install(|| reinsert::find_all(&w, &candidates, 1e-12));
        reinsert::sort_best_first(&mut moves);
        moves
    };
    let one = search(1);
    assert!(one.len() > 20, "{} moves found", one.len());
    assert_eq!(one, search(2));
}

#[test]
fn treelet_heights_from_the_slot_order_equal_those_of_a_tree_walk() {
    let mut w = work_tree(5_000, 4);
    assert!(w.topological);
    for gamma in [3, 64] {
        let scanned = treelet::by_height(&w, gamma);
        w.topological = false;
        let walked = treelet::by_height(&w, gamma);
        w.topological = true;
        assert!(scanned.len() > 3);
        assert_eq!(scanned, walked);
    }
}

#[test]
fn treelet_gamma_follows_the_size_rule() {
    let auto = Tuning::default();
    assert_eq!(auto.treelet_min, 0);
    for (n, gamma) in [
        (3, 64),
        (12_144, 64),
        (65_536, 64),
        (65_537, 128),
        (100_000, 128),
        (124_705, 128),
        (1_000_000, 1_024),
        (1 << 24, 16_384),
    ] {
        assert_eq!(auto.gamma(&RefineParams::default(), n), gamma, "n = {n}");
    }
    // The parameters' γ over the size rule, the tuning's over both.
    let eight = RefineParams {
        treelet_min: 8,
        ..RefineParams::default()
    };
    assert_eq!(auto.gamma(&eight, 1_000_000), 8);
    let fixed = Tuning {
        treelet_min: 3,
        ..Tuning::default()
    };
    assert_eq!(fixed.gamma(&RefineParams::default(), 1_000_000), 3);
    assert_eq!(fixed.gamma(&eight, 1_000_000), 3);
    // The rule is the default: γ = 64 set explicitly gives the same run below 65,536.
    let scene = generate::soup(3_000, 5);
    let tree = group(&scene, &Params::default(), ()).tree;
    let p = RefineParams::default();
    let explicit = Tuning {
        treelet_min: 64,
        ..Tuning::default()
    };
    let a = refine_tuned(&tree, &p, &auto, ());
    let b = refine_tuned(&tree, &p, &explicit, ());
    assert!(a.steps > 0);
    assert_eq!(a.tree, b.tree);
}
