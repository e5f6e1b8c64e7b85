//! Parallel work started from a thread outside the rayon pool.
//!
//! Called from such a thread (a program's main thread, for one), each parallel step of a build
//! (a `join`, a parallel iterator that splits) is handed to the pool, and the caller sleeps
//! until a worker has woken and finished it; the step's results are then in that worker's
//! cache, not the caller's: a hand-over and a cold cache per step, a large share of a small
//! build's time. So the builds run their parallel parts, in
//! one piece, on one of the pool's threads ([`on_pool`]), where those steps are plain calls.

/// Fewest primitives for which a build is handed to the pool: below this the hand over alone
/// would cost more than it saves, and the build runs on the caller's thread, which takes no
/// parallel step when outside the pool ([`parallel_here`]).
pub const POOL_MIN: usize = 1024;

/// Whether parallel steps are worth taking here: on a thread of a pool of several threads. A
/// thread outside the pool would hand each step over (see the module doc), and on a pool of one
/// a `join` only costs.
pub fn parallel_here() -> bool {
    rayon::current_thread_index().is_some() && rayon::current_num_threads() > 1
}

/// A recursion's parallel grain here: `grain` where parallel steps are worth taking
/// ([`parallel_here`]), else none (`u32::MAX`: no range is that large).
pub fn grain(grain: u32) -> u32 {
    if parallel_here() { grain } else { u32::MAX }
}

/// Runs `f` on a thread of the current rayon pool (the global pool when the caller is in none)
/// and returns what it returns; runs it on the caller's thread when that is one of the pool's
/// already, or when `worth` is false. `f` must not wait for other threads that may need the
/// pool (a recorder's channel, say): on a one-thread pool they would wait for it in turn.
pub fn on_pool<R: Send>(worth: bool, f: impl FnOnce() -> R + Send) -> R {
    if !worth || rayon::current_thread_index().is_some() {
        f()
    } else {
        rayon::scope(|_| f())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_work_runs_on_a_pool_thread_only_when_worth_it_and_outside_one() {
        let outside = std::thread::spawn(|| {
            (
                on_pool(true, rayon::current_thread_index),
                on_pool(false, rayon::current_thread_index),
            )
        })
        .join()
        .unwrap();
        assert!(outside.0.is_some(), "handed to the pool");
        assert_eq!(outside.1, None, "kept on the caller's thread");
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let inside = pool.install(|| {
            let me = rayon::current_thread_index();
            (me, on_pool(true, rayon::current_thread_index))
        });
        assert_eq!(inside.0, inside.1, "already on a pool thread: run in place");
    }

    #[test]
    fn parallel_steps_are_taken_only_on_a_thread_of_a_pool_of_several() {
        let outside = std::thread::spawn(parallel_here).join().unwrap();
        assert!(!outside, "outside the pool");
        let pool = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
        };
        assert!(!pool(1).install(parallel_here), "a pool of one");
        assert!(pool(2).install(parallel_here), "a pool of two");
        assert_eq!(pool(1).install(|| grain(256)), u32::MAX);
        assert_eq!(pool(2).install(|| grain(256)), 256);
    }
}
