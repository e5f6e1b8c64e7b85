//! The programs in `examples/` run and do what they say. `cargo test` builds them next to the
//! test binaries (`target/<profile>/examples/`); this test runs those binaries, never cargo.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use wraptree::geom::P3;
use wraptree::grouping::{Limits, Params, group};
use wraptree::query::reference;
use wraptree::replay::{self, Verified};
use wraptree::scene::generate;

/// The built example `name`: `target/<profile>/examples/<name>`, beside `deps/` where this
/// test's binary is.
fn example(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("the test binary's path");
    let dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("the test binary is in target/<profile>/deps");
    let path = dir
        .join("examples")
        .join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
    assert!(
        path.is_file(),
        "{} is not built: run `cargo test --release` (which builds the examples) or \
         `cargo build --release --examples` first",
        path.display()
    );
    path
}

fn run(name: &str, args: &[&str]) -> Output {
    let out = Command::new(example(name))
        .args(args)
        .output()
        .expect("the example runs");
    assert!(
        out.status.success(),
        "{name} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A bundled scene's path.
fn bundled(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(file)
}

/// What example `name` printed, run with `args` and then the bundled scene `file`.
fn printed(name: &str, args: &[&str], file: &str) -> String {
    let path = bundled(file);
    let mut all = args.to_vec();
    all.push(path.to_str().expect("a UTF-8 path"));
    String::from_utf8_lossy(&run(name, &all).stdout).into_owned()
}

/// The cells of the markdown table rows of `stdout` (header, rule and other lines left out:
/// rows start with `| ` and do not start with `header`).
fn table_rows<'a>(stdout: &'a str, header: &str) -> Vec<Vec<&'a str>> {
    stdout
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with(header))
        .map(|l| l.split('|').map(str::trim).collect())
        .collect()
}

