//! What the round loop (`cluster`) needs from a p-set wrapper, and the AABB p-set's answer;
//! the hull p-set's is in `hull_pset`.

use crate::geom::Aabb;

/// What the round loop needs from a p-set wrapper beyond each body's AABB and diameter.
pub(super) trait PSetBodies {
    /// Whether the diameter of a pair is the diagonal of the union of the two boxes (the AABB
    /// p-set). Its Cost is then a symmetric function of the two records, bounded below by the
    /// boxes' positions, which lets the searches visit each pair once at round start and skip
    /// voxels that cannot improve a list (`cluster::scan`). Other p-sets read every candidate.
    const AABB: bool = false;
    /// The diameter of the body `x ∪ y` if the pair is eligible (gap ≤ `glimit`), given that
    /// their AABBs are within L∞ gap `glimit` and `merged` is the union of their AABBs.
    fn eligible(&self, x: u32, y: u32, merged: &Aabb, glimit: f64) -> Option<f64>;
    /// Records the merge of `x` and `y` into body `new`; returns the new body's diameter.
    fn merge(&mut self, x: u32, y: u32, new: u32, merged: &Aabb) -> f64;
    /// Whether bodies `x` and `y`, whose boxes and diameters are bit for bit the same, are
    /// the same body for every pair they are in ([`PSetBodies::eligible`] gives them the same
    /// answers): the searches then share one scan (`cluster::scan::Memo`).
    fn same(&self, x: u32, y: u32) -> bool;
}

/// The AABB p-set: the diameter is the box diagonal and the L∞ box gap is the gap.
pub(super) struct AabbBodies;

impl PSetBodies for AabbBodies {
    const AABB: bool = true;
    #[inline(always)]
    fn eligible(&self, _: u32, _: u32, merged: &Aabb, _: f64) -> Option<f64> {
        Some(merged.diameter())
    }
    #[inline(always)]
    fn merge(&mut self, _: u32, _: u32, _: u32, merged: &Aabb) -> f64 {
        merged.diameter()
    }
    /// A body is its box.
    fn same(&self, _: u32, _: u32) -> bool {
        true
    }
}
