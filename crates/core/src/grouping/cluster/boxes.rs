//! The round loop on bodies given by their boxes (the AABB p-set): the parts of pre-grouping
//! and the chunks of the partitioned schedule, run to the root or until a few bodies remain.

use super::{Clusterer, tie_tag};
use crate::geom::Aabb;
use crate::grouping::pset::AabbBodies;
use crate::grouping::subset_tree::NONE;
use crate::grouping::{Budget, Grouping, Observer, ResolvedParams, Stats, Stopped};

/// Runs the grouping phase with the AABB p-set on bodies given by their boxes (leaf `i` has
/// box `boxes[i]`; its diameter is the box diagonal): the primitives of a scene, or the roots
/// of groupings made before (components, chunks). Merge ids are local: leaves `0..boxes.len()`.
pub(crate) fn run_boxes<O: Observer>(
    boxes: Vec<Aabb>,
    params: &ResolvedParams,
    observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    assert!(!boxes.is_empty(), "grouping needs at least one body");
    let diameters = boxes.iter().map(Aabb::diameter).collect();
    Clusterer::new(boxes, params, AabbBodies, diameters, observer).run(budget)
}

/// What [`run_boxes_until`] leaves: the merges made (local ids, as in [`run_boxes`]) and the
/// bodies still without a parent.
pub(crate) struct Partial {
    /// Children of each new body, in merge order (new body `i` has local id `boxes.len() + i`).
    pub children: Vec<[u32; 2]>,
    /// Box of each new body, in merge order.
    pub aabb: Vec<Aabb>,
    /// Diameter of each new body, in merge order.
    pub diameter: Vec<f64>,
    /// Local ids of the bodies left without a parent, in increasing order.
    pub roots: Vec<u32>,
    /// Rounds run.
    pub rounds: u32,
    /// Work counters.
    pub stats: Stats,
}

/// Like [`run_boxes`], but stops as soon as only `keep` (≥ 1) parent-less bodies remain, and
/// breaks ties by the tags of the ids `tag_id(local id)` (so a subproblem whose local ids map
/// increasingly onto a larger run's ids breaks ties as that run would). No `Finish` event.
pub(crate) fn run_boxes_until<O: Observer>(
    boxes: Vec<Aabb>,
    keep: usize,
    tag_id: impl Fn(u32) -> u32,
    params: &ResolvedParams,
    observer: O,
    budget: &Budget<'_>,
) -> Result<Partial, Stopped> {
    assert!(
        keep >= 1 && keep <= boxes.len(),
        "keep must be in 1..=bodies"
    );
    let n = boxes.len();
    let diameters = boxes.iter().map(Aabb::diameter).collect();
    let mut c = Clusterer::new(boxes, params, AabbBodies, diameters, observer);
    c.keep = keep;
    for (i, t) in c.tag.iter_mut().enumerate() {
        *t = tie_tag(params.seed, tag_id(i as u32));
    }
    let rounds = c.rounds(budget)?;
    let roots = (0..c.parent.len() as u32)
        .filter(|&x| c.parent[x as usize] == NONE && (x as usize) < n + c.children.len())
        .collect();
    Ok(Partial {
        aabb: c.aabb.split_off(n),
        diameter: c.diameter.split_off(n),
        children: c.children,
        roots,
        rounds,
        stats: c.stats,
    })
}
