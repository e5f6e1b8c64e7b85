//! The round loop of §2.2 (steps 2–5), generic over the p-set wrapper.
//!
//! Partner searches (the voxel scans of steps 3 and 4b) live in [`scan`], Fill and Balance in
//! [`fill`], and the runs on bodies given by their boxes (pre-grouping's parts, the partitioned
//! schedule's chunks) in [`boxes`].

use super::hull_pset::HullBodies;
use super::mpairs::{Entry, MPairs, Partners, order_bits};
use super::pset::PSetBodies;
use super::subset_tree::{NONE, SubsetTree};
use super::voxel_hash::VoxelHash;
use super::{Budget, Grouping, PSet, ResolvedParams, Stats, StopReason, Stopped};
use crate::events::{Event, Merge, Observer};
use crate::geom::morton::spread_bits;
use crate::geom::{Aabb, surface_area};
use crate::scene::Scene;
use std::sync::atomic::Ordering;

mod boxes;
mod fill;
mod keys;
mod scan;

pub(crate) use boxes::{run_boxes, run_boxes_until};
pub(in crate::grouping) use fill::fill_balance;
pub(in crate::grouping) use keys::tie_tag;
pub(in crate::grouping) use scan::pair_cost_any;

/// Runs the grouping phase; see the module doc of [`super`] for the steps.
pub(super) fn group_scene<O: Observer>(
    scene: &Scene,
    params: &ResolvedParams,
    observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    assert!(!scene.is_empty(), "grouping needs at least one primitive");
    let boxes = (0..scene.len()).map(|i| scene.prim_aabb(i)).collect();
    match params.pset {
        PSet::Aabb => run_boxes(boxes, params, observer, budget),
        PSet::Hull => {
            let bodies = HullBodies::new(scene);
            let diameters = bodies.leaf_diameters();
            Clusterer::new(boxes, params, bodies, diameters, observer).run(budget)
        }
    }
}

/// The budget as the round-start scans see it: pairs left before `max_pairs` is exceeded,
/// and the stop flag and deadline, read every [`Budget::CLOCK_EVERY`] bodies.
pub(super) struct ScanLimit<'b> {
    budget: &'b Budget<'b>,
    /// Eligible pairs this scan may find before the budget is exceeded (`u64::MAX`: no limit).
    room: u64,
    /// Whether the budget has a stop flag or a deadline.
    timed: bool,
    bodies: u32,
    /// The limit that cut the scan short, if any.
    hit: Option<StopReason>,
}

impl ScanLimit<'_> {
    /// Whether the scan must stop before its next body, having found `pairs` so far.
    #[inline(always)]
    pub(super) fn over(&mut self, pairs: u64) -> bool {
        if pairs > self.room {
            self.hit = Some(StopReason::MaxPairs);
            return true;
        }
        if self.timed {
            self.bodies = self.bodies.wrapping_add(1);
            if self.bodies.is_multiple_of(Budget::CLOCK_EVERY) {
                self.hit = self.budget.exceeded_now();
                return self.hit.is_some();
            }
        }
        false
    }
}

/// The state of one grouping run.
struct Clusterer<P, O> {
    n: usize,
    /// Parent-less bodies at which the run stops (1: the root).
    keep: usize,
    params: ResolvedParams,
    pset: P,
    observer: O,
    aabb: Vec<Aabb>,
    diameter: Vec<f64>,
    /// Active and not yet merged (stored in the voxel hash) — `live[x]`.
    live: Vec<bool>,
    parent: Vec<u32>,
    tag: Vec<u64>,
    /// Children of each interior node made so far, in merge order.
    children: Vec<[u32; 2]>,
    hash: VoxelHash,
    bounds: Aabb,
    /// Largest half-extent per axis of the bodies in the hash this round.
    half_ext: [f64; 3],
    morton_scale: [f64; 3],
    mpairs: MPairs,
    partners: Partners,
    /// Partner list length.
    k: usize,
    /// Whether Cost lower bounds may skip voxels (AABB p-set, finite non-negative weights,
    /// scene coordinates far from overflow).
    prune: bool,
    /// Whether every box coordinate is finite, so the round-start scan may stop early in a
    /// cell's records (sorted by smallest x).
    finite: bool,
    /// Whether the scene coordinates are below 1e100 in magnitude (AABB p-set, `prune`), so
    /// the searches' sqrt-free Cost filter keeps its operands in range.
    quick: bool,
    /// The last AABB partner search, reused while the voxel hash is unchanged.
    memo: Option<scan::Memo>,
    /// A single search's Cost bounds of a crowded cell's blocks (kept for its allocation).
    items: Vec<(f64, u32)>,
    stats: Stats,
}

