//! The one Wavefront OBJ writer: comment, object, vertex and face lines ([`ObjWriter`]), and a
//! scene's primitives as faces or as blocks of hull triangles ([`write_scene`]). Coordinates are
//! written with Rust's shortest round-trip formatting, so the loader reads back the same `f64`.

use super::{PrimitiveKind, Scene};
use crate::geom::P3;
use std::io::{self, Write};

/// Writes OBJ lines to `out`, counting the vertices written so that faces can name them.
pub struct ObjWriter<W: Write> {
    out: W,
    vertices: usize,
}

impl<W: Write> ObjWriter<W> {
    /// A writer to `out` that starts with the comment line `# comment`.
    pub fn new(mut out: W, comment: &str) -> io::Result<Self> {
        writeln!(out, "# {comment}")?;
        Ok(ObjWriter { out, vertices: 0 })
    }

    /// An `o NAME` line.
    pub fn object(&mut self, name: &str) -> io::Result<()> {
        writeln!(self.out, "o {name}")
    }

    /// A `v X Y Z` line.
    pub fn vertex(&mut self, p: &P3) -> io::Result<()> {
        self.vertices += 1;
        writeln!(self.out, "v {} {} {}", p.x, p.y, p.z)
    }

    /// The number of vertices written so far (the 0-based index of the next one).
    pub fn vertices(&self) -> usize {
        self.vertices
    }

    /// An `f` line over the vertices of 0-based indices `face`.
    pub fn face(&mut self, face: impl IntoIterator<Item = usize>) -> io::Result<()> {
        self.out.write_all(b"f")?;
        for v in face {
            write!(self.out, " {}", v + 1)?;
        }
        self.out.write_all(b"\n")
    }

    /// The output, once every line is written.
    pub fn into_inner(self) -> W {
        self.out
    }
}

/// Writes `scene` to `w`: its points (each through `point`), then each primitive as one face
/// (a polygon) or as its hull triangles (a polyhedron), after an `o NAME` line where
/// `object_line(i)` names one for primitive `i`.
pub fn write_scene<W: Write>(
    w: &mut ObjWriter<W>,
    scene: &Scene,
    point: impl Fn(&P3) -> P3,
    object_line: impl Fn(usize) -> Option<String>,
) -> io::Result<()> {
    for p in &scene.points {
        w.vertex(&point(p))?;
    }
    let poly = scene.kind == Some(PrimitiveKind::Polyhedron);
    for i in 0..scene.len() {
        if let Some(name) = object_line(i) {
            w.object(&name)?;
        }
        if poly {
            for t in scene.prim_tris(i) {
                w.face(t.iter().map(|&v| v as usize))?;
            }
        } else {
            w.face(scene.prim(i).iter().map(|&v| v as usize))?;
        }
    }
    Ok(())
}
