//! Wrapper Trees (§2.4): a covering shape for every node of a Subset Tree.
//!
//! - [`sphere`] — bounding spheres, either merged from the children's spheres (O(N)) or computed
//!   from the leaves' vertices around the node's AABB centre (the paper's choice, tighter).

pub mod sphere;

pub use sphere::{Sphere, SphereMethod, sphere_tree};
