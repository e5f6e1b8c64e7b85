//! Step 3's round-start scan (AABB p-set) on several threads, with the same result as the
//! sequential scan.
//!
//! The voxel hash's records, cell by cell, are cut into ranges of equal length (a late round
//! holds many bodies in a few cells, so ranges of cells would be uneven) and scanned as the
//! sequential scan does. A range writes the lists of its own bodies directly and buffers offers
//! to other ranges' bodies, made after the parallel part. A list holds the first partners in
//! (Cost, tie tag) order whatever the order of the offers, and the Cost filter only skips
//! offers that could not enter a list, so every list and count is the sequential scan's.
//!
//! It runs when the pool has several threads, the round has at least [`MIN_BODIES`] active
//! bodies and the budget has no `max_pairs` (where a scan stops would depend on the order of
//! counting). The stop flag and deadline are read every [`Budget::CLOCK_EVERY`] bodies.

use super::{Clusterer, PSetBodies, Quick, ScanLimit, apart, merged_extents, pair_cost};
use super::{MemoKey, count_cell, later_near, memo_key, reachable};
use crate::events::Observer;
use crate::grouping::mpairs::{K_MAX, List, Top};
use crate::grouping::{Budget, StopReason};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// Rounds with fewer active bodies scan on one thread.
pub(super) const MIN_BODIES: usize = 2048;

/// Record ranges per thread (more than one evens out uneven ranges).
const RANGES_PER_THREAD: usize = 8;

/// Crowded rounds with fewer active bodies start on one thread (their bodies cost more each).
pub(super) const CROWDED_MIN_BODIES: usize = 256;

/// Whether a round start of `bodies` active bodies under `limit` runs in parallel: at least
/// `min` of them ([`MIN_BODIES`], or [`CROWDED_MIN_BODIES`] for a crowded round), no
/// `max_pairs`, and more than one thread.
pub(super) fn worth_it(min: usize, bodies: usize, limit: &ScanLimit<'_>) -> bool {
    bodies >= min && limit.budget.max_pairs.is_none() && rayon::current_num_threads() > 1
}

/// The partner lists, shared by the ranges; each range writes only its own bodies' lists.
#[derive(Clone, Copy)]
struct Lists(*mut List);

// SAFETY: the ranges write disjoint lists (see `Clusterer::pairs_once_par`).
unsafe impl Send for Lists {}
// SAFETY: as above.
unsafe impl Sync for Lists {}

impl Lists {
    /// The list in slot `s`.
    ///
    /// # Safety
    /// `s` is a valid slot, and no other reference to that list is alive.
    #[inline(always)]
    unsafe fn get<'a>(self, s: usize) -> &'a mut List {
        // SAFETY: guaranteed by the caller.
        unsafe { &mut *self.0.add(s) }
    }
}

/// What one record range found.
#[derive(Default)]
struct Found {
    pairs: u64,
    candidates: u64,
    /// Offers to bodies of other ranges: (slot, Cost, partner).
    remote: Vec<(u32, f64, u32)>,
}

