//! Subproblems of at most [`MAX_BODIES`] bodies, solved by brute force: the size dispatcher
//! between the two solvers, [`all_pairs`] (at most [`all_pairs::MAX_BODIES`] bodies, fixed
//! arrays) and [`partner_table`] (a table of every pair and each body's cheapest partner).
//! Both make the merges of the exact schedule run on the same bodies with the same limits.

use super::subproblem::{Body, Leftover, MergeSlots, PairList, RunInputs};
use super::{all_pairs, partner_table};

/// The most bodies a subproblem may have to be solved by brute force (more go to
/// `voxel_step`).
pub(super) const MAX_BODIES: usize = partner_table::MAX_BODIES;

/// Groups the bodies of `body` (at most [`MAX_BODIES`]: the first `parts[0].n` of one half, then
/// `parts[1].n` of the other) until `keep` remain, writing merge `i` to `out` at index `i`
/// with new id `first_new + i`; the bodies left end up at the start of `body`. Returns how many,
/// with their pairs when `export` (the merges do not depend on the order of the bodies: every
/// choice is by Cost and tie tags). A part's pairs, when given, are used instead of evaluating
/// them again.
pub(super) fn combine(
    ctx: &RunInputs,
    body: &mut [Body],
    parts: [Leftover; 2],
    keep: usize,
    out: &mut MergeSlots<'_>,
    export: bool,
) -> Leftover {
    if body.len() <= keep {
        return Leftover {
            n: body.len(),
            pairs: PairList::new(),
        };
    }
    if body.len() <= all_pairs::MAX_BODIES {
        return all_pairs::combine_few(ctx, body, parts, keep, out, export);
    }
    partner_table::combine_by_partners(ctx, body, parts, keep, out, export)
}
