//! The events of a partitioned run, announced after the grouping: each finished subproblem in
//! the split's post-order, with its merges.

use super::plan::{Node, post_order};
use super::subproblem::MergeInfo;
use crate::events::{Event, Merge, Observer, Part, PartKind};
use crate::geom::Aabb;
use std::sync::atomic::{AtomicBool, Ordering};

/// The merges of the run, by step (new body `n + step`).
pub(super) struct Built<'a> {
    /// Primitives.
    pub(super) n: usize,
    /// Children of each merge.
    pub(super) children: &'a [[u32; 2]],
    /// Boxes and diameters of all bodies, primitives first.
    pub(super) aabb: &'a [Aabb],
    pub(super) diameter: &'a [f64],
    /// Details of each merge (empty when nobody listens).
    pub(super) info: &'a [MergeInfo],
}

/// Announces, in post-order up to the first unfinished subproblem, each subproblem that merges
/// anything ([`Event::Part`]) followed by its merges and a `Dormant` event after each merge
/// whose body exceeds its subproblem's DLimit, when `listens`; returns the number of merges of
/// those subproblems.
pub(super) fn announce<O: Observer>(
    observer: &mut O,
    nodes: &[Node],
    done: &[AtomicBool],
    made: &Built<'_>,
    listens: bool,
) -> u32 {
    let Built {
        n,
        children,
        aabb,
        diameter,
        info,
    } = *made;
    let mut emitted = 0u32;
    let mut part = 0u32;
    for k in post_order(nodes) {
        let node = &nodes[k as usize];
        if !done[k as usize].load(Ordering::Relaxed) {
            break;
        }
        let count = node.inputs - node.keep;
        if listens && count > 0 {
            let kind = if node.level == 0 {
                PartKind::Top
            } else {
                PartKind::Chunk {
                    level: node.level,
                    keep: node.keep,
                }
            };
            observer.on_event(&Event::Part(Part {
                id: part,
                kind,
                bodies: node.inputs,
                first_step: emitted,
            }));
            part += 1;
            for step in emitted..emitted + count {
                let s = step as usize;
                let new = (n + s) as u32;
                let i = info[s];
                observer.on_event(&Event::Merge(Merge {
                    step,
                    round: i.round,
                    a: children[s][0],
                    b: children[s][1],
                    new,
                    aabb: aabb[n + s],
                    diameter: diameter[n + s],
                    fill: i.fill,
                    balance: i.balance,
                    cost: i.cost,
                    queue_len: i.queue_len,
                    active: i.active,
                }));
                if !i.active {
                    observer.on_event(&Event::Dormant {
                        round: i.round,
                        body: new,
                        diameter: diameter[n + s],
                    });
                }
            }
        }
        emitted += count;
    }
    emitted
}