#[test]
fn record_scene_writes_both_recordings_of_the_lamp_and_they_replay() {
    let dir = tempfile::tempdir().unwrap();
    let prefix = dir.path().join("out").join("lamp");
    std::fs::create_dir(dir.path().join("out")).unwrap();
    let lamp = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/lamp.obj");
    let out = run("record_scene", &[lamp, prefix.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let (rrd, mcap) = (
        dir.path().join("out/lamp.rrd"),
        dir.path().join("out/lamp.mcap"),
    );
    assert!(stdout.starts_with("lamp: "), "{stdout}");
    assert!(stdout.contains(&rrd.display().to_string()), "{stdout}");
    assert!(stdout.contains(&mcap.display().to_string()), "{stdout}");
    common::assert_rrd_verifies(&rrd);
    let replay = replay::open(&mcap).unwrap();
    assert!(replay.rec.complete);
    assert_eq!(replay.loaded.scene.len(), 626);
    match replay::verify(&replay, &Limits::default(), &wraptree::stop::Stop::new()).unwrap() {
        Verified::Identical { merges, .. } => assert_eq!(merges, 625),
        v => panic!("the recording does not replay: {v:?}"),
    }
}

#[test]
fn record_scene_without_arguments_cleans_up_after_itself() {
    let out = run("record_scene", &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let files: Vec<&str> = stdout.lines().skip(1).collect();
    assert_eq!(files.len(), 2, "{stdout}");
    for f in files {
        assert!(!Path::new(f).exists(), "{f} is left behind");
    }
}

#[test]
fn query_tree_prints_the_exact_distance() {
    let scene = generate::replicate(&generate::robot_base(), 44, 1);
    for (args, p) in [
        (vec![], P3::new(2.0, 0.0, 0.0)),
        (vec!["0.1", "-0.2", "0.3"], P3::new(0.1, -0.2, 0.3)),
    ] {
        let out = run("query_tree", &args);
        let stdout = String::from_utf8_lossy(&out.stdout);
        let line = stdout
            .lines()
            .find(|l| l.starts_with("distance from"))
            .unwrap_or_else(|| panic!("no distance line: {stdout}"));
        let d: f64 = line.rsplit(' ').next().unwrap().parse().unwrap();
        let exact = reference::point_distance(&scene, &p);
        assert!((d - exact).abs() <= 1e-9, "{d} vs brute force {exact}");
        let depth = group(&scene, &Params::default(), ()).tree.depth_max();
        assert!(
            stdout.contains(&format!("(12144 primitives), depth {depth}")),
            "{stdout}"
        );
    }
    let bad = Command::new(example("query_tree"))
        .args(["1", "2"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
}

#[test]
fn exact_timing_prints_one_tree_hash_for_both_thread_counts() {
    let lamp = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/lamp.obj");
    let out = run(
        "exact_timing",
        &["--threads", "1,2", "--repeat", "1", lamp.to_str().unwrap()],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    let rows: Vec<Vec<&str>> = stdout
        .lines()
        .filter(|l| l.starts_with("| lamp |"))
        .map(|l| l.split('|').map(str::trim).collect())
        .collect();
    assert_eq!(rows.len(), 2, "{stdout}");
    let hash = |r: &Vec<&str>| r[r.len() - 2].to_string();
    assert_eq!(hash(&rows[0]), hash(&rows[1]), "{stdout}");
    assert_eq!(rows[0][3], "1");
    assert_eq!(rows[1][3], "2");
}

#[test]
fn partitioned_levels_sums_each_tree_s_interior_areas_by_node_size() {
    let stdout = printed("partitioned_levels", &[], "husky.obj");
    let rows = table_rows(&stdout, "| leaves");
    assert_eq!(rows[0][1], "2–3", "{stdout}");
    let (all, sizes) = rows.split_last().unwrap();
    assert_eq!(all[1], "all", "{stdout}");
    // The exact column is the exact tree's interior area over its root's, split by size.
    let scene = wraptree::scene::load_path(&bundled("husky.obj"), &Default::default())
        .unwrap()
        .scene;
    let tree = group(&scene, &Params::default(), ()).tree;
    let root = wraptree::geom::area(&tree.aabb[tree.root() as usize]);
    let interior: f64 = tree.aabb[tree.leaves()..]
        .iter()
        .map(wraptree::geom::area)
        .sum();
    let cell = |r: &[&str], i: usize| r[i].parse::<f64>().unwrap();
    assert_eq!(all[2], format!("{:.2}", interior / root), "{stdout}");
    let split: f64 = sizes.iter().map(|r| cell(r, 2)).sum();
    assert!(
        (split - interior / root).abs() < 0.01 * sizes.len() as f64,
        "{stdout}"
    );
    // The partitioned tree is another tree (husky is split: 35,902 primitives).
    assert_ne!(all[2], all[3], "{stdout}");
}

#[test]
fn exact_prefix_splices_a_tree_that_is_the_exact_one_when_the_rest_is_grouped_whole() {
    // husky (35,902 primitives): with a quarter of the bodies left (under the 12,288 that the
    // partitioned schedule groups whole), the second stage is the exact run's continuation in
    // all but the rounds it starts from, so both measures stay within 2 % of the exact tree's.
    let stdout = printed("exact_prefix", &["0.25"], "husky.obj");
    let row: Vec<&str> = stdout
        .lines()
        .find(|l| l.starts_with("| husky |"))
        .unwrap_or_else(|| panic!("{stdout}"))
        .split('|')
        .map(str::trim)
        .collect();
    assert_eq!(row[2], "35902", "{stdout}");
    let ratios: Vec<f64> = row[4].split(" / ").map(|v| v.parse().unwrap()).collect();
    assert_eq!(ratios.len(), 2, "{stdout}");
    assert!(ratios.iter().all(|r| (0.98..=1.02).contains(r)), "{stdout}");
    let times: Vec<f64> = row[5].split(", ").map(|v| v.parse().unwrap()).collect();
    assert!(times.iter().all(|&t| t > 0.0), "{stdout}");
}

#[test]
fn exact_rounds_accounts_for_every_merge_and_the_whole_time() {
    let stdout = printed("exact_rounds", &[], "lamp.obj");
    let rows = table_rows(&stdout, "| round");
    assert!(rows.len() >= 2, "{stdout}");
    assert_eq!(rows[0][1], "0", "{stdout}");
    let scene = wraptree::scene::load_path(&bundled("lamp.obj"), &Default::default())
        .unwrap()
        .scene;
    let g = group(&scene, &Params::default(), ());
    assert_eq!(rows.len(), g.rounds as usize, "{stdout}");
    let merges: usize = rows
        .iter()
        .map(|r| r[4].split(' ').next().unwrap().parse::<usize>().unwrap())
        .sum();
    assert_eq!(merges, scene.len() - 1, "{stdout}");
    let share: f64 = rows
        .iter()
        .map(|r| r[7].trim_end_matches(" %").parse::<f64>().unwrap())
        .sum();
    assert!((share - 100.0).abs() < 1.0, "{stdout}");
}

#[test]
fn exact_order_maps_each_order_s_tree_back_to_the_input_ids() {
    // random-urdf-782 has no equal Costs: every order gives the input order's exact tree, so
    // each tree mapped back has the same SAH and node tests. robot-base (276 primitives, a CAD
    // part of congruent faces) has ties, which break by id: another order gives another tree.
    // Both are grouped whole by the partitioned schedule, so its tree of each order is that
    // order's exact tree.
    let urdf = printed("exact_order", &[], "random-urdf-782.obj");
    let rows = table_rows(&urdf, "| scene");
    assert_eq!(rows.len(), 1, "{urdf}");
    assert!(
        rows[0][3..10].iter().all(|c| *c == "1.000 / 1.000"),
        "{urdf}"
    );
    let base = printed("exact_order", &[], "robot-base.obj");
    let rows = table_rows(&base, "| scene");
    assert_eq!(rows.len(), 1, "{base}");
    let r = &rows[0];
    assert_eq!((r[1], r[2]), ("robot-base", "276"), "{base}");
    assert_eq!(r[6], "1.000 / 1.000", "{base}");
    assert_eq!(r[3..6], r[7..10], "{base}");
    assert!(r[3..6].iter().any(|c| *c != "1.000 / 1.000"), "{base}");
}
