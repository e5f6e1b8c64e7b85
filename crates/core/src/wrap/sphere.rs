//! Bounding-sphere Wrapper Trees.

use crate::geom::{P3, Sphere};
use crate::grouping::SubsetTree;
use crate::scene::Scene;
use crate::stop::{Interrupted, Stop};
use crate::wrap::{LeafOrder, welzl};

/// How a sphere Wrapper Tree is computed.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum SphereMethod {
    /// Merge the children's spheres (O(N), loosest).
    Merged,
    /// Centre at the node's AABB centre, radius to the farthest leaf vertex (the paper's choice).
    #[default]
    AabbCenter,
    /// Ritter's approximation over the leaves' vertices (O(n) per node).
    Ritter,
    /// The exact minimum enclosing sphere of the leaves' vertices (Welzl, O(n) expected per
    /// node).
    #[value(alias = "welzl")]
    Minimum,
}

/// One sphere per Subset Tree node (index = node id), each holding every vertex below it.
///
/// `Merged` is O(N); the others visit every leaf vertex once per ancestor, O(N log N) for a
/// tree of depth O(log N) (§2.4). All are `f64`; every radius is at least the distance from
/// the centre to the farthest vertex below, so containment is exact up to rounding.
pub fn sphere_tree(tree: &SubsetTree, scene: &Scene, method: SphereMethod) -> Vec<Sphere> {
    match sphere_tree_until(tree, scene, method, &Stop::new()) {
        Ok(spheres) => spheres,
        Err(Interrupted) => unreachable!("a new stop token is never set"),
    }
}

/// [`sphere_tree`], checking `stop` at every node of the per-node methods, else every
/// [`STRIDE`](crate::stop::STRIDE) leaves.
pub fn sphere_tree_until(
    tree: &SubsetTree,
    scene: &Scene,
    method: SphereMethod,
    stop: &Stop,
) -> Result<Vec<Sphere>, Interrupted> {
    let per_node = |f: fn(&[P3]) -> Sphere| {
        let order = LeafOrder::new(tree, scene);
        (0..tree.len() as u32)
            .map(|x| {
                // Every node: a node near the root alone visits most of the scene.
                stop.check()?;
                Ok(f(order.node_points(x)))
            })
            .collect()
    };
    match method {
        SphereMethod::Ritter => return per_node(welzl::ritter_sphere),
        SphereMethod::Minimum => return per_node(welzl::min_sphere),
        SphereMethod::Merged | SphereMethod::AabbCenter => {}
    }
    let n = tree.leaves();
    let mut out: Vec<Sphere> = (0..tree.len())
        .map(|x| Sphere {
            center: tree.aabb[x].center(),
            radius: 0.0,
        })
        .collect();
    for (leaf, s) in out.iter_mut().enumerate().take(n) {
        stop.check_every(leaf)?;
        let c = s.center;
        s.radius = scene
            .prim_vertices(leaf)
            .map(|p| (p - c).norm())
            .fold(0.0, f64::max);
    }
    match method {
        SphereMethod::Merged => {
            for (i, [a, b]) in tree.children.iter().enumerate() {
                out[n + i] = out[*a as usize].merge(&out[*b as usize]);
            }
        }
        SphereMethod::AabbCenter => {
            for leaf in 0..n {
                stop.check_every(leaf)?;
                let mut node = tree.parent[leaf];
                while node != crate::grouping::NONE {
                    let c = out[node as usize].center;
                    let r = scene
                        .prim_vertices(leaf)
                        .map(|p| (p - c).norm())
                        .fold(0.0, f64::max);
                    let s = &mut out[node as usize];
                    s.radius = s.radius.max(r);
                    node = tree.parent[node as usize];
                }
            }
        }
        SphereMethod::Ritter | SphereMethod::Minimum => {}
    }
    Ok(out)
}