impl<P: PSetBodies, O: Observer> Clusterer<P, O> {
    /// [`Clusterer::pairs_once`] on the current rayon pool (see the module doc).
    pub(super) fn pairs_once_par<const A: u8>(
        &mut self,
        glimit: f64,
        limit: &mut ScanLimit<'_>,
    ) -> u64 {
        let (k, w, finite) = (self.k, self.params.weights, self.finite);
        let quick = Quick::new(&w, self.quick);
        let hash = &self.hash;
        let half_ext = self.half_ext;
        let tags: &[u64] = &self.tag;
        let cells = hash.cells();
        // Each cell's first position in the records taken in cell order: ranges are cut by
        // records, not cells, since a late round holds many bodies in a few cells.
        let mut first = Vec::with_capacity(cells as usize + 1);
        let mut total = 0usize;
        for c in 0..cells {
            first.push(total);
            total += hash.recs(c).len();
        }
        first.push(total);
        let first = &first;
        let parts = (rayon::current_num_threads() * RANGES_PER_THREAD).clamp(1, total.max(1));
        let lists = self.partners.lists_mut();
        let slots = lists.len();
        let lists = Lists(lists.as_mut_ptr());
        let halt = AtomicBool::new(false);
        let (budget, timed) = (limit.budget, limit.timed);
        let scan = |p: usize| -> (Found, Option<StopReason>) {
            let (lo, hi) = (p * total / parts, (p + 1) * total / parts);
            let ours = |cell: u32, i: usize| (lo..hi).contains(&(first[cell as usize] + i));
            let mut f = Found::default();
            let mut near: Vec<u32> = Vec::with_capacity(27);
            let mut fwd: Vec<u32> = Vec::with_capacity(27);
            let mut bodies = 0u32;
            let c0 = first.partition_point(|&s| s <= lo).saturating_sub(1) as u32;
            for c in (c0..cells).take_while(|&c| first[c as usize] < hi) {
                later_near(hash, &half_ext, c, glimit, &mut near);
                let at = first[c as usize];
                for i in lo.saturating_sub(at)..hash.recs(c).len().min(hi - at) {
                    if timed {
                        bodies = bodies.wrapping_add(1);
                        if bodies.is_multiple_of(Budget::CLOCK_EVERY) {
                            if halt.load(Ordering::Relaxed) {
                                return (f, None);
                            }
                            if let Some(r) = budget.exceeded_now() {
                                halt.store(true, Ordering::Relaxed);
                                return (f, Some(r));
                            }
                        }
                    }
                    let xr = hash.recs(c)[i];
                    let (x, xa, dx, sx) = (xr.id, xr.aabb, xr.diameter, xr.slot as usize);
                    debug_assert!(sx < slots);
                    fwd.clear();
                    fwd.extend(
                        near.iter()
                            .copied()
                            .filter(|&cell| reachable(hash.bounds(cell), &xa, glimit)),
                    );
                    let own = hash.runs_from(c, i + 1).map(|run| (c, run));
                    let later = fwd
                        .iter()
                        .flat_map(|&cell| hash.runs_from(cell, 0).map(move |run| (cell, run)));
                    for (cell, (at, seg)) in own.chain(later) {
                        for (j, yr) in (at..).zip(seg) {
                            if finite && yr.aabb.min.x - xa.max.x > glimit {
                                break;
                            }
                            f.candidates += 1;
                            if apart(&xa, &yr.aabb, glimit) {
                                continue;
                            }
                            f.pairs += 1;
                            let e = merged_extents(&xa, &yr.aabb);
                            let sy = yr.slot as usize;
                            // SAFETY: `x` is a record of this range, which alone writes its
                            // list; `y` too when it is ours; `x != y`.
                            let lx = unsafe { lists.get(sx) };
                            if ours(cell, j) {
                                // SAFETY: as above.
                                let ly = unsafe { lists.get(sy) };
                                if let Some(q) = quick {
                                    let bar = lx.bar(k).max(ly.bar(k));
                                    if q.beyond(e.norm_squared(), dx + yr.diameter, bar) {
                                        continue;
                                    }
                                }
                                let cost = pair_cost::<A>(&w, e.norm(), dx, yr.diameter);
                                lx.offer(k, cost, yr.id, tags);
                                ly.offer(k, cost, x, tags);
                            } else {
                                let cost = pair_cost::<A>(&w, e.norm(), dx, yr.diameter);
                                lx.offer(k, cost, yr.id, tags);
                                f.remote.push((sy as u32, cost, x));
                            }
                        }
                    }
                }
            }
            (f, None)
        };
        let found: Vec<(Found, Option<StopReason>)> =
            (0..parts).into_par_iter().map(scan).collect();
        let lists = self.partners.lists_mut();
        let mut pairs = 0u64;
        for (f, hit) in &found {
            pairs += f.pairs;
            self.stats.candidates += f.candidates;
            if limit.hit.is_none() {
                limit.hit = *hit;
            }
            for &(s, cost, x) in &f.remote {
                lists[s as usize].offer(k, cost, x, &self.tag);
            }
        }
        if limit.hit.is_none() && halt.load(Ordering::Relaxed) {
            limit.hit = budget.exceeded_now();
        }
        pairs
    }

