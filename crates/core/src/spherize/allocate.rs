//! Covers per link and the robot-wide allocation of a sphere budget.
//!
//! A link's cover is a cut of its Subset Tree (every leaf has exactly one ancestor-or-self in
//! it), each node drawn as its sphere; its error is the largest excess of its nodes. Unlike
//! [`wrap::cover`](crate::wrap::cover), a leaf is a sphere too, with its own excess, so a leaf
//! over the tolerance makes its subtree infeasible rather than free.
//!
//! **Tolerance.** [`min_cut`]: the fewest nodes with every excess ≤ T, top down: a node is
//! taken when it qualifies, else its children are searched. A cut of a subtree whose root
//! qualifies cannot beat `{x}`; otherwise it is a cut of each child's subtree, chosen
//! independently, so the sum of the children's smallest cuts is the smallest.
//!
//! **Budget.** [`by_budget`]: the least robot-wide largest excess with at most K spheres in
//! all. The total of the links' smallest covers within T is non-increasing in T, so a binary
//! search over T finds the smallest feasible one; it runs over the bit patterns of the `f64`s
//! ≥ 0 (ordered as the numbers are), so it ends on the exact smallest feasible `f64`, which is a
//! node's excess. That is an exact allocation across links: each link gets exactly the spheres
//! its smallest cover within that T needs. Excess is measured only for the nodes the search
//! visits, and a probe stops once its count passes K.

use super::link_tree::LinkTree;
use super::spend::Spent;
use crate::stop::{Interrupted, Stop};

/// Whether an excess is within the tolerance (NaN never is).
fn qualifies(e: f64, t: f64) -> bool {
    e.partial_cmp(&t).is_some_and(|o| o.is_le())
}

/// The smallest cut of `link` with every node's excess ≤ `t`, sorted by id, measuring the
/// nodes it visits; `None` once it would exceed `cap` nodes, or (when `strict`) when a leaf
/// over `t` has no qualifying ancestor. Not strict, such leaves are taken as they are.
pub fn min_cut(
    link: &mut LinkTree,
    t: f64,
    cap: usize,
    strict: bool,
    stop: &Stop,
) -> Result<Option<Vec<u32>>, Interrupted> {
    let mut cut = Vec::new();
    let mut frontier = vec![link.tree.root()];
    while !frontier.is_empty() {
        link.measure(&frontier, stop)?;
        let mut next = Vec::new();
        for &x in &frontier {
            match link.tree.children_of(x) {
                _ if qualifies(link.excess[x as usize], t) => cut.push(x),
                None if strict => return Ok(None),
                None => cut.push(x),
                Some([a, b]) => next.extend([a, b]),
            }
        }
        // Every frontier node adds at least one node to the cut.
        if cut.len() + next.len() > cap {
            return Ok(None);
        }
        frontier = next;
    }
    cut.sort_unstable();
    Ok(Some(cut))
}

/// One probe of the budget's binary search.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Probe {
    /// The largest excess tried.
    pub threshold: f64,
    /// Spheres the links' smallest covers within it need in all (`None`: over the budget, or
    /// some link has none).
    pub spheres: Option<usize>,
}

/// How many spheres each link gets and the largest excess they keep to.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Allocation {
    /// The largest excess every link's cover keeps to (the tolerance, or the budget's optimum).
    pub threshold: f64,
    /// Spheres per link, in the links' order.
    pub per_link: Vec<usize>,
    /// The budget's binary search, probe by probe (empty for a tolerance).
    pub probes: Vec<Probe>,
    /// The budget's spending on the mean ([`spend`](super::spend)), once made.
    pub spent: Option<Spent>,
}

/// The links' smallest covers within `t`, if they total at most `k`.
fn covers_within(
    links: &mut [LinkTree],
    t: f64,
    k: usize,
    stop: &Stop,
) -> Result<Option<Vec<Vec<u32>>>, Interrupted> {
    let n = links.len();
    let mut out = Vec::with_capacity(n);
    let mut used = 0usize;
    for (i, l) in links.iter_mut().enumerate() {
        // Each later link needs one sphere at least.
        let cap = k.saturating_sub(used + (n - i - 1));
        match min_cut(l, t, cap, true, stop)? {
            Some(c) => {
                used += c.len();
                out.push(c);
            }
            None => return Ok(None),
        }
    }
    Ok(Some(out))
}

/// The fewest spheres per link with every excess ≤ `t` (a link that cannot keep to it gets its
/// leaves where they exceed it); the covers and their allocation.
pub fn by_tolerance(
    links: &mut [LinkTree],
    t: f64,
    stop: &Stop,
) -> Result<(Vec<Vec<u32>>, Allocation), Interrupted> {
    let mut covers = Vec::with_capacity(links.len());
    for l in links.iter_mut() {
        covers.push(min_cut(l, t, usize::MAX, false, stop)?.expect("no cap, not strict"));
    }
    let per_link = covers.iter().map(Vec::len).collect();
    Ok((
        covers,
        Allocation {
            threshold: t,
            per_link,
            probes: Vec::new(),
            spent: None,
        },
    ))
}

/// Each link's cover (its chosen nodes) and the allocation that gave them.
pub type Budgeted = (Vec<Vec<u32>>, Allocation);

/// The least largest excess with at most `k` spheres over all links, and each link's cover
/// (see the module's proof). Err: fewer spheres than links (each needs one). `stop` is checked
/// as nodes are measured.
pub fn by_budget(
    links: &mut [LinkTree],
    k: usize,
    stop: &Stop,
) -> Result<Result<Budgeted, String>, Interrupted> {
    if k < links.len() {
        return Ok(Err(format!(
            "a budget of {k} spheres is below the {} links with geometry (each needs one)",
            links.len()
        )));
    }
    // One sphere per link keeps to the largest root excess.
    let mut top = 0.0f64;
    for l in links.iter_mut() {
        let root = l.tree.root();
        l.measure(&[root], stop)?;
        top = top.max(l.excess[root as usize]);
    }
    let (mut lo, mut hi) = (0u64, top.to_bits());
    let mut best = covers_within(links, top, k, stop)?.expect("one sphere per link fits");
    let mut probes = vec![Probe {
        threshold: top,
        spheres: Some(best.iter().map(Vec::len).sum()),
    }];
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        let t = f64::from_bits(mid);
        let found = covers_within(links, t, k, stop)?;
        probes.push(Probe {
            threshold: t,
            spheres: found.as_ref().map(|c| c.iter().map(Vec::len).sum()),
        });
        match found {
            Some(c) => {
                best = c;
                hi = mid;
            }
            None => lo = mid + 1,
        }
    }
    let threshold = f64::from_bits(hi);
    let per_link = best.iter().map(Vec::len).collect();
    Ok(Ok((
        best,
        Allocation {
            threshold,
            per_link,
            probes,
            spent: None,
        },
    )))
}
