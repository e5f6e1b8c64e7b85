//! Faces read from a mesh file (STL, PLY, OFF, glTF, a URDF's meshes and shapes) and how they
//! become a [`Scene`]: the rules OBJ files follow ([`super::polygon`],
//! [`super::polyhedron`]).
//!
//! [`build`] checks every coordinate (finite, within ±[`MAX_COORDINATE`]), turns the scene so
//! that the file's up axis is +Z, merges vertices with bit-identical positions (in order of first
//! use), and makes each face a polygon (or each object one polyhedron), dropping degenerate
//! faces and splitting non-planar or non-convex ones with one warning per kind. Object ids are
//! numbered in order of first appearance among the primitives.

use nalgebra::{Matrix3, Vector3};

use super::Scene;
use super::input::{LoadError, LoadErrorKind, LoadOptions, MAX_COORDINATE, Up};
use super::polygon::{self, PolygonStats};
use super::polyhedron::{self, PolyhedronStats};
use crate::geom::P3;
use crate::stop::Stop;

/// Faces over a vertex list, each in one named object.
#[derive(Clone, Debug, Default)]
pub(crate) struct Faces {
    /// Vertex positions, as read (repeats allowed).
    pub coords: Vec<[f64; 3]>,
    /// Every face's vertex indices into `coords`, concatenated.
    verts: Vec<u32>,
    /// Offsets into `verts`, one more than the faces.
    starts: Vec<usize>,
    /// The object of each face.
    object: Vec<u32>,
    /// Object names by id, each different.
    pub names: Vec<String>,
    /// The names in `names`, to keep them different.
    taken: std::collections::HashSet<String>,
    /// Faces with fewer than 3 vertices, dropped as they were read.
    pub short: usize,
}

impl Faces {
    /// No faces, no objects.
    pub fn new() -> Faces {
        Faces {
            starts: vec![0],
            ..Faces::default()
        }
    }

    /// Number of faces kept (3 vertices or more).
    pub fn len(&self) -> usize {
        self.starts.len() - 1
    }

    /// Whether no face is kept.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// A new object named `name`, or `name.2`, `name.3`, … when the name is taken (an empty
    /// name becomes `object<id>`); returns its id.
    pub fn object(&mut self, name: &str) -> u32 {
        let id = self.names.len() as u32;
        let base = clean_name(name);
        let base = if base.is_empty() {
            format!("object{id}")
        } else {
            base
        };
        let mut candidate = base.clone();
        let mut k = 2;
        while self.taken.contains(&candidate) {
            candidate = format!("{base}.{k}");
            k += 1;
        }
        self.taken.insert(candidate.clone());
        self.names.push(candidate);
        id
    }

    /// Appends a vertex; returns its index.
    pub fn vertex(&mut self, p: [f64; 3]) -> u32 {
        self.coords.push(p);
        (self.coords.len() - 1) as u32
    }

    /// Appends a face of object `object` (indices into `coords`, checked by the caller);
    /// a face of fewer than 3 vertices is counted in `short` instead.
    pub fn face(&mut self, verts: impl IntoIterator<Item = u32>, object: u32) {
        let at = self.verts.len();
        self.verts.extend(verts);
        if self.verts.len() - at < 3 {
            self.verts.truncate(at);
            self.short += 1;
            return;
        }
        self.starts.push(self.verts.len());
        self.object.push(object);
    }

    /// The faces, in order, with their objects.
    pub fn faces(&self) -> impl Iterator<Item = (&[u32], u32)> {
        self.starts
            .windows(2)
            .zip(&self.object)
            .map(|(w, &o)| (&self.verts[w[0]..w[1]], o))
    }

    /// Appends every face of `other`, its vertices moved by `m`, into object `object`.
    pub fn append(&mut self, other: &Faces, m: &Affine, object: u32) {
        let base = self.coords.len() as u32;
        self.coords.extend(other.coords.iter().map(|p| m.apply(*p)));
        for (f, _) in other.faces() {
            self.face(f.iter().map(|&v| v + base), object);
        }
        self.short += other.short;
    }
}

/// An object name as one line (control characters as `_`, ends trimmed).
fn clean_name(name: &str) -> String {
    name.trim()
        .chars()
        .map(|c| if c.is_control() { '_' } else { c })
        .collect()
}

/// An affine map x ↦ M x + t in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Affine {
    /// The linear part.
    pub m: Matrix3<f64>,
    /// The translation.
    pub t: Vector3<f64>,
}

