//! The agglomerative step of §2.2 by brute force with a table of every pair, for subproblems of
//! more than `all_pairs::MAX_BODIES` and at most
//! [`MAX_BODIES`] bodies.
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

use super::pairs::{eval, leave, merged, pairs_of, put_merge};
use super::round_limits::NO_ROUND;
use super::subproblem::{Body, Counters, Leftover, MergeSlots, RunInputs};
use crate::grouping::cluster::tie_tag;
use std::cell::RefCell;

/// The most bodies a subproblem solved here may have (the brute-force limit).
pub(super) const MAX_BODIES: usize = 64;

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
        let (mut b, mut next, mut above) = (NO, NO_ROUND, 0u64);
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

/// Groups the bodies of `body` down to `keep` with the thread's table (see
/// `combine`).
pub(super) fn combine_by_partners(
    ctx: &RunInputs,
    body: &mut [Body],
    parts: [Leftover; 2],
    keep: usize,
    out: &mut MergeSlots<'_>,
    export: bool,
) -> Leftover {
    TABLE.with(|t| with_table(ctx, body, parts, keep, out, export, &mut t.borrow_mut()))
}

/// [`combine_by_partners`] with table `t`.
fn with_table(
    ctx: &RunInputs,
    body: &mut [Body],
    parts: [Leftover; 2],
    keep: usize,
    out: &mut MergeSlots<'_>,
    export: bool,
    t: &mut Table,
) -> Leftover {
    let m = body.len();
    debug_assert!(m <= MAX_BODIES && keep >= 1 && parts[0].n + parts[1].n == m);
    let mut st = Counters::default();
    let seed = ctx.params.seed;
    t.m = m;
    if t.cost.len() < m * m {
        t.cost.resize(m * m, 0);
        t.round.resize(m * m, NO_ROUND);
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
            let next = t.live.iter().map(|&i| t.next[i]).min().unwrap_or(NO_ROUND);
            assert!(next != NO_ROUND, "bodies of NaN size never become eligible");
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
