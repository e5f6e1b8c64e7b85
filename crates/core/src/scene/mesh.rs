//! One mesh file's faces, read by its format's reader: the choice of mesh reader, made once for
//! a file loaded alone (`load.rs`) and for a URDF's meshes (`urdf.rs`).

use std::path::Path;

use super::faces::Faces;
use super::input::{Format, LoadError, LoadErrorKind, Up};
use super::{dae, gltf, obj, off, ply, stl};

/// A mesh file as read: its faces in the file's own coordinates (not turned to Z-up).
#[derive(Debug)]
pub(crate) struct Mesh {
    /// The faces, one object per part the format names (solid, node, group, geometry).
    pub faces: Faces,
    /// The up axis the file names itself (a COLLADA `<up_axis>`), if any.
    pub up: Option<Up>,
    /// Whether the input refers to other files (a `.gltf`'s buffers, a URDF's meshes): a
    /// recording then embeds the loaded scene's OBJ form, not the file.
    pub external: bool,
    /// One line per kind of thing skipped, naming the file.
    pub warnings: Vec<String>,
}

impl Mesh {
    fn plain(faces: Faces) -> Mesh {
        Mesh {
            faces,
            up: None,
            external: false,
            warnings: Vec::new(),
        }
    }
}

/// The faces of the mesh file `bytes` named `file_name`, of format `format`; `dir` is where
/// the file's own references (a `.gltf`'s buffers) are looked up.
pub(crate) fn read(
    file_name: &str,
    format: Format,
    bytes: &[u8],
    dir: Option<&Path>,
) -> Result<Mesh, LoadError> {
    Ok(match format {
        Format::Obj => Mesh::plain(obj::read_faces(file_name, bytes.to_vec())?),
        Format::Stl => Mesh::plain(stl::read(file_name, bytes)?),
        Format::Ply => Mesh::plain(ply::read(file_name, bytes)?),
        Format::Off => Mesh::plain(off::read(file_name, bytes)?),
        Format::Gltf | Format::Glb => {
            let read = gltf::read(file_name, bytes, dir)?;
            Mesh {
                faces: read.faces,
                up: None,
                external: read.external,
                warnings: read.warnings,
            }
        }
        Format::Dae => {
            let read = dae::read(file_name, bytes)?;
            Mesh {
                faces: read.faces,
                up: read.up,
                external: false,
                warnings: read.warnings,
            }
        }
        Format::Urdf => {
            return Err(LoadError {
                file: file_name.to_string(),
                kind: LoadErrorKind::Unsupported,
                problem: "a URDF is not a mesh".to_string(),
            });
        }
    })
}