impl Affine {
    /// The identity.
    pub const IDENTITY: Affine = Affine {
        m: Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        t: Vector3::new(0.0, 0.0, 0.0),
    };

    /// `self` after `other`: x ↦ self(other(x)).
    pub fn then_apply(&self, other: &Affine) -> Affine {
        Affine {
            m: self.m * other.m,
            t: self.m * other.t + self.t,
        }
    }

    /// The image of `p`.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let q = self.m * Vector3::from(p) + self.t;
        [q.x, q.y, q.z]
    }

    /// Whether every entry is finite.
    pub fn is_finite(&self) -> bool {
        self.m.iter().chain(self.t.iter()).all(|x| x.is_finite())
    }
}

/// A scene built from [`Faces`], with its object names by id and the repair warnings.
#[derive(Debug)]
pub(crate) struct Built {
    /// The scene.
    pub scene: Scene,
    /// Object names by (renumbered) object id.
    pub names: Vec<String>,
    /// One line per kind of repair, naming the file.
    pub warnings: Vec<String>,
}

/// The stem of `file_name` (its name without directory or extension): what a scene or its
/// one object is named after.
pub(crate) fn stem(file_name: &str) -> String {
    std::path::Path::new(file_name)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Turns `faces` of the file `file_name` into a scene by the rules of the module docs, checking
/// `stop` as it goes.
pub(crate) fn build(
    file_name: &str,
    mut faces: Faces,
    opts: &LoadOptions,
    up: Up,
    stop: &Stop,
) -> Result<Built, LoadError> {
    let interrupted = |_| LoadError::interrupted(file_name);
    let err = |kind, problem: String| LoadError {
        file: file_name.to_string(),
        kind,
        problem,
    };
    for (k, c) in faces.coords.iter().enumerate() {
        if c.iter().any(|x| !x.is_finite()) {
            let why = format!("vertex {} has a non-finite coordinate ({c:?})", k + 1);
            return Err(err(LoadErrorKind::NonFinite, why));
        }
        if c.iter().any(|x| x.abs() > MAX_COORDINATE) {
            let why = format!(
                "vertex {} has a coordinate beyond ±{MAX_COORDINATE:e}",
                k + 1
            );
            return Err(err(LoadErrorKind::NonFinite, why));
        }
    }
    if up == Up::Y {
        turn_y_up(&mut faces.coords);
    }
    if faces.is_empty() {
        let why = match faces.short {
            0 => String::new(),
            n => format!(" ({n} faces with fewer than 3 vertices were dropped)"),
        };
        return Err(err(LoadErrorKind::NoFaces, format!("no faces{why}")));
    }
    let stem = stem(file_name);
    let mut scene = Scene::new(stem);
    stop.check().map_err(interrupted)?;
    let of_coord = weld(&faces.coords, &mut scene.points);
    let face_verts = |f: &[u32]| {
        f.iter()
            .map(|&v| of_coord[v as usize])
            .collect::<Vec<u32>>()
    };
    let mut warnings = Vec::new();
    // The object of each primitive, before renumbering.
    let mut objects = Vec::new();
    if opts.polyhedra {
        let mut stats = PolyhedronStats::default();
        let mut by_object: Vec<Vec<Vec<u32>>> = vec![Vec::new(); faces.names.len()];
        let mut order = Vec::new();
        for (f, o) in faces.faces() {
            let list = &mut by_object[o as usize];
            if list.is_empty() {
                order.push(o);
            }
            list.push(face_verts(f));
        }
        for o in order {
            stop.check().map_err(interrupted)?;
            let list: Vec<&[u32]> = by_object[o as usize].iter().map(Vec::as_slice).collect();
            polyhedron::add(
                &mut scene,
                &faces.names[o as usize],
                &list,
                opts.strict,
                &mut stats,
            )
            .map_err(|p| err(LoadErrorKind::NotConvex, p))?;
            objects.resize(scene.len(), o);
        }
        warnings.extend(stats.warnings());
    } else {
        let mut stats = PolygonStats {
            degenerate: faces.short,
            ..PolygonStats::default()
        };
        let mut scratch = polygon::Scratch::default();
        for (k, (f, o)) in faces.faces().enumerate() {
            stop.check_every(k).map_err(interrupted)?;
            polygon::add(&mut scene, &face_verts(f), &mut stats, &mut scratch);
            objects.resize(scene.len(), o);
        }
        warnings.extend(stats.warnings());
    }
    if scene.is_empty() {
        let all = faces.len() + faces.short;
        return Err(err(
            LoadErrorKind::NoFaces,
            format!("no faces (all {all} faces are degenerate)"),
        ));
    }
    // Object ids in order of first appearance among the primitives.
    let mut new_id = vec![u32::MAX; faces.names.len()];
    let mut names = Vec::new();
    scene.objects = objects
        .iter()
        .map(|&o| {
            let slot = &mut new_id[o as usize];
            if *slot == u32::MAX {
                *slot = names.len() as u32;
                names.push(faces.names[o as usize].clone());
            }
            *slot
        })
        .collect();
    let warnings = warnings
        .into_iter()
        .map(|w| format!("{file_name}: {w}"))
        .collect();
    Ok(Built {
        scene,
        names,
        warnings,
    })
}

/// Turns Y-up coordinates to Z-up: +90° about X, (x, y, z) → (x, −z, y), exact in `f64`.
pub(crate) fn turn_y_up(coords: &mut [[f64; 3]]) {
    for c in coords {
        *c = [c[0], -c[2], c[1]];
    }
}

/// Merges bit-identical positions (−0 as 0) of the used `coords` into `points` in order of
/// first use; returns each coordinate's point id (`u32::MAX` for unused ones).
fn weld(coords: &[[f64; 3]], points: &mut Vec<P3>) -> Vec<u32> {
    let mut ids = std::collections::HashMap::<[u64; 3], u32>::with_capacity(coords.len());
    coords
        .iter()
        .map(|c| {
            let p = c.map(|x| x + 0.0);
            *ids.entry(p.map(f64::to_bits)).or_insert_with(|| {
                points.push(P3::from(p));
                (points.len() - 1) as u32
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::PrimitiveKind;

    fn quad_faces() -> Faces {
        let mut f = Faces::new();
        let a = f.object("a");
        let b = f.object("a");
        for p in [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ] {
            f.vertex(p);
        }
        f.face([0, 1, 2, 3], b);
        f.face([0, 1], a);
        f.face([0, 1, 2], a);
        f
    }

    #[test]
    fn names_are_made_unique_and_ids_follow_first_appearance() {
        let f = quad_faces();
        assert_eq!(f.names, ["a", "a.2"]);
        assert_eq!((f.len(), f.short), (2, 1));
        let b = build("q.stl", f, &LoadOptions::default(), Up::Z, &Stop::new()).unwrap();
        assert_eq!(b.scene.len(), 2);
        assert_eq!(b.scene.objects, [0, 1]);
        assert_eq!(b.names, ["a.2", "a"]);
        assert_eq!(
            b.warnings,
            ["q.stl: dropped 1 degenerate faces (fewer than 3 distinct vertices or zero area)"]
        );
    }

    #[test]
    fn y_up_turns_plus_y_to_plus_z() {
        let b = build(
            "q.glb",
            quad_faces(),
            &LoadOptions::default(),
            Up::Y,
            &Stop::new(),
        )
        .unwrap();
        assert!(b.scene.points.iter().all(|p| p.z >= 0.0 && p.y == 0.0));
        assert!(b.scene.points.iter().any(|p| p.z == 1.0));
    }

    #[test]
    fn bad_coordinates_and_empty_files_are_one_line_errors() {
        let mut f = quad_faces();
        f.coords[2][1] = f64::NAN;
        let e = build("q.ply", f, &LoadOptions::default(), Up::Z, &Stop::new()).unwrap_err();
        assert_eq!(e.kind, LoadErrorKind::NonFinite);
        assert!(e.problem.starts_with("vertex 3 has a non-finite"), "{e}");
        let e = build(
            "q.ply",
            Faces::new(),
            &LoadOptions::default(),
            Up::Z,
            &Stop::new(),
        )
        .unwrap_err();
        assert_eq!(
            (e.kind, e.problem.as_str()),
            (LoadErrorKind::NoFaces, "no faces")
        );
    }

    #[test]
    fn polyhedra_mode_makes_one_polyhedron_per_object() {
        let mut f = Faces::new();
        let o = f.object("tet");
        for p in [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ] {
            f.vertex(p);
        }
        for t in [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]] {
            f.face(t, o);
        }
        let opts = LoadOptions {
            polyhedra: true,
            strict: true,
            up: None,
        };
        let b = build("t.stl", f, &opts, Up::Z, &Stop::new()).unwrap();
        assert_eq!(b.scene.len(), 1);
        assert_eq!(b.scene.kind, Some(PrimitiveKind::Polyhedron));
        assert_eq!(b.scene.labels, ["tet"]);
    }
}
