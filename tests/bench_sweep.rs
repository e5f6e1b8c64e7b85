//! `bench SCENE… -o DIR` and `sweep`: the CSV has one row per method × wrapper (or setting), the
//! charts are real PNGs, and the `.rrd` passes `rerun rrd verify` with the expected entities
//! (PyPI `rerun-sdk==0.36.3`, provisioned by the tests, `common::readers`).

mod common;

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

use wraptree::metrics::{compare, quality};
use wraptree::peers::{Method, build};

/// Entity paths of the first recording in `argv[1]`.
const ENTITIES: &str = r#"
import json, sys
from rerun.experimental import RrdReader
r = RrdReader(sys.argv[1])
print(json.dumps(sorted({c.entity_path for c in r.stream()})))
"#;

fn entities(path: &Path) -> BTreeSet<String> {
    common::assert_rrd_verifies(path);
    let out = common::python()
        .args(["-c", ENTITIES])
        .arg(path)
        .output()
        .expect("the readers' Python runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice::<Vec<String>>(&out.stdout)
        .unwrap()
        .into_iter()
        .collect()
}

fn wraptree(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_wraptree"))
        .args(args)
        .output()
        .unwrap()
}

fn assert_png(path: &Path) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
        "{}",
        path.display()
    );
    assert!(bytes.len() > 5_000, "{} looks empty", path.display());
}

#[test]
fn bench_writes_one_row_per_method_and_wrapper_with_charts_and_rrd() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("file");
    std::fs::write(&file, "not a directory").unwrap();
    let not_dir = wraptree(&["bench", "robot-base", "-o", file.to_str().unwrap()]);
    common::assert_one_line_error(&not_dir, "cannot create the output directory");
    // A missing output directory is created with its parents.
    let out = dir.path().join("new").join("out");
    let o = out.to_str().unwrap();
    let r = wraptree(&[
        "bench",
        "robot-base",
        "soup:300",
        "-o",
        o,
        "--repeat",
        "1",
        "--methods",
        "all",
        "--wrappers",
        "all",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    assert_eq!(
        rows.len(),
        2 * Method::ALL.len() * compare::Wrapper::ALL.len()
    );
    for row in &rows {
        assert_eq!(row.len(), header.len());
        let sah: f64 = row[col("sah")].parse().unwrap();
        assert!(sah > 1.0, "SAH {sah}");
        // Refinement time: its own column, part of the (total) build time; 0 when unrefined.
        let build: f64 = row[col("build_s")].parse().unwrap();
        let refine: f64 = row[col("refine_s")].parse().unwrap();
        assert!(refine <= build, "{row:?}");
        assert_eq!(
            refine > 0.0,
            Method::parse(row[col("method")]).unwrap().is_refined(),
            "{row:?}"
        );
        let query = row[col("node_tests_per_query")];
        let is_query_bv = row[col("wrapper")] == "box" || row[col("wrapper")].starts_with("sphere");
        assert_eq!(!query.is_empty(), is_query_bv, "{row:?}");
        assert!(
            !row[col("tightness")].is_empty(),
            "small scenes measure tightness"
        );
        let levels = row[col("tightness_per_level")].split(';').count();
        let depth: usize = row[col("depth_max")].parse().unwrap();
        assert_eq!(levels, depth + 1, "one tightness per level: {row:?}");
    }
    for m in Method::ALL {
        assert!(
            rows.iter().any(|r| r[col("method")] == m.name()),
            "{}",
            m.name()
        );
    }
    for stem in ["robot-base", "soup-300"] {
        assert_png(&out.join(format!("{stem}-time_vs_query.png")));
        assert_png(&out.join(format!("{stem}-wrapper_time_vs_tightness.png")));
    }
    let e = entities(&out.join("bench.rrd"));
    for m in Method::ALL {
        // Rerun escapes `+` (the refined methods' names) in entity paths.
        let path = format!(
            "/bench/robot-base/time_vs_query/{}",
            m.name().replace('+', "\\+")
        );
        assert!(e.contains(&path), "{path}: {e:?}");
    }
    assert!(
        e.contains("/bench/soup-300/time_vs_query/pareto_front"),
        "{e:?}"
    );
    assert!(
        e.contains("/bench/soup-300/wrapper_time_vs_tightness/hull"),
        "{e:?}"
    );
    assert!(e.contains("/bench/soup-300/table"), "{e:?}");
    // Results are not replaced without --force, and the refusal comes before any measuring:
    // no table printed, every file as it was.
    let csv_before = std::fs::read(out.join("results.csv")).unwrap();
    let again = wraptree(&["bench", "robot-base", "-o", o, "--repeat", "1"]);
    common::assert_one_line_error(&again, "already exists");
    assert!(
        again.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&again.stdout)
    );
    assert_eq!(std::fs::read(out.join("results.csv")).unwrap(), csv_before);
    // A chart left from an earlier run is refused too, before a new results.csv is written
    // beside it.
    let charts = dir.path().join("charts");
    std::fs::create_dir(&charts).unwrap();
    let stale = charts.join("soup-300-wrapper_time_vs_tightness.png");
    std::fs::write(&stale, "an earlier run's chart").unwrap();
    let c = charts.to_str().unwrap();
    let refused = wraptree(&["bench", "robot-base", "soup:300", "-o", c, "--repeat", "1"]);
    common::assert_one_line_error(
        &refused,
        "soup-300-wrapper_time_vs_tightness.png: already exists",
    );
    assert!(refused.stdout.is_empty());
    assert!(!charts.join("results.csv").exists());
    assert_eq!(std::fs::read(&stale).unwrap(), b"an earlier run's chart");
    // By default: the default builders × the default wrappers, in their order.
    let d = dir.path().join("defaults");
    let r = wraptree(&[
        "bench",
        "robot-base",
        "-o",
        d.to_str().unwrap(),
        "--repeat",
        "1",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let csv = std::fs::read_to_string(d.join("results.csv")).unwrap();
    let pairs: Vec<(String, String)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[col("method")].to_string(), f[col("wrapper")].to_string())
        })
        .collect();
    let want: Vec<(String, String)> = Method::DEFAULT
        .iter()
        .flat_map(|m| {
            compare::Wrapper::DEFAULT
                .iter()
                .map(|w| (m.name().to_string(), w.name().to_string()))
        })
        .collect();
    assert_eq!(pairs, want);
    let bad = wraptree(&["bench", "robot-base", "-o", o, "--methods", "fast,nope"]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("unknown method 'nope'") && err.contains("or all"),
        "{err}"
    );
}

