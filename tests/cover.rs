//! Covers: the tolerance DP and the budget search against brute force over every cut of small
//! random trees with non-monotone errors; the kind choice; covers of a bundled scene against its
//! uniform levels; and the `cover` command's JSON and OBJ.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;
use std::process::Command;
use wraptree::geom::Aabb;
use wraptree::grouping::{Params, SubsetTree, group};
use wraptree::scene::{LoadOptions, load_bytes, load_path};
use wraptree::stop::Stop;
use wraptree::wrap::cover::{
    Candidate, CoverKind, Fits, budget_tolerance, compare_levels, min_cut, query_cost,
};
use wraptree::wrap::{DEFAULT_SAMPLES, SphereMethod, WrapperKind, Wrappers};

/// A random binary tree over `n` leaves (random merge order).
fn random_tree(n: usize, rng: &mut ChaCha8Rng) -> SubsetTree {
    let mut live: Vec<u32> = (0..n as u32).collect();
    let mut merges = Vec::new();
    for i in 0..n - 1 {
        let a = live.swap_remove(rng.random_range(0..live.len()));
        let b = live.swap_remove(rng.random_range(0..live.len()));
        merges.push((a, b, Aabb::EMPTY, 0.0));
        live.push((n + i) as u32);
    }
    SubsetTree::from_merges(vec![Aabb::EMPTY; n], vec![0.0; n], &merges).unwrap()
}

/// Every cut of the subtree of `x`.
fn cuts(tree: &SubsetTree, x: u32) -> Vec<Vec<u32>> {
    let mut out = vec![vec![x]];
    if let Some([a, b]) = tree.children_of(x) {
        let (ca, cb) = (cuts(tree, a), cuts(tree, b));
        for p in &ca {
            for q in &cb {
                out.push(p.iter().chain(q).copied().collect());
            }
        }
    }
    out
}

fn max_err(cut: &[u32], err: &[f64]) -> f64 {
    cut.iter().map(|&x| err[x as usize]).fold(0.0, f64::max)
}

/// Panics unless every leaf has exactly one ancestor-or-self in `cut`.
fn assert_cut(tree: &SubsetTree, cut: &[u32]) {
    let mut hits = vec![0u32; tree.leaves()];
    for &x in cut {
        for l in tree.leaves_under(x) {
            hits[l as usize] += 1;
        }
    }
    assert!(hits.iter().all(|&h| h == 1), "not a cut: {cut:?}");
}

/// Random trees with random (non-monotone) interior errors and leaves at 0.
fn cases() -> Vec<(SubsetTree, Vec<f64>)> {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    (0..40)
        .map(|k| {
            let n = 2 + k % 12;
            let tree = random_tree(n, &mut rng);
            let err = (0..tree.len())
                .map(|x| {
                    if x < n {
                        0.0
                    } else {
                        (rng.random_range(0..8) as f64) * 0.5
                    }
                })
                .collect();
            (tree, err)
        })
        .collect()
}

#[test]
fn tolerance_dp_is_the_smallest_cut_within_t() {
    for (tree, err) in cases() {
        let all = cuts(&tree, tree.root());
        for t in [0.0, 0.25, 0.5, 1.0, 1.7, 2.5, 3.5, 10.0] {
            let cut = min_cut(&tree, &err, t);
            assert_cut(&tree, &cut);
            assert!(max_err(&cut, &err) <= t);
            let best = all
                .iter()
                .filter(|c| max_err(c, &err) <= t)
                .map(Vec::len)
                .min()
                .unwrap();
            assert_eq!(cut.len(), best, "t {t}, err {err:?}");
        }
    }
}

#[test]
fn budget_minimises_the_largest_error() {
    for (tree, err) in cases() {
        let all = cuts(&tree, tree.root());
        assert_eq!(budget_tolerance(&tree, &err, 0), None);
        for k in 1..=tree.leaves() + 1 {
            let t = budget_tolerance(&tree, &err, k).unwrap();
            let cut = min_cut(&tree, &err, t);
            assert_cut(&tree, &cut);
            assert!(cut.len() <= k, "k {k}: {} nodes", cut.len());
            let best = all
                .iter()
                .filter(|c| c.len() <= k)
                .map(|c| max_err(c, &err))
                .fold(f64::INFINITY, f64::min);
            assert_eq!(max_err(&cut, &err), best, "k {k}");
            assert_eq!(t, best, "k {k}");
        }
    }
}

