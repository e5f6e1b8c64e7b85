//! The A/B/C grid (`wraptree sweep`): the grouping phase once per weight setting of
//! `Cost = size^A × (B·Fill + C·Balance)` and per size measure (the paper's diameter, or the
//! surface area with `--cost area`, see [`CostMeasure`]), measured the same way as `bench`.
//!
//! Note for reading the grid: multiplying B and C by the same factor multiplies every Cost by it
//! and leaves the merge order unchanged, so along a ray B:C = const the trees are identical; the
//! grid still lists what was asked for.

use super::{Quality, quality};
use crate::geom::Aabb;
use crate::grouping::{
    self, CostMeasure, EventLog, Limits, Merge, Mode, Params, StopReason, SubsetTree, Weights,
};
use crate::query::{self, Bv, QueryCost, Workload};
use crate::record::compare::{CompareRun, write_comparison};
use crate::scene::Scene;
use crate::stop::{Interrupted, Stop};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Settings shown side by side in the sweep's comparison recording, at most.
pub const COMPARED: usize = 6;

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

/// What [`sweep`] measured: a row per finished setting, in grid order, and the settings left
/// out because a grouping run exceeded the limits, each with why.
#[derive(Clone, Debug)]
pub struct Swept {
    /// The finished settings.
    pub rows: Vec<SweepRow>,
    /// The settings left out, with one line saying what stopped them.
    pub left_out: Vec<(Setting, String)>,
}

/// How [`sweep`] runs each setting: timed repetitions, workload seed, and the limits of each
/// grouping run.
#[derive(Clone, Copy, Debug, Default)]
pub struct SweepRuns {
    /// Timed repetitions per setting (at least one).
    pub repeat: u32,
    /// Seed of the query workload.
    pub seed: u64,
    /// Limits of each grouping run; a setting whose run exceeds them is left out.
    pub limits: Limits,
}

/// Runs the grouping phase for every setting of `settings` (each checked first) with the other
/// parameters of `base`; `each` receives every finished setting's merges (for recordings).
/// Each setting is timed up to `runs.repeat` times, repeated only while its runs took under
/// [`REPEAT_BUDGET_S`](super::compare::REPEAT_BUDGET_S) in all; a setting whose grouping
/// exceeds `runs.limits` is left out ([`Swept::left_out`]). `stop` is checked between merges
/// and queries (Err: [`Interrupted`]).
pub fn sweep(
    scene: &Scene,
    settings: &[Setting],
    base: &Params,
    runs: &SweepRuns,
    stop: &Stop,
    mut each: impl FnMut(usize, &Setting, &[Merge]) -> anyhow::Result<()>,
) -> anyhow::Result<Swept> {
    for s in settings {
        s.weights.check().map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    let workload = Workload::standard(scene, runs.seed);
    let mut swept = Swept {
        rows: Vec::with_capacity(settings.len()),
        left_out: Vec::new(),
    };
    for (k, setting) in settings.iter().enumerate() {
        let params = Params {
            weights: setting.weights,
            mode: Mode {
                cost: setting.cost,
                ..base.mode
            },
            ..base.clone()
        }
        .resolve(scene);
        let group = |log: Option<&mut EventLog>| {
            let budget = runs.limits.budget(Some(stop.flag()));
            grouping::group_within(scene, &params, log, &budget)
        };
        let (mut build_s, mut spent) = (f64::INFINITY, 0.0);
        let mut run = Ok(());
        for r in 0..runs.repeat.max(1) {
            if r > 0 && spent >= super::compare::REPEAT_BUDGET_S {
                break;
            }
            let t = Instant::now();
            match group(None) {
                Ok(g) => {
                    std::hint::black_box(g);
                }
                Err(e) => {
                    run = Err(e);
                    break;
                }
            }
            let s = t.elapsed().as_secs_f64();
            (spent, build_s) = (spent + s, build_s.min(s));
        }
        let mut log = EventLog::default();
        let g = run.and_then(|()| group(Some(&mut log)));
        let g = match g {
            Ok(g) => g,
            Err(s) if s.reason == StopReason::Interrupted => return Err(Interrupted.into()),
            Err(s) => {
                let why = runs.limits.message(&s, scene.len());
                swept.left_out.push((*setting, why));
                continue;
            }
        };
        each(k, setting, &log.merges)?;
        swept.rows.push(SweepRow {
            weights: setting.weights,
            cost: setting.cost,
            build_s,
            rounds: g.rounds,
            quality: quality(&g.tree),
            query: query::measure_until(&g.tree, scene, Bv::Aabb, &workload, stop)?,
        });
    }
    Ok(swept)
}

/// Which settings the comparison shows: one per distinct merge sequence (the first setting that
/// gives it), the [`COMPARED`] lowest SAH first; indices into `rows` and `merges`.
pub fn compared(rows: &[SweepRow], merges: &[Vec<Merge>]) -> Vec<usize> {
    let mut distinct: Vec<usize> = Vec::new();
    for k in 0..rows.len().min(merges.len()) {
        if !distinct.iter().any(|&j| same_pairs(&merges[j], &merges[k])) {
            distinct.push(k);
        }
    }
    distinct.sort_by(|&x, &y| {
        rows[x]
            .quality
            .sah
            .total_cmp(&rows[y].quality.sah)
            .then(x.cmp(&y))
    });
    distinct.truncate(COMPARED);
    distinct
}

fn same_pairs(a: &[Merge], b: &[Merge]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x.a, x.b) == (y.a, y.b))
}

/// Writes `PREFIX.rrd` and `PREFIX.mcap`: the [`compared`] settings' runs side by side, the
/// lowest SAH first as the reference ([`write_comparison`]); `names` label the settings.
/// Replaces existing files only with `force`. `None` when fewer than two settings differ;
/// [`Interrupted`] when `stop` is requested before both files are complete.
pub fn write_sweep_comparison(
    prefix: &Path,
    scene: &Scene,
    rows: &[SweepRow],
    merges: &[Vec<Merge>],
    names: &[String],
    force: bool,
    stop: &Stop,
) -> anyhow::Result<Option<[PathBuf; 2]>> {
    let shown = compared(rows, merges);
    if shown.len() < 2 {
        return Ok(None);
    }
    let leaves: Vec<Aabb> = (0..scene.len()).map(|i| scene.prim_aabb(i)).collect();
    let diameters: Vec<f64> = leaves.iter().map(Aabb::diameter).collect();
    let trees = shown
        .iter()
        .map(|&k| {
            let m: Vec<_> = merges[k]
                .iter()
                .map(|m| (m.a, m.b, m.aabb, m.diameter))
                .collect();
            SubsetTree::from_merges(leaves.clone(), diameters.clone(), &m)
                .map_err(anyhow::Error::msg)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let runs: Vec<CompareRun<'_>> = shown
        .iter()
        .zip(&trees)
        .map(|(&k, t)| CompareRun {
            label: format!("{} (SAH {:.4})", names[k], rows[k].quality.sah),
            merges: &merges[k],
            tree: Some(t),
        })
        .collect();
    write_comparison(prefix, scene, &scene.name, &runs, force, stop).map(Some)
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
