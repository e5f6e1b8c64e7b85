//! [`Limits`]: wall-time and pair-count limits on a grouping run, as plain values that turn into
//! a [`Budget`] when the run starts (the command line's `--max-seconds` and `--max-pairs`);
//! the [`Budget`] a run checks, and why it [`Stopped`].

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Limits on the grouping phase, for runs that could run away (huge GLimit, dense soups).
///
/// ```
/// use wraptree_core::grouping::Limits;
/// let limits = Limits { max_seconds: Some(2.5), max_pairs: None };
/// assert!(limits.check().is_ok());
/// assert!(Limits { max_seconds: Some(-1.0), ..limits }.check().is_err());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Limits {
    /// Stop after this many seconds of wall time from the start of the grouping.
    pub max_seconds: Option<f64>,
    /// Stop once the round-start scans (step 3) have found more eligible pairs than this,
    /// summed over rounds.
    pub max_pairs: Option<u64>,
}

impl Limits {
    /// Whether no limit is set.
    pub fn is_none(&self) -> bool {
        self.max_seconds.is_none() && self.max_pairs.is_none()
    }

    /// Checks the values: `max_seconds` must be a finite number > 0. The error names the
    /// command-line flag (`--max-seconds`).
    pub fn check(&self) -> Result<(), String> {
        match self.max_seconds {
            Some(s) if !(s.is_finite() && s > 0.0) => Err(format!(
                "--max-seconds must be a finite number > 0, got {s}"
            )),
            _ => Ok(()),
        }
    }

    /// The budget of a grouping starting now, with the stop flag `stop` if any.
    pub fn budget<'a>(&self, stop: Option<&'a AtomicBool>) -> Budget<'a> {
        Budget {
            stop,
            // Beyond ~10^10 s `checked_add` fails: no deadline, as good as none.
            deadline: self
                .max_seconds
                .and_then(|s| Instant::now().checked_add(Duration::from_secs_f64(s.min(1e10)))),
            max_pairs: self.max_pairs,
        }
    }

    /// One line saying what stopped a run of `n` primitives, e.g. `grouping stopped by
    /// --max-pairs 1000 after 12 of 275 merges (1043 eligible pairs found)`.
    pub fn message(&self, s: &Stopped, n: usize) -> String {
        let by = match s.reason {
            StopReason::Interrupted => "grouping interrupted".to_string(),
            StopReason::MaxSeconds => format!(
                "grouping stopped by --max-seconds {}",
                self.max_seconds.unwrap_or(f64::NAN)
            ),
            StopReason::MaxPairs => format!(
                "grouping stopped by --max-pairs {}",
                self.max_pairs.unwrap_or(0)
            ),
        };
        format!(
            "{by} after {} of {} merges ({} eligible pairs found)",
            s.merges,
            n.saturating_sub(1),
            s.eligible_pairs
        )
    }
}

/// Limits on one run of the grouping phase; a run that exceeds one stops with [`Stopped`].
///
/// - `stop`: a flag (Ctrl-C/SIGTERM), checked before every merge.
/// - `deadline`: a wall-clock instant, checked every [`Budget::CLOCK_EVERY`] merges and during
///   the round-start scans (every [`Budget::CLOCK_EVERY`] bodies scanned).
/// - `max_pairs`: the most eligible pairs the round-start scans (step 3) may find, summed over
///   rounds: [`Stats::eligible_pairs`](super::Stats::eligible_pairs), counted as they are
///   found, so a scan that would find more stops partway. These are the pairs the paper's
///   MPairs would queue at step 3, and what grows quadratically when DLimit + GLimit spans too
///   many bodies (all N active bodies within GLimit of each other give N(N − 1)/2 pairs).
///   Partner searches for new bodies during a round (step 4b) are not counted: each reads at
///   most the active bodies, and the deadline bounds them. A run that needs exactly
///   `max_pairs` pairs completes.
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
