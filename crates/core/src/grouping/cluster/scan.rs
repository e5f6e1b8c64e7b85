//! Partner searches over the voxel hash: step 3's round-start scan and step 4(b)'s search for a
//! new body (also run when a body's partner list is used up).
//!
//! Only cells within reach are visited: a partner's centre lies in the body's box grown by
//! GLimit plus the largest half-extent of the round's active bodies ([`query_box`]), and a cell
//! counts only if the union of its boxes is within GLimit ([`reachable`]). For the AABB p-set,
//! the round-start scan visits each pair of cells once (`pairs_once`), and a single search
//! visits cells cheapest Cost bound first ([`cost_bound`]) and stops when no cell can improve
//! its list, which is still exactly the first partners in key order (`scan_pruned`). A cell cut
//! into blocks is read block by block, cheapest block bound first, and in a run of records sorted
//! by smallest x a search reads them outward from the searcher and stops each way at the first
//! record no pair with could enter the list. Where the round's cells are crowded ([`CROWDED`]),
//! the round-start scan runs that search for each body instead and counts the eligible pairs
//! apart (`count_pairs`, a pair of blocks at once where it can). Other p-sets search every
//! candidate for the first partners (`scan_all`). A search after a merge by a body identical to
//! the last searcher (same box, diameter and p-set body, the voxel hash unchanged) reuses its
//! result ([`Memo`]).
//!
//! With `--cost area` the bound and the `sqrt`-free filter ([`Quick`]) do not hold, so those
//! searches visit every reachable cell (`docs/method.md`, "The Cost in surface area").

mod par;

use super::{Clusterer, PSetBodies, ScanLimit, fill_balance};
use crate::events::Observer;
use crate::geom::surface_area;
use crate::geom::{Aabb, P3, V3};
use crate::grouping::mpairs::{K_MAX, Top};
use crate::grouping::voxel_hash::{BLOCK, CellBounds, DEAD, Rec, VoxelHash};
use crate::grouping::{CostMeasure, Exponent, Weights};

/// The last search after a merge: its searcher, the bits of the searcher's box and diameter
/// and the voxel hash version, and the first `K_MAX + 1` partners in key order of all stored
/// bodies, the searcher included.
///
/// With one partner more than a list holds and the searcher counted as its own candidate, the
/// result, with the searcher dropped, serves every body of bit-identical box, diameter and
/// p-set body ([`PSetBodies::same`]): their candidates' keys are the same and differ only by
/// which body is left out. It is kept until the voxel hash changes, so N coincident bodies
/// re-searching between two merges cost one scan, not N.
pub(super) struct Memo {
    key: MemoKey,
    body: u32,
    top: Top<{ K_MAX + 1 }>,
}

/// A body's box and diameter bits and the voxel hash version (see [`Memo`]).
type MemoKey = ([u64; 6], u64, u64);

/// The memo key of a body with box `xa` and diameter `dx` while the voxel hash is at `version`.
#[inline]
fn memo_key(xa: &Aabb, dx: f64, version: u64) -> MemoKey {
    let b = |p: &P3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let (l, h) = (b(&xa.min), b(&xa.max));
    ([l[0], l[1], l[2], h[0], h[1], h[2]], dx.to_bits(), version)
}

/// Runs `$body` with the const `$A` set to the code of the Cost form `$exponent`
/// ([`Exponent::code`]): the one dispatch from a run's form to its specialised scan.
macro_rules! by_exponent {
    ($exponent:expr, $A:ident => $body:expr) => {
        match $exponent {
            Exponent::One => {
                const $A: u8 = Exponent::One.code();
                $body
            }
            Exponent::Zero => {
                const $A: u8 = Exponent::Zero.code();
                $body
            }
            Exponent::Other => {
                const $A: u8 = Exponent::Other.code();
                $body
            }
        }
    };
}

/// Cost of a pair of AABB bodies whose merged box has diagonal `d`; `A` = 1 or 0 selects the
/// exponent without `powf` (any other value uses `w.a`).
#[inline(always)]
fn pair_cost<const A: u8>(w: &Weights, d: f64, dx: f64, dy: f64) -> f64 {
    let scale = match A {
        1 => d,
        0 => 1.0,
        _ => d.powf(w.a),
    };
    if w.c == 0.0 && w.b > 0.0 && dx < f64::INFINITY && dy < f64::INFINITY {
        // Balance is then finite, so C·Balance = ±0 and B·Fill + C·Balance = B·Fill bit for
        // bit (B·Fill is +0, positive or NaN): skip Balance's division.
        let sum = dx + dy;
        let fill = if sum > 0.0 { d / sum } else { 1.0 };
        return scale * (w.b * fill);
    }
    let (fill, balance) = fill_balance(d, dx, dy);
    w.cost_scaled(scale, fill, balance)
}

