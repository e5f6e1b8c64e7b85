//! The backstop of a stop request: every long loop checks the [`Stop`] token, but a step that
//! cannot (inside a dependency, or a single geometric computation) may still run long. Once a
//! stop is requested, the process gets [`GRACE`] to end on its own; then its unfinished outputs
//! are taken away ([`discard_unfinished`]) and it exits with [`EXIT_INTERRUPTED`], saying on
//! stderr that it was cut short (the mark tests look for: a run they stop must end by itself).
//! [`GRACE_ENV`] sets another grace, for tests on a loaded machine.

use super::progress::EXIT_INTERRUPTED;
use std::time::Duration;
use wraptree::output::discard_unfinished;
use wraptree::stop::Stop;

/// How long a stopped run may take to end on its own: well within the second a stop promises.
pub const GRACE: Duration = Duration::from_millis(600);

/// The environment variable that sets the grace in milliseconds instead of [`GRACE`].
pub const GRACE_ENV: &str = "WRAPTREE_STOP_GRACE_MS";

/// The grace: [`GRACE_ENV`]'s when it is a number of milliseconds, else [`GRACE`].
fn grace() -> Duration {
    std::env::var(GRACE_ENV)
        .ok()
        .and_then(|ms| ms.parse().ok())
        .map_or(GRACE, Duration::from_millis)
}

/// How often the watcher looks at the token.
const POLL: Duration = Duration::from_millis(20);

/// Starts the watcher of `stop` on a thread of its own.
pub fn arm(stop: Stop) {
    let watcher = std::thread::Builder::new().name("stop-deadline".into());
    // Fails only when no thread can be made; a stop is then obeyed by the loops alone.
    let grace = grace();
    let _ = watcher.spawn(move || {
        while !stop.is_requested() {
            std::thread::sleep(POLL);
        }
        std::thread::sleep(grace);
        discard_unfinished();
        eprintln!(
            "stopped by Ctrl-C or SIGTERM; the step in progress did not end within {} ms, so it \
             was cut short; no output written",
            grace.as_millis()
        );
        std::process::exit(i32::from(EXIT_INTERRUPTED));
    });
}
