//! Insertion-based optimisation: remove a subtree and insert it where the sum of interior box
//! areas drops most (Bittner, Hapala and Havran, "Fast insertion-based optimization of bounding
//! volume hierarchies", CGF 2013), in the parallel form of Meister and Bittner ("Parallel
//! reinsertion for bounding volume hierarchy optimization", CGF 2018): every candidate's best
//! position is searched on the same frozen tree, then the moves are applied best first.
//! Reference implementations: obvhs 0.4 `bvh2/reinsertion.rs`, madmann91/bvh
//! `v2/reinsertion_optimizer.h`.
//!
//! Differences from those, each for the Subset Tree's contract:
//! - every move is re-checked against the current tree when applied (still valid, still a
//!   strict decrease of the SAH, else undone) instead of skipping moves that touch a node an
//!   earlier move touched, so the SAH never rises and more of a pass's moves survive;
//! - ties (equal gains) break by the moved node's id, and the search order is fixed, so the
//!   moves do not depend on the number of threads that searched them.

use super::work::WorkTree;
use crate::geom::Aabb;
use crate::grouping::NONE;
use crate::metrics::area;
use rayon::prelude::*;

/// The best move found for one node: put `node` next to `target`, lowering the sum of interior
/// areas by `gain` (> 0) as computed on the tree the search ran on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Move {
    /// The subtree moved.
    pub node: u32,
    /// Its new sibling.
    pub target: u32,
    /// Decrease of Σ interior area.
    pub gain: f64,
}

/// The position for `node` that lowers the sum of interior areas most, if any lowers it by
/// more than `min_gain`.
///
/// Removing `node` deletes its parent `p` (area A(p)) and shrinks `p`'s ancestors; inserting it
/// next to `t` adds a parent of area A(node ∪ t) and grows `t`'s ancestors below the common
/// one. The search climbs from `p`, and at each ancestor explores the other child's subtree
/// best-first-by-bound: a subtree whose bound (the removal gain so far minus the growth above
/// it minus A(node)) cannot beat the best found is skipped (branch and bound of Bittner 2013).
pub fn find_best(
    w: &WorkTree,
    node: u32,
    min_gain: f64,
    stack: &mut Vec<(f64, u32)>,
) -> Option<Move> {
    let p = w.parent[node as usize];
    if p == NONE {
        return None;
    }
    let bx: Aabb = w.aabb[node as usize];
    let node_area = w.area[node as usize];
    let first = w.sibling(node);
    let (mut best_t, mut best_g) = (NONE, min_gain);
    let mut removal = w.area[p as usize];
    let mut sibling = first;
    let mut pivot = p;
    let mut pivot_box = w.aabb[first as usize];
    loop {
        stack.clear();
        stack.push((removal, sibling));
        while let Some((d, t)) = stack.pop() {
            if d - node_area <= best_g {
                continue;
            }
            let merged = area(&w.aabb[t as usize].merge(&bx));
            let g = d - merged;
            if g > best_g {
                (best_t, best_g) = (t, g);
            }
            if !w.is_leaf(t) {
                let down = g + w.area[t as usize];
                let [a, b] = w.kids(t);
                stack.push((down, b));
                stack.push((down, a));
            }
        }
        if pivot != p {
            pivot_box = pivot_box.merge(&w.aabb[sibling as usize]);
            removal += w.area[pivot as usize] - area(&pivot_box);
        }
        if pivot == w.root {
            break;
        }
        sibling = w.sibling(pivot);
        pivot = w.parent[pivot as usize];
    }
    (best_t != NONE && best_t != first).then_some(Move {
        node,
        target: best_t,
        gain: best_g,
    })
}

/// The best moves of `candidates` on the frozen tree `w`, in candidate order (searched in
/// parallel; the result is the same for any number of threads). Batches under
/// [`PARALLEL_MIN`] are searched on the calling thread, where handing work to rayon costs
/// more than it saves.
pub fn find_all(w: &WorkTree, candidates: &[u32], min_gain: f64) -> Vec<Move> {
    if candidates.len() < PARALLEL_MIN {
        let mut stack = Vec::new();
        return candidates
            .iter()
            .filter_map(|&c| find_best(w, c, min_gain, &mut stack))
            .collect();
    }
    candidates
        .par_iter()
        .map_init(Vec::new, |stack, &c| find_best(w, c, min_gain, stack))
        .flatten_iter()
        .collect()
}

/// Fewest candidates searched in parallel.
pub const PARALLEL_MIN: usize = 2048;

/// Orders moves best first: larger gain, then smaller node id.
pub fn sort_best_first(moves: &mut [Move]) {
    moves.sort_unstable_by(|a, b| b.gain.total_cmp(&a.gain).then(a.node.cmp(&b.node)));
}

/// Whether `m` can still be applied to `w`: `node` has a parent, and `target` is neither its
/// parent nor its sibling nor inside its subtree.
pub fn still_valid(w: &WorkTree, m: &Move) -> bool {
    let p = w.parent[m.node as usize];
    p != NONE && m.target != p && m.target != w.sibling(m.node) && !w.is_under(m.target, m.node)
}

/// The `count` most promising candidates of a pass (ties by id): the non-root nodes `x` ranked
/// by A(p)² / min(A(x), A(s)) for parent `p` and sibling `s` — the parent's area times
/// its inefficiency over its smaller child, after Bittner 2013's m_min × m_area measure, which
/// that paper found best; here it ranks the children of inefficient, large parents. Measured
/// against ranking by A(x) (obvhs, madmann91/bvh), A(p) and A(p)² / (A(x) + A(s)) on the bench
/// scenes at the same batch: the lowest SAH and node tests for the same time (README).
///
/// The set is what matters ([`find_all`]'s moves are sorted by gain afterwards), so it is
/// selected, not sorted: returned in id order. Keys are computed on rayon's threads for large
/// trees; the set is the same for any number of threads.
pub fn candidates(w: &WorkTree, count: usize) -> Vec<u32> {
    let nodes = w.parent.len();
    let count = count.min(nodes - 1);
    if count == 0 {
        return Vec::new();
    }
    // Rank key: descending A(p)² / min(A(x), A(s)) (f64 total order), then ascending id,
    // packed in one integer so that selection compares plain numbers.
    let key = |x: usize| -> u128 {
        let p = w.parent[x];
        let k = if p == NONE {
            f64::NEG_INFINITY
        } else {
            let ap = w.area[p as usize];
            let small = w.area[x].min(w.area[w.sibling(x as u32) as usize]);
            ap * ap / small.max(f64::MIN_POSITIVE)
        };
        let b = k.to_bits() as i64;
        let ordered = ((b ^ (((b >> 63) as u64) >> 1) as i64) as u64) ^ (1 << 63);
        (u128::from(!ordered) << 32) | x as u128
    };
    let mut all: Vec<u128> = if nodes >= PARALLEL_MIN * 8 {
        (0..nodes).into_par_iter().map(key).collect()
    } else {
        (0..nodes).map(key).collect()
    };
    // The root ranks last (key −∞), so it is never among the first `count` ≤ N − 1.
    if count < all.len() {
        all.select_nth_unstable(count - 1);
        all.truncate(count);
    }
    let mut ids: Vec<u32> = all.iter().map(|&k| k as u32).collect();
    ids.sort_unstable();
    ids
}