/// [`pair_cost`] for any `w.a` (chosen per call): the Cost of the partitioned schedule's pairs,
/// bit for bit the exact schedule's.
#[inline(always)]
pub(in crate::grouping) fn pair_cost_any(w: &Weights, d: f64, dx: f64, dy: f64) -> f64 {
    by_exponent!(w.exponent(), A => pair_cost::<A>(w, d, dx, dy))
}

/// The Cost's size measures of a pair whose merged box has extents `e`: its diagonal and the
/// bodies' diameters `dx`, `dy`, or with `area` the surface areas of the merged box and of the
/// bodies' boxes `xa`, `ya`.
#[inline(always)]
fn measures(area: bool, e: &V3, xa: &Aabb, dx: f64, ya: &Aabb, dy: f64) -> (f64, f64, f64) {
    if area {
        let ex = |b: &Aabb| b.max - b.min;
        (
            surface_area(e),
            surface_area(&ex(xa)),
            surface_area(&ex(ya)),
        )
    } else {
        (e.norm(), dx, dy)
    }
}

/// The extents of `a ∪ b`: the values of `a.merge(b).extents()` up to the sign of zeros (which
/// the diameter squares away), with `<`/`>` selects that compile to `minsd`/`maxsd`.
#[inline(always)]
fn merged_extents(a: &Aabb, b: &Aabb) -> V3 {
    let lo = |k: usize| {
        if a.min[k] < b.min[k] {
            a.min[k]
        } else {
            b.min[k]
        }
    };
    let hi = |k: usize| {
        if a.max[k] > b.max[k] {
            a.max[k]
        } else {
            b.max[k]
        }
    };
    V3::new(hi(0) - lo(0), hi(1) - lo(1), hi(2) - lo(2))
}

/// Whether the L∞ gap of `a` and `b` exceeds `g`: the answer of `a.gap_linf(b) > g`, as the
/// running maximum below skips NaN terms just like `f64::max`, but compiles to plain `maxsd`.
#[inline(always)]
fn apart(a: &Aabb, b: &Aabb, g: f64) -> bool {
    let mut m = 0.0f64;
    for k in 0..3 {
        for t in [b.min[k] - a.max[k], a.min[k] - b.max[k]] {
            m = if t > m { t } else { m };
        }
    }
    m > g
}

/// Sorted records a cell needs before a search sweeps them outward from the searcher rather
/// than reading them all.
const SWEEP_MIN: usize = 16;

/// Average cell-mates per active body (Σ cell size² / bodies) above which the round-start
/// scan searches each body's partners one body at a time (sweeping the sorted cells) and
/// counts the eligible pairs apart, instead of costing every eligible pair once.
const CROWDED: usize = 64;

/// A Cost filter without `sqrt` or division for A = 1, C = 0, B in [1e-40, 1e40] and scene
/// coordinates below 1e100 in magnitude (else `None`). There the Cost of a pair with merged
/// squared diagonal `d2` and diameter sum `sum` > 0 is B·d2/sum within a few ulps, so
/// [`Quick::beyond`] may say it exceeds `bar` only when the exact Cost does (margin 1e-12
/// relative; operands kept in the normal range).
#[derive(Clone, Copy)]
struct Quick {
    b: f64,
}

impl Quick {
    fn new(w: &Weights, small: bool) -> Option<Quick> {
        (small && w.exponent() == Exponent::One && w.c == 0.0 && (1e-40..=1e40).contains(&w.b))
            .then_some(Quick { b: w.b })
    }

    /// Whether the exact Cost of the pair is certainly greater than `bar`.
    #[inline(always)]
    fn beyond(self, d2: f64, sum: f64, bar: f64) -> bool {
        let rhs = bar * sum * (1.0 + 1e-12);
        (sum > 0.0) & (d2 > 1e-250) & (rhs > 1e-200) & (d2 * self.b > rhs)
    }

    /// Whether every pair of a body of diameter `dx` > 0 with a body of diameter at most `dmax`
    /// whose merged squared diagonal is at least `s2` is certainly costlier than `bar`: then
    /// [`Quick::beyond`] holds for each of them (its squared diagonal is no smaller, its
    /// diameter sum no larger and at least `dx`).
    #[inline(always)]
    fn beyond_all(self, s2: f64, dx: f64, dmax: f64, bar: f64) -> bool {
        dx > 0.0
            && s2 > 1e-250
            && bar * dx * (1.0 + 1e-12) > 1e-200
            && s2 * self.b > bar * (dx + dmax) * (1.0 + 1e-12)
    }
}

