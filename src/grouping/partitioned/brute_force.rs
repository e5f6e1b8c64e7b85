//! The agglomerative step of §2.2 by brute force, for subproblems of at most [`SMALL`] bodies.
//!
//! Every pair of bodies gets, once, its Cost and the first round in which it is eligible: the
//! smallest `r` with both diameters ≤ DLimit0·2^r and the L∞ gap ≤ GLimit0·2^r (the limits of
//! round `r` are DLimit0 and GLimit0 doubled `r` times, as in the exact run). Each body keeps
//! its cheapest partner among the pairs eligible in the current round; the cheapest of those
//! is merged, the merged body takes the slot of one of its children, and only the bodies whose
//! partner was one of the children search their row again. When no pair is eligible, the run
//! moves to the first round in which one is (the rounds in between would merge nothing). Pairs
//! are ordered by (Cost, smaller tie tag, larger tie tag) as in MPairs, so the merges are those
//! of the exact schedule run on the same bodies with the same limits. A half of the split that
//! was solved here passes its bodies' pairs up with them (`Leftover`), so its parent evaluates only
//! the pairs across the two halves (a pair's Cost and round depend on its two bodies alone).

use super::subproblem::{Body, Counters, Leftover, MergeInfo, MergeSlots, PairList, RunInputs};
use crate::grouping::cluster::{fill_balance, pair_cost_any, tie_tag};
use crate::grouping::mpairs::order_bits;
use std::cell::RefCell;

/// The most bodies a subproblem may have to be solved by brute force.
pub(super) const SMALL: usize = 64;

/// A round that never comes (NaN sizes).
pub(super) const NEVER: u32 = u32::MAX;

/// The limits of every round: `tab[r]` = `base` doubled `r` times, up to the first infinity.
pub(super) struct RoundLimits {
    tab: Vec<f64>,
}

impl RoundLimits {
    /// The doubling sequence of `base` (> 0).
    pub(super) fn new(base: f64) -> RoundLimits {
        let bits = base.to_bits();
        let exp = (bits >> 52) & 0x7ff;
        if base > 0.0 && exp != 0 && exp != 0x7ff {
            // A positive normal base: each doubling adds one to the exponent field, exactly,
            // until it would reach 2047 (infinity). Independent entries, not a chain of
            // multiplications: the table has up to 2,047 of them, built for every run.
            let last = 0x7ff - exp;
            let tab = (0..=last)
                .map(|r| {
                    if r < last {
                        f64::from_bits(bits + (r << 52))
                    } else {
                        f64::INFINITY
                    }
                })
                .collect();
            return RoundLimits { tab };
        }
        let mut tab = vec![base];
        let mut v = base;
        while v < f64::INFINITY && tab.len() < 4096 {
            v *= 2.0;
            tab.push(v);
        }
        RoundLimits { tab }
    }

    /// The number of rounds before the limit is infinite (the last one's is).
    #[cfg(test)]
    pub(super) fn rounds(&self) -> usize {
        self.tab.len()
    }

    /// The limit of round `r`.
    #[inline]
    pub(super) fn at(&self, r: u32) -> f64 {
        self.tab[(r as usize).min(self.tab.len() - 1)]
    }

    /// The first round whose limit is ≥ `x` ([`NEVER`] for NaN).
    #[inline]
    pub(super) fn first(&self, x: f64) -> u32 {
        let t = &self.tab;
        if x <= t[0] {
            return 0;
        }
        if x.is_nan() {
            return NEVER;
        }
        let last = t.len() - 1;
        // t[r] = t[0]·2^r exactly, so for normal numbers the answer is the difference of the
        // binary exponents, plus one when x's mantissa is the larger (no branch to mispredict);
        // the steps below then do nothing, and fix subnormal limits and the infinite end.
        let (bx, b0) = (x.to_bits(), t[0].to_bits());
        let e = |b: u64| ((b >> 52) & 0x7ff) as i64;
        let frac = |b: u64| b & ((1 << 52) - 1);
        let r = e(bx) - e(b0) + i64::from(frac(bx) > frac(b0));
        let mut r = r.clamp(0, last as i64) as usize;
        while r < last && t[r] < x {
            r += 1;
        }
        while r > 0 && t[r - 1] >= x {
            r -= 1;
        }
        r as u32
    }
}

/// The pairs of a subproblem: Cost (as [`order_bits`]) and first eligible round of every
/// ordered pair of slots, each body's cheapest partner eligible in the current round, and the
/// first later round in which any of its pairs becomes eligible (a lower bound once partners
/// merge away).
struct Table {
    m: usize,
    cost: Vec<u64>,
    round: Vec<u32>,
    tag: Vec<u64>,
    /// Slots holding a body, in no particular order.
    live: Vec<usize>,
    best: Vec<usize>,
    next: Vec<u32>,
}

/// No partner.
const NO: usize = usize::MAX;

impl Table {
    /// Whether partner `j` comes before partner `b` in slot `i`'s row (Cost, then tie tag).
    #[inline(always)]
    fn better(&self, i: usize, j: usize, b: usize) -> bool {
        if b == NO {
            return true;
        }
        let (cj, cb) = (self.cost[i * self.m + j], self.cost[i * self.m + b]);
        cj < cb || (cj == cb && self.tag[j] < self.tag[b])
    }

