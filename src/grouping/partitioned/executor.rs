//! The executor: groups the split's nodes bottom-up, the two halves of a large node in
//! parallel, each node's own merges by brute force or with the voxel hash.

use super::plan::Node;
use super::subproblem::{Body, Counters, Leftover, MergeSlots, PairList, RunInputs};
use super::{brute_force, voxel_step};
use std::sync::atomic::{AtomicBool, Ordering};

/// Halves of at least this many primitives are grouped in parallel.
const GRAIN: u32 = 1024;

/// The read-only inputs of the recursive grouping.
pub(super) struct Executor<'a> {
    pub(super) ctx: &'a RunInputs<'a>,
    pub(super) nodes: &'a [Node],
    pub(super) done: &'a [AtomicBool],
}

impl Executor<'_> {
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
        let (parts, mut own, mut stats) = match node.kids(k) {
            None => {
                for b in arena.iter_mut() {
                    b.first_round = self.ctx.dl.first(b.diameter);
                }
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
                let want = node.inputs as usize <= brute_force::SMALL && node.inputs > node.keep;
                let mid = (ln.hi - ln.lo) as usize;
                let (la, ra) = arena.split_at_mut(mid);
                let ((lb, ls), (rb, rs)) = if node.hi - node.lo >= GRAIN {
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
        let keep = node.keep as usize;
        let m = parts[0].n + parts[1].n;
        let left = if m <= brute_force::SMALL {
            Some(brute_force::combine(
                self.ctx,
                &mut arena[..m],
                parts,
                keep,
                &mut own,
                export,
            ))
        } else {
            voxel_step::combine(self.ctx, arena[..m].to_vec(), keep, &mut own).map(|bodies| {
                arena[..bodies.len()].copy_from_slice(&bodies);
                Leftover {
                    n: bodies.len(),
                    pairs: PairList::new(),
                }
            })
        };
        // Only a budget reads the shared count (an atomic add per node costs on 2 threads).
        if !self.ctx.budget.is_unlimited() {
            self.ctx
                .pairs
                .fetch_add(own.stats.eligible_pairs, Ordering::Relaxed);
        }
        stats.add(&own.stats);
        if left.is_some() {
            self.done[k as usize].store(true, Ordering::Relaxed);
        }
        (left, stats)
    }
}
