//! Our grouping phase beside its peers, on the same primitives, each as a [`SubsetTree`] so
//! that quality measures (SAH, depth, balance), Wrapper Trees ([`crate::wrap`]) and queries
//! ([`crate::query`]) measure every hierarchy the same way (`docs/benchmarks.md`, "What is
//! measured").
//!
//! - [`Method::Grouping`], [`Method::GroupingHull`], [`Method::GroupingPartitioned`]: the
//!   paper's grouping phase (§2.2) with AABB or hull p-sets, and in the partitioned schedule;
//! - [`Method::Fast`]: the fast path, the partitioned schedule with small subproblems
//!   ([`Method::GroupingFast`]) then a bounded refinement ([`crate::refine::refine_fast`]);
//! - [`Method::GroupingPregroup`], [`Method::GroupingInstanced`], [`Method::GroupingObjects`]:
//!   the same with the paper's §1.3 speed-ups ([`crate::grouping::pregroup`]);
//! - [`parry_bvh`]: parry3d's `Bvh`, binned SAH or PLOC, as published;
//! - [`obvhs_ploc`]: obvhs's PLOC, with or without its reinsertion optimiser, as published;
//! - [`median_split`]: a top-down median split;
//! - [`goldsmith_salmon`]: Goldsmith–Salmon incremental insertion;
//! - `…+refine` ([`Method::is_refined`]): a builder's tree then [`crate::refine`] with default
//!   parameters (grouping, parry Binned, obvhs PLOC).

pub mod goldsmith_salmon;
pub mod median_split;
pub mod obvhs_ploc;
pub mod parry_bvh;
pub mod topology;

use crate::grouping::{self, Budget, PSet, Params, Pregroup, Schedule, Stats, SubsetTree};
use crate::refine::{self, RefineParams};
use crate::scene::Scene;
use crate::stop::{Interrupted, Stop};
use parry3d::partitioning::BvhBuildStrategy;
use std::time::Instant;

/// A hierarchy builder.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
pub enum Method {
    /// The grouping phase with AABB p-sets and the given parameters.
    Grouping,
    /// The grouping phase with convex-hull p-sets.
    GroupingHull,
    /// The grouping phase in the partitioned schedule (AABB p-sets).
    GroupingPartitioned,
    /// The grouping phase with connected components pre-grouped (AABB p-set).
    GroupingPregroup,
    /// The grouping phase with connected components pre-grouped and rigid copies copy-moved.
    GroupingInstanced,
    /// The grouping phase with the scene's objects pre-grouped and rigid copies copy-moved.
    GroupingObjects,
    /// parry3d `Bvh`, binned SAH strategy.
    ParryBinned,
    /// parry3d `Bvh`, PLOC strategy.
    ParryPloc,
    /// obvhs PLOC.
    ObvhsPloc,
    /// obvhs PLOC followed by reinsertion.
    ObvhsPlocReinsert,
    /// Top-down median split.
    MedianSplit,
    /// Goldsmith–Salmon incremental insertion.
    GoldsmithSalmon,
    /// [`Method::Grouping`] then the refinement pass.
    GroupingRefine,
    /// [`Method::ParryBinned`] then the refinement pass.
    ParryBinnedRefine,
    /// [`Method::ObvhsPloc`] then the refinement pass.
    ObvhsPlocRefine,
    /// [`Method::GroupingPartitioned`] then the refinement pass.
    GroupingPartitionedRefine,
    /// The partitioned schedule with the fast path's split
    /// ([`Chunking::FAST`](crate::grouping::partitioned::Chunking::FAST)).
    GroupingFast,
    /// The fast path: [`Method::GroupingFast`] then [`crate::refine::refine_fast`].
    Fast,
}

impl Method {
    /// What a bench compares by default: the paper's exact run, the fast path, the exact run
    /// refined, the partitioned schedule, and the peers users choose between (parry Binned,
    /// obvhs PLOC with and without reinsertion). The others (the hull p-set, pre-grouping,
    /// the peers refined, median split, Goldsmith–Salmon) on request.
    pub const DEFAULT: [Method; 7] = [
        Method::Grouping,
        Method::Fast,
        Method::GroupingRefine,
        Method::GroupingPartitioned,
        Method::ParryBinned,
        Method::ObvhsPloc,
        Method::ObvhsPlocReinsert,
    ];

