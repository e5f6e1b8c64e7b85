//! Frames and figure sheets as SVG text: shapes projected by a [`Camera`], depth-sorted far to
//! near (painter's algorithm) and written as `<path>`/`<circle>` elements with a caption.

use super::camera::Camera;
use super::shape::{Rgb, Shape, Style, normal, tint};
use std::collections::BTreeSet;
use std::fmt::Write;

/// The font family captions ask for (bundled for PNG output, see `assets/fonts/`).
pub const FONT_FAMILY: &str = "DejaVu Sans";

/// One picture: shapes and the caption under them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    /// What to draw.
    pub shapes: Vec<Shape>,
    /// The caption, e.g. "level 9 · 104 nodes".
    pub caption: String,
}

/// A projected primitive ready to write.
enum Item {
    Poly {
        pts: Vec<(f64, f64)>,
        fill: Rgb,
        style: Style,
    },
    Disc {
        c: (f64, f64),
        r: f64,
        style: Style,
    },
}

/// Height of the caption band under a frame, in pixels.
pub fn caption_height(cam: &Camera) -> u32 {
    (cam.size.1 / 14).clamp(18, 40)
}

/// Two-sided Lambert shading of a face with normal `n`.
fn shade(fill: Rgb, n: Option<crate::geom::V3>, cam: &Camera) -> Rgb {
    let k = n.map_or(0.75, |n| 0.5 + 0.5 * n.dot(&cam.light()).abs());
    tint(fill, k)
}

/// Projects the frame's shapes and sorts them far to near (ties keep input order).
fn items(frame: &Frame, cam: &Camera) -> Vec<Item> {
    let mut out: Vec<(f64, usize, Item)> = Vec::new();
    let push_poly = |pts: &[crate::geom::P3], style: &Style, out: &mut Vec<(f64, usize, Item)>| {
        if pts.is_empty() {
            return;
        }
        let proj: Vec<(f64, f64, f64)> = pts.iter().map(|p| cam.project(p)).collect();
        let depth = proj.iter().map(|p| p.2).sum::<f64>() / proj.len() as f64;
        let item = Item::Poly {
            pts: proj.iter().map(|p| (p.0, p.1)).collect(),
            fill: shade(style.fill, normal(pts), cam),
            style: *style,
        };
        out.push((depth, out.len(), item));
    };
    for shape in &frame.shapes {
        match shape {
            Shape::Polygon { points, style } => push_poly(points, style, &mut out),
            Shape::Faces { faces, style } => {
                for f in faces {
                    push_poly(f, style, &mut out);
                }
            }
            Shape::Sphere {
                center,
                radius,
                style,
            } => {
                // Sorted by its nearest point, so what lies inside shows through it.
                let (x, y, depth) = cam.project(center);
                let depth = depth - radius;
                let item = Item::Disc {
                    c: (x, y),
                    r: (radius * cam.scale()).max(1.5),
                    style: *style,
                };
                out.push((depth, out.len(), item));
            }
        }
    }
    out.retain(|(d, _, _)| d.is_finite());
    out.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    out.into_iter().map(|(_, _, i)| i).collect()
}

fn hex(c: Rgb) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

/// Escapes text for an XML text node or attribute.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn stroke_attrs(s: &Style) -> String {
    if s.stroke_width <= 0.0 {
        return " stroke=\"none\"".into();
    }
    format!(
        " stroke=\"{}\" stroke-opacity=\"{:.2}\" stroke-width=\"{:.2}\" stroke-linejoin=\"round\"",
        hex(s.stroke),
        s.stroke_opacity,
        s.stroke_width
    )
}

/// Radial-gradient ids for every sphere colour used by `frames` (sorted, so output is stable).
fn sphere_colours(frames: &[&Frame]) -> BTreeSet<Rgb> {
    frames
        .iter()
        .flat_map(|f| &f.shapes)
        .filter_map(|s| match s {
            Shape::Sphere { style, .. } => Some(style.fill),
            _ => None,
        })
        .collect()
}

fn defs(out: &mut String, frames: &[&Frame]) {
    let colours = sphere_colours(frames);
    if colours.is_empty() {
        return;
    }
    out.push_str("<defs>\n");
    for c in colours {
        let _ = writeln!(
            out,
            "<radialGradient id=\"sph{}\" cx=\"0.5\" cy=\"0.5\" r=\"0.5\" fx=\"0.36\" fy=\"0.3\">\
             <stop offset=\"0\" stop-color=\"{}\"/><stop offset=\"0.55\" stop-color=\"{}\"/>\
             <stop offset=\"1\" stop-color=\"{}\"/></radialGradient>",
            &hex(c)[1..],
            hex(tint(c, 1.55)),
            hex(c),
            hex(tint(c, 0.6))
        );
    }
    out.push_str("</defs>\n");
}

