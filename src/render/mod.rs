//! Headless figures like the paper's Figures 1–4: a small 3D → 2D renderer on top of `resvg`.
//!
//! Shapes ([`Shape`]: polygons, spheres, convex polyhedra as faces) are projected by an
//! orthographic [`Camera`], sorted far to near (painter's algorithm, translucent fills so what is
//! inside a wrapper shows through) and written as SVG ([`svg`]); PNG is the same SVG rendered by
//! `resvg` with the bundled DejaVu Sans font ([`png`]). [`figure`] builds the frames of a Subset
//! Tree: the input, then levels with leaves as polygons and interior nodes as wrappers;
//! [`snapshot`] draws and writes them all (`wraptree snapshot`), [`spheres`] a spherized robot
//! (`wraptree spherize --snapshot`), both through [`frames`].

pub mod camera;
pub mod chart;
pub mod figure;
pub mod frames;
pub mod png;
pub mod shape;
pub mod snapshot;
pub mod spheres;
pub mod svg;

pub use camera::{Camera, View};
pub use figure::{
    fit_camera, input_frame, level_counts, level_for_nodes, level_frame, sheet_columns,
    wrapper_shape,
};
pub use png::svg_to_png;
pub use shape::{Rgb, Shape, Style};
pub use svg::{Frame, frame_svg, sheet_svg};
