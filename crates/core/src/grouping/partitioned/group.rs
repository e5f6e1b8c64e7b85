//! The entry points of the partitioned schedule: the Morton order and the split planned, the
//! executor run over it, the events announced and the Subset Tree assembled.

use super::announce::{Built, announce};
use super::chunking::Chunking;
use super::executor::Executor;
use super::pairs::merge_info;
use super::plan::{Node, plan};
use super::split::morton_order;
use super::subproblem::{Body, Counters, Leftover, MergeInfo, MergeSlots, RunInputs};
use super::twins::{self, Twins};
use crate::events::{Event, Observer};
use crate::geom::Aabb;
use crate::grouping::cluster;
use crate::grouping::subset_tree::SubsetTree;
use crate::grouping::voxel_hash::prefetch;
use crate::grouping::{
    Budget, Grouping, PAR_MIN_LEN, PSet, ResolvedParams, Stats, StopReason, Stopped,
};
use crate::par::{POOL_MIN, on_pool};
use crate::scene::Scene;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// How many leaves ahead the gather asks for the box it will read (its reads are random).
const GATHER_AHEAD: usize = 16;

/// Runs the partitioned schedule split as `chunking` says (see the module doc; δ = 0 is taken
/// by the scene's size, [`Chunking::for_size`]); `params.mode.schedule` is not read. With the
/// hull p-set, which has no partitioned form, the exact schedule runs. Panics only if the
/// scene is empty.
pub fn group_with<O: Observer>(
    scene: &Scene,
    params: &ResolvedParams,
    chunking: &Chunking,
    observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    assert!(!scene.is_empty(), "grouping needs at least one primitive");
    if params.pset == PSet::Hull {
        return cluster::group_scene(scene, params, observer, budget);
    }
    let n = scene.len();
    // Room for the merged bodies from the start (no copy when they are added).
    let mut aabb: Vec<Aabb> = Vec::with_capacity(2 * n - 1);
    aabb.par_extend(
        (0..n)
            .into_par_iter()
            .with_min_len(PAR_MIN_LEN)
            .map(|i| scene.prim_aabb(i)),
    );
    group_boxes(aabb, params, chunking, observer, budget)
}

/// The partitioned schedule (AABB p-set) on primitives whose boxes are `aabb`, the primitive
/// ids being their indices (`aabb` grows to the tree's 2N − 1 boxes: give it that capacity to
/// spare a copy). Panics only if `aabb` is empty.
///
/// The split and the subproblems, which tell the observer nothing until they are done, run in
/// one piece on the rayon pool (`crate::par`); the events are announced on the caller's thread.
pub fn group_boxes<O: Observer>(
    aabb: Vec<Aabb>,
    params: &ResolvedParams,
    chunking: &Chunking,
    mut observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    assert!(!aabb.is_empty(), "grouping needs at least one primitive");
    let n = aabb.len();
    let chunking = &chunking.for_size(n);
    let ctx = RunInputs::new(*params, budget);
    let listens = !observer.is_silent();
    let g = on_pool(n >= POOL_MIN, || {
        split_and_group(aabb, chunking, &ctx, listens)
    });
    // Events, in post-order, up to the first unfinished subproblem.
    let emitted = if listens || g.result.is_none() {
        let made = Built {
            n,
            twins: g.twins.0,
            twin_bodies: g.twins.1,
            children: &g.children,
            aabb: &g.aabb,
            diameter: &g.diameter,
            info: &g.info,
        };
        announce(&mut observer, &g.nodes, &g.done, &made, listens)
    } else {
        0
    };
    if g.result.is_none() {
        return Err(stopped(&ctx, emitted));
    }
    let tree = SubsetTree::new(g.aabb, g.diameter, g.children)
        .expect("the partitioned schedule makes exactly N - 1 valid merges");
    observer.on_event(&Event::Finish {
        root: tree.root(),
        rounds: g.sub.rounds,
        merges: (n - 1) as u32,
    });
    Ok(finished(tree, params, &g.sub, g.twins.0))
}

/// What the split and the subproblems leave: the tree's arrays (the merges' details when the
/// observer listens), the split's nodes with which of them finished, and the outcome.
struct Grouped {
    aabb: Vec<Aabb>,
    diameter: Vec<f64>,
    children: Vec<[u32; 2]>,
    info: Vec<MergeInfo>,
    /// Merges of identical neighbours, made before the split (the first steps), and the bodies
    /// they start from.
    twins: (usize, u32),
    nodes: Vec<Node>,
    done: Vec<AtomicBool>,
    /// `None` when the budget stopped the run.
    result: Option<Leftover>,
    sub: Counters,
}

