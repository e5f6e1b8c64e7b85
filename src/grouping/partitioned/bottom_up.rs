//! The split's lowest levels built bottom-up ([`Chunking::nearest`](super::Chunking::nearest)):
//! a small range's binary tree by PLOC's scheme (Meister and Bittner 2018, "Parallel Locally-
//! Ordered Clustering for Bounding Volume Hierarchy Construction") over its primitives in
//! their order, handed to the split as the cuts it makes. The split's SAH cuts part a range
//! by planes, so that each side holds whatever lies there; merged from nearest neighbours, the
//! lowest levels group the primitives that lie closest together, and queries that descend to
//! many leaves at once (a distance query against another mesh, contact queries) visit fewer
//! nodes. Boxes are compared in `f32`, relative to the range's first box: the tree only
//! orders the primitives, the Subset Tree's boxes stay exact.

use crate::geom::{Aabb, greater, lesser};

/// How many places each way a cluster looks for its partner.
const RADIUS: usize = 8;

/// A coordinate beyond any box's: boxes from −`FAR` to `FAR` end the rows (their unions'
/// areas overflow to infinity).
const FAR: f32 = 1e30;

/// The least of `v` and one plus its first place holding it; (∞, 0) when none is finite.
#[inline(always)]
fn least(v: [f32; RADIUS]) -> (f32, usize) {
    let (mut best, mut at) = (f32::INFINITY, 0);
    for (d, &x) in v.iter().enumerate() {
        let lt = x < best;
        best = if lt { x } else { best };
        at = if lt { d + 1 } else { at };
    }
    (best, at)
}

/// Scratch and result of [`BottomUp::plan`], kept across the ranges of a zone.
#[derive(Default)]
pub(super) struct BottomUp {
    /// The clusters' boxes, one array per corner coordinate, relative to the range's first
    /// box (so that `f32` keeps the small boxes' sizes).
    lo: [Vec<f32>; 3],
    hi: [Vec<f32>; 3],
    /// Each cluster's node: leaves are 0..m, inner nodes m + their index in `kids`.
    node: Vec<u32>,
    /// Each cluster's union areas with the clusters on its right, nearest first, after
    /// [`RADIUS`] rows of infinite ones.
    rows: Vec<[f32; RADIUS]>,
    /// Each cluster's partner.
    nn: Vec<u32>,
    /// The inner nodes' children, in the order made.
    kids: Vec<(u32, u32)>,
    /// Leaf count and lowest leaf of every node.
    count: Vec<u32>,
    first: Vec<u32>,
    stack: Vec<u32>,
    /// The range's leaves (indices into it) in depth-first order.
    pub(super) order: Vec<u32>,
    /// In pre-order, each inner node of more than `skip` leaves: (offset of its first leaf in
    /// `order`, its leaves, its left side's leaves).
    pub(super) cuts: Vec<(u32, u32, u32)>,
}

