//! Figures of a spherized robot (`wraptree spherize --snapshot`): the robot's meshes as it
//! stands, then its links' sphere trees at a few depths (one sphere per link first) and the
//! chosen cover, every sphere over the meshes and coloured by its excess like the recordings.

use std::path::Path;

use anyhow::Result;

use super::frames::{Drawn, Look, draw_frames};
use super::{Frame, Shape, Style, input_frame};
use crate::geom::Sphere;
use crate::record::spherize::View;
use crate::stop::Stop;

/// Depths of the links' trees drawn between the robot and its cover.
pub const DEPTHS: [usize; 3] = [0, 2, 4];

/// The style of a sphere of colour `c` (RGBA in 0..=1, as recorded).
fn sphere_style(c: [f64; 4]) -> Style {
    let byte = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    let fill = [byte(c[0]), byte(c[1]), byte(c[2])];
    Style {
        fill,
        opacity: 0.4,
        stroke: super::shape::tint(fill, 0.45),
        stroke_opacity: 0.8,
        stroke_width: 0.7,
    }
}

/// Every link's mesh, then `spheres` over them, captioned.
fn frame(view: &View, spheres: &[(Sphere, [f64; 4])], caption: String) -> Frame {
    let mut shapes: Vec<Shape> = view
        .links
        .iter()
        .flat_map(|l| input_frame(&l.mesh).shapes)
        .collect();
    shapes.extend(spheres.iter().map(|(s, c)| Shape::Sphere {
        center: s.center,
        radius: s.radius,
        style: sphere_style(*c),
    }));
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
    let mut frames = vec![frame(
        view,
        &[],
        format!(
            "robot · {} · {}",
            count(view.links.len(), "link"),
            count(triangles, "polygon")
        ),
    )];
    let mut names = vec!["frame-00-robot".to_string()];
    let deepest = view.links.iter().map(|l| l.levels.len()).max().unwrap_or(0);
    for d in DEPTHS.into_iter().filter(|&d| d < deepest) {
        stop.check()?;
        let spheres: Vec<(Sphere, [f64; 4])> = view
            .links
            .iter()
            .flat_map(|l| l.levels[d.min(l.levels.len() - 1)].iter().copied())
            .collect();
        let caption = if d == 0 {
            format!("one per link · {}", count(spheres.len(), "sphere"))
        } else {
            format!("depth {d} · {}", count(spheres.len(), "sphere"))
        };
        names.push(format!("frame-{:02}-depth-{d}", frames.len()));
        frames.push(frame(view, &spheres, caption));
    }
    let cover: Vec<(Sphere, [f64; 4])> = view
        .links
        .iter()
        .flat_map(|l| l.cover.iter().copied())
        .collect();
    names.push(format!("frame-{:02}-cover", frames.len()));
    frames.push(frame(
        view,
        &cover,
        format!("cover · {}", count(cover.len(), "sphere")),
    ));
    let captions = frames.iter().map(|f| f.caption.clone()).collect();
    let title = format!("{robot} · collision spheres · {}", view.summary);
    Ok((
        draw_frames(frames, names, &title, look, dir, stop)?,
        captions,
    ))
}
