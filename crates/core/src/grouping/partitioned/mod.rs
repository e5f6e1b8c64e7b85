//! The partitioned schedule: the §2.2 grouping step run inside the chunks of a top-down split,
//! bottom-up and in parallel (approximate agglomerative clustering, AAC: Gu, He, Fatahalian and
//! Blelloch 2013, "Efficient BVH Construction via Approximate Agglomerative Clustering").
//!
//! The primitives are sorted by Morton code (`split`), neighbours with identical boxes are
//! merged first where the chunking asks (`twins`), the sorted range is split into chunks
//! (`plan`, with what each node keeps for its parent from `keep`), and each chunk and each
//! node of the split groups its bodies with the paper's Cost and limits (`executor`): by brute
//! force up to 64 bodies (`brute_force`, `all_pairs`), with the exact run's voxel hash and
//! MPairs above (`voxel_step`). Merge steps are numbered in the split's post-order before any
//! grouping starts, so the tree is the same for any number of threads. After the grouping, the
//! finished subproblems are announced as events in that order (`announce`). The hull p-set has
//! no partitioned form: with it the exact schedule runs. docs/method.md tells the whole story.

mod all_pairs;
mod announce;
mod brute_force;
mod chunking;
mod executor;
mod group;
mod keep;
mod pairs;
mod partner_table;
mod plan;
mod round_limits;
mod sort;
mod split;
mod subproblem;
#[cfg(test)]
mod tests;
mod twins;
mod voxel_step;

pub use chunking::Chunking;
pub use group::{group_boxes, group_with};