impl BottomUp {
    /// Plans the tree over `boxes` (at least 2) into [`BottomUp::order`] and
    /// [`BottomUp::cuts`] (nodes of more than `skip` leaves): while more than one cluster is
    /// left, each finds the cluster of least union area within [`RADIUS`] places (ties to the
    /// nearer, then the one on the left), and mutual pairs merge into the lower place,
    /// keeping the order. The child holding the lower leaf goes left. Where no union has a
    /// finite area (NaN or infinite boxes) a cluster takes the next one; a round without a
    /// mutual pair (ties in a cycle) merges the first two clusters.
    pub(super) fn plan<'b>(&mut self, boxes: impl Iterator<Item = &'b Aabb> + Clone, skip: usize) {
        let o = boxes.clone().next().expect("at least two boxes").min;
        for k in 0..3 {
            self.lo[k].clear();
            self.hi[k].clear();
            self.lo[k].extend(boxes.clone().map(|b| (b.min[k] - o[k]) as f32));
            self.hi[k].extend(boxes.clone().map(|b| (b.max[k] - o[k]) as f32));
        }
        let m = self.lo[0].len();
        debug_assert!(m >= 2);
        self.node.clear();
        self.node.extend(0..m as u32);
        self.kids.clear();
        while self.node.len() > 1 {
            self.round(m);
        }
        self.walk(m, skip);
    }

    /// One round of PLOC over the current clusters. Each cluster's union areas with the
    /// [`RADIUS`] clusters on its right are computed together (one row, 4 lanes at a time;
    /// the arrays end in [`RADIUS`] boxes whose unions have infinite area), and its best on
    /// the left is read from the rows of the clusters before it.
    fn round(&mut self, m: usize) {
        let len = self.node.len();
        for k in 0..3 {
            self.lo[k].truncate(len);
            self.lo[k].resize(len + RADIUS, -FAR);
            self.hi[k].truncate(len);
            self.hi[k].resize(len + RADIUS, FAR);
        }
        // Rows of infinite areas before the first cluster's.
        self.rows.clear();
        self.rows.resize(len + RADIUS, [f32::INFINITY; RADIUS]);
        self.nn.clear();
        let [xl, yl, zl] = &self.lo;
        let [xh, yh, zh] = &self.hi;
        for i in 0..len {
            let row = |v: &[f32]| -> [f32; RADIUS] {
                v[i + 1..i + 1 + RADIUS].try_into().expect("padded")
            };
            let (xl1, yl1, zl1, xh1, yh1, zh1) =
                (row(xl), row(yl), row(zl), row(xh), row(yh), row(zh));
            let mut a = [0.0f32; RADIUS];
            for d in 0..RADIUS {
                let x = greater(xh[i], xh1[d]) - lesser(xl[i], xl1[d]);
                let y = greater(yh[i], yh1[d]) - lesser(yl[i], yl1[d]);
                let z = greater(zh[i], zh1[d]) - lesser(zl[i], zl1[d]);
                a[d] = x * y + y * z + z * x;
            }
            self.rows[i + RADIUS] = a;
            let (br, dr) = least(a);
            // Cluster i − d's row holds its area with cluster i at d − 1.
            let (bl, dl) = least(std::array::from_fn(|k| self.rows[i + RADIUS - 1 - k][k]));
            // The nearer side wins a tie of areas, then the left; with no finite area on
            // either side, the next cluster (or the one before the last).
            let left = dl > 0 && (dr == 0 || bl < br || (bl == br && dl <= dr));
            let j = if left {
                i - dl
            } else if dr > 0 {
                i + dr
            } else if i + 1 < len {
                i + 1
            } else {
                i - 1
            };
            self.nn.push(j as u32);
        }
        let mut w = 0;
        let mut merged = false;
        for i in 0..len {
            let j = self.nn[i] as usize;
            let mutual = self.nn[j] as usize == i;
            if mutual && j < i {
                continue;
            }
            if mutual {
                self.merge(m, w, i, j);
                merged = true;
            } else {
                self.keep(w, i);
            }
            w += 1;
        }
        if !merged {
            // No mutual pair: the first two clusters (already kept in place) merge.
            self.merge(m, 0, 0, 1);
            for i in 2..w {
                self.keep(i - 1, i);
            }
            w -= 1;
        }
        for k in 0..3 {
            self.lo[k].truncate(w);
            self.hi[k].truncate(w);
        }
        self.node.truncate(w);
    }

    /// Cluster `i` moved to place `w` (at most `i`).
    #[inline(always)]
    fn keep(&mut self, w: usize, i: usize) {
        for k in 0..3 {
            self.lo[k][w] = self.lo[k][i];
            self.hi[k][w] = self.hi[k][i];
        }
        self.node[w] = self.node[i];
    }

    /// Clusters `i` and `j` (`i` < `j`, `w` ≤ `i`) merged into place `w`.
    #[inline(always)]
    fn merge(&mut self, m: usize, w: usize, i: usize, j: usize) {
        for k in 0..3 {
            self.lo[k][w] = lesser(self.lo[k][i], self.lo[k][j]);
            self.hi[k][w] = greater(self.hi[k][i], self.hi[k][j]);
        }
        self.kids.push((self.node[i], self.node[j]));
        self.node[w] = (m + self.kids.len() - 1) as u32;
    }

    /// The leaves in depth-first order and the cuts of the nodes of more than `skip` leaves.
    fn walk(&mut self, m: usize, skip: usize) {
        let total = m + self.kids.len();
        self.count.clear();
        self.count.resize(total, 1);
        self.first.clear();
        self.first.extend(0..total as u32);
        for (k, &(l, r)) in self.kids.iter().enumerate() {
            let (l, r) = (l as usize, r as usize);
            self.count[m + k] = self.count[l] + self.count[r];
            self.first[m + k] = self.first[l].min(self.first[r]);
        }
        self.order.clear();
        self.cuts.clear();
        self.stack.clear();
        self.stack.push(self.node[0]);
        while let Some(node) = self.stack.pop() {
            let node = node as usize;
            if node < m {
                self.order.push(node as u32);
                continue;
            }
            let (mut l, mut r) = self.kids[node - m];
            if self.first[r as usize] < self.first[l as usize] {
                std::mem::swap(&mut l, &mut r);
            }
            if self.count[node] as usize > skip {
                let at = self.order.len() as u32;
                self.cuts
                    .push((at, self.count[node], self.count[l as usize]));
            }
            self.stack.push(r);
            self.stack.push(l);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::P3;
    use rand::{Rng, SeedableRng};

    /// A cube of half-edge `r` centred at `c`.
    fn cube(c: [f64; 3], r: f64) -> Aabb {
        Aabb {
            min: P3::new(c[0] - r, c[1] - r, c[2] - r),
            max: P3::new(c[0] + r, c[1] + r, c[2] + r),
        }
    }

    /// The plan of `boxes` with every node of more than `skip` leaves, checked to be one
    /// binary tree: the order a permutation, the cuts those of a pre-order walk.
    fn planned(boxes: &[Aabb], skip: usize) -> BottomUp {
        let mut b = BottomUp::default();
        b.plan(boxes.iter(), skip);
        let mut seen = b.order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..boxes.len() as u32).collect::<Vec<_>>());
        // Walks the ranges as the split asks for them, taking the cuts in turn.
        fn walk(cuts: &[(u32, u32, u32)], next: &mut usize, at: u32, n: u32, skip: usize) {
            if n as usize <= skip {
                return;
            }
            let (a, len, nl) = cuts[*next];
            *next += 1;
            assert_eq!((a, len), (at, n));
            assert!(0 < nl && nl < n);
            walk(cuts, next, at, nl, skip);
            walk(cuts, next, at + nl, n - nl, skip);
        }
        let mut next = 0;
        walk(&b.cuts, &mut next, 0, boxes.len() as u32, skip);
        assert_eq!(next, b.cuts.len());
        b
    }

    /// The leaves under each node of the plan (more than `skip` leaves), as sorted lists.
    fn nodes(b: &BottomUp) -> Vec<Vec<u32>> {
        b.cuts
            .iter()
            .map(|&(at, n, _)| {
                let mut v = b.order[at as usize..(at + n) as usize].to_vec();
                v.sort_unstable();
                v
            })
            .collect()
    }

    #[test]
    fn nearest_pairs_merge_first_and_clusters_become_subtrees() {
        // Pairs 0.1 apart, 10 apart from each other: each pair is a node.
        let pairs: Vec<Aabb> = (0..16)
            .map(|i| {
                cube(
                    [10.0 * f64::from(i / 2) + 0.1 * f64::from(i % 2), 0.0, 0.0],
                    0.01,
                )
            })
            .collect();
        let b = planned(&pairs, 1);
        let got = nodes(&b);
        for k in 0..8u32 {
            assert!(got.contains(&vec![2 * k, 2 * k + 1]), "pair {k}: {got:?}");
        }
        // Four clusters of five at the corners of a square, listed corner by corner but
        // with each corner's order shuffled: each cluster is one subtree.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let corners = [[0.0, 0.0], [100.0, 0.0], [0.0, 100.0], [100.0, 100.0]];
        let boxes: Vec<Aabb> = (0..20)
            .map(|i| {
                let c = corners[i / 5];
                let j = [0; 2].map(|_| rng.random_range(-1.0..1.0));
                cube([c[0] + j[0], c[1] + j[1], 0.0], 0.2)
            })
            .collect();
        let got = nodes(&planned(&boxes, 1));
        for k in 0..4u32 {
            let want: Vec<u32> = (5 * k..5 * k + 5).collect();
            assert!(got.contains(&want), "cluster {k}: {got:?}");
        }
    }

    #[test]
    fn plans_are_trees_for_random_and_degenerate_boxes() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        for m in [2usize, 3, 5, 9, 17, 40, 64, 200] {
            let boxes: Vec<Aabb> = (0..m)
                .map(|_| {
                    let c = [0; 3].map(|_| rng.random_range(0.0..10.0));
                    cube(c, rng.random_range(0.001..1.0))
                })
                .collect();
            for skip in [1, 4] {
                let a = planned(&boxes, skip);
                // The same boxes give the same plan.
                let b = planned(&boxes, skip);
                assert_eq!((a.order, a.cuts), (b.order, b.cuts));
            }
            // Every box the same, NaN or infinite corners: still one tree over every leaf.
            planned(&vec![cube([1.0; 3], 0.5); m], 1);
            let mut odd = boxes.clone();
            odd[0].min.x = f64::NAN;
            odd[m / 2].max.y = f64::INFINITY;
            odd[m - 1] = Aabb {
                min: P3::new(f64::NAN, f64::NAN, f64::NAN),
                max: P3::new(f64::NAN, f64::NAN, f64::NAN),
            };
            planned(&odd, 1);
        }
    }
}
