//! Comparisons: several runs of one scene in one `.rrd` and one `.mcap`, side by side, so that
//! two weightings can be told apart at a glance (what `replay --a/--b/--c`, `compare` and `sweep`
//! write). The first run is the reference; each other run's first divergence from it is the
//! first merge where it merges another pair. The `.rrd` is laid out with the runs' 3D views side
//! by side ([`rrd::write_comparison_rrd`](crate::record::rrd::write_comparison_rrd)); the `.mcap`
//! holds the same runs under `/runs/<i>/…` for Foxglove with `recordings/foxglove-compare-layout.json`
//! ([`mcap::write_comparison_mcap`](crate::record::mcap::write_comparison_mcap)).

use std::path::{Path, PathBuf};

use crate::grouping::{Merge, SubsetTree, sah};
use crate::output::{Pending, with_ext};
use crate::scene::Scene;
use crate::stop::Stop;

/// One run of a comparison.
pub struct CompareRun<'a> {
    /// How the run is named in the views, plots and log (e.g. `A1 B1 C0`).
    pub label: String,
    /// Its merges, in order.
    pub merges: &'a [Merge],
    /// Its Subset Tree, when the run finished.
    pub tree: Option<&'a SubsetTree>,
}

/// Index of the first merge where `a` and `b` merge a different pair (their Costs differ
/// whenever their weights do, so only the bodies count), if any.
pub fn divergence(a: &[Merge], b: &[Merge]) -> Option<usize> {
    let same = |x: &Merge, y: &Merge| x.a == y.a && x.b == y.b && x.new == y.new;
    (0..a.len().max(b.len())).find(|&i| match (a.get(i), b.get(i)) {
        (Some(x), Some(y)) => !same(x, y),
        _ => true,
    })
}

/// The earliest merge where a run diverges from the first run, if any.
pub fn earliest_divergence(runs: &[CompareRun<'_>]) -> Option<usize> {
    let reference = runs.first()?.merges;
    runs.iter()
        .filter_map(|r| divergence(reference, r.merges))
        .min()
}

/// One line of a comparison's log.
#[derive(Clone, Debug, PartialEq)]
pub struct LogLine {
    /// The merge tick it belongs to.
    pub merge: usize,
    /// Whether it is a warning (the divergence).
    pub warn: bool,
    /// Its text.
    pub text: String,
}

/// The log of a comparison, in tick order: each run (tick 0), each run's first divergence from
/// the first run (at its merge), each run's finish (SAH and depth) at its last merge.
pub fn log_lines(runs: &[CompareRun<'_>]) -> Vec<LogLine> {
    let line = |merge: usize, warn: bool, text: String| LogLine { merge, warn, text };
    let mut lines: Vec<LogLine> = runs
        .iter()
        .enumerate()
        .map(|(i, r)| {
            line(
                0,
                false,
                format!("run {i}: {}, {} merges", r.label, r.merges.len()),
            )
        })
        .collect();
    let pair = |m: Option<&Merge>| {
        m.map_or("no merge".into(), |m| {
            format!("bodies {} + {} (Cost {:.6e})", m.a, m.b, m.cost)
        })
    };
    let first = &runs[..runs.len().min(1)];
    for (i, r) in runs.iter().enumerate().skip(1) {
        let reference = first[0].merges;
        lines.push(match divergence(reference, r.merges) {
            Some(k) => line(
                k,
                true,
                format!(
                    "first divergence at merge {k}: run 0 ({}) merges {}, run {i} ({}) merges {}",
                    first[0].label,
                    pair(reference.get(k)),
                    r.label,
                    pair(r.merges.get(k)),
                ),
            ),
            None => line(
                0,
                false,
                format!("run {i} ({}) makes the same merges as run 0", r.label),
            ),
        });
    }
    for (i, r) in runs.iter().enumerate() {
        let text = match r.tree {
            Some(t) => format!(
                "run {i} ({}) finished: SAH {:.4}, depth {}",
                r.label,
                sah(t),
                t.depth_max()
            ),
            None => format!(
                "run {i} ({}) stopped after {} merges",
                r.label,
                r.merges.len()
            ),
        };
        lines.push(line(r.merges.len().saturating_sub(1), false, text));
    }
    lines.sort_by_key(|l| l.merge);
    lines
}

/// Writes `PREFIX.rrd` and `PREFIX.mcap`, the comparison of `runs` (at least two) over `scene`
/// (named `scene_name`). Each file appears whole or not at all; existing files are replaced
/// only with `force`. Returns both paths. When `stop` is requested before both are complete,
/// neither is moved into place and the error is [`Interrupted`](crate::stop::Interrupted).
pub fn write_comparison(
    prefix: &Path,
    scene: &Scene,
    scene_name: &str,
    runs: &[CompareRun<'_>],
    force: bool,
    stop: &Stop,
) -> anyhow::Result<[PathBuf; 2]> {
    let (rrd, mcap) = (with_ext(prefix, ".rrd"), with_ext(prefix, ".mcap"));
    let rrd_file = Pending::create(&rrd, force)?;
    let mcap_file = Pending::create(&mcap, force)?;
    stop.check()?;
    super::rrd::write_comparison_rrd(rrd_file.path(), &rrd, scene, scene_name, runs)?;
    stop.check()?;
    super::mcap::write_comparison_mcap(&mcap_file, scene, scene_name, runs)?;
    stop.check()?;
    Ok([rrd_file.commit()?, mcap_file.commit()?])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Aabb, P3};

    fn merge(step: u32, a: u32, b: u32) -> Merge {
        Merge {
            step,
            round: 0,
            a,
            b,
            new: 4 + step,
            aabb: Aabb::from_points(&[P3::origin()]),
            diameter: 1.0,
            fill: 1.0,
            balance: 1.0,
            cost: 1.0,
            queue_len: 0,
            active: true,
        }
    }

    #[test]
    fn divergence_is_the_first_different_pair() {
        let a = [merge(0, 0, 1), merge(1, 2, 3), merge(2, 4, 5)];
        let b = [merge(0, 0, 1), merge(1, 1, 2), merge(2, 3, 4)];
        assert_eq!(divergence(&a, &a), None);
        assert_eq!(divergence(&a, &b), Some(1));
        assert_eq!(divergence(&a, &a[..2]), Some(2));
        let costlier = [Merge { cost: 9.0, ..a[0] }, a[1], a[2]];
        assert_eq!(divergence(&a, &costlier), None, "only the pairs count");
    }
}
