//! The table, CSV and charts of `wraptree stress` ([`crate::metrics::stress`]).

use crate::render::chart::{Scatter, Series};
use anyhow::Result;
use std::fmt::Write as _;

/// One measured case: a row of the table and of stress.csv.
#[derive(Clone, Debug, Default)]
pub struct StressRow {
    /// Scene name.
    pub scene: String,
    /// Primitives grouped (after the split, if any).
    pub n: usize,
    /// Builder: `group-aabb`, `group-hull`, `wrap-…` or a peer's name.
    pub method: String,
    /// The `--split-aspect` R applied first, if any.
    pub split_r: Option<f64>,
    /// Whether the build finished within the budget.
    pub finished: bool,
    /// Whether the tree (or the Wrapper Tree's containment) checked out; `None` if not built.
    pub valid: Option<bool>,
    /// Largest depth of the tree.
    pub depth: Option<u32>,
    /// Build time.
    pub seconds: Option<f64>,
    /// Eligible pairs per body (groupings).
    pub k_eligible: Option<f64>,
    /// Candidates examined per body (groupings).
    pub k_candidates: Option<f64>,
    /// Why a case failed or was stopped.
    pub note: String,
}

/// Formats an optional number, blank when absent.
fn opt(v: Option<f64>, prec: usize) -> String {
    v.map(|x| format!("{x:.prec$}")).unwrap_or_default()
}

/// The CSV of `rows` (header first).
pub fn stress_csv(rows: &[StressRow]) -> Result<Vec<u8>> {
    super::csv_bytes(
        "scene,n,method,split_r,finished,valid,depth_max,seconds,k_eligible,k_candidates,note",
        rows.iter().map(|r| {
            vec![
                r.scene.clone(),
                r.n.to_string(),
                r.method.clone(),
                opt(r.split_r, 0),
                r.finished.to_string(),
                r.valid.map(|v| v.to_string()).unwrap_or_default(),
                r.depth.map(|d| d.to_string()).unwrap_or_default(),
                opt(r.seconds, 6),
                opt(r.k_eligible, 3),
                opt(r.k_candidates, 3),
                r.note.clone(),
            ]
        }),
    )
}

/// `rows` as a text table (header first).
pub fn stress_table(rows: &[StressRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<28} {:>7} {:<22} {:>5} {:>4} {:>5} {:>5} {:>10} {:>9} {:>9}  note",
        "scene", "N", "method", "split", "done", "valid", "depth", "ms", "k", "cand/N"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{:<28} {:>7} {:<22} {:>5} {:>4} {:>5} {:>5} {:>10} {:>9} {:>9}  {}",
            r.scene,
            r.n,
            r.method,
            opt(r.split_r, 0),
            if r.finished { "yes" } else { "NO" },
            match r.valid {
                Some(true) => "yes",
                Some(false) => "NO",
                None => "",
            },
            r.depth.map(|d| d.to_string()).unwrap_or_default(),
            opt(r.seconds.map(|s| s * 1e3), 2),
            opt(r.k_eligible, 2),
            opt(r.k_candidates, 2),
            r.note
        );
    }
    s
}

/// A log–log chart of grouping time and k against the `x` of a sweep, with and without the
/// split at `r`.
pub fn stress_sweep_chart(
    sweep: &[(f64, StressRow)],
    title: String,
    x_label: &str,
    r: f64,
) -> Scatter {
    let series = |label: String, split: bool, f: fn(&StressRow) -> Option<f64>| Series {
        label,
        hollow: false,
        points: sweep
            .iter()
            .filter(|(_, row)| row.split_r.is_some() == split)
            .filter_map(|(a, row)| Some((*a, f(row)?)))
            .collect(),
    };
    Scatter {
        title,
        x_label: x_label.into(),
        y_label: "grouping time (ms)  ·  k = eligible pairs per body".into(),
        log_x: true,
        log_y: true,
        lines: true,
        pareto: false,
        series: vec![
            series("time ms".into(), false, |r| Some(r.seconds? * 1e3)),
            series(format!("time ms, split R = {r}"), true, |r| {
                Some(r.seconds? * 1e3)
            }),
            series("k".into(), false, |r| r.k_eligible),
            series(format!("k, split R = {r}"), true, |r| r.k_eligible),
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scene_or_note_with_a_comma_or_a_quote_keeps_its_columns() {
        let rows = [
            StressRow {
                scene: "a,b.obj".into(),
                n: 300,
                method: "group-aabb".into(),
                finished: true,
                valid: Some(true),
                depth: Some(11),
                seconds: Some(0.5),
                ..StressRow::default()
            },
            StressRow {
                scene: "say \"hi\".obj".into(),
                method: "wrap-obb".into(),
                split_r: Some(8.0),
                note: "over budget: stopped after 3 merges, \"quoted\"".into(),
                ..StressRow::default()
            },
        ];
        let bytes = stress_csv(&rows).unwrap();
        let mut reader = csv::Reader::from_reader(&bytes[..]);
        assert_eq!(reader.headers().unwrap().len(), 11);
        let records: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
        assert_eq!(records.len(), 2);
        assert!(records.iter().all(|r| r.len() == 11));
        assert_eq!(&records[0][0], "a,b.obj");
        assert_eq!(&records[0][6], "11");
        assert_eq!(&records[1][0], "say \"hi\".obj");
        assert_eq!(&records[1][3], "8");
        assert_eq!(&records[1][10], rows[1].note);
    }
}
