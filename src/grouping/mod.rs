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
pub mod events;
mod hull_pset;
mod limits;
pub mod mpairs;
pub mod partitioned;
pub mod pregroup;
mod pset;
pub mod subset_tree;
pub mod voxel_hash;

pub use events::{Event, EventLog, Merge, Observer, Part, PartKind, Tee};
pub use limits::Limits;
pub use pregroup::Pregrouping;
pub use subset_tree::{NONE, SubsetTree};

use crate::scene::Scene;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// The p-set wrapper bodies carry while grouping.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum PSet {
    /// Axis-aligned boxes, diagonal as diameter, L∞ gaps (the paper's fast variant).
    #[default]
    Aabb,
    /// Convex hulls (parry), largest vertex distance as diameter, L2 gaps (GJK).
    Hull,
}

/// The Cost weights of eq. (2).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Weights {
    /// Exponent A on the diameter.
    pub a: f64,
    /// Weight B on Fill.
    pub b: f64,
    /// Weight C on Balance.
    pub c: f64,
}

impl Weights {
    /// Cost = diameter^A × (B·Fill + C·Balance). When B = C = 0 the bracket would vanish for
    /// every pair; it is then taken as 1, so the cost is diameter^A.
    #[inline]
    pub fn cost(&self, diameter: f64, fill: f64, balance: f64) -> f64 {
        let scale = if self.a == 1.0 {
            diameter
        } else if self.a == 0.0 {
            1.0
        } else {
            diameter.powf(self.a)
        };
        self.cost_scaled(scale, fill, balance)
    }

    /// Checks that A, B and C are finite and ≥ 0; the error names the weight (`a`, `b`, `c`).
    pub fn check(&self) -> Result<(), String> {
        for (name, v) in [("a", self.a), ("b", self.b), ("c", self.c)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{name} must be a finite number ≥ 0, got {v}"));
            }
        }
        Ok(())
    }

    /// The cost given `scale` = diameter^A already computed.
    #[inline(always)]
    pub fn cost_scaled(&self, scale: f64, fill: f64, balance: f64) -> f64 {
        if self.b == 0.0 && self.c == 0.0 {
            scale
        } else {
            scale * (self.b * fill + self.c * balance)
        }
    }
}

/// How the grouping phase is scheduled over the scene.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum Schedule {
    /// The literal §2.2 run over all bodies at once (the default; what users debug step by step).
    #[default]
    Exact,
    /// The same grouping step run inside the chunks of a top-down Morton split, bottom-up
    /// (approximate agglomerative clustering), in parallel.
    Partitioned,
}

/// Which components are grouped on their own before the top level (the paper's §1.3 speed-up).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum Pregroup {
    /// No pre-grouping: the literal §2.2 run.
    #[default]
    None,
    /// The file's own `o`/`g` objects are the components.
    Objects,
    /// Primitives joined by shared (welded) vertices are the components.
    Connected,
}

/// The size measure in the Cost: the paper's diameter, or a surface-area alternative.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum CostMeasure {
    /// Cost = diameter^A × (B·Fill + C·Balance), eq. (2) of the paper.
    #[default]
    Diameter,
    /// The surface area of the merged box in place of the diameter (Walter et al. 2008).
    Area,
}

/// How a grouping run is organised beyond its Cost weights and limits. The default is the
/// literal §2.2 run; every other setting is recorded in recordings' metadata so that
/// `replay --verify` re-runs the same mode.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Mode {
    /// Exact or partitioned schedule.
    pub schedule: Schedule,
    /// Components grouped first, if any.
    pub pregroup: Pregroup,
    /// Whether rigid copies of a component reuse its Subset Tree shape.
    pub instancing: bool,
    /// The size measure in the Cost.
    pub cost: CostMeasure,
}

