//! The order the split cuts (the Morton codes of the primitives' centres, [`morton_order`]) and
//! where it cuts a range: at its highest differing Morton bit ([`morton_cut`]), or, in a range
//! of at most [`Chunking::sah_below`](super::Chunking::sah_below) primitives, where the
//! surface area heuristic puts the cut ([`Zone`]).
//!
//! A Morton cut is a fixed plane of the scene's grid, whatever lies there: it runs through
//! clusters (a patch of a soup, the parts of one copy) as readily as between them, and each side
//! is then grouped down to a few bodies before the two can meet. A small range is cut instead
//! at the boundary of least `area(left)·|left| + area(right)·|right|` among those leaving at
//! least a quarter of the range on each side, on each of the three axes its primitives'
//! centres span (ties to the lower axis, then the lower boundary): between [`BINS`] equal bins
//! of the centres above [`SWEEP`] primitives, between sorted neighbours up to it; a range of 3
//! or 4 (the fast path's smallest cuts) tries every partition ([`Zone::few`]). All three
//! axes, not the longest alone: thin parts part best across their thin direction, which the
//! longest axis of a range's centres never is (cut along it alone, a CAD chair's tree needed
//! far more node tests than the exact tree). The range is partitioned stably, so
//! each side stays in Morton order; a range without such a boundary (centres that span no
//! length, or NaN) gets the Morton cut.

use super::subproblem::Body;
use crate::geom::morton::spread_bits;
use crate::geom::{Aabb, V3, surface_area};
use crate::grouping::PAR_MIN_LEN;
use crate::grouping::mpairs::order_bits;
use rayon::prelude::*;

/// Bins along the axis.
const BINS: usize = 16;

/// Where `items` (at least 2), sorted by their Morton `code`, split: at their highest
/// differing bit, or the middle when every code is equal.
pub(super) fn morton_cut<T>(items: &[T], code: impl Fn(&T) -> u64) -> usize {
    let (a, b) = (code(&items[0]), code(&items[items.len() - 1]));
    if a == b {
        return items.len() / 2;
    }
    let bit = 63 - (a ^ b).leading_zeros();
    items.partition_point(|x| code(x) >> bit & 1 == 0)
}

/// The primitives' ids sorted by the Morton code of their box centres (ties by id), quantised
/// on one scale for all axes: the cube on the longest side of the centres' box. Scaling each axis
/// to its own extent (as many builders do) stretches flat or long scenes: 50,000 stacked slabs,
/// 0.001 apart in z with 0.05 of jitter in x and y, were ordered by their jitter, and their
/// partitioned tree's SAH was far above the exact tree's (below it with the cube).
pub(super) fn morton_order(boxes: &[Aabb]) -> Vec<(u64, u32)> {
    let cb = boxes
        .par_iter()
        .with_min_len(PAR_MIN_LEN)
        .fold(|| Aabb::EMPTY, |b, x| b.grow(&x.center()))
        .reduce(|| Aabb::EMPTY, |a, b| a.merge(&b));
    let ext = cb.extents().max();
    let s = if ext > 0.0 && ext.is_finite() {
        2_097_151.0 / ext
    } else {
        0.0
    };
    let scale = [s; 3];
    let codes: Vec<(u64, u32)> = boxes
        .par_iter()
        .with_min_len(PAR_MIN_LEN)
        .enumerate()
        .map(|(i, b)| {
            let c = b.center();
            let mut key = 0u64;
            for k in 0..3 {
                let t = ((c[k] - cb.min[k]) * scale[k]).clamp(0.0, 2_097_151.0) as u64;
                key |= spread_bits(t) << k;
            }
            (key, i as u32)
        })
        .collect();
    super::sort::sorted(codes, 63)
}

/// Defines `network::<N>`, which applies the first `N` of the listed comparators to 16 keys,
/// unrolled on a copy the compiler keeps in registers (a loop over a table of index pairs
/// goes through memory, and each step waits on the previous one's stores).
macro_rules! comparators {
    ($($i:literal, $j:literal;)*) => {
        /// The first `N` comparators of the network applied to `keys`.
        #[inline(always)]
        fn network<const N: usize>(keys: &mut [u64; SWEEP]) {
            let mut k = *keys;
            let mut step = 0usize;
            $(
                if step < N {
                    let (a, b) = (k[$i], k[$j]);
                    k[$i] = a.min(b);
                    k[$j] = a.max(b);
                }
                step += 1;
            )*
            debug_assert!(N <= step);
            *keys = k;
        }
    };
}

