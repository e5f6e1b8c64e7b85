//! `sweep`'s files: `sweep.csv`, the heat maps and `sweep.rrd` with every setting's merge
//! series side by side.

use super::{QUERY_COLUMNS, csv_bytes, query_fields, write_chart};
use crate::grouping::{CostMeasure, Merge};
use crate::metrics::compare::query_values;
use crate::metrics::sweep::{Setting, SweepRow};
use crate::output::write_atomic;
use crate::record::rrd::SeriesFile;
use crate::render::chart::HeatMap;
use anyhow::{Result, anyhow};
use rerun::EntityPath;
use rerun::blueprint::components::PanelState;
use rerun::blueprint::{
    Blueprint, ContainerLike, Grid, Horizontal, TextDocumentView, TimePanel, TimeSeriesView,
    Vertical,
};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The sweep rows as CSV.
pub fn sweep_csv(rows: &[SweepRow]) -> Result<Vec<u8>> {
    let header = format!(
        "a,b,c,cost,build_s,rounds,sah,depth_max,depth_mean,structural_balance,spatial_balance,{QUERY_COLUMNS}"
    );
    csv_bytes(&header, rows.iter().map(sweep_record))
}

/// One row's fields in the order of [`sweep_csv`]'s header.
fn sweep_record(r: &SweepRow) -> Vec<String> {
    let (w, q) = (&r.weights, &r.quality);
    let mut fields = vec![
        w.a.to_string(),
        w.b.to_string(),
        w.c.to_string(),
        measure_name(r.cost).to_string(),
        format!("{:.6e}", r.build_s),
        r.rounds.to_string(),
        format!("{:.6e}", q.sah),
        q.depth_max.to_string(),
        format!("{:.4}", q.depth_mean),
        format!("{:.4}", q.structural_balance),
        format!("{:.4}", q.spatial_balance),
    ];
    fields.extend(query_fields(Some(&r.query)));
    fields
}

/// A sweep measure: file stem, title and how to read it from a row.
type Measure = (&'static str, &'static str, fn(&SweepRow) -> f64);

/// `diameter` or `area`.
fn measure_name(c: CostMeasure) -> &'static str {
    match c {
        CostMeasure::Diameter => "diameter",
        CostMeasure::Area => "area",
    }
}

/// Heat maps of the sweep: rows are A values, columns the (B, C, size measure) triples.
pub fn sweep_heat_maps(scene: &str, rows: &[SweepRow]) -> Vec<(String, HeatMap)> {
    let mut a_vals: Vec<f64> = Vec::new();
    let mut bc_vals: Vec<(f64, f64, CostMeasure)> = Vec::new();
    for r in rows {
        if !a_vals.contains(&r.weights.a) {
            a_vals.push(r.weights.a);
        }
        if !bc_vals.contains(&(r.weights.b, r.weights.c, r.cost)) {
            bc_vals.push((r.weights.b, r.weights.c, r.cost));
        }
    }
    let metrics: [Measure; 4] = [
        ("depth", "depth max", |r| r.quality.depth_max as f64),
        ("sah", "SAH cost", |r| r.quality.sah),
        ("query", "node tests per query (AABB)", |r| {
            query_values(&r.query)[6]
        }),
        ("time", "grouping time (ms)", |r| r.build_s * 1e3),
    ];
    metrics
        .iter()
        .map(|(stem, title, f)| {
            let values = a_vals
                .iter()
                .map(|&a| {
                    bc_vals
                        .iter()
                        .map(|&(b, c, m)| {
                            rows.iter()
                                .find(|r| {
                                    r.weights.a == a
                                        && r.weights.b == b
                                        && r.weights.c == c
                                        && r.cost == m
                                })
                                .map_or(f64::NAN, f)
                        })
                        .collect()
                })
                .collect();
            let map = HeatMap {
                title: format!("{scene}: {title} over Cost = size^A (B·Fill + C·Balance)"),
                x_label: "B, C, size".into(),
                y_label: "A".into(),
                x_ticks: bc_vals
                    .iter()
                    .map(|&(b, c, m)| match m {
                        CostMeasure::Diameter => format!("B{b} C{c}"),
                        CostMeasure::Area => format!("B{b} C{c} area"),
                    })
                    .collect(),
                y_ticks: a_vals.iter().map(|a| format!("A{a}")).collect(),
                values,
            };
            (format!("sweep-{stem}"), map)
        })
        .collect()
}

/// Writes `sweep.csv` and the heat maps into `dir`; returns what it wrote.
pub fn write_sweep(
    dir: &Path,
    scene: &str,
    rows: &[SweepRow],
    force: bool,
) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    let csv = dir.join("sweep.csv");
    write_atomic(&csv, &sweep_csv(rows)?, force)?;
    written.push(csv);
    for (stem, map) in sweep_heat_maps(scene, rows) {
        let cols = map.x_ticks.len().clamp(1, 40) as u32;
        let svg = map
            .to_svg(240 + 90 * cols, 200 + 40 * map.y_ticks.len() as u32)
            .map_err(|e| anyhow!(e))?;
        written.extend(write_chart(dir, &stem, &svg, force)?);
    }
    Ok(written)
}

/// The sweep's `.rrd`: one entity subtree per setting, `sweep/<A…_B…_C…>/{cost, diameter, fill,
/// balance, queue_len}` over the `merge` timeline, so the settings' merge timelines and plots
/// sit side by side; and `summary/{depth_max, sah, node_tests_per_query, build_ms}` over the
/// `setting` timeline (one tick per setting, in grid order), with `summary/table`, a markdown
/// table of every setting.
pub struct SweepRrd(SeriesFile);

