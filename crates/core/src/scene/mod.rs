//! Scenes: the convex primitives the grouping phase clusters.
//!
//! A [`Scene`] stores its primitives flat (CSR-style) so a million triangles cost a handful of
//! allocations: primitive `i` owns the vertex indices `prim_points[prim_start[i]..prim_start[i+1]]`
//! and the triangles `tris[tri_start[i]..tri_start[i+1]]` that draw it (a fan for a convex polygon,
//! the hull's faces for a polyhedron).
//!
//! - [`load`] loads a scene file by its extension: [`obj`] Wavefront OBJ (via `tobj`), [`stl`],
//!   [`ply`], [`off`], [`gltf`] (glTF/GLB), [`dae`] (COLLADA) and [`urdf`] (a robot's links
//!   placed by its joints), as polygons or as polyhedra, with validation; `mesh` picks a mesh
//!   file's reader, `faces` holds the rules the non-OBJ formats share, [`input`] the types they
//!   all share (formats, options, errors), and [`export`] the OBJ a multi-file input is embedded
//!   as in recordings;
//! - [`generate`] makes the seeded synthetic scenes (robot base, lamp, replicas, soups);
//! - [`pathological`] makes the seeded scenes that stress builders (spaghetti, slabs, …);
//! - [`soup`] makes random triangle soups (used by both);
//! - [`spec`] turns a command line's `KIND[:COUNT]` or OBJ path into a scene;
//! - [`split`] cuts long thin polygons into pieces of limited aspect (§4).

pub mod assembly;
pub mod coincident;
pub mod components;
pub mod dae;
pub mod export;
pub(crate) mod faces;
pub mod generate;
pub mod gltf;
pub(crate) mod guard;
pub mod input;
pub mod load;
pub(crate) mod mesh;
pub mod obj;
pub mod obj_writer;
pub mod off;
pub mod pathological;
pub mod ply;
pub mod polygon;
pub mod polyhedron;
pub mod soup;
pub mod spec;
pub mod split;
pub mod stl;
pub mod urdf;

pub use input::{Format, LoadError, LoadErrorKind, LoadOptions, Loaded, SceneSource, Up};
pub use load::{load_bytes, load_bytes_until, load_path, load_path_until, load_path_with};
pub use urdf::UrdfOptions;

use crate::geom::{Aabb, P3};

/// What one primitive of a scene is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PrimitiveKind {
    /// One planar convex polygon per OBJ face.
    Polygon,
    /// One convex polyhedron per OBJ object/group.
    Polyhedron,
}

/// A set of convex primitives in input order.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Human-readable name (usually the file stem).
    pub name: String,
    /// Whether primitives are polygons or polyhedra (`None` for an empty scene).
    pub kind: Option<PrimitiveKind>,
    /// All vertex positions.
    pub points: Vec<P3>,
    /// Offsets into `prim_points`, length N + 1.
    pub prim_start: Vec<u32>,
    /// Vertex indices of every primitive, concatenated (polygon order for polygons).
    pub prim_points: Vec<u32>,
    /// Offsets into `tris`, length N + 1.
    pub tri_start: Vec<u32>,
    /// Triangles (vertex indices into `points`) that draw each primitive.
    pub tris: Vec<[u32; 3]>,
    /// Optional per-primitive label (OBJ group name for polyhedra).
    pub labels: Vec<String>,
    /// Per-primitive object id: the OBJ `o`/`g` object the primitive came from (ids in order of
    /// first appearance, objects of the same name sharing one id), or the copy index of a
    /// generated replica. Empty when unknown: every primitive is then in object 0. What
    /// `--pregroup objects` takes as components.
    pub objects: Vec<u32>,
}

impl Scene {
    /// An empty scene named `name`, ready for [`Scene::push`].
    pub fn new(name: impl Into<String>) -> Scene {
        Scene {
            name: name.into(),
            prim_start: vec![0],
            tri_start: vec![0],
            ..Scene::default()
        }
    }

