//! The limits of the rounds of a subproblem: DLimit0 and GLimit0 doubled once per round, as in
//! the exact run, and the first round in which a size fits them.

/// A round that never comes (NaN sizes).
pub(super) const NO_ROUND: u32 = u32::MAX;

/// The limits of every round: `tab[r]` = `base` doubled `r` times, up to the first infinity.
pub(super) struct RoundLimits {
    tab: Vec<f64>,
}

impl RoundLimits {
    /// The doubling sequence of `base` (> 0).
    pub(super) fn new(base: f64) -> RoundLimits {
        let bits = base.to_bits();
        let exp = (bits >> 52) & 0x7ff;
        if base > 0.0 && exp != 0 && exp != 0x7ff {
            // A positive normal base: each doubling adds one to the exponent field, exactly,
            // until it would reach 2047 (infinity). Independent entries, not a chain of
            // multiplications: the table has up to 2,047 of them, built for every run.
            let last = 0x7ff - exp;
            let tab = (0..=last)
                .map(|r| {
                    if r < last {
                        f64::from_bits(bits + (r << 52))
                    } else {
                        f64::INFINITY
                    }
                })
                .collect();
            return RoundLimits { tab };
        }
        let mut tab = vec![base];
        let mut v = base;
        while v < f64::INFINITY && tab.len() < 4096 {
            v *= 2.0;
            tab.push(v);
        }
        RoundLimits { tab }
    }

    /// The number of rounds before the limit is infinite (the last one's is).
    #[cfg(test)]
    pub(super) fn rounds(&self) -> usize {
        self.tab.len()
    }

    /// The limit of round `r`.
    #[inline]
    pub(super) fn at(&self, r: u32) -> f64 {
        self.tab[(r as usize).min(self.tab.len() - 1)]
    }

    /// The first round whose limit is ≥ `x` ([`NO_ROUND`] for NaN).
    #[inline]
    pub(super) fn first(&self, x: f64) -> u32 {
        let t = &self.tab;
        if x <= t[0] {
            return 0;
        }
        if x.is_nan() {
            return NO_ROUND;
        }
        let last = t.len() - 1;
        // t[r] = t[0]·2^r exactly, so for normal numbers the answer is the difference of the
        // binary exponents, plus one when x's mantissa is the larger (no branch to mispredict);
        // the steps below then do nothing, and fix subnormal limits and the infinite end.
        let (bx, b0) = (x.to_bits(), t[0].to_bits());
        let e = |b: u64| ((b >> 52) & 0x7ff) as i64;
        let frac = |b: u64| b & ((1 << 52) - 1);
        let r = e(bx) - e(b0) + i64::from(frac(bx) > frac(b0));
        let mut r = r.clamp(0, last as i64) as usize;
        while r < last && t[r] < x {
            r += 1;
        }
        while r > 0 && t[r - 1] >= x {
            r -= 1;
        }
        r as u32
    }
}
