//! The top-down split: the tree of chunks over the Morton order of the primitives, cut as its
//! [`Chunking`] asks.

use super::chunking::Chunking;
use super::keep::Keep;
use super::split::{Zone, morton_cut};
use super::subproblem::Body;
#[cfg(test)]
use crate::geom::Aabb;
use crate::par;
use rayon::prelude::*;

/// A node of the split, in pre-order (a node, its left half's subtree, then its right half's),
/// so that the grouping, which descends the split depth first, reads the nodes in order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Node {
    /// Range of the Morton-sorted primitives.
    pub(super) lo: u32,
    pub(super) hi: u32,
    /// How far after the node its right half is (its left half is just after it); 0 for a
    /// chunk. Relative, so that blocks of nodes planned apart can be laid end to end.
    right_ahead: u32,
    /// Depth (0 = the root).
    pub(super) level: u32,
    /// Bodies the node's own subproblem starts from.
    pub(super) inputs: u32,
    /// Bodies it leaves (1 at the root).
    pub(super) keep: u32,
}

impl Node {
    /// The indices of the two halves of node `k` (this node), or none for a chunk.
    #[inline]
    pub(super) fn kids(&self, k: u32) -> Option<(u32, u32)> {
        (self.right_ahead > 0).then(|| (k + 1, k + self.right_ahead))
    }

    /// The merges made in the node's subtree below its own subproblem.
    #[inline]
    pub(super) fn below(&self) -> u32 {
        self.hi - self.lo - self.inputs
    }

    /// The merges made in the node's subtree, its own included.
    #[inline]
    pub(super) fn merges(&self) -> u32 {
        self.hi - self.lo - self.keep
    }
}

/// The nodes of `nodes` (pre-order) in post-order (each node after its two halves' subtrees).
pub(super) fn post_order(nodes: &[Node]) -> Vec<u32> {
    let mut order = Vec::with_capacity(nodes.len());
    // (node, whether its halves are done)
    let mut stack = vec![(0u32, false)];
    while let Some((k, expanded)) = stack.pop() {
        match nodes[k as usize].kids(k) {
            Some((l, r)) if !expanded => {
                stack.push((k, true));
                stack.push((r, false));
                stack.push((l, false));
            }
            _ => order.push(k),
        }
    }
    order
}

/// Ranges of at least this many primitives plan their halves in parallel (a finer grain than
/// 1,024, with `executor`'s grain and the refinement's search threshold lowered alike, made the
/// fast path faster on 4 and 16 threads: `docs/benchmarks.md`).
const PLAN_GRAIN: u32 = 1 << 8;

/// The split of the primitives into chunks, nodes in pre-order (the root first): `codes`
/// sorted, `leaves` the primitives in the same order. Ranges of at most
/// [`Chunking::sah_below`] primitives are cut by binned SAH (`split`), which
/// reorders `codes` and `leaves` alike within them; the nodes' ranges index the new order.
/// Halves of large ranges are planned in parallel into blocks of nodes, laid end to end at the
/// end (the same nodes and order as one sequential pass, whatever the number of threads).
pub(super) fn plan(
    codes: &mut [(u64, u32)],
    leaves: &mut [Body],
    chunking: &Chunking,
) -> Vec<Node> {
    let n = codes.len() as u32;
    if chunking.whole(codes.len()) {
        // One subproblem: the root over every primitive, the exact schedule's step.
        return vec![Node {
            lo: 0,
            hi: n,
            right_ahead: 0,
            level: 0,
            inputs: n,
            keep: 1,
        }];
    }
    let keep = Keep::new(chunking, codes.len());
    let planner = Planner {
        keep: &keep,
        grain: par::grain(PLAN_GRAIN),
    };
    let blocks = planner.blocks(codes, leaves, 0, 0).blocks;
    let total = blocks.iter().map(Vec::len).sum();
    let mut nodes: Vec<Node> = Vec::with_capacity(total);
    if rayon::current_num_threads() == 1 {
        for b in &blocks {
            nodes.extend_from_slice(b);
        }
        return nodes;
    }
    // On several threads each block is copied to its place by any thread (so are the fresh
    // pages faulted in).
    let mut rest = &mut nodes.spare_capacity_mut()[..total];
    let mut places = Vec::with_capacity(blocks.len());
    for b in &blocks {
        let (place, after) = std::mem::take(&mut rest).split_at_mut(b.len());
        places.push(place);
        rest = after;
    }
    places
        .into_par_iter()
        .zip(&blocks)
        .with_max_len(1)
        .for_each(|(place, b)| {
            place.write_copy_of_slice(b);
        });
    // SAFETY: the places cover the first `total` slots, and each was written above.
    unsafe { nodes.set_len(total) };
    nodes
}

