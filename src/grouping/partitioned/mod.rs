//! The partitioned schedule: the §2.2 grouping step run inside the chunks of a top-down Morton
//! split, bottom-up, in parallel — approximate agglomerative clustering (AAC; Gu, He,
//! Fatahalian and Blelloch 2013, "Efficient BVH Construction via Approximate Agglomerative
//! Clustering").
//!
//! 1. The primitives are sorted by the Morton code of their box centres (21 bits per axis over
//!    the cube on the longest side of the centres' box, so that a code's bits follow distance
//!    alike on every axis; ties by id).
//! 2. The sorted range is split top-down at its highest differing Morton bit (at the middle
//!    when every code is equal) until a range holds fewer than δ = [`Chunking::delta`]
//!    primitives: a *chunk*. Ranges of at most [`Chunking::sah_below`] primitives are cut
//!    instead at the binned-SAH boundary on the longest axis of their centres (`split`; they
//!    are reordered, each side keeping its Morton order), where a Morton cut would run through
//!    clusters.
//! 3. Bottom-up, each chunk groups its primitives until at most f(δ) bodies remain, and each
//!    inner node of the split groups the bodies its two halves left until at most f(n) remain,
//!    n its number of primitives, with AAC's reduction function f(n) = ⌈c·n^(1/2 − ε)⌉,
//!    c = δ^(1/2 + ε)/2 (so f(δ) = δ/2) — but never fewer than ⌈top·n/N⌉ bodies
//!    ([`Chunking::top`]), so that the root, which groups what is left into one body, starts
//!    from about `top` bodies (nodes above that size pass their halves' bodies up unmerged,
//!    but for the one merge that the halves' rounded-up shares leave now and then to a node of
//!    at most `SMALL` bodies; larger nodes leave those merges to the root).
//! 4. Each of those subproblems is the paper's step: Cost = diameter^A × (B·Fill + C·Balance),
//!    the AABB p-set, DLimit/GLimit eligibility from DLimit0/GLimit0 with doubling, the
//!    cheapest eligible pair first, ties by the pair's tie tags of the run's (global) ids. Up to
//!    `SMALL` bodies it is solved by brute force (`small`), above with the
//!    voxel hash and MPairs of the exact schedule.
//!
//! The halves of the split are grouped in parallel (rayon, in the current thread pool). Every
//! subproblem's result depends only on its bodies, and merge steps are numbered in the split's
//! post-order (left half, right half, then the node's own merges), fixed before any grouping
//! starts, so the tree is identical for any number of threads. A scene of fewer than δ
//! primitives, or of at most 1.5 × `top` ([`Chunking::whole`]), is one subproblem: the exact
//! schedule's tree.
//!
//! Events: after the grouping, each subproblem that merges anything is announced, in that
//! post-order, by [`Event::Part`] (`Chunk { level, keep }`, the root `Top`), followed by its
//! merges (new id `N + step`) and a `Dormant` event after each merge whose body exceeds its
//! subproblem's DLimit; then `Finish`. Subproblems' rounds are not the run's rounds, so no
//! `RoundStart` or `Doubling` is emitted; each merge carries its subproblem's round, and a
//! brute-force subproblem's `queue_len` is the number of its bodies that have an eligible
//! partner after the merge. Events are buffered only when the observer listens
//! ([`Observer::is_silent`]). [`Grouping::rounds`] is the most rounds any subproblem ran.
//!
//! Budget: the stop flag and the deadline are checked before every subproblem and, in
//! voxel-hash subproblems, as in the exact run. `max_pairs` caps the eligible pairs found at
//! the round starts of all subproblems together (a brute-force subproblem counts the pairs
//! eligible at each of its round starts), checked before every subproblem and inside
//! voxel-hash subproblems against what was counted when they started. A stopped run reports
//! the merges of the subproblems finished before the first unfinished one in post-order.
//!
//! The hull p-set has no partitioned form here (its diameters and gaps are not functions of
//! boxes); with it the partitioned schedule runs the exact schedule.

