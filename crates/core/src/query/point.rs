//! Point–scene distance: best-first branch and bound over one hierarchy.

use super::{Counts, Entry, Hierarchy};
use crate::geom::P3;
use crate::wrap::distance::point_prim;
use std::collections::BinaryHeap;

/// Distance from `p` to the nearest primitive surface of `h`.
///
/// Nodes are expanded nearest bound first from a heap; a node whose bound is at least the best
/// distance found is pruned, and the search ends when the smallest pending bound reaches it.
/// Every node whose bound is evaluated is one BV test (the root included); every leaf reached
/// is one primitive test.
pub fn point_distance(h: &Hierarchy, p: &P3, counts: &mut Counts) -> f64 {
    point_distance_within(h, p, u64::MAX, counts)
}

/// [`point_distance`] that stops once it has made `max_tests` tests and reached a primitive:
/// the distance to the nearest primitive found by then (never less than the true distance),
/// the stop counted in [`Counts::capped`].
pub fn point_distance_within(h: &Hierarchy, p: &P3, max_tests: u64, counts: &mut Counts) -> f64 {
    let start = counts.tests();
    let slack = h.slack();
    let tree = h.tree;
    let root = tree.root();
    let mut heap = BinaryHeap::new();
    let mut best = f64::INFINITY;
    counts.bv_tests += 1;
    heap.push(Entry {
        bound: h.point_bound(root, p) - slack,
        depth: 0,
        a: root,
        b: 0,
    });
    while let Some(e) = heap.pop() {
        if e.bound >= best {
            break;
        }
        if counts.tests() - start >= max_tests && best.is_finite() {
            counts.capped += 1;
            break;
        }
        match tree.children_of(e.a) {
            None => {
                counts.prim_tests += 1;
                best = best.min(point_prim(h.scene, e.a as usize, p));
            }
            Some(children) => {
                for c in children {
                    counts.bv_tests += 1;
                    let bound = h.point_bound(c, p) - slack;
                    if bound < best {
                        heap.push(Entry {
                            bound,
                            depth: e.depth + 1,
                            a: c,
                            b: 0,
                        });
                    }
                }
            }
        }
    }
    best
}
