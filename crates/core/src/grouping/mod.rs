//! The grouping phase of §2.2: bottom-up greedy clustering of convex primitives into a binary
//! Subset Tree (`docs/method.md`, "The grouping phase").
//!
//! The paper's steps and where they are done:
//! 1. DLimit and GLimit start at [`ResolvedParams::dlimit0`]/[`ResolvedParams::glimit0`]
//!    ([`Params::resolve`]).
//! 2. One parent-less body left is the root; otherwise those with diameter ≤ DLimit are active,
//!    the rest dormant (`cluster::group_scene`, top of its round loop).
//! 3. Active centres go into a voxel hash of cell size DLimit + GLimit ([`voxel_hash::VoxelHash`]);
//!    the scans around each body (`cluster::scan`) queue the eligible pairs in MPairs
//!    ([`mpairs::MPairs`]) by Cost ([`Weights::cost`]).
//! 4. Pop the cheapest pair and merge it; the new body is searched and queued if it obeys
//!    DLimit, else it goes dormant (`cluster::group_scene`, inner loop).
//! 5. When MPairs is empty, double DLimit and GLimit and go to 2 (end of the round loop).
//!
//! MPairs holds each active body's cheapest partners, yet pops the global minimum ([`mpairs`]).
//! [`group_within`] stops at a [`Budget`] with [`Stopped`], after the unlimited run's first merges.
//!
//! Called from a thread outside the rayon pool, a run whose observer ignores every event goes in
//! one piece to one of the pool's threads (from 1,024 primitives), and the partitioned schedule
//! runs its split and subproblems there whatever the observer; events are always delivered on
//! the caller's thread.

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
pub use params::{
    CostMeasure, Exponent, Mode, PSet, Params, Pregroup, ResolvedParams, Schedule, Weights,
};
pub use pregroup::Pregrouping;
pub use subset_tree::{C_PRIM, C_TRAV, NONE, SubsetTree, sah, sah_of_sums};

use crate::geom::Aabb;
use crate::par::{POOL_MIN, on_pool};
use crate::scene::Scene;
use std::sync::atomic::AtomicBool;

/// Fewest items per piece of the grouping's parallel per-primitive passes (boxes, diameters,
/// Morton codes): below it a pass stays on the calling thread, where waking another costs more
/// than the pass.
pub(crate) const PAR_MIN_LEN: usize = 4096;

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
    /// Merges of neighbours with identical boxes made before the partitioned schedule's split
    /// (`Chunking::twins`, the fast path).
    pub identical: u64,
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
    group_on_pool(scene, &params.resolve(scene), observer, &Budget::default())
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
    group_on_pool(scene, params, observer, &budget)
}

/// Like [`group`] within `budget`: returns [`Stopped`] once a limit is exceeded (the observer
/// has then seen every merge made so far, and no `Finish`).
pub fn group_within<O: Observer>(
    scene: &Scene,
    params: &ResolvedParams,
    observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    group_on_pool(scene, params, observer, budget)
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
    group_boxes_within(boxes, params, observer, &Budget::default())
        .expect("an unlimited budget never stops")
}

/// Like [`group_boxes`] within `budget` (see [`group_within`]).
pub fn group_boxes_within<O: Observer>(
    boxes: Vec<Aabb>,
    params: &ResolvedParams,
    observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    if observer.is_silent() {
        // Nothing to tell: the whole run goes to the pool in one piece (`crate::par`).
        let worth = boxes.len() >= POOL_MIN;
        return on_pool(worth, move || run_boxes(boxes, params, (), budget));
    }
    run_boxes(boxes, params, observer, budget)
}

/// [`group_boxes_within`] on the caller's thread.
fn run_boxes<O: Observer>(
    boxes: Vec<Aabb>,
    params: &ResolvedParams,
    observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    match params.mode.schedule {
        Schedule::Exact => cluster::run_boxes(boxes, params, observer, budget),
        Schedule::Partitioned(c) => partitioned::group_boxes(boxes, params, &c, observer, budget),
    }
}

/// Runs the grouping phase in the schedule and mode that `params` names: with an observer that
/// ignores every event, in one piece on the rayon pool (`crate::par`).
fn group_on_pool<O: Observer>(
    scene: &Scene,
    params: &ResolvedParams,
    observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    if observer.is_silent() {
        return on_pool(scene.len() >= POOL_MIN, || {
            run_here(scene, params, (), budget)
        });
    }
    run_here(scene, params, observer, budget)
}

/// [`group_on_pool`] on the caller's thread.
fn run_here<O: Observer>(
    scene: &Scene,
    params: &ResolvedParams,
    observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    if params.mode.pregroup != Pregroup::None && params.pset == PSet::Aabb {
        return pregroup::group_components(scene, params, observer, budget);
    }
    match params.mode.schedule {
        Schedule::Exact => cluster::group_scene(scene, params, observer, budget),
        Schedule::Partitioned(c) => partitioned::group_with(scene, params, &c, observer, budget),
    }
}
