//! The sort of the Morton codes: one parallel pass scatters the (code, id) pairs into buckets by
//! their top [`BUCKET_BITS`] bits, then the buckets, each small enough for the cache, are sorted
//! apart in parallel (scattered once more by the next [`INNER_BITS`] bits, the few pairs of
//! each run then by insertion). The pairs are distinct (ids differ), so the order is the one
//! any sort gives, whatever the number of threads. `par_sort_unstable` partitions the whole
//! array on one thread first, which this avoids. Fewer pairs, from [`LSD_MIN`], are sorted by
//! least-significant digit first ([`lsd`]: linear in the pairs, faster than a comparison sort
//! there), the fewest by comparison.

use rayon::prelude::*;

/// Bits of the code that pick a bucket.
const BUCKET_BITS: u32 = 10;

/// Below this many pairs the buckets are not worth their passes.
const MIN_LEN: usize = 1 << 16;

/// From this many pairs (below [`MIN_LEN`]) the sort is [`lsd`]; below, its passes over the
/// digit counts cost more than a comparison sort.
const LSD_MIN: usize = 4096;

/// Pairs per block of the histogram and the scatter (the unit of parallel work).
const BLOCK: usize = 1 << 15;

/// A destination the scatter's blocks write to at disjoint places.
#[derive(Clone, Copy)]
struct Dest(*mut (u64, u32));

// SAFETY: every block writes only its own places (see `sorted`).
unsafe impl Send for Dest {}
unsafe impl Sync for Dest {}

impl Dest {
    /// Writes `pair` at place `i`.
    ///
    /// # Safety
    /// `i` is within the destination, and no other thread reads or writes place `i`.
    #[inline]
    unsafe fn write(self, i: usize, pair: (u64, u32)) {
        // SAFETY: as the caller promises.
        unsafe { self.0.add(i).write(pair) }
    }
}

/// `codes` in increasing order; every code is below 2^`key_bits` (`key_bits` ≥ [`BUCKET_BITS`]).
pub(super) fn sorted(mut codes: Vec<(u64, u32)>, key_bits: u32) -> Vec<(u64, u32)> {
    let n = codes.len();
    if n < MIN_LEN {
        if n >= LSD_MIN {
            return lsd(codes, key_bits);
        }
        if rayon::current_num_threads() == 1 {
            codes.sort_unstable();
        } else {
            codes.par_sort_unstable();
        }
        return codes;
    }
    let shift = key_bits - BUCKET_BITS;
    let buckets = 1usize << BUCKET_BITS;
    let bucket = |code: u64| ((code >> shift) as usize).min(buckets - 1);
    let counts: Vec<Vec<u32>> = codes
        .par_chunks(BLOCK)
        .map(|block| {
            let mut h = vec![0u32; buckets];
            for &(code, _) in block {
                h[bucket(code)] += 1;
            }
            h
        })
        .collect();
    // Block i's pairs of bucket j go after those of every lower bucket and of blocks before i.
    let mut starts = vec![vec![0usize; buckets]; counts.len()];
    let mut ends = Vec::with_capacity(buckets);
    let mut at = 0usize;
    for j in 0..buckets {
        for (s, h) in starts.iter_mut().zip(&counts) {
            s[j] = at;
            at += h[j] as usize;
        }
        ends.push(at);
    }
    let mut out: Vec<(u64, u32)> = Vec::with_capacity(n);
    let dest = Dest(out.as_mut_ptr());
    codes
        .par_chunks(BLOCK)
        .zip(starts.into_par_iter())
        .for_each(|(block, mut next)| {
            for &pair in block {
                let j = bucket(pair.0);
                // SAFETY: `next[j]` runs through this block's places of bucket j, which no
                // other block writes and which lie below `n` (the counts add up to `n`).
                unsafe { dest.write(next[j], pair) };
                next[j] += 1;
            }
        });
    // SAFETY: the places of all blocks and buckets cover `0..n`, each written once above.
    unsafe { out.set_len(n) };
    drop(codes);
    let mut slices = Vec::with_capacity(buckets);
    let mut rest = &mut out[..];
    let mut lo = 0;
    for &end in &ends {
        let (s, r) = std::mem::take(&mut rest).split_at_mut(end - lo);
        slices.push(s);
        rest = r;
        lo = end;
    }
    let inner = shift.saturating_sub(INNER_BITS);
    slices.into_par_iter().for_each_init(Vec::new, |tmp, s| {
        if s.len() >= MIN_LEN {
            // Most of a scene in one bucket (a dense spot): sorted on every thread.
            s.par_sort_unstable();
        } else {
            sort_bucket(s, inner, tmp);
        }
    });
    out
}

/// Bits of the code per pass of [`lsd`].
const DIGIT: u32 = 11;