impl<P: PSetBodies, O: Observer> Clusterer<P, O> {
    fn new(
        mut aabb: Vec<Aabb>,
        params: &ResolvedParams,
        pset: P,
        diameter: Vec<f64>,
        observer: O,
    ) -> Self {
        let n = aabb.len();
        let total = 2 * n - 1;
        aabb.reserve(total - n);
        let mut d = diameter;
        d.reserve(total - n);
        let bounds = aabb.iter().fold(Aabb::EMPTY, |b, x| b.merge(x));
        let finite = aabb
            .iter()
            .all(|b| (0..3).all(|k| b.min[k].is_finite() && b.max[k].is_finite()));
        let ext = bounds.extents();
        let morton_scale = [0, 1, 2].map(|k| {
            if ext[k] > 0.0 {
                2_097_151.0 / ext[k]
            } else {
                0.0
            }
        });
        let w = params.weights;
        let sane = |v: f64| v.is_finite() && v >= 0.0;
        let small = |v: f64| v.abs() < 1e300;
        let prune = P::AABB
            && sane(w.a)
            && sane(w.b)
            && sane(w.c)
            && (0..3).all(|k| small(bounds.min[k]) && small(bounds.max[k]));
        Clusterer {
            n,
            keep: 1,
            params: *params,
            pset,
            observer,
            aabb,
            diameter: d,
            live: vec![false; total],
            parent: vec![NONE; total],
            tag: (0..total as u32).map(|i| tie_tag(params.seed, i)).collect(),
            children: Vec::with_capacity(n - 1),
            hash: VoxelHash::default(),
            bounds,
            half_ext: [0.0; 3],
            morton_scale,
            mpairs: MPairs::default(),
            partners: Partners::default(),
            k: super::mpairs::K_MAX,
            prune,
            finite,
            quick: prune
                && finite
                && (0..3).all(|k| bounds.min[k].abs() < 1e100 && bounds.max[k].abs() < 1e100),
            memo: None,
            items: Vec::new(),
            stats: Stats::default(),
        }
    }

    /// Morton (Z-order) code of body `x`'s centre on a 2^21 grid over the scene box.
    fn morton_key(&self, x: u32) -> u64 {
        let c = self.aabb[x as usize].center();
        let mut key = 0u64;
        for k in 0..3 {
            let t =
                ((c[k] - self.bounds.min[k]) * self.morton_scale[k]).clamp(0.0, 2_097_151.0) as u64;
            key |= spread_bits(t) << k;
        }
        key
    }

    fn grow_half_ext(&mut self, x: u32) {
        let e = self.aabb[x as usize].extents();
        for k in 0..3 {
            self.half_ext[k] = self.half_ext[k].max(e[k] / 2.0);
        }
    }

    /// Queues the current entry of `x`'s list, if any.
    fn queue_current(&mut self, x: u32) {
        if let Some(c) = self.partners.get(x).current() {
            let e = Entry {
                cost: order_bits(c.cost),
                owner: x,
                partner: c.partner,
            };
            self.mpairs.push(e, &self.tag);
        }
    }

    /// What [`run`] returns when `reason` stops it after `rounds` announced rounds.
    fn stopped(&self, reason: StopReason, rounds: u32) -> Stopped {
        Stopped {
            reason,
            merges: self.children.len() as u32,
            rounds,
            eligible_pairs: self.stats.eligible_pairs,
        }
    }

    fn run(mut self, budget: &Budget<'_>) -> Result<Grouping, Stopped> {
        let round = self.rounds(budget)?;
        let merges = self.children.len() as u32;
        let tree = SubsetTree::new(self.aabb, self.diameter, self.children)
            .expect("the round loop makes exactly N - 1 valid merges");
        self.observer.on_event(&Event::Finish {
            root: tree.root(),
            rounds: round,
            merges,
        });
        Ok(Grouping {
            tree,
            rounds: round,
            params: self.params,
            stats: self.stats,
            pregrouping: None,
        })
    }

