//! A loaded scene written as one self-describing OBJ file, the form in which a multi-file input
//! (a URDF and its meshes, a `.gltf` with separate buffers) is embedded in recordings.
//!
//! [`obj_text`] writes every point with the shortest decimal that reads back to the same
//! `f64`, and each primitive as a face (a polygon) or as an `o` block of its hull triangles (a
//! polyhedron), with an `o NAME` line wherever the object changes, so loading the text with
//! the same polygon/polyhedra option gives the same primitives, objects and object names.
//! `converted` does that and returns the scene loaded back from the text, so what a recording
//! embeds is exactly what was grouped.

use super::input::{LoadError, LoadOptions, Loaded};
use super::obj_writer::{ObjWriter, write_scene};
use super::{PrimitiveKind, Scene, obj};
use crate::geom::P3;
use crate::stop::Stop;

/// The OBJ text of `scene`, whose object `k` is named `names[k]` (`object<k>` past the end).
/// `what` is written in the first comment line.
pub fn obj_text(scene: &Scene, names: &[String], what: &str) -> Vec<u8> {
    let out = Vec::with_capacity(scene.points.len() * 40 + scene.prim_points.len() * 8);
    let comment = format!(
        "{what}: {} primitives, written by wraptree {}",
        scene.len(),
        env!("CARGO_PKG_VERSION")
    );
    let name = |k: u32| {
        names
            .get(k as usize)
            .cloned()
            .unwrap_or_else(|| format!("object{k}"))
    };
    let poly = scene.kind == Some(PrimitiveKind::Polyhedron);
    // Writing to a Vec cannot fail.
    let mut w = ObjWriter::new(out, &comment).expect("writing to memory");
    write_scene(
        &mut w,
        scene,
        // `+ 0.0`: -0 is written as 0 (the loader merges them anyway).
        |p| P3::new(p.x + 0.0, p.y + 0.0, p.z + 0.0),
        |i| {
            (poly || i == 0 || scene.object(i) != scene.object(i - 1))
                .then(|| name(scene.object(i)))
        },
    )
    .expect("writing to memory");
    w.into_inner()
}

/// The scene of the multi-file input `file_name` as a [`Loaded`] whose source is its OBJ text
/// `<stem>.obj` (loaded with `opts` less the up axis: the text is already Z-up), and whose scene
/// is that text loaded back. `warnings` are the original load's.
pub(super) fn converted(
    file_name: &str,
    scene: &Scene,
    names: &[String],
    opts: &LoadOptions,
    warnings: Vec<String>,
    stop: &Stop,
) -> Result<Loaded, LoadError> {
    let text = obj_text(scene, names, &format!("{file_name} as loaded"));
    let obj_name = format!("{}.obj", scene.name);
    let opts = LoadOptions { up: None, ..*opts };
    let mut loaded = obj::load(&obj_name, text, &opts, stop).map_err(|e| LoadError {
        file: file_name.to_string(),
        problem: format!(
            "the scene does not load back from its OBJ form ({})",
            e.problem
        ),
        ..e
    })?;
    loaded.warnings = warnings;
    Ok(loaded)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load_bytes;

    #[test]
    fn the_text_loads_back_to_the_same_primitives_and_objects() {
        for polyhedra in [false, true] {
            let opts = LoadOptions {
                polyhedra,
                ..LoadOptions::default()
            };
            let obj =
                b"v 0.1 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 0.3 0.3 0.3\no a b\nf 1 2 3\nf 1 2 4\n\
                        f 1 3 4\nf 2 3 4\no c\nf 2 3 5\nf 2 5 4\nf 3 5 4\nf 2 3 4\n";
            let a = load_bytes("x.obj", obj.to_vec(), &opts).unwrap();
            let names = ["a b".to_string(), "c".to_string()];
            let text = obj_text(&a.scene, &names, "test");
            let b = load_bytes("x.obj", text, &opts).unwrap();
            assert_eq!(a.scene.len(), b.scene.len());
            assert_eq!(a.scene.objects, b.scene.objects);
            assert_eq!(a.scene.aabb(), b.scene.aabb());
            if polyhedra {
                assert_eq!(b.scene.labels, names);
            }
        }
    }
}
