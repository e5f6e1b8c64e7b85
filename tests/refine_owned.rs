//! Refining a tree handed over by value works in the tree's own arrays: it gives what refining
//! a borrowed tree gives, and the undo log that lets it give back the input (when the final
//! SAH check fails) restores every array.

use wraptree::grouping::{EventLog, Params, SubsetTree, group};
use wraptree::refine::reinsert;
use wraptree::refine::treelet;
use wraptree::refine::work::{Undo, WorkTree};
use wraptree::refine::{FAST, RefineParams, refine, refine_owned};
use wraptree::scene::{LoadOptions, generate, load_path};

fn trees() -> Vec<SubsetTree> {
    let mug = load_path(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/mug.obj"),
        &LoadOptions::default(),
    )
    .expect("bundled mug")
    .scene;
    [generate::soup(4_000, 5), mug]
        .iter()
        .map(|s| group(s, &Params::default(), ()).tree)
        .collect()
}

#[test]
fn refining_by_value_gives_the_steps_events_and_tree_of_refining_by_reference() {
    for tree in trees() {
        for params in [FAST, RefineParams::default()] {
            let (mut by_ref, mut by_value) = (EventLog::default(), EventLog::default());
            let a = refine(&tree, &params, &mut by_ref);
            let b = refine_owned(tree.clone(), &params, &mut by_value);
            assert!(a.steps > 0);
            assert_eq!(a.tree, b.tree);
            assert_eq!(a.sah_before.to_bits(), b.sah_before.to_bits());
            assert_eq!(a.sah_after.to_bits(), b.sah_after.to_bits());
            assert_eq!((a.steps, a.passes), (b.steps, b.passes));
            assert_eq!(by_ref.refine, by_value.refine);
            // The SAH reported is the result's, bit for bit.
            assert_eq!(
                b.sah_after.to_bits(),
                wraptree::grouping::sah(&b.tree).to_bits()
            );
        }
    }
}

#[test]
fn undoing_treelets_and_moves_newest_first_gives_back_every_array() {
    for tree in trees() {
        let (mut w, depth, diameter) = WorkTree::from_tree(tree.clone());
        let min_gain = 1e-12 * w.area[w.root as usize];
        let mut log = Vec::new();
        // Treelets rebuilt on the lowest heights, as a treelet pass does...
        for roots in treelet::by_height(&w, 3).into_iter().take(3) {
            for plan in treelet::solve_all(&w, &roots, 7, min_gain) {
                w.restructure(&plan, &mut log);
            }
        }
        let treelet_entries = log.len();
        // ...then moves, as a reinsertion pass applies them.
        let candidates = reinsert::candidates(&w, w.parent.len() / 10);
        let mut moves = reinsert::find_all(&w, &candidates, min_gain);
        reinsert::sort_best_first(&mut moves);
        for m in &moves {
            if reinsert::still_valid(&w, m) {
                let moved = w.reinsert(m.node, m.target);
                log.push(Undo::Move {
                    node: m.node,
                    sibling: moved.sibling,
                });
            }
        }
        assert!(treelet_entries > 0 && log.len() > treelet_entries + 10);
        assert_ne!(w.parent, tree.parent);
        for u in log.iter().rev() {
            w.undo(u);
        }
        let back = w.into_tree(depth, diameter);
        assert_eq!(back, tree);
        assert_eq!(back.root(), tree.root());
    }
}
