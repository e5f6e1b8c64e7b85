//! Figures of a spherized robot (`wraptree spherize --snapshot`): the robot's meshes as it
//! stands, then its links' sphere trees at a few depths (one sphere per link first) and the
//! chosen cover, every sphere over the meshes and coloured by its excess like the recordings.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use anyhow::Result;

use super::frames::{Drawn, Look, draw_frames};
use super::{Frame, Shape, Style, fit_camera, input_frame};
use crate::geom::{P3, Sphere, V3};
use crate::record::spherize::View;
use crate::scene::Scene;
use crate::stop::Stop;

/// The mesh's drawing resolution in the robot's own frame, in pixels ([`clustered`]).
pub const ROBOT_CELL: f64 = 0.5;
/// The mesh's drawing resolution under the spheres, in pixels.
pub const UNDER_SPHERES_CELL: f64 = 2.0;

/// Depths of the links' trees drawn between the robot and its cover.
pub const DEPTHS: [usize; 3] = [0, 2, 4];

/// Spheres with their colours (RGBA in 0..=1), as recorded.
type Coloured = Vec<(Sphere, [f64; 4])>;

/// A sphere as drawn, in its colour (RGBA in 0..=1, as recorded).
fn sphere_shape((s, c): &(Sphere, [f64; 4])) -> Shape {
    let byte = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    let fill = [byte(c[0]), byte(c[1]), byte(c[2])];
    Shape::Sphere {
        center: s.center,
        radius: s.radius,
        style: Style {
            fill,
            opacity: 0.4,
            stroke: super::shape::tint(fill, 0.45),
            stroke_opacity: 0.8,
            stroke_width: 0.7,
        },
    }
}

/// The triangles of `mesh` as drawn at a resolution of `cell` (vertex clustering): vertices in
/// one cell of a grid of that size become their mean, and triangles that collapse or repeat
/// are left out. Below a pixel, the picture does not change; the files shrink with dense meshes.
pub fn clustered(mesh: &Scene, cell: f64) -> Vec<Shape> {
    if cell.is_nan() || cell <= 0.0 {
        return input_frame(mesh).shapes;
    }
    let key = |p: &P3| (p / cell).map(|x| x.floor() as i64);
    let mut cells: BTreeMap<[i64; 3], u32> = BTreeMap::new();
    let mut sums: Vec<(V3, f64)> = Vec::new();
    let ids: Vec<u32> = mesh
        .points
        .iter()
        .map(|p| {
            let k = key(p);
            let id = *cells.entry([k.x, k.y, k.z]).or_insert_with(|| {
                sums.push((V3::zeros(), 0.0));
                sums.len() as u32 - 1
            });
            let s = &mut sums[id as usize];
            s.0 += p.coords;
            s.1 += 1.0;
            id
        })
        .collect();
    let centers: Vec<P3> = sums.iter().map(|(s, n)| P3::from(s / *n)).collect();
    let mut seen = BTreeSet::new();
    mesh.tris
        .iter()
        .filter_map(|t| {
            let c = t.map(|v| ids[v as usize]);
            let mut k = c;
            k.sort_unstable();
            (k[0] != k[1] && k[1] != k[2] && seen.insert(k)).then(|| Shape::Polygon {
                points: c.iter().map(|&i| centers[i as usize]).collect(),
                style: Style::INPUT,
            })
        })
        .collect()
}

/// Every link's mesh (at `cell`, see [`clustered`]), then `spheres` over them, captioned.
fn frame(view: &View, cell: f64, spheres: &[(Sphere, [f64; 4])], caption: String) -> Frame {
    let mut shapes: Vec<Shape> = view
        .links
        .iter()
        .flat_map(|l| clustered(&l.mesh, cell))
        .collect();
    shapes.extend(spheres.iter().map(sphere_shape));
    Frame { shapes, caption }
}

fn count(n: usize, one: &str) -> String {
    format!("{n} {one}{}", if n == 1 { "" } else { "s" })
}

