//! Whether the partitioned tree's distance from the exact tree comes from its bottom clusters:
//! the exact schedule run until only a share of the bodies is left (its first merges, the same
//! as the unlimited run's), then the default partitioned schedule on the bodies left, from the
//! scene's own DLimit0 and GLimit0. Prints, per scene and share, the spliced tree's SAH and node
//! tests per query over the exact tree's, and what each stage took of the exact run's time, one
//! thread (a variant study; its table is in the git history of `docs/benchmarks.md`).
//!
//! `cargo run --release -p wraptree-bench --bin exact_prefix -- SHARES FILE...` — SHARES as `0.5,0.25`.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;
use wraptree::geom::Aabb;
use wraptree::grouping::partitioned::{Chunking, group_with};
use wraptree::grouping::{
    Budget, Event, Observer, Params, Schedule, SubsetTree, group, group_boxes, group_within,
};
use wraptree::metrics::{compare::query_values, sah};
use wraptree::query::{self, Bv, Workload};
use wraptree::scene::Scene;

/// Records the merges and raises `stop` once `count` were made.
struct FirstMerges<'a> {
    count: usize,
    stop: &'a AtomicBool,
    merges: Vec<(u32, u32, Aabb, f64)>,
}

impl Observer for FirstMerges<'_> {
    fn on_event(&mut self, e: &Event<'_>) {
        if let Event::Merge(m) = e {
            self.merges.push((m.a, m.b, m.aabb, m.diameter));
            if self.merges.len() >= self.count {
                self.stop.store(true, Ordering::Relaxed);
            }
        }
    }
}

/// The exact schedule's first merges until about `share` × N bodies are left, then the
/// partitioned schedule over the bodies left, spliced into one tree; with the two stages' times.
fn spliced(scene: &Scene, share: f64) -> anyhow::Result<(SubsetTree, f64, f64)> {
    let n = scene.len();
    let params = Params::default().resolve(scene);
    let stop = AtomicBool::new(false);
    let mut first = FirstMerges {
        count: n - ((n as f64 * share) as usize).max(2),
        stop: &stop,
        merges: Vec::new(),
    };
    let budget = Budget {
        stop: Some(&stop),
        deadline: None,
        max_pairs: None,
    };
    let t = Instant::now();
    // Stopped by the observer: what counts is the merges it saw.
    let _ = group_within(scene, &params, &mut first, &budget);
    let t_prefix = t.elapsed().as_secs_f64();
    let prefix = first.merges;
    let mut boxes: Vec<Aabb> = (0..n).map(|i| scene.prim_aabb(i)).collect();
    let leaf_diameter: Vec<f64> = boxes.iter().map(Aabb::diameter).collect();
    let mut merged = vec![false; n + prefix.len()];
    for &(a, b, bx, _) in &prefix {
        merged[a as usize] = true;
        merged[b as usize] = true;
        boxes.push(bx);
    }
    let left: Vec<u32> = (0..merged.len() as u32)
        .filter(|&x| !merged[x as usize])
        .collect();
    let mut rest = params;
    rest.mode.schedule = Schedule::PARTITIONED;
    let t = Instant::now();
    let top = group_boxes(left.iter().map(|&x| boxes[x as usize]).collect(), &rest, ()).tree;
    let t_rest = t.elapsed().as_secs_f64();
    // The second tree's leaves are the bodies left; its interior nodes follow the prefix's.
    let id = |x: u32| match left.get(x as usize) {
        Some(&body) => body,
        None => (merged.len() + x as usize - left.len()) as u32,
    };
    let mut merges = prefix;
    for x in top.leaves()..top.len() {
        let [a, b] = top.children_of(x as u32).expect("an interior node");
        merges.push((id(a), id(b), top.aabb[x], top.diameter[x]));
    }
    boxes.truncate(n);
    let tree =
        SubsetTree::from_merges(boxes, leaf_diameter, &merges).map_err(anyhow::Error::msg)?;
    Ok((tree, t_prefix, t_rest))
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let shares: Vec<f64> = args
        .next()
        .unwrap_or_default()
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    print!("| scene | N | partitioned SAH / tests |");
    for s in &shares {
        print!(" {s} left: SAH / tests | exact prefix, rest (× exact time) |");
    }
    println!();
    println!("|---|---|---|{}", "---|---|".repeat(shares.len()));
    for path in args {
        let scene = wraptree::scene::load_path(path.as_ref(), &Default::default())?.scene;
        let workload = Workload::standard(&scene, 1);
        let quality = |t: &SubsetTree| {
            let q = query::measure(t, &scene, Bv::Aabb, &workload);
            (sah(t), query_values(&q)[6])
        };
        let t = Instant::now();
        let exact = pool.install(|| group(&scene, &Params::default(), ())).tree;
        let t_exact = t.elapsed().as_secs_f64();
        let (se, qe) = quality(&exact);
        let params = Params::default().resolve(&scene);
        let part = pool
            .install(|| {
                group_with(
                    &scene,
                    &params,
                    &Chunking {
                        delta: Chunking::LARGE_DELTA,
                        ..Chunking::DEFAULT
                    },
                    (),
                    &Budget::default(),
                )
            })
            .map_err(|s| anyhow::anyhow!("stopped: {:?}", s.reason))?;
        let (sp, qp) = quality(&part.tree);
        print!(
            "| {} | {} | {:.3} / {:.3} |",
            scene.name,
            scene.len(),
            sp / se,
            qp / qe
        );
        for &share in &shares {
            let (tree, t_prefix, t_rest) = pool.install(|| spliced(&scene, share))?;
            let (s, q) = quality(&tree);
            print!(
                " {:.3} / {:.3} | {:.2}, {:.2} |",
                s / se,
                q / qe,
                t_prefix / t_exact,
                t_rest / t_exact
            );
        }
        println!();
    }
    Ok(())
}
