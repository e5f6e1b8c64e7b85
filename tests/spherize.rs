//! `wraptree spherize`: per-link spheres are conservative, the budget's allocation is exact
//! (against brute force), the writers read back in independent readers (urdf_parser_py,
//! PyYAML, Python's xml, run by `tests/spheres_reader.py`), and bad input is one error line.

mod common;

use std::path::{Path, PathBuf};

use wraptree::scene::UrdfOptions;
use wraptree::scene::urdf::links::read_links;
use wraptree::spherize::allocate::by_budget;
use wraptree::spherize::link_tree::LinkTree;
use wraptree::spherize::spend::by_mean;
use wraptree::spherize::tighten::tighten;
use wraptree::spherize::{Limit, Settings, spherize};
use wraptree::stop::Stop;

fn r2d2() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/r2d2/r2d2.urdf")
}

fn collision() -> UrdfOptions {
    UrdfOptions {
        collision: true,
        ..UrdfOptions::default()
    }
}

#[test]
fn every_vertex_of_every_link_is_inside_one_of_its_spheres() {
    let links = read_links(&r2d2(), &collision(), &Stop::new()).unwrap();
    assert!(links.links.len() >= 10, "{}", links.links.len());
    for (limit, refine) in [
        (Limit::Budget(links.links.len()), false),
        (Limit::Budget(40), false),
        (Limit::Budget(40), true),
        (Limit::Tolerance(0.02), false),
        (Limit::Tolerance(0.02), true),
    ] {
        let settings = Settings {
            limit,
            margin: 0.0,
            min_radius: 0.0,
            slack: 0.0,
            refine,
        };
        let s = spherize(links.links.clone(), settings, &Stop::new()).unwrap();
        let cover = s.cover_spheres();
        if let Limit::Budget(k) = limit {
            let n: usize = cover.iter().map(|(_, v)| v.len()).sum();
            assert!(n <= k, "{n} spheres for a budget of {k}");
        }
        for (l, (name, spheres)) in s.links.iter().zip(&cover) {
            assert_eq!(&l.link.name, name);
            let size = l.link.mesh.aabb().diameter();
            for p in &l.link.mesh.points {
                let inside = spheres.iter().any(|s| s.contains(p, 1e-9 * size));
                assert!(
                    inside,
                    "{limit:?} (refine {refine}): a vertex of {name} at {p} is outside"
                );
            }
        }
        let score = s.score(&cover);
        assert_eq!(score.uncovered, 0.0, "{limit:?}");
    }
}

#[test]
fn margins_and_minimum_radii_are_applied_to_written_spheres() {
    let links = read_links(&r2d2(), &collision(), &Stop::new()).unwrap();
    let plain = Settings {
        limit: Limit::Budget(30),
        margin: 0.0,
        min_radius: 0.0,
        slack: 0.0,
        refine: false,
    };
    let padded = Settings {
        margin: 0.01,
        min_radius: 0.05,
        ..plain
    };
    let a = spherize(links.links.clone(), plain, &Stop::new()).unwrap();
    let b = spherize(links.links, padded, &Stop::new()).unwrap();
    for ((_, x), (_, y)) in a.cover_spheres().iter().zip(&b.cover_spheres()) {
        for (s, t) in x.iter().zip(y) {
            assert_eq!(s.center, t.center);
            assert_eq!(t.radius, (s.radius + 0.01).max(0.05));
        }
    }
}

/// Every cut of the subtree of `x`, as node lists.
fn cuts(t: &LinkTree, x: u32) -> Vec<Vec<u32>> {
    let mut out = vec![vec![x]];
    if let Some([a, b]) = t.tree.children_of(x) {
        for l in cuts(t, a) {
            for r in cuts(t, b) {
                out.push([l.clone(), r].concat());
            }
        }
    }
    out
}

/// A tree per (triangles, seed) soup, every node measured.
fn measured_soups(specs: &[(usize, u64)]) -> Vec<LinkTree> {
    let stop = Stop::new();
    specs
        .iter()
        .map(|&(n, seed)| {
            let mut t = LinkTree::build(wraptree::scene::generate::soup(n, seed), 16, false, &stop)
                .unwrap();
            let all: Vec<u32> = (0..t.tree.len() as u32).collect();
            t.measure(&all, &stop).unwrap();
            t
        })
        .collect()
}

