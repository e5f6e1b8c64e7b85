//! Geometry-agnostic shapes the renderer draws: polygons, spheres and convex polyhedra given as
//! faces (hulls, boxes, oriented boxes and triangle meshes all become faces).

use crate::geom::{Aabb, P3, V3};

/// An sRGB colour.
pub type Rgb = [u8; 3];

/// How a shape is filled and outlined.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Style {
    /// Base fill colour (shaded by the renderer).
    pub fill: Rgb,
    /// Fill opacity in 0..=1 (below 1 lets what is behind show through).
    pub opacity: f64,
    /// Outline colour.
    pub stroke: Rgb,
    /// Outline opacity in 0..=1.
    pub stroke_opacity: f64,
    /// Outline width in pixels (0: no outline).
    pub stroke_width: f64,
}

impl Style {
    /// Opaque light-grey polygons with a dark outline (the input frame).
    pub const INPUT: Style = Style {
        fill: [214, 214, 208],
        opacity: 1.0,
        stroke: [70, 70, 70],
        stroke_opacity: 0.6,
        stroke_width: 0.5,
    };
    /// Opaque light-orange polygons (leaves at or below a drawn level).
    pub const LEAF: Style = Style {
        fill: [244, 178, 110],
        opacity: 1.0,
        stroke: [110, 64, 24],
        stroke_opacity: 0.6,
        stroke_width: 0.5,
    };
    /// Translucent blue wrappers (interior nodes of a drawn level).
    pub const WRAPPER: Style = Style {
        fill: [96, 140, 200],
        opacity: 0.38,
        stroke: [30, 55, 100],
        stroke_opacity: 0.75,
        stroke_width: 0.9,
    };
    /// Translucent green convex hulls.
    pub const HULL: Style = Style {
        fill: [110, 178, 132],
        opacity: 0.3,
        stroke: [30, 80, 50],
        stroke_opacity: 0.22,
        stroke_width: 0.4,
    };
    /// Translucent violet boxes (axis-aligned or oriented).
    pub const BOX: Style = Style {
        fill: [160, 130, 200],
        opacity: 0.3,
        stroke: [60, 40, 100],
        stroke_opacity: 0.6,
        stroke_width: 0.7,
    };
}

/// One thing to draw, in world coordinates.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A planar polygon (vertices in order), flat-shaded by its normal.
    Polygon {
        /// Vertices in order.
        points: Vec<P3>,
        /// Fill and outline.
        style: Style,
    },
    /// A sphere, drawn as a disc with a radial gradient; radius 0 is drawn as a small dot.
    Sphere {
        /// Centre.
        center: P3,
        /// Radius (≥ 0).
        radius: f64,
        /// Fill and outline.
        style: Style,
    },
    /// A convex polyhedron as planar faces (any winding), each flat-shaded and depth-sorted on
    /// its own so translucent back faces show through front faces.
    Faces {
        /// The faces' vertices in order.
        faces: Vec<Vec<P3>>,
        /// Fill and outline.
        style: Style,
    },
}

impl Shape {
    /// The six faces of an axis-aligned box.
    pub fn aabb(b: &Aabb, style: Style) -> Shape {
        let c = b.center();
        let h = (b.max - b.min) / 2.0;
        Shape::oriented_box(c, [V3::x() * h.x, V3::y() * h.y, V3::z() * h.z], style)
    }

    /// The six faces of the box `center ± axes[0] ± axes[1] ± axes[2]` (axes scaled by the
    /// half-extents).
    pub fn oriented_box(center: P3, axes: [V3; 3], style: Style) -> Shape {
        let corner = |s: [f64; 3]| center + axes[0] * s[0] + axes[1] * s[1] + axes[2] * s[2];
        let mut faces = Vec::with_capacity(6);
        for k in 0..3 {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            for side in [-1.0, 1.0] {
                let face = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                    .iter()
                    .map(|&(a, b)| {
                        let mut s = [0.0; 3];
                        (s[k], s[i], s[j]) = (side, a, b);
                        corner(s)
                    })
                    .collect();
                faces.push(face);
            }
        }
        Shape::Faces { faces, style }
    }

    /// A triangle mesh (e.g. a convex hull's faces) with indices into `points`; triangles with
    /// an out-of-range index are skipped.
    pub fn mesh(points: &[P3], tris: &[[u32; 3]], style: Style) -> Shape {
        let faces = tris
            .iter()
            .filter_map(|t| {
                t.iter()
                    .map(|&i| points.get(i as usize).copied())
                    .collect::<Option<Vec<P3>>>()
            })
            .collect();
        Shape::Faces { faces, style }
    }

    /// The shape's style.
    pub fn style(&self) -> &Style {
        match self {
            Shape::Polygon { style, .. }
            | Shape::Sphere { style, .. }
            | Shape::Faces { style, .. } => style,
        }
    }

    /// Points with a radius around each that together bound the shape (for framing).
    pub fn extent(&self) -> Vec<(P3, f64)> {
        match self {
            Shape::Polygon { points, .. } => points.iter().map(|&p| (p, 0.0)).collect(),
            Shape::Sphere { center, radius, .. } => vec![(*center, *radius)],
            Shape::Faces { faces, .. } => faces.iter().flatten().map(|&p| (p, 0.0)).collect(),
        }
    }
}

/// Unit normal of a polygon by Newell's method; `None` when it has no area.
pub fn normal(points: &[P3]) -> Option<V3> {
    let mut n = V3::zeros();
    for (i, a) in points.iter().enumerate() {
        let b = points[(i + 1) % points.len()];
        n += V3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let len = n.norm();
    (len > 0.0 && len.is_finite()).then(|| n / len)
}

/// `c` scaled by `k` (darker below 1) or blended towards white by `k − 1` (above 1).
pub fn tint(c: Rgb, k: f64) -> Rgb {
    c.map(|v| {
        let v = v as f64;
        let out = if k <= 1.0 {
            v * k.max(0.0)
        } else {
            v + (255.0 - v) * (k - 1.0).min(1.0)
        };
        out.round().clamp(0.0, 255.0) as u8
    })
}
