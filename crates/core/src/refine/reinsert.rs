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
use crate::geom::area;
use crate::geom::morton::spread_bits;
use crate::grouping::NONE;
use crate::par::parallel_here;
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
            // The children's bound, checked before they are stacked (the best gain only grows,
            // so one that fails now would be skipped when popped).
            if !w.is_leaf(t) && g + w.area[t as usize] - node_area > best_g {
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

/// The best moves of `candidates` (a set: their order is not used) on the frozen tree `w`.
/// Batches of [`PARALLEL_MIN`] and more are searched on rayon's threads in [`spatial_order`]
/// when called on a thread of a pool of several threads, and so are batches of [`SPATIAL_MIN`]
/// and more anywhere (the order keeps the tree in cache); others on the calling thread in id
/// order, where handing work to rayon or ordering by space costs more than it saves. The moves
/// come back in that fixed order, the same for any number of threads, and [`sort_best_first`]
/// ranks them independently of it.
pub fn find_all(w: &WorkTree, candidates: &[u32], min_gain: f64) -> Vec<Move> {
    let parallel = candidates.len() >= PARALLEL_MIN && parallel_here();
    if !parallel && candidates.len() < SPATIAL_MIN {
        let mut ids = candidates.to_vec();
        ids.sort_unstable();
        let mut stack = Vec::new();
        return ids
            .iter()
            .filter_map(|&c| find_best(w, c, min_gain, &mut stack))
            .collect();
    }
    spatial_order(w, candidates)
        .par_iter()
        .map_init(Vec::new, |stack, &c| find_best(w, c, min_gain, stack))
        .flatten_iter()
        .collect()
}

/// `candidates` in Z-order (Morton order) of their box centres on a 2²¹ grid over the root's
/// box, ties by id. Searched in this order, consecutive candidates climb through the same
/// ancestors and look into the same sibling subtrees, which are then still in cache: at 10^6
/// primitives the search waits on memory, not on arithmetic. Each search is a pure function of
/// the frozen tree, so the order changes the time, never the moves.
pub fn spatial_order(w: &WorkTree, candidates: &[u32]) -> Vec<u32> {
    const GRID: f64 = 2_097_151.0;
    let root = w.aabb[w.root as usize];
    let ext = root.extents();
    let scale = [0, 1, 2].map(|k| {
        if ext[k] > 0.0 && ext[k].is_finite() {
            GRID / ext[k]
        } else {
            0.0
        }
    });
    let key = |&x: &u32| -> (u64, u32) {
        let c = w.aabb[x as usize].center();
        let mut code = 0u64;
        for k in 0..3 {
            let t = ((c[k] - root.min[k]) * scale[k]).clamp(0.0, GRID) as u64;
            code |= spread_bits(t) << k;
        }
        (code, x)
    };
    let mut keys: Vec<(u64, u32)> = candidates.par_iter().map(key).collect();
    keys.par_sort_unstable();
    keys.into_iter().map(|(_, x)| x).collect()
}

/// Fewest candidates searched in parallel on a pool of several threads (with the split's finer
/// grains; `docs/benchmarks.md`, "How does it scale with threads?").
pub const PARALLEL_MIN: usize = 256;

/// Fewest candidates searched in [`spatial_order`] on one thread, and the size from which a
/// pass ranks its candidates on rayon's threads (eight times as many nodes).
pub const SPATIAL_MIN: usize = 2048;

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
/// that paper found best; here it ranks the children of inefficient, large parents. Of the
/// rankings tried (A(x) as obvhs and madmann91/bvh, A(p), A(p)² / (A(x) + A(s))) it gave the
/// lowest SAH and node tests for the same time (`wraptree-bench`'s `refine_cost`).
///
/// The set is what matters ([`find_all`]'s moves are sorted by gain afterwards), so it is
/// selected, not sorted, and returned in the order it is found (the chosen slots' children in
/// slot order, then the tied ones by id; [`find_all`] orders its searches itself). Keys are
/// computed on rayon's threads for large trees; the set and its order are the same for any
/// number of threads.
pub fn candidates(w: &WorkTree, count: usize) -> Vec<u32> {
    let nodes = w.parent.len();
    let count = count.min(nodes - 1);
    if count == 0 {
        return Vec::new();
    }
    // Both children of a slot share the value, so there is one key per interior slot, from a
    // sequential scan of the slots (the root, no slot's child, is never a candidate): the f64
    // mapped to an integer that sorts ascending from the best (largest) value.
    let n = w.n as usize;
    let key = |&[a, b]: &[u32; 2], ap: f64| -> u64 {
        let small = w.area[a as usize].min(w.area[b as usize]);
        let k = ap * ap / small.max(f64::MIN_POSITIVE);
        let bits = k.to_bits() as i64;
        !(((bits ^ (((bits >> 63) as u64) >> 1) as i64) as u64) ^ (1 << 63))
    };
    let keys: Vec<u64> = if nodes >= SPATIAL_MIN * 8 {
        (w.children.par_iter(), w.area[n..].par_iter())
            .into_par_iter()
            .map(|(k, &ap)| key(k, ap))
            .collect()
    } else {
        w.children
            .iter()
            .zip(&w.area[n..])
            .map(|(k, &ap)| key(k, ap))
            .collect()
    };
    // Nodes in rank order are the slots' children, two per slot: node rank `count − 1` is a
    // child of the slot of rank (count − 1) / 2. Every child of a slot with a smaller key is in;
    // children of slots with that key fill the rest by id.
    let mut ranked = keys.clone();
    let (_, &mut last, _) = ranked.select_nth_unstable((count - 1) / 2);
    let mut ids = Vec::with_capacity(count);
    let mut tied = Vec::new();
    for (&k, kids) in keys.iter().zip(&w.children) {
        if k < last {
            ids.extend_from_slice(kids);
        } else if k == last {
            tied.extend_from_slice(kids);
        }
    }
    tied.sort_unstable();
    tied.truncate(count - ids.len());
    ids.extend(tied);
    ids
}
