//! Loading a scene file of any supported format, chosen by the file name's extension.
//!
//! | extension | format | read by |
//! |---|---|---|
//! | `.stl` | STL, binary or ASCII (one object per `solid`) | [`super::stl`] (`stl_io`) |
//! | `.ply` | PLY, ASCII or binary, faces of any size | [`super::ply`] (`ply-rs-bw`) |
//! | `.off` | OFF, ASCII, faces of any size | [`super::off`] (read here: `f64` coordinates) |
//! | `.gltf`, `.glb` | glTF 2.0: the default scene's triangle meshes, node transforms applied | [`super::gltf`] (`gltf`) |
//! | `.urdf` | a robot: each link's meshes and shapes placed by its joints | [`super::urdf`] (`urdf-rs`) |
//! | `.dae`, `.xacro` | refused with a one-line error saying what to do | |
//! | anything else | Wavefront OBJ | [`super::obj`] (`tobj`) |
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

use std::fmt;
use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use super::faces::Faces;
use super::urdf::UrdfOptions;
use super::{Scene, export, gltf, obj, off, ply, stl, urdf};
use crate::stop::{Interrupted, Stop};

/// Which axis of a file points up. The loader turns the scene so that it is +Z, the up axis
/// of the recordings and snapshots.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum Up {
    /// +Y is up (glTF, many OBJ exports): turned by +90° about X, so (x, y, z) → (x, −z, y).
    Y,
    /// +Z is up (URDF, CAD, the recordings): kept as it is.
    Z,
}

impl Up {
    /// The name used on the command line and in recordings (`y`, `z`).
    pub fn name(self) -> &'static str {
        match self {
            Up::Y => "y",
            Up::Z => "z",
        }
    }
}

impl std::str::FromStr for Up {
    type Err = String;

    fn from_str(s: &str) -> Result<Up, String> {
        match s {
            "y" | "Y" => Ok(Up::Y),
            "z" | "Z" => Ok(Up::Z),
            _ => Err(format!("up axis must be y or z, not {s:?}")),
        }
    }
}

/// How to turn a file into primitives. These are the options a recording stores to load its
/// embedded scene again.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
pub struct LoadOptions {
    /// One convex polyhedron per object (OBJ `o`/`g`, STL `solid`, glTF node, URDF link)
    /// instead of one polygon per face.
    pub polyhedra: bool,
    /// With `polyhedra`: an object whose vertices are not in convex position is an error
    /// instead of being replaced by its convex hull with a warning.
    pub strict: bool,
    /// The file's up axis; `None`: the format's ([`Format::default_up`]: Y for glTF, Z for the
    /// others).
    #[serde(default)]
    pub up: Option<Up>,
}

/// The exact input of a loaded scene, kept so recordings can re-create it.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct SceneSource {
    /// File name (no directory), e.g. `mug.obj`; `<stem>.obj` for a converted URDF or glTF.
    pub file_name: String,
    /// The file's bytes, verbatim, or the OBJ text a multi-file input was converted to.
    pub bytes: Vec<u8>,
    /// The options that load `bytes` into the scene.
    pub options: LoadOptions,
    /// Lowercase hex SHA-256 of `bytes`.
    pub sha256: String,
}

/// A loaded scene, its source and the warnings raised while loading it.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The primitives.
    pub scene: Scene,
    /// What it was loaded from.
    pub source: SceneSource,
    /// One line per kind of repair (dropped, split or hulled primitives), naming the file.
    pub warnings: Vec<String>,
}

/// What went wrong while loading.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadErrorKind {
    /// The file (or a file it refers to) could not be read.
    Read,
    /// The bytes are not a well-formed file of their format.
    Malformed,
    /// A vertex has a NaN, infinite or absurdly large coordinate.
    NonFinite,
    /// A face refers to a vertex that does not exist.
    BadIndex,
    /// Nothing usable: no faces, or only degenerate ones.
    NoFaces,
    /// `--strict --polyhedra` and an object is not in convex position.
    NotConvex,
    /// A format or feature wraptree does not read (COLLADA, xacro, compressed glTF meshes).
    Unsupported,
    /// A [`Stop`] was requested while loading; the error's source is [`Interrupted`].
    Interrupted,
}

