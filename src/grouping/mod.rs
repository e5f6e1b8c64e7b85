//! The grouping phase of §2.2: bottom-up greedy clustering of convex primitives into a binary
//! Subset Tree.
//!
//! The paper's steps and where they live:
//!
//! 1. *GLimit* (largest gap between merged bodies) and *DLimit* (largest diameter of a body that
//!    may merge) start at [`ResolvedParams::dlimit0`]/[`ResolvedParams::glimit0`]
//!    ([`Params::resolve`]).
//! 2. One parent-less body left → it is the root. Otherwise parent-less bodies with
//!    diameter ≤ DLimit are active (*ABods*), the rest dormant (*DBods*) — `cluster::run`, top of
//!    its round loop.
//! 3. Active body centres go into a voxel hash with cell size CSize = DLimit + GLimit
//!    ([`voxel_hash::VoxelHash`]); scanning the voxels around each body (at round start each
//!    pair of cells once for the AABB p-set, see `cluster::scan`) and filtering by GLimit gives
//!    the eligible pairs, queued in *MPairs* by Cost ([`mpairs::MPairs`]).
//! 4. Until MPairs is empty: (a) pop the cheapest pair, skipping pairs that lost a member, and
//!    merge it; (b) if the new body obeys DLimit it becomes active, enters the hash and its
//!    eligible pairs are queued; (c) otherwise it goes dormant — `cluster::run`, inner loop.
//! 5. Double DLimit and GLimit and go to 2 — end of the round loop.
//!
//! Cost = diameter^A × (B·Fill + C·Balance) ([`Weights::cost`]), Fill = parent diameter / sum of
//! child diameters, Balance = greater ratio of the child diameters.
//!
//! MPairs keeps one entry per active body: the first live entry of its partner list (the AABB
//! p-set's four cheapest eligible partners at the body's last search; the hull p-set's single
//! best). When a popped entry's partner has merged away, the next live list entry replaces it;
//! only a used-up list triggers a new search. Because pair Costs are symmetric and fixed, the
//! pair popped at every step is the global minimum over all eligible pairs (argument in
//! [`mpairs`]), exactly the pair the literal queue would pop, so the tree is the same; the
//! queue is O(N) instead of O(kN). Ties break by the pair's (smaller id, larger id), or by seeded random tags with
//! `--seed`.
//!
//! [`group_within`] runs under a [`Budget`] (a stop flag, a deadline, a cap on the eligible
//! pairs of step 3), checked between merges and between the bodies of a round-start scan, and
//! returns [`Stopped`] with the reason when one is exceeded; the merges made so far are the
//! unlimited run's first ones.

mod cluster;

mod hull_pset;
mod limits;
pub mod mpairs;
mod params;
pub mod partitioned;
pub mod pregroup;
mod pset;
pub mod subset_tree;
pub mod voxel_hash;

pub use crate::events::{Event, EventLog, Merge, Observer, Part, PartKind, Tee};
pub use limits::{Budget, Limits, StopReason, Stopped};
pub use params::{CostMeasure, Mode, PSet, Params, Pregroup, ResolvedParams, Schedule, Weights};
pub use pregroup::Pregrouping;
pub use subset_tree::{C_PRIM, C_TRAV, NONE, SubsetTree, sah};

use crate::geom::Aabb;
use crate::scene::Scene;
use std::sync::atomic::AtomicBool;

/// Counters of one run, for benchmarks and the stability study.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Stats {
    /// Eligible pairs found by the round-start scans, summed over rounds.
    pub eligible_pairs: u64,
    /// Candidate bodies examined in voxel scans.
    pub candidates: u64,
    /// MPairs pops.
    pub pops: u64,
    /// Pops skipped because a member had merged away.
    pub stale_pops: u64,
    /// Largest MPairs length.
    pub peak_queue: u64,
}

/// The outcome of the grouping phase.
#[derive(Clone, Debug)]
pub struct Grouping {
    /// The Subset Tree.
    pub tree: SubsetTree,
    /// Number of rounds (DLimit values) used.
    pub rounds: u32,
    /// The parameters after resolution.
    pub params: ResolvedParams,
    /// Work counters.
    pub stats: Stats,
    /// What pre-grouping found and did, when the mode pre-groups ([`pregroup`]).
    pub pregrouping: Option<Pregrouping>,
}

/// Runs the grouping phase on `scene`, reporting every step to `observer`.
///
/// Panics only if the scene is empty; loaders reject empty scenes first.
pub fn group<O: Observer>(scene: &Scene, params: &Params, observer: O) -> Grouping {
    run(scene, &params.resolve(scene), observer, &Budget::default())
        .expect("an unlimited budget never stops")
}

/// Like [`group`], but checks `stop` between merges and returns [`Stopped`] once it is set
/// (the observer has then seen every merge made so far).
pub fn group_until<O: Observer>(
    scene: &Scene,
    params: &ResolvedParams,
    observer: O,
    stop: &AtomicBool,
) -> Result<Grouping, Stopped> {
    let budget = Budget {
        stop: Some(stop),
        ..Budget::default()
    };
    run(scene, params, observer, &budget)
}

/// Like [`group`] within `budget`: returns [`Stopped`] once a limit is exceeded (the observer
/// has then seen every merge made so far, and no `Finish`).
pub fn group_within<O: Observer>(
    scene: &Scene,
    params: &ResolvedParams,
    observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    run(scene, params, observer, budget)
}

/// Runs the grouping phase on primitives known by their boxes alone (primitive `i` is
/// `boxes[i]`), with the AABB p-set and the schedule `params` names (its p-set and pre-grouping
/// are not read: the hull p-set and pre-grouping need the polygons, see [`group`]). Gives the
/// tree [`group`] gives for those settings on a scene whose [`Scene::prim_aabb`] are `boxes`.
/// Panics only if `boxes` is empty.
pub fn group_boxes<O: Observer>(
    boxes: Vec<Aabb>,
    params: &ResolvedParams,
    observer: O,
) -> Grouping {
    let budget = Budget::default();
    match params.mode.schedule {
        Schedule::Exact => cluster::run_boxes(boxes, params, observer, &budget),
        Schedule::Partitioned => partitioned::run_boxes(boxes, params, observer, &budget),
    }
    .expect("an unlimited budget never stops")
}

/// Runs the grouping phase in the schedule and mode that `params` names.
fn run<O: Observer>(
    scene: &Scene,
    params: &ResolvedParams,
    observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    if params.mode.pregroup != Pregroup::None && params.pset == PSet::Aabb {
        return pregroup::run(scene, params, observer, budget);
    }
    match params.mode.schedule {
        Schedule::Exact => cluster::run(scene, params, observer, budget),
        Schedule::Partitioned => partitioned::run(scene, params, observer, budget),
    }
}
