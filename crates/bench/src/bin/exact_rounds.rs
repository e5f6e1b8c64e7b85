//! Where the exact schedule's time goes, round by round: each round's start (the voxel scans of
//! step 3, timed up to its `RoundStart` event, the first round's with the run's set-up) and its
//! merges (step 4, up to its `Doubling` or the run's `Finish`),
//! with the round's active bodies, eligible pairs and merges; one thread, one run per file
//! (`docs/benchmarks.md`, "What does the exact run cost?").
//!
//! `cargo run --release -p wraptree-bench --bin exact_rounds -- FILE...`

use std::time::Instant;
use wraptree::grouping::{Event, Observer, Params, group};

/// One round's counts and times (ms).
#[derive(Default)]
struct Round {
    active: usize,
    pairs: u64,
    merges: u32,
    scan_ms: f64,
    merge_ms: f64,
}

/// Times the rounds from the events.
struct Rounds {
    start: Instant,
    /// When the last round ended (or the run started).
    mark: f64,
    rounds: Vec<Round>,
}

impl Rounds {
    fn now(&self) -> f64 {
        self.start.elapsed().as_secs_f64() * 1e3
    }
}

impl Observer for Rounds {
    fn on_event(&mut self, e: &Event<'_>) {
        match e {
            Event::RoundStart { active, pairs, .. } => {
                let t = self.now();
                self.rounds.push(Round {
                    active: active.len(),
                    pairs: *pairs,
                    scan_ms: t - self.mark,
                    ..Round::default()
                });
                self.mark = t;
            }
            Event::Merge(_) => {
                if let Some(r) = self.rounds.last_mut() {
                    r.merges += 1;
                }
            }
            Event::Doubling { .. } | Event::Finish { .. } => {
                let t = self.now();
                if let Some(r) = self.rounds.last_mut() {
                    r.merge_ms = t - self.mark;
                }
                self.mark = t;
            }
            _ => {}
        }
    }
}

fn main() -> anyhow::Result<()> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    for path in std::env::args().skip(1) {
        let scene = wraptree::scene::load_path(path.as_ref(), &Default::default())?.scene;
        let mut r = Rounds {
            start: Instant::now(),
            mark: 0.0,
            rounds: Vec::new(),
        };
        pool.install(|| group(&scene, &Params::default(), &mut r));
        // Up to the `Finish` event: the shares below add up to the whole run.
        let total = r.mark;
        let n = scene.len() as f64;
        println!("{} ({} primitives): {total:.1} ms", scene.name, scene.len());
        println!(
            "| round | active | eligible pairs | merges | start ms | merges ms | share of the time |"
        );
        println!("|---|---|---|---|---|---|---|");
        for (k, x) in r.rounds.iter().enumerate() {
            println!(
                "| {k} | {} | {} | {} ({:.1} %) | {:.2} | {:.2} | {:.1} % |",
                x.active,
                x.pairs,
                x.merges,
                100.0 * f64::from(x.merges) / n,
                x.scan_ms,
                x.merge_ms,
                100.0 * (x.scan_ms + x.merge_ms) / total
            );
        }
        println!();
    }
    Ok(())
}