/// The box that holds the centre of every eligible partner of a body with box `xa`, given the
/// largest half-extent per axis of the stored bodies.
#[inline]
fn query_box(half_ext: &[f64; 3], xa: &Aabb, glimit: f64) -> (P3, P3) {
    // A little more than GLimit + half-extent, so rounding never drops a partner.
    let m = (0..3).fold(0f64, |m, k| m.max(xa.min[k].abs()).max(xa.max[k].abs()));
    let reach = V3::from(half_ext.map(|h| (h + glimit) * (1.0 + 1e-12) + m * 1e-13));
    (xa.min - reach, xa.max + reach)
}

/// A lower bound on the Cost of pairing the body with box `xa` and diameter `dx` with any body
/// stored in a cell with bounds `cb`.
///
/// The merged diameter D is at least that of the box spanning `xa` and, per axis, the cell's
/// smallest box maximum and largest box minimum (every body's box reaches them), and at least
/// the cell's smallest diameter; Fill = d / (dx + dy) with d ≥ max(D, dy) is then at least
/// D / (dx + min(D, the cell's largest diameter)); Balance ≥ 1. It is evaluated with the same
/// floating-point operations as the Cost, on operands no larger, so it never exceeds a Cost it
/// bounds, and is lowered by 1e-9 relative for `powf` and the rounding of the Fill bound's sum.
#[inline(always)]
fn cost_bound<const A: u8>(w: &Weights, xa: &Aabb, dx: f64, cb: &CellBounds) -> f64 {
    let span = |k: usize| xa.max[k].max(cb.min_hi[k]) - xa.min[k].min(cb.max_lo[k]);
    let d = V3::new(span(0), span(1), span(2)).norm().max(cb.dmin);
    let scale = match A {
        1 => d,
        0 => 1.0,
        _ => d.powf(w.a),
    };
    let sum = dx + cb.dmax.min(d);
    let fill = if sum > 0.0 {
        let q = d / sum;
        if dx == 0.0 { q.min(1.0) } else { q }
    } else {
        1.0
    };
    w.cost_scaled(scale, fill, 1.0) * (1.0 - 1e-9)
}

/// Whether every box stored in a cell with bounds `a` is within L∞ gap `g` ≥ 0 of every box
/// stored in one with bounds `b`: per axis, the largest box minimum of one minus the smallest
/// box maximum of the other is at most `g` (as rounded, it bounds each pair's difference).
#[inline]
fn within(a: &CellBounds, b: &CellBounds, g: f64) -> bool {
    (0..3).all(|k| b.max_lo[k] - a.min_hi[k] <= g && a.max_lo[k] - b.min_hi[k] <= g)
}

/// The records of `recs` (sorted by smallest x, finite) not [`apart`] from `xa`, and the number
/// read before the rest lie beyond GLimit in x.
#[inline]
fn count_near(xa: &Aabb, recs: &[Rec], g: f64) -> (u64, u64) {
    let end = recs.partition_point(|r| r.aabb.min.x - xa.max.x <= g);
    let near = recs[..end]
        .iter()
        .filter(|r| !apart(xa, &r.aabb, g))
        .count();
    (near as u64, end as u64)
}

/// Sorts a search's cells by Cost bound, ascending (insertion sort: 27 cells but for rounding).
#[inline]
fn insertion_sort<T: Copy>(v: &mut [(f64, T)]) {
    for i in 1..v.len() {
        let mut j = i;
        while j > 0 && v[j].0 < v[j - 1].0 {
            v.swap(j, j - 1);
            j -= 1;
        }
    }
}

/// The records of a cell that a single search reads in one go.
#[derive(Clone, Copy, Debug)]
enum Part {
    /// Every record.
    All,
    /// One block of the sorted head.
    Block(u32),
    /// The records after the sorted head.
    Tail,
}

/// Adds to `pairs` the number of eligible pairs of a record of sorted run `a` with one of sorted
/// run `b` (fresh, finite boxes, GLimit `g` ≥ 0), each run with the bounds of its boxes: the
/// product of their sizes when every two boxes are within `g`, none when their unions are apart,
/// else counted record by record (those read added to `candidates`).
fn count_across(
    (a, ab): (&[Rec], &CellBounds),
    (b, bb): (&[Rec], &CellBounds),
    g: f64,
    pairs: &mut u64,
    candidates: &mut u64,
) {
    if within(ab, bb, g) {
        *pairs += (a.len() * b.len()) as u64;
    } else if !apart(&ab.union, &bb.union, g) {
        for x in a {
            let (m, seen) = count_near(&x.aabb, b, g);
            *pairs += m;
            *candidates += seen;
        }
    }
}