/// A planned subtree: its nodes as blocks in pre-order, the bodies its root leaves and its
/// number of nodes.
struct Planned {
    blocks: Vec<Vec<Node>>,
    keep: u32,
    count: u32,
}

/// The inputs of the split.
struct Planner<'a> {
    keep: &'a Keep,
    /// Ranges of at least this many primitives plan their halves in parallel: [`PLAN_GRAIN`]
    /// where parallel steps are worth taking, else none ([`par::grain`]).
    grain: u32,
}

impl Planner<'_> {
    /// Plans the range of `codes` and `leaves` that starts at primitive `lo`, its halves in
    /// parallel while they are large.
    fn blocks(
        &self,
        codes: &mut [(u64, u32)],
        leaves: &mut [Body],
        lo: u32,
        level: u32,
    ) -> Planned {
        let size = codes.len() as u32;
        if size < self.grain || self.keep.chunking.is_chunk(size) || self.sah(size) {
            let mut nodes = Vec::new();
            let (keep, count) = self.build(codes, leaves, lo, level, &mut nodes);
            return Planned {
                blocks: vec![nodes],
                keep,
                count,
            };
        }
        let mid = morton_cut(codes, |c| c.0);
        let (lc, rc) = codes.split_at_mut(mid);
        let (ll, rl) = leaves.split_at_mut(mid);
        let m = lo + mid as u32;
        let (l, r) = rayon::join(
            || self.blocks(lc, ll, lo, level + 1),
            || self.blocks(rc, rl, m, level + 1),
        );
        let node = self.inner(lo, lo + size, level, l.keep, r.keep, l.count);
        let mut blocks = vec![vec![node]];
        blocks.extend(l.blocks);
        blocks.extend(r.blocks);
        Planned {
            blocks,
            keep: node.keep,
            count: l.count + r.count + 1,
        }
    }

    /// Whether a range of `size` primitives (and everything below it) is cut by SAH.
    fn sah(&self, size: u32) -> bool {
        size <= self.keep.chunking.sah_below && !self.keep.chunking.is_chunk(size)
    }

    /// Plans the range that starts at primitive `lo` into `nodes`, cut at Morton bits down to
    /// the SAH zones; returns the bodies its root leaves and its number of nodes.
    fn build(
        &self,
        codes: &mut [(u64, u32)],
        leaves: &mut [Body],
        lo: u32,
        level: u32,
        nodes: &mut Vec<Node>,
    ) -> (u32, u32) {
        let size = codes.len() as u32;
        if self.sah(size) {
            let mut zone = Zone::new(codes, leaves, self.keep.chunking.few);
            let planned = self.build_with(
                &mut |start, len| zone.cut(start, len),
                0,
                size,
                lo,
                level,
                nodes,
            );
            zone.apply();
            return planned;
        }
        if self.keep.chunking.is_chunk(size) {
            return self.chunk(lo, size, level, nodes);
        }
        let mid = morton_cut(codes, |c| c.0);
        let at = nodes.len();
        nodes.push(PLACEHOLDER);
        let (lc, rc) = codes.split_at_mut(mid);
        let (ll, rl) = leaves.split_at_mut(mid);
        let (kl, cl) = self.build(lc, ll, lo, level + 1, nodes);
        let (kr, cr) = self.build(rc, rl, lo + mid as u32, level + 1, nodes);
        let node = self.inner(lo, lo + size, level, kl, kr, cl);
        nodes[at] = node;
        (node.keep, cl + cr + 1)
    }

    /// Plans positions `start..start + size` of a zone (primitives from `lo`), each range cut
    /// by `cut(start, len)`, which returns the left side's length.
    fn build_with(
        &self,
        cut: &mut dyn FnMut(usize, usize) -> usize,
        start: usize,
        size: u32,
        lo: u32,
        level: u32,
        nodes: &mut Vec<Node>,
    ) -> (u32, u32) {
        if self.keep.chunking.is_chunk(size) {
            return self.chunk(lo, size, level, nodes);
        }
        let mid = cut(start, size as usize);
        let at = nodes.len();
        nodes.push(PLACEHOLDER);
        let (kl, cl) = self.build_with(cut, start, mid as u32, lo, level + 1, nodes);
        let right = size - mid as u32;
        let (kr, cr) = self.build_with(cut, start + mid, right, lo + mid as u32, level + 1, nodes);
        let node = self.inner(lo, lo + size, level, kl, kr, cl);
        nodes[at] = node;
        (node.keep, cl + cr + 1)
    }

    /// A chunk of `size` primitives from `lo`.
    fn chunk(&self, lo: u32, size: u32, level: u32, nodes: &mut Vec<Node>) -> (u32, u32) {
        let keep = if level == 0 {
            1
        } else {
            size.min(self.keep.at(self.keep.chunking.delta, size))
        };
        nodes.push(Node {
            lo,
            hi: lo + size,
            right_ahead: 0,
            level,
            inputs: size,
            keep,
        });
        (keep, 1)
    }

    /// The inner node over `lo..hi` whose halves leave `kl` and `kr` bodies, the left one
    /// having `left_count` nodes.
    fn inner(&self, lo: u32, hi: u32, level: u32, kl: u32, kr: u32, left_count: u32) -> Node {
        let inputs = kl + kr;
        let size = hi - lo;
        Node {
            lo,
            hi,
            right_ahead: left_count + 1,
            level,
            inputs,
            keep: if level == 0 {
                1
            } else if self.keep.passes(size, inputs) {
                inputs
            } else {
                inputs.min(self.keep.at(size, size))
            },
        }
    }
}

