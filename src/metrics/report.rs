//! Results of `bench` and `sweep` as files: CSV tables, charts (SVG + PNG) and `.rrd` series.

use super::compare::Row;
use super::sweep::SweepRow;
use crate::grouping::Weights;
use crate::query::QueryCost;
use crate::record::output::write_atomic;
use crate::record::rrd::SeriesFile;
use crate::render::chart::{HeatMap, Scatter, Series, pareto_front};
use crate::render::svg_to_png;
use anyhow::{Result, anyhow};
use rerun::EntityPath;
use rerun::blueprint::components::PanelState;
use rerun::blueprint::{
    Blueprint, ContainerLike, Grid, Horizontal, Spatial2DView, TextDocumentView, TimePanel,
    TimeSeriesView, Vertical,
};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Chart size in pixels.
const SIZE: (u32, u32) = (960, 640);

fn opt(v: Option<f64>) -> String {
    v.map_or_else(String::new, |x| format!("{x:.6e}"))
}

/// Columns of a query cost: node (BV) and primitive tests per query of each kind, the eq. (1)
/// total per query, and seconds for the whole workload.
const QUERY_COLUMNS: &str = "point_bv,point_prim,distance_bv,distance_prim,overlap_bv,overlap_prim,\
node_tests_per_query,query_cost,query_s";

fn query_fields(q: Option<&QueryCost>) -> String {
    match q {
        None => ",".repeat(QUERY_COLUMNS.matches(',').count()),
        Some(q) => {
            let v = super::compare::query_values(q);
            v.iter()
                .map(|x| format!("{x:.6e}"))
                .collect::<Vec<_>>()
                .join(",")
        }
    }
}

/// The bench rows as CSV (one header line, one line per row).
pub fn bench_csv(rows: &[Row]) -> String {
    let mut s = format!(
        "scene,n,method,wrapper,build_s,wrapper_s,sah,depth_max,depth_mean,structural_balance,\
spatial_balance,tightness,{QUERY_COLUMNS}\n"
    );
    for r in rows {
        let q = &r.quality;
        let _ = writeln!(
            s,
            "{},{},{},{},{:.6e},{:.6e},{:.6e},{},{:.4},{:.4},{:.4},{},{}",
            r.scene,
            r.n,
            r.method,
            r.wrapper,
            r.build_s,
            r.wrapper_s,
            q.sah,
            q.depth_max,
            q.depth_mean,
            q.structural_balance,
            q.spatial_balance,
            opt(r.tightness),
            query_fields(r.query.as_ref()),
        );
    }
    s
}

/// Writes `stem.svg` and `stem.png` in `dir`; returns both paths.
fn write_chart(dir: &Path, stem: &str, svg: &str, force: bool) -> Result<Vec<PathBuf>> {
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
fn series_by<'a>(rows: impl Iterator<Item = (String, (f64, f64))> + 'a) -> Vec<Series> {
    let mut out: Vec<Series> = Vec::new();
    for (label, p) in rows {
        match out.iter_mut().find(|s| s.label == label) {
            Some(s) => s.points.push(p),
            None => out.push(Series {
                label,
                points: vec![p],
            }),
        }
    }
    out
}