/// The Morton order, the split planned over it and the executor run on it.
fn split_and_group(
    mut aabb: Vec<Aabb>,
    chunking: &Chunking,
    ctx: &RunInputs,
    listens: bool,
) -> Grouped {
    let n = aabb.len();
    aabb.reserve_exact(n - 1);
    let mut diameter: Vec<f64> = Vec::with_capacity(2 * n - 1);
    diameter.par_extend(
        aabb.par_iter()
            .with_min_len(PAR_MIN_LEN)
            .map(Aabb::diameter),
    );
    let mut codes = morton_order(&aabb);
    let twins = if chunking.twins {
        twins::pair(&mut codes, &mut aabb, &mut diameter)
    } else {
        Twins::default()
    };
    // The split's first new body follows the twins.
    let first = aabb.len();
    let mut leaves = gather_leaves(&aabb, &codes);
    // Planned on the leaves themselves: the SAH cuts read their boxes in order, and reorder
    // them with their codes.
    let nodes = plan(&mut codes, &mut leaves, chunking);
    drop(codes);
    let merges = n - 1;
    let made = twins.children.len();
    let mut children = vec![[0u32; 2]; merges];
    children[..made].copy_from_slice(&twins.children);
    // The merges' slots, filled on every thread (fresh pages are written, and faulted in, in
    // parallel).
    let rest = merges - made;
    aabb.par_extend(rayon::iter::repeat_n(Aabb::EMPTY, rest).with_min_len(PAR_MIN_LEN));
    diameter.par_extend(rayon::iter::repeat_n(0.0, rest).with_min_len(PAR_MIN_LEN));
    let mut info = if listens {
        let mut info = vec![MergeInfo::default(); merges];
        for (i, &[a, b]) in twins.children.iter().enumerate() {
            let d = [n + i, a as usize, b as usize].map(|x| diameter[x]);
            info[i] = merge_info(ctx, d, 0, 0);
        }
        info
    } else {
        Vec::new()
    };
    let done: Vec<AtomicBool> = nodes.iter().map(|_| AtomicBool::new(false)).collect();
    let exec = Executor {
        ctx,
        nodes: &nodes,
        done: &done,
        grain: Executor::grain(),
    };
    let (_, new_aabb) = aabb.split_at_mut(first);
    let (_, new_d) = diameter.split_at_mut(first);
    let out = MergeSlots {
        first_new: first as u32,
        children: &mut children[made..],
        aabb: new_aabb,
        diameter: new_d,
        info: if listens {
            Some(&mut info[made..])
        } else {
            None
        },
        stats: Counters::default(),
    };
    let (result, sub) = exec.node(0, &mut leaves, out, false);
    Grouped {
        aabb,
        diameter,
        children,
        info,
        twins: (made, twins.bodies),
        nodes,
        done,
        result,
        sub,
    }
}

/// The leaves as bodies in Morton order: one gather (its loads overlap) instead of one per
/// chunk, of the box alone (the diameter is recomputed, the same value, rather than read at
/// random from a second array); `first_round` is set by their chunk.
fn gather_leaves(aabb: &[Aabb], codes: &[(u64, u32)]) -> Vec<Body> {
    (0..codes.len())
        .into_par_iter()
        .with_min_len(PAR_MIN_LEN)
        .map(|i| {
            if let Some(&(_, ahead)) = codes.get(i + GATHER_AHEAD) {
                prefetch(&aabb[ahead as usize]);
            }
            let id = codes[i].1;
            let aabb = aabb[id as usize];
            Body {
                id,
                first_round: 0,
                aabb,
                diameter: aabb.diameter(),
            }
        })
        .collect()
}

/// The stop of a run whose budget ended it after `emitted` announced merges.
fn stopped(ctx: &RunInputs, emitted: u32) -> Stopped {
    let reason = ctx
        .reason
        .lock()
        .expect("no panics hold it")
        .unwrap_or(StopReason::Interrupted);
    Stopped {
        reason,
        merges: emitted,
        rounds: 0,
        eligible_pairs: ctx.pairs.load(Ordering::Relaxed),
    }
}

/// The outcome of a finished run: the tree with the subproblems' summed counters and the
/// number of merges of identical neighbours.
fn finished(
    tree: SubsetTree,
    params: &ResolvedParams,
    sub: &Counters,
    identical: usize,
) -> Grouping {
    Grouping {
        tree,
        rounds: sub.rounds,
        params: *params,
        stats: Stats {
            eligible_pairs: sub.eligible_pairs,
            candidates: sub.candidates,
            pops: sub.pops,
            stale_pops: sub.stale_pops,
            peak_queue: sub.peak_queue,
            identical: identical as u64,
        },
        pregrouping: None,
    }
}
