//! [`Limits`]: wall-time and pair-count limits on a grouping run, as plain values that turn into
//! a [`Budget`] when the run starts (the command line's `--max-seconds` and `--max-pairs`).

use super::{Budget, StopReason, Stopped};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// Limits on the grouping phase, for runs that could run away (huge GLimit, dense soups).
///
/// ```
/// use wraptree::grouping::Limits;
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