/// The two bench charts for one scene: build time against node tests per query (hierarchy +
/// query wrapper, Pareto front marked), and wrapper build time against tightness.
pub fn bench_charts(scene: &str, rows: &[Row]) -> Result<Vec<(String, String)>> {
    let rows: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
    let n = rows.first().map_or(0, |r| r.n);
    let query = Scatter {
        title: format!("{scene} (N = {n}): build time vs query cost"),
        x_label: "hierarchy + wrapper build time (s, log)".into(),
        y_label: "node tests per query".into(),
        log_x: true,
        pareto: true,
        series: series_by(rows.iter().filter_map(|r| {
            let q = r.query.as_ref()?;
            let y = super::compare::query_values(q)[6];
            Some((r.method.to_string(), (r.build_s + r.wrapper_s, y)))
        })),
        ..Scatter::default()
    };
    let tight = Scatter {
        title: format!("{scene} (N = {n}): wrapper build time vs tightness"),
        x_label: "wrapper build time on top of the hierarchy (s, log)".into(),
        y_label: "mean relative surface-to-geometry distance".into(),
        log_x: true,
        pareto: true,
        series: series_by(rows.iter().filter_map(|r| {
            let t = r.tightness?;
            (r.wrapper_s > 0.0).then(|| (r.wrapper.to_string(), (r.wrapper_s, t)))
        })),
        ..Scatter::default()
    };
    let mut out = vec![(
        "time_vs_query".to_string(),
        query.to_svg(SIZE.0, SIZE.1).map_err(|e| anyhow!(e))?,
    )];
    if !tight.series.is_empty() {
        out.push((
            "wrapper_time_vs_tightness".into(),
            tight.to_svg(SIZE.0, SIZE.1).map_err(|e| anyhow!(e))?,
        ));
    }
    Ok(out)
}

/// Writes `results.csv`, per-scene charts and `bench.rrd` into `dir`; returns what it wrote.
pub fn write_bench(dir: &Path, rows: &[Row], force: bool) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    let csv = dir.join("results.csv");
    write_atomic(&csv, bench_csv(rows).as_bytes(), force)?;
    written.push(csv);
    let mut scenes: Vec<&str> = rows.iter().map(|r| r.scene.as_str()).collect();
    scenes.dedup();
    for scene in &scenes {
        for (name, svg) in bench_charts(scene, rows)? {
            let stem = format!("{}-{name}", sanitize(scene));
            written.extend(write_chart(dir, &stem, &svg, force)?);
        }
    }
    written.push(bench_rrd(&dir.join("bench.rrd"), rows, force)?);
    Ok(written)
}

fn sanitize(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// One scene's rows as a markdown table (what `bench` prints and logs).
pub fn bench_table(rows: &[&Row]) -> String {
    let mut md = String::from(
        "| method | wrapper | build ms | wrapper ms | SAH | depth | tightness | tests/query |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            md,
            "| {} | {} | {:.3} | {:.3} | {:.2} | {} | {} | {} |",
            r.method,
            r.wrapper,
            r.build_s * 1e3,
            r.wrapper_s * 1e3,
            r.quality.sah,
            r.quality.depth_max,
            r.tightness.map(|t| format!("{t:.4}")).unwrap_or_default(),
            r.query
                .as_ref()
                .map(|q| format!("{:.1}", super::compare::query_values(q)[6]))
                .unwrap_or_default()
        );
    }
    md
}

/// Per scene: the two charts as 2D views beside the results table.
fn bench_blueprint(rows: &[Row]) -> Blueprint {
    let views: Vec<ContainerLike> = scenes_of(rows)
        .into_iter()
        .map(|s| {
            let at = |leaf: &str| EntityPath::from(vec!["bench".into(), s.into(), leaf.into()]);
            Horizontal::new([
                Spatial2DView::new(format!(
                    "{s}: build time (log, →) vs node tests per query (↑)"
                ))
                .with_origin(at("time_vs_query").to_string())
                .into(),
                Spatial2DView::new(format!("{s}: wrapper time (log, →) vs tightness (↑)"))
                    .with_origin(at("wrapper_time_vs_tightness").to_string())
                    .into(),
                TextDocumentView::new(format!("{s}: results"))
                    .with_origin(at("table").to_string())
                    .into(),
            ])
            .into()
        })
        .collect();
    Blueprint::new(Vertical::new(views))
}

fn scenes_of(rows: &[Row]) -> Vec<&str> {
    let mut scenes: Vec<&str> = rows.iter().map(|r| r.scene.as_str()).collect();
    scenes.dedup();
    scenes
}