// Batcher's odd–even merge sort of 16 keys: its first 5 comparators sort keys 0..4, its first
// 19 keys 0..8, all 63 keys 0..16.
comparators! {
    0, 1;
    2, 3;
    0, 2;
    1, 3;
    1, 2;
    4, 5;
    6, 7;
    4, 6;
    5, 7;
    5, 6;
    0, 4;
    2, 6;
    2, 4;
    1, 5;
    3, 7;
    3, 5;
    1, 2;
    3, 4;
    5, 6;
    8, 9;
    10, 11;
    8, 10;
    9, 11;
    9, 10;
    12, 13;
    14, 15;
    12, 14;
    13, 15;
    13, 14;
    8, 12;
    10, 14;
    10, 12;
    9, 13;
    11, 15;
    11, 13;
    9, 10;
    11, 12;
    13, 14;
    0, 8;
    4, 12;
    4, 8;
    2, 10;
    6, 14;
    6, 10;
    2, 4;
    6, 8;
    10, 12;
    1, 9;
    5, 13;
    5, 9;
    3, 11;
    7, 15;
    7, 11;
    3, 5;
    7, 9;
    11, 13;
    1, 2;
    3, 4;
    5, 6;
    7, 8;
    9, 10;
    11, 12;
    13, 14;
}

/// Sorts the first `len` (at most 16) of `keys`, the rest being `u64::MAX`, without branches:
/// the sweep's keys are random, so an insertion sort mispredicts most of its steps.
#[inline(always)]
fn sort_keys(keys: &mut [u64; SWEEP], len: usize) {
    match len {
        0..=4 => network::<5>(keys),
        5..=8 => network::<19>(keys),
        _ => network::<63>(keys),
    }
}

/// Ranges of at most this many primitives are cut by an exact sweep over their sorted centres
/// instead of bins (the bins' fixed cost would dominate).
const SWEEP: usize = 16;

/// Ranges of at most this many primitives (and at least 3: two are a chunk or merge) are cut
/// by trying every partition ([`Zone::few`]).
const FEW: usize = super::Chunking::FEW_MAX as usize;

/// A range of at most [`Chunking::sah_below`](super::Chunking::sah_below) primitives, planned
/// as a permutation of its leaves (moving 4-byte positions, not 64-byte bodies, at each cut)
/// that [`Zone::apply`] carries out at the end.
pub(super) struct Zone<'z> {
    /// The range's codes and leaves, in their order on entry.
    codes: &'z mut [(u64, u32)],
    leaves: &'z mut [Body],
    /// Position on entry of each primitive, in the planned order.
    perm: Vec<u32>,
    /// Doubled centre (min + max) of each primitive, by position on entry.
    cen: Vec<[f64; 3]>,
    /// Bins of each primitive of the range being cut on the three axes (binned cuts).
    bins: Vec<[u8; 3]>,
    /// The partitions' buffer.
    tmp: Vec<u32>,
    /// Per axis, the positions on entry of each range of at most [`SWEEP`] primitives sorted
    /// by centre as a sweep orders them, at the range's place in the planned order: a sweep
    /// sorts a range once and hands each side its part of the orders (a stable partition of
    /// a sorted sequence is sorted, ties included, as each side keeps its order).
    ord: [Vec<u32>; 3],
    /// Whether `ord` holds the orders of the range planned to start at each place.
    sorted: Vec<bool>,
    /// Side (0 left, 1 right) of each primitive of the range a sweep cuts, by position on
    /// entry.
    side: Vec<u8>,
    /// Ranges of 3 up to this many primitives try every partition ([`Zone::few`]).
    few: usize,
}

/// Surface area of the box `lo..hi`.
#[inline]
fn area(lo: &[f64; 3], hi: &[f64; 3]) -> f64 {
    surface_area(&V3::new(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]))
}

/// The lesser of `a` and `b`, `a` when `b` is NaN: one `minsd` (`f64::min` also checks `a`).
#[inline(always)]
fn lesser(a: f64, b: f64) -> f64 {
    if b < a { b } else { a }
}

