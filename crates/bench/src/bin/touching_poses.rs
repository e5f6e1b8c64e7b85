//! Node tests of each touching pose's overlap query (stops at the first touching pair) and
//! contact query (every touching pair), per builder: the fast path, parry Binned, obvhs PLOC
//! and PLOC + reinsertion, AABB BVs, on the touching poses of the standard workloads of seeds
//! 1 to SEEDS (8 each). Then per builder the sums, and each sum over the least of the peers'
//! (a study; its table is in the git history of `docs/benchmarks.md`).
//!
//! `cargo run --release -p wraptree-bench --bin touching_poses -- SEEDS FILE`

use std::path::Path;
use wraptree::grouping::Params;
use wraptree::peers::{Method, build};
use wraptree::query::{Bv, Counts, Hierarchy, Workload, contacts, moved, overlap};
use wraptree::scene::{LoadOptions, load_path};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [seeds, file] = &args[..] else {
        anyhow::bail!("usage: touching_poses SEEDS FILE");
    };
    let seeds: u64 = seeds.parse()?;
    let scene = load_path(Path::new(file), &LoadOptions::default())?.scene;
    let methods = [
        Method::FAST,
        Method::PARRY_BINNED,
        Method::OBVHS_PLOC,
        Method::OBVHS_PLOC_REINSERT,
    ];
    let trees = methods
        .iter()
        .map(|&m| build(m, &scene, &Params::default()).map(|b| b.tree))
        .collect::<Result<Vec<_>, _>>()
        .map_err(anyhow::Error::msg)?;
    let names: Vec<&str> = methods.iter().map(|m| m.name()).collect();
    println!(
        "| seed | pose | overlap: {} | contact: {} |",
        names.join(" | overlap: "),
        names.join(" | contact: ")
    );
    println!("|---|---|{}", "---|".repeat(2 * methods.len()));
    let (mut over, mut cont) = (vec![0u64; methods.len()], vec![0u64; methods.len()]);
    for seed in 1..=seeds {
        let w = Workload::standard(&scene, seed);
        for (i, pose) in w.poses_touching.iter().enumerate() {
            let (mut o, mut c) = (Vec::new(), Vec::new());
            for (k, tree) in trees.iter().enumerate() {
                let h = Hierarchy {
                    tree,
                    scene: &scene,
                    bv: Bv::Aabb,
                };
                let (t, s) = moved(tree, &scene, pose);
                let copy = Hierarchy {
                    tree: &t,
                    scene: &s,
                    bv: Bv::Aabb,
                };
                let (mut a, mut b) = (Counts::default(), Counts::default());
                overlap(&h, &copy, &mut a);
                contacts(&h, &copy, &mut b);
                over[k] += a.bv_tests;
                cont[k] += b.bv_tests;
                o.push(a.bv_tests.to_string());
                c.push(b.bv_tests.to_string());
            }
            println!("| {seed} | {i} | {} | {} |", o.join(" | "), c.join(" | "));
        }
    }
    let row = |sums: &[u64]| {
        let best = *sums[1..].iter().min().expect("three peers") as f64;
        let cells: Vec<String> = sums
            .iter()
            .map(|&x| format!("{x} ({:.3})", x as f64 / best))
            .collect();
        cells.join(" | ")
    };
    println!("| sum (/ best peer) | | {} | {} |", row(&over), row(&cont));
    Ok(())
}
