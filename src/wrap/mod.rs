//! Wrapper Trees (§2.4): a covering shape for every node of a Subset Tree, index = node id.
//!
//! - [`sphere`] — bounding spheres: merged from the children's (O(N)), or from the leaves'
//!   vertices around the AABB centre (the paper's choice), by Ritter's approximation, or the
//!   exact minimum enclosing sphere ([`welzl`]);
//! - [`hull`] — convex hulls, built from the children's hull vertices, robust to flat,
//!   collinear and duplicate points (never panics);
//! - axis-aligned boxes are the Subset Tree's own [`SubsetTree::aabb`](crate::grouping::SubsetTree);
//! - [`obb`] — oriented boxes from the principal axes ([`crate::geom::pca`]);
//! - [`kind`] — [`WrapperKind`] (`--wrapper`) and [`Wrappers`], several trees built together;
//! - [`tightness`] — per-level volume, volume ratio and surface-to-geometry error;
//! - [`distance`] — exact point–primitive distances with the Subset Tree as BVH;
//! - [`report`] — build time, containment check and tightness of several trees together.
//!
//! Everything is `f64` except parry's hull decision (`f32`). Containment of every vertex below
//! a node holds up to rounding for spheres, boxes and OBBs (tests allow 1e-9 × the scene
//! diagonal) and up to [`HULL_TOL_REL`] × the node's AABB diameter for hulls.
//!
//! ```no_run
//! # fn demo(tree: &wraptree::grouping::SubsetTree, scene: &wraptree::scene::Scene) {
//! use wraptree::wrap::{SphereMethod, WrapperKind, Wrappers, hull_tree, level_tightness};
//! let kinds = WrapperKind::parse_list("sphere,hull").unwrap();
//! let w = Wrappers::build(tree, scene, &kinds, SphereMethod::Minimum);
//! let hulls = w.hulls.as_deref().unwrap();
//! for t in w.trees() {
//!     let stats = level_tightness(tree, scene, t, hulls, wraptree::wrap::DEFAULT_SAMPLES);
//!     println!("{}: {:?}", t.kind().name(), stats.last());
//! }
//! # }
//! ```

pub mod cover;
pub mod distance;
pub mod hull;
pub mod kind;
pub mod obb;
pub mod order;
pub mod report;
pub mod sphere;
pub mod tightness;
pub mod welzl;

pub use crate::geom::Sphere;
pub use hull::{HULL_TOL_REL, Hull, hull_tree};
pub use kind::{WrapperKind, WrapperTree, Wrappers};
pub use obb::{Obb, obb_tree};
pub use order::LeafOrder;
pub use sphere::{SphereMethod, sphere_tree};
pub use tightness::{
    DEFAULT_SAMPLES, LevelStats, NodeStats, containment_excess, level_tightness, node_tightness,
};
