//! Step 3's body-centre occupancy array (§2.3: "the array can be implemented virtually with a
//! spatial hash table … the storage for the array only really need be size O(N)").
//!
//! Voxels have edge CSize = DLimit + GLimit. Each round the array is rebuilt over the box of
//! the active bodies: as a dense grid of cell indices when that grid has at most a few voxels
//! per active body, otherwise as a hash of voxel coordinates (scenes of far-apart clusters).
//! A cell keeps its bodies as contiguous records (box, diameter, id) in one shared arena, laid
//! out in the order the bodies were inserted (Morton order at round start), with slack for the
//! bodies made during the round; a full cell moves to the end of the arena with twice the room.
//! Removal swaps the body with its cell's last record (O(1), the arena position of every body is
//! kept). At build each cell's records are laid out in sorted runs: a cell of fewer than
//! [`BLOCKED_MIN`] records is one run, sorted by the boxes' smallest x; a larger one is cut into
//! blocks of at most [`BLOCK`] records with nearby centres (median splits of the centres on their
//! widest axis), each sorted by smallest x and with its own bounds ([`VoxelHash::block_bounds`]),
//! so a search can bound the Cost of a block's bodies and skip it, as it skips cells. The
//! round-start scan stops early in each run; insertions append after the runs and a removal
//! keeps the order only of the records before its place ([`VoxelHash::sorted_len`]). Each
//! cell also keeps the union of the boxes, the largest box minimum and smallest box maximum
//! corner, and the largest and smallest diameter ever stored in it this round, so callers can
//! bound the Cost of any pair with a body of that cell.

use crate::geom::{Aabb, P3};
use std::collections::HashMap;

/// One active body as stored in a voxel.
#[derive(Clone, Copy, Debug)]
#[repr(align(64))]
pub struct Rec {
    /// Its AABB.
    pub aabb: Aabb,
    /// Its diameter.
    pub diameter: f64,
    /// Body id.
    pub id: u32,
    /// The body's partner-list slot (fills the record's padding; spares a lookup by id).
    pub slot: u32,
}

/// What a cell knows about every body stored in it during the round (grow-only).
#[derive(Clone, Copy, Debug)]
pub struct CellBounds {
    /// The union of the boxes.
    pub union: Aabb,
    /// Largest box minimum corner coordinates (every box reaches at least this low).
    pub max_lo: [f64; 3],
    /// Smallest box maximum corner coordinates (every box reaches at least this high).
    pub min_hi: [f64; 3],
    /// Largest diameter.
    pub dmax: f64,
    /// Smallest diameter.
    pub dmin: f64,
}

const EMPTY_BOUNDS: CellBounds = CellBounds {
    union: Aabb::EMPTY,
    max_lo: [f64::NEG_INFINITY; 3],
    min_hi: [f64::INFINITY; 3],
    dmax: 0.0,
    dmin: f64::INFINITY,
};

/// A cell's place in the arena and its bounds, together in two cache lines (one miss with
/// the adjacent-line prefetch) since a search reads both.
#[derive(Clone, Copy, Debug)]
#[repr(align(128))]
struct Cell {
    start: u32,
    len: u32,
    cap: u32,
    /// How many leading records are still sorted by their boxes' smallest x.
    sorted: u32,
    bounds: CellBounds,
}

/// Voxel coordinates are clamped to `0..=MAX_COORD` so keys never alias.
const MAX_COORD: i64 = (1 << 42) - 1;
const NO_CELL: u32 = u32::MAX;
/// The id of a removed record left in place ([`VoxelHash::remove`]).
pub const DEAD: u32 = u32::MAX;
/// Cells of at least this many records keep their sorted records in order when one is removed.
const KEEP_ORDER: u32 = 32;
/// The most records in a block of a cell's sorted runs.
pub const BLOCK: usize = 16;
/// Cells of at least this many records are cut into blocks (at least `KEEP_ORDER`, so a
/// removal leaves the blocks in place).
pub const BLOCKED_MIN: usize = 32;
const BLANK: Rec = Rec {
    aabb: Aabb::EMPTY,
    diameter: 0.0,
    id: DEAD,
    slot: u32::MAX,
};

