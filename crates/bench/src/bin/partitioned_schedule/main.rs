//! The partitioned schedule against the exact one and obvhs PLOC: the exact and the partitioned
//! grouping and PLOC in rayon pools of 1 and 2 threads, the partitioned tree's SAH and node
//! tests per query over the exact tree's, the builds' peak memory, and what recording the
//! 10^6-triangle soup with the partitioned schedule costs (`docs/benchmarks.md`, "The
//! partitioned schedule").
//!
//! `cargo run --release -p wraptree-bench --bin partitioned_schedule -- [--repeat 3]
//! [--max-soup 1000000] [SCENE...]` — SCENEs are files or generated scenes (`soup:100000`);
//! without them the targets scenes of `wraptree bench` (and a 10^7 soup with
//! `--max-soup 10000000`).

mod measure;
mod report;

use anyhow::{Context, Result};
use measure::{RECORD_N, record_row, row};
use report::{partitioned_header, partitioned_line, partitioned_notes, partitioned_record_line};
use wraptree::metrics::bench::target_scenes;
use wraptree::scene::spec::scene_spec;
use wraptree::scene::{Scene, generate};

/// Measures and prints a row per scene (`repeat` timed builds each, fewer from 10^6
/// primitives), then what recording the scene of [`RECORD_N`] primitives costs, if there is
/// one.
fn print_table(cases: &[Scene], repeat: u32) -> Result<()> {
    print!("{}", partitioned_header());
    for scene in cases {
        print!("{}", partitioned_line(&row(scene, repeat)?));
    }
    print!("{}", partitioned_notes());
    if let Some(scene) = cases.iter().find(|s| s.len() == RECORD_N) {
        let cost = record_row(scene, repeat)?;
        print!(
            "{}",
            partitioned_record_line(&scene.name, scene.len(), &cost)
        );
    }
    Ok(())
}

fn main() -> Result<()> {
    let (mut repeat, mut max_soup, mut specs) = (3u32, 1_000_000usize, Vec::new());
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = |flag: &str| args.next().with_context(|| format!("{flag} needs a value"));
        match a.as_str() {
            "--repeat" => repeat = value("--repeat")?.parse()?,
            "--max-soup" => max_soup = value("--max-soup")?.parse()?,
            _ => specs.push(a),
        }
    }
    let cases = if specs.is_empty() {
        let mut cases = target_scenes(max_soup)?;
        if max_soup >= 10_000_000 {
            cases.push(generate::soup(10_000_000, 1));
        }
        cases
    } else {
        let mut cases = Vec::new();
        for spec in &specs {
            let (scene, warnings) = scene_spec(spec)?;
            for w in &warnings {
                eprintln!("warning: {w}");
            }
            cases.push(scene);
        }
        cases
    };
    print_table(&cases, repeat)
}
