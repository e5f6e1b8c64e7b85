//! wraptree: build, record and inspect bounding-volume hierarchies with the bottom-up grouping
//! phase of Xavier, "A Generic Algorithm for Constructing Hierarchical Representations of
//! Geometric Objects". The modules are layers, each using only those below it
//! (`docs/architecture.md`); the algorithm is described in `docs/method.md`.
//!
//! Each `wraptree` command is one call here, and what it prints is built here too:
//!
//! | command | entry point | what it prints |
//! |---|---|---|
//! | `group` | [`grouping::group`], [`grouping::group_within`] with [`grouping::Limits`] | [`metrics::report::group_text`], [`metrics::report::group_json`] |
//! | `record` | [`record::record`] with [`record::RecordOptions`] | [`record::Written::summary`] |
//! | `replay` | [`replay::open`], [`replay::verify`], [`replay::reweight`] | [`replay::report`] |
//! | `wrap` | [`wrap::report::report`] | [`wrap::report::report_text`] |
//! | `cover` | [`wrap::cover::solve::cover_scene`], [`wrap::cover::solve::solve`] | [`wrap::cover::solve::CoverSummary::text`] |
//! | `snapshot` | [`render::snapshot::draw`] | [`render::snapshot::Snapshot::text`] |
//! | `bench` | [`metrics::compare::evaluate`], [`metrics::bench`] | [`metrics::report::bench_table`], [`metrics::report::target_line`], … |
//! | `sweep` | [`metrics::sweep::sweep`] | [`metrics::report::sweep_table`] |
//! | `stress` | [`metrics::stress::run`] | [`metrics::report::stress_table`] |
//! | `spherize` | [`spherize::spherize`], [`spherize::score_set`], [`record::spherize::record_spherized`] | [`spherize::Report::text`], [`spherize::score_text`] |
//! | `scene` | [`scene::generate::by_name`] | |
//!
//! Group a scene and ask the tree for the distance from a point (as `examples/query_tree.rs`):
//!
//! ```
//! use wraptree::geom::P3;
//! use wraptree::grouping::{Params, group};
//! use wraptree::query::{Bv, Counts, Hierarchy, point_distance};
//!
//! let scene = wraptree::scene::generate::soup(1_000, 1);
//! let tree = group(&scene, &Params::default(), ()).tree;
//! assert_eq!(tree.leaves(), 1_000);
//! let h = Hierarchy { tree: &tree, scene: &scene, bv: Bv::Aabb };
//! let d = point_distance(&h, &P3::new(2.0, 0.5, 0.5), &mut Counts::default());
//! assert!(d > 0.9 && d < 1.1);
//! ```
#![deny(missing_docs)]

pub use wraptree_core::{
    events, geom, grouping, output, par, query, refine, scene, spherize, stop, wrap,
};

pub mod metrics;
pub mod peers;
pub mod record;
pub mod render;
pub mod replay;