/// Voxel hash with edge length CSize = DLimit + GLimit.
#[derive(Debug)]
pub struct VoxelHash {
    origin: [f64; 3],
    inv_csize: f64,
    /// Dense grid dimensions, or `None` when the sparse map is used.
    dims: Option<[i64; 3]>,
    dense: Vec<u32>,
    sparse: HashMap<u128, u32, foldhash::fast::FixedState>,
    cells: Vec<Cell>,
    /// Removed records left in place in each cell.
    dead: Vec<u32>,
    coords: Vec<[i64; 3]>,
    recs: Vec<Rec>,
    /// Each cell's first block in `block_bounds` and its number of blocks (0: one run).
    blocks: Vec<(u32, u32)>,
    /// The bounds of every block, for the boxes stored in it when it was made.
    block_bounds: Vec<CellBounds>,
    /// Arena position and cell of every body id (valid while the body is stored).
    at: Vec<(u32, u32)>,
    /// Bumped by every build, insertion and removal.
    version: u64,
}

impl Default for VoxelHash {
    fn default() -> Self {
        VoxelHash {
            origin: [0.0; 3],
            inv_csize: 1.0,
            dims: None,
            dense: Vec::new(),
            sparse: HashMap::with_hasher(foldhash::fast::FixedState::with_seed(0)),
            cells: Vec::new(),
            dead: Vec::new(),
            coords: Vec::new(),
            recs: Vec::new(),
            blocks: Vec::new(),
            block_bounds: Vec::new(),
            at: Vec::new(),
            version: 0,
        }
    }
}

impl VoxelHash {
    /// Empties the hash (keeping allocations), sets the voxel edge to `csize` and stores
    /// `bodies` (the round's active bodies, in the order their records should be laid out).
    /// `boxes`, `diameters` and `slots` (partner-list slots) are indexed by body id; `ids` is
    /// the number of body ids.
    pub fn build(
        &mut self,
        csize: f64,
        bodies: &[u32],
        boxes: &[Aabb],
        diameters: &[f64],
        slots: &[u32],
        ids: usize,
    ) {
        self.version += 1;
        self.inv_csize = 1.0 / csize;
        let all = bodies
            .iter()
            .fold(Aabb::EMPTY, |b, &x| b.merge(&boxes[x as usize]));
        // Every body made this round lies inside the union of the active boxes.
        self.origin = [all.min.x, all.min.y, all.min.z];
        self.cells.clear();
        self.dead.clear();
        self.coords.clear();
        self.recs.clear();
        self.blocks.clear();
        self.block_bounds.clear();
        self.sparse.clear();
        self.at.resize(ids, (0, NO_CELL));
        self.dims = None;
        let max = self.coords_of(&all.max);
        let dims = max.map(|m| m.max(0) + 1);
        let voxels = dims.iter().try_fold(1i64, |a, &d| a.checked_mul(d));
        self.dims = voxels
            .filter(|&v| v <= 4 * bodies.len() as i64 + 4096)
            .map(|_| dims);
        if let Some(v) = voxels.filter(|_| self.dims.is_some()) {
            self.dense.clear();
            self.dense.resize(v as usize, NO_CELL);
        }
        // Count per cell, then give each cell its records plus slack for the round's new bodies.
        let mut cell_of = Vec::with_capacity(bodies.len());
        for &x in bodies {
            let c = self.cell_at(&boxes[x as usize].center());
            self.cells[c as usize].len += 1;
            cell_of.push(c);
        }
        let mut start = 0u32;
        for cell in &mut self.cells {
            cell.start = start;
            cell.cap = cell.len + cell.len / 2 + 2;
            start += cell.cap;
            cell.len = 0;
        }
        self.recs.resize(start as usize, BLANK);
        for (&x, &c) in bodies.iter().zip(&cell_of) {
            let x = x as usize;
            self.put(
                c,
                Rec {
                    aabb: boxes[x],
                    diameter: diameters[x],
                    id: x as u32,
                    slot: slots[x],
                },
            );
        }
        for c in 0..self.cells.len() as u32 {
            let len = self.cells[c as usize].len;
            self.lay_out(c, len);
        }
    }

