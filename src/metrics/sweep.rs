//! The A/B/C grid (`wraptree sweep`): the grouping phase once per weight setting of
//! `Cost = size^A × (B·Fill + C·Balance)` and per size measure (the paper's diameter, or the
//! surface area with `--cost area`, see [`CostMeasure`]), measured the same way as `bench`.
//!
//! Note for reading the grid: multiplying B and C by the same factor multiplies every Cost by it
//! and leaves the merge order unchanged, so along a ray B:C = const the trees are identical; the
//! grid still lists what was asked for.

use super::{Quality, quality};
use crate::grouping::{self, CostMeasure, EventLog, Merge, Mode, Params, Weights};
use crate::query::{self, Bv, QueryCost, Workload};
use crate::scene::Scene;
use std::time::Instant;

/// One point of the grid: Cost weights and size measure.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Setting {
    /// The weights A, B, C.
    pub weights: Weights,
    /// The size measure in the Cost.
    pub cost: CostMeasure,
}

/// One setting's results.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SweepRow {
    /// The weights.
    pub weights: Weights,
    /// The size measure in the Cost.
    pub cost: CostMeasure,
    /// Grouping seconds with no observer (best of the repetitions).
    pub build_s: f64,
    /// Rounds (DLimit values) used.
    pub rounds: u32,
    /// Quality of the Subset Tree.
    pub quality: Quality,
    /// Query cost of the standard workload with the tree's AABBs.
    pub query: QueryCost,
}

/// Every combination of `measures × a × b × c`, in that nesting order (C fastest).
pub fn grid(a: &[f64], b: &[f64], c: &[f64], measures: &[CostMeasure]) -> Vec<Setting> {
    let mut out = Vec::with_capacity(measures.len() * a.len() * b.len() * c.len());
    for &cost in measures {
        for &a in a {
            for &b in b {
                for &c in c {
                    out.push(Setting {
                        weights: Weights { a, b, c },
                        cost,
                    });
                }
            }
        }
    }
    out
}

/// Runs the grouping phase for every setting of `settings` (each checked first) with the other
/// parameters of `base`; `each` receives every setting's merges (for recordings).
pub fn sweep(
    scene: &Scene,
    settings: &[Setting],
    base: &Params,
    repeat: u32,
    seed: u64,
    mut each: impl FnMut(usize, &Setting, &[Merge]) -> anyhow::Result<()>,
) -> anyhow::Result<Vec<SweepRow>> {
    for s in settings {
        s.weights.check().map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    let workload = Workload::standard(scene, seed);
    let mut rows = Vec::with_capacity(settings.len());
    for (k, setting) in settings.iter().enumerate() {
        let params = Params {
            weights: setting.weights,
            mode: Mode {
                cost: setting.cost,
                ..base.mode
            },
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
        each(k, setting, &log.merges)?;
        rows.push(SweepRow {
            weights: setting.weights,
            cost: setting.cost,
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
        let g = grid(&[0.0, 1.0], &[1.0], &[0.0, 2.0], &[CostMeasure::Diameter]);
        let abc: Vec<_> = g
            .iter()
            .map(|s| (s.weights.a, s.weights.b, s.weights.c))
            .collect();
        assert_eq!(
            abc,
            vec![
                (0.0, 1.0, 0.0),
                (0.0, 1.0, 2.0),
                (1.0, 1.0, 0.0),
                (1.0, 1.0, 2.0)
            ]
        );
        let both = grid(
            &[1.0],
            &[1.0],
            &[0.0],
            &[CostMeasure::Diameter, CostMeasure::Area],
        );
        assert_eq!(both.len(), 2);
        assert_eq!(both[1].cost, CostMeasure::Area);
    }
}
