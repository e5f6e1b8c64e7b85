//! How build times are compared (`wraptree bench`, `wraptree-bench`'s `method_timing`, and so the tables
//! of `docs/benchmarks.md`): in rounds, each building every method once, in the order given, so
//! that a slow spell of the machine falls on all of them alike; each method keeps its fastest
//! build, the best of the rounds. The rounds run in one piece on a thread of the current rayon
//! pool (`crate::par`), whoever calls.

use crate::grouping::Params;
use crate::peers::{self, Built, Method};
use crate::scene::Scene;
use crate::stop::{Interrupted, Stop};
use anyhow::{Result, anyhow};

/// The rounds `wraptree bench` runs by default: with fewer, its fast path / obvhs PLOC ratio
/// moved by more between runs on a busy machine (`docs/benchmarks.md`).
pub const ROUNDS: u32 = 9;

/// The fastest of `rounds` (at least one) builds of each of `methods`, in `methods`' order. Each
/// round calls `build` once per method, in `methods`' order; a build is kept when its
/// [`Built::seconds`] is below that method's fastest so far. `stop` is checked before each
/// build, and a build that fails once it is requested counts as stopped (Err: [`Interrupted`],
/// or why a build failed).
pub fn fastest_builds(
    methods: &[Method],
    rounds: u32,
    stop: &Stop,
    mut build: impl FnMut(Method) -> Result<Built, String> + Send,
) -> Result<Vec<Built>> {
    crate::par::on_pool(true, || {
        let mut fastest: Vec<Option<Built>> = vec![None; methods.len()];
        for _ in 0..rounds.max(1) {
            for (slot, &m) in fastest.iter_mut().zip(methods) {
                stop.check()?;
                let b = match build(m) {
                    // A build that obeyed the stop (`peers::build_until`).
                    Err(_) if stop.is_requested() => return Err(Interrupted.into()),
                    b => b.map_err(|e| anyhow!(e))?,
                };
                if slot.as_ref().is_none_or(|x| b.seconds < x.seconds) {
                    *slot = Some(b);
                }
            }
        }
        Ok(fastest
            .into_iter()
            .map(|b| b.expect("built in the first round"))
            .collect())
    })
}

/// [`fastest_builds`] of `methods` on `scene` with `params`, each built by
/// [`peers::build`].
pub fn fastest(
    methods: &[Method],
    scene: &Scene,
    params: &Params,
    rounds: u32,
    stop: &Stop,
) -> Result<Vec<Built>> {
    fastest_builds(methods, rounds, stop, |m| {
        peers::build_until(m, scene, params, stop)
    })
}
