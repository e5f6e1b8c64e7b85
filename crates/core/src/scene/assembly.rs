//! Assemblies of real parts: `--part FILE:COUNT` rigid copies of each part at its own scale,
//! each randomly rotated and placed in a cell of its own on a jittered grid, so that copies do
//! not overlap (every cell holds its copy's bounding sphere). Deterministic for a seed.
//!
//! ```
//! use wraptree_core::scene::assembly::{Part, assemble};
//! let part = Part { scene: wraptree_core::scene::generate::lamp(), copies: 3 };
//! let (scene, names) = assemble(&[part], 7).unwrap();
//! assert_eq!(scene.len(), 3 * wraptree_core::scene::generate::lamp().len());
//! assert_eq!(names.len(), 3);
//! ```

use super::Scene;
use super::generate::random_rotation;
use super::load::{LoadOptions, load_path};
use crate::geom::{P3, V3};
use rand::{Rng, SeedableRng, seq::SliceRandom};
use rand_chacha::ChaCha8Rng;
use std::path::PathBuf;

/// A part and how many copies of it to place.
#[derive(Clone, Debug)]
pub struct Part {
    /// The part, as loaded.
    pub scene: Scene,
    /// Its number of copies, at least 1.
    pub copies: usize,
}

/// Splits a `FILE:COUNT` part spec (the count after the last `:`).
pub fn parse_part(spec: &str) -> Result<(PathBuf, usize), String> {
    let bad = |why: &str| format!("--part {spec}: {why} (expected FILE:COUNT, e.g. link.obj:12)");
    let (file, count) = spec.rsplit_once(':').ok_or_else(|| bad("no :COUNT"))?;
    if file.is_empty() {
        return Err(bad("no file"));
    }
    let copies: usize = count
        .parse()
        .map_err(|_| bad(&format!("count '{count}' is not a whole number")))?;
    if copies == 0 {
        return Err(bad("count must be at least 1"));
    }
    Ok((PathBuf::from(file), copies))
}

/// Loads the part of a `FILE:COUNT` spec (any scene format the loader reads, one polygon per
/// face); an empty part is an error.
pub fn load_part(spec: &str) -> Result<Part, String> {
    let (file, copies) = parse_part(spec)?;
    let loaded = load_path(&file, &LoadOptions::default()).map_err(|e| e.to_string())?;
    if loaded.scene.is_empty() {
        return Err(format!("{}: the part has no primitives", file.display()));
    }
    Ok(Part {
        scene: loaded.scene,
        copies,
    })
}

/// The assembly of `parts` and the name of each copy (`{part}_{k}`, index = object id).
///
/// Copies are shuffled over the cells of a cubic grid whose cell is 1.1 × the largest part's
/// box diagonal; each copy is rotated about its box centre by a uniformly random rotation and
/// centred in its cell, jittered by up to the room its bounding sphere leaves there. Primitives
/// keep their part's order within a copy; copies are in part order. Err: the vertices would
/// not fit u32 indices.
pub fn assemble(parts: &[Part], seed: u64) -> Result<(Scene, Vec<String>), String> {
    let points: usize = parts
        .iter()
        .map(|p| p.scene.points.len().saturating_mul(p.copies))
        .fold(0, usize::saturating_add);
    if points > u32::MAX as usize {
        return Err(format!("assembly too large ({points} vertices)"));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let boxes: Vec<(P3, f64)> = parts
        .iter()
        .map(|p| {
            let b = p.scene.aabb();
            (b.center(), b.diameter())
        })
        .collect();
    let cell = 1.1 * boxes.iter().map(|b| b.1).fold(0.0, f64::max);
    let total: usize = parts.iter().map(|p| p.copies).sum();
    let side = (1..).find(|s: &usize| s.pow(3) >= total).unwrap_or(1);
    let mut cells: Vec<usize> = (0..side.pow(3)).collect();
    cells.shuffle(&mut rng);
    let mut out = Scene::new("assembly");
    let mut names = Vec::with_capacity(total);
    let mut slot = cells.into_iter();
    for (part, &(centre, diam)) in parts.iter().zip(&boxes) {
        let scene = &part.scene;
        let stem = scene.name.clone();
        for k in 0..part.copies {
            let c = slot.next().unwrap_or(0);
            let grid = V3::new(
                (c % side) as f64,
                ((c / side) % side) as f64,
                (c / (side * side)) as f64,
            );
            let room = 0.5 * (cell - diam);
            let jitter: [f64; 3] = rng.random();
            let at = grid * cell + V3::from(jitter.map(|x| (2.0 * x - 1.0) * room));
            let rot = random_rotation(&mut rng);
            let object = names.len() as u32;
            out.append_copy(scene, |p| P3::from(at) + rot * (p - centre), object);
            names.push(format!("{stem}_{k}"));
        }
    }
    Ok((out, names))
}