mod announce;
mod big;
mod keep;
mod plan;
mod small;
mod sort;
mod split;
#[cfg(test)]
mod tests;
mod tiny;

use super::cluster;
use super::subset_tree::SubsetTree;
use super::voxel_hash::prefetch;
use super::{Budget, Grouping, PSet, ResolvedParams, Stats, StopReason, Stopped};
use crate::events::{Event, Observer};
use crate::geom::Aabb;
use crate::scene::Scene;
use announce::{Made, announce};
pub use plan::Chunking;
use plan::{Node, plan};
use rayon::prelude::*;
use small::Limits;
use split::morton_order;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// How many leaves ahead the gather asks for the box it will read (its reads are random).
const GATHER_AHEAD: usize = 16;

/// Halves of at least this many primitives are grouped in parallel.
const GRAIN: u32 = 2048;

/// A body of a subproblem: its run-wide id, the first round in which it obeys DLimit, its box
/// and diameter.
#[derive(Clone, Copy, Debug)]
pub(super) struct Body {
    id: u32,
    rd: u32,
    aabb: Aabb,
    d: f64,
}

/// What a subproblem leaves: the number of its bodies (at the start of its range of the arena)
/// and, when a brute-force subproblem made them for a brute-force parent, the Cost (as
/// `order_bits`) and first eligible round of each pair of them (`p < q`, row by row), so that
/// the parent does not evaluate them again.
#[derive(Debug, Default)]
pub(super) struct Left {
    n: usize,
    pairs: Vec<(u64, u32)>,
}

/// What a merge event needs beyond the tree.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Info {
    round: u32,
    fill: f64,
    balance: f64,
    cost: f64,
    queue_len: u32,
    active: bool,
}

/// Work counters of subproblems.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct SubStats {
    eligible_pairs: u64,
    candidates: u64,
    pops: u64,
    stale_pops: u64,
    peak_queue: u64,
    rounds: u32,
}

impl SubStats {
    fn add(&mut self, o: &SubStats) {
        self.eligible_pairs += o.eligible_pairs;
        self.candidates += o.candidates;
        self.pops += o.pops;
        self.stale_pops += o.stale_pops;
        self.peak_queue = self.peak_queue.max(o.peak_queue);
        self.rounds = self.rounds.max(o.rounds);
    }
}

/// The run-wide inputs of every subproblem.
pub(super) struct Ctx<'a> {
    params: ResolvedParams,
    dl: Limits,
    gl: Limits,
    budget: &'a Budget<'a>,
    /// Eligible pairs counted so far by finished subproblems.
    pairs: AtomicU64,
    /// Set once a subproblem stops; the others then stop before their next subproblem.
    halt: AtomicBool,
    reason: Mutex<Option<StopReason>>,
}

impl Ctx<'_> {
    /// Whether the budget stops the run before a subproblem.
    fn exceeded(&self) -> bool {
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

    fn stop(&self, r: StopReason) {
        self.reason
            .lock()
            .expect("no panics hold it")
            .get_or_insert(r);
        self.halt.store(true, Ordering::Relaxed);
    }
}

/// Where a subproblem writes its merges: merge `i` has step `first_new − N + i`.
pub(super) struct Out<'a> {
    first_new: u32,
    children: &'a mut [[u32; 2]],
    aabb: &'a mut [Aabb],
    diameter: &'a mut [f64],
    info: Option<&'a mut [Info]>,
    stats: SubStats,
}

impl<'a> Out<'a> {
    /// Whether merge details are kept for events.
    #[inline]
    fn listens(&self) -> bool {
        self.info.is_some()
    }

    #[inline]
    fn put(&mut self, i: usize, ch: [u32; 2], aabb: Aabb, d: f64, info: Info) {
        self.children[i] = ch;
        self.aabb[i] = aabb;
        self.diameter[i] = d;
        if let Some(inf) = &mut self.info {
            inf[i] = info;
        }
    }

