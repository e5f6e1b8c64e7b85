//! The brute-force step (`brute_force`) for subproblems of at most
//! [`MAX_BODIES`] bodies,
//! most of the partitioned schedule's subproblems (AAC's chunks and the levels just above).
//!
//! With so few bodies, keeping each body's cheapest partner costs more than it saves: every
//! step looks at all pairs of the bodies left. The pair merged next is the least by (its
//! round, clamped to the current round; Cost; smaller tie tag; larger tie tag), which is the
//! pair `partner_table` merges: the cheapest pair eligible in the current round, or, when none is,
//! the cheapest of those eligible first in a later round, which becomes the current one. The
//! counters (eligible pairs at each round start, candidates, pops, rounds) and the events'
//! queue length (bodies with an eligible partner after the merge) are those of `brute_force`.

use super::pairs::{eval, leave, merged, pairs_of, put_merge};
use super::round_limits::NO_ROUND;
use super::subproblem::{Body, Counters, Leftover, MergeSlots, RunInputs};
use crate::grouping::cluster::tie_tag;

/// The most bodies a subproblem may have to be solved here.
pub(super) const MAX_BODIES: usize = 8;

/// The pairs of the bodies in the slots `0..m`: Cost bits and first eligible round (`[i][j]`,
/// `i < j`), the slots' tie tags and which slots hold a body.
struct Pairs {
    cost: [[u64; MAX_BODIES]; MAX_BODIES],
    round: [[u32; MAX_BODIES]; MAX_BODIES],
    tag: [u64; MAX_BODIES],
    live: [bool; MAX_BODIES],
    m: usize,
}

impl Pairs {
    /// The number of pairs eligible in round `r`, and of bodies with an eligible partner.
    fn eligible(&self, r: u32) -> (u64, u32) {
        let (mut pairs, mut with) = (0u64, [false; MAX_BODIES]);
        for i in (0..self.m).filter(|&i| self.live[i]) {
            for j in (i + 1..self.m).filter(|&j| self.live[j]) {
                if self.round[i][j] <= r {
                    pairs += 1;
                    (with[i], with[j]) = (true, true);
                }
            }
        }
        (pairs, with.iter().filter(|&&w| w).count() as u32)
    }

    /// The pair merged next in round `r` and its round (clamped to `r`); with `COUNT`, also
    /// the number of pairs eligible in round `r` (else 0), counted in the same pass.
    fn next<const COUNT: bool>(&self, r: u32) -> (Option<(usize, usize, u32)>, u64) {
        let mut best: Option<(u32, u64, usize, usize)> = None;
        let mut eligible = 0u64;
        for i in (0..self.m).filter(|&i| self.live[i]) {
            for j in (i + 1..self.m).filter(|&j| self.live[j]) {
                let (pr, c) = (self.round[i][j].max(r), self.cost[i][j]);
                if COUNT {
                    eligible += u64::from(self.round[i][j] <= r);
                }
                let wins = match best {
                    None => true,
                    Some((br, bc, bi, bj)) => {
                        pr < br
                            || (pr == br
                                && (c < bc || (c == bc && self.key(i, j) < self.key(bi, bj))))
                    }
                };
                if wins {
                    best = Some((pr, c, i, j));
                }
            }
        }
        (best.map(|(pr, _, i, j)| (i, j, pr)), eligible)
    }

    /// The pair's tie tags, smaller first.
    #[inline]
    fn key(&self, i: usize, j: usize) -> (u64, u64) {
        let (a, b) = (self.tag[i], self.tag[j]);
        (a.min(b), a.max(b))
    }

    #[inline]
    fn set(&mut self, i: usize, j: usize, (c, r): (u64, u32)) {
        let (i, j) = (i.min(j), i.max(j));
        self.cost[i][j] = c;
        self.round[i][j] = r;
    }
}

/// [`run`] for two bodies `x` and `y` (in slot order) that become one, without the table of
/// pairs: the same merge (slot 0 of `out`), event and counters (added to `stats`); returns the
/// new body. Below the root's share of the fast path's split every node does this
/// (`Executor::merge_down`).
pub(super) fn pair(
    ctx: &RunInputs,
    x: &Body,
    y: &Body,
    out: &mut MergeSlots<'_>,
    stats: &mut Counters,
) -> Body {
    let (_, round) = eval(ctx, x, y);
    assert!(
        round != NO_ROUND,
        "bodies of NaN size never become eligible"
    );
    let body = merged(ctx, x, y, out.first_new);
    // No body is left with a partner.
    put_merge(ctx, out, 0, [x, y], &body, round, || 0);
    // The pair is eligible at the first round start, or at the one it waits for.
    stats.eligible_pairs += 1;
    stats.candidates += 1;
    stats.pops += 1;
    stats.rounds = stats.rounds.max(round + 1);
    body
}

/// `brute_force::combine` for at most [`MAX_BODIES`] bodies (more
/// than `keep`).
pub(super) fn combine_few(
    ctx: &RunInputs,
    body: &mut [Body],
    parts: [Leftover; 2],
    keep: usize,
    out: &mut MergeSlots<'_>,
    export: bool,
) -> Leftover {
    let m = body.len();
    debug_assert!(m <= MAX_BODIES && keep >= 1 && keep < m && parts[0].n + parts[1].n == m);
    let seed = ctx.params.seed;
    let mut st = Counters::default();
    let mut p = Pairs {
        cost: [[0; MAX_BODIES]; MAX_BODIES],
        round: [[NO_ROUND; MAX_BODIES]; MAX_BODIES],
        tag: [0; MAX_BODIES],
        live: [false; MAX_BODIES],
        m,
    };
    for (k, b) in body.iter().enumerate() {
        p.tag[k] = tie_tag(seed, b.id);
        p.live[k] = true;
    }
    pairs_of(ctx, body, &parts, &mut st, |i, j, pair| p.set(i, j, pair));
    let mut round = 0u32;
    for made in 0..m - keep {
        let (pair, eligible) = if made == 0 {
            // The first round start's eligible pairs, counted by the same pass.
            p.next::<true>(round)
        } else {
            p.next::<false>(round)
        };
        st.eligible_pairs += eligible;
        let (i, j, r) = pair.expect("more than one body is left");
        assert!(r != NO_ROUND, "bodies of NaN size never become eligible");
        if r > round {
            // Step 5 until this pair is eligible: a round start.
            round = r;
            st.eligible_pairs += p.eligible(round).0;
        }
        let (x, y) = (body[i], body[j]);
        let new = out.first_new + made as u32;
        st.pops += 1;
        // The new body takes slot i (the smaller); slot j is gone.
        body[i] = merged(ctx, &x, &y, new);
        p.tag[i] = tie_tag(seed, new);
        p.live[j] = false;
        for k in 0..m {
            if p.live[k] && k != i {
                p.set(i, k, eval(ctx, &body[i], &body[k]));
                st.candidates += 1;
            }
        }
        put_merge(ctx, out, made, [&x, &y], &body[i], round, || {
            p.eligible(round).1
        });
    }
    st.rounds = round + 1;
    out.stats.add(&st);
    // Keep the live slots' bodies, in slot order, and their pairs.
    let mut slots = [0usize; MAX_BODIES];
    let mut n = 0;
    for k in (0..m).filter(|&k| p.live[k]) {
        slots[n] = k;
        n += 1;
    }
    leave(body, &slots[..n], export, |i, j| {
        (p.cost[i][j], p.round[i][j])
    })
}