    /// Lays out the first `len` records of cell `c` (none of them [`DEAD`]) in sorted runs
    /// (module doc), updates their arena positions, and makes them the cell's sorted head.
    fn lay_out(&mut self, c: u32, len: u32) {
        let cell = &mut self.cells[c as usize];
        let s = cell.start as usize;
        cell.sorted = len;
        let recs = &mut self.recs[s..s + len as usize];
        let by_x = |a: &Rec, b: &Rec| a.aabb.min.x.total_cmp(&b.aabb.min.x);
        if recs.len() < BLOCKED_MIN {
            recs.sort_unstable_by(by_x);
            self.blocks[c as usize] = (0, 0);
        } else {
            split_blocks(recs);
            let first = self.block_bounds.len() as u32;
            for block in recs.chunks_mut(BLOCK) {
                block.sort_unstable_by(by_x);
                let mut b = EMPTY_BOUNDS;
                for r in block.iter() {
                    grow(&mut b, &r.aabb, r.diameter);
                }
                self.block_bounds.push(b);
            }
            let n = self.block_bounds.len() as u32 - first;
            self.blocks[c as usize] = (first, n);
        }
        for (i, r) in recs.iter().enumerate() {
            self.at[r.id as usize].0 = (s + i) as u32;
        }
    }

    #[inline]
    fn coords_of(&self, p: &P3) -> [i64; 3] {
        let f = |k: usize| floor((p[k] - self.origin[k]) * self.inv_csize).clamp(0, MAX_COORD);
        let v = [f(0), f(1), f(2)];
        match self.dims {
            Some(d) => [v[0].min(d[0] - 1), v[1].min(d[1] - 1), v[2].min(d[2] - 1)],
            None => v,
        }
    }

    /// The voxel coordinates of the voxels holding `lo` and `hi` (a monotone map, so a centre
    /// inside `[lo, hi]` lies in a voxel of the returned range).
    #[inline]
    pub fn range(&self, lo: &P3, hi: &P3) -> ([i64; 3], [i64; 3]) {
        (self.coords_of(lo), self.coords_of(hi))
    }

    /// The cell of voxel `v`, if any body was stored there this round.
    #[inline]
    pub fn cell(&self, v: [i64; 3]) -> Option<u32> {
        let c = match self.dims {
            Some(d) => self.dense[((v[0] * d[1] + v[1]) * d[2] + v[2]) as usize],
            None => *self.sparse.get(&key(v))?,
        };
        (c != NO_CELL).then_some(c)
    }

    /// The cell of the voxel holding `p`, made (empty) if there is none.
    fn cell_at(&mut self, p: &P3) -> u32 {
        let v = self.coords_of(p);
        if let Some(c) = self.cell(v) {
            return c;
        }
        let c = self.cells.len() as u32;
        match self.dims {
            Some(d) => self.dense[((v[0] * d[1] + v[1]) * d[2] + v[2]) as usize] = c,
            None => {
                self.sparse.insert(key(v), c);
            }
        }
        self.cells.push(Cell {
            start: self.recs.len() as u32,
            len: 0,
            cap: 0,
            sorted: 0,
            bounds: EMPTY_BOUNDS,
        });
        self.dead.push(0);
        self.blocks.push((0, 0));
        self.coords.push(v);
        c
    }

    fn put(&mut self, c: u32, rec: Rec) {
        let (id, aabb, diameter) = (rec.id, &rec.aabb, rec.diameter);
        let cell = &mut self.cells[c as usize];
        if cell.len == cell.cap {
            // Move the cell to the end of the arena with twice the room.
            let (from, len) = (cell.start as usize, cell.len as usize);
            let start = self.recs.len();
            cell.start = start as u32;
            cell.cap = 2 * cell.cap + 4;
            self.recs.resize(start + cell.cap as usize, BLANK);
            self.recs.copy_within(from..from + len, start);
            for i in start..start + len {
                let id = self.recs[i].id;
                if id != DEAD {
                    self.at[id as usize].0 = i as u32;
                }
            }
        }
        let cell = &mut self.cells[c as usize];
        let i = (cell.start + cell.len) as usize;
        cell.len += 1;
        self.recs[i] = rec;
        self.at[id as usize] = (i as u32, c);
        grow(&mut self.cells[c as usize].bounds, aabb, diameter);
    }

    /// Adds body `id` (partner-list slot `slot`) by the centre of its box.
    pub fn insert(&mut self, id: u32, aabb: &Aabb, diameter: f64, slot: u32) {
        self.insert_rec(id, aabb, diameter, slot);
        let c = self.at[id as usize].1;
        self.tidy(c);
    }

