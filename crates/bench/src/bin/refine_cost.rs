//! What the refinement costs and buys, on the targets scenes: each variant's refinement time
//! over an obvhs PLOC build timed in the same process (both on the default rayon pool), and the
//! SAH and node tests per query (AABB BVs, standard workload) of grouping + that refinement
//! over the best peer's (the lower of parry Binned and obvhs PLOC + reinsertion, as
//! `wraptree bench`). How the refinement's defaults were chosen (`docs/benchmarks.md`).
//!
//! `cargo run --release -p wraptree-bench --bin refine_cost [MAX_SOUP] [REPEAT] [VARIANT ...]` — default
//! 100000, 3 and the default refinement; `scene=NAME` arguments keep only those scenes. A
//! variant is `T:K:P:B[:G[:E[:after]]]`: T treelet passes of K leaves rooted at the nodes of at
//! least G leaves on every E-th height (defaults: [`Tuning::default`]'s; G = 0 is γ by the
//! scene's size, [`Tuning::gamma`]), then P reinsertion passes of first batch B (`after`: the
//! treelet passes after them); `default` is the defaults.

use std::time::Instant;
use wraptree::grouping::{Params, SubsetTree, group};
use wraptree::metrics::bench::target_scenes;
use wraptree::metrics::{compare::query_values, sah};
use wraptree::peers::{self, Method};
use wraptree::query::{self, Bv, Workload};
use wraptree::refine::{RefineParams, Tuning, refine_tuned};

type Variant = (RefineParams, Tuning);

fn parse(s: &str) -> anyhow::Result<Variant> {
    let (mut p, mut t) = (RefineParams::default(), Tuning::default());
    if s == "default" {
        return Ok((p, t));
    }
    let v: Vec<&str> = s.split(':').collect();
    anyhow::ensure!(
        (4..=7).contains(&v.len()),
        "variant '{s}' is not T:K:P:B[:G[:E[:after]]]"
    );
    p.treelet_passes = v[0].parse()?;
    p.treelet = v[1].parse()?;
    p.passes = v[2].parse()?;
    p.batch = v[3].parse()?;
    if let Some(g) = v.get(4) {
        t.treelet_min = g.parse()?;
    }
    if let Some(e) = v.get(5) {
        t.treelet_every = e.parse()?;
    }
    if let Some(a) = v.get(6) {
        t.treelet_after = *a == "after";
    }
    p.check().map_err(anyhow::Error::msg)?;
    Ok((p, t))
}

fn name((p, t): &Variant) -> String {
    format!(
        "{}:{}:{}:{}:{}:{}{}",
        p.treelet_passes,
        p.treelet,
        p.passes,
        p.batch,
        t.treelet_min,
        t.treelet_every,
        if t.treelet_after { ":after" } else { "" }
    )
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let max_soup = args.first().map_or(Ok(100_000), |a| a.parse())?;
    let repeat: u32 = args.get(1).map_or(Ok(3), |a| a.parse())?;
    let only: Vec<&str> = args
        .iter()
        .filter_map(|a| a.strip_prefix("scene="))
        .collect();
    let mut variants = args
        .iter()
        .skip(2)
        .filter(|a| !a.starts_with("scene="))
        .map(|a| parse(a))
        .collect::<anyhow::Result<Vec<_>>>()?;
    if variants.is_empty() {
        variants.push((RefineParams::default(), Tuning::default()));
    }
    print!("{:<18} {:>8} {:>9}", "scene", "N", "PLOC ms");
    for p in &variants {
        print!(" | {:>17} {:>6} {:>6}", name(p), "SAH", "qry");
    }
    println!(
        "\n{:<37}{}",
        "",
        " | ref/PLOC SAH/best qry/best".repeat(variants.len())
    );
    let mut sums = vec![(0.0, 0.0, 0.0, 0.0f64, 0.0f64, 0.0f64); variants.len()];
    let mut scenes = target_scenes(max_soup)?;
    if !only.is_empty() {
        scenes.retain(|s| only.contains(&s.name.as_str()));
    }
    for scene in &scenes {
        let workload = Workload::standard(scene, 1);
        let quality = |tree: &SubsetTree| {
            let q = query::measure(tree, scene, Bv::Aabb, &workload);
            (sah(tree), query_values(&q)[6])
        };
        let build = |m| peers::build(m, scene, &Params::default()).map_err(anyhow::Error::msg);
        let (sb, qb) = quality(&build(Method::PARRY_BINNED)?.tree);
        let (so, qo) = quality(&build(Method::OBVHS_PLOC_REINSERT)?.tree);
        let (s_best, q_best) = (sb.min(so), qb.min(qo));
        let tree = group(scene, &Params::default(), ()).tree;
        // Rounds of one PLOC build and one run of every variant, so that a busy spell of the
        // shared machine weighs on all of them; the best time of each is kept.
        let mut ploc = f64::INFINITY;
        let mut times = vec![f64::INFINITY; variants.len()];
        let mut trees = vec![None; variants.len()];
        for _ in 0..repeat.max(1) {
            ploc = ploc.min(build(Method::OBVHS_PLOC)?.seconds);
            for ((p, tu), (t, out)) in variants.iter().zip(times.iter_mut().zip(&mut trees)) {
                let start = Instant::now();
                let r = refine_tuned(&tree, p, tu, ());
                *t = t.min(start.elapsed().as_secs_f64());
                *out = Some(r.tree);
            }
        }
        print!("{:<18} {:>8} {:>9.2}", scene.name, scene.len(), ploc * 1e3);
        for ((t, out), sum) in times.iter().zip(&trees).zip(&mut sums) {
            let (s, q) = quality(out.as_ref().expect("ran once"));
            let (rt, rs, rq) = (t / ploc, s / s_best, q / q_best);
            print!(" | {rt:>8.2} {:>8.3} {:>6.3}", rs, rq);
            sum.0 += rt;
            sum.1 += rs;
            sum.2 += rq;
            sum.3 = sum.3.max(rt);
            sum.4 = sum.4.max(rs);
            sum.5 = sum.5.max(rq);
        }
        println!();
    }
    let k = scenes.len() as f64;
    print!("{:<37}", "mean");
    for s in &sums {
        print!(" | {:>8.2} {:>8.3} {:>6.3}", s.0 / k, s.1 / k, s.2 / k);
    }
    print!("\n{:<37}", "worst");
    for s in &sums {
        print!(" | {:>8.2} {:>8.3} {:>6.3}", s.3, s.4, s.5);
    }
    println!();
    Ok(())
}
