//! Treelet restructuring (Karras and Aila, "Fast parallel construction of high-quality bounding
//! volume hierarchies", HPG 2013): a *treelet* is a node `r` and the interior nodes below it
//! grown by repeatedly opening the treelet leaf of largest area, up to `k` ≤ [`MAX_LEAVES`]
//! treelet leaves (subtrees or primitives). Every binary tree over those leaves has the same
//! root box, so the one of least Σ interior area is found exactly by dynamic programming over
//! the 2^k − 1 leaf subsets (each subset's best split among its partitions), and replaces the
//! treelet when it lowers that sum. The treelet leaves and the nodes above `r` are untouched.
//!
//! One pass visits every interior node whose subtree has ≥ γ leaves (at least 3;
//! [`super::Tuning::treelet_min`]), on every height or every e-th
//! ([`super::Tuning::treelet_every`]), bottom-up by height (as computed when the pass starts). Nodes of one height are never ancestors of each other, and a
//! restructuring only reorders nodes inside its own root's subtree, so the treelets of one height
//! are disjoint and independent: they are solved in parallel on the frozen tree (rayon, from
//! [`PARALLEL_MIN`] treelets up) and applied in root-id order, which makes the result the same
//! for any number of threads.

use super::work::{Undo, WorkTree};
use crate::geom::Aabb;
use crate::geom::area;
use crate::grouping::NONE;
use rayon::prelude::*;

/// Most leaves of a treelet (Karras and Aila's choice; the subsets then fit in a `u8`).
pub const MAX_LEAVES: usize = crate::events::MAX_TREELET_LEAVES;

/// Fewest treelets of one height solved in parallel.
pub const PARALLEL_MIN: usize = 256;

/// The optimal restructuring of one treelet: the new children and boxes of its interior slots.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The treelet's root (keeps its place and box).
    pub root: u32,
    /// Treelet leaves.
    pub leaves: u32,
    /// Decrease of Σ interior area.
    pub gain: f64,
    /// Per interior slot of the treelet (root first): its new children and box, and whether
    /// its leaf set changed.
    pub nodes: Vec<(u32, [u32; 2], Aabb, bool)>,
}

/// The interior nodes of the tree bottom-up by height (1 = both children leaves), only those of
/// height ≥ 2 (a subtree of 2 leaves has one shape) and of at least `min_leaves` leaves; each
/// height's nodes in id order.
pub fn by_height(w: &WorkTree, min_leaves: u32) -> Vec<Vec<u32>> {
    let mut height = vec![0u32; w.parent.len()];
    let mut count = vec![1u32; w.parent.len()];
    // Children before parents: the slots in id order while the work tree still has the
    // Subset Tree's order (a sequential scan), else a reversed depth-first order.
    let order: Vec<u32> = if w.topological {
        (w.n..w.n + w.children.len() as u32).collect()
    } else {
        let mut order = Vec::with_capacity(w.children.len());
        let mut stack = vec![w.root];
        while let Some(x) = stack.pop() {
            if !w.is_leaf(x) {
                order.push(x);
                stack.extend(w.kids(x));
            }
        }
        order.reverse();
        order
    };
    let mut levels: Vec<Vec<u32>> = Vec::new();
    for &x in &order {
        let [a, b] = w.kids(x);
        let h = height[a as usize].max(height[b as usize]) + 1;
        height[x as usize] = h;
        count[x as usize] = count[a as usize] + count[b as usize];
        if h >= 2 && count[x as usize] >= min_leaves {
            let i = h as usize - 2;
            if levels.len() <= i {
                levels.resize_with(i + 1, Vec::new);
            }
            levels[i].push(x);
        }
    }
    for l in &mut levels {
        l.sort_unstable();
    }
    levels
}

/// Per-thread buffers of [`solve`]: boxes, best costs and best splits of every leaf subset.
pub struct Scratch {
    boxes: [Aabb; 1 << MAX_LEAVES],
    cost: [f64; 1 << MAX_LEAVES],
    split: [u8; 1 << MAX_LEAVES],
}

impl Default for Scratch {
    fn default() -> Self {
        Scratch {
            boxes: [Aabb::EMPTY; 1 << MAX_LEAVES],
            cost: [0.0; 1 << MAX_LEAVES],
            split: [0; 1 << MAX_LEAVES],
        }
    }
}