    fn insert_rec(&mut self, id: u32, aabb: &Aabb, diameter: f64, slot: u32) {
        self.version += 1;
        if self.at.len() <= id as usize {
            self.at.resize(id as usize + 1, (0, NO_CELL));
        }
        let c = self.cell_at(&aabb.center());
        self.put(
            c,
            Rec {
                aabb: *aabb,
                diameter,
                id,
                slot,
            },
        );
    }

    /// Removes body `id` (which must be stored).
    ///
    /// In a cell of at least 32 records, a removed record among the sorted ones
    /// stays in place with id [`DEAD`] (so the order holds), until the dead and unsorted
    /// records are half the cell and it is compacted and sorted again.
    pub fn remove(&mut self, id: u32) {
        self.version += 1;
        let (i, c) = self.at[id as usize];
        self.at[id as usize].1 = NO_CELL;
        let cell = &mut self.cells[c as usize];
        if cell.len >= KEEP_ORDER && i - cell.start < cell.sorted {
            self.recs[i as usize].id = DEAD;
            self.dead[c as usize] += 1;
            self.tidy(c);
            return;
        }
        cell.len -= 1;
        // The records before `i` keep their order.
        cell.sorted = cell.sorted.min(i - cell.start);
        let last = (cell.start + cell.len) as usize;
        self.recs.swap(i as usize, last);
        let moved = self.recs[i as usize].id;
        if moved != DEAD {
            self.at[moved as usize].0 = i;
        }
    }

    /// Compacts and sorts cell `c` once its dead and unsorted records are half of it.
    fn tidy(&mut self, c: u32) {
        let cell = &mut self.cells[c as usize];
        let messy = cell.len - cell.sorted + self.dead[c as usize];
        if cell.len < KEEP_ORDER || 2 * messy <= cell.len {
            return;
        }
        let s = cell.start as usize;
        let recs = &mut self.recs[s..s + cell.len as usize];
        // The live records first, in their order (a stable partition).
        let mut live = 0;
        for i in 0..recs.len() {
            if recs[i].id != DEAD {
                recs[live] = recs[i];
                live += 1;
            }
        }
        recs[live..].fill(BLANK);
        let live = live as u32;
        cell.len = live;
        self.dead[c as usize] = 0;
        self.lay_out(c, live);
    }

    /// A number that changes whenever the stored bodies or the voxel edge change.
    #[inline]
    pub fn version(&self) -> u64 {
        self.version
    }

    /// Number of cells (voxels that held a body this round).
    pub fn cells(&self) -> u32 {
        self.cells.len() as u32
    }

    /// The records stored in cell `c`; after a removal, some may be [`DEAD`] (none right after
    /// a build).
    #[inline]
    pub fn recs(&self, c: u32) -> &[Rec] {
        let cell = &self.cells[c as usize];
        &self.recs[cell.start as usize..(cell.start + cell.len) as usize]
    }

    /// How many leading records of cell `c` ([`VoxelHash::recs`]) are in their sorted runs:
    /// all of them after a build, then those before the first removal's place (insertions
    /// append after them).
    #[inline]
    pub fn sorted_len(&self, c: u32) -> usize {
        self.cells[c as usize].sorted as usize
    }

    /// The bounds of cell `c`'s blocks (empty when its sorted head is one run); block `j` holds
    /// the records `j·BLOCK..(j + 1)·BLOCK` of the cell, cut at [`VoxelHash::sorted_len`].
    #[inline]
    pub fn block_bounds(&self, c: u32) -> &[CellBounds] {
        let (first, n) = self.blocks[c as usize];
        &self.block_bounds[first as usize..(first + n) as usize]
    }

    /// The records in each of cell `c`'s sorted runs (a block, or the whole sorted head of an
    /// unblocked cell): [`BLOCK`] or the head's length.
    #[inline]
    fn run_size(&self, c: u32) -> usize {
        if self.blocks[c as usize].1 == 0 {
            self.sorted_len(c).max(1)
        } else {
            BLOCK
        }
    }

    /// The sorted runs of cell `c`'s head from position `from` of [`VoxelHash::recs`] on (the
    /// rest of `from`'s run, then the later runs), each sorted by the boxes' smallest x, with
    /// the position of its first record.
    #[inline]
    pub fn runs_from(&self, c: u32, from: usize) -> impl Iterator<Item = (usize, &[Rec])> {
        let head = &self.recs(c)[..self.sorted_len(c)];
        let size = self.run_size(c);
        let from = from.min(head.len());
        let end = ((from / size + 1) * size).min(head.len());
        let rest = head[end..]
            .chunks(size)
            .enumerate()
            .map(move |(k, r)| (end + k * size, r));
        std::iter::once((from, &head[from..end])).chain(rest)
    }

