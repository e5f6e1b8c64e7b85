//! The rows of one per-merge plot that the `.rrd` keeps: every merge's row while a run's merges
//! fit in [`ROWS_MAX`] rows, else, per bucket of consecutive merges, the bucket's first row and
//! the rows of each scalar's smallest and largest value. The plot then keeps every peak and dip
//! a viewer draws when the whole run is on screen, in a bounded number of rows; the `.mcap`
//! keeps every merge.

/// The most rows one plot's entity gets in a run.
pub(super) const ROWS_MAX: usize = 1 << 14;

/// One plot's rows: those kept and not sent yet, and the open bucket.
#[derive(Debug, Default)]
pub(super) struct Envelope {
    /// Scalars per row.
    scalars: usize,
    /// Merges per bucket; 1 keeps every row.
    bucket: usize,
    /// Merge ticks and scalars of the open bucket's rows.
    open_ticks: Vec<i64>,
    open: Vec<f64>,
    /// Merge ticks and scalars of the rows kept, not sent yet.
    ticks: Vec<i64>,
    values: Vec<f64>,
}

impl Envelope {
    /// The rows of a plot with `scalars` scalars per row in a run of at most `merges` merges.
    pub(super) fn new(scalars: usize, merges: usize) -> Envelope {
        Envelope {
            scalars,
            bucket: bucket_size(merges, scalars),
            ..Envelope::default()
        }
    }

    /// Adds the row of merge `tick`: `values` holds its `scalars` scalars.
    pub(super) fn push(&mut self, tick: i64, values: &[f64]) {
        debug_assert_eq!(values.len(), self.scalars);
        if self.bucket <= 1 {
            self.ticks.push(tick);
            self.values.extend_from_slice(values);
            return;
        }
        self.open_ticks.push(tick);
        self.open.extend_from_slice(values);
        if self.open_ticks.len() == self.bucket {
            self.close();
        }
    }

    /// Keeps the open bucket's first row and each scalar's smallest and largest (the first
    /// such row on ties; NaN never counts), in merge order.
    pub(super) fn close(&mut self) {
        let rows = self.open_ticks.len();
        if rows == 0 {
            return;
        }
        let s = self.scalars;
        let mut keep = vec![0usize];
        for j in 0..s {
            let value = |r: usize| self.open[r * s + j];
            let (mut lo, mut hi) = (None::<usize>, None::<usize>);
            for r in (0..rows).filter(|&r| !value(r).is_nan()) {
                if lo.is_none_or(|l| value(r) < value(l)) {
                    lo = Some(r);
                }
                if hi.is_none_or(|h| value(r) > value(h)) {
                    hi = Some(r);
                }
            }
            keep.extend(lo.into_iter().chain(hi));
        }
        keep.sort_unstable();
        keep.dedup();
        for r in keep {
            self.ticks.push(self.open_ticks[r]);
            self.values
                .extend_from_slice(&self.open[r * s..(r + 1) * s]);
        }
        self.open_ticks.clear();
        self.open.clear();
    }

    /// Moves the rows kept so far to an envelope of their own, leaving the open bucket here.
    pub(super) fn split_off(&mut self) -> Envelope {
        let (ticks, values) = self.take();
        Envelope {
            scalars: self.scalars,
            bucket: 1,
            ticks,
            values,
            ..Envelope::default()
        }
    }

    /// Scalars per row.
    pub(super) fn scalars(&self) -> usize {
        self.scalars
    }

    /// Takes the rows kept so far: their merge ticks and scalars, row after row.
    pub(super) fn take(&mut self) -> (Vec<i64>, Vec<f64>) {
        (
            std::mem::take(&mut self.ticks),
            std::mem::take(&mut self.values),
        )
    }
}

/// The fewest merges per bucket that keep a plot of `scalars` scalars per row within
/// [`ROWS_MAX`] rows over `merges` merges (a bucket keeps at most `1 + 2 × scalars` rows).
fn bucket_size(merges: usize, scalars: usize) -> usize {
    if merges <= ROWS_MAX {
        return 1;
    }
    let per_bucket = 1 + 2 * scalars;
    (per_bucket + 1..)
        .find(|&k| merges.div_ceil(k) * per_bucket.min(k) <= ROWS_MAX)
        .unwrap_or(merges)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(e: &mut Envelope) -> (Vec<i64>, Vec<f64>) {
        e.close();
        e.take()
    }

    #[test]
    fn every_row_is_kept_while_the_run_fits() {
        let mut e = Envelope::new(2, ROWS_MAX);
        for t in 0..ROWS_MAX as i64 {
            e.push(t, &[t as f64, -(t as f64)]);
        }
        let (ticks, values) = rows(&mut e);
        assert_eq!(ticks, (0..ROWS_MAX as i64).collect::<Vec<_>>());
        assert_eq!(values.len(), 2 * ROWS_MAX);
    }

    #[test]
    fn a_long_run_keeps_each_buckets_extremes_within_the_bound() {
        for scalars in [1, 2, 3] {
            let merges = 10 * ROWS_MAX + 7;
            let mut e = Envelope::new(scalars, merges);
            let value = |t: i64, j: usize| ((t * 7919 + j as i64 * 104_729) % 1_000_003) as f64;
            let spike = 123_457_i64;
            let mut sent = (Vec::new(), Vec::new());
            for t in 0..merges as i64 {
                let v: Vec<f64> = (0..scalars)
                    .map(|j| if t == spike { 1e12 } else { value(t, j) })
                    .collect();
                e.push(t, &v);
                if t % 4096 == 4095 {
                    let (a, b) = e.take();
                    sent.0.extend(a);
                    sent.1.extend(b);
                }
            }
            let (a, b) = rows(&mut e);
            sent.0.extend(a);
            sent.1.extend(b);
            let (ticks, values) = sent;
            assert!(ticks.len() <= ROWS_MAX, "{scalars}: {} rows", ticks.len());
            assert!(
                ticks.len() > ROWS_MAX / 2,
                "{scalars}: {} rows",
                ticks.len()
            );
            assert!(ticks.windows(2).all(|w| w[0] < w[1]), "merge order");
            assert_eq!(ticks[0], 0, "the first row");
            assert!(ticks.contains(&spike), "the peak");
            let max = values.iter().copied().fold(f64::MIN, f64::max);
            assert_eq!(max, 1e12);
            // Every kept row holds the scalars its merge had.
            for (r, &t) in ticks.iter().enumerate() {
                for j in 0..scalars {
                    let want = if t == spike { 1e12 } else { value(t, j) };
                    assert_eq!(values[r * scalars + j], want);
                }
            }
        }
    }

    #[test]
    fn nan_rows_are_not_extremes() {
        let mut e = Envelope::new(1, 100 * ROWS_MAX);
        let k = e.bucket;
        for t in 0..k as i64 {
            e.push(t, &[if t == 1 { f64::NAN } else { t as f64 }]);
        }
        let (ticks, _) = e.take();
        assert_eq!(ticks, vec![0, k as i64 - 1]);
    }
}