/// A loading failure; its `Display` is one line `FILE: PROBLEM`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoadError {
    /// The file as the user named it.
    pub file: String,
    /// The category of the problem.
    pub kind: LoadErrorKind,
    /// The problem, one line, with the line number (text formats) where known.
    pub problem: String,
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.file, self.problem)
    }
}

impl std::error::Error for LoadError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        (self.kind == LoadErrorKind::Interrupted).then_some(&Interrupted as _)
    }
}

impl LoadError {
    /// The error of a load of `file` that obeyed a [`Stop`].
    pub(crate) fn interrupted(file: &str) -> LoadError {
        LoadError {
            file: file.to_string(),
            kind: LoadErrorKind::Interrupted,
            problem: Interrupted.to_string(),
        }
    }
}

/// Largest accepted coordinate magnitude: squared distances must stay finite in `f64`.
pub const MAX_COORDINATE: f64 = 1e100;

/// A file format, told by the file name's extension (case-insensitive).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ (every extension not listed below).
    Obj,
    /// STL, binary or ASCII.
    Stl,
    /// PLY, ASCII or binary.
    Ply,
    /// OFF (Object File Format), ASCII.
    Off,
    /// glTF 2.0 JSON (`.gltf`).
    Gltf,
    /// glTF 2.0 binary (`.glb`).
    Glb,
    /// URDF robot description.
    Urdf,
}

impl Format {
    /// The format of `file_name`; Err: an extension wraptree refuses (`.dae`, `.xacro`), with
    /// the reason.
    pub fn of(file_name: &str) -> Result<Format, String> {
        let ext = Path::new(file_name)
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        Ok(match ext.as_str() {
            "stl" => Format::Stl,
            "ply" => Format::Ply,
            "off" => Format::Off,
            "gltf" => Format::Gltf,
            "glb" => Format::Glb,
            "urdf" => Format::Urdf,
            "dae" => {
                return Err(
                    "COLLADA (.dae) files are not read: convert it to STL, OBJ, PLY or \
                            glTF (e.g. with Blender or assimp)"
                        .into(),
                );
            }
            "xacro" => {
                return Err("a xacro macro file: expand it to a URDF first \
                            (`xacro FILE > robot.urdf`)"
                    .into());
            }
            _ => Format::Obj,
        })
    }

    /// The up axis the format defines: Y for glTF (its specification), Z for URDF (ROS) and for
    /// OBJ, STL, PLY and OFF, which define none (files made for robotics and CAD are Z-up).
    pub fn default_up(self) -> Up {
        match self {
            Format::Gltf | Format::Glb => Up::Y,
            _ => Up::Z,
        }
    }

    /// Whether a file of this format names `file_name` (case-insensitive extension), for
    /// command lines that take a scene file or a generated scene's name.
    pub fn is_scene_file(file_name: &str) -> bool {
        let ext = Path::new(file_name)
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        matches!(
            ext.as_deref(),
            Some("obj" | "stl" | "ply" | "off" | "gltf" | "glb" | "urdf" | "dae" | "xacro")
        )
    }
}

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

/// Reads `path`, the error as one line without the OS error number.
pub(super) fn read_file(path: &Path) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| {
        let msg = e.to_string();
        let msg = msg.split(" (os error").next().unwrap_or(&msg).to_string();
        format!("cannot read: {msg}")
    })
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
    let err = |kind, problem: String| LoadError {
        file: file_name.to_string(),
        kind,
        problem,
    };
    let format = Format::of(file_name).map_err(|p| err(LoadErrorKind::Unsupported, p))?;
    if format == Format::Obj {
        return obj::load(file_name, bytes, opts, stop);
    }
    // Names from the file (links, solids, nodes) may hold line breaks: one line, whatever.
    load_other(file_name, format, bytes, opts, dir, urdf_opts, stop).map_err(|e| LoadError {
        problem: one_line(&e.problem, 1000),
        ..e
    })
}

