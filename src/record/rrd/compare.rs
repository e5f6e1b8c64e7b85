//! The `.rrd` of a comparison ([`crate::record::compare`]): several runs of one scene side by side.
//!
//! Entities (positions relative to the scene's AABB centre, moved back by a static transform):
//! - `scene/primitives`: the scene once, static, shown in every run's view;
//! - `runs/<i>/merge` (timelines `merge`, `round`): run i's merged pair (orange) and new body
//!   (green) per merge, for the last [`BODIES_CAP`](crate::record::BODIES_CAP) merges and around the first divergence;
//! - `runs/<i>/divergence` (`merge`): from the first merge where run i decides otherwise than
//!   run 0, the pair run i merges there (magenta, labelled); run 0 shows its own pair;
//! - `runs/<i>/levels/spheres` (`level`): the interior nodes of the cut at depth d as spheres;
//! - `series/{cost,diameter,height,queue_len}/<i>` (`merge`): one line per run in each plot;
//! - `log/compare` (`merge`): the runs' parameters, the divergence, each run's finish.
//!
//! The layout puts the runs' 3D views side by side with the same eye over one shared `merge`
//! timeline, the plots overlaid below beside the log.

use std::path::Path;

use rerun::RecordingStream;
use rerun::components::FillMode;

use super::blueprint::{self, Layout, Node, View, ViewKind};
use super::levels::level_spheres;
use super::mesh::PrimMesh;
use super::{BoxF32, SCENE_GREY, columns, file_error, origin_of, send_at, send_static, sink};
use crate::geom::P3;
use crate::grouping::{Merge, SubsetTree};
use crate::record::boxes_drawn;
use crate::record::compare::{CompareRun, earliest_divergence, log_lines};
use crate::scene::Scene;
use crate::wrap::{SphereMethod, sphere_tree};

/// Line colours of the runs, in order (then repeated).
const RUN_COLORS: [u32; 6] = [
    0x1F77B4FF, 0xFF7F0EFF, 0x2CA02CFF, 0xD62728FF, 0x9467BDFF, 0x8C564BFF,
];
/// Magenta of the divergence.
const DIVERGENCE: u32 = 0xFF00FFFF;
/// Merges drawn before and after the first divergence, besides the last [`BODIES_CAP`](crate::record::BODIES_CAP).
const AROUND: u32 = 256;

/// The plots: name, entity under `series/`, and the per-merge value.
const PLOTS: [(&str, &str); 4] = [
    ("Cost", "cost"),
    ("diameter", "diameter"),
    ("height of the new body", "height"),
    ("MPairs length", "queue_len"),
];