/// The per-merge series of each setting.
const SWEEP_SERIES: [&str; 5] = ["cost", "diameter", "fill", "balance", "queue_len"];

/// The sweep as a markdown table, one row per setting in grid order (what `sweep` prints and
/// logs as `summary/table`).
pub fn sweep_table(rows: &[SweepRow]) -> String {
    let mut md = String::from(
        "| tick | setting | group ms | rounds | depth | SAH | balance | tests/query |\n|---|---|---|---|---|---|---|---|\n",
    );
    for (k, r) in rows.iter().enumerate() {
        let _ = writeln!(
            md,
            "| {k} | {} | {:.2} | {} | {} | {:.3} | {:.3} | {:.1} |",
            setting_name(&Setting {
                weights: r.weights,
                cost: r.cost
            }),
            r.build_s * 1e3,
            r.rounds,
            r.quality.depth_max,
            r.quality.sah,
            r.quality.structural_balance,
            query_values(&r.query)[6]
        );
    }
    md
}

/// Entity name of one setting: `A1_B1_C0` with the diameter, `A1_B1_C0_area` with the area.
pub fn setting_name(s: &Setting) -> String {
    let w = &s.weights;
    match s.cost {
        CostMeasure::Diameter => format!("A{}_B{}_C{}", w.a, w.b, w.c),
        CostMeasure::Area => format!("A{}_B{}_C{}_area", w.a, w.b, w.c),
    }
}

impl SweepRrd {
    /// Starts the file (moved into place by [`SweepRrd::finish`]) for `settings`; it opens on
    /// one plot per merge series with every setting in it, and the summary over `setting`.
    pub fn create(path: &Path, settings: &[Setting], force: bool) -> Result<SweepRrd> {
        let names: Vec<String> = settings.iter().map(setting_name).collect();
        let plot = |series: &str| -> ContainerLike {
            TimeSeriesView::new(format!("{series} (timeline merge)"))
                .with_origin("/sweep")
                .with_contents(names.iter().map(|n| format!("+ /sweep/{n}/{series}")))
                .into()
        };
        let plots = Grid::new(SWEEP_SERIES.iter().map(|s| plot(s)).collect::<Vec<_>>());
        let summary = TimeSeriesView::new("summary (timeline setting)").with_origin("/summary");
        let blueprint = Blueprint::new(Horizontal::new([
            plots.into(),
            Vertical::new([
                summary.into(),
                TextDocumentView::new("settings")
                    .with_origin("/summary/table")
                    .into(),
            ])
            .into(),
        ]))
        .with_time_panel(
            TimePanel::new()
                .with_state(PanelState::Expanded)
                .with_timeline("merge"),
        );
        Ok(SweepRrd(SeriesFile::create(
            path,
            "wraptree_sweep",
            force,
            Some(blueprint),
        )?))
    }

    /// Logs one setting's merges as columns.
    pub fn setting(&self, w: &Setting, merges: &[Merge]) -> Result<()> {
        let rec = self.0.rec();
        let base = EntityPath::from(vec!["sweep".into(), setting_name(w).as_str().into()]);
        let steps: Vec<i64> = merges.iter().map(|m| m.step as i64).collect();
        let series: [(&str, Vec<f64>); 5] = [
            ("cost", merges.iter().map(|m| m.cost).collect()),
            ("diameter", merges.iter().map(|m| m.diameter).collect()),
            ("fill", merges.iter().map(|m| m.fill).collect()),
            ("balance", merges.iter().map(|m| m.balance).collect()),
            (
                "queue_len",
                merges.iter().map(|m| m.queue_len as f64).collect(),
            ),
        ];
        for (name, values) in series {
            let time = rerun::TimeColumn::new_sequence("merge", steps.iter().copied());
            rec.send_columns(
                base.join(&EntityPath::from(vec![name.into()])),
                [time],
                rerun::Scalars::new(values).columns_of_unit_batches()?,
            )?;
        }
        Ok(())
    }

    /// Logs the per-setting summary series and commits the file.
    pub fn finish(self, rows: &[SweepRow]) -> Result<PathBuf> {
        let rec = self.0.rec();
        let ticks: Vec<i64> = (0..rows.len() as i64).collect();
        let series: [(&str, Vec<f64>); 4] = [
            (
                "depth_max",
                rows.iter().map(|r| r.quality.depth_max as f64).collect(),
            ),
            ("sah", rows.iter().map(|r| r.quality.sah).collect()),
            (
                "node_tests_per_query",
                rows.iter().map(|r| query_values(&r.query)[6]).collect(),
            ),
            ("build_ms", rows.iter().map(|r| r.build_s * 1e3).collect()),
        ];
        for (name, values) in series {
            let time = rerun::TimeColumn::new_sequence("setting", ticks.iter().copied());
            rec.send_columns(
                EntityPath::from(vec!["summary".into(), name.into()]),
                [time],
                rerun::Scalars::new(values).columns_of_unit_batches()?,
            )?;
        }
        let md = sweep_table(rows);
        rec.log_static(
            "summary/table",
            &rerun::TextDocument::new(md).with_media_type(rerun::MediaType::markdown()),
        )?;
        self.0.commit()
    }
}
