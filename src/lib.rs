//! wraptree: build, record and inspect bounding-volume hierarchies with the bottom-up grouping
//! phase of Xavier, "A Generic Algorithm for Constructing Hierarchical Representations of
//! Geometric Objects".
//!
//! Data flows [`scene`] → [`grouping`] (Subset Tree, §2.2) → [`wrap`] (Wrapper Trees, §2.4) →
//! [`record`] (`.rrd`, `.mcap`), [`replay`], [`render`], [`metrics`] and [`query`]; [`peers`]
//! wraps the hierarchies it is compared with, and [`geom`] is the small geometry every stage
//! shares. Each `wraptree` command is a thin layer over one entry point here:
//!
//! | command | entry point |
//! |---|---|
//! | `group` | [`grouping::group`], [`grouping::group_within`] with [`grouping::Limits`] |
//! | `record` | [`record::record`] with [`record::RecordOptions`] |
//! | `replay` | [`replay::open`], [`replay::verify`], [`replay::reweight`] |
//! | `wrap` | [`wrap::report::report`] |
//! | `cover` | [`wrap::cover::solve::cover_scene`], [`wrap::cover::solve::solve`] |
//! | `snapshot` | [`render::snapshot::draw`] |
//! | `bench` | [`metrics::compare::evaluate`], [`metrics::bench`] |
//! | `sweep` | [`metrics::sweep::sweep`] |
//! | `stress` | [`metrics::stress::run`] |
//! | `scene` | [`scene::generate::by_name`] |
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

pub mod geom;
pub mod grouping;
pub mod metrics;
pub mod peers;
pub mod query;
pub mod record;
pub mod refine;
pub mod render;
pub mod replay;
pub mod scene;
pub mod wrap;
