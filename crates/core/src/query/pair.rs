//! Scene–scene queries over the bounding-volume test tree (BVTT): the pairs (node of `a`,
//! node of `b`) reached from the root pair by splitting one side at a time.

use super::prim::{prim_prim, prims_touch};
use super::{Counts, Entry, Hierarchy, pair_bound, pair_depth};
use std::collections::BinaryHeap;

/// The child pairs of the BVTT node `(x, y)`: split the side that is not a leaf, or when
/// both are interior the one with the larger BV (ties: `a`). `None` when both are leaves.
fn split(a: &Hierarchy, x: u32, b: &Hierarchy, y: u32) -> Option<[(u32, u32); 2]> {
    match (a.tree.children_of(x), b.tree.children_of(y)) {
        (None, None) => None,
        (Some([c, d]), None) => Some([(c, y), (d, y)]),
        (None, Some([c, d])) => Some([(x, c), (x, d)]),
        (Some([c, d]), Some([e, f])) => Some(if a.size(x) >= b.size(y) {
            [(c, y), (d, y)]
        } else {
            [(x, e), (x, f)]
        }),
    }
}

/// Distance between the primitive surfaces of `a` and `b` (0 when they touch).
///
/// Best-first branch and bound over the BVTT: node pairs are expanded smallest bound first
/// (ties: deeper pair first) and pruned when their bound reaches the best primitive distance
/// found; the search ends at the first touching primitive pair (0 cannot be beaten). Each pair
/// bound evaluated is one BV test (the root pair included), each leaf pair reached one
/// primitive test.
pub fn scene_distance(a: &Hierarchy, b: &Hierarchy, counts: &mut Counts) -> f64 {
    scene_distance_within(a, b, u64::MAX, counts)
}

/// [`scene_distance`] that stops once it has made `max_tests` tests and reached a primitive
/// pair: the smallest primitive distance found by then (never less than the true distance),
/// the stop counted in [`Counts::capped`].
pub fn scene_distance_within(
    a: &Hierarchy,
    b: &Hierarchy,
    max_tests: u64,
    counts: &mut Counts,
) -> f64 {
    let start = counts.tests();
    let slack = a.slack() + b.slack();
    let (ra, rb) = (a.tree.root(), b.tree.root());
    let mut heap = BinaryHeap::new();
    let mut best = f64::INFINITY;
    counts.bv_tests += 1;
    heap.push(Entry {
        bound: pair_bound(a, ra, b, rb) - slack,
        depth: 0,
        a: ra,
        b: rb,
    });
    while let Some(e) = heap.pop() {
        if e.bound >= best || best == 0.0 {
            break;
        }
        if counts.tests() - start >= max_tests && best.is_finite() {
            counts.capped += 1;
            break;
        }
        match split(a, e.a, b, e.b) {
            None => {
                counts.prim_tests += 1;
                best = best.min(prim_prim(a.scene, e.a as usize, b.scene, e.b as usize));
            }
            Some(pairs) => {
                for (x, y) in pairs {
                    counts.bv_tests += 1;
                    let bound = pair_bound(a, x, b, y) - slack;
                    if bound < best {
                        heap.push(Entry {
                            bound,
                            depth: e.depth + 1,
                            a: x,
                            b: y,
                        });
                    }
                }
            }
        }
    }
    best
}

/// Whether some primitive of `a` touches some primitive of `b` (their distance is 0).
///
/// Depth-first over the BVTT, skipping pairs whose BVs are apart (bound above 0 after slack),
/// and returning at the first touching primitive pair. Of a pair's two child pairs, the one
/// whose BVs overlap deeper is searched first, so the tests do not depend on which child a
/// node stores first (only exact ties keep the stored order). Counted as in
/// [`scene_distance`].
pub fn overlap(a: &Hierarchy, b: &Hierarchy, counts: &mut Counts) -> bool {
    overlap_within(a, b, u64::MAX, counts)
}

/// [`overlap`] that gives up once it has made `max_tests` tests without finding a touching
/// pair: `false` (unproven), the stop counted in [`Counts::capped`].
pub fn overlap_within(a: &Hierarchy, b: &Hierarchy, max_tests: u64, counts: &mut Counts) -> bool {
    descend(a, b, max_tests, counts, true, |x, y| {
        prim_prim(a.scene, x as usize, b.scene, y as usize) == 0.0
    })
}

/// Depth-first over the BVTT pairs of `a` and `b` whose BVs overlap (bound at most 0 after
/// slack), from the root pair: `leaf` is called on each primitive pair reached (one primitive
/// test), and the descent ends when it returns `true` (then `true` is returned), when every
/// overlapping pair is visited, or once `max_tests` tests are made (the stop counted in
/// [`Counts::capped`]). With `deeper_first`, of a pair's two child pairs the one whose BVs
/// overlap deeper is searched first (ties keep the stored order); otherwise the stored order.
fn descend(
    a: &Hierarchy,
    b: &Hierarchy,
    max_tests: u64,
    counts: &mut Counts,
    deeper_first: bool,
    mut leaf: impl FnMut(u32, u32) -> bool,
) -> bool {
    let start = counts.tests();
    let slack = a.slack() + b.slack();
    let (ra, rb) = (a.tree.root(), b.tree.root());
    counts.bv_tests += 1;
    if pair_bound(a, ra, b, rb) - slack > 0.0 {
        return false;
    }
    let mut stack = vec![(ra, rb)];
    while let Some((x, y)) = stack.pop() {
        if counts.tests() - start >= max_tests {
            counts.capped += 1;
            return false;
        }
        match split(a, x, b, y) {
            None => {
                counts.prim_tests += 1;
                if leaf(x, y) {
                    return true;
                }
            }
            Some(pairs) => {
                let mut open = [None; 2];
                for (slot, (c, d)) in open.iter_mut().zip(pairs) {
                    counts.bv_tests += 1;
                    let bound = pair_bound(a, c, b, d);
                    if bound - slack <= 0.0 {
                        let depth = if deeper_first {
                            pair_depth(a, c, b, d, bound)
                        } else {
                            0.0
                        };
                        *slot = Some((depth, (c, d)));
                    }
                }
                // The deeper-overlapping pair is searched first (pushed last).
                if let [Some((p, _)), Some((q, _))] = open
                    && q > p
                {
                    open.swap(0, 1);
                }
                stack.extend(open.iter().rev().flatten().map(|&(_, pair)| pair));
            }
        }
    }
    false
}

/// How many primitive pairs of `a` and `b` touch (their distance is 0): every contact, as
/// collision response needs them.
///
/// Depth-first over the BVTT, skipping pairs whose BVs are apart (bound above 0 after slack),
/// until every overlapping pair is split down to its primitives. Every pair of overlapping
/// BVs is visited whatever the order, so the tests depend only on the two trees, not on which
/// child a node stores first. Counted as in [`scene_distance`].
pub fn contacts(a: &Hierarchy, b: &Hierarchy, counts: &mut Counts) -> u64 {
    contacts_within(a, b, u64::MAX, counts)
}

/// [`contacts`] that gives up once it has made `max_tests` tests: the contacts found by then
/// (a lower bound), the stop counted in [`Counts::capped`].
pub fn contacts_within(a: &Hierarchy, b: &Hierarchy, max_tests: u64, counts: &mut Counts) -> u64 {
    let mut found = 0u64;
    descend(a, b, max_tests, counts, false, |x, y| {
        found += u64::from(prims_touch(a.scene, x as usize, b.scene, y as usize));
        false
    });
    found
}
