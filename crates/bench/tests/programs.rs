//! The measuring programs (`src/bin/`) run on small inputs and print what they say. Cargo
//! builds them for this test (`CARGO_BIN_EXE_<name>`); the test runs those binaries.

use std::path::{Path, PathBuf};
use std::process::Output;
use wraptree::grouping::{Params, group};

/// Runs the program `exe` with `args`; it must succeed.
fn run(exe: &str, args: &[&str]) -> Output {
    let out = std::process::Command::new(exe)
        .args(args)
        .output()
        .expect("the program runs");
    assert!(
        out.status.success(),
        "{exe} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A bundled scene's path (the workspace's `scenes/`).
fn bundled(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(file)
}

/// What program `exe` printed, run with `args` and then the bundled scene `file`.
fn printed(exe: &str, args: &[&str], file: &str) -> String {
    let path = bundled(file);
    let mut all = args.to_vec();
    all.push(path.to_str().expect("a UTF-8 path"));
    String::from_utf8_lossy(&run(exe, &all).stdout).into_owned()
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
fn exact_timing_prints_one_tree_hash_for_both_thread_counts() {
    let lamp = bundled("lamp.obj");
    let out = run(
        env!("CARGO_BIN_EXE_exact_timing"),
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
    let stdout = printed(env!("CARGO_BIN_EXE_partitioned_levels"), &[], "husky.obj");
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
    let stdout = printed(env!("CARGO_BIN_EXE_exact_prefix"), &["0.25"], "husky.obj");
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
    let stdout = printed(env!("CARGO_BIN_EXE_exact_rounds"), &[], "lamp.obj");
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
    let urdf = printed(
        env!("CARGO_BIN_EXE_exact_order"),
        &[],
        "random-urdf-782.obj",
    );
    let rows = table_rows(&urdf, "| scene");
    assert_eq!(rows.len(), 1, "{urdf}");
    assert!(
        rows[0][3..10].iter().all(|c| *c == "1.000 / 1.000"),
        "{urdf}"
    );
    let base = printed(env!("CARGO_BIN_EXE_exact_order"), &[], "robot-base.obj");
    let rows = table_rows(&base, "| scene");
    assert_eq!(rows.len(), 1, "{base}");
    let r = &rows[0];
    assert_eq!((r[1], r[2]), ("robot-base", "276"), "{base}");
    assert_eq!(r[6], "1.000 / 1.000", "{base}");
    assert_eq!(r[3..6], r[7..10], "{base}");
    assert!(r[3..6].iter().any(|c| *c != "1.000 / 1.000"), "{base}");
}

#[test]
fn method_timing_prints_a_row_per_method_measured_against_the_peers() {
    let stdout = printed(
        env!("CARGO_BIN_EXE_method_timing"),
        &["--repeat", "1", "--methods", "fast,grouping"],
        "lamp.obj",
    );
    let rows = table_rows(&stdout, "| scene");
    assert_eq!(rows.len(), 2, "{stdout}");
    assert_eq!((rows[0][1], rows[0][4]), ("lamp", "fast"), "{stdout}");
    assert_eq!(rows[1][4], "grouping", "{stdout}");
    // Every ratio is a finite positive number (the peers were measured in the same run).
    for r in &rows {
        for cell in &r[6..13] {
            let x: f64 = cell.parse().unwrap_or_else(|_| panic!("{cell}: {stdout}"));
            assert!(x.is_finite() && x > 0.0, "{stdout}");
        }
    }
}

#[test]
fn touching_poses_counts_every_pose_of_each_seed_and_sums_them() {
    let stdout = printed(env!("CARGO_BIN_EXE_touching_poses"), &["1"], "lamp.obj");
    let rows = table_rows(&stdout, "| seed");
    let (sum, poses) = rows.split_last().unwrap();
    assert_eq!(poses.len(), 8, "{stdout}");
    assert!(poses.iter().all(|r| r[1] == "1"), "{stdout}");
    assert!(sum[1].starts_with("sum"), "{stdout}");
}

#[test]
fn partitioned_schedule_measures_each_scene_against_the_exact_run() {
    let lamp = bundled("lamp.obj");
    let out = run(
        env!("CARGO_BIN_EXE_partitioned_schedule"),
        &["--repeat", "1", "soup:300", lamp.to_str().unwrap()],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = |name: &str| -> Vec<&str> {
        stdout
            .lines()
            .find(|l| l.starts_with(name))
            .unwrap_or_else(|| panic!("no {name} line: {stdout}"))
            .split_whitespace()
            .collect()
    };
    // Both are grouped whole (under 12,288 primitives): the partitioned tree is the exact one.
    for (name, n) in [("soup", "300"), ("lamp", "626")] {
        let cells = line(name);
        assert_eq!(cells[1], n, "{stdout}");
        assert_eq!((cells[10], cells[11]), ("1.000", "1.000"), "{stdout}");
    }
}
