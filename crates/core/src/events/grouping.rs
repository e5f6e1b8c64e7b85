//! What the grouping phase reports: a merge, and the part of the run it belongs to.

use super::ser_aabb;
use crate::geom::Aabb;

/// One merge of step 4(a): bodies `a` and `b` become the new body `new`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Merge {
    /// 0-based merge index; the new body's id is `n + step`.
    pub step: u32,
    /// Round (number of DLimit doublings so far) in which the merge happened.
    pub round: u32,
    /// First merged body (the smaller id).
    pub a: u32,
    /// Second merged body (the larger id).
    pub b: u32,
    /// Id of the new body.
    pub new: u32,
    /// AABB of the new body.
    #[serde(serialize_with = "ser_aabb")]
    pub aabb: Aabb,
    /// Diameter of the new body.
    pub diameter: f64,
    /// Fill = new diameter / (diameter a + diameter b).
    pub fill: f64,
    /// Balance = greater ratio of the children's diameters (≥ 1).
    pub balance: f64,
    /// Cost = diameter^A × (B·Fill + C·Balance).
    pub cost: f64,
    /// Entries left in MPairs after the pop.
    pub queue_len: u32,
    /// Whether the new body obeys DLimit (active) or went dormant (step 4c).
    pub active: bool,
}

/// What a [`Part`] of a grouping run groups.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum PartKind {
    /// A chunk of the partitioned schedule: a set of bodies at `level` of the top-down split
    /// (0 = the whole scene), grouped until at most `keep` of them remain.
    Chunk {
        /// Depth of the chunk in the split (0 = the top).
        level: u32,
        /// Bodies left ungrouped for the level above (1 at the top).
        keep: u32,
    },
    /// A component (pre-grouping): its primitives are grouped on their own.
    Component {
        /// Index of the component in the documented component order.
        index: u32,
    },
    /// A rigid copy of component `of` (instancing): it takes the representative's Subset Tree
    /// shape; `rotation` (row-major 3×3) and `translation` map the representative onto it.
    Copy {
        /// Index of the component this one copies.
        of: u32,
        /// Row-major rotation matrix.
        rotation: [f64; 9],
        /// Translation applied after the rotation.
        translation: [f64; 3],
    },
    /// The top level: the roots of the parts (and any bodies left out of parts) grouped together.
    Top,
    /// Bodies with identical boxes merged in pairs before the partitioned schedule's split
    /// (`Chunking::twins`, the fast path): double-sided faces, duplicated parts.
    Twins,
}

/// A part of a grouping run: the merges that follow it, up to the next `Part` or `Finish`,
/// group the bodies of this part (a chunk of the partitioned schedule, a component, a copy, the
/// top level, or bodies with identical boxes).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Part {
    /// 0-based index of the part in the run, in event order.
    pub id: u32,
    /// What the part groups.
    pub kind: PartKind,
    /// Number of bodies the part starts from.
    pub bodies: u32,
    /// Merge step of the part's first merge (= merges made before it).
    pub first_step: u32,
}

impl std::fmt::Display for Part {
    /// One log line, e.g. `part 3: chunk at level 2 (12 bodies → 4) from merge 57`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "part {}: ", self.id)?;
        match self.kind {
            PartKind::Chunk { level, keep } => write!(
                f,
                "chunk at level {level} ({} bodies → {keep})",
                self.bodies
            )?,
            PartKind::Component { index } => {
                write!(f, "component {index} ({} primitives)", self.bodies)?
            }
            PartKind::Copy {
                of, translation, ..
            } => write!(
                f,
                "copy of component {of} ({} primitives, moved by [{:.4}, {:.4}, {:.4}])",
                self.bodies, translation[0], translation[1], translation[2]
            )?,
            PartKind::Top => write!(f, "top level ({} bodies)", self.bodies)?,
            PartKind::Twins => write!(f, "identical boxes ({} bodies)", self.bodies)?,
        }
        write!(f, " from merge {}", self.first_step)
    }
}