#[test]
fn near_ties_go_to_the_cheaper_kind_within_the_tolerance() {
    let c = |kind, error| Candidate {
        kind,
        error,
        cost: query_cost(kind, 8),
    };
    let node = |s: f64| vec![c(CoverKind::Sphere, s), c(CoverKind::Hull, 1.0)];
    let fits = Fits::from_options(vec![node(1.05), node(1.2), node(1.05)], 0.0);
    assert_eq!(fits.choose(0, 5.0).kind, CoverKind::Sphere);
    assert_eq!(fits.choose(1, 5.0).kind, CoverKind::Hull);
    assert_eq!(fits.choose(2, 1.02).kind, CoverKind::Hull);
    assert!(query_cost(CoverKind::Sphere, 0) < query_cost(CoverKind::Box, 0));
    assert!(query_cost(CoverKind::Box, 0) < query_cost(CoverKind::Obb, 0));
    assert!(query_cost(CoverKind::Obb, 0) < query_cost(CoverKind::Hull, 0));
}

fn scene_path(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

#[test]
fn robot_base_covers_beat_uniform_levels() {
    let scene = load_path(&scene_path("robot-base.obj"), &LoadOptions::default())
        .unwrap()
        .scene;
    let g = group(&scene, &Params::default(), ());
    let tree = &g.tree;
    let kinds = [WrapperKind::Sphere, WrapperKind::Box, WrapperKind::Hull];
    let w = Wrappers::build(tree, &scene, &kinds, SphereMethod::Minimum);
    let fits = Fits::measure(tree, &scene, &w, None, DEFAULT_SAMPLES, &Stop::new()).unwrap();
    assert!(fits.best[..tree.leaves()].iter().all(|&e| e == 0.0));
    let levels = compare_levels(tree, &fits.best);
    let mut strictly_smaller = 0;
    for r in &levels {
        let c = fits.cover_tolerance(tree, r.level_max_error);
        let ids: Vec<u32> = c.nodes.iter().map(|n| n.node).collect();
        assert_cut(tree, &ids);
        assert_eq!(c.nodes.len(), r.cover_nodes);
        assert!(c.max_error() <= r.level_max_error);
        assert!(r.cover_nodes <= r.level_nodes, "{r:?}");
        strictly_smaller += usize::from(r.cover_nodes < r.level_nodes);
    }
    assert!(strictly_smaller >= levels.len() / 2, "{levels:?}");
    for k in [1, 5, 20, 100] {
        let c = fits.cover_budget(tree, k).unwrap();
        assert!(c.nodes.len() <= k);
        assert_eq!(c.max_error(), c.tolerance);
    }
}

#[test]
fn cover_command_writes_json_and_obj() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rb");
    let run_k = |k: &str, extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_wraptree"))
            .arg("cover")
            .arg(scene_path("robot-base.obj"))
            .args(["--budget", k, "--kinds", "sphere,box,obb,hull", "-o"])
            .arg(&out)
            .args(extra)
            .output()
            .unwrap()
    };
    let run = |extra: &[&str]| run_k("40", extra);
    let o = run(&[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("rb.json")).unwrap()).unwrap();
    let wrappers = json["wrappers"].as_array().unwrap();
    assert!(!wrappers.is_empty() && wrappers.len() <= 40);
    assert_eq!(json["size"].as_u64().unwrap() as usize, wrappers.len());
    let leaves: u64 = wrappers.iter().map(|w| w["leaves"].as_u64().unwrap()).sum();
    assert_eq!(leaves, json["primitives"].as_u64().unwrap());
    for w in wrappers {
        assert_eq!(w["kind"], w["geometry"]["type"]);
        assert!(w["error"].as_f64().unwrap() <= json["max_error"].as_f64().unwrap());
    }
    let bytes = std::fs::read(dir.path().join("rb.obj")).unwrap();
    let opts = LoadOptions {
        polyhedra: true,
        strict: false,
        up: None,
    };
    let loaded = load_bytes("rb.obj", bytes, &opts).unwrap();
    assert_eq!(loaded.scene.len(), wrappers.len());
    let again = run(&[]);
    assert!(!again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("--force"));
    assert!(run(&["--force"]).status.success());
    let bad = run_k("0", &["--force"]);
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--budget must be"));
}
