//! The measurements: the exact and the partitioned grouping beside obvhs PLOC, each in a rayon
//! pool of 1 and 2 threads, with the partitioned tree's quality against the exact tree's and
//! the builds' peak memory.

use anyhow::{Result, anyhow};
use wraptree::grouping::{Params, Schedule};
use wraptree::metrics::bench::{RecordCost, record_cost};
use wraptree::metrics::timing::fastest;
use wraptree::metrics::{compare, peak_rss_bytes, sah};
use wraptree::peers::Method;
use wraptree::query::{self, Bv, Workload};
use wraptree::record::Detail;
use wraptree::scene::Scene;
use wraptree::scene::spec::as_loaded;
use wraptree::stop::Stop;

/// Thread counts of the table.
pub const THREADS: [usize; 2] = [1, 2];

/// Above this many primitives the exact schedule is left out (minutes per run).
pub const EXACT_MAX_N: usize = 1_000_000;

/// One builder on one scene and thread count.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Case {
    /// Best build time of the repetitions (s).
    pub seconds: f64,
    /// SAH of the best build's tree (NaN when quality was not measured).
    pub sah: f64,
    /// Node tests per query of that tree (AABB BVs, standard workload; NaN when not measured).
    pub tests: f64,
    /// Peak resident memory of the builds in bytes: since a reset before them when the
    /// kernel supports it (Linux `clear_refs`), else the process's peak.
    pub peak_bytes: u64,
}

/// One scene of the table; arrays are indexed like [`THREADS`].
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Scene name.
    pub scene: String,
    /// Primitives.
    pub n: usize,
    /// The exact schedule (none above [`EXACT_MAX_N`]); quality on 1 thread only.
    pub exact: [Option<Case>; 2],
    /// The partitioned schedule; quality on 1 thread only, up to [`EXACT_MAX_N`].
    pub partitioned: [Case; 2],
    /// obvhs PLOC (its `parallel` build); no quality.
    pub ploc: [Case; 2],
}

impl Row {
    /// Partitioned time / PLOC time on `THREADS[t]` threads.
    pub fn per_ploc(&self, t: usize) -> f64 {
        self.partitioned[t].seconds / self.ploc[t].seconds
    }

    /// The partitioned tree's SAH / the exact tree's (1 thread), if the exact one ran.
    pub fn sah_ratio(&self) -> Option<f64> {
        self.exact[0].map(|e| self.partitioned[0].sah / e.sah)
    }

    /// The partitioned tree's node tests per query / the exact tree's, if the exact one ran.
    pub fn query_ratio(&self) -> Option<f64> {
        self.exact[0].map(|e| self.partitioned[0].tests / e.tests)
    }

    /// Partitioned time on 1 thread per primitive (ns).
    pub fn ns_per_primitive(&self) -> f64 {
        self.partitioned[0].seconds * 1e9 / self.n.max(1) as f64
    }
}

/// Resets the process's peak resident memory (Linux `clear_refs` 5) to what is in use now:
/// first the allocator hands back the free memory it keeps (glibc `malloc_trim`), so that the
/// cases measured later do not start from the freed memory of those before. False if
/// unsupported.
fn reset_peak() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only returns free memory to the system.
    unsafe {
        libc::malloc_trim(0);
    }
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// Best of `repeat` builds of `m` on `threads` threads ([`fastest`]), with its tree's quality if
/// `quality`.
fn measure(
    m: Method,
    scene: &Scene,
    threads: usize,
    repeat: u32,
    workload: &Workload,
    quality: bool,
) -> Result<Case> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| anyhow!("building a {threads}-thread pool: {e}"))?;
    reset_peak();
    let built = pool.install(|| fastest(&[m], scene, &Params::default(), repeat, &Stop::new()))?;
    let peak_bytes = peak_rss_bytes().unwrap_or(0);
    let b = &built[0];
    let (sah, tests) = if quality {
        let q = query::measure(&b.tree, scene, Bv::Aabb, workload);
        (sah(&b.tree), compare::query_values(&q)[6])
    } else {
        (f64::NAN, f64::NAN)
    };
    Ok(Case {
        seconds: b.seconds,
        sah,
        tests,
        peak_bytes,
    })
}

/// Measures one scene: `repeat` timed builds per case (at most 2 from 10^6 primitives).
pub fn row(scene: &Scene, repeat: u32) -> Result<Row> {
    let n = scene.len();
    let repeat = if n >= 1_000_000 {
        repeat.min(2)
    } else {
        repeat
    };
    let workload = Workload::standard(scene, 1);
    let each = |m: Method, quality: bool| -> Result<[Case; 2]> {
        let c1 = measure(m, scene, THREADS[0], repeat, &workload, quality)?;
        let c2 = measure(m, scene, THREADS[1], repeat, &workload, false)?;
        Ok([c1, c2])
    };
    let exact = if n <= EXACT_MAX_N {
        let [a, b] = each(Method::GROUPING, true)?;
        [Some(a), Some(b)]
    } else {
        [None, None]
    };
    Ok(Row {
        scene: scene.name.clone(),
        n,
        exact,
        // Quality only where the exact tree is there to compare with.
        partitioned: each(Method::GROUPING_PARTITIONED, n <= EXACT_MAX_N)?,
        ploc: each(Method::OBVHS_PLOC, false)?,
    })
}

/// The scene size whose recording the table measures ([`record_row`]).
pub const RECORD_N: usize = 1_000_000;

/// What `wraptree record --schedule partitioned --detail merges` costs on `scene` in a
/// 1-thread pool: `repeat` pairs, at least 3 and at most 5 (so that the median means
/// something on a noisy machine), of the grouping alone and the recorded run (both files, into
/// a temporary directory; the scene attached as its OBJ text, as for a file).
pub fn record_row(scene: &Scene, repeat: u32) -> Result<RecordCost> {
    let loaded = as_loaded(scene)?;
    let mut params = Params::default();
    params.mode.schedule = Schedule::PARTITIONED;
    let dir = tempfile::tempdir()?;
    let prefix = dir.path().join("partitioned");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| anyhow!("building a 1-thread pool: {e}"))?;
    pool.install(|| {
        record_cost(
            &loaded,
            &params,
            Detail::Merges,
            &prefix,
            repeat.clamp(3, 5),
        )
    })
}
