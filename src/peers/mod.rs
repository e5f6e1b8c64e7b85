//! Our grouping phase beside its peers, on the same primitives, each as a [`SubsetTree`] so
//! that quality measures (SAH, depth, balance), Wrapper Trees ([`crate::wrap`]) and queries
//! ([`crate::query`]) measure every hierarchy the same way (`docs/benchmarks.md`, "How it is
//! measured").
//!
//! A [`Method`] is a [`Builder`] and optionally a [`Refinement`] of its tree.
//!
//! - [`Builder::Grouping`], [`Builder::GroupingHull`], [`Builder::GroupingPartitioned`]: the
//!   paper's grouping phase (§2.2) with AABB or hull p-sets, and in the partitioned schedule;
//! - [`Method::FAST`]: the fast path, the partitioned schedule with small subproblems
//!   ([`Builder::GroupingFast`]) then a bounded refinement ([`Refinement::Fast`]);
//! - [`Builder::GroupingPregroup`], [`Builder::GroupingInstanced`], [`Builder::GroupingObjects`]:
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

#[cfg(doc)]
use crate::grouping::partitioned::Chunking;
use crate::grouping::{self, Budget, PSet, Params, Pregroup, Schedule, Stats, SubsetTree};
use crate::refine::{self, Refinement};
use crate::scene::Scene;
use crate::stop::{Interrupted, Stop};
use parry3d::partitioning::BvhBuildStrategy;
use std::time::Instant;