    /// Every method, ours first (`--methods all`).
    pub const ALL: [Method; 18] = [
        Method::Grouping,
        Method::Fast,
        Method::GroupingFast,
        Method::GroupingRefine,
        Method::GroupingHull,
        Method::GroupingPartitioned,
        Method::GroupingPartitionedRefine,
        Method::GroupingPregroup,
        Method::GroupingInstanced,
        Method::GroupingObjects,
        Method::ParryBinned,
        Method::ParryPloc,
        Method::ObvhsPloc,
        Method::ObvhsPlocReinsert,
        Method::MedianSplit,
        Method::GoldsmithSalmon,
        Method::ParryBinnedRefine,
        Method::ObvhsPlocRefine,
    ];

    /// Short name used in tables, CSV and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Grouping => "grouping",
            Method::GroupingHull => "grouping-hull",
            Method::GroupingPartitioned => "grouping-partitioned",
            Method::GroupingPregroup => "grouping-pregroup",
            Method::GroupingInstanced => "grouping-instanced",
            Method::GroupingObjects => "grouping-objects",
            Method::ParryBinned => "parry-binned",
            Method::ParryPloc => "parry-ploc",
            Method::ObvhsPloc => "obvhs-ploc",
            Method::ObvhsPlocReinsert => "obvhs-ploc-reinsert",
            Method::MedianSplit => "median-split",
            Method::GoldsmithSalmon => "goldsmith-salmon",
            Method::GroupingRefine => "grouping+refine",
            Method::ParryBinnedRefine => "parry-binned+refine",
            Method::ObvhsPlocRefine => "obvhs-ploc+refine",
            Method::GroupingPartitionedRefine => "grouping-partitioned+refine",
            Method::GroupingFast => "grouping-fast",
            Method::Fast => "fast",
        }
    }

    /// Parses a name as printed by [`Method::name`].
    pub fn parse(s: &str) -> Result<Method, String> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s.trim())
            .ok_or_else(|| {
                let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
                format!("unknown method '{s}' (valid: {})", names.join(", "))
            })
    }

    /// Whether this is the paper's grouping phase (refined or not).
    pub fn is_grouping(self) -> bool {
        matches!(
            self,
            Method::Grouping
                | Method::GroupingHull
                | Method::GroupingRefine
                | Method::GroupingPregroup
                | Method::GroupingInstanced
                | Method::GroupingObjects
                | Method::GroupingPartitioned
                | Method::GroupingPartitionedRefine
                | Method::GroupingFast
                | Method::Fast
        )
    }

    /// Whether the builder's tree goes through [`crate::refine`].
    pub fn is_refined(self) -> bool {
        self.base() != self
    }

    /// The builder without refinement.
    pub fn base(self) -> Method {
        match self {
            Method::GroupingRefine => Method::Grouping,
            Method::ParryBinnedRefine => Method::ParryBinned,
            Method::ObvhsPlocRefine => Method::ObvhsPloc,
            Method::GroupingPartitionedRefine => Method::GroupingPartitioned,
            Method::Fast => Method::GroupingFast,
            m => m,
        }
    }

    /// The partitioned schedule's settings this method groups a scene of `n` primitives with
    /// under `params`, for the methods that run it (`grouping-partitioned` with `params`'
    /// chunks, `fast` with its own): `delta=… epsilon=… top=… sah=…`, as the `--chunk-*` flags
    /// name them, with δ as the run uses it ([`Chunking::delta_for`](crate::grouping::partitioned::Chunking::delta_for)).
    pub fn chunking(self, params: &Params, n: usize) -> Option<String> {
        let mode = match self.base() {
            Method::GroupingPartitioned => params.mode,
            Method::GroupingFast => params.mode.fast(),
            _ => return None,
        };
        Some(format!(
            "delta={} epsilon={} top={} sah={}",
            crate::grouping::partitioned::Chunking::delta_for(mode.chunk_delta, n),
            mode.chunk_epsilon,
            mode.chunk_top,
            mode.chunk_sah
        ))
    }
}

/// A built hierarchy.
#[derive(Clone, Debug)]
pub struct Built {
    /// The method.
    pub method: Method,
    /// The hierarchy as a Subset Tree (boxes recomputed in `f64`).
    pub tree: SubsetTree,
    /// Build time in seconds (see [`build`] for what is timed).
    pub seconds: f64,
    /// Grouping work counters (grouping methods only).
    pub stats: Option<Stats>,
    /// Seconds of `seconds` spent refining (0 for an unrefined method).
    pub refine_seconds: f64,
}