#[test]
fn the_budget_allocation_is_exact_against_brute_force() {
    let stop = Stop::new();
    let mut trees = measured_soups(&[(7, 3), (6, 11), (5, 29)]);
    // Each link's cuts as (size, largest excess), the smallest excess per size.
    let curves: Vec<Vec<(usize, f64)>> = trees
        .iter()
        .map(|t| {
            cuts(t, t.tree.root())
                .iter()
                .map(|c| {
                    let e = c.iter().map(|&x| t.excess[x as usize]).fold(0.0, f64::max);
                    (c.len(), e)
                })
                .collect()
        })
        .collect();
    let leaves: usize = trees.iter().map(|t| t.tree.leaves()).sum();
    for k in 3..=leaves {
        let mut brute = f64::INFINITY;
        for a in &curves[0] {
            for b in &curves[1] {
                for c in &curves[2] {
                    if a.0 + b.0 + c.0 <= k {
                        brute = brute.min(a.1.max(b.1).max(c.1));
                    }
                }
            }
        }
        let (covers, alloc) = by_budget(&mut trees, k, &stop).unwrap().unwrap();
        assert_eq!(alloc.threshold, brute, "budget {k}");
        let used: usize = covers.iter().map(Vec::len).sum();
        assert!(used <= k);
        assert_eq!(
            alloc.per_link,
            covers.iter().map(Vec::len).collect::<Vec<_>>()
        );
        for (t, c) in trees.iter().zip(&covers) {
            assert!(c.iter().all(|&x| t.excess[x as usize] <= brute));
        }
    }
    assert!(by_budget(&mut trees, 2, &stop).unwrap().is_err());
}

#[test]
fn the_mean_spending_is_exact_against_brute_force() {
    let stop = Stop::new();
    let mut trees = measured_soups(&[(6, 5), (5, 17), (5, 23)]);
    // Each link's cuts as (size, largest excess, Σ S, Σ N).
    let curves: Vec<Vec<(usize, f64, f64, f64)>> = trees
        .iter()
        .map(|t| {
            cuts(t, t.tree.root())
                .iter()
                .map(|c| {
                    let e = c.iter().map(|&x| t.excess[x as usize]).fold(0.0, f64::max);
                    let s = c.iter().map(|&x| t.outside[x as usize].0).sum();
                    let n = c.iter().map(|&x| t.outside[x as usize].1 as f64).sum();
                    (c.len(), e, s, n)
                })
                .collect()
        })
        .collect();
    let ratio = |s: f64, n: f64| if n > 0.0 { s / n } else { 0.0 };
    let leaves: usize = trees.iter().map(|t| t.tree.leaves()).sum();
    let mut improved = 0;
    for k in 3..=leaves {
        let (start, alloc) = by_budget(&mut trees, k, &stop).unwrap().unwrap();
        for slack in [0.0, 0.3, 1.0] {
            let t = alloc.threshold * (1.0 + slack);
            let mut brute = f64::INFINITY;
            for a in &curves[0] {
                for b in &curves[1] {
                    for c in &curves[2] {
                        if a.0 + b.0 + c.0 <= k && a.1.max(b.1).max(c.1) <= t {
                            brute = brute.min(ratio(a.2 + b.2 + c.2, a.3 + b.3 + c.3));
                        }
                    }
                }
            }
            let (covers, spent) = by_mean(&trees, k, t, start.clone(), &stop).unwrap();
            assert!(
                (spent.mean - brute).abs() <= 1e-12 * brute.max(1e-9),
                "budget {k} slack {slack}: {} vs {brute}",
                spent.mean
            );
            assert!(covers.iter().map(Vec::len).sum::<usize>() <= k);
            let (mut s, mut n) = (0.0, 0.0);
            for (tr, c) in trees.iter().zip(&covers) {
                let is_cut = cuts(tr, tr.tree.root()).into_iter().any(|mut x| {
                    x.sort_unstable();
                    x == *c
                });
                assert!(is_cut, "a cut");
                for &x in c {
                    assert!(tr.excess[x as usize] <= t);
                    s += tr.outside[x as usize].0;
                    n += tr.outside[x as usize].1 as f64;
                }
            }
            assert!((ratio(s, n) - spent.mean).abs() <= 1e-12 * brute.max(1e-9));
            if spent.rounds > 1 {
                improved += 1;
            }
        }
    }
    assert!(improved > 0, "the spending never changed a cover");
}

