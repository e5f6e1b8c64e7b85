//! Calling a third-party reader that may panic on malformed input: the panic is caught and
//! becomes `None`, and its message stays off stderr, so that bad input still gives one error
//! line.

use std::cell::Cell;
use std::panic::AssertUnwindSafe;
use std::sync::Once;

thread_local! {
    /// Whether this thread is inside [`caught`]: its panics print nothing.
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f`; `None` if it panicked. The first call wraps the process's panic hook once so that
/// it stays silent for panics inside `caught` on the calling thread and prints as before for
/// every other panic.
pub(crate) fn caught<R>(f: impl FnOnce() -> R) -> Option<R> {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                previous(info);
            }
        }));
    });
    let was = QUIET.with(|q| q.replace(true));
    let result = std::panic::catch_unwind(AssertUnwindSafe(f));
    QUIET.with(|q| q.set(was));
    result.ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_none_and_a_value_passes() {
        assert_eq!(caught(|| 7), Some(7));
        let v: Vec<u32> = Vec::new();
        assert_eq!(caught(|| v[3]), None);
        assert!(!QUIET.with(Cell::get));
    }
}