/// The later cells (in voxel order) any body of cell `c` may pair with, into `near`: those
/// in reach of its bodies' query boxes whose unions are within GLimit `g` of its union.
fn later_near(hash: &VoxelHash, half_ext: &[f64; 3], c: u32, g: f64, near: &mut Vec<u32>) {
    let vc = hash.coords(c);
    let (mut clo, mut chi) = (
        P3::new(f64::MAX, f64::MAX, f64::MAX),
        P3::new(f64::MIN, f64::MIN, f64::MIN),
    );
    for r in hash.recs(c) {
        let (lo, hi) = query_box(half_ext, &r.aabb, g);
        clo = clo.inf(&lo);
        chi = chi.sup(&hi);
    }
    near.clear();
    hash.for_each_cell(&clo, &chi, |cell, v| {
        if v > vc && !apart(&hash.bounds(c).union, &hash.bounds(cell).union, g) {
            near.push(cell);
        }
    });
}

/// The eligible pairs of cell `c`'s bodies with each other and with the bodies of later cells
/// (fresh cells, finite boxes, GLimit `g` ≥ 0; `half_ext` the round's largest half-extents), as
/// [`Clusterer::pairs_once`] counts them, and the records read: a pair of cells or runs whose
/// every two boxes are within GLimit adds the product of their sizes without reading the
/// records. `near` is scratch.
fn count_cell(
    hash: &VoxelHash,
    half_ext: &[f64; 3],
    c: u32,
    g: f64,
    near: &mut Vec<u32>,
) -> (u64, u64) {
    let (mut pairs, mut candidates) = (0u64, 0u64);
    later_near(hash, half_ext, c, g, near);
    let n = hash.recs(c).len() as u64;
    if within(hash.bounds(c), hash.bounds(c), g) {
        pairs += n * n.saturating_sub(1) / 2;
    } else {
        for (i, (a, ab)) in hash.bounded_runs(c).enumerate() {
            let m = a.len() as u64;
            if within(ab, ab, g) {
                pairs += m * m.saturating_sub(1) / 2;
            } else {
                for (j, x) in a.iter().enumerate() {
                    let (m, seen) = count_near(&x.aabb, &a[j + 1..], g);
                    pairs += m;
                    candidates += seen;
                }
            }
            for (b, bb) in hash.bounded_runs(c).skip(i + 1) {
                count_across((a, ab), (b, bb), g, &mut pairs, &mut candidates);
            }
        }
    }
    for &cell in near.iter() {
        if within(hash.bounds(c), hash.bounds(cell), g) {
            pairs += n * hash.recs(cell).len() as u64;
        } else {
            for a in hash.bounded_runs(c) {
                for b in hash.bounded_runs(cell) {
                    count_across(a, b, g, &mut pairs, &mut candidates);
                }
            }
        }
    }
    (pairs, candidates)
}

/// What a single search offers each record with.
struct Searcher<'t> {
    xa: Aabb,
    dx: f64,
    glimit: f64,
    quick: Option<Quick>,
    area: bool,
    w: Weights,
    wide: usize,
    tags: &'t [u64],
}

impl Searcher<'_> {
    /// Offers record `r` (skipped if [`DEAD`]) to `list`, whose bar is `bar`; returns the
    /// list's bar after.
    #[inline(always)]
    fn visit<const A: u8>(&self, r: &Rec, bar: f64, list: &mut Top<{ K_MAX + 1 }>) -> f64 {
        let xa = &self.xa;
        let e = merged_extents(xa, &r.aabb);
        // One branch on the three tests together (each alone is a coin flip to predict).
        let beyond = match self.quick {
            Some(q) => q.beyond(e.norm_squared(), self.dx + r.diameter, bar),
            None => false,
        };
        if (r.id == DEAD) | apart(xa, &r.aabb, self.glimit) | beyond {
            return bar;
        }
        let (d, sx, sy) = measures(self.area, &e, xa, self.dx, &r.aabb, r.diameter);
        let cost = pair_cost::<A>(&self.w, d, sx, sy);
        list.offer(self.wide, cost, r.id, self.tags);
        list.bar(self.wide)
    }
}

