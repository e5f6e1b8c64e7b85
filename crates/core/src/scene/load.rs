//! Loading a scene file of any supported format, chosen by the file name's extension.
//!
//! | extension | format | read by |
//! |---|---|---|
//! | `.stl` | STL, binary or ASCII (one object per `solid`) | [`super::stl`] (`stl_io`) |
//! | `.ply` | PLY, ASCII or binary, faces of any size | [`super::ply`] (`ply-rs-bw`) |
//! | `.off` | OFF, ASCII, faces of any size | [`super::off`] (read here: `f64` coordinates) |
//! | `.gltf`, `.glb` | glTF 2.0: the default scene's triangle meshes, node transforms applied | [`super::gltf`] (`gltf`) |
//! | `.dae` | COLLADA: the visual scene's triangle meshes, node transforms and `<unit>` applied, turned by its `<up_axis>` | [`super::dae`] (`mesh-loader`, `roxmltree`) |
//! | `.urdf` | a robot: each link's meshes and shapes placed by its joints | [`super::urdf`] (`urdf-rs`) |
//! | `.xacro` | refused with a one-line error saying what to do | |
//! | anything else | Wavefront OBJ | [`super::obj`] (`tobj`) |
//!
//! The one choice of reader is here and in `mesh.rs` (for the mesh formats, which a URDF refers
//! to too): a standalone OBJ goes its own way ([`super::obj`]: groups, `f64`, streaming), a URDF
//! to [`super::urdf`], every other file to `mesh.rs`. The types they share are in
//! [`super::input`], below them all.
//!
//! Every format ends in the same rules (`faces.rs`): each face is one convex polygon
//! (non-planar or non-convex faces split into triangles, degenerate ones dropped, one warning
//! per kind), or with [`LoadOptions::polyhedra`] each object one convex polyhedron; vertices with
//! bit-identical positions are merged; the scene is turned so that the file's up axis
//! ([`LoadOptions::up`]) is +Z. Bad input gives one [`LoadError`] line naming the file.
//!
//! A loaded scene keeps its source ([`SceneSource`]) so that recordings can embed it. A
//! single-file input is kept byte for byte; a URDF, or a `.gltf` whose buffers are separate
//! files, is kept as the OBJ text of the loaded scene (one `o` per object) and the returned scene
//! is that OBJ loaded back, so that a recording re-creates it exactly without the original files.

use std::path::{Path, PathBuf};

// The loading API's types, also at this path (they live in `input.rs`).
pub use super::input::{
    Format, LoadError, LoadErrorKind, LoadOptions, Loaded, MAX_COORDINATE, SceneSource, Up,
};
use super::input::{one_line, read_file, source};
use super::urdf::UrdfOptions;
use super::{export, mesh, obj, urdf};
use crate::stop::Stop;

/// Reads and loads the scene file at `path`; errors name the path as given.
pub fn load_path(path: &Path, opts: &LoadOptions) -> Result<Loaded, LoadError> {
    load_path_with(path, opts, &UrdfOptions::default())
}

/// [`load_path`], with how to pose a URDF and where to find its meshes.
pub fn load_path_with(
    path: &Path,
    opts: &LoadOptions,
    urdf: &UrdfOptions,
) -> Result<Loaded, LoadError> {
    load_path_until(path, opts, urdf, &Stop::new())
}

/// [`load_path_with`], its long loops checking `stop` (Err: kind
/// [`LoadErrorKind::Interrupted`]).
pub fn load_path_until(
    path: &Path,
    opts: &LoadOptions,
    urdf: &UrdfOptions,
    stop: &Stop,
) -> Result<Loaded, LoadError> {
    let shown = path.display().to_string();
    let bytes = read_file(path).map_err(|problem| LoadError {
        file: shown.clone(),
        kind: LoadErrorKind::Read,
        problem,
    })?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| shown.clone());
    let dir = path.parent().map(|d| {
        if d.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            d.to_path_buf()
        }
    });
    load_in(&name, bytes, opts, dir.as_deref(), urdf, stop)
        .map_err(|e| LoadError { file: shown, ..e })
}

