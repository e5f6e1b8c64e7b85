//! A queue between a recorder's thread and a live stream's forwarding thread that never makes
//! the recorder wait: above its byte cap, droppable items are dropped (and counted) instead.

use std::collections::VecDeque;
use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

/// The queue's state behind its lock.
struct State<T> {
    items: VecDeque<(T, usize)>,
    bytes: usize,
    closed: bool,
    /// Items taken by the consumer so far: its progress.
    taken: u64,
    pushed: u64,
    dropped: u64,
}

/// A multi-producer, single-consumer queue bounded in bytes for droppable items.
pub(super) struct Lossy<T> {
    state: Mutex<State<T>>,
    ready: Condvar,
    cap: usize,
}

/// How many items went through a [`Lossy`] queue, and how many were dropped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Counts {
    /// Items offered to the queue.
    pub offered: u64,
    /// Items dropped because the queue was full.
    pub dropped: u64,
}

impl<T> Lossy<T> {
    /// An empty queue that holds at most `cap` bytes of droppable items.
    pub(super) fn new(cap: usize) -> Lossy<T> {
        Lossy {
            state: Mutex::new(State {
                items: VecDeque::new(),
                bytes: 0,
                closed: false,
                taken: 0,
                pushed: 0,
                dropped: 0,
            }),
            ready: Condvar::new(),
            cap,
        }
    }

    fn lock(&self) -> MutexGuard<'_, State<T>> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Queues `item` of about `bytes` bytes without waiting. A `droppable` item that would take
    /// the queue over its cap is dropped instead; other items (control messages, small and few)
    /// are always queued. Returns whether it was queued.
    pub(super) fn push(&self, item: T, bytes: usize, droppable: bool) -> bool {
        let mut s = self.lock();
        s.pushed += 1;
        if s.closed || (droppable && s.bytes + bytes > self.cap && !s.items.is_empty()) {
            s.dropped += 1;
            return false;
        }
        s.bytes += bytes;
        s.items.push_back((item, bytes));
        drop(s);
        self.ready.notify_one();
        true
    }

    /// The next item, waiting for one; `None` once the queue is closed and empty.
    pub(super) fn pop(&self) -> Option<T> {
        let mut s = self.lock();
        loop {
            if let Some((item, bytes)) = s.items.pop_front() {
                s.bytes -= bytes;
                s.taken += 1;
                return Some(item);
            }
            if s.closed {
                return None;
            }
            s = self.ready.wait(s).unwrap_or_else(PoisonError::into_inner);
        }
    }

    /// Ends the queue: the consumer gets what is queued, then `None`; later pushes are dropped.
    pub(super) fn close(&self) {
        self.lock().closed = true;
        self.ready.notify_all();
    }

    /// Items taken by the consumer so far, and items still queued.
    pub(super) fn progress(&self) -> (u64, usize) {
        let s = self.lock();
        (s.taken, s.items.len())
    }

    /// Items offered and dropped so far.
    pub(super) fn counts(&self) -> Counts {
        let s = self.lock();
        Counts {
            offered: s.pushed,
            dropped: s.dropped,
        }
    }
}

/// Waits for `done` while `progress` keeps changing. Err(None): `patience` went by without a
/// change; Err(Some(why)): `abort` gave a reason to stop waiting (it is asked every 100 ms).
pub(super) fn wait_while_progressing<R>(
    done: &std::sync::mpsc::Receiver<R>,
    mut progress: impl FnMut() -> u64,
    mut abort: impl FnMut() -> Option<String>,
    patience: Duration,
) -> Result<R, Option<String>> {
    let tick = Duration::from_millis(100).min(patience);
    let mut last = progress();
    let mut still = Duration::ZERO;
    loop {
        match done.recv_timeout(tick) {
            Ok(r) => return Ok(r),
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => return Err(None),
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                if let Some(why) = abort() {
                    return Err(Some(why));
                }
                let now = progress();
                if now == last {
                    still += tick;
                    if still >= patience {
                        return Err(None);
                    }
                } else {
                    (last, still) = (now, Duration::ZERO);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn droppable_items_over_the_cap_are_dropped_and_counted() {
        let q = Lossy::new(10);
        assert!(q.push(1, 6, true));
        assert!(!q.push(2, 6, true));
        assert!(q.push(3, 6, false), "control items are always queued");
        assert!(!q.push(4, 1, true));
        assert_eq!(
            q.counts(),
            Counts {
                offered: 4,
                dropped: 2
            }
        );
        q.close();
        assert_eq!(q.pop(), Some(1));
        assert_eq!(q.pop(), Some(3));
        assert_eq!(q.pop(), None);
        assert_eq!(q.progress(), (2, 0));
    }

    #[test]
    fn an_item_larger_than_the_cap_passes_an_empty_queue() {
        let q = Lossy::new(10);
        assert!(q.push(1, 100, true));
        assert!(!q.push(2, 1, true));
    }

    #[test]
    fn the_consumer_waits_for_items_and_sees_them_in_order() {
        let q = std::sync::Arc::new(Lossy::new(1 << 20));
        let c = q.clone();
        let h = std::thread::spawn(move || std::iter::from_fn(|| c.pop()).collect::<Vec<u32>>());
        for i in 0..1000 {
            q.push(i, 4, true);
        }
        q.close();
        assert_eq!(h.join().unwrap(), (0..1000).collect::<Vec<_>>());
    }
}
