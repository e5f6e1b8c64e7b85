//! `bench`'s files: `results.csv`, per scene the build-time/query-cost and wrapper-time/
//! tightness charts, and `bench.rrd` with the same charts and the results table.

use super::{QUERY_COLUMNS, SIZE, csv_bytes, opt, query_fields, series_by, write_chart};
use crate::metrics::compare::{Row, query_values};
use crate::output::write_atomic;
use crate::peers::Method;
use crate::record::rrd::SeriesFile;
use crate::render::chart::{Scatter, Series, pareto_front};
use anyhow::{Result, anyhow};
use rerun::EntityPath;
use rerun::blueprint::{
    Blueprint, ContainerLike, Horizontal, Spatial2DView, TextDocumentView, Vertical,
};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The bench rows as CSV (one header line, one line per row).
pub fn bench_csv(rows: &[Row]) -> Result<Vec<u8>> {
    let header = format!(
        "scene,n,method,wrapper,build_s,refine_s,wrapper_s,sah,depth_max,depth_mean,structural_balance,\
spatial_balance,tightness,tightness_per_level,{QUERY_COLUMNS},chunking"
    );
    csv_bytes(&header, rows.iter().map(bench_record))
}

/// One row's fields in the order of [`bench_csv`]'s header.
fn bench_record(r: &Row) -> Vec<String> {
    let q = &r.quality;
    let mut fields = vec![
        r.scene.clone(),
        r.n.to_string(),
        r.method.to_string(),
        r.wrapper.to_string(),
        format!("{:.6e}", r.build_s),
        format!("{:.6e}", r.refine_s),
        format!("{:.6e}", r.wrapper_s),
        format!("{:.6e}", q.sah),
        q.depth_max.to_string(),
        format!("{:.4}", q.depth_mean),
        format!("{:.4}", q.structural_balance),
        format!("{:.4}", q.spatial_balance),
        opt(r.tightness),
        r.tightness_levels
            .iter()
            .map(|t| format!("{t:.4}"))
            .collect::<Vec<_>>()
            .join(";"),
    ];
    fields.extend(query_fields(r.query.as_ref()));
    fields.push(r.chunking.clone());
    fields
}

/// Names of the bench charts of a scene (files `SCENE-NAME.svg` and `.png`), in
/// [`bench_charts`]'s order; the second is drawn only when some wrapper's tightness was measured.
const CHARTS: [&str; 2] = ["time_vs_query", "wrapper_time_vs_tightness"];

/// Every file [`write_bench`] may write into `dir` for the scenes named `scenes`, so that a
/// run can refuse an existing one before it measures anything.
pub fn bench_outputs(dir: &Path, scenes: &[&str]) -> Vec<PathBuf> {
    let mut paths = vec![dir.join("results.csv"), dir.join("bench.rrd")];
    for scene in scenes {
        for name in CHARTS {
            for ext in ["svg", "png"] {
                paths.push(dir.join(format!("{}-{name}.{ext}", sanitize(scene))));
            }
        }
    }
    paths
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
            let y = query_values(q)[6];
            Some((r.method.to_string(), (r.build_s + r.wrapper_s, y)))
        }))
        .into_iter()
        .map(|s| Series {
            // Refined methods (`…+refine`) as rings beside their builders' dots.
            hollow: s.label.ends_with("+refine"),
            ..s
        })
        .collect(),
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
        CHARTS[0].to_string(),
        query.to_svg(SIZE.0, SIZE.1).map_err(|e| anyhow!(e))?,
    )];
    if !tight.series.is_empty() {
        out.push((
            CHARTS[1].to_string(),
            tight.to_svg(SIZE.0, SIZE.1).map_err(|e| anyhow!(e))?,
        ));
    }
    Ok(out)
}

/// Writes `results.csv`, per-scene charts and `bench.rrd` into `dir`; returns what it wrote.
pub fn write_bench(dir: &Path, rows: &[Row], force: bool) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    let csv = dir.join("results.csv");
    write_atomic(&csv, &bench_csv(rows)?, force)?;
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