/// [`load_in`] for the formats other than OBJ.
fn load_other(
    file_name: &str,
    format: Format,
    bytes: Vec<u8>,
    opts: &LoadOptions,
    dir: Option<&Path>,
    urdf_opts: &UrdfOptions,
    stop: &Stop,
) -> Result<Loaded, LoadError> {
    let up = opts.up.unwrap_or(format.default_up());
    let (faces, converted, mut warnings) = match format {
        Format::Obj => return obj::load(file_name, bytes, opts, stop),
        Format::Stl => (stl::read(file_name, &bytes)?, false, Vec::new()),
        Format::Ply => (ply::read(file_name, &bytes)?, false, Vec::new()),
        Format::Off => (off::read(file_name, &bytes)?, false, Vec::new()),
        Format::Gltf | Format::Glb => {
            let read = gltf::read(file_name, &bytes, dir)?;
            (read.faces, read.external, read.warnings)
        }
        Format::Urdf => {
            let (faces, warnings) = urdf::read(file_name, &bytes, dir, urdf_opts)?;
            (faces, true, warnings)
        }
    };
    stop.check()
        .map_err(|_| LoadError::interrupted(file_name))?;
    let built = super::faces::build(file_name, faces, opts, up, stop)?;
    warnings.extend(built.warnings);
    if converted {
        return export::converted(file_name, &built.scene, &built.names, opts, warnings, stop);
    }
    Ok(Loaded {
        scene: built.scene,
        source: source(file_name, bytes, *opts),
        warnings,
    })
}

/// The [`SceneSource`] of `bytes`.
pub(super) fn source(file_name: &str, bytes: Vec<u8>, options: LoadOptions) -> SceneSource {
    let sha256 = Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    SceneSource {
        file_name: file_name.to_string(),
        bytes,
        options,
        sha256,
    }
}

/// The faces of a mesh file that another file refers to (a URDF's meshes), in the file's own
/// coordinates (no up-axis turn). `dir` is where the mesh's own references (a `.gltf`'s
/// buffers) are looked up.
pub(super) fn mesh_faces(
    file_name: &str,
    bytes: Vec<u8>,
    dir: Option<&Path>,
) -> Result<(Faces, Vec<String>), LoadError> {
    let err = |kind, problem: String| LoadError {
        file: file_name.to_string(),
        kind,
        problem,
    };
    let format = Format::of(file_name).map_err(|p| err(LoadErrorKind::Unsupported, p))?;
    Ok(match format {
        Format::Obj => (obj::read_faces(file_name, bytes)?, Vec::new()),
        Format::Stl => (stl::read(file_name, &bytes)?, Vec::new()),
        Format::Ply => (ply::read(file_name, &bytes)?, Vec::new()),
        Format::Off => (off::read(file_name, &bytes)?, Vec::new()),
        Format::Gltf | Format::Glb => {
            let read = gltf::read(file_name, &bytes, dir)?;
            (read.faces, read.warnings)
        }
        Format::Urdf => {
            return Err(err(
                LoadErrorKind::Unsupported,
                "a URDF is not a mesh".to_string(),
            ));
        }
    })
}

/// A problem message cut to one line of at most `max` characters: line breaks and tabs become
/// spaces, runs of spaces one.
pub(super) fn one_line(msg: &str, max: usize) -> String {
    let mut out = String::with_capacity(msg.len().min(max + 3));
    let mut space = false;
    for c in msg.chars() {
        if c.is_whitespace() || c.is_control() {
            space = !out.is_empty();
            continue;
        }
        if space {
            out.push(' ');
            space = false;
        }
        if out.chars().count() >= max {
            out.push('…');
            break;
        }
        out.push(c);
    }
    out
}
