//! What a node of the split keeps for the level above: AAC's reduction function and the root's
//! share.

use super::chunking::Chunking;

/// Below this many primitives f(n) comes from a table (most nodes are small).
const TABLED: usize = 4096;

/// What a node may keep: AAC's reduction function f (from a table for small arguments), and at
/// least ⌈top·n/N⌉ for a node of n primitives; and which nodes pass all their bodies up.
///
/// Two halves' shares, rounded up, can exceed their parent's by one, so a node above the share's
/// size would make a merge or two, each a voxel-hash round over thousands of bodies when it
/// has more than [`brute_force::MAX_BODIES`](super::brute_force::MAX_BODIES) of them. Such a node passes its bodies
/// up, and the root makes those merges. (Shares that add up exactly, as differences of one
/// rounded-down prefix, push merges into the smallest nodes above f and cost tree quality.)
pub(super) struct Keep {
    pub(super) chunking: Chunking,
    small: Vec<u32>,
    n: u64,
}

impl Keep {
    /// The keeps of a split of `n` primitives with `chunking`.
    pub(super) fn new(chunking: &Chunking, n: usize) -> Keep {
        let small = (0..TABLED.min(n + 1))
            .map(|k| chunking.keep(k as u32))
            .collect();
        Keep {
            chunking: *chunking,
            small,
            n: n as u64,
        }
    }

    /// max(f(`f_of`), ⌈top·`size`/N⌉).
    #[inline]
    pub(super) fn at(&self, f_of: u32, size: u32) -> u32 {
        self.f(f_of).max(self.share(size))
    }

    /// f(`n`).
    #[inline]
    fn f(&self, n: u32) -> u32 {
        match self.small.get(n as usize) {
            Some(&f) => f,
            None => self.chunking.keep(n),
        }
    }

    /// ⌈top·`size`/N⌉.
    #[inline]
    fn share(&self, size: u32) -> u32 {
        let share = (u64::from(self.chunking.top) * u64::from(size)).div_ceil(self.n.max(1));
        share.min(u64::from(u32::MAX)) as u32
    }

    /// Whether a node of `size` primitives and `inputs` bodies passes them all up: more than
    /// [`brute_force::MAX_BODIES`](super::brute_force::MAX_BODIES) bodies, and a share above f(`size`).
    pub(super) fn passes(&self, size: u32, inputs: u32) -> bool {
        inputs as usize > super::brute_force::MAX_BODIES && self.share(size) > self.f(size)
    }
}
