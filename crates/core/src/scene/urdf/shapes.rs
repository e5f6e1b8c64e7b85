//! URDF shapes as meshes of convex polygons, in the shape's own frame (centred on the origin,
//! cylinders and capsules along Z, as URDF defines them).

use std::f64::consts::{PI, TAU};

use crate::scene::faces::Faces;

/// Sides of a cylinder (and of a capsule's band).
pub const SIDES: usize = 32;
/// Meridians of a sphere or a capsule's half-spheres.
pub const SLICES: usize = 32;
/// Parallels bands of a sphere, pole to pole (a capsule has half as many per half-sphere).
pub const STACKS: usize = 16;

/// Checks that every size is finite and not negative.
fn sizes(what: &str, v: &[f64]) -> Result<(), String> {
    if v.iter().all(|x| x.is_finite() && *x >= 0.0) {
        Ok(())
    } else {
        Err(format!(
            "a {what} with a negative or non-finite size ({v:?})"
        ))
    }
}

/// A box of edge lengths `size`: 6 rectangles.
pub(crate) fn cuboid(size: [f64; 3]) -> Result<Faces, String> {
    sizes("box", &size)?;
    let mut f = Faces::new();
    let o = f.object("box");
    let h = size.map(|s| s / 2.0);
    for k in 0..8 {
        let s = |bit: usize| if k >> bit & 1 == 1 { 1.0 } else { -1.0 };
        f.vertex([s(0) * h[0], s(1) * h[1], s(2) * h[2]]);
    }
    for quad in [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ] {
        f.face(quad, o);
    }
    Ok(f)
}

/// A cylinder of `radius` and `length` along Z: [`SIDES`] rectangles and two [`SIDES`]-gons.
pub(crate) fn cylinder(radius: f64, length: f64) -> Result<Faces, String> {
    sizes("cylinder", &[radius, length])?;
    let mut f = Faces::new();
    let o = f.object("cylinder");
    let ring = |f: &mut Faces, z: f64| -> Vec<u32> {
        (0..SIDES)
            .map(|k| {
                let a = TAU * k as f64 / SIDES as f64;
                f.vertex([radius * a.cos(), radius * a.sin(), z])
            })
            .collect()
    };
    let bottom = ring(&mut f, -length / 2.0);
    let top = ring(&mut f, length / 2.0);
    for k in 0..SIDES {
        let n = (k + 1) % SIDES;
        f.face([bottom[k], bottom[n], top[n], top[k]], o);
    }
    f.face(bottom.iter().rev().copied(), o);
    f.face(top.iter().copied(), o);
    Ok(f)
}

/// A sphere of `radius`: [`SLICES`] × [`STACKS`] polygons.
pub(crate) fn sphere(radius: f64) -> Result<Faces, String> {
    sizes("sphere", &[radius])?;
    let rings: Vec<(f64, f64)> = (1..STACKS)
        .map(|i| {
            let polar = PI * i as f64 / STACKS as f64;
            (radius * polar.cos(), radius * polar.sin())
        })
        .collect();
    Ok(revolved("sphere", radius, -radius, &rings))
}

/// A capsule of `radius` and `length` (of its cylinder part) along Z: two half-spheres of
/// [`STACKS`] / 2 bands and a band of [`SLICES`] rectangles between them.
pub(crate) fn capsule(radius: f64, length: f64) -> Result<Faces, String> {
    sizes("capsule", &[radius, length])?;
    let half = STACKS / 2;
    let h = length / 2.0;
    let mut rings = Vec::new();
    for i in 1..=half {
        let polar = PI * i as f64 / STACKS as f64;
        rings.push((h + radius * polar.cos(), radius * polar.sin()));
    }
    for i in half..STACKS {
        let polar = PI * i as f64 / STACKS as f64;
        rings.push((-h + radius * polar.cos(), radius * polar.sin()));
    }
    Ok(revolved("capsule", h + radius, -h - radius, &rings))
}

/// A surface of revolution about Z from the pole at `top` through `rings` (z, radius) to the
/// pole at `bottom`, with [`SLICES`] meridians: triangles at the poles, quadrilaterals between.
fn revolved(name: &str, top: f64, bottom: f64, rings: &[(f64, f64)]) -> Faces {
    let mut f = Faces::new();
    let o = f.object(name);
    let north = f.vertex([0.0, 0.0, top]);
    let ids: Vec<Vec<u32>> = rings
        .iter()
        .map(|&(z, r)| {
            (0..SLICES)
                .map(|k| {
                    let a = TAU * k as f64 / SLICES as f64;
                    f.vertex([r * a.cos(), r * a.sin(), z])
                })
                .collect()
        })
        .collect();
    let south = f.vertex([0.0, 0.0, bottom]);
    for k in 0..SLICES {
        let n = (k + 1) % SLICES;
        f.face([north, ids[0][k], ids[0][n]], o);
        for w in ids.windows(2) {
            f.face([w[0][k], w[1][k], w[1][n], w[0][n]], o);
        }
        let last = &ids[ids.len() - 1];
        f.face([south, last[n], last[k]], o);
    }
    f
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::faces::build;
    use crate::scene::input::{LoadOptions, Up};
    use crate::stop::Stop;

    fn count(f: Faces) -> usize {
        let b = build("s.urdf", f, &LoadOptions::default(), Up::Z, &Stop::new()).unwrap();
        assert!(b.warnings.is_empty(), "{:?}", b.warnings);
        b.scene.len()
    }

    #[test]
    fn shapes_are_convex_planar_polygons_of_the_stated_counts() {
        assert_eq!(count(cuboid([1.0, 2.0, 3.0]).unwrap()), 6);
        assert_eq!(count(cylinder(0.5, 2.0).unwrap()), SIDES + 2);
        assert_eq!(count(sphere(0.3).unwrap()), SLICES * STACKS);
        assert_eq!(count(capsule(0.3, 1.0).unwrap()), SLICES * (STACKS + 1));
        assert!(cuboid([1.0, -1.0, 1.0]).is_err());
        assert!(sphere(f64::NAN).is_err());
    }
}