    /// The crowded round start on the current rayon pool: the eligible pairs counted cell by
    /// cell, and each body's search, in ranges of `order`. Each search is a function of the
    /// voxel hash alone, and each range keeps its own [`Memo`](super::Memo), so every list and
    /// count is the sequential run's. Crowded rounds use the sqrt-free filter, so A = 1.
    pub(super) fn crowded_par(
        &mut self,
        order: &[u32],
        glimit: f64,
        limit: &mut ScanLimit<'_>,
    ) -> u64 {
        let hash = &self.hash;
        let half_ext = self.half_ext;
        let (pairs, seen) = (0..hash.cells())
            .into_par_iter()
            .map_init(
                || Vec::with_capacity(27),
                |near, c| count_cell(hash, &half_ext, c, glimit, near),
            )
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        let search = self.pruned();
        let (aabb, diameter, version, k) = (&self.aabb, &self.diameter, hash.version(), self.k);
        let len = order.len();
        let parts = (rayon::current_num_threads() * RANGES_PER_THREAD).clamp(1, len.max(1));
        let start = |p: usize| p * len / parts;
        let range = |p: usize| &order[start(p)..start(p + 1)];
        let halt = AtomicBool::new(false);
        let (budget, timed) = (limit.budget, limit.timed);
        let found: Vec<(Vec<List>, u64, Option<StopReason>)> = (0..parts)
            .into_par_iter()
            .map(|p| {
                let bodies = range(p);
                let mut lists = Vec::with_capacity(bodies.len());
                let (mut items, mut candidates) = (Vec::new(), 0u64);
                let key_of = |x: u32| memo_key(&aabb[x as usize], diameter[x as usize], version);
                // The key the one-thread run's memo holds on entering the range: its last body's
                // (a body identical to the last one is served from the memo, and reads nothing).
                let before = start(p).checked_sub(1).map(|i| key_of(order[i]));
                let mut memo: Option<(MemoKey, Top<{ K_MAX + 1 }>)> = None;
                for (i, &x) in bodies.iter().enumerate() {
                    if timed && (i as u32 + 1).is_multiple_of(Budget::CLOCK_EVERY) {
                        if halt.load(Ordering::Relaxed) {
                            return (lists, candidates, None);
                        }
                        if let Some(r) = budget.exceeded_now() {
                            halt.store(true, Ordering::Relaxed);
                            return (lists, candidates, Some(r));
                        }
                    }
                    let key = key_of(x);
                    let top = match memo {
                        Some((mk, top)) if mk == key => top,
                        _ => {
                            // Counted as the one-thread run reads: nothing for a body that its
                            // memo would have served.
                            let mut read = 0u64;
                            let top = search.list::<1>(x, glimit, &mut items, &mut read);
                            if !(i == 0 && before == Some(key)) {
                                candidates += read;
                            }
                            memo = Some((key, top));
                            top
                        }
                    };
                    lists.push(top.without(x, k));
                }
                (lists, candidates, None)
            })
            .collect();
        self.stats.candidates += seen;
        for (p, (lists, candidates, hit)) in found.into_iter().enumerate() {
            for (&x, list) in range(p).iter().zip(lists) {
                *self.partners.get(x) = list;
            }
            self.stats.candidates += candidates;
            if limit.hit.is_none() {
                limit.hit = hit;
            }
        }
        if limit.hit.is_none() && halt.load(Ordering::Relaxed) {
            limit.hit = budget.exceeded_now();
        }
        pairs
    }
}