#[test]
fn the_formats_read_back_in_independent_readers_and_score_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let robot = r2d2().display().to_string();
    let prefix = dir.path().join("r2");
    let p = prefix.display().to_string();
    common::printed(
        &[
            "spherize",
            &robot,
            "--urdf-collision",
            "--budget",
            "40",
            "-o",
            &p,
        ],
        dir.path(),
    );
    for ext in [
        ".urdf", "_1.urdf", ".yml", ".srdf", ".json", ".rrd", ".mcap",
    ] {
        assert!(Path::new(&format!("{p}{ext}")).is_file(), "{ext}");
    }
    let out = common::python()
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/spheres_reader.py"))
        .args([&robot, &p])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let read: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(format!("{p}.json")).unwrap()).unwrap();
    // The same numbers in every format (a reader may give 0 where another gives 0.0).
    let numbers = |v: &serde_json::Value| -> Vec<(String, Vec<Vec<f64>>)> {
        v.as_object()
            .unwrap()
            .iter()
            .map(|(k, s)| {
                let s = s.as_array().unwrap();
                let s = s.iter().map(|x| {
                    x.as_array()
                        .unwrap()
                        .iter()
                        .map(|n| n.as_f64().unwrap())
                        .collect()
                });
                (k.clone(), s.collect())
            })
            .collect()
    };
    assert_eq!(numbers(&read["urdf"]), numbers(&read["curobo"]));
    assert_eq!(numbers(&read["urdf"]), numbers(&read["srdf"]));
    let n: usize = read["urdf"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_array().unwrap().len())
        .sum();
    assert_eq!(n as u64, report["score"]["spheres"].as_u64().unwrap());
    assert!(n <= 40);
    let input = urdf_rs::read_file(r2d2()).unwrap();
    assert_eq!(
        read["joints"].as_u64().unwrap() as usize,
        input.joints.len()
    );
    let visuals: usize = input.links.iter().map(|l| l.visual.len()).sum();
    assert_eq!(read["visuals"].as_u64().unwrap() as usize, visuals);
    for (link, d) in read["outside"].as_object().unwrap() {
        let d = d.as_f64().unwrap_or(f64::INFINITY);
        assert!(
            d <= 1e-9,
            "{link}: a collision point {d} outside its spheres"
        );
    }
    // Scoring the written sets gives the report's score.
    for ext in [".urdf", ".yml"] {
        let json = common::printed(
            &[
                "spherize",
                &robot,
                "--urdf-collision",
                "--score",
                &format!("{p}{ext}"),
                "--json",
            ],
            dir.path(),
        );
        let s: serde_json::Value = serde_json::from_str(&json).unwrap();
        assert_eq!(s["uncovered"], report["score"]["uncovered"], "{ext}");
        assert_eq!(s["spheres"], report["score"]["spheres"], "{ext}");
        let (a, b) = (
            s["excess_max"].as_f64().unwrap(),
            report["score"]["excess_max"].as_f64().unwrap(),
        );
        assert!((a - b).abs() <= 1e-9 + 0.05 * b, "{ext}: {a} vs {b}");
    }
    common::assert_rrd_verifies(Path::new(&format!("{p}.rrd")));
}

#[test]
fn bad_input_is_one_error_line_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.urdf");
    std::fs::write(&bad, "<robot name=\"x\"><link").unwrap();
    let b = bad.display().to_string();
    let out = common::wraptree(&["spherize", &b, "--budget", "5", "-o", "out"], dir.path());
    common::assert_one_line_error(&out, "bad.urdf");
    let robot = r2d2().display().to_string();
    let out = common::wraptree(
        &[
            "spherize",
            &robot,
            "--urdf-collision",
            "--budget",
            "3",
            "-o",
            "out",
        ],
        dir.path(),
    );
    common::assert_one_line_error(&out, "budget of 3 spheres");
    let out = common::wraptree(
        &[
            "spherize",
            &robot,
            "--urdf-collision",
            "--budget",
            "30",
            "--slack",
            "nan",
            "-o",
            "out",
        ],
        dir.path(),
    );
    common::assert_one_line_error(&out, "--slack");
    let out = common::wraptree(
        &["spherize", &robot, "--urdf-collision", "--score", &b],
        dir.path(),
    );
    common::assert_one_line_error(&out, "bad.urdf");
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 1, "{left:?}");
}