/// The best restructuring of the treelet of up to `k` leaves rooted at `root`, if it lowers
/// Σ interior area by more than `min_gain`.
pub fn solve(w: &WorkTree, root: u32, k: usize, min_gain: f64, buf: &mut Scratch) -> Option<Plan> {
    let (leaves, inner, n) = form(w, root, k.clamp(3, MAX_LEAVES));
    if n < 3 {
        return None;
    }
    let (leaves, inner) = (&leaves[..n], &inner[..n - 1]);
    best_subtrees(w, leaves, buf);
    let before: f64 = inner.iter().map(|&x| w.area[x as usize]).sum();
    let gain = before - buf.cost[(1usize << n) - 1];
    if gain <= min_gain {
        return None;
    }
    Some(Plan {
        root,
        leaves: n as u32,
        gain,
        nodes: new_nodes(w, leaves, inner, buf),
    })
}

/// The treelet of up to `k` leaves under `root`: its leaves, its interior nodes (root first)
/// and how many leaves it has.
#[inline]
fn form(w: &WorkTree, root: u32, k: usize) -> ([u32; MAX_LEAVES], [u32; MAX_LEAVES - 1], usize) {
    // Formation: open the largest-area interior treelet leaf (ties: smaller id) until k leaves.
    let mut leaves = [NONE; MAX_LEAVES];
    let mut inner = [NONE; MAX_LEAVES - 1];
    [leaves[0], leaves[1]] = w.kids(root);
    inner[0] = root;
    let mut n = 2;
    while n < k {
        let mut open = None;
        for (i, &x) in leaves[..n].iter().enumerate() {
            if w.is_leaf(x) {
                continue;
            }
            let better = open.is_none_or(|j: usize| {
                let y = leaves[j];
                w.area[x as usize]
                    .total_cmp(&w.area[y as usize])
                    .then(y.cmp(&x))
                    .is_gt()
            });
            if better {
                open = Some(i);
            }
        }
        let Some(i) = open else { break };
        let x = leaves[i];
        inner[n - 1] = x;
        [leaves[i], leaves[n]] = w.kids(x);
        n += 1;
    }
    (leaves, inner, n)
}

/// Fills `buf` with the box, the best cost and the best split of every subset of `leaves`.
#[inline]
fn best_subtrees(w: &WorkTree, leaves: &[u32], buf: &mut Scratch) {
    let Scratch { boxes, cost, split } = buf;
    let full = (1usize << leaves.len()) - 1;
    // Boxes and best costs of every subset (cost = Σ interior area of its best subtree, 0 for
    // one leaf); a proper subset is always numerically smaller than its set.
    for s in 1..=full {
        let low = s.trailing_zeros() as usize;
        let rest = s & (s - 1);
        if rest == 0 {
            boxes[s] = w.aabb[leaves[low] as usize];
            cost[s] = 0.0;
            continue;
        }
        boxes[s] = boxes[rest].merge(&boxes[s ^ rest]);
        // Partitions {P, s \ P} with P holding the lowest leaf: P = low ∪ (a subset of rest
        // other than rest itself).
        let lowbit = s ^ rest;
        let (mut best, mut best_p) = (f64::INFINITY, 0);
        let mut sub = 0usize;
        loop {
            let p = lowbit | sub;
            let c = cost[p] + cost[s ^ p];
            if c < best {
                (best, best_p) = (c, p);
            }
            sub = (sub.wrapping_sub(rest)) & rest;
            if sub == rest {
                break;
            }
        }
        cost[s] = best + area(&boxes[s]);
        split[s] = best_p as u8;
    }
}