impl Mode {
    /// Checks that the settings fit together with the p-set `pset`: instancing needs
    /// pre-grouping (copies are found among components), and pre-grouping needs the AABB p-set.
    /// The errors name the CLI flags.
    pub fn check(&self, pset: PSet) -> Result<(), String> {
        if self.instancing && self.pregroup == Pregroup::None {
            return Err(
                "--instancing needs --pregroup objects or --pregroup connected (copies are \
                 found among components)"
                    .to_string(),
            );
        }
        if self.pregroup != Pregroup::None && pset != PSet::Aabb {
            return Err("--pregroup needs --pset aabb (parts are grouped as boxes)".to_string());
        }
        Ok(())
    }
}

/// User-facing parameters; `None` limits are derived from the scene by [`Params::resolve`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Params {
    /// Cost weights.
    pub weights: Weights,
    /// Initial DLimit (default: median primitive diameter).
    pub dlimit: Option<f64>,
    /// Initial GLimit (default: DLimit / 4).
    pub glimit: Option<f64>,
    /// P-set wrapper kind.
    pub pset: PSet,
    /// Seed for randomised tie-breaking (`None`: ties break by id).
    pub seed: Option<u64>,
    /// Schedule, pre-grouping, instancing and Cost measure.
    #[serde(default)]
    pub mode: Mode,
}

impl Default for Params {
    /// A = 1, B = 1, C = 0: cost = diameter × Fill. The calibration runs found Balance (C > 0)
    /// worsened SAH on every scene and could produce degenerate trees with small GLimit.
    fn default() -> Self {
        Params {
            weights: Weights {
                a: 1.0,
                b: 1.0,
                c: 0.0,
            },
            dlimit: None,
            glimit: None,
            pset: PSet::Aabb,
            seed: None,
            mode: Mode::default(),
        }
    }
}

/// Parameters with every limit fixed, as recorded in recordings' metadata.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ResolvedParams {
    /// Cost weights.
    pub weights: Weights,
    /// DLimit of the first round.
    pub dlimit0: f64,
    /// GLimit of the first round.
    pub glimit0: f64,
    /// P-set wrapper kind.
    pub pset: PSet,
    /// Seed for randomised ties, if any.
    pub seed: Option<u64>,
    /// Schedule, pre-grouping, instancing and Cost measure.
    #[serde(default)]
    pub mode: Mode,
}

impl ResolvedParams {
    /// Checks what the round loop relies on: valid weights and finite, positive initial limits
    /// (with GLimit0 = 0 a scene of several components would never finish). Parameters from
    /// [`Params::resolve`] always pass; ones read from a file may not.
    pub fn check(&self) -> Result<(), String> {
        self.weights.check()?;
        self.mode.check(self.pset)?;
        for (name, v) in [("dlimit0", self.dlimit0), ("glimit0", self.glimit0)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{name} must be a finite number > 0, got {v}"));
            }
        }
        Ok(())
    }
}

impl Params {
    /// Fixes the initial limits: DLimit0 = the median primitive diameter (AABB diagonal) and
    /// GLimit0 = DLimit0 / 4. When that median is 0 (point-like primitives) DLimit0 falls back
    /// to 1e-6 × the scene diagonal, and to 1 for a scene that is a single point. A given
    /// DLimit ≤ 0 (or not finite) becomes 1; a given GLimit ≤ 0 becomes 1e-9 × DLimit0, since
    /// the paper's GLimit must be positive for scenes of several connected components.
    pub fn resolve(&self, scene: &Scene) -> ResolvedParams {
        let dlimit0 = match self.dlimit {
            Some(d) => d,
            None => {
                let mut d: Vec<f64> = (0..scene.len())
                    .map(|i| scene.prim_aabb(i).diameter())
                    .collect();
                let median = if d.is_empty() {
                    0.0
                } else {
                    let mid = d.len() / 2;
                    *d.select_nth_unstable_by(mid, f64::total_cmp).1
                };
                if median > 0.0 {
                    median
                } else {
                    let diag = scene.aabb().diameter();
                    if diag.is_finite() && diag > 0.0 {
                        diag * 1e-6
                    } else {
                        1.0
                    }
                }
            }
        };
        let dlimit0 = if dlimit0.is_finite() && dlimit0 > 0.0 {
            dlimit0
        } else {
            1.0
        };
        // GLimit must be positive or disconnected scenes would never finish (doubling 0 stays 0).
        let glimit0 = match self.glimit {
            Some(g) if g.is_finite() && g > 0.0 => g,
            Some(_) => dlimit0 * 1e-9,
            None => dlimit0 / 4.0,
        };
        ResolvedParams {
            weights: self.weights,
            dlimit0,
            glimit0,
            pset: self.pset,
            seed: self.seed,
            mode: self.mode,
        }
    }
}

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

