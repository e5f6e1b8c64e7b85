//! The top-down split: its parameters ([`Chunking`]), the Morton order of the primitives and the
//! tree of chunks over it.

use crate::geom::Aabb;
use crate::grouping::cluster::spread_bits;
use rayon::prelude::*;

/// The split's parameters: chunk size δ, the reduction function's ε (AAC §3) and the root's share.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chunking {
    /// Ranges of fewer primitives than this are chunks.
    pub delta: u32,
    /// f(n) = ⌈c·n^(1/2 − ε)⌉ with c = δ^(1/2 + ε)/2.
    pub epsilon: f64,
    /// A node of n of the N primitives keeps at least ⌈top·n/N⌉ bodies, so the root's
    /// subproblem (the exact schedule's step) starts from about `top` bodies; 0 = AAC's f alone.
    pub top: u32,
}

impl Chunking {
    /// AAC's fast setting, δ = 4, ε = 0.2, with a root step of about 8,192 bodies: on the
    /// bench scenes (README) this root share brought the trees' SAH and node tests per query
    /// to within 2 % of the exact schedule's on all but two of them (worst 3.7 %, against 6 %
    /// with 4,096 and 13 % without it) for 1.6 % more instructions at 10^6 than 4,096; scenes
    /// of at most 8,192 primitives get the exact schedule's tree.
    pub const DEFAULT: Chunking = Chunking {
        delta: 4,
        epsilon: 0.2,
        top: 8192,
    };

    /// The bodies a node of `n` primitives leaves for the level above: f(n), at least 1.
    pub fn keep(&self, n: u32) -> u32 {
        let d = self.delta as f64;
        let c = d.powf(0.5 + self.epsilon) / 2.0;
        ((c * (n as f64).powf(0.5 - self.epsilon)).ceil() as u32).max(1)
    }
}

impl Default for Chunking {
    fn default() -> Self {
        Chunking::DEFAULT
    }
}

/// A node of the split, in post-order.
#[derive(Clone, Copy, Debug)]
pub(super) struct Node {
    /// Range of the Morton-sorted primitives.
    pub(super) lo: u32,
    pub(super) hi: u32,
    /// The two halves (node indices), or none for a chunk.
    pub(super) kids: Option<(u32, u32)>,
    /// Depth (0 = the root).
    pub(super) level: u32,
    /// Bodies the node's own subproblem starts from.
    pub(super) inputs: u32,
    /// Bodies it leaves (1 at the root).
    pub(super) keep: u32,
    /// Step of its own first merge.
    pub(super) own_step: u32,
}

/// Below this many primitives f(n) comes from a table (most nodes are small).
const TABLED: usize = 4096;

/// What a node may keep: AAC's reduction function f (from a table for small arguments), and at
/// least ⌈top·n/N⌉ for a node of n primitives.
struct Keep {
    chunking: Chunking,
    small: Vec<u32>,
    n: u64,
}

impl Keep {
    fn new(chunking: &Chunking, n: usize) -> Keep {
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
    fn at(&self, f_of: u32, size: u32) -> u32 {
        let f = match self.small.get(f_of as usize) {
            Some(&f) => f,
            None => self.chunking.keep(f_of),
        };
        let share = (u64::from(self.chunking.top) * u64::from(size)).div_ceil(self.n.max(1));
        f.max(share.min(u64::from(u32::MAX)) as u32)
    }
}

/// The split of `codes` (sorted) into chunks, nodes in post-order.
pub(super) fn plan(codes: &[(u64, u32)], chunking: &Chunking) -> Vec<Node> {
    fn build(
        codes: &[(u64, u32)],
        keep: &Keep,
        lo: u32,
        hi: u32,
        level: u32,
        first_step: u32,
        nodes: &mut Vec<Node>,
    ) -> u32 {
        let size = hi - lo;
        let top = level == 0;
        let ch = &keep.chunking;
        let node = if size < ch.delta.max(2) {
            Node {
                lo,
                hi,
                kids: None,
                level,
                inputs: size,
                keep: if top {
                    1
                } else {
                    size.min(keep.at(ch.delta, size))
                },
                own_step: first_step,
            }
        } else {
            let (a, b) = (codes[lo as usize].0, codes[hi as usize - 1].0);
            let mid = if a == b {
                lo + size / 2
            } else {
                let bit = 63 - (a ^ b).leading_zeros();
                let part = &codes[lo as usize..hi as usize];
                lo + part.partition_point(|c| c.0 >> bit & 1 == 0) as u32
            };
            let l = build(codes, keep, lo, mid, level + 1, first_step, nodes);
            let kl = nodes[l as usize].keep;
            let r_first = first_step + (mid - lo - kl);
            let r = build(codes, keep, mid, hi, level + 1, r_first, nodes);
            let kr = nodes[r as usize].keep;
            let inputs = kl + kr;
            Node {
                lo,
                hi,
                kids: Some((l, r)),
                level,
                inputs,
                keep: if top {
                    1
                } else {
                    inputs.min(keep.at(size, size))
                },
                own_step: r_first + (hi - mid - kr),
            }
        };
        nodes.push(node);
        nodes.len() as u32 - 1
    }
    let mut nodes = Vec::with_capacity(codes.len() / 2 + 1);
    let keep = Keep::new(chunking, codes.len());
    build(codes, &keep, 0, codes.len() as u32, 0, 0, &mut nodes);
    nodes
}

/// The primitives' ids sorted by the Morton code of their box centres (ties by id).
pub(super) fn morton_order(boxes: &[Aabb]) -> Vec<(u64, u32)> {
    let cb = boxes.iter().fold(Aabb::EMPTY, |b, x| b.grow(&x.center()));
    let ext = cb.extents();
    let scale = [0, 1, 2].map(|k| {
        if ext[k] > 0.0 && ext[k].is_finite() {
            2_097_151.0 / ext[k]
        } else {
            0.0
        }
    });
    let mut codes: Vec<(u64, u32)> = boxes
        .par_iter()
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
    codes.par_sort_unstable();
    codes
}
