//! What both brute-force solvers (`partner_table` and
//! `all_pairs`) share: a pair's Cost and first eligible round, every pair of
//! a subproblem, the merged body, the merge written out with what its events read, and the
//! bodies left with their pairs.

use super::subproblem::{Body, Counters, Leftover, MergeInfo, MergeSlots, PairList, RunInputs};
use crate::grouping::cluster::{fill_balance, pair_cost_any};
use crate::grouping::mpairs::order_bits;

/// The Cost (as [`order_bits`]) and first eligible round of the pair `a`, `b`.
#[inline(always)]
pub(super) fn eval(ctx: &RunInputs, a: &Body, b: &Body) -> (u64, u32) {
    let d = a.aabb.merge(&b.aabb).diameter();
    let round = a
        .first_round
        .max(b.first_round)
        .max(ctx.gl.first(a.aabb.gap_linf(&b.aabb)));
    let cost = pair_cost_any(&ctx.params.weights, d, a.diameter, b.diameter);
    (order_bits(cost), round)
}

/// Every pair of `body` (`set(i, j, pair)`, `i < j`): each part's own pairs (copied when the
/// part brings them, else evaluated), then the pairs across the parts; evaluations are counted.
#[inline(always)]
pub(super) fn pairs_of(
    ctx: &RunInputs,
    body: &[Body],
    parts: &[Leftover; 2],
    st: &mut Counters,
    mut set: impl FnMut(usize, usize, (u64, u32)),
) {
    let (ka, m) = (parts[0].n, body.len());
    for (lo, hi, pairs) in [(0, ka, &parts[0].pairs), (ka, m, &parts[1].pairs)] {
        let k = hi - lo;
        let mut given = (pairs.len() == k * (k.max(1) - 1) / 2).then_some(pairs.iter());
        for i in lo..hi {
            for j in i + 1..hi {
                let pair = match &mut given {
                    Some(it) => *it.next().expect("k(k-1)/2 pairs"),
                    None => {
                        st.candidates += 1;
                        eval(ctx, &body[i], &body[j])
                    }
                };
                set(i, j, pair);
            }
        }
    }
    for i in 0..ka {
        for j in ka..m {
            set(i, j, eval(ctx, &body[i], &body[j]));
        }
    }
    st.candidates += (ka * (m - ka)) as u64;
}

/// The body made by merging `x` and `y`, with id `new`.
#[inline(always)]
pub(super) fn merged(ctx: &RunInputs, x: &Body, y: &Body, new: u32) -> Body {
    let aabb = x.aabb.merge(&y.aabb);
    let d = aabb.diameter();
    Body {
        id: new,
        first_round: ctx.dl.first(d),
        aabb,
        diameter: d,
    }
}

/// Writes merge `made` of `x` and `y` into `nb` in round `round` to `out`, with what only
/// events read (Fill, Balance, Cost, `queue_len`) when someone listens.
#[inline(always)]
pub(super) fn put_merge(
    ctx: &RunInputs,
    out: &mut MergeSlots<'_>,
    made: usize,
    [x, y]: [&Body; 2],
    nb: &Body,
    round: u32,
    queue_len: impl FnOnce() -> u32,
) {
    let d = nb.diameter;
    let info = if out.listens() {
        merge_info(ctx, [d, x.diameter, y.diameter], round, queue_len())
    } else {
        MergeInfo::default()
    };
    out.put(made, [x.id.min(y.id), x.id.max(y.id)], nb.aabb, d, info);
}

/// What the events of a merge in round `round` read beyond the tree, for a new body of
/// diameter `d` from bodies of diameters `dx` and `dy`, with `queue_len` entries queued after it.
pub(super) fn merge_info(
    ctx: &RunInputs,
    [d, dx, dy]: [f64; 3],
    round: u32,
    queue_len: u32,
) -> MergeInfo {
    let (fill, balance) = fill_balance(d, dx, dy);
    MergeInfo {
        round,
        fill,
        balance,
        cost: ctx.params.weights.cost(d, fill, balance),
        queue_len,
        active: d <= ctx.dl.at(round),
    }
}

/// Moves the bodies of the `live` slots (increasing) to the start of `body` and returns them,
/// with their pairs (`pair(i, j)`, row by row) when `export`.
pub(super) fn leave(
    body: &mut [Body],
    live: &[usize],
    export: bool,
    pair: impl Fn(usize, usize) -> (u64, u32),
) -> Leftover {
    let pairs = if export {
        let mut v = PairList::with_capacity(live.len() * (live.len() - 1) / 2);
        for (x, &i) in live.iter().enumerate() {
            v.extend(live[x + 1..].iter().map(|&j| pair(i, j)));
        }
        v
    } else {
        PairList::new()
    };
    for (k, &i) in live.iter().enumerate() {
        body[k] = body[i];
    }
    Leftover {
        n: live.len(),
        pairs,
    }
}