/// Limits on one run of the grouping phase; a run that exceeds one stops with [`Stopped`].
///
/// - `stop`: a flag (Ctrl-C/SIGTERM), checked before every merge.
/// - `deadline`: a wall-clock instant, checked every [`Budget::CLOCK_EVERY`] merges and during
///   the round-start scans (every [`Budget::CLOCK_EVERY`] bodies scanned).
/// - `max_pairs`: the most eligible pairs the round-start scans (step 3) may find, summed over
///   rounds: [`Stats::eligible_pairs`], counted as they are found, so a scan that would find
///   more stops partway. These are the pairs the paper's MPairs would queue at step 3, and what
///   grows quadratically when DLimit + GLimit spans too many bodies (all N active bodies
///   within GLimit of each other give N(N − 1)/2 pairs). Partner searches for new bodies during
///   a round (step 4b) are not counted: each reads at most the active bodies, and the deadline
///   bounds them. A run that needs exactly `max_pairs` pairs completes.
///
/// The default (no limit) costs one predictable branch per merge and per scanned body.
#[derive(Clone, Copy, Debug, Default)]
pub struct Budget<'a> {
    /// Stop as soon as this flag is set.
    pub stop: Option<&'a AtomicBool>,
    /// Stop once this instant has passed.
    pub deadline: Option<Instant>,
    /// Stop once the round-start scans have found more eligible pairs than this.
    pub max_pairs: Option<u64>,
}

impl Budget<'_> {
    /// How many merges (or scanned bodies) pass between two reads of the clock.
    pub const CLOCK_EVERY: u32 = 64;

    /// Whether no limit is set.
    pub fn is_unlimited(&self) -> bool {
        self.stop.is_none() && self.deadline.is_none() && self.max_pairs.is_none()
    }

    /// The limit among `stop` and `deadline` that is exceeded now, if any (`max_pairs` is
    /// checked by the scans, which count the pairs).
    pub fn exceeded_now(&self) -> Option<StopReason> {
        if self.stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            return Some(StopReason::Interrupted);
        }
        match self.deadline {
            Some(d) if Instant::now() >= d => Some(StopReason::MaxSeconds),
            _ => None,
        }
    }
}

/// Which limit of a [`Budget`] stopped a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// The stop flag was set (Ctrl-C or SIGTERM).
    Interrupted,
    /// The deadline passed (`--max-seconds`).
    MaxSeconds,
    /// The round-start scans found more eligible pairs than allowed (`--max-pairs`).
    MaxPairs,
}

impl StopReason {
    /// The name written to recordings' metadata: `interrupted`, `max-seconds`, `max-pairs`.
    pub fn name(self) -> &'static str {
        match self {
            StopReason::Interrupted => "interrupted",
            StopReason::MaxSeconds => "max-seconds",
            StopReason::MaxPairs => "max-pairs",
        }
    }

    /// The reason named `name` (as [`StopReason::name`] writes it).
    pub fn from_name(name: &str) -> Option<StopReason> {
        [
            StopReason::Interrupted,
            StopReason::MaxSeconds,
            StopReason::MaxPairs,
        ]
        .into_iter()
        .find(|r| r.name() == name)
    }
}

impl std::fmt::Display for StopReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Why and where a run stopped before the root.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stopped {
    /// The limit that stopped it.
    pub reason: StopReason,
    /// Merges completed before the stop (the observer has seen each of them).
    pub merges: u32,
    /// Rounds whose `RoundStart` the observer has seen (a round whose scan was cut short is
    /// not counted).
    pub rounds: u32,
    /// Eligible pairs found by the round-start scans so far, including a scan cut short.
    pub eligible_pairs: u64,
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