    /// The round loop, until `self.keep` parent-less bodies remain; returns the rounds run.
    fn rounds(&mut self, budget: &Budget<'_>) -> Result<u32, Stopped> {
        let n = self.n;
        let keep = self.keep;
        let max_pairs = budget.max_pairs.unwrap_or(u64::MAX);
        let timed = budget.stop.is_some() || budget.deadline.is_some();
        // Merges since the clock was last read.
        let mut tick = 0u32;
        let mut parentless: Vec<u32> = (0..n as u32).collect();
        let (mut dlimit, mut glimit) = (self.params.dlimit0, self.params.glimit0);
        let mut round = 0u32;
        let mut active: Vec<u32> = Vec::new();
        let mut morton: Vec<(u64, u32)> = Vec::new();
        let mut order: Vec<u32> = Vec::new();
        // Step 2: one parent-less body left is the root.
        while parentless.len() > keep {
            if let Some(reason) = budget.exceeded_now() {
                return Err(self.stopped(reason, round));
            }
            active.clear();
            active.extend(
                parentless
                    .iter()
                    .copied()
                    .filter(|&x| self.diameter[x as usize] <= dlimit),
            );
            let dormant = (parentless.len() - active.len()) as u32;
            // Step 3: voxel hash of active centres, CSize = DLimit + GLimit; queue best pairs.
            self.hash_active(&active, &mut morton, &mut order, dlimit + glimit);
            let pairs = match self.eligible_pairs(&order, glimit, budget, max_pairs, timed) {
                Ok(pairs) => pairs,
                Err(reason) => return Err(self.stopped(reason, round)),
            };
            for &x in &order {
                self.queue_current(x);
            }
            self.observer.on_event(&Event::RoundStart {
                round,
                dlimit,
                glimit,
                active: &active,
                dormant,
                pairs,
            });
            // Step 4: pop and merge until MPairs is empty.
            let merges_before = self.children.len();
            while let Some(e) = self.mpairs.peek() {
                self.stats.pops += 1;
                if !self.live[e.owner as usize] {
                    self.stats.stale_pops += 1;
                    self.mpairs.pop(&self.tag);
                    continue;
                }
                if !self.live[e.partner as usize] {
                    self.stats.stale_pops += 1;
                    self.requeue_owner(e, glimit);
                    continue;
                }
                self.mpairs.pop(&self.tag);
                if timed {
                    // The flag before every merge, the clock every CLOCK_EVERY merges.
                    let clock =
                        budget.deadline.is_some() && tick.is_multiple_of(Budget::CLOCK_EVERY);
                    tick = tick.wrapping_add(1);
                    let reason = if clock {
                        budget.exceeded_now()
                    } else if budget.stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                        Some(StopReason::Interrupted)
                    } else {
                        None
                    };
                    if let Some(reason) = reason {
                        return Err(self.stopped(reason, round + 1));
                    }
                }
                self.merge_pair(e, round, dlimit, glimit);
                if keep > 1 && parentless.len() - (self.children.len() - merges_before) <= keep {
                    break;
                }
            }
            let made = (self.children.len() - merges_before) as u32;
            parentless.retain(|&x| self.parent[x as usize] == NONE);
            parentless.extend(
                ((n + merges_before) as u32..(n + self.children.len()) as u32)
                    .filter(|&x| self.parent[x as usize] == NONE),
            );
            round += 1;
            if parentless.len() > keep {
                // Step 5: double the limits and go to step 2.
                dlimit *= 2.0;
                glimit *= 2.0;
                self.observer.on_event(&Event::Doubling {
                    round: round - 1,
                    merges: made,
                    dlimit,
                    glimit,
                });
            }
        }
        Ok(round)
    }

    /// Step 3 for the round's `active` bodies: stored and searched in Morton order of their
    /// centres (`order`), so consecutive searches reuse the same cells from cache (the order
    /// changes no result), and put in a voxel hash of cell size `csize` = DLimit + GLimit.
    fn hash_active(
        &mut self,
        active: &[u32],
        morton: &mut Vec<(u64, u32)>,
        order: &mut Vec<u32>,
        csize: f64,
    ) {
        morton.clear();
        morton.extend(active.iter().map(|&x| (self.morton_key(x), x)));
        morton.sort_unstable();
        order.clear();
        order.extend(morton.iter().map(|&(_, x)| x));
        let ids = 2 * self.n - 1;
        self.half_ext = [0.0; 3];
        self.partners.reset(ids);
        for &x in order.iter() {
            self.live[x as usize] = true;
            self.grow_half_ext(x);
            self.partners.open(x);
        }
        let slots = self.partners.slots();
        self.hash
            .build(csize, order, &self.aabb, &self.diameter, slots, ids);
    }

    /// Step 3's scan of the hashed bodies `order` for their eligible pairs (within GLimit
    /// `glimit`), counted into the stats; Err when the budget (the stop, the deadline, or
    /// `max_pairs` eligible pairs in all) ends the run.
    fn eligible_pairs(
        &mut self,
        order: &[u32],
        glimit: f64,
        budget: &Budget<'_>,
        max_pairs: u64,
        timed: bool,
    ) -> Result<u64, StopReason> {
        let mut limit = ScanLimit {
            budget,
            room: max_pairs.saturating_sub(self.stats.eligible_pairs),
            timed,
            bodies: 0,
            hit: None,
        };
        let pairs = self.round_start_search(order, glimit, &mut limit);
        self.stats.eligible_pairs += pairs;
        if self.stats.eligible_pairs > max_pairs {
            limit.hit = Some(StopReason::MaxPairs);
        }
        match limit.hit {
            Some(reason) => Err(reason),
            None => Ok(pairs),
        }
    }

    /// The popped entry `e`'s partner merged away: the owner's next live partner replaces the
    /// entry, else a new search finds one, else the entry leaves MPairs.
    #[inline]
    fn requeue_owner(&mut self, e: Entry, glimit: f64) {
        let live = &self.live;
        let mut next = self.partners.get(e.owner).advance(|y| live[y as usize]);
        if next.is_none() {
            self.search(e.owner, glimit);
            next = self.partners.get(e.owner).current();
        }
        match next {
            Some(c) => {
                let again = Entry {
                    cost: order_bits(c.cost),
                    owner: e.owner,
                    partner: c.partner,
                };
                self.mpairs.replace_top(again, &self.tag);
            }
            None => {
                self.mpairs.pop(&self.tag);
            }
        }
    }

    /// Step 4(a)–(c) for one popped pair.
    fn merge_pair(&mut self, e: Entry, round: u32, dlimit: f64, glimit: f64) {
        let (a, b) = (e.owner.min(e.partner), e.owner.max(e.partner));
        let new = (self.n + self.children.len()) as u32;
        let merged = self.aabb[a as usize].merge(&self.aabb[b as usize]);
        for x in [a, b] {
            self.live[x as usize] = false;
            self.parent[x as usize] = new;
            self.hash.remove(x);
            self.partners.close(x);
        }
        let d = self.pset.merge(a, b, new, &merged);
        let (size, sa, sb) = if self.params.mode.cost == super::CostMeasure::Area {
            let ext = |x: u32| self.aabb[x as usize].max - self.aabb[x as usize].min;
            (
                surface_area(&(merged.max - merged.min)),
                surface_area(&ext(a)),
                surface_area(&ext(b)),
            )
        } else {
            (d, self.diameter[a as usize], self.diameter[b as usize])
        };
        let (fill, balance) = fill_balance(size, sa, sb);
        let cost = self.params.weights.cost(size, fill, balance);
        self.aabb.push(merged);
        self.diameter.push(d);
        self.children.push([a, b]);
        let is_active = d <= dlimit;
        if is_active {
            // Step 4(b): the new body joins ABods and queues its best eligible pair.
            self.live[new as usize] = true;
            self.grow_half_ext(new);
            self.partners.open(new);
            let slot = self.partners.slot(new) as u32;
            self.hash.insert(new, &merged, d, slot);
            self.search(new, glimit);
            self.queue_current(new);
        }
        self.stats.peak_queue = self.stats.peak_queue.max(self.mpairs.len() as u64);
        self.observer.on_event(&Event::Merge(Merge {
            step: (new as usize - self.n) as u32,
            round,
            a,
            b,
            new,
            aabb: merged,
            diameter: d,
            fill,
            balance,
            cost,
            queue_len: self.mpairs.len() as u32,
            active: is_active,
        }));
        if !is_active {
            // Step 4(c): too big for this round's DLimit; dormant until a later round.
            self.observer.on_event(&Event::Dormant {
                round,
                body: new,
                diameter: d,
            });
        }
    }
}