/// Writes the `.rrd` comparison of `runs` (at least two, over `scene`, named `scene_name`) to
/// `path`; errors name `name`. The first run is the reference the others' divergence is
/// measured from.
pub fn write_comparison_rrd(
    path: &Path,
    name: &Path,
    scene: &Scene,
    scene_name: &str,
    runs: &[CompareRun<'_>],
) -> anyhow::Result<()> {
    if runs.len() < 2 {
        anyhow::bail!("{}: a comparison needs two runs or more", name.display());
    }
    let id = recording_id(scene_name, runs);
    let builder = rerun::RecordingStreamBuilder::new("wraptree").recording_id(id.clone());
    let (rec, status) = sink::save(builder, path, None)
        .map_err(|e| file_error(name, "cannot create the Rerun recording", e))?;
    let what = "cannot write the Rerun recording";
    write_all(&rec, scene, scene_name, runs, &id).map_err(|e| file_error(name, what, e))?;
    sink::close(rec, &status, path).map_err(|e| file_error(name, what, e))
}

fn recording_id(scene_name: &str, runs: &[CompareRun<'_>]) -> String {
    use sha2::{Digest, Sha256};
    let mut h = Sha256::new();
    h.update(b"wraptree compare\0");
    h.update(scene_name.as_bytes());
    for r in runs {
        h.update(b"\0");
        h.update(r.label.as_bytes());
        h.update((r.merges.len() as u64).to_le_bytes());
    }
    super::uuid_text(&h.finalize())
}

fn write_all(
    rec: &RecordingStream,
    scene: &Scene,
    scene_name: &str,
    runs: &[CompareRun<'_>],
    id: &str,
) -> anyhow::Result<()> {
    let bbox = scene.aabb();
    let origin = origin_of(&bbox);
    let labels: Vec<&str> = runs.iter().map(|r| r.label.as_str()).collect();
    rec.send_recording_name(format!("{scene_name}: {}", labels.join(" vs ")))?;
    send_static(rec, "/", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP())?;
    let shift =
        rerun::Transform3D::from_translation([origin.x, origin.y, origin.z].map(|v| v as f32));
    send_static(rec, "scene", &shift)?;
    send_static(rec, "runs", &shift)?;
    let prims = PrimMesh::new(scene, &origin).to_mesh3d();
    send_static(
        rec,
        "scene/primitives",
        &prims.with_albedo_factor(SCENE_GREY),
    )?;

    let n = scene.len();
    let first = earliest_divergence(runs);
    let mut maxima = [0.0f64; 4];
    for (i, run) in runs.iter().enumerate() {
        let color = RUN_COLORS[i % RUN_COLORS.len()];
        let m = log_series(rec, i, run, color, n)?;
        for (max, v) in maxima.iter_mut().zip(m) {
            *max = max.max(v);
        }
        log_merges(rec, i, run, scene, &origin, first)?;
        if let Some(k) = first.filter(|&k| k < run.merges.len()) {
            log_divergence(rec, i, &run.merges[k], k, &origin)?;
        }
        if let Some(tree) = run.tree {
            log_levels(rec, i, tree, scene, &origin)?;
        }
    }
    log_text(rec, runs)?;

    let last = runs
        .iter()
        .map(|r| r.merges.len())
        .max()
        .unwrap_or(1)
        .max(1) as i64
        - 1;
    layout(&labels, blueprint::framing(&bbox), last, &maxima).send(rec, id)?;
    Ok(())
}

/// Logs run `i`'s series, one entity per plot; returns each plot's largest value.
fn log_series(
    rec: &RecordingStream,
    i: usize,
    run: &CompareRun<'_>,
    color: u32,
    n: usize,
) -> anyhow::Result<[f64; 4]> {
    let mut height = vec![0u32; n + run.merges.len()];
    let mut values: [Vec<f64>; 4] = Default::default();
    for m in run.merges {
        let h = 1 + height
            .get(m.a as usize)
            .copied()
            .unwrap_or(0)
            .max(height.get(m.b as usize).copied().unwrap_or(0));
        if let Some(slot) = height.get_mut(m.new as usize) {
            *slot = h;
        }
        let row = [m.cost, m.diameter, f64::from(h), f64::from(m.queue_len)];
        for (v, x) in values.iter_mut().zip(row) {
            v.push(x);
        }
    }
    let ticks =
        || rerun::TimeColumn::new_sequence("merge", run.merges.iter().map(|m| i64::from(m.step)));
    let mut maxima = [0.0; 4];
    for ((plot, v), max) in PLOTS.iter().zip(&values).zip(&mut maxima) {
        let path = format!("series/{}/{i}", plot.1);
        send_static(
            rec,
            &path,
            &rerun::SeriesLines::new()
                .with_names([run.label.as_str()])
                .with_colors([color]),
        )?;
        if !v.is_empty() {
            let columns = rerun::Scalars::new(v.iter().copied()).columns_of_unit_batches()?;
            rec.send_columns(path.as_str(), [ticks()], columns)?;
        }
        *max = v
            .iter()
            .copied()
            .filter(|x| x.is_finite())
            .fold(0.0, f64::max);
    }
    Ok(maxima)
}

/// Logs run `i`'s per-merge boxes: the last [`BODIES_CAP`](crate::record::BODIES_CAP) merges and those within [`AROUND`]
/// of the first divergence `first`.
fn log_merges(
    rec: &RecordingStream,
    i: usize,
    run: &CompareRun<'_>,
    scene: &Scene,
    origin: &P3,
    first: Option<usize>,
) -> anyhow::Result<()> {
    let n = scene.len();
    let mut boxes: Vec<BoxF32> = (0..n)
        .map(|p| BoxF32::new(&scene.prim_aabb(p), origin))
        .collect();
    let near = |step: u32| first.is_some_and(|k| (step as usize).abs_diff(k) <= AROUND as usize);
    let (mut merge, mut round, mut centers, mut halves) = (vec![], vec![], vec![], vec![]);
    for m in run.merges {
        let new = BoxF32::new(&m.aabb, origin);
        let drawn = boxes_drawn(m.step, n) || near(m.step);
        if let (true, Some(a), Some(b)) = (drawn, boxes.get(m.a as usize), boxes.get(m.b as usize))
        {
            merge.push(i64::from(m.step));
            round.push(i64::from(m.round));
            centers.extend([a.center, b.center, new.center]);
            halves.extend([a.half, b.half, new.half]);
        }
        boxes.push(new);
    }
    let path = format!("runs/{i}/merge");
    columns::log_styles(rec, &path)?;
    if merge.is_empty() {
        return Ok(());
    }
    let rows = merge.len();
    let columns = rerun::Boxes3D::update_fields()
        .with_centers(centers)
        .with_half_sizes(halves)
        .columns(std::iter::repeat_n(3, rows))?;
    let ticks = [
        rerun::TimeColumn::new_sequence("merge", merge),
        rerun::TimeColumn::new_sequence("round", round),
    ];
    rec.send_columns(path.as_str(), ticks, columns)?;
    Ok(())
}

/// Marks merge `k`, the first where the runs decide otherwise: run `i`'s pair there.
fn log_divergence(
    rec: &RecordingStream,
    i: usize,
    m: &Merge,
    k: usize,
    origin: &P3,
) -> anyhow::Result<()> {
    let b = BoxF32::new(&m.aabb, origin);
    let label = format!("first divergence (merge {k}): {} + {}", m.a, m.b);
    let arch = rerun::Boxes3D::from_centers_and_half_sizes([b.center], [b.half])
        .with_colors([DIVERGENCE])
        .with_radii([rerun::components::Radius::new_ui_points(3.5)])
        .with_labels([label])
        .with_fill_mode(FillMode::MajorWireframe);
    send_at(
        rec,
        &format!("runs/{i}/divergence"),
        &[("merge", k as i64)],
        &arch,
    )
}

/// Logs run `i`'s levels: at tick d of `level`, the interior nodes of the cut at depth d as
/// spheres.
fn log_levels(
    rec: &RecordingStream,
    i: usize,
    tree: &SubsetTree,
    scene: &Scene,
    origin: &P3,
) -> anyhow::Result<()> {
    let spheres = sphere_tree(tree, scene, SphereMethod::default());
    let path = format!("runs/{i}/levels/spheres");
    for d in 0..=tree.depth_max() {
        let mut interior = tree.level(d);
        interior.retain(|&x| !tree.is_leaf(x));
        let arch = level_spheres(&interior, &spheres, origin);
        send_at(rec, &path, &[("level", i64::from(d))], &arch)?;
    }
    Ok(())
}

/// The log ([`log_lines`]) on `log/compare`.
fn log_text(rec: &RecordingStream, runs: &[CompareRun<'_>]) -> anyhow::Result<()> {
    for l in log_lines(runs) {
        let level = if l.warn {
            rerun::TextLogLevel::WARN
        } else {
            rerun::TextLogLevel::INFO
        };
        send_at(
            rec,
            "log/compare",
            &[("merge", l.merge as i64)],
            &rerun::TextLog::new(l.text).with_level(level),
        )?;
    }
    Ok(())
}

/// The comparison's layout: the runs' 3D views side by side (three per row at most), the
/// overlaid plots in two columns beside the log.
fn layout(labels: &[&str], eye: Option<blueprint::Eye>, last: i64, maxima: &[f64; 4]) -> Layout {
    let views: Vec<Node> = labels
        .iter()
        .enumerate()
        .map(|(i, label)| {
            Node::View(View {
                kind: ViewKind::Spatial(eye),
                name: format!("run {i}: {label} (timelines merge, level)"),
                origin: "/".into(),
                contents: vec!["+ /scene/**".into(), format!("+ /runs/{i}/**")],
            })
        })
        .collect();
    let top = if views.len() <= 3 {
        let shares = vec![1.0; views.len()];
        Node::Row(views, shares)
    } else {
        Node::Grid(views, 3)
    };
    let x = Some((0, last.max(1)));
    let plots = PLOTS
        .iter()
        .zip(maxima)
        .map(|((name, s), &hi)| {
            let y = (hi.is_finite() && hi > 0.0).then_some((0.0, hi * 1.05));
            blueprint::plot(name, &[format!("{s}/**")], x, y)
        })
        .collect();
    let bottom = Node::Row(
        vec![
            Node::Grid(plots, 2),
            blueprint::text_log("Runs and divergence", "/log"),
        ],
        vec![3.0, 2.0],
    );
    Layout {
        root: Node::Column(vec![top, bottom], vec![3.0, 2.0]),
        timeline: "merge",
    }
}