#[test]
fn tightening_keeps_every_piece_covered_and_never_loosens_a_sphere() {
    let stop = Stop::new();
    let mut changed = 0;
    for seed in [3, 11, 29] {
        let mut t =
            LinkTree::build(wraptree::scene::generate::soup(300, seed), 32, false, &stop).unwrap();
        let cover = t.tree.level(3);
        t.measure(&cover, &stop).unwrap();
        let tight = tighten(&t, &cover, &stop).unwrap();
        assert!(!tight.is_empty() && tight.len() <= cover.len());
        let size = t.mesh.aabb().diameter();
        for p in &t.mesh.points {
            let out = tight
                .iter()
                .map(|s| (p - s.sphere.center).norm() - s.sphere.radius)
                .fold(f64::INFINITY, f64::min);
            assert!(out <= 1e-9 * size, "seed {seed}: a vertex {out} outside");
        }
        let largest = |e: &mut dyn Iterator<Item = f64>| e.fold(0.0, f64::max);
        let before = largest(&mut cover.iter().map(|&x| t.excess[x as usize]));
        let after = largest(&mut tight.iter().map(|s| s.excess));
        assert!(
            after <= before * (1.0 + 1e-9),
            "seed {seed}: {after} > {before}"
        );
        let outside = |s: &mut dyn Iterator<Item = f64>| s.sum::<f64>();
        let before = outside(&mut cover.iter().map(|&x| t.outside[x as usize].0));
        let after = outside(&mut tight.iter().map(|s| s.outside.0));
        assert!(after <= before * (1.0 + 1e-9), "seed {seed}");
        changed += usize::from(tight.len() < cover.len() || after < before);
    }
    assert!(changed > 0, "tightening never changed a cover");
}

#[test]
fn the_snapshot_draws_the_robot_its_trees_and_its_cover() {
    let dir = tempfile::tempdir().unwrap();
    let robot = r2d2().display().to_string();
    let p = dir.path().join("r2").display().to_string();
    let figs = dir.path().join("figs");
    let f = figs.display().to_string();
    let args = [
        "spherize",
        &robot,
        "--urdf-collision",
        "--budget",
        "30",
        "--format",
        "urdf",
        "--no-record",
        "-o",
        &p,
        "--snapshot",
        &f,
    ];
    common::printed(&args, dir.path());
    let svg = |n: &str| std::fs::read_to_string(figs.join(format!("{n}.svg"))).unwrap();
    let circles = |s: &str| s.matches("<circle").count();
    let read: Vec<String> = std::fs::read_dir(&figs)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    let cover = read
        .iter()
        .find(|n| n.ends_with("-cover.svg"))
        .expect("a cover frame")
        .trim_end_matches(".svg")
        .to_string();
    // The robot alone, then exactly the written spheres over it.
    assert_eq!(circles(&svg("frame-00-robot")), 0);
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(format!("{p}.json")).unwrap()).unwrap();
    let spheres = report["score"]["spheres"].as_u64().unwrap() as usize;
    assert!(spheres > 2 && spheres <= 30, "{spheres}");
    assert_eq!(circles(&svg(&cover)), spheres);
    let links = circles(&svg("frame-01-depth-0"));
    assert!(links > 1 && links < circles(&svg(&cover)), "{links}");
    for name in ["frame-00-robot", &cover, "figure"] {
        let png = std::fs::read(figs.join(format!("{name}.png"))).unwrap();
        assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"), "{name}");
    }
    // Again, to another prefix but the same figures, without --force: one error line, the
    // figures kept and nothing else written.
    let before = std::fs::read(figs.join("figure.png")).unwrap();
    let other = dir.path().join("again").display().to_string();
    let mut args = args;
    args[9] = &other;
    let out = common::wraptree(&args, dir.path());
    assert!(!Path::new(&format!("{other}.json")).exists());
    common::assert_one_line_error(&out, "figure.png");
    assert_eq!(std::fs::read(figs.join("figure.png")).unwrap(), before);
    // Figures that cannot be written: one error line, and nothing else left (`.sph` included).
    let fresh = tempfile::tempdir().unwrap();
    std::fs::write(fresh.path().join("blocker"), "").unwrap();
    let out = common::wraptree(
        &[
            "spherize",
            &robot,
            "--urdf-collision",
            "--budget",
            "30",
            "--no-record",
            "-o",
            "r2",
            "--snapshot",
            "blocker/figs",
        ],
        fresh.path(),
    );
    common::assert_one_line_error(&out, "blocker/figs");
    let left: Vec<_> = std::fs::read_dir(fresh.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, ["blocker"], "{left:?}");
}
