//! Frames of the paper's figures: the input, and tree levels where leaves at or below the level
//! are drawn as polygons and interior nodes by their wrappers.

use super::camera::Camera;
use super::shape::{Shape, Style};
use super::svg::Frame;
use crate::grouping::SubsetTree;
use crate::scene::{PrimitiveKind, Scene};
use crate::wrap::WrapperTree;

/// Number of nodes in the cut of every level `0..=depth_max` (index = level), in O(N).
pub fn level_counts(tree: &SubsetTree) -> Vec<usize> {
    let dmax = tree.depth_max() as usize;
    let (mut at, mut leaves_at) = (vec![0usize; dmax + 1], vec![0usize; dmax + 1]);
    for x in 0..tree.len() {
        let d = tree.depth[x] as usize;
        at[d] += 1;
        if tree.is_leaf(x as u32) {
            leaves_at[d] += 1;
        }
    }
    let mut shallower_leaves = 0;
    (0..=dmax)
        .map(|d| {
            let n = at[d] + shallower_leaves;
            shallower_leaves += leaves_at[d];
            n
        })
        .collect()
}

/// The level whose cut has the node count closest to `k` (ties go to the shallower level).
pub fn level_for_nodes(counts: &[usize], k: usize) -> u32 {
    (0..counts.len())
        .min_by_key(|&d| counts[d].abs_diff(k))
        .unwrap_or(0) as u32
}

/// Primitive `i` of `scene`: a polygon, or a polyhedron's faces.
pub fn leaf_shape(scene: &Scene, i: usize, style: Style) -> Shape {
    match scene.kind {
        Some(PrimitiveKind::Polyhedron) => Shape::mesh(&scene.points, scene.prim_tris(i), style),
        _ => Shape::Polygon {
            points: scene.prim_vertices(i).copied().collect(),
            style,
        },
    }
}

/// "276 polygons" / "5 polyhedra".
fn primitives(scene: &Scene) -> String {
    let n = scene.len();
    let (one, many) = match scene.kind {
        Some(PrimitiveKind::Polyhedron) => ("polyhedron", "polyhedra"),
        _ => ("polygon", "polygons"),
    };
    format!("{n} {}", if n == 1 { one } else { many })
}

/// The input frame: every primitive, captioned "input · 276 polygons".
pub fn input_frame(scene: &Scene) -> Frame {
    Frame {
        shapes: (0..scene.len())
            .map(|i| leaf_shape(scene, i, Style::INPUT))
            .collect(),
        caption: format!("input · {}", primitives(scene)),
    }
}

/// The frame of level `d` (see [`SubsetTree::level`]): leaves of the cut as polygons, interior
/// nodes as `wrapper(node)`; captioned "level 9 · 104 nodes".
pub fn level_frame(
    scene: &Scene,
    tree: &SubsetTree,
    d: u32,
    wrapper: &dyn Fn(u32) -> Shape,
) -> Frame {
    let cut = tree.level(d);
    let shapes = cut
        .iter()
        .map(|&x| {
            if tree.is_leaf(x) {
                leaf_shape(scene, x as usize, Style::LEAF)
            } else {
                wrapper(x)
            }
        })
        .collect();
    let n = cut.len();
    Frame {
        shapes,
        caption: format!("level {d} · {n} node{}", if n == 1 { "" } else { "s" }),
    }
}

/// The shape of `node`'s wrapper in a Wrapper Tree: spheres as spheres, hulls, boxes and
/// oriented boxes as faces; a hull with no faces (a segment or a point) as a polygon or dot.
pub fn wrapper_shape(w: WrapperTree<'_>, node: u32) -> Shape {
    let x = node as usize;
    match w {
        WrapperTree::Spheres(s) => Shape::Sphere {
            center: s[x].center,
            radius: s[x].radius,
            style: Style::WRAPPER,
        },
        WrapperTree::Hulls(h) => {
            let h = &h[x];
            match (h.triangles.is_empty(), h.vertices.len()) {
                (false, _) => Shape::mesh(&h.vertices, &h.triangles, Style::HULL),
                (true, 1) => Shape::Sphere {
                    center: h.vertices[0],
                    radius: 0.0,
                    style: Style::HULL,
                },
                (true, _) => Shape::Polygon {
                    points: h.vertices.clone(),
                    style: Style::HULL,
                },
            }
        }
        WrapperTree::Boxes(b) => Shape::aabb(&b[x], Style::BOX),
        WrapperTree::Obbs(o) => {
            let o = &o[x];
            let axes = [0, 1, 2].map(|k| o.axes.column(k) * o.half[k]);
            Shape::oriented_box(o.center, axes, Style::BOX)
        }
    }
}

/// One camera for all `frames` (so sizes compare across frames), fitted to everything drawn.
pub fn fit_camera(frames: &[Frame], azimuth: f64, elevation: f64, size: (u32, u32)) -> Camera {
    let pts = frames
        .iter()
        .flat_map(|f| &f.shapes)
        .flat_map(Shape::extent);
    Camera::fit(azimuth, elevation, size, 0.04, pts)
}

/// Columns of a figure sheet for `n` frames: 2×2 for four, 3 wide for five or six, …
pub fn sheet_columns(n: usize) -> usize {
    match n {
        0..=3 => n.max(1),
        4 => 2,
        _ => (n as f64).sqrt().ceil() as usize,
    }
}
