//! The typed events of a run, the grouping phase's steps (§2.2) and the refinement's, and the
//! one observer interface recorders subscribe to.
//!
//! The algorithms call [`Observer::on_event`] at each step; they know nothing about Rerun or
//! MCAP. The unit observer `()` ignores everything and is inlined away, so a run without a
//! listener costs nothing. This module sits below both producers (`grouping` and
//! `refine`), which re-export what their callers need.

mod grouping;
mod log;
mod observer;
mod refine;

pub use grouping::{Merge, Part, PartKind};
pub use log::{EventLog, OwnedEvent};
pub use observer::{Observer, Tee};
pub use refine::{MAX_TREELET_LEAVES, RefineParams, Step, StepKind};

use crate::geom::Aabb;

/// A step of the grouping phase.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event<'a> {
    /// A part of the run starts (partitioned schedule, pre-grouping, instancing); the plain
    /// §2.2 run emits none.
    Part(Part),
    /// Step 2–3: a round starts with these limits and sets.
    RoundStart {
        /// Round index (0 for the first).
        round: u32,
        /// DLimit of this round.
        dlimit: f64,
        /// GLimit of this round.
        glimit: f64,
        /// Active bodies (parent-less, diameter ≤ DLimit), sorted by id.
        active: &'a [u32],
        /// Number of dormant bodies.
        dormant: u32,
        /// Eligible pairs found by the voxel scan (the literal MPairs length).
        pairs: u64,
    },
    /// Step 4(a): a pair was popped and merged.
    Merge(Merge),
    /// Step 4(c): a new body exceeds DLimit and goes dormant until a later round.
    Dormant {
        /// Round index.
        round: u32,
        /// The body.
        body: u32,
        /// Its diameter.
        diameter: f64,
    },
    /// Step 5: MPairs is empty; DLimit and GLimit double.
    Doubling {
        /// Round that just ended.
        round: u32,
        /// Merges made in that round.
        merges: u32,
        /// New DLimit.
        dlimit: f64,
        /// New GLimit.
        glimit: f64,
    },
    /// A refinement run of the finished tree starts (`record --refine`); comes after
    /// `Finish`.
    RefineStart {
        /// Its parameters.
        params: RefineParams,
        /// SAH of the tree before refinement.
        sah: f64,
    },
    /// The refinement kept one step (a rebuilt treelet or a move, [`StepKind`]); one per
    /// kept step, after `RefineStart`.
    Refine(Step),
    /// The root exists; grouping is over.
    Finish {
        /// Root body id.
        root: u32,
        /// Number of rounds run.
        rounds: u32,
        /// Number of merges (N − 1).
        merges: u32,
    },
}

/// Serialises a box as `[min x, min y, min z, max x, max y, max z]`.
fn ser_aabb<S: serde::Serializer>(b: &Aabb, s: S) -> Result<S::Ok, S::Error> {
    use serde::Serialize;
    [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z].serialize(s)
}