    /// The first `k` merges and the rest.
    fn split(self, k: usize) -> (Out<'a>, Out<'a>) {
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
        let out = |first_new, children, aabb, diameter, info| Out {
            first_new,
            children,
            aabb,
            diameter,
            info,
            stats: SubStats::default(),
        };
        (
            out(self.first_new, c0, a0, d0, i0),
            out(self.first_new + k as u32, c1, a1, d1, i1),
        )
    }
}

/// The default [`Chunking`] with the root share `params.mode` names.
fn chunking_of(params: &ResolvedParams) -> Chunking {
    Chunking {
        top: params.mode.chunk_top,
        epsilon: params.mode.chunk_epsilon,
        sah_below: params.mode.chunk_sah,
        ..Chunking::DEFAULT
    }
}

/// Runs the partitioned schedule with the default [`Chunking`].
pub(crate) fn run<O: Observer>(
    scene: &Scene,
    params: &ResolvedParams,
    observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    group_with(scene, params, &chunking_of(params), observer, budget)
}

/// Runs the partitioned schedule on primitive boxes (see [`group_boxes`]) with the default
/// [`Chunking`].
pub(crate) fn run_boxes<O: Observer>(
    aabb: Vec<Aabb>,
    params: &ResolvedParams,
    observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    group_boxes(aabb, params, &chunking_of(params), observer, budget)
}

/// Runs the partitioned schedule with `chunking` instead of [`Chunking::DEFAULT`] (see the module
/// doc); `params.mode` is not read. Panics only if the scene is empty.
pub fn group_with<O: Observer>(
    scene: &Scene,
    params: &ResolvedParams,
    chunking: &Chunking,
    observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    assert!(!scene.is_empty(), "grouping needs at least one primitive");
    if params.pset == PSet::Hull {
        return cluster::run(scene, params, observer, budget);
    }
    let n = scene.len();
    // Room for the merged bodies from the start (no copy when they are added).
    let mut aabb: Vec<Aabb> = Vec::with_capacity(2 * n - 1);
    aabb.par_extend((0..n).into_par_iter().map(|i| scene.prim_aabb(i)));
    group_boxes(aabb, params, chunking, observer, budget)
}

