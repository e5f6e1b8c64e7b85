//! Quality of a hierarchy, whatever built it: the surface-area heuristic, depth and balance.
//!
//! - SAH cost ([`sah`], defined next to the Subset Tree).
//! - Structural balance: mean over interior nodes of `min(|L|, |R|) / max(|L|, |R|)` in leaves
//!   (1 = perfectly balanced, → 0 = a chain).
//! - Spatial balance: mean over interior nodes of the sibling box-volume ratio
//!   `min(V_L, V_R) / max(V_L, V_R)`; a pair of zero-volume (flat) siblings counts as 1.
//! - Depth: largest and mean leaf depth.
//!
//! Wrapper tightness per level comes from [`crate::wrap::level_tightness`]. [`timing`] times
//! builders against each other (interleaved rounds, best of N); [`compare`] runs
//! every hierarchy builder × wrapper on a scene, [`sweep`] the A/B/C grid of the grouping
//! phase, [`bench`](mod@bench) the targets table and the cost of recording, [`stress`] every
//! builder on pathological scenes, and [`report`] writes their CSV, charts and `.rrd`.

pub mod bench;
pub mod compare;
pub mod report;
pub mod stress;
pub mod sweep;
pub mod timing;

pub use crate::grouping::{C_PRIM, C_TRAV, sah};

use crate::grouping::SubsetTree;

/// Peak resident memory of this process in bytes (Linux `VmHWM`), if known.
pub fn peak_rss_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Quality measures of one hierarchy.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Quality {
    /// SAH cost (see [`sah`] for the constants).
    pub sah: f64,
    /// Largest leaf depth.
    pub depth_max: u32,
    /// Mean leaf depth.
    pub depth_mean: f64,
    /// Mean leaf-count ratio of siblings.
    pub structural_balance: f64,
    /// Mean box-volume ratio of siblings.
    pub spatial_balance: f64,
}

/// Volumes of the cut at depth `d` (the paper's Figure 3 shows "the 8-node level", d = 3):
/// the summed volumes of its interior nodes' AABBs and of the convex hulls of their primitives'
/// vertices (leaves in the cut are drawn as themselves and add nothing).
pub fn level_volume(tree: &SubsetTree, scene: &crate::scene::Scene, d: u32) -> (f64, f64) {
    let mut boxes = 0.0;
    let mut hulls = 0.0;
    for x in tree.level(d) {
        if tree.is_leaf(x) {
            continue;
        }
        let e = tree.aabb[x as usize].extents();
        boxes += e.x * e.y * e.z;
        let points: Vec<_> = tree
            .leaves_under(x)
            .iter()
            .flat_map(|&l| scene.prim_vertices(l as usize).copied())
            .collect();
        hulls += crate::geom::hull::hull_of(points).volume();
    }
    (boxes, hulls)
}

/// Every quality measure of `tree`.
pub fn quality(tree: &SubsetTree) -> Quality {
    let n = tree.leaves();
    let mut count = vec![1u32; tree.len()];
    let (mut structural, mut spatial) = (0.0, 0.0);
    for (i, &[a, b]) in tree.children.iter().enumerate() {
        let (ca, cb) = (count[a as usize], count[b as usize]);
        count[n + i] = ca + cb;
        structural += ca.min(cb) as f64 / ca.max(cb) as f64;
        let (va, vb) = (
            tree.aabb[a as usize].volume(),
            tree.aabb[b as usize].volume(),
        );
        spatial += if va.max(vb) > 0.0 {
            va.min(vb) / va.max(vb)
        } else {
            1.0
        };
    }
    let interior = tree.children.len().max(1) as f64;
    let single = tree.children.is_empty();
    Quality {
        sah: sah(tree),
        depth_max: tree.depth_max(),
        depth_mean: tree.depth_mean(),
        structural_balance: if single { 1.0 } else { structural / interior },
        spatial_balance: if single { 1.0 } else { spatial / interior },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Aabb, P3};

    fn unit(x: f64) -> Aabb {
        Aabb::from_points(&[P3::new(x, 0.0, 0.0), P3::new(x + 1.0, 1.0, 1.0)])
    }

    #[test]
    fn hand_computed_sah_and_balance() {
        // Leaves at x = 0, 1, 3; ((0, 1), 2).
        let b01 = unit(0.0).merge(&unit(1.0));
        let root = b01.merge(&unit(3.0));
        let aabb = vec![unit(0.0), unit(1.0), unit(3.0), b01, root];
        let diameter = aabb.iter().map(Aabb::diameter).collect();
        let t = SubsetTree::new(aabb, diameter, vec![[0, 1], [2, 3]]).unwrap();
        let q = quality(&t);
        // Areas: leaves 6 each, b01 = 2·(2+1+2) = 10, root = 2·(4+1+4) = 18.
        assert!((q.sah - (10.0 + 18.0 + 18.0) / 18.0).abs() < 1e-12);
        assert!((q.structural_balance - (1.0 + 0.5) / 2.0).abs() < 1e-12);
        assert!((q.spatial_balance - (1.0 + 0.5) / 2.0).abs() < 1e-12);
        assert_eq!(q.depth_max, 2);
        assert!((q.depth_mean - 5.0 / 3.0).abs() < 1e-12);
    }
}