/// Draws `view` of the robot `robot` for `dir` (see [`draw_frames`]): `frame-00-robot`,
/// `frame-NN-depth-D` for each of [`DEPTHS`] the trees reach, `frame-NN-cover` and the
/// `figure` sheet, ready to commit; also returns the frames' captions.
pub fn draw(
    robot: &str,
    view: &View,
    look: &Look,
    dir: &Path,
    stop: &Stop,
) -> Result<(Drawn, Vec<String>)> {
    let triangles: usize = view.links.iter().map(|l| l.mesh.len()).sum();
    let mut names = vec!["frame-00-robot".to_string()];
    let mut plans: Vec<(Coloured, String)> = vec![(
        Vec::new(),
        format!(
            "robot · {} · {}",
            count(view.links.len(), "link"),
            count(triangles, "polygon")
        ),
    )];
    let deepest = view.links.iter().map(|l| l.levels.len()).max().unwrap_or(0);
    for d in DEPTHS.into_iter().filter(|&d| d < deepest) {
        let spheres: Coloured = view
            .links
            .iter()
            .flat_map(|l| l.levels[d.min(l.levels.len() - 1)].iter().copied())
            .collect();
        let caption = if d == 0 {
            format!("one per link · {}", count(spheres.len(), "sphere"))
        } else {
            format!("depth {d} · {}", count(spheres.len(), "sphere"))
        };
        names.push(format!("frame-{:02}-depth-{d}", plans.len()));
        plans.push((spheres, caption));
    }
    let cover: Coloured = view
        .links
        .iter()
        .flat_map(|l| l.cover.iter().copied())
        .collect();
    names.push(format!("frame-{:02}-cover", plans.len()));
    let caption = format!("cover · {}", count(cover.len(), "sphere"));
    plans.push((cover, caption));
    // The camera that fits the robot and every sphere, for the meshes' resolution.
    let bounds = view
        .links
        .iter()
        .map(|l| l.mesh.aabb())
        .reduce(|a, b| a.merge(&b));
    let outline = Frame {
        shapes: bounds
            .iter()
            .map(|b| Shape::aabb(b, Style::INPUT))
            .chain(plans.iter().flat_map(|(s, _)| s).map(sphere_shape))
            .collect(),
        caption: String::new(),
    };
    let cam = fit_camera(&[outline], look.azimuth, look.elevation, look.size);
    let pixel = 1.0 / cam.scale();
    let mut frames = Vec::with_capacity(plans.len());
    for (spheres, caption) in plans {
        stop.check()?;
        // Under the spheres' fill a coarser mesh does not show.
        let cell = if spheres.is_empty() {
            ROBOT_CELL * pixel
        } else {
            UNDER_SPHERES_CELL * pixel
        };
        frames.push(frame(view, cell, &spheres, caption));
    }
    let captions = frames.iter().map(|f| f.caption.clone()).collect();
    let title = format!("{robot} · collision spheres · {}", view.summary);
    Ok((
        draw_frames(frames, names, &title, look, dir, stop)?,
        captions,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::PrimitiveKind;

    /// A flat `n` × `n` grid of unit squares, two triangles each.
    fn grid(n: u32) -> Scene {
        let mut s = Scene::new("grid");
        for j in 0..=n {
            for i in 0..=n {
                s.points.push(P3::new(f64::from(i), f64::from(j), 0.0));
            }
        }
        let at = |i: u32, j: u32| j * (n + 1) + i;
        for j in 0..n {
            for i in 0..n {
                let [a, b, c, d] = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                s.push(PrimitiveKind::Polygon, &[a, b, c], &[[a, b, c]]);
                s.push(PrimitiveKind::Polygon, &[a, c, d], &[[a, c, d]]);
            }
        }
        s
    }

    fn extent(shapes: &[Shape]) -> (f64, f64) {
        let xs = shapes.iter().flat_map(Shape::extent).map(|(p, _)| p.x);
        xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        })
    }

    #[test]
    fn clustering_keeps_the_outline_and_drops_what_is_finer_than_a_cell() {
        let s = grid(100);
        assert_eq!(clustered(&s, 0.0).len(), 20_000);
        assert_eq!(clustered(&s, 0.5).len(), 20_000, "a cell below the spacing");
        let coarse = clustered(&s, 10.0);
        assert!(coarse.len() < 400, "{}", coarse.len());
        let (lo, hi) = extent(&coarse);
        assert!(lo < 10.0 && hi > 90.0, "{lo} {hi}");
        for sh in &coarse {
            let Shape::Polygon { points, .. } = sh else {
                panic!("a polygon")
            };
            let area = (points[1] - points[0])
                .cross(&(points[2] - points[0]))
                .norm();
            assert!(area > 0.0);
        }
    }
}
