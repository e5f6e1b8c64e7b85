//! What loading takes and gives, shared by every reader of `scene/` and by the dispatcher
//! (`load.rs`): the file formats ([`Format`]), the options ([`LoadOptions`], [`Up`]), the
//! result ([`Loaded`], [`SceneSource`]) and the errors ([`LoadError`]), with the helpers every
//! reader uses to read a file and to keep a problem on one line.

use std::fmt;
use std::path::Path;

use sha2::{Digest, Sha256};

use super::Scene;
use crate::stop::Interrupted;

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
    /// The file's up axis; `None`: the one a COLLADA file names in its `<up_axis>`, else the
    /// format's ([`Format::default_up`]: Y for glTF and COLLADA, Z for the
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
    /// A format or feature wraptree does not read (xacro, compressed glTF meshes, a COLLADA
    /// `<lookat>` or `<skew>` transform).
    Unsupported,
    /// A [`Stop`](crate::stop::Stop) was requested while loading; the error's source is
    /// [`Interrupted`].
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
    /// The error of a load of `file` that obeyed a [`Stop`](crate::stop::Stop).
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
    /// COLLADA 1.4/1.5 (`.dae`): the visual scene's triangle meshes, node transforms applied.
    Dae,
    /// URDF robot description.
    Urdf,
}

impl Format {
    /// The format of `file_name`; Err: an extension wraptree refuses (`.xacro`), with the
    /// reason.
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
            "dae" => Format::Dae,
            "xacro" => {
                return Err("a xacro macro file: expand it to a URDF first \
                            (`xacro FILE > robot.urdf`)"
                    .into());
            }
            _ => Format::Obj,
        })
    }

    /// The up axis the format defines: Y for glTF (its specification) and for COLLADA (its
    /// specification's default, when a file has no `<up_axis>`), Z for URDF (ROS) and for OBJ,
    /// STL, PLY and OFF, which define none (files made for robotics and CAD are Z-up).
    pub fn default_up(self) -> Up {
        match self {
            Format::Gltf | Format::Glb | Format::Dae => Up::Y,
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

/// Reads `path`, the error as one line without the OS error number.
pub(super) fn read_file(path: &Path) -> Result<Vec<u8>, String> {
    std::fs::read(path).map_err(|e| {
        let msg = e.to_string();
        let msg = msg.split(" (os error").next().unwrap_or(&msg).to_string();
        format!("cannot read: {msg}")
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
