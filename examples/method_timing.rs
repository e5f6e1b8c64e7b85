//! Time bench methods on scene files against obvhs PLOC, best of the repeats (run in rounds of
//! every peer and method in turn, so that the machine's slow spells fall on all alike), in one
//! rayon pool of the given size, with the refinement's share, and their SAH and node tests per
//! query of the standard workload against the best of parry Binned, obvhs PLOC and PLOC +
//! reinsertion (all queries, and the point and distance queries alone); with `LOOP=SECONDS` set
//! it instead builds the first method on the first file over and over for that long (a target
//! for `perf`).
//!
//! With `MIRROR=1` every method's tree (the peers' too) is measured a second time with each
//! node's two children swapped, and a second table gives both node tests: the queries that
//! stop at their first touching pair depend on which child is visited first, the others not.
//!
//! The fast path's settings can be varied through the environment: `TOP`, `SAH`, `EPS`, `MAX`
//! (its split: root share, SAH-cut size, ε, largest chunk) and `PASSES`, `BATCH` (its reinsertion passes).
//!
//! `cargo run --release --example method_timing -- [--threads 1] [--repeat 5]
//! [--methods fast,grouping] FILE...`

use std::path::Path;
use std::time::Instant;
use wraptree::grouping::{Params, group_boxes, sah};
use wraptree::metrics::compare::query_values;
use wraptree::peers::{Built, Method, build};
use wraptree::query::{Bv, Workload, measure};
use wraptree::refine;
use wraptree::scene::{LoadOptions, Scene, load_path};

/// The environment variable `name` parsed, if set.
fn env<T: std::str::FromStr>(name: &str) -> Option<T> {
    std::env::var(name).ok().and_then(|s| s.parse().ok())
}

/// `method` built, the fast path with the settings the environment varies.
fn build_varied(method: Method, scene: &Scene, params: &Params) -> Built {
    if method != Method::Fast {
        return build(method, scene, params).expect("built");
    }
    let mut p = params.clone();
    p.mode = p.mode.fast();
    p.mode.chunk_top = env("TOP").unwrap_or(p.mode.chunk_top);
    p.mode.chunk_sah = env("SAH").unwrap_or(p.mode.chunk_sah);
    p.mode.chunk_epsilon = env("EPS").unwrap_or(p.mode.chunk_epsilon);
    p.mode.chunk_max = env("MAX").unwrap_or(p.mode.chunk_max);
    let mut rp = refine::fast_for(scene.len());
    rp.passes = env("PASSES").unwrap_or(rp.passes);
    rp.batch = env("BATCH").unwrap_or(rp.batch);
    let n = scene.len();
    let mut boxes = Vec::with_capacity(2 * n - 1);
    boxes.extend((0..n).map(|i| scene.prim_aabb(i)));
    let t = Instant::now();
    let resolved = p.resolve_boxes(&boxes);
    let g = group_boxes(boxes, &resolved, ());
    let t1 = Instant::now();
    let r = refine::refine_owned(g.tree, &rp, ());
    Built {
        method,
        tree: r.tree,
        seconds: t.elapsed().as_secs_f64(),
        stats: Some(g.stats),
        refine_seconds: t1.elapsed().as_secs_f64(),
    }
}