impl Searcher<'_> {
    /// Offers the records of `part` of `cell` to `list`, counting them into `candidates`;
    /// a sorted run of at least [`SWEEP_MIN`] records is read outward from the searcher and
    /// left each way at the first record no pair with could enter the list.
    #[inline(always)]
    fn read<const A: u8>(
        &self,
        hash: &VoxelHash,
        cell: u32,
        part: Part,
        list: &mut Top<{ K_MAX + 1 }>,
        candidates: &mut u64,
    ) {
        let xa = &self.xa;
        let mut bar = list.bar(self.wide);
        let recs = hash.recs(cell);
        let sorted = hash.sorted_len(cell);
        let (head, tail, dmax) = match part {
            Part::All => (&recs[..sorted], &recs[sorted..], hash.bounds(cell).dmax),
            Part::Tail => (&recs[..0], &recs[sorted..], 0.0),
            Part::Block(j) => {
                let j = j as usize;
                let end = ((j + 1) * BLOCK).min(sorted);
                let dmax = hash.block_bounds(cell)[j].dmax;
                (&recs[j * BLOCK..end], &recs[..0], dmax)
            }
        };
        let (swept, rest) = match self.quick {
            Some(q) if head.len() >= SWEEP_MIN && self.dx > 0.0 => {
                // Outward from `x`'s smallest x: the merged box's x extent is at least the
                // distance between the two smallest x (rightward) or from the other's smallest
                // x to `x`'s largest (leftward), and grows with each step, so a direction ends
                // at the first record beyond the bar.
                let at = head.partition_point(|r| r.aabb.min.x < xa.min.x);
                for r in &head[at..] {
                    let s = r.aabb.min.x - xa.min.x;
                    if q.beyond_all(s * s, self.dx, dmax, bar) {
                        break;
                    }
                    *candidates += 1;
                    bar = self.visit::<A>(r, bar, list);
                }
                for r in head[..at].iter().rev() {
                    let s = xa.max.x - r.aabb.min.x;
                    if q.beyond_all(s * s, self.dx, dmax, bar) {
                        break;
                    }
                    *candidates += 1;
                    bar = self.visit::<A>(r, bar, list);
                }
                (true, tail)
            }
            _ => (false, tail),
        };
        let unswept = if swept { &head[..0] } else { head };
        for r in unswept.iter().chain(rest) {
            *candidates += 1;
            bar = self.visit::<A>(r, bar, list);
        }
    }
}

/// Whether a cell may hold an eligible partner of a body with box `xa`: the L∞ gap to the
/// union of the cell's boxes is at most GLimit (it is at most the gap to any of them, also as
/// rounded).
#[inline(always)]
fn reachable(cb: &CellBounds, xa: &Aabb, glimit: f64) -> bool {
    !apart(xa, &cb.union, glimit)
}

/// What a pruned search (AABB p-set) reads: the round's voxel hash and bodies, and the Cost.
pub(super) struct PrunedSearch<'a> {
    /// The round's stored bodies.
    hash: &'a VoxelHash,
    /// Every body's box and diameter, by id.
    aabb: &'a [Aabb],
    diameter: &'a [f64],
    /// Largest half-extent per axis of the stored bodies ([`query_box`]).
    half_ext: [f64; 3],
    /// The Cost's weights.
    w: Weights,
    /// Partner list length.
    k: usize,
    /// Whether the Cost is in surface area.
    area: bool,
    /// Whether Cost bounds may skip cells and blocks.
    prune: bool,
    /// The sqrt-free Cost filter, where it holds.
    quick: Option<Quick>,
    /// Every body's tie tag.
    tags: &'a [u64],
}