/// The greater of `a` and `b`, `a` when `b` is NaN.
#[inline(always)]
fn greater(a: f64, b: f64) -> f64 {
    if b > a { b } else { a }
}

/// The bin of a centre at `x` bin widths from the low end: a NaN or negative `x` goes to bin
/// 0, one at or past the last bin's start to the last (what a saturating `x as usize` clamped
/// to the last bin gives), clamped first so that the conversion needs no range checks.
#[inline(always)]
fn bin(x: f64) -> usize {
    const LAST: f64 = (BINS - 1) as f64;
    let x = if x > 0.0 { x } else { 0.0 };
    let x = if x < LAST { x } else { LAST };
    x as u8 as usize
}

/// A box as corner arrays, grown by plain min/max (a NaN coordinate is skipped: the corners
/// start infinite and never become NaN).
#[derive(Clone, Copy)]
struct Bounds {
    lo: [f64; 3],
    hi: [f64; 3],
}

impl Bounds {
    const EMPTY: Bounds = Bounds {
        lo: [f64::INFINITY; 3],
        hi: [f64::NEG_INFINITY; 3],
    };

    #[inline(always)]
    fn add(&mut self, b: &Aabb) {
        for k in 0..3 {
            self.lo[k] = lesser(self.lo[k], b.min[k]);
            self.hi[k] = greater(self.hi[k], b.max[k]);
        }
    }

    #[inline(always)]
    fn join(&self, o: &Bounds) -> Bounds {
        let mut b = *self;
        for k in 0..3 {
            b.lo[k] = lesser(b.lo[k], o.lo[k]);
            b.hi[k] = greater(b.hi[k], o.hi[k]);
        }
        b
    }

    #[inline(always)]
    fn grow(&mut self, c: &[f64; 3]) {
        for ((lo, hi), &x) in self.lo.iter_mut().zip(&mut self.hi).zip(c) {
            *lo = lesser(*lo, x);
            *hi = greater(*hi, x);
        }
    }

    #[inline]
    fn area(&self) -> f64 {
        area(&self.lo, &self.hi)
    }
}

/// The box of the doubled centres of the primitives at positions `ps`.
fn centres(cen: &[[f64; 3]], ps: impl Iterator<Item = u32>) -> Bounds {
    let mut b = Bounds::EMPTY;
    for p in ps {
        b.grow(&cen[p as usize]);
    }
    b
}

/// Moves the positions of `part` that are not `right` (given their index and position; `nl`
/// of them) before the others, each side in its order, without branches; `tmp` is scratch.
#[inline(always)]
fn stable_split(
    part: &mut [u32],
    nl: usize,
    tmp: &mut Vec<u32>,
    right: impl Fn(usize, u32) -> bool,
) {
    tmp.resize(part.len(), 0);
    let (mut li, mut ri) = (0, nl);
    for (i, &p) in part.iter().enumerate() {
        let right = usize::from(right(i, p));
        let d = if right == 0 { li } else { ri };
        tmp[d] = p;
        li += 1 - right;
        ri += right;
    }
    part.copy_from_slice(&tmp[..part.len()]);
}

