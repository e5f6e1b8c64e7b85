//! Spending a budget on the mean excess, once its largest excess is settled.
//!
//! `allocate::by_budget` finds the least robot-wide largest excess M* within
//! K spheres, and each link's fewest spheres for it. [`by_mean`] then chooses, among the covers
//! of at most K spheres in all whose every node's excess is ≤ a limit T ≥ M* (M* itself, or
//! M* with a slack), those of least **sampled mean**: over every cover sphere's sample points
//! outside the link, the sum of their distances to the surface over their number (Σ S / Σ N,
//! S and N per node from [`LinkTree::measure`]). The cuts are those of each link's measured
//! nodes (the search's and every node down to a depth; a node is split only when both of its
//! children are measured).
//!
//! **Exact.** A ratio of sums is minimised by Dinkelbach's method: for λ, the least
//! Σ (S − λ N) over the covers is found exactly — per link, a tree DP gives the least sum for
//! every count of spheres (a node alone, or the best split of the count between its
//! children), and a knapsack over links gives the least total for every total count ≤ K; the
//! best cover's ratio becomes the next λ. The least sum is ≤ 0 (the current cover gives 0), and
//! it is 0 exactly when no cover has a smaller ratio, so the method stops on the least ratio;
//! λ strictly falls each round and there are finitely many covers.

use super::link_tree::LinkTree;
use crate::stop::{Interrupted, Stop};

/// Most rounds of Dinkelbach's method (it converges in a few).
pub const MAX_ROUNDS: usize = 64;

/// A chosen cover's sampled mean excess and the rounds it took.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Spent {
    /// The largest node excess the covers keep to.
    pub limit: f64,
    /// The sampled mean excess of the covers (Σ S / Σ N; 0 when no sample is outside).
    pub mean: f64,
    /// Rounds of Dinkelbach's method.
    pub rounds: usize,
}

/// Σ S and Σ N of `covers`.
fn sums(links: &[LinkTree], covers: &[Vec<u32>]) -> (f64, f64) {
    let (mut s, mut n) = (0.0, 0.0);
    for (l, c) in links.iter().zip(covers) {
        for &x in c {
            let (a, b) = l.outside[x as usize];
            s += a;
            n += b as f64;
        }
    }
    (s, n)
}

fn ratio((s, n): (f64, f64)) -> f64 {
    if n > 0.0 { s / n } else { 0.0 }
}

/// One link's least Σ (S − λ N) for every count 1..=cap, and how each is reached.
struct Curve {
    /// Per node: least sum per count (index = count; infinite where none).
    best: Vec<Vec<f64>>,
    /// Per node and count: 0 = the node itself, i = i spheres to its first child.
    split: Vec<Vec<u16>>,
}

fn curve(l: &LinkTree, lambda: f64, t: f64, cap: usize) -> Curve {
    let m = l.tree.len();
    let measured = |x: u32| !l.excess[x as usize].is_nan();
    let mut best: Vec<Vec<f64>> = vec![Vec::new(); m];
    let mut split: Vec<Vec<u16>> = vec![Vec::new(); m];
    // Children have smaller ids than their parent: ascending ids visit children first.
    for x in 0..m as u32 {
        if !measured(x) {
            continue;
        }
        let xi = x as usize;
        let (mut f, mut g) = match l.tree.children_of(x) {
            Some([a, b]) if measured(a) && measured(b) => {
                let (fa, fb) = (&best[a as usize], &best[b as usize]);
                let len = (fa.len() + fb.len() - 1).min(cap + 1);
                let (mut f, mut g) = (vec![f64::INFINITY; len], vec![0u16; len]);
                for (i, va) in fa.iter().enumerate().skip(1) {
                    if !va.is_finite() {
                        continue;
                    }
                    for (j, vb) in fb.iter().enumerate().skip(1) {
                        if i + j >= len {
                            break;
                        }
                        let v = va + vb;
                        if v < f[i + j] {
                            f[i + j] = v;
                            g[i + j] = i as u16;
                        }
                    }
                }
                (f, g)
            }
            _ => (
                vec![f64::INFINITY; 2.min(cap + 1)],
                vec![0u16; 2.min(cap + 1)],
            ),
        };
        if l.excess[xi] <= t && f.len() > 1 {
            let (s, n) = l.outside[xi];
            f[1] = s - lambda * n as f64;
            g[1] = 0;
        }
        best[xi] = f;
        split[xi] = g;
    }
    Curve { best, split }
}

fn trace(l: &LinkTree, c: &Curve, x: u32, k: usize, out: &mut Vec<u32>) {
    match (c.split[x as usize][k], l.tree.children_of(x)) {
        (0, _) | (_, None) => out.push(x),
        (i, Some([a, b])) => {
            trace(l, c, a, i as usize, out);
            trace(l, c, b, k - i as usize, out);
        }
    }
}

/// The covers of least Σ (S − λ N) with every node's excess ≤ `t` and at most `k` spheres.
fn least(links: &[LinkTree], lambda: f64, t: f64, k: usize) -> Option<Vec<Vec<u32>>> {
    let cap = (k + 1).saturating_sub(links.len()).min(u16::MAX as usize);
    let curves: Vec<Curve> = links.iter().map(|l| curve(l, lambda, t, cap)).collect();
    // Knapsack over links: least total per total count, and each link's count.
    let mut total = vec![f64::INFINITY; k + 1];
    total[0] = 0.0;
    let mut counts: Vec<Vec<usize>> = Vec::with_capacity(links.len());
    for (l, c) in links.iter().zip(&curves) {
        let f = &c.best[l.tree.root() as usize];
        let mut next = vec![f64::INFINITY; k + 1];
        let mut pick = vec![0usize; k + 1];
        for (j, vj) in total.iter().enumerate() {
            if !vj.is_finite() {
                continue;
            }
            for (i, vi) in f.iter().enumerate().skip(1) {
                if j + i > k {
                    break;
                }
                let v = vj + vi;
                if v < next[j + i] {
                    next[j + i] = v;
                    pick[j + i] = i;
                }
            }
        }
        total = next;
        counts.push(pick);
    }
    let (mut j, _) = total
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .min_by(|a, b| a.1.total_cmp(b.1))?;
    let mut covers = vec![Vec::new(); links.len()];
    for (li, l) in links.iter().enumerate().rev() {
        let i = counts[li][j];
        trace(l, &curves[li], l.tree.root(), i, &mut covers[li]);
        covers[li].sort_unstable();
        j -= i;
    }
    Some(covers)
}

/// The covers of least sampled mean excess (see the module) with every node's excess ≤ `t`
/// and at most `k` spheres in all, starting from `start` (such covers, of measured nodes).
pub fn by_mean(
    links: &[LinkTree],
    k: usize,
    t: f64,
    start: Vec<Vec<u32>>,
    stop: &Stop,
) -> Result<(Vec<Vec<u32>>, Spent), Interrupted> {
    let mut covers = start;
    let mut lambda = ratio(sums(links, &covers));
    let mut rounds = 0;
    while rounds < MAX_ROUNDS {
        stop.check()?;
        rounds += 1;
        let Some(next) = least(links, lambda, t, k) else {
            break;
        };
        let r = ratio(sums(links, &next));
        if r.is_nan() || lambda.is_nan() || r >= lambda {
            break;
        }
        covers = next;
        lambda = r;
    }
    Ok((
        covers,
        Spent {
            limit: t,
            mean: lambda,
            rounds,
        },
    ))
}