impl PrunedSearch<'_> {
    /// The first `K_MAX + 1` partners of `x` in key order, `x` among them (see [`Memo`]),
    /// visiting cells cheapest bound first and stopping at the first cell whose [`cost_bound`]
    /// exceeds the last Cost the list keeps; `items` is scratch, and the records read are
    /// added to `candidates`.
    fn list<const A: u8>(
        &self,
        x: u32,
        glimit: f64,
        items: &mut Vec<(f64, u32)>,
        candidates: &mut u64,
    ) -> Top<{ K_MAX + 1 }> {
        let (k, w, hash, prune, area) = (self.k, self.w, self.hash, self.prune, self.area);
        let xa = self.aabb[x as usize];
        let dx = self.diameter[x as usize];
        let (lo, hi) = query_box(&self.half_ext, &xa, glimit);
        // Gather the voxels' cells first and start loading their bounds, so those cache misses
        // overlap instead of following one another.
        let mut ids = [0u32; 64];
        let mut m = 0;
        let mut more: Vec<u32> = Vec::new();
        hash.for_each_cell(&lo, &hi, |cell, _| {
            hash.prefetch_cell(cell);
            if m < ids.len() {
                ids[m] = cell;
                m += 1;
            } else {
                more.push(cell);
            }
        });
        // The reachable cells with a lower bound on the Cost of their pairs, cheapest first.
        let mut cells: [(f64, u32); 64] = [(0.0, 0); 64];
        let mut n = 0;
        let mut overflow: Vec<(f64, u32)> = Vec::new();
        for &cell in ids[..m].iter().chain(&more) {
            let cb = hash.bounds(cell);
            if reachable(cb, &xa, glimit) {
                hash.prefetch(cell);
                let bound = if prune {
                    cost_bound::<A>(&w, &xa, dx, cb)
                } else {
                    f64::NEG_INFINITY
                };
                if n < cells.len() {
                    cells[n] = (bound, cell);
                    n += 1;
                } else {
                    overflow.push((bound, cell));
                }
            }
        }
        let cells: &mut [(f64, u32)] = if overflow.is_empty() {
            &mut cells[..n]
        } else {
            // Only reachable through rounding at voxel boundaries.
            overflow.extend_from_slice(&cells);
            &mut overflow
        };
        insertion_sort(cells);
        // One more partner than a list holds, and `x` among the candidates (see [`Memo`]).
        let mut list = Top::<{ K_MAX + 1 }>::EMPTY;
        let wide = k + 1;
        let me = Searcher {
            xa,
            dx,
            glimit,
            quick: self.quick,
            area,
            w,
            wide,
            tags: self.tags,
        };
        for &(bound, cell) in cells.iter() {
            if bound > list.bar(wide) {
                break;
            }
            // A blocked cell is read block by block, cheapest bound first, each picked when the
            // last is read (a search reads few of a crowded cell's blocks), then its tail.
            let blocks = hash.block_bounds(cell);
            let sorted = hash.sorted_len(cell);
            let last = if !prune || blocks.is_empty() {
                Part::All
            } else {
                items.clear();
                for (j, bb) in blocks.iter().enumerate() {
                    if j * BLOCK < sorted && reachable(bb, &xa, glimit) {
                        items.push((cost_bound::<A>(&w, &xa, dx, bb), j as u32));
                    }
                }
                for i in 0..items.len() {
                    let least = (i..items.len())
                        .fold(i, |a, j| if items[j].0 < items[a].0 { j } else { a });
                    items.swap(i, least);
                    if items[i].0 > list.bar(wide) {
                        break;
                    }
                    me.read::<A>(hash, cell, Part::Block(items[i].1), &mut list, candidates);
                }
                if sorted == hash.recs(cell).len() || bound > list.bar(wide) {
                    continue;
                }
                Part::Tail
            };
            me.read::<A>(hash, cell, last, &mut list, candidates);
        }
        list
    }
}

impl<P: PSetBodies, O: Observer> Clusterer<P, O> {
    /// The box that holds the centre of every eligible partner of a body with box `xa`.
    #[inline]
    fn query(&self, xa: &Aabb, glimit: f64) -> (P3, P3) {
        query_box(&self.half_ext, xa, glimit)
    }

    /// Step 3 after the active bodies are stored: fills every active body's partner list and
    /// returns the number of eligible pairs. Stops early, with `limit.hit` set, when `limit`
    /// is exceeded (checked before each body).
    pub(super) fn round_start_search(
        &mut self,
        order: &[u32],
        glimit: f64,
        limit: &mut ScanLimit<'_>,
    ) -> u64 {
        if P::AABB {
            let exponent = self.params.weights.exponent();
            // The parallel scan computes the diameter Cost only; the area Cost scans in order.
            let area = self.params.mode.cost == CostMeasure::Area;
            let quick = Quick::new(&self.params.weights, self.quick && !area).is_some();
            if quick && glimit >= 0.0 && limit.budget.max_pairs.is_none() && self.crowded() {
                if par::worth_it(par::CROWDED_MIN_BODIES, order.len(), limit) {
                    // The sqrt-free filter holds for A = 1 only.
                    debug_assert!(exponent == Exponent::One);
                    return self.crowded_par(order, glimit, limit);
                }
                let pairs = self.count_pairs(glimit);
                for &x in order {
                    if limit.over(0) {
                        break;
                    }
                    self.search(x, glimit);
                }
                return pairs;
            }
            if !area && par::worth_it(par::MIN_BODIES, order.len(), limit) {
                by_exponent!(exponent, A => self.pairs_once_par::<A>(glimit, limit))
            } else {
                by_exponent!(exponent, A => self.pairs_once::<A>(glimit, limit))
            }
        } else {
            // Each pair is found from both of its bodies.
            let mut twice = 0u64;
            for &x in order {
                if limit.over(twice / 2) {
                    break;
                }
                twice += self.scan_all(x, glimit) as u64;
            }
            twice / 2
        }
    }