/// `codes` sorted by least-significant digit first, [`DIGIT`] bits per pass over the
/// `key_bits` of the codes (every pass's digit counts taken in one read first; a pass whose
/// digit is the same for every pair is skipped). The passes are stable, so equal codes keep
/// their input order; a last pass puts such runs in id order.
fn lsd(codes: Vec<(u64, u32)>, key_bits: u32) -> Vec<(u64, u32)> {
    const R: usize = 1 << DIGIT;
    let n = codes.len();
    let passes = key_bits.div_ceil(DIGIT) as usize;
    let mut counts = vec![[0usize; R]; passes];
    for &(code, _) in &codes {
        for (p, h) in counts.iter_mut().enumerate() {
            h[(code >> (p as u32 * DIGIT)) as usize & (R - 1)] += 1;
        }
    }
    let (mut from, mut to) = (codes, vec![(0u64, 0u32); n]);
    for (p, h) in counts.iter().enumerate() {
        if h.contains(&n) {
            continue;
        }
        let mut next = starts(h);
        let shift = p as u32 * DIGIT;
        scatter(&from, &mut to, &mut next, |code| {
            (code >> shift) as usize & (R - 1)
        });
        std::mem::swap(&mut from, &mut to);
    }
    for run in from.chunk_by_mut(|a, b| a.0 == b.0) {
        if run.len() > 1 {
            run.sort_unstable();
        }
    }
    from
}

/// Bits of the code below the bucket's that split a bucket once more.
const INNER_BITS: u32 = 8;

/// Sorts one bucket: scattered by the [`INNER_BITS`] bits above bit `shift` of the codes into
/// `tmp`, each of those runs (a few pairs) then sorted by comparison.
fn sort_bucket(s: &mut [(u64, u32)], shift: u32, tmp: &mut Vec<(u64, u32)>) {
    if s.len() <= 64 {
        s.sort_unstable();
        return;
    }
    let mask = (1usize << INNER_BITS) - 1;
    let digit = |code: u64| (code >> shift) as usize & mask;
    let mut counts = [0usize; 1 << INNER_BITS];
    for &(code, _) in s.iter() {
        counts[digit(code)] += 1;
    }
    let begin = starts(&counts);
    let mut next = begin;
    tmp.clear();
    tmp.resize(s.len(), (0, 0));
    scatter(s, tmp, &mut next, digit);
    s.copy_from_slice(tmp);
    for (&lo, &hi) in begin.iter().zip(&next) {
        match hi - lo {
            0 | 1 => {}
            k if k <= INSERTION => insertion_sort(&mut s[lo..hi]),
            // A dense spot of the scene (one run holding most of a bucket): no quadratic sort.
            _ => s[lo..hi].sort_unstable(),
        }
    }
}

/// Where each digit's pairs start, from the digits' counts.
fn starts<const R: usize>(counts: &[usize; R]) -> [usize; R] {
    let mut at = 0;
    counts.map(|k| {
        at += k;
        at - k
    })
}

/// Moves `from` into `to` by `digit` of their codes, keeping their order within a digit:
/// digit d's pairs go from `next[d]` on, and `next[d]` ends past them.
#[inline]
fn scatter(
    from: &[(u64, u32)],
    to: &mut [(u64, u32)],
    next: &mut [usize],
    digit: impl Fn(u64) -> usize,
) {
    for &pair in from {
        let d = digit(pair.0);
        to[next[d]] = pair;
        next[d] += 1;
    }
}

/// Runs of at most this many pairs are sorted by insertion.
const INSERTION: usize = 16;

/// Sorts a few pairs (a run of one bucket's second digit) in place.
#[inline]
fn insertion_sort(s: &mut [(u64, u32)]) {
    for i in 1..s.len() {
        let x = s[i];
        let mut j = i;
        while j > 0 && s[j - 1] > x {
            s[j] = s[j - 1];
            j -= 1;
        }
        s[j] = x;
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// `n` pairs in id order with codes from a few clustered values (many ties) and random
    /// ones.
    pub(in crate::grouping::partitioned) fn codes(n: usize, seed: u64) -> Vec<(u64, u32)> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        (0..n as u32)
            .map(|i| {
                let code = if rng.random_bool(0.3) {
                    rng.random_range(0..4u64) << 40
                } else {
                    rng.random::<u64>() >> 1
                };
                (code, i)
            })
            .collect()
    }

    #[test]
    fn the_bucket_sort_gives_the_comparison_sorts_order_on_any_thread_count() {
        // Clustered codes (many in one bucket, ties broken by id) and spread ones.
        let mut codes = codes(3 * MIN_LEN + 5, 11);
        // A dense spot: a fifth of the pairs share their top 18 bits, in falling order; and
        // the next two fifths one bucket.
        let dense = codes.len() / 5;
        for (k, c) in codes.iter_mut().take(dense).enumerate() {
            c.0 = (5 << 45) | (dense - k) as u64;
        }
        for (k, c) in codes.iter_mut().skip(dense).take(2 * dense).enumerate() {
            c.0 = (9 << 53) | ((k * 7919) as u64 % (1 << 53));
        }
        let mut want = codes.clone();
        want.sort_unstable();
        for t in [1, 2, 3] {
            let got = rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .unwrap()
                .install(|| sorted(codes.clone(), 63));
            assert_eq!(got, want, "{t} threads");
        }
        // Sizes sorted by digits and by comparison, the pairs not in id order and with ties.
        for len in [LSD_MIN - 1, LSD_MIN, 20_000] {
            let mut part: Vec<(u64, u32)> = codes[..len].iter().rev().copied().collect();
            for (k, c) in part.iter_mut().enumerate().step_by(3) {
                c.0 = (k as u64 % 97) << 40;
            }
            let mut want = part.clone();
            want.sort_unstable();
            assert_eq!(sorted(part, 63), want, "{len} pairs");
        }
        let small: Vec<(u64, u32)> = codes[..100].to_vec();
        let mut want = small.clone();
        want.sort_unstable();
        assert_eq!(sorted(small, 63), want);
    }
}
