//! The executor: groups the split's nodes bottom-up, the two halves of a large node in
//! parallel, each node's own merges by brute force or with the voxel hash.

use super::plan::Node;
use super::subproblem::{Body, Counters, Leftover, MergeSlots, PairList, RunInputs};
use super::{all_pairs, brute_force, voxel_step};
use crate::par;
use std::sync::atomic::{AtomicBool, Ordering};

/// Halves of at least this many primitives are grouped in parallel (256: see the split's
/// `PLAN_GRAIN`).
const GRAIN: u32 = 256;

/// The read-only inputs of the recursive grouping.
pub(super) struct Executor<'a> {
    pub(super) ctx: &'a RunInputs<'a>,
    pub(super) nodes: &'a [Node],
    pub(super) done: &'a [AtomicBool],
    /// Halves of at least this many primitives are grouped in parallel ([`Executor::grain`]).
    pub(super) grain: u32,
}

impl Executor<'_> {
    /// The grain of a run on the calling thread: [`GRAIN`] where parallel steps are worth
    /// taking, else none ([`par::grain`]).
    pub(super) fn grain() -> u32 {
        par::grain(GRAIN)
    }

    /// Groups node `k`'s subtree into `out` (its merges, in post-order). `arena` holds the
    /// node's primitives as bodies (its range of the Morton order); the bodies it leaves end
    /// up at its start. Returns how many it leaves (`None` when the budget stopped it), with
    /// their pairs when `export`, and its counters.
    pub(super) fn node(
        &self,
        k: u32,
        arena: &mut [Body],
        out: MergeSlots<'_>,
        export: bool,
    ) -> (Option<Leftover>, Counters) {
        let node = self.nodes[k as usize];
        if node.keep == 1 && node.inputs <= 2 {
            return self.single(k, arena, out);
        }
        let (parts, mut own, mut stats) = match node.kids(k) {
            None => {
                self.first_rounds(arena);
                let part = Leftover {
                    n: arena.len(),
                    pairs: PairList::new(),
                };
                ([part, Leftover::default()], out, Counters::default())
            }
            Some((l, r)) => {
                // The left half is the next node; the right half's merges are the rest of
                // those below this node (its entry is read when it is grouped).
                let ln = self.nodes[l as usize];
                let lm = ln.merges() as usize;
                let rm = (node.below() - ln.merges()) as usize;
                let (lout, rest) = out.split(lm);
                let (rout, own) = rest.split(rm);
                // The children's pairs serve this node's brute-force step.
                let want =
                    node.inputs as usize <= brute_force::MAX_BODIES && node.inputs > node.keep;
                let mid = (ln.hi - ln.lo) as usize;
                let (la, ra) = arena.split_at_mut(mid);
                let ((lb, ls), (rb, rs)) = if node.hi - node.lo >= self.grain {
                    rayon::join(
                        || self.node(l, la, lout, want),
                        || self.node(r, ra, rout, want),
                    )
                } else {
                    (self.node(l, la, lout, want), self.node(r, ra, rout, want))
                };
                let mut stats = ls;
                stats.add(&rs);
                let (Some(lb), Some(rb)) = (lb, rb) else {
                    return (None, stats);
                };
                // The halves' bodies side by side at the node's start.
                arena.copy_within(mid..mid + rb.n, lb.n);
                ([lb, rb], own, stats)
            }
        };
        if self.ctx.exceeded() {
            return (None, stats);
        }
        let left = self.own_step(arena, parts, node.keep as usize, &mut own, export);
        self.count_pairs(own.stats.eligible_pairs);
        stats.add(&own.stats);
        if left.is_some() {
            self.done[k as usize].store(true, Ordering::Relaxed);
        }
        (left, stats)
    }

    /// Sets each primitive's first round within DLimit (a chunk's bodies on entry).
    fn first_rounds(&self, arena: &mut [Body]) {
        for b in arena.iter_mut() {
            b.first_round = self.ctx.dl.first(b.diameter);
        }
    }

    /// Adds a finished subproblem's eligible pairs to the run's count, which only a budget
    /// reads (an atomic add per node costs on 2 threads).
    fn count_pairs(&self, pairs: u64) {
        if !self.ctx.budget.is_unlimited() {
            self.ctx.pairs.fetch_add(pairs, Ordering::Relaxed);
        }
    }

    /// A node's own subproblem: the bodies its halves left (`parts`, side by side at the start
    /// of `arena`) grouped until `keep` remain, by brute force or with the voxel hash; `None`
    /// when the budget stopped it.
    fn own_step(
        &self,
        arena: &mut [Body],
        parts: [Leftover; 2],
        keep: usize,
        own: &mut MergeSlots<'_>,
        export: bool,
    ) -> Option<Leftover> {
        let m = parts[0].n + parts[1].n;
        if m <= brute_force::MAX_BODIES {
            return Some(brute_force::combine(
                self.ctx,
                &mut arena[..m],
                parts,
                keep,
                own,
                export,
            ));
        }
        voxel_step::combine_by_voxels(self.ctx, arena[..m].to_vec(), keep, own).map(|bodies| {
            arena[..bodies.len()].copy_from_slice(&bodies);
            Leftover {
                n: bodies.len(),
                pairs: PairList::new(),
            }
        })
    }

    /// [`Executor::node`] for a node that merges the two bodies its halves leave (or that is a
    /// chunk of at most two primitives leaving one): below it every node keeps one body too,
    /// since what a node keeps grows with its size, so the subtree is grouped by [`merge_down`]
    /// without the subproblems' tables, each merge of two bodies made by [`all_pairs::pair`].
    ///
    /// [`merge_down`]: Executor::merge_down
    fn single(
        &self,
        k: u32,
        arena: &mut [Body],
        out: MergeSlots<'_>,
    ) -> (Option<Leftover>, Counters) {
        let mut stats = Counters::default();
        let Some(body) = self.merge_down(k, arena, out, &mut stats) else {
            return (None, stats);
        };
        arena[0] = body;
        self.count_pairs(stats.eligible_pairs);
        let left = Leftover {
            n: 1,
            pairs: PairList::new(),
        };
        (Some(left), stats)
    }

    /// The body node `k`'s subtree groups into, each node merging its halves' bodies (see
    /// [`Executor::single`]), its merges written to `out` in post-order and counted into
    /// `stats`; `None` when the budget stopped it (checked at nodes of [`GRAIN`] primitives
    /// and more, and at the first).
    fn merge_down(
        &self,
        k: u32,
        arena: &mut [Body],
        out: MergeSlots<'_>,
        stats: &mut Counters,
    ) -> Option<Body> {
        let node = self.nodes[k as usize];
        let size = node.hi - node.lo;
        if (size >= GRAIN || stats.pops == 0) && self.ctx.exceeded() {
            return None;
        }
        let (x, y, mut own) = match node.kids(k) {
            None => {
                self.first_rounds(arena);
                if arena.len() != 2 {
                    // One primitive, or a chunk of more that keeps one:
                    // its own subproblem.
                    let mut out = out;
                    let part = Leftover {
                        n: arena.len(),
                        pairs: PairList::new(),
                    };
                    let parts = [part, Leftover::default()];
                    self.own_step(arena, parts, 1, &mut out, false)?;
                    stats.add(&out.stats);
                    self.done[k as usize].store(true, Ordering::Relaxed);
                    return Some(arena[0]);
                }
                (arena[0], arena[1], out)
            }
            Some((l, r)) => {
                let ln = self.nodes[l as usize];
                debug_assert!(ln.keep == 1 && self.nodes[r as usize].keep == 1);
                let lm = ln.merges() as usize;
                let (lout, rest) = out.split(lm);
                let (rout, own) = rest.split(node.below() as usize - lm);
                let (la, ra) = arena.split_at_mut((ln.hi - ln.lo) as usize);
                let (x, y) = if size >= self.grain {
                    let mut rs = Counters::default();
                    let (x, y) = rayon::join(
                        || self.merge_down(l, la, lout, stats),
                        || self.merge_down(r, ra, rout, &mut rs),
                    );
                    stats.add(&rs);
                    (x?, y?)
                } else {
                    let x = self.merge_down(l, la, lout, stats)?;
                    (x, self.merge_down(r, ra, rout, stats)?)
                };
                (x, y, own)
            }
        };
        let body = all_pairs::pair(self.ctx, &x, &y, &mut own, stats);
        self.done[k as usize].store(true, Ordering::Relaxed);
        Some(body)
    }
}