impl<'z> Zone<'z> {
    /// A zone over `codes` and `leaves` (the same order, Morton-sorted), whose ranges of 3 up to
    /// `few` primitives (at most [`FEW`]) try every partition.
    pub(super) fn new(codes: &'z mut [(u64, u32)], leaves: &'z mut [Body], few: u32) -> Zone<'z> {
        let m = leaves.len();
        let cen: Vec<[f64; 3]> = leaves
            .iter()
            .map(|l| {
                let b = &l.aabb;
                [b.min.x + b.max.x, b.min.y + b.max.y, b.min.z + b.max.z]
            })
            .collect();
        Zone {
            codes,
            leaves,
            perm: (0..m as u32).collect(),
            cen,
            bins: Vec::with_capacity(m),
            tmp: Vec::with_capacity(m),
            ord: [vec![0; m], vec![0; m], vec![0; m]],
            sorted: vec![false; m],
            side: vec![0; m],
            few: (few as usize).min(FEW),
        }
    }

    /// Cuts `start..start + len` of the planned order (at least 2 long) and returns the left
    /// side's length: at the SAH boundary (module doc), each side in its order, or, when there
    /// is none, at the highest differing Morton bit (the middle when every code is equal).
    pub(super) fn cut(&mut self, start: usize, len: usize) -> usize {
        if let Some(nl) = self.sah(start, len) {
            return nl;
        }
        // Positions keep their entry order within a side, so the codes are sorted.
        let codes = &*self.codes;
        let nl = morton_cut(&self.perm[start..start + len], |&p| codes[p as usize].0);
        self.sorted[start] = false;
        self.sorted[start + nl] = false;
        nl
    }

    /// The SAH cut of `start..start + len`, if any (moving the left side to the front).
    fn sah(&mut self, start: usize, len: usize) -> Option<usize> {
        if (3..=self.few).contains(&len) {
            return Some(self.few(start, len));
        }
        let part = &self.perm[start..start + len];
        // The box of the doubled centres (min + max: the same cut, a product less).
        let cb = centres(&self.cen, part.iter().copied());
        let e = [
            cb.hi[0] - cb.lo[0],
            cb.hi[1] - cb.lo[1],
            cb.hi[2] - cb.lo[2],
        ];
        // Every axis with a span is tried; the cheapest cut wins (ties to the lower axis). Bins
        // from `cut` on are the right side.
        let spans = e.map(|w| w > 0.0 && w.is_finite());
        if len <= SWEEP {
            return self.sweep(start, len, spans);
        }
        // One pass bins the centres on all three axes at once.
        let (nl, cut, axis) = self.binned(start, len, &cb.lo, &e, spans)?;
        self.sorted[start] = false;
        self.sorted[start + nl] = false;
        let bins = &self.bins;
        stable_split(
            &mut self.perm[start..start + len],
            nl,
            &mut self.tmp,
            |i, _| bins[i][axis] >= cut,
        );
        Some(nl)
    }

    /// The exact cut of a range of at most [`SWEEP`]: on each axis that `spans`, the primitives
    /// sorted by centre on it, ties (and centres within 16 units in the last place) in range
    /// order (a NaN centre first, −0 as 0), and the boundary of least SAH leaving a quarter on
    /// each side; of those the cheapest (ties to the lower axis). The three sweeps advance
    /// together (each step of one waits on its last, so three side by side take about the
    /// time of one). The orders come from the sweep of the range's parent when it had one
    /// (`ord`), else from sorting; the range is partitioned stably, each side with its part of
    /// the orders. Returns the left side's length.
    fn sweep(&mut self, start: usize, len: usize, spans: [bool; 3]) -> Option<usize> {
        let end = start + len;
        if !self.sorted[start] {
            self.sort_range(start, len);
        }
        let leaves = &*self.leaves;
        let ord = &self.ord;
        let least = (len / 4).max(1);
        let aabb = |a: usize, i: usize| &leaves[ord[a][start + i] as usize].aabb;
        // Areas of the right sides that leave a quarter on each side.
        let mut right = [[0.0f64; 3]; SWEEP];
        let mut acc = [Bounds::EMPTY; 3];
        for i in (least..len).rev() {
            for a in 0..3 {
                acc[a].add(aabb(a, i));
                right[i][a] = acc[a].area();
            }
        }
        let mut left = [Bounds::EMPTY; 3];
        for i in 0..least - 1 {
            for (a, l) in left.iter_mut().enumerate() {
                l.add(aabb(a, i));
            }
        }
        let mut here = [(f64::INFINITY, 0usize); 3];
        for (i, r) in right.iter().enumerate().take(len - least + 1).skip(least) {
            for a in 0..3 {
                left[a].add(aabb(a, i - 1));
                let cost = left[a].area() * i as f64 + r[a] * (len - i) as f64;
                if here[a].1 == 0 || cost < here[a].0 {
                    here[a] = (cost, i);
                }
            }
        }
        let mut best: Option<(f64, usize, usize)> = None;
        for a in (0..3).filter(|&a| spans[a]) {
            let (cost, nl) = here[a];
            if best.is_none_or(|(b, _, _)| cost < b) {
                best = Some((cost, nl, a));
            }
        }
        let Some((_, nl, axis)) = best else {
            self.sorted[start] = false;
            return None;
        };
        for (k, &p) in self.ord[axis][start..end].iter().enumerate() {
            self.side[p as usize] = u8::from(k >= nl);
        }
        let right = |_, p: u32| self.side[p as usize] == 1;
        stable_split(&mut self.perm[start..end], nl, &mut self.tmp, right);
        for o in &mut self.ord {
            stable_split(&mut o[start..end], nl, &mut self.tmp, right);
        }
        self.sorted[start] = true;
        self.sorted[start + nl] = true;
        Some(nl)
    }

    /// The cut of a range of 3 or [`FEW`] primitives (the fast path's split, [`Chunking::few`](super::Chunking::few)) whose subtree has the least sum of
    /// interior areas: every partition is tried, each side then cut the same way, so the
    /// subtree is the best binary tree over these leaves, not only the best of the axis sweeps
    /// (which it never loses to), in about a third of a sweep's time. The partitions are tried
    /// two against two first, then one against the rest by the one's place; the first of
    /// least cost wins (a NaN cost never does, so boxes with a NaN coordinate get the first).
    /// The side holding the range's first primitive goes left, each side in its order.
    /// Returns the left side's length.
    fn few(&mut self, start: usize, len: usize) -> usize {
        debug_assert!((3..=FEW).contains(&len));
        let part = &self.perm[start..start + len];
        let mut b = [Bounds::EMPTY; FEW];
        for (b, &p) in b.iter_mut().zip(part) {
            b.add(&self.leaves[p as usize].aabb);
        }
        // Area of the union of the leaves `i` and `j`.
        let pair = |i: usize, j: usize| b[i].join(&b[j]).area();
        // (cost, the right side as a mask of places)
        let best = if len == 3 {
            [
                (pair(1, 2), 0b110),
                (pair(0, 2), 0b010),
                (pair(0, 1), 0b100),
            ]
            .into_iter()
            .reduce(|a, o| if o.0 < a.0 { o } else { a })
        } else {
            let p = [
                [0.0, pair(0, 1), pair(0, 2), pair(0, 3)],
                [0.0, 0.0, pair(1, 2), pair(1, 3)],
                [0.0, 0.0, 0.0, pair(2, 3)],
            ];
            let pa = |i: usize, j: usize| p[i.min(j)][i.max(j)];
            // Leaf `k` alone: the other three's box, and the best pair among them.
            let alone = |k: usize| {
                let [i, j, l] = match k {
                    0 => [1, 2, 3],
                    1 => [0, 2, 3],
                    2 => [0, 1, 3],
                    _ => [0, 1, 2],
                };
                let three = b[i].join(&b[j]).join(&b[l]).area();
                three + lesser(lesser(pa(i, j), pa(i, l)), pa(j, l))
            };
            [
                (pa(0, 1) + pa(2, 3), 0b1100),
                (pa(0, 2) + pa(1, 3), 0b1010),
                (pa(0, 3) + pa(1, 2), 0b0110),
                (alone(0), 0b1110),
                (alone(1), 0b0010),
                (alone(2), 0b0100),
                (alone(3), 0b1000),
            ]
            .into_iter()
            .reduce(|a, o| if o.0 < a.0 { o } else { a })
        };
        let (_, right) = best.expect("a range of 3 or 4 has partitions");
        let nl = len - (right as u32).count_ones() as usize;
        stable_split(
            &mut self.perm[start..start + len],
            nl,
            &mut self.tmp,
            |i, _| right >> i & 1 == 1,
        );
        self.sorted[start] = false;
        self.sorted[start + nl] = false;
        nl
    }

    /// Sorts the positions of `start..start + len` (at most [`SWEEP`]) by centre on each axis
    /// into `ord`: by the centre's order bits with the range index in the low 4 (one integer
    /// compare per step), a NaN centre as −∞ and −0 as 0.
    fn sort_range(&mut self, start: usize, len: usize) {
        let part = &self.perm[start..start + len];
        for axis in 0..3 {
            let mut keys = [u64::MAX; SWEEP];
            for (i, &p) in part.iter().enumerate() {
                let c = self.cen[p as usize][axis];
                let c = if c.is_nan() {
                    f64::NEG_INFINITY
                } else {
                    c + 0.0
                };
                keys[i] = order_bits(c) & !0xF | i as u64;
            }
            sort_keys(&mut keys, len);
            for (o, k) in self.ord[axis][start..start + len].iter_mut().zip(&keys) {
                *o = part[(k & 0xF) as usize];
            }
        }
    }

    /// The binned cut of a longer range: centres in [`BINS`] equal bins of `lo..lo + e` on each
    /// axis that `spans`, all three binned in one pass over the range; on each axis the bin
    /// boundary of least SAH leaving a quarter on each side, and of those the cheapest (ties to
    /// the lower axis). Sets `bins` to each primitive's bins and returns the left side's
    /// length, the right side's first bin and the axis.
    fn binned(
        &mut self,
        start: usize,
        len: usize,
        lo: &[f64; 3],
        e: &[f64; 3],
        spans: [bool; 3],
    ) -> Option<(usize, u8, usize)> {
        let (leaves, cen) = (&*self.leaves, &self.cen);
        let part = &self.perm[start..start + len];
        let least = (len / 4).max(1);
        // An axis without a span bins everything in bin 0 (its cuts are never taken).
        let scale = [0, 1, 2].map(|k| if spans[k] { BINS as f64 / e[k] } else { 0.0 });
        let mut counts = [[0usize; BINS]; 3];
        let mut boxes = [[Bounds::EMPTY; BINS]; 3];
        self.bins.clear();
        self.bins.extend(part.iter().map(|&p| {
            let c = &cen[p as usize];
            let b = &leaves[p as usize].aabb;
            let at = |a: usize| bin((c[a] - lo[a]) * scale[a]);
            let k = [at(0), at(1), at(2)];
            for a in 0..3 {
                counts[a][k[a]] += 1;
                boxes[a][k[a]].add(b);
            }
            k.map(|x| x as u8)
        }));
        let mut best: Option<(f64, usize, u8, usize)> = None;
        for axis in (0..3).filter(|&a| spans[a]) {
            let (boxes, counts) = (&boxes[axis], &counts[axis]);
            let mut right = [(Bounds::EMPTY, 0usize); BINS];
            let mut acc = (Bounds::EMPTY, 0usize);
            for k in (1..BINS).rev() {
                acc = (acc.0.join(&boxes[k]), acc.1 + counts[k]);
                right[k] = acc;
            }
            let mut left = (Bounds::EMPTY, 0usize);
            let mut here: Option<(f64, usize, usize)> = None;
            for cut in 1..BINS {
                left = (left.0.join(&boxes[cut - 1]), left.1 + counts[cut - 1]);
                let (rb, rn) = right[cut];
                if left.1 < least || rn < least {
                    continue;
                }
                let cost = left.0.area() * left.1 as f64 + rb.area() * rn as f64;
                if here.is_none_or(|(c, _, _)| cost < c) {
                    here = Some((cost, cut, left.1));
                }
            }
            if let Some((cost, cut, nl)) = here
                && best.is_none_or(|(b, _, _, _)| cost < b)
            {
                best = Some((cost, nl, cut as u8, axis));
            }
        }
        best.map(|(_, nl, cut, axis)| (nl, cut, axis))
    }

    /// Reorders the codes and leaves into the planned order.
    pub(super) fn apply(self) {
        let codes: Vec<(u64, u32)> = self.perm.iter().map(|&p| self.codes[p as usize]).collect();
        let leaves: Vec<Body> = self.perm.iter().map(|&p| self.leaves[p as usize]).collect();
        self.codes.copy_from_slice(&codes);
        self.leaves.copy_from_slice(&leaves);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::P3;
    use rand::{Rng, SeedableRng};

    /// Primitive `id` with box `aabb`.
    fn body(id: u32, aabb: Aabb) -> Body {
        Body {
            id,
            first_round: 0,
            aabb,
            diameter: aabb.diameter(),
        }
    }

    /// Primitive `id`, a cube of half-edge `r` centred at `c`.
    fn leaf(id: u32, c: [f64; 3], r: f64) -> Body {
        body(
            id,
            Aabb {
                min: P3::new(c[0] - r, c[1] - r, c[2] - r),
                max: P3::new(c[0] + r, c[1] + r, c[2] + r),
            },
        )
    }

    /// Cuts a fresh zone over `leaves` (codes = 3 × position, so sorted) once, applies it,
    /// and returns the left side's length with the reordered codes and leaves.
    fn cut_once(mut leaves: Vec<Body>) -> (usize, Vec<(u64, u32)>, Vec<Body>) {
        let mut codes: Vec<(u64, u32)> =
            leaves.iter().map(|l| (u64::from(l.id) * 3, l.id)).collect();
        let mut zone = Zone::new(&mut codes, &mut leaves, FEW as u32);
        let nl = zone.cut(0, zone.perm.len());
        zone.apply();
        (nl, codes, leaves)
    }

    #[test]
    fn the_cut_falls_in_the_gap_between_two_clusters_and_keeps_each_side_in_order() {
        // Two clusters along x, interleaved in the input order: binned (64) and swept (12).
        for m in [64u32, 12] {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
            let leaves: Vec<Body> = (0..m)
                .map(|i| {
                    let x = if i % 3 < 2 { 0.0 } else { 10.0 } + rng.random_range(0.0..1.0);
                    leaf(i, [x, rng.random_range(0.0..2.0), 0.0], 0.1)
                })
                .collect();
            let want = (0..m).filter(|i| i % 3 < 2).count();
            let (nl, codes, leaves) = cut_once(leaves);
            assert_eq!(nl, want, "{m} leaves");
            assert!(leaves[..nl].iter().all(|l| l.aabb.center().x < 5.0));
            assert!(leaves[nl..].iter().all(|l| l.aabb.center().x > 5.0));
            // Codes travel with their leaves, and each side keeps its order.
            assert!(codes.iter().zip(&leaves).all(|(c, l)| c.1 == l.id));
            assert!(codes[..nl].is_sorted() && codes[nl..].is_sorted());
        }
    }

    #[test]
    fn the_cut_is_on_the_axis_of_least_cost_not_the_longest_span_of_the_centres() {
        // Two rows of slivers 10 long in x, 2 apart in y; their centres spread 3 in x, 2.1 in
        // y. Any cut in x leaves both rows on both sides; the cut in y parts the rows.
        for m in [64u32, 12] {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
            let leaves: Vec<Body> = (0..m)
                .map(|i| {
                    let (x, y) = (3.5 + rng.random_range(0.0..3.0), f64::from(i % 2) * 2.0);
                    let y = y + rng.random_range(0.0..0.1);
                    let aabb = Aabb {
                        min: P3::new(x - 5.0, y, 0.0),
                        max: P3::new(x + 5.0, y + 0.01, 0.01),
                    };
                    body(i, aabb)
                })
                .collect();
            let (nl, _, leaves) = cut_once(leaves);
            assert_eq!(nl, m as usize / 2, "{m} leaves");
            assert!(
                leaves[..nl].iter().all(|l| l.aabb.min.y < 1.0),
                "{m} leaves"
            );
            assert!(
                leaves[nl..].iter().all(|l| l.aabb.min.y > 1.0),
                "{m} leaves"
            );
        }
    }

    /// Σ interior area of the tree the zone cuts over positions `start..start + len`.
    fn interior(zone: &mut Zone<'_>, start: usize, len: usize) -> f64 {
        let own = |zone: &Zone<'_>| {
            let mut b = Bounds::EMPTY;
            for &p in &zone.perm[start..start + len] {
                b.add(&zone.leaves[p as usize].aabb);
            }
            b.area()
        };
        match len {
            1 => 0.0,
            2 => own(zone),
            _ => {
                let nl = zone.cut(start, len);
                assert!(0 < nl && nl < len);
                own(zone) + interior(zone, start, nl) + interior(zone, start + nl, len - nl)
            }
        }
    }

    /// The least Σ interior area of any binary tree over `boxes`.
    fn best_interior(boxes: &[Aabb]) -> f64 {
        let all = boxes.iter().fold(Aabb::EMPTY, |a, b| a.merge(b));
        if boxes.len() == 1 {
            return 0.0;
        }
        let m = boxes.len();
        // Every partition once: the first box on the left.
        (0..1u32 << (m - 1))
            .map(|bits| {
                let (mut l, mut r) = (vec![boxes[0]], Vec::new());
                for (i, b) in boxes.iter().enumerate().skip(1) {
                    if bits >> (i - 1) & 1 == 1 {
                        &mut r
                    } else {
                        &mut l
                    }
                    .push(*b);
                }
                if r.is_empty() {
                    return f64::INFINITY;
                }
                best_interior(&l) + best_interior(&r)
            })
            .fold(f64::INFINITY, f64::min)
            + surface_area(&all.extents())
    }

    #[test]
    fn ranges_of_three_and_four_get_the_best_tree_over_their_leaves() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
        // Without `few` the sweep cuts them, and misses the best tree on some.
        let mut sweep_missed = 0;
        for m in [3u32, 4] {
            for _ in 0..300 {
                // Slivers and cubes in random places, so that no one axis orders the best tree.
                let leaves: Vec<Body> = (0..m)
                    .map(|i| {
                        let c = [0; 3].map(|_| rng.random_range(0.0..4.0));
                        let h = [0; 3].map(|_| rng.random_range(0.01..2.0));
                        let aabb = Aabb {
                            min: P3::new(c[0] - h[0], c[1] - h[1], c[2] - h[2]),
                            max: P3::new(c[0] + h[0], c[1] + h[1], c[2] + h[2]),
                        };
                        body(i, aabb)
                    })
                    .collect();
                let boxes: Vec<Aabb> = leaves.iter().map(|l| l.aabb).collect();
                // Σ interior area of the zone's tree over these leaves with `few`.
                let tree = |few: u32| {
                    let mut l = leaves.clone();
                    let mut codes: Vec<(u64, u32)> = (0..m).map(|i| (u64::from(i), i)).collect();
                    interior(&mut Zone::new(&mut codes, &mut l, few), 0, m as usize)
                };
                let (got, swept) = (tree(FEW as u32), tree(0));
                let want = best_interior(&boxes);
                assert!(swept >= want * (1.0 - 1e-12));
                sweep_missed += usize::from(swept > want * (1.0 + 1e-12));
                assert!(
                    (got - want).abs() <= 1e-12 * want,
                    "{m} leaves: {got} {want}"
                );
            }
        }
        assert!(sweep_missed > 0);
        // A NaN coordinate: a cut, and every leaf kept once.
        let mut nan: Vec<Body> = (0..4)
            .map(|i| leaf(i, [f64::from(i), 0.0, 0.0], 0.5))
            .collect();
        nan[2].aabb.max.y = f64::NAN;
        let (nl, _, leaves) = cut_once(nan);
        assert!(0 < nl && nl < 4);
        let mut ids: Vec<u32> = leaves.iter().map(|l| l.id).collect();
        ids.sort_unstable();
        assert_eq!(ids, (0..4).collect::<Vec<_>>());
    }

    #[test]
    fn the_sorting_network_sorts_every_length_up_to_sixteen() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for len in 0..=SWEEP {
            for _ in 0..200 {
                let mut keys = [u64::MAX; SWEEP];
                // Few distinct values, so that ties occur.
                for k in &mut keys[..len] {
                    *k = rng.random_range(0..8u64) << 4 | rng.random_range(0..16u64);
                }
                let mut want = keys[..len].to_vec();
                want.sort_unstable();
                sort_keys(&mut keys, len);
                assert_eq!(&keys[..len], &want[..], "{len} keys");
            }
        }
    }

    #[test]
    fn without_a_span_or_a_balanced_boundary_the_morton_cut_applies() {
        // Every centre at one point: the highest differing bit of the codes (0, 3, …, 21).
        let same: Vec<Body> = (0..8).map(|i| leaf(i, [1.0, 1.0, 1.0], 0.5)).collect();
        let (nl, codes, _) = cut_once(same);
        assert_eq!(nl, codes.partition_point(|c| c.0 < 16));
        assert_eq!(
            codes,
            (0..8u32).map(|i| (u64::from(i) * 3, i)).collect::<Vec<_>>()
        );
        // 60 at one end and 4 at the other: no bin boundary leaves 16 on each side.
        let lop: Vec<Body> = (0..64)
            .map(|i| leaf(i, [if i % 16 == 15 { 9.0 } else { 0.0 }, 0.0, 0.0], 0.5))
            .collect();
        let (nl, codes, _) = cut_once(lop);
        assert_eq!(nl, codes.partition_point(|c| c.0 < 128));
        assert!(codes.is_sorted());
        // A NaN box: a cut, and every leaf kept once.
        let mut nan: Vec<Body> = (0..8)
            .map(|i| leaf(i, [f64::from(i), 0.0, 0.0], 0.5))
            .collect();
        nan[3].aabb.min.x = f64::NAN;
        let (_, _, leaves) = cut_once(nan);
        let mut ids: Vec<u32> = leaves.iter().map(|l| l.id).collect();
        ids.sort_unstable();
        assert_eq!(ids, (0..8).collect::<Vec<_>>());
    }
}
