//! [`Stop`]: a request to end a long run at its next safe point (Ctrl-C, SIGTERM, or a test),
//! shared by every command; [`Interrupted`] is the error a run returns when it obeyed one.
//!
//! ```
//! use wraptree_core::stop::{Interrupted, Stop};
//! let stop = Stop::new();
//! assert!(stop.check().is_ok());
//! stop.request();
//! assert_eq!(stop.check(), Err(Interrupted));
//! ```

use std::sync::Arc;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};

/// Items a loop handles between two looks at its [`Stop`] ([`Stop::check_every`]).
pub const STRIDE: usize = 1024;

/// A shared stop request; clones see the same request.
#[derive(Clone, Debug, Default)]
pub struct Stop(Arc<AtomicBool>);

/// The error of a run that ended early because a [`Stop`] was requested.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Interrupted;

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("interrupted")
    }
}

impl std::error::Error for Interrupted {}

impl Stop {
    /// A token nobody has requested to stop yet.
    pub fn new() -> Stop {
        Stop::default()
    }

    /// The process's token, requested by the first Ctrl-C or SIGTERM (the handler is
    /// installed on the first call; every call returns the same token).
    pub fn on_signals() -> Stop {
        static PROCESS: OnceLock<Stop> = OnceLock::new();
        PROCESS
            .get_or_init(|| {
                let stop = Stop::new();
                let handler = stop.clone();
                // Fails only when another handler is installed; the run then cannot be stopped.
                let _ = ctrlc::set_handler(move || handler.request());
                stop
            })
            .clone()
    }

    /// Asks every holder to stop.
    pub fn request(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether a stop was requested.
    pub fn is_requested(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// `Err(Interrupted)` once a stop was requested: `stop.check()?` at a safe point.
    pub fn check(&self) -> Result<(), Interrupted> {
        if self.is_requested() {
            Err(Interrupted)
        } else {
            Ok(())
        }
    }

    /// [`Stop::check`] when `i` is a multiple of [`STRIDE`], else `Ok`: `stop.check_every(i)?`
    /// at the top of a loop over items `i` keeps the look cheap however small each item is.
    #[inline]
    pub fn check_every(&self, i: usize) -> Result<(), Interrupted> {
        if i.is_multiple_of(STRIDE) {
            self.check()
        } else {
            Ok(())
        }
    }

    /// The flag itself, for APIs that take one (the grouping's budget).
    pub fn flag(&self) -> &AtomicBool {
        &self.0
    }

    /// The shared flag, for APIs that keep one.
    pub fn shared(&self) -> Arc<AtomicBool> {
        Arc::clone(&self.0)
    }
}

impl From<Arc<AtomicBool>> for Stop {
    /// The token of a shared flag (an API that keeps the flag itself, e.g. a recording's).
    fn from(flag: Arc<AtomicBool>) -> Stop {
        Stop(flag)
    }
}

/// Whether `e` (or an error it wraps) is [`Interrupted`].
pub fn is_interrupted(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.downcast_ref::<Interrupted>().is_some())
}