/// Writes one frame's picture and caption with its top-left corner at (0, 0).
fn body(out: &mut String, frame: &Frame, caption: &str, cam: &Camera) {
    let (w, h) = cam.size;
    let _ = writeln!(
        out,
        "<rect x=\"0\" y=\"0\" width=\"{w}\" height=\"{}\" fill=\"#ffffff\"/>",
        h + caption_height(cam)
    );
    for item in items(frame, cam) {
        match item {
            Item::Poly { pts, fill, style } => {
                let mut d = String::with_capacity(pts.len() * 16);
                for (i, (x, y)) in pts.iter().enumerate() {
                    let _ = write!(d, "{}{x:.2} {y:.2}", if i == 0 { "M" } else { " L" });
                }
                let _ = writeln!(
                    out,
                    "<path d=\"{d} Z\" fill=\"{}\" fill-opacity=\"{:.2}\"{}/>",
                    hex(fill),
                    style.opacity,
                    stroke_attrs(&style)
                );
            }
            Item::Disc { c, r, style } => {
                let _ = writeln!(
                    out,
                    "<circle cx=\"{:.2}\" cy=\"{:.2}\" r=\"{r:.2}\" fill=\"url(#sph{})\" \
                     fill-opacity=\"{:.2}\"{}/>",
                    c.0,
                    c.1,
                    &hex(style.fill)[1..],
                    style.opacity,
                    stroke_attrs(&style)
                );
            }
        }
    }
    let ch = caption_height(cam);
    let _ = writeln!(
        out,
        "<text x=\"{:.1}\" y=\"{:.1}\" font-family=\"{FONT_FAMILY}, sans-serif\" \
         font-size=\"{:.1}\" text-anchor=\"middle\" fill=\"#202020\">{}</text>",
        w as f64 / 2.0,
        h as f64 + ch as f64 * 0.7,
        ch as f64 * 0.6,
        escape(caption)
    );
}

fn header(out: &mut String, w: u32, h: u32) {
    let _ = writeln!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
         viewBox=\"0 0 {w} {h}\">"
    );
}

/// A standalone SVG of one frame: `cam.size` for the picture plus the caption band below.
pub fn frame_svg(frame: &Frame, cam: &Camera) -> String {
    let mut out = String::new();
    header(&mut out, cam.size.0, cam.size.1 + caption_height(cam));
    defs(&mut out, &[frame]);
    body(&mut out, frame, &frame.caption, cam);
    out.push_str("</svg>\n");
    out
}

/// Gap between tiles of a sheet, in pixels.
const GAP: u32 = 12;

/// A figure sheet: `title` on top, then the frames in a grid of `cols` columns (row-major),
/// each tile framed by a thin border and captioned "(a) …", "(b) …".
pub fn sheet_svg(frames: &[Frame], cam: &Camera, cols: usize, title: &str) -> String {
    let cols = cols.clamp(1, frames.len().max(1));
    let rows = frames.len().div_ceil(cols).max(1);
    let (tw, th) = (cam.size.0, cam.size.1 + caption_height(cam));
    let title_h = caption_height(cam) + GAP;
    let w = cols as u32 * (tw + GAP) + GAP;
    let h = title_h + rows as u32 * (th + GAP) + GAP;
    let mut out = String::new();
    header(&mut out, w, h);
    defs(&mut out, &frames.iter().collect::<Vec<_>>());
    let _ = writeln!(out, "<rect width=\"{w}\" height=\"{h}\" fill=\"#f4f4f2\"/>");
    let _ = writeln!(
        out,
        "<text x=\"{:.1}\" y=\"{:.1}\" font-family=\"{FONT_FAMILY}, sans-serif\" \
         font-size=\"{:.1}\" text-anchor=\"middle\" fill=\"#101010\">{}</text>",
        w as f64 / 2.0,
        GAP as f64 + caption_height(cam) as f64 * 0.7,
        caption_height(cam) as f64 * 0.66,
        escape(title)
    );
    for (i, f) in frames.iter().enumerate() {
        let (x, y) = (
            GAP + (i % cols) as u32 * (tw + GAP),
            title_h + GAP + (i / cols) as u32 * (th + GAP),
        );
        let letter = char::from(b'a' + (i % 26) as u8);
        let _ = writeln!(out, "<g transform=\"translate({x} {y})\">");
        body(&mut out, f, &format!("({letter}) {}", f.caption), cam);
        let _ = writeln!(
            out,
            "<rect x=\"0.5\" y=\"0.5\" width=\"{}\" height=\"{}\" fill=\"none\" \
             stroke=\"#b0b0b0\"/>\n</g>",
            tw - 1,
            th - 1
        );
    }
    out.push_str("</svg>\n");
    out
}
