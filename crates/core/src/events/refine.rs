//! What the refinement of a finished tree reports: its parameters and each step it keeps.

use super::ser_aabb;
use crate::geom::Aabb;

/// Most leaves of a treelet that a refinement restructures.
pub const MAX_TREELET_LEAVES: usize = 7;

/// Parameters of a refinement run.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RefineParams {
    /// Most passes run (a pass that keeps no move ends the run sooner).
    pub passes: u32,
    /// Fraction of the non-root nodes searched in the first pass (pass k searches
    /// batch / (2k + 1) of them); in (0, 1].
    pub batch: f64,
    /// Most leaves of a restructured treelet, 3..=7 ([`MAX_TREELET_LEAVES`]).
    pub treelet: u32,
    /// Treelet restructuring passes run before the reinsertion passes (0: none).
    pub treelet_passes: u32,
    /// Treelets are rooted only at nodes of at least this many leaves (Karras and Aila's γ;
    /// at least 3); 0 = by the tree's size (64 up to 65,536 leaves, more above).
    #[serde(default)]
    pub treelet_min: u32,
}

impl Default for RefineParams {
    /// One treelet pass of 7 leaves (rooted at the nodes of ≥ γ leaves), then 3 reinsertion
    /// passes, first batch = a tenth of the nodes (docs/benchmarks.md has the measurements
    /// behind it).
    fn default() -> Self {
        RefineParams {
            passes: 3,
            batch: 0.1,
            treelet: 7,
            treelet_passes: 1,
            treelet_min: 0,
        }
    }
}

impl RefineParams {
    /// Checks `batch` (in (0, 1]), `treelet` (3 to [`MAX_TREELET_LEAVES`]) and `treelet_min`
    /// (0, or at least 3); the error names the parameter as `record`'s flag does, without its
    /// dashes (`refine-batch`, …).
    pub fn check(&self) -> Result<(), String> {
        if !(self.batch > 0.0 && self.batch <= 1.0) {
            return Err(format!(
                "refine-batch must be in (0, 1], got {}",
                self.batch
            ));
        }
        if !(3..=MAX_TREELET_LEAVES as u32).contains(&self.treelet) {
            return Err(format!(
                "refine-treelet must be 3 to {} leaves, got {}",
                MAX_TREELET_LEAVES, self.treelet
            ));
        }
        if (1..3).contains(&self.treelet_min) {
            return Err(format!(
                "refine-treelet-min must be 0 (by the tree's size) or at least 3 leaves, got {}",
                self.treelet_min
            ));
        }
        Ok(())
    }
}

/// What a refinement step did.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum StepKind {
    /// A subtree moved (reinsertion).
    Move,
    /// A treelet of `leaves` leaves was rebuilt in its optimal shape.
    Treelet {
        /// Treelet leaves (3..=7).
        leaves: u32,
    },
}

/// One kept step of a refinement run: a move or a rebuilt treelet.
///
/// Ids are the input tree's: leaves are primitives; an interior id names the input's node
/// *slot*, which a step can hang elsewhere (the final renumbering to merge order happens after
/// the last step). For a rebuilt treelet, `node` is its root, `parent`,
/// `sibling` and `target` are `u32::MAX` (the Subset Tree's `NONE`), and both boxes are the root's (which
/// a rebuild keeps).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Step {
    /// 0-based index of the step in the run.
    pub step: u32,
    /// Pass the step belongs to (treelet passes first, then reinsertion passes).
    pub pass: u32,
    /// Move or treelet.
    pub kind: StepKind,
    /// The subtree that moved (a treelet's root).
    pub node: u32,
    /// Its parent slot, which moved with it: before, parent of `node` and `sibling`; after,
    /// parent of `node` and `target`.
    pub parent: u32,
    /// Its old sibling, which took the parent's old place.
    pub sibling: u32,
    /// Its new sibling.
    pub target: u32,
    /// Box of the moved subtree.
    #[serde(serialize_with = "ser_aabb")]
    pub aabb: Aabb,
    /// Box of the parent slot after the move (`node` ∪ `target`).
    #[serde(serialize_with = "ser_aabb")]
    pub parent_aabb: Aabb,
    /// SAH before the step.
    pub sah_before: f64,
    /// SAH after the step.
    pub sah: f64,
}
