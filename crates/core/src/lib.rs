//! wraptree-core: the grouping phase of Xavier, "A Generic Algorithm for Constructing
//! Hierarchical Representations of Geometric Objects", and what is built on its Subset Tree:
//! scenes and their loaders, typed events, the grouping itself, refinement, Wrapper Trees,
//! covers and queries. It has no viewer, recording or plotting dependency; the `wraptree` crate
//! adds the `.rrd` and `.mcap` recordings, figures, benchmarks and the command line, and
//! re-exports these modules under the same names. The modules are layers, each using only those
//! below it (`docs/architecture.md`); the algorithm is described in `docs/method.md`.
//!
//! Group a scene and ask the tree for the distance from a point:
//!
//! ```
//! use wraptree_core::geom::P3;
//! use wraptree_core::grouping::{Params, group};
//! use wraptree_core::query::{Bv, Counts, Hierarchy, point_distance};
//!
//! let scene = wraptree_core::scene::generate::soup(1_000, 1);
//! let tree = group(&scene, &Params::default(), ()).tree;
//! assert_eq!(tree.leaves(), 1_000);
//! let h = Hierarchy { tree: &tree, scene: &scene, bv: Bv::Aabb };
//! let d = point_distance(&h, &P3::new(2.0, 0.5, 0.5), &mut Counts::default());
//! assert!(d > 0.9 && d < 1.1);
//! ```
#![deny(missing_docs)]

pub mod events;
pub mod geom;
pub mod grouping;
pub mod output;
pub mod par;
pub mod query;
pub mod refine;
pub mod scene;
pub mod spherize;
pub mod stop;
pub mod wrap;