/// The partitioned schedule (AABB p-set) on primitives whose boxes are `aabb`, the primitive
/// ids being their indices (`aabb` grows to the tree's 2N − 1 boxes: give it that capacity to
/// spare a copy). Panics only if `aabb` is empty.
pub fn group_boxes<O: Observer>(
    mut aabb: Vec<Aabb>,
    params: &ResolvedParams,
    chunking: &Chunking,
    mut observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    assert!(!aabb.is_empty(), "grouping needs at least one primitive");
    let n = aabb.len();
    aabb.reserve_exact(n - 1);
    let mut diameter: Vec<f64> = Vec::with_capacity(2 * n - 1);
    diameter.par_extend(aabb.par_iter().map(Aabb::diameter));
    let mut codes = morton_order(&aabb);
    // The leaves as bodies in Morton order: one gather (its loads overlap) instead of one per
    // chunk, of the box alone (the diameter is recomputed, the same value, rather than read at
    // random from a second array); `rd` is set by their chunk.
    let mut leaves: Vec<Body> = (0..n)
        .into_par_iter()
        .map(|i| {
            if let Some(&(_, ahead)) = codes.get(i + GATHER_AHEAD) {
                prefetch(&aabb[ahead as usize]);
            }
            let id = codes[i].1;
            let aabb = aabb[id as usize];
            Body {
                id,
                rd: 0,
                aabb,
                d: aabb.diameter(),
            }
        })
        .collect();
    // Planned on the leaves themselves: the SAH cuts read their boxes in order, and reorder
    // them with their codes.
    let nodes = plan(&mut codes, &mut leaves, chunking);
    drop(codes);
    let ctx = Ctx {
        params: *params,
        dl: Limits::new(params.dlimit0),
        gl: Limits::new(params.glimit0),
        budget,
        pairs: AtomicU64::new(0),
        halt: AtomicBool::new(false),
        reason: Mutex::new(None),
    };
    let merges = n - 1;
    let mut children = vec![[0u32; 2]; merges];
    // The merges' slots, filled on every thread (fresh pages are written, and faulted in, in
    // parallel).
    aabb.par_extend(rayon::iter::repeat_n(Aabb::EMPTY, n - 1));
    diameter.par_extend(rayon::iter::repeat_n(0.0, n - 1));
    let listens = !observer.is_silent();
    let mut info = if listens {
        vec![Info::default(); merges]
    } else {
        Vec::new()
    };
    let done: Vec<AtomicBool> = nodes.iter().map(|_| AtomicBool::new(false)).collect();
    let exec = Exec {
        ctx: &ctx,
        nodes: &nodes,
        done: &done,
    };
    let (_, new_aabb) = aabb.split_at_mut(n);
    let (_, new_d) = diameter.split_at_mut(n);
    let out = Out {
        first_new: n as u32,
        children: &mut children,
        aabb: new_aabb,
        diameter: new_d,
        info: listens.then_some(&mut info[..]),
        stats: SubStats::default(),
    };
    let (result, sub) = exec.node(0, &mut leaves, out, false);
    // Events, in post-order, up to the first unfinished subproblem.
    let emitted = if listens || result.is_none() {
        let made = Made {
            n,
            children: &children,
            aabb: &aabb,
            diameter: &diameter,
            info: &info,
        };
        announce(&mut observer, &nodes, &done, &made, listens)
    } else {
        0
    };
    if result.is_none() {
        let reason = ctx
            .reason
            .lock()
            .expect("no panics hold it")
            .unwrap_or(StopReason::Interrupted);
        return Err(Stopped {
            reason,
            merges: emitted,
            rounds: 0,
            eligible_pairs: ctx.pairs.load(Ordering::Relaxed),
        });
    }
    let tree = SubsetTree::new(aabb, diameter, children)
        .expect("the partitioned schedule makes exactly N - 1 valid merges");
    observer.on_event(&Event::Finish {
        root: tree.root(),
        rounds: sub.rounds,
        merges: merges as u32,
    });
    Ok(Grouping {
        tree,
        rounds: sub.rounds,
        params: *params,
        stats: Stats {
            eligible_pairs: sub.eligible_pairs,
            candidates: sub.candidates,
            pops: sub.pops,
            stale_pops: sub.stale_pops,
            peak_queue: sub.peak_queue,
        },
        pregrouping: None,
    })
}

/// The read-only inputs of the recursive grouping.
struct Exec<'a> {
    ctx: &'a Ctx<'a>,
    nodes: &'a [Node],
    done: &'a [AtomicBool],
}

impl Exec<'_> {
    /// Groups node `k`'s subtree into `out` (its merges, in post-order). `arena` holds the
    /// node's primitives as bodies (its range of the Morton order); the bodies it leaves end
    /// up at its start. Returns how many it leaves (`None` when the budget stopped it), with
    /// their pairs when `export`, and its counters.
    fn node(
        &self,
        k: u32,
        arena: &mut [Body],
        out: Out<'_>,
        export: bool,
    ) -> (Option<Left>, SubStats) {
        let node = self.nodes[k as usize];
        let (parts, mut own, mut stats) = match node.kids(k) {
            None => {
                for b in arena.iter_mut() {
                    b.rd = self.ctx.dl.first(b.d);
                }
                let part = Left {
                    n: arena.len(),
                    pairs: Vec::new(),
                };
                ([part, Left::default()], out, SubStats::default())
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
                let want = node.inputs as usize <= small::SMALL && node.inputs > node.keep;
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
        let left = if m <= small::SMALL {
            Some(small::combine(
                self.ctx,
                &mut arena[..m],
                parts,
                keep,
                &mut own,
                export,
            ))
        } else {
            big::combine(self.ctx, arena[..m].to_vec(), keep, &mut own).map(|bodies| {
                arena[..bodies.len()].copy_from_slice(&bodies);
                Left {
                    n: bodies.len(),
                    pairs: Vec::new(),
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