/// Builds `method`'s hierarchy over `scene`; `params` is used by the grouping methods (the hull
/// variant overrides the p-set). Fails only if a peer's tree is malformed (a bug).
///
/// The time covers the method's own build only, from primitive boxes (`f32` relative to the
/// scene centre for parry and obvhs, `f64` for ours) to its native tree; reading its topology
/// into a Subset Tree ([`topology`]) and the boxes per primitive are not timed. The AABB
/// groupings are timed from the boxes, DLimit0's median included ([`grouping::group_boxes`]);
/// the hull p-set and the pre-grouped methods (which need the polygons) from the scene,
/// including finding the components and the copies. The partitioned grouping, the exact
/// grouping's round-start scans (rounds of at least 2,048 active bodies), the pre-grouped
/// methods and obvhs PLOC (its `parallel` feature) use the current rayon pool (run them inside
/// `ThreadPool::install` to choose the thread count); the other builders are single-threaded.
/// Called from outside the pool, the build runs on one of its threads.
/// A refined method's time includes the refinement (which searches on rayon's threads);
/// [`Built::refine_seconds`] is its part.
pub fn build(method: Method, scene: &Scene, params: &Params) -> Result<Built, String> {
    build_until(method, scene, params, &Stop::new())
}

/// [`build`], the grouping methods checking `stop` between merges and in their scans (Err:
/// [`Interrupted`]'s text once `stop` is requested; the peers' own builders run to the end).
pub fn build_until(
    method: Method,
    scene: &Scene,
    params: &Params,
    stop: &Stop,
) -> Result<Built, String> {
    // Every method is timed on a thread of the pool, as a caller inside it would run it: from
    // outside, each of a builder's parallel steps would be handed over (`crate::par`).
    crate::par::on_pool(true, || build_here(method, scene, params, stop))
}

/// [`build_until`] on the caller's thread.
fn build_here(
    method: Method,
    scene: &Scene,
    params: &Params,
    stop: &Stop,
) -> Result<Built, String> {
    let base = method.base();
    let mut built = build_base(base, scene, params, stop)?;
    if method.is_refined() {
        let t = Instant::now();
        let Built {
            tree,
            seconds,
            stats,
            ..
        } = built;
        let tree = if method == Method::Fast {
            refine::refine_fast(tree).tree
        } else {
            refine::refine_owned(tree, &RefineParams::default(), ()).tree
        };
        let refine_seconds = t.elapsed().as_secs_f64();
        built = Built {
            method,
            tree,
            seconds: seconds + refine_seconds,
            stats,
            refine_seconds,
        };
    }
    Ok(built)
}