    /// Appends a copy of `part`, every vertex moved by `place`, its primitives in object
    /// `object` (labels are not copied).
    pub fn append_copy(&mut self, part: &Scene, place: impl Fn(&P3) -> P3, object: u32) {
        let off = self.points.len() as u32;
        self.points.extend(part.points.iter().map(place));
        let (pp, tp) = (self.prim_points.len() as u32, self.tris.len() as u32);
        self.prim_points
            .extend(part.prim_points.iter().map(|i| i + off));
        self.tris
            .extend(part.tris.iter().map(|t| t.map(|i| i + off)));
        self.prim_start
            .extend(part.prim_start[1..].iter().map(|s| s + pp));
        self.tri_start
            .extend(part.tri_start[1..].iter().map(|s| s + tp));
        self.objects.extend(std::iter::repeat_n(object, part.len()));
        self.kind = self.kind.or(part.kind);
    }

    /// Number of primitives N.
    pub fn len(&self) -> usize {
        self.prim_start.len().saturating_sub(1)
    }

    /// Whether the scene has no primitives.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Appends a primitive made of existing vertex indices and the triangles that draw it.
    pub fn push(&mut self, kind: PrimitiveKind, verts: &[u32], tris: &[[u32; 3]]) {
        self.kind = Some(kind);
        self.prim_points.extend_from_slice(verts);
        self.prim_start.push(self.prim_points.len() as u32);
        self.tris.extend_from_slice(tris);
        self.tri_start.push(self.tris.len() as u32);
    }

    /// Object id of primitive `i` (0 when the scene has no object ids).
    pub fn object(&self, i: usize) -> u32 {
        self.objects.get(i).copied().unwrap_or(0)
    }

    /// Vertex indices of primitive `i`.
    pub fn prim(&self, i: usize) -> &[u32] {
        &self.prim_points[self.prim_start[i] as usize..self.prim_start[i + 1] as usize]
    }

    /// Vertex positions of primitive `i`.
    pub fn prim_vertices(&self, i: usize) -> impl Iterator<Item = &P3> + '_ {
        self.prim(i).iter().map(|&v| &self.points[v as usize])
    }

    /// Triangles drawing primitive `i`.
    pub fn prim_tris(&self, i: usize) -> &[[u32; 3]] {
        &self.tris[self.tri_start[i] as usize..self.tri_start[i + 1] as usize]
    }

    /// AABB of primitive `i`.
    pub fn prim_aabb(&self, i: usize) -> Aabb {
        Aabb::from_points(self.prim_vertices(i))
    }

    /// AABB of the whole scene.
    pub fn aabb(&self) -> Aabb {
        (0..self.len()).fold(Aabb::EMPTY, |b, i| b.merge(&self.prim_aabb(i)))
    }

    /// Total number of primitive vertices (with repeats across primitives).
    pub fn vertex_refs(&self) -> usize {
        self.prim_points.len()
    }

    /// Writes the scene as Wavefront OBJ: one face per polygon, one `o` block per polyhedron
    /// (its hull triangles as faces). Polygons of a scene with object ids get an `o obj<id>`
    /// line wherever the object changes. Loading the output gives the same primitives and, when
    /// the ids are in order of first appearance (as loaders and generators make them), the same
    /// object ids.
    pub fn write_obj(&self, out: impl std::io::Write) -> std::io::Result<()> {
        let comment = format!("wraptree scene '{}', {} primitives", self.name, self.len());
        let mut w = obj_writer::ObjWriter::new(out, &comment)?;
        let poly = self.kind == Some(PrimitiveKind::Polyhedron);
        obj_writer::write_scene(
            &mut w,
            self,
            |p| *p,
            |i| {
                if poly {
                    Some(match self.labels.get(i).map(String::as_str).unwrap_or("") {
                        "" => format!("part{i}"),
                        label => label.to_string(),
                    })
                } else if !self.objects.is_empty()
                    && (i == 0 || self.object(i) != self.object(i - 1))
                {
                    Some(format!("obj{}", self.object(i)))
                } else {
                    None
                }
            },
        )
    }
}

/// `bytes` as UTF-8 text; Err: the 1-based line of the first byte that is not.
fn utf8_text(bytes: &[u8]) -> Result<&str, usize> {
    std::str::from_utf8(bytes).map_err(|e| {
        bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1
    })
}
