//! The partitioned schedule's chunking against the exact schedule's tree, on the targets
//! scenes: SAH and node tests per query (AABB BVs, standard workload; all queries, and the
//! point and distance queries alone) of each chunking's tree over the exact tree's, and its
//! grouping time on one thread. How the defaults were chosen
//! (`docs/benchmarks.md`, "How close is the partitioned schedule to the exact tree, and how fast?").
//!
//! `cargo run --release -p wraptree-bench --bin partitioned_chunking [MAX_SOUP] [DELTA:EPSILON[:TOP[:SAH]] ...]
//! [FILE ...]` — default 100000 and the default chunking and 20:0.1 (AAC's high-quality
//! setting); δ = 0 is the default's δ by the scene's size (`Chunking::for_size`); scene files are grouped after the targets scenes (held-out scenes). `THREADS=T` runs
//! every build in a pool of T threads instead of one.

use std::time::Instant;
use wraptree::grouping::partitioned::{Chunking, group_with};
use wraptree::grouping::{Budget, Params, SubsetTree, group};
use wraptree::metrics::bench::target_scenes;
use wraptree::metrics::{compare::query_values, sah};
use wraptree::query::{self, Bv, Workload};

fn parse(s: &str) -> anyhow::Result<Chunking> {
    let v: Vec<&str> = s.split(':').collect();
    let mut ch = Chunking::DEFAULT;
    ch.delta = v[0].parse()?;
    ch.epsilon = v.get(1).map_or(Ok(ch.epsilon), |e| e.parse())?;
    ch.top = v.get(2).map_or(Ok(ch.top), |e| e.parse())?;
    ch.sah_below = v.get(3).map_or(Ok(ch.sah_below), |e| e.parse())?;
    Ok(ch)
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let max_soup = args.first().map_or(Ok(100_000), |a| a.parse())?;
    let mut chunkings = args
        .iter()
        .skip(1)
        .filter(|a| !std::path::Path::new(a).is_file())
        .map(|a| parse(a))
        .collect::<anyhow::Result<Vec<_>>>()?;
    if chunkings.is_empty() {
        chunkings = vec![parse("0")?, parse("20:0.1")?];
    }
    let threads = std::env::var("THREADS")
        .ok()
        .and_then(|t| t.parse().ok())
        .unwrap_or(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let budget = Budget::default();
    print!("{:<18} {:>8} {:>9}", "scene", "N", "exact ms");
    for ch in &chunkings {
        let name = format!("{}:{}:{}:{}", ch.delta, ch.epsilon, ch.top, ch.sah_below);
        print!(" | {name:>17} {:>6} {:>6} {:>6}", "SAH", "qry", "far");
    }
    println!();
    let mut sums = vec![(0.0, 0.0, 0.0, 0.0); chunkings.len()];
    let mut scenes = target_scenes(max_soup)?;
    for path in args.iter().filter(|a| std::path::Path::new(a).is_file()) {
        scenes.push(wraptree::scene::load_path(path.as_ref(), &Default::default())?.scene);
    }
    for scene in &scenes {
        let workload = Workload::standard(scene, 1);
        let quality = |tree: &SubsetTree| {
            let q = query::measure(tree, scene, Bv::Aabb, &workload);
            let v = query_values(&q);
            let (points, near) = (workload.points.len(), workload.poses_near.len());
            let far = (v[0] * points as f64 + v[2] * near as f64) / (points + near) as f64;
            (sah(tree), v[6], far)
        };
        let t = Instant::now();
        let exact = pool.install(|| group(scene, &Params::default(), ()));
        let te = t.elapsed().as_secs_f64();
        let (se, qe, fe) = quality(&exact.tree);
        print!("{:<18} {:>8} {:>9.2}", scene.name, scene.len(), te * 1e3);
        let params = Params::default().resolve(scene);
        for (ch, sum) in chunkings.iter().zip(&mut sums) {
            let ch = &ch.for_size(scene.len());
            let t = Instant::now();
            let g = pool
                .install(|| group_with(scene, &params, ch, (), &budget))
                .map_err(|s| anyhow::anyhow!("stopped: {:?}", s.reason))?;
            let tp = t.elapsed().as_secs_f64();
            let (sp, qp, fp) = quality(&g.tree);
            print!(
                " | {:>14.2} ms {:>6.3} {:>6.3} {:>6.3}",
                tp * 1e3,
                sp / se,
                qp / qe,
                fp / fe
            );
            sum.0 += tp / te;
            sum.1 += sp / se;
            sum.2 += qp / qe;
            sum.3 = f64::max(sum.3, (sp / se).max(qp / qe));
        }
        println!();
    }
    let k = scenes.len() as f64;
    print!("{:<18} {:>8} {:>9}", "mean (time/exact)", "", "");
    for s in &sums {
        print!(" | {:>17.3} {:>6.3} {:>6.3}", s.0 / k, s.1 / k, s.2 / k);
    }
    println!();
    print!("{:<18} {:>8} {:>9}", "worst ratio", "", "");
    for s in &sums {
        print!(" | {:>17} {:>13.3}", "", s.3);
    }
    println!();
    Ok(())
}