    /// The sorted runs of cell `c`'s head, each sorted by the boxes' smallest x.
    #[inline]
    pub fn runs(&self, c: u32) -> std::slice::Chunks<'_, Rec> {
        self.recs(c)[..self.sorted_len(c)].chunks(self.run_size(c))
    }

    /// The sorted runs of cell `c`'s head, each with the bounds of the boxes stored in it: a
    /// block's own, or the cell's for an unblocked cell's one run.
    #[inline]
    pub fn bounded_runs(&self, c: u32) -> impl Iterator<Item = (&[Rec], &CellBounds)> {
        let blocks = self.block_bounds(c);
        let cell = self.bounds(c);
        self.runs(c)
            .enumerate()
            .map(move |(j, r)| (r, blocks.get(j).unwrap_or(cell)))
    }

    /// Asks the CPU to start loading the first records of cell `c` (a no-op off x86-64), so a
    /// search that will read several cells waits for their first cache misses once rather than
    /// in turn (the hardware prefetcher follows each cell's contiguous records).
    #[inline]
    pub fn prefetch(&self, c: u32) {
        for r in self.recs(c).iter().take(2) {
            prefetch(r);
        }
    }

    /// Asks the CPU to start loading cell `c`'s bounds and arena place (a no-op off x86-64).
    #[inline]
    pub fn prefetch_cell(&self, c: u32) {
        prefetch(&self.cells[c as usize]);
    }

    /// What cell `c` has held this round.
    #[inline]
    pub fn bounds(&self, c: u32) -> &CellBounds {
        &self.cells[c as usize].bounds
    }

    /// Voxel coordinates of cell `c`.
    #[inline]
    pub fn coords(&self, c: u32) -> [i64; 3] {
        self.coords[c as usize]
    }

    /// Calls `f` with every cell of a voxel that overlaps the box `[lo, hi]`, so every body
    /// whose centre lies in the box is in one of them (and some others).
    ///
    /// The grouping's query boxes are at most 2·CSize wide, so these are at most the 27 voxels
    /// around the querying body's centre that step 3 names.
    #[inline]
    pub fn for_each_cell(&self, lo: &P3, hi: &P3, mut f: impl FnMut(u32, [i64; 3])) {
        let (a, b) = self.range(lo, hi);
        for x in a[0]..=b[0] {
            for y in a[1]..=b[1] {
                for z in a[2]..=b[2] {
                    if let Some(c) = self.cell([x, y, z]) {
                        f(c, [x, y, z]);
                    }
                }
            }
        }
    }
}

/// Adds a box of diameter `diameter` to the bounds `b`.
#[inline]
fn grow(b: &mut CellBounds, aabb: &Aabb, diameter: f64) {
    for k in 0..3 {
        b.union.min[k] = b.union.min[k].min(aabb.min[k]);
        b.union.max[k] = b.union.max[k].max(aabb.max[k]);
        b.max_lo[k] = b.max_lo[k].max(aabb.min[k]);
        b.min_hi[k] = b.min_hi[k].min(aabb.max[k]);
    }
    b.dmax = b.dmax.max(diameter);
    b.dmin = b.dmin.min(diameter);
}

/// Orders `recs` so that each run of [`BLOCK`] records (from the start) holds nearby centres:
/// the records are split at a multiple of `BLOCK` near their middle by the centres on their
/// widest axis (ties by id), and each side likewise, until a side fits in one block.
fn split_blocks(recs: &mut [Rec]) {
    if recs.len() <= BLOCK {
        return;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for r in recs.iter() {
        let c = r.aabb.center();
        for k in 0..3 {
            lo[k] = lo[k].min(c[k]);
            hi[k] = hi[k].max(c[k]);
        }
    }
    let axis = (0..3).fold(0, |a, k| if hi[k] - lo[k] > hi[a] - lo[a] { k } else { a });
    let mid = (recs.len() / 2 + BLOCK / 2) / BLOCK * BLOCK;
    let key = |r: &Rec| r.aabb.min[axis] + r.aabb.max[axis];
    recs.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)).then(a.id.cmp(&b.id)));
    let (left, right) = recs.split_at_mut(mid);
    split_blocks(left);
    split_blocks(right);
}