    /// Finds slot `i`'s cheapest partner eligible in round `r` and its next round; returns the
    /// number of its eligible pairs with a larger slot.
    fn scan_row(&mut self, i: usize, r: u32) -> u64 {
        let (mut b, mut next, mut above) = (NO, NEVER, 0u64);
        let row = i * self.m;
        for &j in &self.live {
            if j == i {
                continue;
            }
            let rj = self.round[row + j];
            if rj <= r {
                above += u64::from(j > i);
                if self.better(i, j, b) {
                    b = j;
                }
            } else if rj < next {
                next = rj;
            }
        }
        self.best[i] = b;
        self.next[i] = next;
        above
    }

    /// The pair merged next: the cheapest eligible pair by (Cost, smaller tag, larger tag).
    fn top(&self) -> Option<(usize, usize)> {
        let mut top: Option<(usize, usize)> = None;
        for &i in &self.live {
            let j = self.best[i];
            if j == NO {
                continue;
            }
            let wins = match top {
                None => true,
                Some((k, l)) => {
                    let (c, d) = (self.cost[i * self.m + j], self.cost[k * self.m + l]);
                    let key = |x: usize, y: usize| {
                        let (a, b) = (self.tag[x], self.tag[y]);
                        (a.min(b), a.max(b))
                    };
                    c < d || (c == d && key(i, j) < key(k, l))
                }
            };
            if wins {
                top = Some((i, j));
            }
        }
        top
    }
}

thread_local! {
    /// Each thread's table, reused by its subproblems (no allocation per subproblem).
    static TABLE: RefCell<Table> = const { RefCell::new(Table {
        m: 0,
        cost: Vec::new(),
        round: Vec::new(),
        tag: Vec::new(),
        live: Vec::new(),
        best: Vec::new(),
        next: Vec::new(),
    }) };
}

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

/// Groups the bodies of `body` (at most [`SMALL`]: the first `parts[0].n` of one half, then
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
    if body.len() <= super::all_pairs::TINY {
        return super::all_pairs::run(ctx, body, parts, keep, out, export);
    }
    TABLE.with(|t| run(ctx, body, parts, keep, out, export, &mut t.borrow_mut()))
}

/// [`combine`] with the thread's table.
fn run(
    ctx: &RunInputs,
    body: &mut [Body],
    parts: [Leftover; 2],
    keep: usize,
    out: &mut MergeSlots<'_>,
    export: bool,
    t: &mut Table,
) -> Leftover {
    let m = body.len();
    debug_assert!(m <= SMALL && keep >= 1 && parts[0].n + parts[1].n == m);
    let mut st = Counters::default();
    let seed = ctx.params.seed;
    t.m = m;
    if t.cost.len() < m * m {
        t.cost.resize(m * m, 0);
        t.round.resize(m * m, NEVER);
    }
    t.tag.clear();
    t.tag.extend(body.iter().map(|b| tie_tag(seed, b.id)));
    t.live.clear();
    t.live.extend(0..m);
    t.best.clear();
    t.best.resize(m, NO);
    // Not scanned yet: every row is scanned at the first round start.
    t.next.clear();
    t.next.resize(m, 0);
    pairs_of(ctx, body, &parts, &mut st, |i, j, (c, r)| {
        (t.cost[i * m + j], t.round[i * m + j]) = (c, r);
        (t.cost[j * m + i], t.round[j * m + i]) = (c, r);
    });
    let mut round = 0u32;
    let mut made = 0usize;
    let mut fresh = true;
    while t.live.len() > keep {
        if fresh {
            // Round start: every body's cheapest eligible partner. When a round ends no body
            // has one, so only bodies with a pair eligible from this round on can gain one.
            for k in 0..t.live.len() {
                let i = t.live[k];
                if t.next[i] <= round {
                    st.eligible_pairs += t.scan_row(i, round);
                }
            }
            fresh = false;
        }
        let Some((i, j)) = t.top() else {
            // Step 5, as often as it takes for a pair to become eligible.
            let next = t.live.iter().map(|&i| t.next[i]).min().unwrap_or(NEVER);
            assert!(next != NEVER, "bodies of NaN size never become eligible");
            round = next;
            fresh = true;
            continue;
        };
        let (i, j) = (i.min(j), i.max(j));
        let (a, b) = (body[i], body[j]);
        let new = out.first_new + made as u32;
        st.pops += 1;
        // The new body takes slot i; slot j is gone.
        body[i] = merged(ctx, &a, &b, new);
        t.tag[i] = tie_tag(seed, new);
        t.live.retain(|&k| k != j);
        for &k in &t.live {
            if k != i {
                let (c, r) = eval(ctx, &body[i], &body[k]);
                (t.cost[i * m + k], t.round[i * m + k]) = (c, r);
                (t.cost[k * m + i], t.round[k * m + i]) = (c, r);
            }
        }
        st.candidates += (t.live.len() - 1) as u64;
        for idx in 0..t.live.len() {
            let k = t.live[idx];
            if k == i {
                continue;
            }
            let bk = t.best[k];
            if bk == i || bk == j {
                t.scan_row(k, round);
            } else {
                let r = t.round[k * m + i];
                if r <= round {
                    if t.better(k, i, bk) {
                        t.best[k] = i;
                    }
                } else if r < t.next[k] {
                    t.next[k] = r;
                }
            }
        }
        t.scan_row(i, round);
        put_merge(ctx, out, made, [&a, &b], &body[i], round, || {
            t.live.iter().filter(|&&k| t.best[k] != NO).count() as u32
        });
        made += 1;
    }
    st.rounds = round + 1;
    out.stats.add(&st);
    // Keep the live slots' bodies, in slot order (`live` is increasing), and their pairs.
    leave(body, &t.live, export, |i, j| {
        (t.cost[i * m + j], t.round[i * m + j])
    })
}