/// One scene's rows as a markdown table (what `bench` prints and logs): with obvhs PLOC among
/// the methods, each build time over PLOC's from the same rows; queries stopped at the test cap
/// are counted beside their row's tests per query and explained below the table.
pub fn bench_table(rows: &[&Row]) -> String {
    let mut md = String::from(
        "| method | wrapper | build ms | / PLOC | wrapper ms | SAH | depth | tightness | tests/query | tests/contact query |\n|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let ploc = rows
        .iter()
        .find(|r| r.method == Method::OBVHS_PLOC.name())
        .map(|r| r.build_s);
    // Contact queries run with box BVs only: other rows leave the cell empty.
    let contact = |q: &crate::query::QueryCost| {
        let c = &q.contact;
        (c.queries > 0).then(|| format!("{:.0}", c.bv_tests))
    };
    for r in rows {
        let _ = writeln!(
            md,
            "| {} | {} | {:.3} | {} | {:.3} | {:.2} | {} | {} | {} | {} |",
            r.method,
            r.wrapper,
            r.build_s * 1e3,
            ploc.map(|p| format!("{:.2}", r.build_s / p))
                .unwrap_or_default(),
            r.wrapper_s * 1e3,
            r.quality.sah,
            r.quality.depth_max,
            r.tightness.map(|t| format!("{t:.4}")).unwrap_or_default(),
            r.query.as_ref().map(tests_cell).unwrap_or_default(),
            r.query.as_ref().and_then(contact).unwrap_or_default()
        );
    }
    let capped: u64 = rows
        .iter()
        .filter_map(|r| r.query.as_ref())
        .map(|q| q.capped())
        .sum();
    if capped > 0 {
        let _ = writeln!(
            md,
            "\n{capped} queries stopped at the cap of {} tests per primitive (exact ties, e.g. \
stacked coincident copies): their rows' tests/query are lower bounds.",
            crate::query::MAX_TESTS_PER_PRIM
        );
    }
    md
}

/// Tests per query, with the queries stopped at the cap when there are any.
fn tests_cell(q: &crate::query::QueryCost) -> String {
    let tests = query_values(q)[6];
    match q.capped() {
        0 => format!("{tests:.1}"),
        k => format!("{tests:.1} ({k} capped)"),
    }
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
                let y = query_values(r.query.as_ref()?)[6];
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::Quality;

    fn row(scene: &str) -> Row {
        Row {
            scene: scene.into(),
            n: 3,
            method: "grouping",
            wrapper: "box",
            build_s: 1.5e-3,
            refine_s: 0.0,
            wrapper_s: 2e-5,
            quality: Quality {
                sah: 12.5,
                depth_max: 4,
                depth_mean: 3.25,
                structural_balance: 0.5,
                spatial_balance: 0.75,
            },
            tightness: Some(0.25),
            tightness_levels: vec![0.5, 0.25],
            query: None,
            chunking: String::new(),
        }
    }

    #[test]
    fn scene_names_with_a_comma_or_a_quote_keep_their_columns() {
        let names = ["a,b.obj", "say \"hi\".obj", "lamp"];
        let bytes = bench_csv(&names.map(row)).unwrap();
        let mut reader = csv::Reader::from_reader(&bytes[..]);
        let width = reader.headers().unwrap().len();
        assert_eq!(width, 27);
        let records: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
        assert_eq!(records.len(), names.len());
        for (r, name) in records.iter().zip(names) {
            assert_eq!(r.len(), width, "{r:?}");
            assert_eq!(&r[0], name);
            assert_eq!(&r[13], "0.5000;0.2500");
        }
    }

    #[test]
    fn an_ordinary_row_is_written_without_quotes() {
        let partitioned = Row {
            chunking: "delta=4 epsilon=0.5 top=8192 sah=256".into(),
            ..row("lamp")
        };
        let text = String::from_utf8(bench_csv(&[row("lamp"), partitioned]).unwrap()).unwrap();
        let head = "lamp,3,grouping,box,1.500000e-3,0.000000e0,2.000000e-5,1.250000e1,4,3.2500,\
0.5000,0.7500,2.500000e-1,0.5000;0.2500,,,,,,,,,,,,,";
        assert_eq!(text.lines().nth(1).unwrap(), head);
        assert_eq!(
            text.lines().nth(2).unwrap(),
            format!("{head}delta=4 epsilon=0.5 top=8192 sah=256")
        );
        assert!(text.ends_with("sah=256\n"));
    }
}
