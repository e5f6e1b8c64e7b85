//! Wrapper Trees (§2.4): a covering shape for every node of a Subset Tree, index = node id
//! (`docs/method.md`, "Wrapper Trees").
//!
//! - [`sphere`] — bounding spheres: merged from the children's, around the AABB centre (the
//!   paper's choice), by Ritter's approximation, or the exact minimum ([`welzl`]);
//! - [`hull`] — convex hulls from the children's hull vertices, robust to degenerate input;
//! - axis-aligned boxes: the Subset Tree's own [`SubsetTree::aabb`](crate::grouping::SubsetTree);
//! - [`obb`] — oriented boxes from the principal axes ([`crate::geom::pca`]);
//! - [`kind`] — [`WrapperKind`] (`--wrapper`) and [`Wrappers`], several trees built together;
//! - [`tightness`], [`report`] — volume, error and containment per level; [`distance`] — exact
//!   point–primitive distances; [`cover`] — the fewest wrappers within an error.
//!
//! Everything is `f64`, and hull faces are decided exactly: every wrapper contains the vertices
//! below its node up to rounding, hulls up to [`HULL_TOL_REL`] × the node's AABB diameter.

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
pub use hull::{HULL_TOL_REL, Hull, hull_tree, hull_tree_until};
pub use kind::{WrapperKind, WrapperTree, Wrappers};
pub use obb::{Obb, obb_tree, obb_tree_until};
pub use order::LeafOrder;
pub use sphere::{SphereMethod, sphere_tree, sphere_tree_until};
pub use tightness::{
    DEFAULT_SAMPLES, DepthSample, LevelStats, MAX_VISITS, NODES_PER_DEPTH, NodeStats,
    containment_excess, containment_excess_until, level_tightness, level_tightness_sampled,
    node_tightness, nodes_tightness,
};