    /// Whether the round's cells are crowded ([`CROWDED`]).
    fn crowded(&self) -> bool {
        let hash = &self.hash;
        let (mut bodies, mut mates) = (0usize, 0usize);
        for c in 0..hash.cells() {
            let n = hash.recs(c).len();
            bodies += n;
            mates += n * n;
        }
        mates > CROWDED * bodies
    }

    /// The number of eligible pairs among the stored bodies (fresh cells, finite boxes, GLimit
    /// ≥ 0), as [`Clusterer::pairs_once`] counts them ([`count_cell`], cell by cell).
    fn count_pairs(&mut self, glimit: f64) -> u64 {
        let mut near: Vec<u32> = Vec::with_capacity(27);
        let (mut pairs, mut candidates) = (0u64, 0u64);
        for c in 0..self.hash.cells() {
            let (p, seen) = count_cell(&self.hash, &self.half_ext, c, glimit, &mut near);
            pairs += p;
            candidates += seen;
        }
        self.stats.candidates += candidates;
        pairs
    }

    /// Step 4(b) (and a used-up list): refills `x`'s partner list.
    pub(super) fn search(&mut self, x: u32, glimit: f64) {
        if P::AABB {
            by_exponent!(self.params.weights.exponent(), A => self.scan_pruned::<A>(x, glimit))
        } else {
            self.search_any(x, glimit);
        }
    }

    /// The memo key of body `x`.
    fn memo_key(&self, x: u32) -> MemoKey {
        memo_key(
            &self.aabb[x as usize],
            self.diameter[x as usize],
            self.hash.version(),
        )
    }

    /// `x`'s list from the [`Memo`] of a search by a body identical to it, if there is one.
    fn reuse_memo(&mut self, x: u32, key: &MemoKey) -> bool {
        let Some(m) = &self.memo else {
            return false;
        };
        if m.key != *key || !self.pset.same(m.body, x) {
            return false;
        }
        *self.partners.get(x) = m.top.without(x, self.k);
        true
    }

    /// The search of a body after a merge for p-sets other than AABB: [`Self::scan_all`]'s
    /// list, served from the [`Memo`] where it can be.
    fn search_any(&mut self, x: u32, glimit: f64) {
        let key = self.memo_key(x);
        if self.reuse_memo(x, &key) {
            return;
        }
        let (top, _) = self.scan_list::<{ K_MAX + 1 }>(x, glimit, true);
        *self.partners.get(x) = top.without(x, self.k);
        self.memo = Some(Memo { key, body: x, top });
    }

