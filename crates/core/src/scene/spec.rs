//! Scenes named on a command line: a scene file (OBJ, STL, PLY, OFF, glTF, URDF), or a generated
//! scene as `KIND[:COUNT]`
//! (`wraptree bench`, `sweep`).

use super::Scene;
use super::generate;
use super::input::{Format, LoadOptions, Loaded};
use super::load::{load_bytes, load_path};
use anyhow::{Result, anyhow};
use std::path::Path;

/// Loads a scene file (any format [`super::load`] reads), or generates `KIND[:COUNT]` (COUNT = triangles for `soup`, copies for
/// `lamps`/`robot-bases`; see [`generate::by_name`]),
/// seed 1, named after the spec (`soup:300` → `soup-300`). Returns the scene and the loader's
/// warnings.
///
/// ```
/// let (scene, warnings) = wraptree_core::scene::spec::scene_spec("soup:300").unwrap();
/// assert_eq!((scene.len(), scene.name.as_str()), (300, "soup-300"));
/// assert!(warnings.is_empty());
/// ```
pub fn scene_spec(spec: &str) -> Result<(Scene, Vec<String>)> {
    let path = Path::new(spec);
    if path.exists() || Format::is_scene_file(spec) {
        let loaded = load_path(path, &LoadOptions::default())?;
        return Ok((loaded.scene, loaded.warnings));
    }
    let (kind, count) = match spec.split_once(':') {
        Some((k, c)) => {
            let c: usize = c
                .parse()
                .map_err(|_| anyhow!("{spec}: COUNT must be a whole number"))?;
            (k, Some(c))
        }
        None => (spec, None),
    };
    let (copies, n) = if kind == "soup" {
        (None, count)
    } else {
        (count, None)
    };
    let mut scene = generate::by_name(kind, copies, n, 1)
        .map_err(|e| anyhow!("{spec}: not a file, and {e}"))?;
    scene.name = spec.replace(':', "-");
    Ok((scene, Vec::new()))
}

/// A generated scene as if loaded from its OBJ text, so that recordings can embed it.
pub fn as_loaded(scene: &Scene) -> Result<Loaded> {
    let mut bytes = Vec::new();
    scene.write_obj(&mut bytes)?;
    Ok(load_bytes(
        &format!("{}.obj", scene.name),
        bytes,
        &LoadOptions::default(),
    )?)
}
