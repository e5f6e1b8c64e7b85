//! Step 3's body-centre occupancy array, stored virtually as a hash of voxel coordinates → the
//! active bodies whose centre lies in that voxel (§2.3: "the storage for the array only really
//! need be size O(N)").
//!
//! A cell keeps its bodies as contiguous small records (id, box, diameter) so a scan reads
//! memory in order; a body is removed from its cell when it merges.

use crate::geom::{Aabb, P3};
use std::collections::HashMap;

/// One active body as stored in a voxel.
#[derive(Clone, Copy, Debug)]
pub struct Rec {
    /// Body id.
    pub id: u32,
    /// Its AABB.
    pub aabb: Aabb,
    /// Its diameter.
    pub diameter: f64,
}

/// Voxel coordinates packed 21 bits per axis. Coordinates far apart may share a key; that only
/// puts more bodies in a cell, which the callers' exact gap test filters, so results never change.
type Key = u64;

#[inline]
fn pack(x: i64, y: i64, z: i64) -> Key {
    const M: i64 = (1 << 21) - 1;
    ((x & M) as u64) | (((y & M) as u64) << 21) | (((z & M) as u64) << 42)
}

/// Voxel hash with edge length CSize = DLimit + GLimit.
#[derive(Debug)]
pub struct VoxelHash {
    origin: P3,
    inv_csize: f64,
    slots: HashMap<Key, u32, foldhash::fast::FixedState>,
    cells: Vec<Vec<Rec>>,
    free: Vec<u32>,
}

impl VoxelHash {
    /// An empty hash; [`VoxelHash::reset`] sets its cell size.
    pub fn new(origin: P3) -> VoxelHash {
        VoxelHash {
            origin,
            inv_csize: 1.0,
            slots: HashMap::with_hasher(foldhash::fast::FixedState::with_seed(0)),
            cells: Vec::new(),
            free: Vec::new(),
        }
    }

    /// Empties the hash (keeping allocations) and sets the voxel edge to `csize`.
    pub fn reset(&mut self, csize: f64) {
        self.inv_csize = 1.0 / csize;
        self.free.clear();
        for (i, c) in self.cells.iter_mut().enumerate() {
            c.clear();
            self.free.push(i as u32);
        }
        self.slots.clear();
    }

    #[inline]
    fn coords(&self, p: &P3) -> [i64; 3] {
        let f = |k: usize| ((p[k] - self.origin[k]) * self.inv_csize).floor() as i64;
        [f(0), f(1), f(2)]
    }

    #[inline]
    fn key(&self, p: &P3) -> Key {
        let [x, y, z] = self.coords(p);
        pack(x, y, z)
    }

    /// Adds a body by the centre of its box.
    pub fn insert(&mut self, rec: Rec) {
        let key = self.key(&rec.aabb.center());
        let slot = match self.slots.get(&key) {
            Some(&s) => s,
            None => {
                let s = match self.free.pop() {
                    Some(s) => s,
                    None => {
                        self.cells.push(Vec::new());
                        (self.cells.len() - 1) as u32
                    }
                };
                self.slots.insert(key, s);
                s
            }
        };
        self.cells[slot as usize].push(rec);
    }

    /// Removes body `id` whose box is `aabb` (as inserted).
    pub fn remove(&mut self, id: u32, aabb: &Aabb) {
        let key = self.key(&aabb.center());
        if let Some(&s) = self.slots.get(&key) {
            let cell = &mut self.cells[s as usize];
            if let Some(i) = cell.iter().position(|r| r.id == id) {
                cell.swap_remove(i);
            }
        }
    }

    /// Calls `f` for every body stored in a voxel that overlaps the box `[lo, hi]`, so every
    /// body whose centre lies in the box is visited (and some others).
    ///
    /// The grouping's query boxes are at most 2·CSize wide, so this visits at most the 27
    /// voxels around the querying body's centre that step 3 names, and usually far fewer.
    #[inline]
    pub fn for_each_in_box(&self, lo: &P3, hi: &P3, mut f: impl FnMut(&Rec)) {
        let (a, b) = (self.coords(lo), self.coords(hi));
        for x in a[0]..=b[0] {
            for y in a[1]..=b[1] {
                for z in a[2]..=b[2] {
                    if let Some(&s) = self.slots.get(&pack(x, y, z)) {
                        for r in &self.cells[s as usize] {
                            f(r);
                        }
                    }
                }
            }
        }
    }
}