/// Loads the bytes of a file named `file_name` (the format is its extension's; the scene is
/// named after its stem). A file that refers to others (a URDF's meshes, a `.gltf`'s `.bin`
/// buffers) cannot be loaded this way: load it with [`load_path`].
///
/// Deterministic: the same bytes and options always give the same scene and warnings.
pub fn load_bytes(
    file_name: &str,
    bytes: Vec<u8>,
    opts: &LoadOptions,
) -> Result<Loaded, LoadError> {
    load_bytes_until(file_name, bytes, opts, &Stop::new())
}

/// [`load_bytes`], its long loops checking `stop` (Err: kind [`LoadErrorKind::Interrupted`]).
pub fn load_bytes_until(
    file_name: &str,
    bytes: Vec<u8>,
    opts: &LoadOptions,
    stop: &Stop,
) -> Result<Loaded, LoadError> {
    load_in(file_name, bytes, opts, None, &UrdfOptions::default(), stop)
}

/// Loads `bytes` named `file_name`, with the directory of the files it refers to (`None`: it
/// may refer to none), warning of coincident primitives ([`super::coincident`]).
fn load_in(
    file_name: &str,
    bytes: Vec<u8>,
    opts: &LoadOptions,
    dir: Option<&Path>,
    urdf_opts: &UrdfOptions,
    stop: &Stop,
) -> Result<Loaded, LoadError> {
    let mut loaded = load_format(file_name, bytes, opts, dir, urdf_opts, stop)?;
    let interrupted = |_| LoadError::interrupted(file_name);
    stop.check().map_err(interrupted)?;
    loaded
        .warnings
        .extend(super::coincident::warning(file_name, &loaded.scene));
    stop.check().map_err(interrupted)?;
    Ok(loaded)
}

/// [`load_in`] by the file's format.
fn load_format(
    file_name: &str,
    bytes: Vec<u8>,
    opts: &LoadOptions,
    dir: Option<&Path>,
    urdf_opts: &UrdfOptions,
    stop: &Stop,
) -> Result<Loaded, LoadError> {
    let format = Format::of(file_name).map_err(|problem| LoadError {
        file: file_name.to_string(),
        kind: LoadErrorKind::Unsupported,
        problem,
    })?;
    if format == Format::Obj {
        return obj::load(file_name, bytes, opts, stop);
    }
    // Names from the file (links, solids, nodes) may hold line breaks: one line, whatever.
    load_other(file_name, format, bytes, opts, dir, urdf_opts, stop).map_err(|e| LoadError {
        problem: one_line(&e.problem, 1000),
        ..e
    })
}

/// [`load_in`] for a URDF or a mesh file other than OBJ.
fn load_other(
    file_name: &str,
    format: Format,
    bytes: Vec<u8>,
    opts: &LoadOptions,
    dir: Option<&Path>,
    urdf_opts: &UrdfOptions,
    stop: &Stop,
) -> Result<Loaded, LoadError> {
    let read = if format == Format::Urdf {
        let (faces, warnings) = urdf::read(file_name, &bytes, dir, urdf_opts)?;
        mesh::Mesh {
            faces,
            up: None,
            external: true,
            warnings,
        }
    } else {
        mesh::read(file_name, format, &bytes, dir)?
    };
    let up = opts.up.or(read.up).unwrap_or(format.default_up());
    stop.check()
        .map_err(|_| LoadError::interrupted(file_name))?;
    let built = super::faces::build(file_name, read.faces, opts, up, stop)?;
    let mut warnings = read.warnings;
    warnings.extend(built.warnings);
    if read.external {
        return export::converted(file_name, &built.scene, &built.names, opts, warnings, stop);
    }
    Ok(Loaded {
        scene: built.scene,
        source: source(file_name, bytes, *opts),
        warnings,
    })
}