/// Declares [`Builder`] with each builder's name and its refined form's name.
macro_rules! builders {
    ($($(#[$doc:meta])* $variant:ident = $name:literal,)*) => {
        /// A hierarchy builder, without refinement.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
        pub enum Builder {
            $($(#[$doc])* $variant,)*
        }

        impl Builder {
            /// The builder's name in tables, CSV and on the command line.
            pub fn name(self) -> &'static str {
                match self {
                    $(Builder::$variant => $name,)*
                }
            }

            /// The name of the builder followed by the default refinement (`NAME+refine`).
            fn refined_name(self) -> &'static str {
                match self {
                    $(Builder::$variant => concat!($name, "+refine"),)*
                }
            }
        }
    };
}

builders! {
    /// The grouping phase with AABB p-sets and the given parameters.
    Grouping = "grouping",
    /// The grouping phase with convex-hull p-sets.
    GroupingHull = "grouping-hull",
    /// The grouping phase in the partitioned schedule (AABB p-sets).
    GroupingPartitioned = "grouping-partitioned",
    /// The grouping phase with connected components pre-grouped (AABB p-set).
    GroupingPregroup = "grouping-pregroup",
    /// The grouping phase with connected components pre-grouped and rigid copies copy-moved.
    GroupingInstanced = "grouping-instanced",
    /// The grouping phase with the scene's objects pre-grouped and rigid copies copy-moved.
    GroupingObjects = "grouping-objects",
    /// The partitioned schedule with the fast path's split ([`Schedule::FAST`]).
    GroupingFast = "grouping-fast",
    /// parry3d `Bvh`, binned SAH strategy.
    ParryBinned = "parry-binned",
    /// parry3d `Bvh`, PLOC strategy.
    ParryPloc = "parry-ploc",
    /// obvhs PLOC.
    ObvhsPloc = "obvhs-ploc",
    /// obvhs PLOC followed by reinsertion.
    ObvhsPlocReinsert = "obvhs-ploc-reinsert",
    /// Top-down median split.
    MedianSplit = "median-split",
    /// Goldsmith–Salmon incremental insertion.
    GoldsmithSalmon = "goldsmith-salmon",
}

impl Builder {
    /// Whether this is the paper's grouping phase.
    pub fn is_grouping(self) -> bool {
        matches!(
            self,
            Builder::Grouping
                | Builder::GroupingHull
                | Builder::GroupingPregroup
                | Builder::GroupingInstanced
                | Builder::GroupingObjects
                | Builder::GroupingPartitioned
                | Builder::GroupingFast
        )
    }
}

/// A hierarchy method: a builder, then optionally a refinement of its tree. Serialised as its
/// name ([`Method::name`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Method {
    /// The builder.
    pub builder: Builder,
    /// The refinement of the builder's tree ([`crate::refine`]), if any.
    pub refinement: Option<Refinement>,
}

impl Method {
    /// `builder` alone.
    pub const fn of(builder: Builder) -> Method {
        Method {
            builder,
            refinement: None,
        }
    }

    /// `builder` then the default refinement.
    pub const fn refined(builder: Builder) -> Method {
        Method {
            builder,
            refinement: Some(Refinement::Default),
        }
    }

    /// The grouping phase with AABB p-sets and the given parameters.
    pub const GROUPING: Method = Method::of(Builder::Grouping);
    /// The grouping phase with convex-hull p-sets.
    pub const GROUPING_HULL: Method = Method::of(Builder::GroupingHull);
    /// The grouping phase in the partitioned schedule.
    pub const GROUPING_PARTITIONED: Method = Method::of(Builder::GroupingPartitioned);
    /// The grouping phase with connected components pre-grouped.
    pub const GROUPING_PREGROUP: Method = Method::of(Builder::GroupingPregroup);
    /// The grouping phase with connected components pre-grouped and copies copy-moved.
    pub const GROUPING_INSTANCED: Method = Method::of(Builder::GroupingInstanced);
    /// The grouping phase with the scene's objects pre-grouped and copies copy-moved.
    pub const GROUPING_OBJECTS: Method = Method::of(Builder::GroupingObjects);
    /// The fast path's split, unrefined.
    pub const GROUPING_FAST: Method = Method::of(Builder::GroupingFast);
    /// parry3d `Bvh`, binned SAH.
    pub const PARRY_BINNED: Method = Method::of(Builder::ParryBinned);
    /// parry3d `Bvh`, PLOC.
    pub const PARRY_PLOC: Method = Method::of(Builder::ParryPloc);
    /// obvhs PLOC.
    pub const OBVHS_PLOC: Method = Method::of(Builder::ObvhsPloc);
    /// obvhs PLOC then its reinsertion.
    pub const OBVHS_PLOC_REINSERT: Method = Method::of(Builder::ObvhsPlocReinsert);
    /// Top-down median split.
    pub const MEDIAN_SPLIT: Method = Method::of(Builder::MedianSplit);
    /// Goldsmith–Salmon incremental insertion.
    pub const GOLDSMITH_SALMON: Method = Method::of(Builder::GoldsmithSalmon);
    /// The exact grouping refined.
    pub const GROUPING_REFINE: Method = Method::refined(Builder::Grouping);
    /// parry Binned refined.
    pub const PARRY_BINNED_REFINE: Method = Method::refined(Builder::ParryBinned);
    /// obvhs PLOC refined.
    pub const OBVHS_PLOC_REFINE: Method = Method::refined(Builder::ObvhsPloc);
    /// The partitioned grouping refined.
    pub const GROUPING_PARTITIONED_REFINE: Method = Method::refined(Builder::GroupingPartitioned);
    /// The fast path: the fast path's split, then its refinement ([`Refinement::Fast`]).
    pub const FAST: Method = Method {
        builder: Builder::GroupingFast,
        refinement: Some(Refinement::Fast),
    };

    /// What a bench compares by default: the paper's exact run, the fast path, the exact run
    /// refined, the partitioned schedule, and the peers users choose between (parry Binned,
    /// obvhs PLOC with and without reinsertion). The others (the hull p-set, pre-grouping,
    /// the peers refined, median split, Goldsmith–Salmon) on request.
    pub const DEFAULT: [Method; 7] = [
        Method::GROUPING,
        Method::FAST,
        Method::GROUPING_REFINE,
        Method::GROUPING_PARTITIONED,
        Method::PARRY_BINNED,
        Method::OBVHS_PLOC,
        Method::OBVHS_PLOC_REINSERT,
    ];

    /// Every named method, ours first (`--methods all`).
    pub const ALL: [Method; 18] = [
        Method::GROUPING,
        Method::FAST,
        Method::GROUPING_FAST,
        Method::GROUPING_REFINE,
        Method::GROUPING_HULL,
        Method::GROUPING_PARTITIONED,
        Method::GROUPING_PARTITIONED_REFINE,
        Method::GROUPING_PREGROUP,
        Method::GROUPING_INSTANCED,
        Method::GROUPING_OBJECTS,
        Method::PARRY_BINNED,
        Method::PARRY_PLOC,
        Method::OBVHS_PLOC,
        Method::OBVHS_PLOC_REINSERT,
        Method::MEDIAN_SPLIT,
        Method::GOLDSMITH_SALMON,
        Method::PARRY_BINNED_REFINE,
        Method::OBVHS_PLOC_REFINE,
    ];

    /// Short name used in tables, CSV and on the command line: the builder's, `NAME+refine`
    /// with the default refinement, and `fast` for the fast path ([`Method::FAST`]); another
    /// builder with the fast path's refinement is `NAME+refine-fast`.
    pub fn name(self) -> &'static str {
        match self.refinement {
            None => self.builder.name(),
            Some(Refinement::Default) => self.builder.refined_name(),
            Some(Refinement::Fast) if self.builder == Builder::GroupingFast => "fast",
            Some(Refinement::Fast) => "+refine-fast",
        }
    }

    /// Parses a name of [`Method::ALL`] as printed by [`Method::name`].
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
        self.builder.is_grouping()
    }

    /// Whether the builder's tree goes through [`crate::refine`].
    pub fn is_refined(self) -> bool {
        self.refinement.is_some()
    }

    /// The builder without refinement.
    pub fn base(self) -> Method {
        Method::of(self.builder)
    }

    /// The schedule this method groups with under `params`, for the grouping builders:
    /// `grouping-partitioned` takes `params`' schedule when it is partitioned (else the default
    /// chunking), `grouping-fast` [`Schedule::FAST`] whatever `params` say, the others the
    /// exact schedule.
    pub fn schedule(self, params: &Params) -> Option<Schedule> {
        match self.builder {
            Builder::GroupingPartitioned => Some(match params.mode.schedule {
                s @ Schedule::Partitioned(_) => s,
                Schedule::Exact => Schedule::PARTITIONED,
            }),
            Builder::GroupingFast => Some(Schedule::FAST),
            b if b.is_grouping() => Some(Schedule::Exact),
            _ => None,
        }
    }

    /// The partitioned schedule's settings this method groups a scene of `n` primitives with
    /// under `params` ([`Method::schedule`]): `delta=… epsilon=… top=… sah=…`, as the
    /// `--chunk-*` flags name them, with δ as the run uses it ([`Chunking::for_size`]).
    pub fn chunking(self, params: &Params, n: usize) -> Option<String> {
        let c = self.schedule(params)?.chunking()?.for_size(n);
        Some(format!(
            "delta={} epsilon={} top={} sah={}",
            c.delta, c.epsilon, c.top, c.sah_below
        ))
    }
}