/// Maps chart points into a 100 × 100 square (x = log10 of the first coordinate, larger y
/// drawn higher), as the 2D view keeps a 1:1 aspect.
fn chart_square(points: &[(f64, f64)]) -> Vec<(f32, f32)> {
    let xs: Vec<f64> = points.iter().map(|p| p.0.max(1e-12).log10()).collect();
    let span = |v: &mut dyn Iterator<Item = f64>| {
        v.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        })
    };
    let (x0, x1) = span(&mut xs.iter().copied());
    let (y0, y1) = span(&mut points.iter().map(|p| p.1));
    let scale = |v: f64, lo: f64, hi: f64| {
        if hi > lo {
            100.0 * (v - lo) / (hi - lo)
        } else {
            50.0
        }
    };
    xs.iter()
        .zip(points)
        .map(|(&x, p)| (scale(x, x0, x1) as f32, (100.0 - scale(p.1, y0, y1)) as f32))
        .collect()
}

/// Logs one chart: a labelled point series per group and the Pareto front as a line.
fn log_chart(
    rec: &rerun::RecordingStream,
    base: &EntityPath,
    points: &[(String, String, (f64, f64))],
) -> Result<()> {
    let xy: Vec<(f64, f64)> = points.iter().map(|p| p.2).collect();
    let square = chart_square(&xy);
    let mut groups: Vec<&str> = Vec::new();
    for (g, ..) in points {
        if !groups.contains(&g.as_str()) {
            groups.push(g);
        }
    }
    for (k, g) in groups.iter().enumerate() {
        let idx: Vec<usize> = (0..points.len()).filter(|&i| points[i].0 == *g).collect();
        let c = crate::render::chart::color(k);
        rec.log_static(
            base.join(&EntityPath::from(vec![(*g).into()])),
            &rerun::Points2D::new(idx.iter().map(|&i| square[i]))
                .with_labels(idx.iter().map(|&i| points[i].1.clone()))
                .with_colors([rerun::Color::from_rgb(c.0, c.1, c.2)])
                .with_radii([rerun::components::Radius::new_ui_points(5.0)]),
        )?;
    }
    let front: Vec<(f32, f32)> = pareto_front(&xy).into_iter().map(|i| square[i]).collect();
    rec.log_static(
        base.join(&EntityPath::from(vec!["pareto_front".into()])),
        &rerun::LineStrips2D::new([front]).with_colors([rerun::Color::from_rgb(230, 230, 230)]),
    )?;
    Ok(())
}

/// Logs, per scene, the two charts of [`bench_charts`] as static 2D points (one entity per
/// method, resp. wrapper, each point labelled with its values; the Pareto front as a line) in
/// a 100 × 100 chart square, and the results as a markdown table.
fn bench_rrd(path: &Path, rows: &[Row], force: bool) -> Result<PathBuf> {
    let file = SeriesFile::create(path, "wraptree_bench", force, Some(bench_blueprint(rows)))?;
    let rec = file.rec();
    for scene in scenes_of(rows) {
        let rows: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        let at = |leaf: &str| EntityPath::from(vec!["bench".into(), scene.into(), leaf.into()]);
        let query: Vec<(String, String, (f64, f64))> = rows
            .iter()
            .filter_map(|r| {
                let y = super::compare::query_values(r.query.as_ref()?)[6];
                let t = r.build_s + r.wrapper_s;
                let label = format!(
                    "{} + {}: {:.3} ms, {y:.0} tests",
                    r.method,
                    r.wrapper,
                    t * 1e3
                );
                Some((r.method.to_string(), label, (t, y)))
            })
            .collect();
        log_chart(rec, &at("time_vs_query"), &query)?;
        let tight: Vec<(String, String, (f64, f64))> = rows
            .iter()
            .filter_map(|r| {
                let y = r.tightness?;
                let label = format!(
                    "{} on {}: {:.3} ms, {y:.3}",
                    r.wrapper,
                    r.method,
                    r.wrapper_s * 1e3
                );
                (r.wrapper_s > 0.0).then(|| (r.wrapper.to_string(), label, (r.wrapper_s, y)))
            })
            .collect();
        if !tight.is_empty() {
            log_chart(rec, &at("wrapper_time_vs_tightness"), &tight)?;
        }
        let md = bench_table(&rows);
        rec.log_static(
            at("table"),
            &rerun::TextDocument::new(md).with_media_type(rerun::MediaType::markdown()),
        )?;
    }
    file.commit()
}

