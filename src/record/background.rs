//! An [`Observer`] that hands events to other threads, where the real observers see them in
//! the same order. Recording then overlaps with the grouping phase instead of adding to it:
//! the grouping thread only copies each event (a `Merge` is plain data; a round start's active
//! list is the one allocation) into a batch and sends each full batch, shared, down one
//! bounded channel per worker.

use crate::events::OwnedEvent as Owned;
use crate::grouping::{Event, Observer};
use std::sync::Arc;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};

/// Events per batch sent to the worker.
const BATCH: usize = 1024;
/// Batches in flight before the grouping thread waits for the worker.
const IN_FLIGHT: usize = 64;

/// The sending half: pass it to the grouping phase as its observer, then call
/// [`Background::close`] so the workers see the last batch.
pub struct Background {
    /// One sender per worker still listening.
    txs: Vec<SyncSender<Arc<Vec<Owned>>>>,
    batch: Vec<Owned>,
}

/// A receiving half: run [`Worker::run`] on another thread with a real observer.
pub struct Worker(Receiver<Arc<Vec<Owned>>>);

/// A connected sender and worker.
pub fn channel() -> (Background, Worker) {
    let (tx, mut workers) = fan_out(1);
    (tx, workers.remove(0))
}

/// A sender and `n` workers, each of which sees every event.
pub fn fan_out(n: usize) -> (Background, Vec<Worker>) {
    let (txs, workers) = (0..n)
        .map(|_| {
            let (tx, rx) = sync_channel(IN_FLIGHT);
            (tx, Worker(rx))
        })
        .unzip();
    (
        Background {
            txs,
            batch: Vec::with_capacity(BATCH),
        },
        workers,
    )
}

impl Background {
    fn send(&mut self) {
        if self.batch.is_empty() {
            return;
        }
        let full = Arc::new(std::mem::replace(
            &mut self.batch,
            Vec::with_capacity(BATCH),
        ));
        // A worker that has gone away (its observer failed to start or panicked) is reported
        // by its own thread.
        self.txs.retain(|tx| tx.send(Arc::clone(&full)).is_ok());
    }

    /// Sends what is buffered and ends the stream; the worker's `run` then returns.
    pub fn close(mut self) {
        self.send();
    }
}

impl Observer for Background {
    #[inline]
    fn on_event(&mut self, event: &Event<'_>) {
        self.batch.push(Owned::of(event));
        if self.batch.len() == BATCH {
            self.send();
        }
    }
}

impl Worker {
    /// Feeds every event to `observer`, in order, until the sender is closed or dropped.
    pub fn run<O: Observer>(self, observer: &mut O) {
        for batch in self.0 {
            for e in batch.iter() {
                observer.on_event(&e.event());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grouping::{EventLog, Params, group};
    use crate::scene::generate;

    #[test]
    fn the_worker_sees_the_same_events_in_order() {
        let scene = generate::lamp();
        let mut direct = EventLog::default();
        group(&scene, &Params::default(), &mut direct);
        let (tx, worker) = channel();
        let mut relayed = EventLog::default();
        std::thread::scope(|s| {
            let h = s.spawn(|| worker.run(&mut relayed));
            let mut tx = tx;
            group(&scene, &Params::default(), &mut tx);
            tx.close();
            h.join().unwrap();
        });
        assert_eq!(direct, relayed);
        assert!(direct.merges.len() == scene.len() - 1);
    }

    #[test]
    fn every_worker_of_a_fan_out_sees_every_event() {
        let scene = generate::lamp();
        let mut direct = EventLog::default();
        group(&scene, &Params::default(), &mut direct);
        let (mut tx, workers) = fan_out(3);
        let logs = std::thread::scope(|s| {
            let handles: Vec<_> = workers
                .into_iter()
                .map(|w| {
                    s.spawn(move || {
                        let mut log = EventLog::default();
                        w.run(&mut log);
                        log
                    })
                })
                .collect();
            group(&scene, &Params::default(), &mut tx);
            tx.close();
            handles
                .into_iter()
                .map(|h| h.join().unwrap())
                .collect::<Vec<_>>()
        });
        assert_eq!(logs.len(), 3);
        for log in logs {
            assert_eq!(log, direct);
        }
    }
}
