//! What every subproblem of the partitioned schedule shares: its bodies, the run-wide inputs,
//! the slots its merges go to and its counters.

use super::round_limits::RoundLimits;
use crate::geom::Aabb;
use crate::grouping::{Budget, ResolvedParams, StopReason};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// A body of a subproblem: its run-wide id, the first round in which it obeys DLimit, its box
/// and diameter.
#[derive(Clone, Copy, Debug)]
pub(super) struct Body {
    pub(super) id: u32,
    pub(super) first_round: u32,
    pub(super) aabb: Aabb,
    pub(super) diameter: f64,
}

/// What a subproblem leaves: the number of its bodies (at the start of its range of the arena)
/// and, when a brute-force subproblem made them for a brute-force parent, the Cost (as
/// `order_bits`) and first eligible round of each pair of them (`p < q`, row by row), so that
/// the parent does not evaluate them again.
#[derive(Debug, Default)]
pub(super) struct Leftover {
    pub(super) n: usize,
    pub(super) pairs: PairList,
}

/// The pairs a subproblem leaves: inline up to the 6 of four bodies (below the root's share
/// every node leaves two), so that most nodes allocate nothing.
pub(super) type PairList = smallvec::SmallVec<[(u64, u32); 6]>;

/// What a merge event needs beyond the tree.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct MergeInfo {
    pub(super) round: u32,
    pub(super) fill: f64,
    pub(super) balance: f64,
    pub(super) cost: f64,
    pub(super) queue_len: u32,
    pub(super) active: bool,
}

/// Work counters of subproblems.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Counters {
    pub(super) eligible_pairs: u64,
    pub(super) candidates: u64,
    pub(super) pops: u64,
    pub(super) stale_pops: u64,
    pub(super) peak_queue: u64,
    pub(super) rounds: u32,
}

impl Counters {
    pub(super) fn add(&mut self, o: &Counters) {
        self.eligible_pairs += o.eligible_pairs;
        self.candidates += o.candidates;
        self.pops += o.pops;
        self.stale_pops += o.stale_pops;
        self.peak_queue = self.peak_queue.max(o.peak_queue);
        self.rounds = self.rounds.max(o.rounds);
    }
}

/// The run-wide inputs of every subproblem.
pub(super) struct RunInputs<'a> {
    pub(super) params: ResolvedParams,
    pub(super) dl: RoundLimits,
    pub(super) gl: RoundLimits,
    pub(super) budget: &'a Budget<'a>,
    /// Eligible pairs counted so far by finished subproblems.
    pub(super) pairs: AtomicU64,
    /// Set once a subproblem stops; the others then stop before their next subproblem.
    pub(super) halt: AtomicBool,
    pub(super) reason: Mutex<Option<StopReason>>,
}

impl<'a> RunInputs<'a> {
    /// The inputs of a run with `params` under `budget`, nothing counted or stopped yet.
    pub(super) fn new(params: ResolvedParams, budget: &'a Budget<'a>) -> RunInputs<'a> {
        RunInputs {
            params,
            dl: RoundLimits::new(params.dlimit0),
            gl: RoundLimits::new(params.glimit0),
            budget,
            pairs: AtomicU64::new(0),
            halt: AtomicBool::new(false),
            reason: Mutex::new(None),
        }
    }
}

impl RunInputs<'_> {
    /// Whether the budget stops the run before a subproblem.
    pub(super) fn exceeded(&self) -> bool {
        if self.halt.load(Ordering::Relaxed) {
            return true;
        }
        let reason = self.budget.exceeded_now().or_else(|| {
            self.budget
                .max_pairs
                .filter(|&m| self.pairs.load(Ordering::Relaxed) > m)
                .map(|_| StopReason::MaxPairs)
        });
        match reason {
            Some(r) => {
                self.stop(r);
                true
            }
            None => false,
        }
    }

    pub(super) fn stop(&self, r: StopReason) {
        self.reason
            .lock()
            .expect("no panics hold it")
            .get_or_insert(r);
        self.halt.store(true, Ordering::Relaxed);
    }
}

/// Where a subproblem writes its merges: merge `i` has step `first_new − N + i`.
pub(super) struct MergeSlots<'a> {
    pub(super) first_new: u32,
    pub(super) children: &'a mut [[u32; 2]],
    pub(super) aabb: &'a mut [Aabb],
    pub(super) diameter: &'a mut [f64],
    pub(super) info: Option<&'a mut [MergeInfo]>,
    pub(super) stats: Counters,
}

impl<'a> MergeSlots<'a> {
    /// Whether merge details are kept for events.
    #[inline]
    pub(super) fn listens(&self) -> bool {
        self.info.is_some()
    }

    #[inline]
    pub(super) fn put(&mut self, i: usize, ch: [u32; 2], aabb: Aabb, d: f64, info: MergeInfo) {
        self.children[i] = ch;
        self.aabb[i] = aabb;
        self.diameter[i] = d;
        if let Some(inf) = &mut self.info {
            inf[i] = info;
        }
    }

    /// The first `k` merges and the rest.
    pub(super) fn split(self, k: usize) -> (MergeSlots<'a>, MergeSlots<'a>) {
        let (c0, c1) = self.children.split_at_mut(k);
        let (a0, a1) = self.aabb.split_at_mut(k);
        let (d0, d1) = self.diameter.split_at_mut(k);
        let (i0, i1) = match self.info {
            Some(i) => {
                let (x, y) = i.split_at_mut(k);
                (Some(x), Some(y))
            }
            None => (None, None),
        };
        let out = |first_new, children, aabb, diameter, info| MergeSlots {
            first_new,
            children,
            aabb,
            diameter,
            info,
            stats: Counters::default(),
        };
        (
            out(self.first_new, c0, a0, d0, i0),
            out(self.first_new + k as u32, c1, a1, d1, i1),
        )
    }
}
