//! Where the partitioned tree's SAH differs from the exact tree's: the interior boxes' areas
//! (over the root box's) summed by the size of each node's leaf set, 2^k to 2^(k+1) − 1
//! leaves, for the exact schedule and the default partitioned schedule, one thread
//! (a variant study; its table is in the git history of `docs/benchmarks.md`).
//!
//! `cargo run --release -p wraptree-bench --bin partitioned_levels -- FILE...`

use wraptree::geom::area;
use wraptree::grouping::partitioned::{Chunking, group_with};
use wraptree::grouping::{Budget, Params, SubsetTree, group};

/// Σ area(interior node) / area(root), by ⌊log2(leaves below)⌋.
fn by_size(t: &SubsetTree) -> Vec<f64> {
    let n = t.leaves();
    let mut leaves = vec![1u32; t.len()];
    let mut sums = vec![0.0; 33];
    for x in n..t.len() {
        let [a, b] = t.children_of(x as u32).expect("an interior node");
        leaves[x] = leaves[a as usize] + leaves[b as usize];
        sums[leaves[x].ilog2() as usize] += area(&t.aabb[x]);
    }
    let root = area(&t.aabb[t.root() as usize]);
    sums.iter().map(|s| s / root).collect()
}

fn main() -> anyhow::Result<()> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    for path in std::env::args().skip(1) {
        let scene = wraptree::scene::load_path(path.as_ref(), &Default::default())?.scene;
        let exact = pool.install(|| group(&scene, &Params::default(), ()));
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
        let (e, p) = (by_size(&exact.tree), by_size(&part.tree));
        println!("{} ({} primitives)", scene.name, scene.len());
        println!("| leaves below | exact | partitioned | difference |\n|---|---|---|---|");
        for k in (1..e.len()).filter(|&k| e[k] > 0.0 || p[k] > 0.0) {
            let (lo, hi) = (1u64 << k, (1u64 << (k + 1)) - 1);
            println!(
                "| {lo}–{hi} | {:.2} | {:.2} | {:+.2} |",
                e[k],
                p[k],
                p[k] - e[k]
            );
        }
        let (se, sp): (f64, f64) = (e.iter().sum(), p.iter().sum());
        println!(
            "| all | {se:.2} | {sp:.2} | {:+.2} ({:+.1} %) |\n",
            sp - se,
            (sp / se - 1.0) * 100.0
        );
    }
    Ok(())
}
