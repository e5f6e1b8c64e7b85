//! Oriented-box Wrapper Trees (beyond the paper): axes from the principal components of the
//! node's hull vertices (or of all its vertices when no hulls are given), extents from
//! projecting every vertex below the node onto them, in `f64`. When the axis-aligned box of the
//! node is smaller (by volume, then by surface), that box is used instead, so an OBB is never
//! looser than the AABB. Degenerate covariances fall back to the world axes ([`Frame`]).

use super::hull::Hull;
use super::order::LeafOrder;
use crate::geom::pca::Frame;
use crate::geom::{Aabb, P3, V3};
use crate::grouping::SubsetTree;
use crate::scene::Scene;
use crate::stop::{Interrupted, Stop};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion};

/// An oriented box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Obb {
    /// Centre.
    pub center: P3,
    /// Unit axes as columns, right-handed.
    pub axes: Matrix3<f64>,
    /// Half extents along the axes (≥ 0).
    pub half: V3,
}

impl Obb {
    /// The tightest box with the axes of `frame` around `points`.
    pub fn fit(frame: &Frame, points: &[P3]) -> Obb {
        let (lo, hi) = frame.bounds(points);
        Obb {
            center: frame.world(&((lo + hi) / 2.0)),
            axes: frame.axes,
            half: (hi - lo) / 2.0,
        }
    }

    /// An axis-aligned box as an OBB.
    pub fn from_aabb(b: &Aabb) -> Obb {
        Obb {
            center: b.center(),
            axes: Matrix3::identity(),
            half: b.extents() / 2.0,
        }
    }

    /// Volume.
    pub fn volume(&self) -> f64 {
        8.0 * self.half.x * self.half.y * self.half.z
    }

    /// Half the surface area (used to break volume ties between flat boxes).
    fn half_area(&self) -> f64 {
        let h = self.half;
        4.0 * (h.x * h.y + h.y * h.z + h.z * h.x)
    }

    /// How far `p` lies outside (largest per-axis excess; ≤ 0 inside).
    pub fn excess(&self, p: &P3) -> f64 {
        let l = self.axes.transpose() * (p - self.center);
        (0..3)
            .map(|k| l[k].abs() - self.half[k])
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Corner `k` (bit `a` of `k` set = top of axis `a`), matching [`super::hull::BOX_TRIANGLES`].
    pub fn corner(&self, k: usize) -> P3 {
        let s = |a: usize| if k >> a & 1 == 1 { 1.0 } else { -1.0 };
        let l = V3::new(s(0) * self.half.x, s(1) * self.half.y, s(2) * self.half.z);
        self.center + self.axes * l
    }

    /// The rotation taking the world axes to the box axes.
    pub fn rotation(&self) -> UnitQuaternion<f64> {
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(self.axes))
    }
}

/// One oriented box per Subset Tree node (index = node id). With `hulls`, the axes come from
/// the PCA of each node's hull vertices; without, from all its vertices.
pub fn obb_tree(tree: &SubsetTree, scene: &Scene, hulls: Option<&[Hull]>) -> Vec<Obb> {
    match obb_tree_until(tree, scene, hulls, &Stop::new()) {
        Ok(obbs) => obbs,
        Err(Interrupted) => unreachable!("a new stop token is never set"),
    }
}

/// [`obb_tree`], checking `stop` at every node.
pub fn obb_tree_until(
    tree: &SubsetTree,
    scene: &Scene,
    hulls: Option<&[Hull]>,
    stop: &Stop,
) -> Result<Vec<Obb>, Interrupted> {
    let order = LeafOrder::new(tree, scene);
    (0..tree.len() as u32)
        .map(|x| {
            // Every node: a node near the root alone visits most of the scene.
            stop.check()?;
            let pts = order.node_points(x);
            let basis = match hulls {
                Some(h) => h[x as usize].vertices.as_slice(),
                _ => pts,
            };
            let obb = Obb::fit(&Frame::principal(basis), pts);
            let aabb = Obb::from_aabb(&crate::geom::Aabb::from_points(pts));
            let key = |b: &Obb| (b.volume(), b.half_area());
            Ok(if key(&aabb) < key(&obb) { aabb } else { obb })
        })
        .collect()
}