/// A node replaced once its halves are planned.
const PLACEHOLDER: Node = Node {
    lo: 0,
    hi: 0,
    right_ahead: 0,
    level: 0,
    inputs: 0,
    keep: 0,
};

#[cfg(test)]
mod tests {
    use super::super::sort::tests::codes;
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A leaf for each of `codes`: a small box at a random place (not its code's).
    fn leaves(codes: &[(u64, u32)], seed: u64) -> Vec<Body> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        codes
            .iter()
            .map(|&(_, id)| {
                let c = crate::geom::P3::new(
                    rng.random_range(0.0..100.0),
                    rng.random_range(0.0..10.0),
                    rng.random_range(0.0..1.0),
                );
                let aabb = Aabb::EMPTY
                    .grow(&c)
                    .grow(&(c + crate::geom::V3::repeat(0.5)));
                Body {
                    id,
                    first_round: 0,
                    aabb,
                    diameter: aabb.diameter(),
                }
            })
            .collect()
    }

    #[test]
    fn parallel_plan_equals_one_sequential_pass() {
        // Above the size the default chunking groups whole, and several plan grains.
        // The default's split for large scenes (δ = 4).
        let default = Chunking::DEFAULT.for_size(usize::MAX);
        let len = (5 * PLAN_GRAIN).max(2 * default.top) as usize + 17;
        let mut items = codes(len, 5);
        items.sort_unstable();
        let bodies = leaves(&items, 6);
        for chunking in [
            default,
            Chunking {
                delta: 8,
                epsilon: 0.1,
                top: 0,
                sah_below: 0,
                few: 0,
                twins: false,
            },
            // The fast path's split: ranges of 3 and 4 try every partition.
            Chunking::FAST,
            // SAH cuts in the parallel part of the plan too.
            Chunking {
                sah_below: 4 * PLAN_GRAIN,
                ..default
            },
        ] {
            let keep = Keep::new(&chunking, items.len());
            let planner = Planner {
                keep: &keep,
                grain: PLAN_GRAIN,
            };
            let mut want = Vec::new();
            let (mut wc, mut wl) = (items.clone(), bodies.clone());
            planner.build(&mut wc, &mut wl, 0, 0, &mut want);
            let want_ids: Vec<u32> = wl.iter().map(|b| b.id).collect();
            assert!(wc.iter().zip(&wl).all(|(c, b)| c.1 == b.id));
            for t in [1, 2] {
                let (mut c, mut l) = (items.clone(), bodies.clone());
                let got = rayon::ThreadPoolBuilder::new()
                    .num_threads(t)
                    .build()
                    .unwrap()
                    .install(|| plan(&mut c, &mut l, &chunking));
                assert_eq!(got, want);
                assert_eq!(c, wc);
                assert_eq!(l.iter().map(|b| b.id).collect::<Vec<_>>(), want_ids);
            }
            // The SAH cuts moved leaves (and only within their ranges: every id once).
            let mut ids = want_ids.clone();
            assert_eq!(
                chunking.sah_below == 0,
                ids == items.iter().map(|c| c.1).collect::<Vec<_>>()
            );
            ids.sort_unstable();
            assert_eq!(ids, (0..items.len() as u32).collect::<Vec<_>>());
            let (l, r) = want[0].kids(0).unwrap();
            assert_eq!(
                (want[l as usize].lo, want[r as usize].hi),
                (0, items.len() as u32)
            );
            assert_eq!(want[l as usize].hi, want[r as usize].lo);
            // Post-order: every node once, after both halves, the root last.
            let order = post_order(&want);
            let mut at = vec![usize::MAX; want.len()];
            for (i, &k) in order.iter().enumerate() {
                assert_eq!(at[k as usize], usize::MAX, "node {k} twice");
                at[k as usize] = i;
            }
            assert_eq!(order.last(), Some(&0));
            for (k, node) in want.iter().enumerate() {
                if let Some((l, r)) = node.kids(k as u32) {
                    assert!(at[l as usize] < at[r as usize] && at[r as usize] < at[k]);
                    assert_eq!(
                        node.below(),
                        want[l as usize].merges() + want[r as usize].merges()
                    );
                }
            }
        }
    }

    #[test]
    fn large_nodes_above_the_root_share_merge_nothing() {
        let n = 200_000;
        let mut items = codes(n, 7);
        items.sort_unstable();
        let mut bodies = leaves(&items, 8);
        let chunking = Chunking {
            top: 2048,
            ..Chunking::DEFAULT.for_size(usize::MAX)
        };
        let nodes = plan(&mut items, &mut bodies, &chunking);
        let share = |node: &Node| {
            (u64::from(chunking.top) * u64::from(node.hi - node.lo)).div_ceil(n as u64) as u32
        };
        let mut passed = 0;
        for (k, node) in nodes.iter().enumerate().skip(1) {
            assert!(node.keep >= share(node).min(node.inputs), "node {k}");
            if node.inputs as usize > super::super::brute_force::MAX_BODIES && share(node) > 2 {
                assert_eq!(node.keep, node.inputs, "node {k}");
                passed += 1;
            }
        }
        assert!(passed > 20, "{passed} nodes pass their bodies up");
        // The roundings of the shares are left to the root: a few more than `top`.
        let root = nodes[0];
        assert!(root.inputs > chunking.top && root.inputs < chunking.top + chunking.top / 8);
    }
}