/// Builds an unrefined method's hierarchy (see [`build`]).
fn build_base(
    method: Method,
    scene: &Scene,
    params: &Params,
    stop: &Stop,
) -> Result<Built, String> {
    let budget = Budget {
        stop: Some(stop.flag()),
        ..Budget::default()
    };
    let interrupted = |_| Interrupted.to_string();
    let t = Instant::now();
    let done = |tree: SubsetTree, stats: Option<Stats>, seconds: f64| Built {
        method,
        tree,
        seconds,
        stats,
        refine_seconds: 0.0,
    };
    if method.is_grouping() {
        let mut p = Params {
            pset: if method == Method::GroupingHull {
                PSet::Hull
            } else {
                params.pset
            },
            ..params.clone()
        };
        let (pregroup, instancing) = match method {
            Method::GroupingPregroup => (Pregroup::Connected, false),
            Method::GroupingInstanced => (Pregroup::Connected, true),
            Method::GroupingObjects => (Pregroup::Objects, true),
            _ => (p.mode.pregroup, p.mode.instancing),
        };
        if pregroup != Pregroup::None {
            p.pset = PSet::Aabb;
        }
        p.mode.pregroup = pregroup;
        p.mode.instancing = instancing;
        if method == Method::GroupingPartitioned {
            p.pset = PSet::Aabb;
            p.mode.schedule = Schedule::Partitioned;
        }
        if method == Method::GroupingFast {
            p.pset = PSet::Aabb;
            p.mode = p.mode.fast();
        }
        if p.pset == PSet::Aabb && pregroup == Pregroup::None {
            // Like the peers', from the primitives' boxes, computed untimed (with room for
            // the merged bodies' boxes, which the grouping appends).
            let n = scene.len();
            let mut boxes = Vec::with_capacity(2 * n - 1);
            boxes.extend((0..n).map(|i| scene.prim_aabb(i)));
            let t = Instant::now();
            let resolved = p.resolve_boxes(&boxes);
            let g =
                grouping::group_boxes_within(boxes, &resolved, (), &budget).map_err(interrupted)?;
            let seconds = t.elapsed().as_secs_f64();
            return Ok(done(g.tree, Some(g.stats), seconds));
        }
        let g =
            grouping::group_within(scene, &p.resolve(scene), (), &budget).map_err(interrupted)?;
        let seconds = t.elapsed().as_secs_f64();
        return Ok(done(g.tree, Some(g.stats), seconds));
    }
    let (nodes, root, seconds) = match method {
        Method::ParryBinned | Method::ParryPloc => {
            let boxes = topology::local_boxes(scene);
            let strategy = if method == Method::ParryBinned {
                BvhBuildStrategy::Binned
            } else {
                BvhBuildStrategy::Ploc
            };
            let t = Instant::now();
            let bvh = parry_bvh::build(&boxes, strategy);
            let s = t.elapsed().as_secs_f64();
            let (nodes, root) = parry_bvh::topology(&bvh);
            (nodes, root, s)
        }
        Method::ObvhsPloc | Method::ObvhsPlocReinsert => {
            let boxes = topology::local_boxes(scene);
            let t = Instant::now();
            let bvh = obvhs_ploc::build(&boxes, method == Method::ObvhsPlocReinsert);
            let s = t.elapsed().as_secs_f64();
            let (nodes, root) = obvhs_ploc::topology(&bvh);
            (nodes, root, s)
        }
        Method::MedianSplit => {
            let centres: Vec<_> = (0..scene.len())
                .map(|i| scene.prim_aabb(i).center())
                .collect();
            let t = Instant::now();
            let (nodes, root) = median_split::build(&centres);
            (nodes, root, t.elapsed().as_secs_f64())
        }
        Method::GoldsmithSalmon => {
            let boxes: Vec<_> = (0..scene.len()).map(|i| scene.prim_aabb(i)).collect();
            let t = Instant::now();
            let (nodes, root) = goldsmith_salmon::build(&boxes);
            (nodes, root, t.elapsed().as_secs_f64())
        }
        Method::Grouping
        | Method::GroupingHull
        | Method::GroupingPregroup
        | Method::GroupingInstanced
        | Method::GroupingObjects
        | Method::GroupingPartitioned
        | Method::GroupingFast => unreachable!("handled above"),
        Method::GroupingRefine
        | Method::ParryBinnedRefine
        | Method::ObvhsPlocRefine
        | Method::GroupingPartitionedRefine
        | Method::Fast => {
            unreachable!("refined methods are built from their base")
        }
    };
    let tree = topology::subset_tree(scene, &nodes, root)
        .map_err(|e| format!("{}: malformed tree: {e}", method.name()))?;
    Ok(done(tree, None, seconds))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::generate;

    #[test]
    fn the_partitioned_methods_name_their_chunks_and_the_others_none() {
        let mut p = Params::default();
        // δ by the scene's size by default: 4,096 up to 2^18 primitives, 4 above.
        let by_size = |n| Method::GroupingPartitioned.chunking(&p, n);
        let d = "delta=4096 epsilon=0.5 top=8192 sah=256";
        assert_eq!(by_size(1 << 18).as_deref(), Some(d));
        let above = "delta=4 epsilon=0.5 top=8192 sah=256";
        assert_eq!(by_size((1 << 18) + 1).as_deref(), Some(above));
        p.mode.chunk_delta = 16;
        let d = "delta=16 epsilon=0.5 top=8192 sah=256";
        assert_eq!(
            Method::GroupingPartitioned.chunking(&p, 10).as_deref(),
            Some(d)
        );
        assert_eq!(
            Method::GroupingPartitionedRefine
                .chunking(&p, 1 << 20)
                .as_deref(),
            Some(d)
        );
        // The fast path keeps its own chunks whatever `params` say.
        let f = "delta=2 epsilon=0.5 top=16 sah=256";
        assert_eq!(Method::Fast.chunking(&p, 10).as_deref(), Some(f));
        assert_eq!(
            Method::GroupingFast.chunking(&p, 1 << 20).as_deref(),
            Some(f)
        );
        for m in [Method::Grouping, Method::GroupingRefine, Method::ObvhsPloc] {
            assert_eq!(m.chunking(&p, 10), None, "{}", m.name());
        }
    }

    #[test]
    fn every_method_builds_a_valid_tree() {
        for scene in [
            generate::soup(1, 3),
            generate::soup(2, 3),
            generate::robot_base(),
        ] {
            for m in Method::ALL {
                let b = build(m, &scene, &Params::default()).unwrap();
                let t = &b.tree;
                assert_eq!(t.leaves(), scene.len(), "{}", m.name());
                for (i, &[a, c]) in t.children.iter().enumerate() {
                    let x = t.leaves() + i;
                    assert!(t.aabb[x].contains_aabb(&t.aabb[a as usize], 0.0));
                    assert!(t.aabb[x].contains_aabb(&t.aabb[c as usize], 0.0));
                }
            }
        }
    }

    #[test]
    fn median_split_depth_is_logarithmic() {
        let scene = generate::soup(1000, 2);
        let b = build(Method::MedianSplit, &scene, &Params::default()).unwrap();
        assert_eq!(b.tree.depth_max(), 10);
    }
}