fn main() -> anyhow::Result<()> {
    let mut threads = 1usize;
    let mut repeat = 5usize;
    let mut methods = vec![Method::Fast];
    let mut files = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--threads" => threads = args.next().unwrap_or_default().parse()?,
            "--repeat" => repeat = args.next().unwrap_or_default().parse()?,
            "--methods" => {
                methods = args
                    .next()
                    .unwrap_or_default()
                    .split(',')
                    .map(Method::parse)
                    .collect::<Result<_, _>>()
                    .map_err(anyhow::Error::msg)?;
            }
            _ => files.push(a),
        }
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let params = Params::default();
    if let Some(secs) = std::env::var("LOOP")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
    {
        let scene = load_path(Path::new(&files[0]), &LoadOptions::default())?.scene;
        let t = Instant::now();
        let mut runs = 0u64;
        pool.install(|| {
            while t.elapsed().as_secs_f64() < secs {
                build_varied(methods[0], &scene, &params);
                runs += 1;
            }
        });
        println!("{runs} runs, {:.3} ms each", secs * 1e3 / runs as f64);
        return Ok(());
    }
    println!(
        "| scene | N | PLOC ms | method | ms (refine) | / PLOC | SAH / best peer | node tests / best peer | without overlap queries |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let peers = [
        Method::ParryBinned,
        Method::ObvhsPloc,
        Method::ObvhsPlocReinsert,
    ];
    let mut mirrored_rows = Vec::new();
    for f in &files {
        let scene = load_path(Path::new(f), &LoadOptions::default())?.scene;
        let workload = Workload::standard(&scene, 1);
        // The repeats in rounds, each building every peer and method once in turn, so that a
        // slow spell of the machine falls on all of them alike; each keeps its fastest build.
        let all: Vec<Method> = peers.iter().chain(&methods).copied().collect();
        let mut fastest: Vec<Option<Built>> = vec![None; all.len()];
        pool.install(|| {
            for _ in 0..repeat {
                for (slot, &m) in fastest.iter_mut().zip(&all) {
                    let b = build_varied(m, &scene, &params);
                    if slot.as_ref().is_none_or(|x| b.seconds < x.seconds) {
                        *slot = Some(b);
                    }
                }
            }
        });
        // Each fastest build's time, refinement share, SAH and node tests per query.
        let mirror = env::<u32>("MIRROR") == Some(1);
        let mut mirrored = Vec::new();
        let mut measured = |b: Built| -> (f64, f64, f64, f64, f64) {
            let q = measure(&b.tree, &scene, Bv::Aabb, &workload);
            let v = query_values(&q);
            let queries = (workload.points.len() + workload.poses_near.len()) as f64;
            let far = (v[0] * workload.points.len() as f64
                + v[2] * workload.poses_near.len() as f64)
                / queries;
            if mirror {
                let mut t = b.tree.clone();
                t.children.iter_mut().for_each(|k| k.swap(0, 1));
                let w = query_values(&measure(&t, &scene, Bv::Aabb, &workload));
                mirrored.push((scene.name.clone(), b.method.name(), v[6], w[6], far));
            }
            (b.seconds, b.refine_seconds, sah(&b.tree), v[6], far)
        };
        let rows: Vec<_> = fastest
            .into_iter()
            .map(|b| measured(b.expect("at least one repeat")))
            .collect();
        let (peer, ours) = rows.split_at(peers.len());
        let ploc = peer[1].0;
        let best_sah = peer.iter().map(|p| p.2).fold(f64::INFINITY, f64::min);
        let best_tests = peer.iter().map(|p| p.3).fold(f64::INFINITY, f64::min);
        let best_far = peer.iter().map(|p| p.4).fold(f64::INFINITY, f64::min);
        for (&m, &(s, r, q, t, f)) in methods.iter().zip(ours) {
            println!(
                "| {} | {} | {:.3} | {} | {:.3} ({:.3}) | {:.2} | {:.3} | {:.3} | {:.3} |",
                scene.name,
                scene.len(),
                ploc * 1e3,
                m.name(),
                s * 1e3,
                r * 1e3,
                s / ploc,
                q / best_sah,
                t / best_tests,
                f / best_far
            );
        }
        mirrored_rows.append(&mut mirrored);
    }
    if !mirrored_rows.is_empty() {
        println!();
        println!(
            "| scene | method | node tests | children swapped | swapped / stored | point and distance queries |"
        );
        println!("|---|---|---|---|---|---|");
        for (name, m, a, b, far) in &mirrored_rows {
            println!(
                "| {name} | {m} | {a:.1} | {b:.1} | {:.3} | {far:.1} |",
                b / a
            );
        }
    }
    Ok(())
}