/// `v.floor() as i64` without a libm call (baseline x86-64 has no rounding instruction); NaN
/// gives 0 and out-of-range values saturate, like the cast.
#[inline(always)]
fn floor(v: f64) -> i64 {
    let t = v as i64;
    t - ((t as f64) > v) as i64
}

#[inline]
fn key(v: [i64; 3]) -> u128 {
    (v[0] as u128) | ((v[1] as u128) << 42) | ((v[2] as u128) << 84)
}

/// Asks the CPU to start loading the cache line of `x` (a no-op off x86-64): for reads whose
/// addresses are known ahead but that would each wait for a cache miss in turn.
#[inline(always)]
pub(crate) fn prefetch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // SAFETY: SSE is part of x86-64; a prefetch reads nothing and cannot fault.
        unsafe { _mm_prefetch::<_MM_HINT_T0>((x as *const T).cast()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Every stored body is found at its arena position; every block of a cell's sorted head
    /// is sorted by smallest x and within its bounds.
    fn check(hash: &VoxelHash, stored: &[u32]) {
        for &id in stored {
            let (i, c) = hash.at[id as usize];
            assert_eq!(hash.recs[i as usize].id, id);
            assert!(hash.recs(c).iter().any(|r| r.id == id));
        }
        for c in 0..hash.cells() {
            let blocks = hash.block_bounds(c);
            for (j, (run, b)) in hash.bounded_runs(c).enumerate() {
                assert!(run.is_sorted_by(|a, b| a.aabb.min.x <= b.aabb.min.x));
                assert!(std::ptr::eq(b, blocks.get(j).unwrap_or(hash.bounds(c))));
                for r in run.iter().filter(|r| r.id != DEAD) {
                    for k in 0..3 {
                        assert!(b.union.min[k] <= r.aabb.min[k] && r.aabb.max[k] <= b.union.max[k]);
                        assert!(r.aabb.min[k] <= b.max_lo[k] && b.min_hi[k] <= r.aabb.max[k]);
                    }
                    assert!(b.dmin <= r.diameter && r.diameter <= b.dmax);
                }
            }
        }
    }

    #[test]
    fn a_crowded_cell_is_cut_into_sorted_blocks_that_stay_valid_through_removals() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let n = 300;
        let mut boxes: Vec<Aabb> = (0..n)
            .map(|_| {
                let c = P3::new(rng.random(), rng.random(), rng.random());
                let h = rng.random_range(0.001..0.05);
                Aabb {
                    min: c - crate::geom::V3::repeat(h),
                    max: c + crate::geom::V3::repeat(h),
                }
            })
            .collect();
        let diameters: Vec<f64> = boxes.iter().map(Aabb::diameter).collect();
        let ids: Vec<u32> = (0..n as u32).collect();
        let slots = ids.clone();
        let mut hash = VoxelHash::default();
        // One voxel holds every centre.
        hash.build(2.0, &ids, &boxes, &diameters, &slots, 2 * n);
        assert_eq!(hash.cells(), 1);
        assert_eq!(hash.block_bounds(0).len(), n.div_ceil(BLOCK));
        check(&hash, &ids);
        // The blocks hold nearby centres: their boxes span less than the cell's.
        let spread = |b: &CellBounds| (0..3).map(|k| b.union.max[k] - b.union.min[k]).sum::<f64>();
        let blocks = hash.block_bounds(0);
        let mean = blocks.iter().map(spread).sum::<f64>() / blocks.len() as f64;
        assert!(mean < 0.6 * spread(hash.bounds(0)), "{mean}");
        // Remove two thirds and add merged bodies: the blocks and the tail stay consistent.
        let mut stored: Vec<u32> = ids.clone();
        for round in 0..100u32 {
            let (a, b) = (stored.remove(0), stored.remove(0));
            hash.remove(a);
            hash.remove(b);
            let merged = boxes[a as usize].merge(&boxes[b as usize]);
            let new = n as u32 + round;
            boxes.push(merged);
            hash.insert(new, &merged, merged.diameter(), new);
            stored.push(new);
            check(&hash, &stored);
        }
    }
}
