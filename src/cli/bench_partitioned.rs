//! The targets table's second part: the partitioned schedule beside the exact one and obvhs
//! PLOC, each on 1 and 2 threads, with quality and peak memory.

use anyhow::{Result, anyhow};
use wraptree::grouping::Params;
use wraptree::metrics;
use wraptree::peers::{self, Method};
use wraptree::query::{self, Bv, Workload};
use wraptree::scene::Scene;

/// Thread counts of the table.
const THREADS: [usize; 2] = [1, 2];

/// Above this many primitives the exact schedule is left out (minutes per run).
const EXACT_MAX_N: usize = 1_000_000;

/// Resets the process's peak resident memory (Linux `clear_refs` 5); false if unsupported.
fn reset_peak() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// Peak resident memory in MB since the last [`reset_peak`].
fn peak_mb() -> f64 {
    wraptree::metrics::peak_rss_bytes().unwrap_or(0) as f64 / 1e6
}

/// Best time of `repeat` builds of `m` on `threads` threads, its tree's SAH and node tests per
/// query, and the peak memory of the builds in MB (relative to the process's resident memory
/// before them when the peak can be reset, else the process peak).
struct Case {
    seconds: f64,
    sah: f64,
    tests: f64,
    peak: f64,
}

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
    let params = Params::default();
    reset_peak();
    let mut best: Option<peers::Built> = None;
    for _ in 0..repeat.max(1) {
        let b = pool
            .install(|| peers::build(m, scene, &params))
            .map_err(|e| anyhow!(e))?;
        if best.as_ref().is_none_or(|x| b.seconds < x.seconds) {
            best = Some(b);
        }
    }
    let peak = peak_mb();
    let b = best.expect("ran at least once");
    let (sah, tests) = if quality {
        let q = query::measure(&b.tree, scene, Bv::Aabb, workload);
        (
            metrics::sah(&b.tree),
            wraptree::metrics::compare::query_values(&q)[6],
        )
    } else {
        (f64::NAN, f64::NAN)
    };
    Ok(Case {
        seconds: b.seconds,
        sah,
        tests,
        peak,
    })
}

/// Prints the table for `cases` (`repeat` timed builds each, fewer from 10^6 primitives).
pub(super) fn print_table(cases: &[Scene], repeat: u32) -> Result<()> {
    println!();
    println!(
        "{:<18} {:>8} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>6} {:>6} {:>7} {:>7} {:>7} {:>7} {:>7}",
        "scene",
        "N",
        "exact 1t",
        "exact 2t",
        "part 1t",
        "part 2t",
        "PLOC 1t",
        "PLOC 2t",
        "p/P 1t",
        "p/P 2t",
        "SAH p/e",
        "qry p/e",
        "ns/prim",
        "MB ex",
        "MB part"
    );
    for scene in cases {
        let n = scene.len();
        let repeat = if n >= 1_000_000 {
            repeat.min(2)
        } else {
            repeat
        };
        let workload = Workload::standard(scene, 1);
        let exact: Vec<Option<Case>> = THREADS
            .iter()
            .map(|&t| {
                (n <= EXACT_MAX_N)
                    .then(|| measure(Method::Grouping, scene, t, repeat, &workload, t == 1))
                    .transpose()
            })
            .collect::<Result<_>>()?;
        let part: Vec<Case> = THREADS
            .iter()
            .map(|&t| {
                measure(
                    Method::GroupingPartitioned,
                    scene,
                    t,
                    repeat,
                    &workload,
                    t == 1,
                )
            })
            .collect::<Result<_>>()?;
        let ploc: Vec<Case> = THREADS
            .iter()
            .map(|&t| measure(Method::ObvhsPloc, scene, t, repeat, &workload, false))
            .collect::<Result<_>>()?;
        let ms =
            |c: Option<&Case>| c.map_or("-".to_string(), |c| format!("{:.2}", c.seconds * 1e3));
        let e1 = exact[0].as_ref();
        let ratio = |f: fn(&Case) -> f64| {
            e1.map_or("-".to_string(), |e| format!("{:.3}", f(&part[0]) / f(e)))
        };
        println!(
            "{:<18} {:>8} {:>9} {:>9} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>6.2} {:>6.2} {:>7} {:>7} {:>7.0} {:>7} {:>7.0}",
            scene.name,
            n,
            ms(e1),
            ms(exact[1].as_ref()),
            part[0].seconds * 1e3,
            part[1].seconds * 1e3,
            ploc[0].seconds * 1e3,
            ploc[1].seconds * 1e3,
            part[0].seconds / ploc[0].seconds,
            part[1].seconds / ploc[1].seconds,
            ratio(|c| c.sah),
            ratio(|c| c.tests),
            part[0].seconds * 1e9 / n as f64,
            e1.map_or("-".to_string(), |e| format!("{:.0}", e.peak)),
            part[0].peak,
        );
    }
    println!(
        "exact/part/PLOC = best build ms of the exact grouping, the partitioned grouping and obvhs"
    );
    println!(
        "PLOC (its `parallel` build) in a rayon pool of 1 or 2 threads (1t, 2t); p/P = part / PLOC."
    );
    println!(
        "SAH p/e, qry p/e = SAH and node tests per query (AABB BVs) of the partitioned tree / the"
    );
    println!(
        "exact tree's. ns/prim = part 1t per primitive. MB = peak RSS during the 1-thread builds"
    );
    println!(
        "(peak reset before each; exact left out above 10^6). Goals: p/P 1t <= 1.5, p/P 2t <= 1,"
    );
    println!("SAH and qry p/e <= 1.02.");
    Ok(())
}