    /// Every eligible pair once (AABB p-set); returns their number (so far, when `limit` cuts
    /// the scan short).
    ///
    /// The AABB pair Cost is a symmetric function of the two boxes and diameters, so each pair
    /// of cells is visited once (a body's own cell after it, and the voxels after its own in
    /// (x, y, z) order) and each eligible pair is offered to both bodies' partner lists.
    fn pairs_once<const A: u8>(&mut self, glimit: f64, limit: &mut ScanLimit<'_>) -> u64 {
        let (k, w, finite) = (self.k, self.params.weights, self.finite);
        let area = self.params.mode.cost == CostMeasure::Area;
        let quick = Quick::new(&w, self.quick && !area);
        let mut pairs = 0u64;
        let mut candidates = 0u64;
        let mut near: Vec<u32> = Vec::with_capacity(27);
        let mut fwd: Vec<u32> = Vec::with_capacity(27);
        'cells: for c in 0..self.hash.cells() {
            // The later cells any body of this cell may pair with, found once per cell.
            let hash = &self.hash;
            later_near(hash, &self.half_ext, c, glimit, &mut near);
            for i in 0..hash.recs(c).len() {
                if limit.over(pairs) {
                    break 'cells;
                }
                let xr = hash.recs(c)[i];
                let (x, xa, dx, sx) = (xr.id, xr.aabb, xr.diameter, xr.slot as usize);
                fwd.clear();
                fwd.extend(
                    near.iter()
                        .copied()
                        .filter(|&cell| reachable(hash.bounds(cell), &xa, glimit)),
                );
                let (tags, partners) = (&self.tag, &mut self.partners);
                let own = hash.runs_from(c, i + 1).map(|(_, run)| run);
                let later = fwd.iter().flat_map(|&cell| hash.runs(cell));
                for seg in own.chain(later) {
                    for yr in seg {
                        // Fresh runs are sorted by smallest x: the rest are farther still.
                        if finite && yr.aabb.min.x - xa.max.x > glimit {
                            break;
                        }
                        candidates += 1;
                        if apart(&xa, &yr.aabb, glimit) {
                            continue;
                        }
                        pairs += 1;
                        let e = merged_extents(&xa, &yr.aabb);
                        let sy = yr.slot as usize;
                        let lists = partners.lists_mut();
                        if let Some(q) = quick {
                            let bar = lists[sx].bar(k).max(lists[sy].bar(k));
                            if q.beyond(e.norm_squared(), dx + yr.diameter, bar) {
                                continue;
                            }
                        }
                        let (d, sx_, sy_) = measures(area, &e, &xa, dx, &yr.aabb, yr.diameter);
                        let cost = pair_cost::<A>(&w, d, sx_, sy_);
                        lists[sx].offer(k, cost, yr.id, tags);
                        lists[sy].offer(k, cost, x, tags);
                    }
                }
            }
        }
        self.stats.candidates += candidates;
        pairs
    }

    /// What a pruned search reads (AABB p-set).
    fn pruned(&self) -> PrunedSearch<'_> {
        let area = self.params.mode.cost == CostMeasure::Area;
        PrunedSearch {
            hash: &self.hash,
            aabb: &self.aabb,
            diameter: &self.diameter,
            half_ext: self.half_ext,
            w: self.params.weights,
            k: self.k,
            area,
            prune: self.prune && !area,
            quick: Quick::new(&self.params.weights, self.quick && !area),
            tags: &self.tag,
        }
    }

    /// The first partners of `x` in key order (AABB p-set), into its list, served from the
    /// [`Memo`] where it can be ([`PrunedSearch::list`]).
    fn scan_pruned<const A: u8>(&mut self, x: u32, glimit: f64) {
        let key = self.memo_key(x);
        if self.reuse_memo(x, &key) {
            return;
        }
        let mut items = std::mem::take(&mut self.items);
        let mut candidates = 0u64;
        let list = self
            .pruned()
            .list::<A>(x, glimit, &mut items, &mut candidates);
        self.items = items;
        self.stats.candidates += candidates;
        *self.partners.get(x) = list.without(x, self.k);
        self.memo = Some(Memo {
            key,
            body: x,
            top: list,
        });
    }

    /// The first partners of `x` over every candidate (any p-set), into its list; returns the
    /// number of eligible partners.
    fn scan_all(&mut self, x: u32, glimit: f64) -> u32 {
        let (list, eligible) = self.scan_list::<K_MAX>(x, glimit, false);
        *self.partners.get(x) = list;
        eligible
    }

    /// The first `C` partners of `x` in key order over every candidate, `x` itself among them
    /// when `with_self` (see [`Memo`]), and the number of eligible pairs found.
    fn scan_list<const C: usize>(&mut self, x: u32, glimit: f64, with_self: bool) -> (Top<C>, u32) {
        let k = self.k + usize::from(with_self);
        let xa = self.aabb[x as usize];
        let dx = self.diameter[x as usize];
        let (lo, hi) = self.query(&xa, glimit);
        let (hash, pset, tags, w) = (&self.hash, &self.pset, &self.tag, self.params.weights);
        let area = self.params.mode.cost == CostMeasure::Area;
        let mut list = Top::<C>::EMPTY;
        let mut eligible = 0u32;
        let mut candidates = 0u64;
        hash.for_each_cell(&lo, &hi, |cell, _| {
            for r in hash.recs(cell) {
                candidates += 1;
                if (r.id == x && !with_self) || r.id == DEAD || apart(&xa, &r.aabb, glimit) {
                    continue;
                }
                let merged = xa.merge(&r.aabb);
                let Some(d) = pset.eligible(x, r.id, &merged, glimit) else {
                    continue;
                };
                eligible += u32::from(r.id != x);
                let (d, sx, sy) = if area {
                    let e = merged.max - merged.min;
                    measures(true, &e, &xa, dx, &r.aabb, r.diameter)
                } else {
                    (d, dx, r.diameter)
                };
                let (fill, balance) = fill_balance(d, sx, sy);
                list.offer(k, w.cost(d, fill, balance), r.id, tags);
            }
        });
        self.stats.candidates += candidates;
        (list, eligible)
    }
}
