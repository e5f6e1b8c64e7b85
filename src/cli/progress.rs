//! Progress on stderr for the long commands, and how they end on a stop request: bars and
//! spinners are hidden when stderr is not a terminal, so pipes and tests see no change.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::process::ExitCode;
use wraptree::stop::is_interrupted;

/// Exit code of a run stopped by Ctrl-C or SIGTERM (128 + SIGINT, as shells report it).
pub const EXIT_INTERRUPTED: u8 = 130;

/// A bar of `len` steps labelled `prefix`, with the current step as its message.
pub fn bar(len: u64, prefix: &str) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    if let Ok(style) =
        ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} {msg} {elapsed}")
    {
        bar.set_style(style);
    }
    bar.set_prefix(prefix.to_string());
    bar
}

/// A spinner labelled `prefix` for work without a known length.
pub fn spinner(prefix: &str) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new_spinner();
    if let Ok(style) = ProgressStyle::with_template("{spinner} {prefix} {msg} {elapsed}") {
        bar.set_style(style);
    }
    bar.set_prefix(prefix.to_string());
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}

/// A [`spinner`] cleared from the terminal when dropped, so that an early return with an error
/// leaves no progress line above it.
pub struct Status(ProgressBar);

impl Status {
    /// A spinner labelled `prefix` showing `message`.
    pub fn new(prefix: &str, message: &str) -> Status {
        let bar = spinner(prefix);
        bar.set_message(message.to_string());
        Status(bar)
    }
}

impl std::ops::Deref for Status {
    type Target = ProgressBar;

    fn deref(&self) -> &ProgressBar {
        &self.0
    }
}

impl Drop for Status {
    fn drop(&mut self) {
        self.0.finish_and_clear();
    }
}

/// The command's result, with a stop request turned into one line on stderr and exit code
/// [`EXIT_INTERRUPTED`]: commands stop before writing, so nothing was written.
pub fn or_stopped(command: &str, result: anyhow::Result<ExitCode>) -> anyhow::Result<ExitCode> {
    match result {
        Err(e) if is_interrupted(&e) => {
            eprintln!("{command}: stopped by Ctrl-C or SIGTERM; no output written");
            Ok(ExitCode::from(EXIT_INTERRUPTED))
        }
        r => r,
    }
}
