//! Results of `group`, `bench`, `sweep` and `stress`: text tables, CSV tables, charts (SVG +
//! PNG) and `.rrd` series.
//!
//! - `group`: the run's summary as text or JSON;
//! - `bench`: `results.csv`, the two charts per scene and `bench.rrd`;
//! - `sweep`: `sweep.csv`, the heat maps and `sweep.rrd`;
//! - `stress`: `stress.csv` and the spaghetti sweep charts;
//! - the targets tables and `bench --record`'s table as text ([`targets_header`] …).

mod bench;
mod group;
mod stress;
mod sweep;
mod targets;

pub use bench::{bench_charts, bench_csv, bench_outputs, bench_table, write_bench};
pub use group::{group_json, group_text, pregrouping_lines};
pub use stress::{StressRow, stress_csv, stress_sweep_chart, stress_table};
pub use sweep::{SweepRrd, setting_name, sweep_csv, sweep_heat_maps, sweep_table, write_sweep};
pub use targets::{
    record_cost_header, record_cost_line, record_cost_notes, refine_table, speedup_table,
    target_line, targets_header, targets_notes,
};

use crate::output::write_atomic;
use crate::query::QueryCost;
use crate::render::chart::Series;
use crate::render::svg_to_png;
use anyhow::{Result, anyhow};
use std::path::{Path, PathBuf};

/// Chart size in pixels.
pub(super) const SIZE: (u32, u32) = (960, 640);

pub(super) fn opt(v: Option<f64>) -> String {
    v.map_or_else(String::new, |x| format!("{x:.6e}"))
}

/// Columns of a query cost: node (BV) and primitive tests per query of each kind, the eq. (1)
/// total per query (point, distance and overlap queries), seconds for the whole workload, node
/// and primitive tests per contact query (empty without contact queries: sphere BVs), and how
/// many queries stopped at the test cap
/// ([`crate::query::Workload::max_tests`]).
pub(super) const QUERY_COLUMNS: &str = "point_bv,point_prim,distance_bv,distance_prim,overlap_bv,overlap_prim,\
node_tests_per_query,query_cost,query_s,contact_bv,contact_prim,query_capped";

/// The [`QUERY_COLUMNS`] fields of a query cost, all empty without one.
pub(super) fn query_fields(q: Option<&QueryCost>) -> Vec<String> {
    match q {
        None => vec![String::new(); QUERY_COLUMNS.split(',').count()],
        Some(q) => {
            let values = crate::metrics::compare::query_values(q);
            let mut f: Vec<String> = values.iter().map(|x| format!("{x:.6e}")).collect();
            if q.contact.queries == 0 {
                // No contact queries (sphere BVs): their columns stay empty.
                f[9].clear();
                f[10].clear();
            }
            f.push(q.capped().to_string());
            f
        }
    }
}

/// `header` (comma-separated names) and `records` as CSV, written by the csv crate: `\n` after
/// each line, a field quoted only where it holds a comma, a quote or a line break. Err: a
/// record whose length differs from the header's.
pub(super) fn csv_bytes(
    header: &str,
    records: impl IntoIterator<Item = Vec<String>>,
) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(header.split(','))?;
    for r in records {
        w.write_record(&r)?;
    }
    w.into_inner().map_err(|e| anyhow!("CSV: {}", e.error()))
}

/// Writes `stem.svg` and `stem.png` in `dir`; returns both paths.
pub(super) fn write_chart(dir: &Path, stem: &str, svg: &str, force: bool) -> Result<Vec<PathBuf>> {
    let png = svg_to_png(svg).map_err(|e| anyhow!("{stem}: {e}"))?;
    let (s, p) = (
        dir.join(format!("{stem}.svg")),
        dir.join(format!("{stem}.png")),
    );
    write_atomic(&s, svg.as_bytes(), force)?;
    write_atomic(&p, &png, force)?;
    Ok(vec![s, p])
}

/// Groups points by a key in first-seen order.
pub(super) fn series_by<'a>(rows: impl Iterator<Item = (String, (f64, f64))> + 'a) -> Vec<Series> {
    let mut out: Vec<Series> = Vec::new();
    for (label, p) in rows {
        match out.iter_mut().find(|s| s.label == label) {
            Some(s) => s.points.push(p),
            None => out.push(Series {
                label,
                points: vec![p],
                hollow: false,
            }),
        }
    }
    out
}