/// The SAH and chunking columns of each method's row in `dir`'s results.csv.
fn sah_by_method(dir: &Path) -> Vec<(String, f64, String)> {
    let csv = std::fs::read_to_string(dir.join("results.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    csv.lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (
                f[col("method")].to_string(),
                f[col("sah")].parse().unwrap(),
                f[col("chunking")].to_string(),
            )
        })
        .collect()
}

#[test]
fn bench_sets_the_partitioned_chunks_and_refuses_them_where_they_set_nothing() {
    let dir = tempfile::tempdir().unwrap();
    // 3,000 triangles under a root share of 256 are split; chunks as large as the scene make
    // the partitioned run the exact one, chunks of 4 do not.
    let run = |name: &str, delta: &str| {
        let out = dir.path().join(name);
        let r = wraptree(&[
            "bench",
            "soup:3000",
            "--methods",
            "grouping,grouping-partitioned",
            "--wrappers",
            "box",
            "--tightness-max-n",
            "0",
            "--repeat",
            "1",
            "--chunk-top",
            "256",
            "--chunk-delta",
            delta,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(err.contains(&format!("chunks of δ = {delta}")), "{err}");
        sah_by_method(&out)
    };
    let whole = run("whole", "3000");
    assert_eq!(whole[0].0, "grouping");
    assert_eq!(whole[1].0, "grouping-partitioned");
    assert_eq!(whole[0].1, whole[1].1);
    // The CSV names the chunks each partitioned row grouped with.
    assert_eq!(whole[0].2, "");
    assert_eq!(whole[1].2, "delta=3000 epsilon=0.5 top=256 sah=256");
    let small = run("small", "4");
    assert_eq!(small[0].1, whole[0].1);
    assert_ne!(small[1].1, small[0].1);
    let o = dir.path().join("refused");
    let o = o.to_str().unwrap();
    let out = wraptree(&[
        "bench",
        "soup:300",
        "--methods",
        "grouping,fast",
        "--chunk-delta",
        "64",
        "-o",
        o,
    ]);
    common::assert_one_line_error(&out, "--chunk-delta sets grouping-partitioned's chunks");
    let out = wraptree(&["bench", "--record", "--chunk-top", "64", "-o", o]);
    common::assert_one_line_error(&out, "--chunk-top needs SCENEs");
    let out = wraptree(&[
        "bench",
        "soup:300",
        "--methods",
        "grouping-partitioned",
        "--chunk-delta",
        "1",
        "-o",
        o,
    ]);
    common::assert_one_line_error(
        &out,
        "--chunk-delta (δ) must be at least 2 (or 0: by the scene's size), got 1",
    );
    assert!(!Path::new(o).exists());
}

#[test]
fn sweep_writes_every_setting_to_csv_heat_maps_and_one_rrd() {
    let dir = tempfile::tempdir().unwrap();
    let o = dir.path().to_str().unwrap();
    let r = wraptree(&[
        "sweep", "lamp", "--a", "0,1", "--b", "1", "--c", "0,2", "-o", o, "--repeat", "1",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let csv = std::fs::read_to_string(dir.path().join("sweep.csv")).unwrap();
    let settings: Vec<String> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').take(4).collect::<Vec<_>>().join(","))
        .collect();
    // Both size measures of the Cost by default, the diameter first.
    let abc = ["0,1,0", "0,1,2", "1,1,0", "1,1,2"];
    let want: Vec<String> = ["diameter", "area"]
        .iter()
        .flat_map(|m| abc.iter().map(move |s| format!("{s},{m}")))
        .collect();
    assert_eq!(settings, want);
    for stem in ["depth", "sah", "query", "time"] {
        assert_png(&dir.path().join(format!("sweep-{stem}.png")));
    }
    let e = entities(&dir.path().join("sweep.rrd"));
    for s in [
        "A0_B1_C0",
        "A0_B1_C2",
        "A1_B1_C0",
        "A1_B1_C2",
        "A1_B1_C0_area",
    ] {
        assert!(e.contains(&format!("/sweep/{s}/cost")), "{s}: {e:?}");
    }
    assert!(
        e.contains("/summary/sah") && e.contains("/summary/table"),
        "{e:?}"
    );
    let bad = wraptree(&["sweep", "lamp", "--a", "-1", "-o", o]);
    common::assert_one_line_error(&bad, "--a must be a finite number");
}

/// A command that fails after making its output directory takes away the directories it made
/// (still empty) and leaves one that was there before, with its files.
#[test]
fn a_failed_sweep_leaves_no_output_directories_behind() {
    let dir = tempfile::tempdir().unwrap();
    let made = dir.path().join("new").join("out");
    let o = made.to_str().unwrap();
    // Every setting is left out at a 1 µs budget, which fails after the directory is made.
    let args = [
        "sweep",
        "lamp",
        "--a",
        "1",
        "--b",
        "1",
        "--c",
        "0",
        "--max-seconds",
        "1e-6",
    ];
    let out = wraptree(&[&args[..], &["-o", o]].concat());
    common::assert_one_line_error(&out, "every setting was left out");
    assert!(!dir.path().join("new").exists(), "made directories removed");
    let kept = dir.path().join("kept");
    std::fs::create_dir(&kept).unwrap();
    std::fs::write(kept.join("notes.txt"), "mine").unwrap();
    let out = wraptree(&[&args[..], &["-o", kept.to_str().unwrap()]].concat());
    common::assert_one_line_error(&out, "every setting was left out");
    assert_eq!(
        std::fs::read_to_string(kept.join("notes.txt")).unwrap(),
        "mine"
    );
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let out = wraptree(&[&args[..], &["-o", empty.to_str().unwrap()]].concat());
    common::assert_one_line_error(&out, "every setting was left out");
    assert!(empty.is_dir(), "a directory the user made stays");
}

#[test]
fn peers_build_valid_trees_on_bundled_meshes_and_differ_in_quality() {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let loaded = wraptree::scene::load_path(
        &scenes.join("kuka-link0.obj"),
        &wraptree::scene::LoadOptions::default(),
    )
    .unwrap();
    let scene = loaded.scene;
    let mut sahs = Vec::new();
    for m in Method::ALL {
        let b = build(m, &scene, &Default::default()).unwrap();
        let t = &b.tree;
        let mut leaves: Vec<u32> = t.leaves_under(t.root());
        leaves.sort_unstable();
        assert_eq!(
            leaves,
            (0..scene.len() as u32).collect::<Vec<_>>(),
            "{}",
            m.name()
        );
        let q = quality(t);
        assert!(
            q.depth_max as f64 >= (scene.len() as f64).log2().ceil(),
            "{}",
            m.name()
        );
        assert!((0.0..=1.0).contains(&q.structural_balance));
        sahs.push(q.sah);
        // Same input, same tree.
        assert_eq!(build(m, &scene, &Default::default()).unwrap().tree, b.tree);
    }
    let distinct: BTreeSet<u64> = sahs.iter().map(|s| s.to_bits()).collect();
    assert!(
        distinct.len() >= 6,
        "builders should not all agree: {sahs:?}"
    );
}
