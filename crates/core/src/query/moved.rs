//! Rigidly moved copies of a tree, its scene and its spheres: the second object of a
//! scene–scene query.

use crate::geom::Aabb;
use crate::grouping::SubsetTree;
use crate::scene::Scene;
use crate::wrap::Sphere;
use nalgebra::Isometry3;

/// A copy of `tree` and `scene` moved by `pose`: every vertex mapped by `pose`, the same
/// topology, and the AABBs refitted bottom-up in `f64` (each leaf's box from its moved
/// vertices, each interior box the union of its children's). Diameters are copied: the
/// diameters of hull p-sets do not change under a rigid motion; those of AABB p-sets are the
/// build-time values (queries do not use them).
pub fn moved(tree: &SubsetTree, scene: &Scene, pose: &Isometry3<f64>) -> (SubsetTree, Scene) {
    let mut s = scene.clone();
    for p in &mut s.points {
        *p = pose * *p;
    }
    let n = tree.leaves();
    let mut aabb: Vec<Aabb> = Vec::with_capacity(tree.len());
    aabb.extend((0..n).map(|i| s.prim_aabb(i)));
    for [a, b] in &tree.children {
        let m = aabb[*a as usize].merge(&aabb[*b as usize]);
        aabb.push(m);
    }
    let mut t = tree.clone();
    t.aabb = aabb;
    (t, s)
}

/// Spheres moved by `pose`: centres mapped, radii kept (exact up to the rounding of the centre).
pub fn moved_spheres(spheres: &[Sphere], pose: &Isometry3<f64>) -> Vec<Sphere> {
    spheres
        .iter()
        .map(|s| Sphere {
            center: pose * s.center,
            radius: s.radius,
        })
        .collect()
}