impl serde::Serialize for Method {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
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
    let mut built = build_base(method.builder, scene, params, stop)?;
    if let Some(refinement) = method.refinement {
        let t = Instant::now();
        let Built {
            tree,
            seconds,
            stats,
            ..
        } = built;
        let params = refinement.params(tree.leaves());
        let tree = refine::refine_owned(tree, &params, ()).tree;
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

/// Builds `builder`'s hierarchy (see [`build`]).
fn build_base(
    builder: Builder,
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
    let method = Method::of(builder);
    let done = |tree: SubsetTree, stats: Option<Stats>, seconds: f64| Built {
        method,
        tree,
        seconds,
        stats,
        refine_seconds: 0.0,
    };
    if builder.is_grouping() {
        let mut p = Params {
            pset: if builder == Builder::GroupingHull {
                PSet::Hull
            } else {
                params.pset
            },
            ..params.clone()
        };
        let (pregroup, instancing) = match builder {
            Builder::GroupingPregroup => (Pregroup::Connected, false),
            Builder::GroupingInstanced => (Pregroup::Connected, true),
            Builder::GroupingObjects => (Pregroup::Objects, true),
            _ => (p.mode.pregroup, p.mode.instancing),
        };
        if pregroup != Pregroup::None {
            p.pset = PSet::Aabb;
        }
        p.mode.pregroup = pregroup;
        p.mode.instancing = instancing;
        if let Some(schedule @ Schedule::Partitioned(_)) = method.schedule(params) {
            p.pset = PSet::Aabb;
            p.mode.schedule = schedule;
        } else {
            p.mode.schedule = Schedule::Exact;
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
    let (nodes, root, seconds) = match builder {
        Builder::ParryBinned | Builder::ParryPloc => {
            let boxes = topology::local_boxes(scene);
            let strategy = if builder == Builder::ParryBinned {
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
        Builder::ObvhsPloc | Builder::ObvhsPlocReinsert => {
            let boxes = topology::local_boxes(scene);
            let t = Instant::now();
            let bvh = obvhs_ploc::build(&boxes, builder == Builder::ObvhsPlocReinsert);
            let s = t.elapsed().as_secs_f64();
            let (nodes, root) = obvhs_ploc::topology(&bvh);
            (nodes, root, s)
        }
        Builder::MedianSplit => {
            let centres: Vec<_> = (0..scene.len())
                .map(|i| scene.prim_aabb(i).center())
                .collect();
            let t = Instant::now();
            let (nodes, root) = median_split::build(&centres);
            (nodes, root, t.elapsed().as_secs_f64())
        }
        Builder::GoldsmithSalmon => {
            let boxes: Vec<_> = (0..scene.len()).map(|i| scene.prim_aabb(i)).collect();
            let t = Instant::now();
            let (nodes, root) = goldsmith_salmon::build(&boxes);
            (nodes, root, t.elapsed().as_secs_f64())
        }
        Builder::Grouping
        | Builder::GroupingHull
        | Builder::GroupingPregroup
        | Builder::GroupingInstanced
        | Builder::GroupingObjects
        | Builder::GroupingPartitioned
        | Builder::GroupingFast => unreachable!("handled above"),
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
        let by_size = |n| Method::GROUPING_PARTITIONED.chunking(&p, n);
        let d = "delta=4096 epsilon=0.5 top=8192 sah=256";
        assert_eq!(by_size(1 << 18).as_deref(), Some(d));
        let above = "delta=4 epsilon=0.5 top=8192 sah=256";
        assert_eq!(by_size((1 << 18) + 1).as_deref(), Some(above));
        p.mode.schedule = Schedule::Partitioned(crate::grouping::partitioned::Chunking {
            delta: 16,
            ..crate::grouping::partitioned::Chunking::DEFAULT
        });
        let d = "delta=16 epsilon=0.5 top=8192 sah=256";
        assert_eq!(
            Method::GROUPING_PARTITIONED.chunking(&p, 10).as_deref(),
            Some(d)
        );
        assert_eq!(
            Method::GROUPING_PARTITIONED_REFINE
                .chunking(&p, 1 << 20)
                .as_deref(),
            Some(d)
        );
        // The fast path keeps its own chunks whatever `params` say.
        let f = "delta=2 epsilon=0.5 top=16 sah=256";
        assert_eq!(Method::FAST.chunking(&p, 10).as_deref(), Some(f));
        assert_eq!(
            Method::GROUPING_FAST.chunking(&p, 1 << 20).as_deref(),
            Some(f)
        );
        // Every name of `ALL` parses back to its method.
        for m in Method::ALL {
            assert_eq!(Method::parse(m.name()), Ok(m));
        }
        for m in [
            Method::GROUPING,
            Method::GROUPING_REFINE,
            Method::OBVHS_PLOC,
        ] {
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
        let b = build(Method::MEDIAN_SPLIT, &scene, &Params::default()).unwrap();
        assert_eq!(b.tree.depth_max(), 10);
    }
}
