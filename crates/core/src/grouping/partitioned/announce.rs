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
    /// Merges of identical neighbours, the first steps (before the split's subproblems).
    pub(super) twins: usize,
    /// Bodies those merges start from.
    pub(super) twin_bodies: u32,
    /// Children of each merge.
    pub(super) children: &'a [[u32; 2]],
    /// Boxes and diameters of all bodies, primitives first.
    pub(super) aabb: &'a [Aabb],
    pub(super) diameter: &'a [f64],
    /// Details of each merge (empty when nobody listens).
    pub(super) info: &'a [MergeInfo],
}

/// Announces the merges of identical neighbours, if any, as one part ([`PartKind::Twins`]),
/// then, in post-order up to the first unfinished subproblem, each subproblem that merges
/// anything ([`Event::Part`]), each part followed by its merges and a `Dormant` event after
/// each merge whose body exceeds its subproblem's DLimit, when `listens`; returns the number of
/// merges of those parts.
pub(super) fn announce<O: Observer>(
    observer: &mut O,
    nodes: &[Node],
    done: &[AtomicBool],
    made: &Built<'_>,
    listens: bool,
) -> u32 {
    let mut emitted = 0u32;
    let mut part = 0u32;
    let mut announce_part = |kind, bodies, count: u32, emitted: u32| {
        if listens && count > 0 {
            observer.on_event(&Event::Part(Part {
                id: part,
                kind,
                bodies,
                first_step: emitted,
            }));
            part += 1;
            for step in emitted..emitted + count {
                merge(observer, made, step);
            }
        }
    };
    let twins = made.twins as u32;
    announce_part(PartKind::Twins, made.twin_bodies, twins, 0);
    emitted += twins;
    for k in post_order(nodes) {
        let node = &nodes[k as usize];
        if !done[k as usize].load(Ordering::Relaxed) {
            break;
        }
        let count = node.inputs - node.keep;
        let kind = if node.level == 0 {
            PartKind::Top
        } else {
            PartKind::Chunk {
                level: node.level,
                keep: node.keep,
            }
        };
        announce_part(kind, node.inputs, count, emitted);
        emitted += count;
    }
    emitted
}

/// Announces merge `step` ([`Event::Merge`]), and its body's [`Event::Dormant`] when it exceeds
/// its subproblem's DLimit.
fn merge<O: Observer>(observer: &mut O, made: &Built<'_>, step: u32) {
    let Built {
        n,
        children,
        aabb,
        diameter,
        info,
        ..
    } = *made;
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