/// The restructured treelet's interior nodes, root first: each keeps the slot of an old node
/// with the same leaf set where there is one, the other old slots are reused in order.
fn new_nodes(
    w: &WorkTree,
    leaves: &[u32],
    inner: &[u32],
    buf: &Scratch,
) -> Vec<(u32, [u32; 2], Aabb, bool)> {
    let Scratch { boxes, split, .. } = buf;
    let (n, full) = (leaves.len(), (1usize << leaves.len()) - 1);
    // The old interior slots' leaf sets. Each interior node was opened after its parent, so in
    // reverse formation order a node's interior children already have theirs.
    let mut old = [0usize; MAX_LEAVES - 1];
    for i in (0..inner.len()).rev() {
        old[i] = w.kids(inner[i]).iter().fold(0, |m, &c| {
            m | match leaves.iter().position(|&l| l == c) {
                Some(j) => 1 << j,
                None => old[inner.iter().position(|&y| y == c).expect("a treelet node")],
            }
        });
    }
    let old = &old[..inner.len()];
    // New interior sets, root first (depth-first, P side before the rest); the pending sets
    // are disjoint, so at most n.
    let mut sets = [0usize; MAX_LEAVES - 1];
    let mut count = 0;
    let mut stack = [0usize; MAX_LEAVES];
    let mut top = 1;
    stack[0] = full;
    while top > 0 {
        top -= 1;
        let s = stack[top];
        if s.count_ones() >= 2 {
            sets[count] = s;
            count += 1;
            let p = split[s] as usize;
            stack[top] = s ^ p;
            stack[top + 1] = p;
            top += 2;
        }
    }
    debug_assert_eq!(count, n - 1);
    let sets = &sets[..count];
    let mut slot = [NONE; MAX_LEAVES - 1];
    let mut used = [false; MAX_LEAVES - 1];
    for (i, &s) in sets.iter().enumerate() {
        if let Some(j) = old.iter().position(|&m| m == s) {
            slot[i] = inner[j];
            used[j] = true;
        }
    }
    let mut free = inner
        .iter()
        .zip(&used)
        .filter(|(_, u)| !**u)
        .map(|(&x, _)| x);
    for s in slot[..count].iter_mut().filter(|s| **s == NONE) {
        *s = free
            .next()
            .expect("a treelet of n leaves has n − 1 interior slots");
    }
    let node_of = |set: usize| -> u32 {
        if set.count_ones() == 1 {
            leaves[set.trailing_zeros() as usize]
        } else {
            slot[sets
                .iter()
                .position(|&t| t == set)
                .expect("every set has a slot")]
        }
    };
    sets.iter()
        .zip(&slot)
        .map(|(&s, &x)| {
            let p = split[s] as usize;
            let mut kids = [node_of(p), node_of(s ^ p)];
            if w.kids(x) == [kids[1], kids[0]] {
                kids.swap(0, 1);
            }
            let changed = !inner.iter().zip(old).any(|(&y, &m)| y == x && m == s);
            (x, kids, boxes[s], changed)
        })
        .collect()
}

/// The plans of `roots` (treelets of one height, disjoint) on the frozen tree, in root order.
pub fn solve_all(w: &WorkTree, roots: &[u32], k: usize, min_gain: f64) -> Vec<Plan> {
    if roots.len() < PARALLEL_MIN {
        let mut buf = Box::<Scratch>::default();
        return roots
            .iter()
            .filter_map(|&r| solve(w, r, k, min_gain, &mut buf))
            .collect();
    }
    roots
        .par_iter()
        .map_init(Box::<Scratch>::default, |buf, &r| {
            solve(w, r, k, min_gain, buf)
        })
        .flatten_iter()
        .collect()
}

impl WorkTree {
    /// Replaces a treelet by its plan: new children, parents, boxes and areas of its interior
    /// slots, the running interior sum kept in step, changed leaf sets marked; each slot as it
    /// was goes to `undo`. The root's box is its leaves' union either way, so nothing above it
    /// changes.
    pub fn restructure(&mut self, plan: &Plan, undo: &mut Vec<Undo>) {
        self.topological = false;
        for &(x, kids, bx, changed) in &plan.nodes {
            undo.push(Undo::Slot {
                x,
                kids: self.kids(x),
                aabb: self.aabb[x as usize],
                area: self.area[x as usize],
            });
            let i = (x - self.n) as usize;
            self.children[i] = kids;
            for c in kids {
                self.parent[c as usize] = x;
            }
            if x != plan.root {
                let ar = area(&bx);
                self.interior += ar - self.area[x as usize];
                self.aabb[x as usize] = bx;
                self.area[x as usize] = ar;
                self.changed[i] |= changed;
            }
        }
    }
}
