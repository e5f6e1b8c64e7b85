//! The A/B/C grid (`wraptree sweep`): the grouping phase once per weight setting of
//! `Cost = diameter^A × (B·Fill + C·Balance)`, measured the same way as `bench`.
//!
//! Note for reading the grid: multiplying B and C by the same factor multiplies every Cost by it
//! and leaves the merge order unchanged, so along a ray B:C = const the trees are identical; the
//! grid still lists what was asked for.

use super::{Quality, quality};
use crate::grouping::{self, EventLog, Merge, Params, Weights};
use crate::query::{self, Bv, QueryCost, Workload};
use crate::scene::Scene;
use std::time::Instant;

/// One weight setting's results.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SweepRow {
    /// The weights.
    pub weights: Weights,
    /// Grouping seconds with no observer (best of the repetitions).
    pub build_s: f64,
    /// Rounds (DLimit values) used.
    pub rounds: u32,
    /// Quality of the Subset Tree.
    pub quality: Quality,
    /// Query cost of the standard workload with the tree's AABBs.
    pub query: QueryCost,
}

/// Every combination of `a × b × c`, in that nesting order (C fastest).
pub fn grid(a: &[f64], b: &[f64], c: &[f64]) -> Vec<Weights> {
    let mut out = Vec::with_capacity(a.len() * b.len() * c.len());
    for &a in a {
        for &b in b {
            for &c in c {
                out.push(Weights { a, b, c });
            }
        }
    }
    out
}

/// Runs the grouping phase for every setting of `settings` (each checked first) with the other
/// parameters of `base`; `each` receives every setting's merges (for recordings).
pub fn sweep(
    scene: &Scene,
    settings: &[Weights],
    base: &Params,
    repeat: u32,
    seed: u64,
    mut each: impl FnMut(usize, &Weights, &[Merge]) -> anyhow::Result<()>,
) -> anyhow::Result<Vec<SweepRow>> {
    for w in settings {
        w.check().map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    let workload = Workload::standard(scene, seed);
    let mut rows = Vec::with_capacity(settings.len());
    for (k, &weights) in settings.iter().enumerate() {
        let params = Params {
            weights,
            ..base.clone()
        };
        let mut build_s = f64::INFINITY;
        for _ in 0..repeat.max(1) {
            let t = Instant::now();
            std::hint::black_box(grouping::group(scene, &params, ()));
            build_s = build_s.min(t.elapsed().as_secs_f64());
        }
        let mut log = EventLog::default();
        let g = grouping::group(scene, &params, &mut log);
        each(k, &weights, &log.merges)?;
        rows.push(SweepRow {
            weights,
            build_s,
            rounds: g.rounds,
            quality: quality(&g.tree),
            query: query::measure(&g.tree, scene, Bv::Aabb, &workload),
        });
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_nests_c_fastest() {
        let g = grid(&[0.0, 1.0], &[1.0], &[0.0, 2.0]);
        let abc: Vec<_> = g.iter().map(|w| (w.a, w.b, w.c)).collect();
        assert_eq!(
            abc,
            vec![
                (0.0, 1.0, 0.0),
                (0.0, 1.0, 2.0),
                (1.0, 1.0, 0.0),
                (1.0, 1.0, 2.0)
            ]
        );
    }
}
