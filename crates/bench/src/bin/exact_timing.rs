//! Time the exact grouping schedule alone against obvhs PLOC on scene files, one rayon pool per
//! thread count, and print a hash of each tree (the same for every thread count). The times are
//! the best of the repeats: wall time for both, and the grouping thread's CPU time (steadier on
//! a shared machine; the PLOC CPU column includes converting its boxes and tree). With `STATS`
//! set, the work counters go to stderr.
//!
//! `cargo run --release -p wraptree-bench --bin exact_timing -- [--threads 1,2] [--repeat 5] FILE...`

use std::hash::{Hash, Hasher};
use std::path::Path;
use std::time::Instant;
use wraptree::grouping::{Params, group_boxes};
use wraptree::peers::{Method, build};
use wraptree::scene::{LoadOptions, load_path};

/// CPU time of the calling thread, in seconds.
fn cpu() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: a valid clock id and a valid pointer.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn main() -> anyhow::Result<()> {
    let mut threads = vec![1usize];
    let mut repeat = 5usize;
    let mut files = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--threads" => {
                let v = args.next().unwrap_or_default();
                threads = v.split(',').map(str::parse).collect::<Result<_, _>>()?;
            }
            "--repeat" => repeat = args.next().unwrap_or_default().parse()?,
            _ => files.push(a),
        }
    }
    println!(
        "| scene | N | threads | exact ms | PLOC ms | ratio | exact CPU ms | PLOC CPU ms | CPU ratio | tree hash |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for f in &files {
        let scene = load_path(Path::new(f), &LoadOptions::default())?.scene;
        let n = scene.len();
        let boxes: Vec<_> = (0..n).map(|i| scene.prim_aabb(i)).collect();
        let params = Params::default();
        for &t in &threads {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build()?;
            let (best, ploc, hash, best_cpu, ploc_cpu) =
                pool.install(|| -> anyhow::Result<(f64, f64, u64, f64, f64)> {
                    let mut best = f64::INFINITY;
                    let mut ploc = f64::INFINITY;
                    let (mut best_cpu, mut ploc_cpu) = (f64::INFINITY, f64::INFINITY);
                    let mut hash = 0;
                    let mut stats = None;
                    for _ in 0..repeat {
                        let mut b = Vec::with_capacity(2 * n - 1);
                        b.extend_from_slice(&boxes);
                        let (t0, c0) = (Instant::now(), cpu());
                        let resolved = params.resolve_boxes(&b);
                        let g = group_boxes(b, &resolved, ());
                        best = best.min(t0.elapsed().as_secs_f64());
                        best_cpu = best_cpu.min(cpu() - c0);
                        let mut h = std::collections::hash_map::DefaultHasher::new();
                        g.tree.parent_i64().hash(&mut h);
                        hash = h.finish();
                        stats = Some((g.stats, g.rounds));
                        let c0 = cpu();
                        let p = build(Method::OBVHS_PLOC, &scene, &params)
                            .map_err(anyhow::Error::msg)?;
                        ploc = ploc.min(p.seconds);
                        ploc_cpu = ploc_cpu.min(cpu() - c0);
                    }
                    if std::env::var_os("STATS").is_some() {
                        eprintln!("{}: {:?}", scene.name, stats);
                    }
                    Ok((best, ploc, hash, best_cpu, ploc_cpu))
                })?;
            println!(
                "| {} | {n} | {t} | {:.3} | {:.3} | {:.2} | {:.3} | {:.3} | {:.2} | {hash:016x} |",
                scene.name,
                best * 1e3,
                ploc * 1e3,
                best / ploc,
                best_cpu * 1e3,
                ploc_cpu * 1e3,
                best_cpu / ploc_cpu
            );
        }
    }
    Ok(())
}
