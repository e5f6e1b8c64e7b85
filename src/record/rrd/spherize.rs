//! The `.rrd` of a spherize run ([`crate::record::spherize`]): `robot/<link>/mesh`,
//! `robot/<link>/spheres` (static), `levels/<link>` on the `level` timeline (and at
//! [`OPENING_DEPTH`] on `probe`, so the view is not empty on opening) and
//! `allocation/threshold`, `allocation/spheres` on the `probe` timeline. It opens on a layout
//! (`blueprint`): the robot and its cover large, framed on the whole robot,
//! beside the tree levels; below, the budget's probes and the log; the time panel on `probe`.

use std::path::Path;

use rerun::components::FillMode;

use super::blueprint::{self, Layout, Node, View as Pane, ViewKind};
use super::series_file::SeriesFile;
use super::{send_at, send_static};
use crate::geom::{Aabb, Sphere};
use crate::output::Pending;
use crate::record::spherize::View;

/// The depth of the links' trees the level view shows on opening (the `probe` timeline).
const OPENING_DEPTH: usize = 2;

fn rgba(c: [f64; 4]) -> rerun::Color {
    let b = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    rerun::Color::from_unmultiplied_rgba(b(c[0]), b(c[1]), b(c[2]), b(c[3]))
}

fn spheres(list: &[(Sphere, [f64; 4])]) -> rerun::Ellipsoids3D {
    let centers: Vec<[f32; 3]> = list
        .iter()
        .map(|(s, _)| [s.center.x as f32, s.center.y as f32, s.center.z as f32])
        .collect();
    let radii: Vec<f32> = list.iter().map(|(s, _)| s.radius as f32).collect();
    rerun::Ellipsoids3D::from_centers_and_radii(centers, radii)
        .with_colors(list.iter().map(|(_, c)| rgba(*c)))
        .with_fill_mode(FillMode::TransparentFillMajorWireframe)
}

/// A view of kind `kind` named `name` showing the entities `contents` (`+ /path/**`).
fn pane(kind: ViewKind, name: &str, contents: &[&str]) -> Node {
    Node::View(Pane {
        kind,
        name: name.into(),
        origin: "/".into(),
        contents: contents.iter().map(|c| c.to_string()).collect(),
    })
}

/// The layout the recording opens on, its 3D views looking at `bbox`; probe ticks 0..=`last`.
fn layout(bbox: &Aabb, last: i64) -> Layout {
    let eye = blueprint::framing(bbox);
    let x = Some((0, last.max(1)));
    let top = Node::Row(
        vec![
            pane(
                ViewKind::Spatial(eye),
                "Robot and its spheres (colour: excess, green none to red the limit)",
                &["+ /robot/**"],
            ),
            pane(
                ViewKind::Spatial(eye),
                &format!(
                    "Each link's tree at depth {OPENING_DEPTH} (every depth on the `level` timeline)"
                ),
                &["+ /robot/*/mesh", "+ /levels/**"],
            ),
        ],
        vec![3.0, 2.0],
    );
    let bottom = Node::Row(
        vec![
            pane(
                ViewKind::Plot { x, y: None },
                "Budget search: spheres needed per probe",
                &["+ /allocation/spheres"],
            ),
            pane(
                ViewKind::Plot { x, y: None },
                "Budget search: largest excess tried",
                &["+ /allocation/threshold"],
            ),
            pane(
                ViewKind::TextLog,
                "Summary and probes",
                &["+ /spherize/**", "+ /allocation/log"],
            ),
        ],
        vec![1.0, 1.0, 1.5],
    );
    Layout {
        root: Node::Column(vec![top, bottom], vec![3.0, 1.0]),
        timeline: "probe",
    }
}

/// Writes `view` for `dest` (replaced only with `force`), not yet moved into place.
pub fn write(view: &View, dest: &Path, force: bool) -> anyhow::Result<Pending> {
    let file = SeriesFile::create(dest, "wraptree-spherize", force, None)?;
    let rec = file.rec();
    let mut bbox: Option<Aabb> = None;
    for l in &view.links {
        let b = Aabb::from_points(&l.mesh.points);
        bbox = Some(bbox.map_or(b, |a| a.merge(&b)));
        for (s, _) in &l.cover {
            for sign in [-1.0, 1.0] {
                let p = s.center + crate::geom::V3::repeat(sign * s.radius);
                bbox = bbox.map(|a| a.grow(&p));
            }
        }
    }
    if let Some(b) = &bbox {
        layout(b, view.probes.len() as i64 - 1).send(rec, "wraptree-spherize")?;
    }
    send_static(
        rec,
        "spherize/summary",
        &rerun::TextLog::new(view.summary.clone()),
    )?;
    for l in &view.links {
        let m = &l.mesh;
        let positions: Vec<[f32; 3]> = m
            .points
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        let mesh = rerun::Mesh3D::new(positions)
            .with_triangle_indices(m.tris.iter().copied())
            .with_albedo_factor(rerun::Rgba32::from_unmultiplied_rgba(200, 200, 200, 255));
        send_static(rec, &format!("robot/{}/mesh", l.name), &mesh)?;
        send_static(
            rec,
            &format!("robot/{}/spheres", l.name),
            &spheres(&l.cover),
        )?;
        for (d, level) in l.levels.iter().enumerate() {
            send_at(
                rec,
                &format!("levels/{}", l.name),
                &[("level", d as i64)],
                &spheres(level),
            )?;
        }
        // What the view shows on the `probe` timeline, where the file opens.
        if let Some(level) = l.levels.get(OPENING_DEPTH).or(l.levels.last()) {
            send_at(
                rec,
                &format!("levels/{}", l.name),
                &[("probe", 0)],
                &spheres(level),
            )?;
        }
    }
    for (k, (t, n)) in view.probes.iter().enumerate() {
        let at = [("probe", k as i64)];
        send_at(rec, "allocation/threshold", &at, &rerun::Scalars::new([*t]))?;
        if let Some(n) = n {
            send_at(
                rec,
                "allocation/spheres",
                &at,
                &rerun::Scalars::new([*n as f64]),
            )?;
        }
        let text = match n {
            Some(n) => format!("largest excess {t:.6}: {n} spheres, within the budget"),
            None => format!("largest excess {t:.6}: over the budget"),
        };
        send_at(rec, "allocation/log", &at, &rerun::TextLog::new(text))?;
    }
    file.finish()
}
