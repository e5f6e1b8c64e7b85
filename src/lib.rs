//! wraptree: build, record and inspect bounding-volume hierarchies with the bottom-up grouping
//! phase of Xavier, "A Generic Algorithm for Constructing Hierarchical Representations of
//! Geometric Objects".
//!
//! Data flows `scene` → `grouping` (Subset Tree, §2.2) → `wrap` (Wrapper Trees, §2.4) →
//! `record` (`.rrd`, `.mcap`).

pub mod geom;
pub mod grouping;
pub mod metrics;
pub mod peers;
pub mod query;
pub mod record;
pub mod render;
pub mod replay;
pub mod scene;
pub mod wrap;
