//! Recordings of a grouping run: `.rrd` for the Rerun viewer ([`rrd`]) and `.mcap` for Foxglove
//! ([`mcap`]). Both recorders are [`Observer`](crate::grouping::Observer)s fed the same events and
//! share nothing else; [`output`](crate::output) makes their files appear atomically, and
//! [`background`] lets a recorder consume the events on another thread while the grouping runs;
//! [`record()`] runs a grouping with both recorders listening, and [`Written`] says what it wrote;
//! [`live`] streams the same run to viewers while it happens.

pub mod background;
pub mod compare;
pub mod direct;
pub mod live;
pub mod mcap;
mod options;
pub mod rrd;
mod run;
pub mod spherize;
mod summary;

pub use run::{RecordOptions, Written, record};

/// The form of the recordings this build writes, in the `.mcap`'s `wraptree` metadata and the
/// `.rrd`'s `wraptree` property (`format_version`). Readers take this version and files without
/// one (older recordings, through one table of the settings they were made with:
/// [`mcap::metadata::current_form`]); a newer one is an error.
pub const FORMAT_VERSION: u32 = 1;

use crate::grouping::{Grouping, ResolvedParams, Stopped};
use crate::scene::{Scene, SceneSource};
use crate::wrap::cover::Cover;
use crate::wrap::cover::export::WrapperRecord;
use crate::wrap::{Sphere, Wrappers};

/// A round start with more active bodies than this draws none of their boxes, in both files
/// (`grouping/active` in the `.rrd`, `/grouping/active` in the `.mcap`; the count is in the
/// round's log line and on `/grouping/round`): tens of thousands of boxes overload a 3D view
/// and the file, and at that scale they only paint the scene over.
pub const ACTIVE_CAP: usize = 8192;

/// The per-merge boxes (the merged pair and the new body: `grouping/merge` in the `.rrd`,
/// `/grouping/bodies` in the `.mcap`) are written for the last this many merges of a run: the
/// merges of the top of the tree, large enough to be told apart at the scene's scale. Every
/// merge is still in the series, the log and `/grouping/merge` of the `.mcap`.
pub const BODIES_CAP: u32 = 4096;

/// Whether merge `step` of a run over `n` primitives is among the last [`BODIES_CAP`].
pub fn boxes_drawn(step: u32, n: usize) -> bool {
    step + BODIES_CAP >= n.saturating_sub(1) as u32
}

/// What a recording holds (`--detail`).
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Detail {
    /// Scene, merge events and series, round summaries and every tree level; no per-merge or
    /// per-round geometry.
    Levels,
    /// Scene, merge events, per-merge boxes (in the `.rrd` only) and each round's active bodies; no
    /// levels.
    Merges,
    /// Everything.
    #[default]
    Full,
}

impl Detail {
    /// Whether per-merge and per-round geometry is written.
    pub fn merges(self) -> bool {
        matches!(self, Detail::Merges | Detail::Full)
    }

    /// Whether tree levels are written.
    pub fn levels(self) -> bool {
        matches!(self, Detail::Levels | Detail::Full)
    }
}

/// What recorders know before the first event.
#[derive(Clone, Copy, Debug)]
pub struct RunInfo<'a> {
    /// The scene being grouped.
    pub scene: &'a Scene,
    /// Where it came from (embedded in `.mcap` for `replay --verify`).
    pub source: &'a SceneSource,
    /// Resolved parameters.
    pub params: &'a ResolvedParams,
    /// What to write.
    pub detail: Detail,
}

/// What recorders learn after the last event.
#[derive(Clone, Copy, Debug)]
pub struct Outcome<'a> {
    /// The finished grouping; `None` when the run was interrupted.
    pub grouping: Option<&'a Grouping>,
    /// Sphere Wrapper Tree (one per node) when levels are written; empty when levels are
    /// written without spheres.
    pub spheres: Option<&'a [Sphere]>,
    /// Further Wrapper Trees (hulls, boxes, oriented boxes) logged with the levels; its
    /// `spheres` are ignored (see `spheres`).
    pub wrappers: Option<&'a Wrappers>,
    /// A cover logged as one extra level after the last (`record --cover-tolerance` or
    /// `--cover-budget`); `None` when not requested.
    pub cover: Option<CoverLevel<'a>>,
    /// Merges made.
    pub merges: u32,
    /// Rounds started.
    pub rounds: u32,
    /// Grouping wall time in seconds.
    pub seconds: f64,
    /// Why the run stopped before the root (`grouping` is then `None`); `None` for a finished
    /// run, or an incomplete one whose reason is unknown.
    pub stopped: Option<Stopped>,
}

impl<'a> Outcome<'a> {
    /// The outcome of the finished `grouping`, with no Wrapper Trees, no cover and a grouping
    /// time of 0; set the other fields with struct-update syntax.
    pub fn finished(grouping: &'a Grouping) -> Outcome<'a> {
        Outcome {
            grouping: Some(grouping),
            spheres: None,
            wrappers: None,
            cover: None,
            merges: grouping.tree.leaves().saturating_sub(1) as u32,
            rounds: grouping.rounds,
            seconds: 0.0,
            stopped: None,
        }
    }
}

/// A cover of the finished tree (see [`crate::wrap::cover`]) with its wrappers' geometry, logged
/// as one extra level after the tree levels.
#[derive(Clone, Copy, Debug)]
pub struct CoverLevel<'a> {
    /// The chosen nodes, kinds and errors; `tolerance` is the absolute error bound used.
    pub cover: &'a Cover,
    /// One record per cover node, in the cover's order, with its geometry.
    pub wrappers: &'a [WrapperRecord],
    /// The wrapper budget K when the cover was asked for by budget rather than by tolerance.
    pub budget: Option<usize>,
}