/// The sweep rows as CSV.
pub fn sweep_csv(rows: &[SweepRow]) -> String {
    let mut s = format!(
        "a,b,c,build_s,rounds,sah,depth_max,depth_mean,structural_balance,spatial_balance,{QUERY_COLUMNS}\n"
    );
    for r in rows {
        let (w, q) = (&r.weights, &r.quality);
        let _ = writeln!(
            s,
            "{},{},{},{:.6e},{},{:.6e},{},{:.4},{:.4},{:.4},{}",
            w.a,
            w.b,
            w.c,
            r.build_s,
            r.rounds,
            q.sah,
            q.depth_max,
            q.depth_mean,
            q.structural_balance,
            q.spatial_balance,
            query_fields(Some(&r.query)),
        );
    }
    s
}

/// A sweep measure: file stem, title and how to read it from a row.
type Measure = (&'static str, &'static str, fn(&SweepRow) -> f64);

/// Heat maps of the sweep: rows are A values, columns the (B, C) pairs.
pub fn sweep_heat_maps(scene: &str, rows: &[SweepRow]) -> Vec<(String, HeatMap)> {
    let mut a_vals: Vec<f64> = Vec::new();
    let mut bc_vals: Vec<(f64, f64)> = Vec::new();
    for r in rows {
        if !a_vals.contains(&r.weights.a) {
            a_vals.push(r.weights.a);
        }
        if !bc_vals.contains(&(r.weights.b, r.weights.c)) {
            bc_vals.push((r.weights.b, r.weights.c));
        }
    }
    let metrics: [Measure; 4] = [
        ("depth", "depth max", |r| r.quality.depth_max as f64),
        ("sah", "SAH cost", |r| r.quality.sah),
        ("query", "node tests per query (AABB)", |r| {
            super::compare::query_values(&r.query)[6]
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
                        .map(|&(b, c)| {
                            rows.iter()
                                .find(|r| r.weights.a == a && r.weights.b == b && r.weights.c == c)
                                .map_or(f64::NAN, f)
                        })
                        .collect()
                })
                .collect();
            let map = HeatMap {
                title: format!("{scene}: {title} over Cost = d^A (B·Fill + C·Balance)"),
                x_label: "B, C".into(),
                y_label: "A".into(),
                x_ticks: bc_vals.iter().map(|(b, c)| format!("B{b} C{c}")).collect(),
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
    write_atomic(&csv, sweep_csv(rows).as_bytes(), force)?;
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

/// Entity name of one setting.
pub fn setting_name(w: &Weights) -> String {
    format!("A{}_B{}_C{}", w.a, w.b, w.c)
}

impl SweepRrd {
    /// Starts the file (moved into place by [`SweepRrd::finish`]) for `settings`; it opens on
    /// one plot per merge series with every setting in it, and the summary over `setting`.
    pub fn create(path: &Path, settings: &[Weights], force: bool) -> Result<SweepRrd> {
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
    pub fn setting(
        &self,
        w: &crate::grouping::Weights,
        merges: &[crate::grouping::Merge],
    ) -> Result<()> {
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
                rows.iter()
                    .map(|r| super::compare::query_values(&r.query)[6])
                    .collect(),
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
        let mut md = String::from(
            "| tick | setting | group ms | rounds | depth | SAH | balance | tests/query |\n|---|---|---|---|---|---|---|---|\n",
        );
        for (k, r) in rows.iter().enumerate() {
            let _ = writeln!(
                md,
                "| {k} | {} | {:.2} | {} | {} | {:.3} | {:.3} | {:.1} |",
                setting_name(&r.weights),
                r.build_s * 1e3,
                r.rounds,
                r.quality.depth_max,
                r.quality.sah,
                r.quality.structural_balance,
                super::compare::query_values(&r.query)[6]
            );
        }
        rec.log_static(
            "summary/table",
            &rerun::TextDocument::new(md).with_media_type(rerun::MediaType::markdown()),
        )?;
        self.0.commit()
    }
}
