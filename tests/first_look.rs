//! What a user sees when a recording opens: for the default blueprint of every kind of `.rrd`
//! (`record` at each `--detail`, refined, partitioned, and the comparisons of `replay
//! --a/--b/--c`, `compare` and `sweep`), every view reachable from the layout's root shows
//! something on the time panel's timeline at the cursor the viewer opens at; the 3D views open
//! on an eye that frames the whole scene; the plots span the whole run and, once the run ended,
//! hold their values in a range from 0. Read with rerun-sdk's `RrdReader`
//! (`tests/blueprint_check.py`), independent of the writer.

mod common;

use std::path::{Path, PathBuf};

use serde_json::Value;

const CHECK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/blueprint_check.py");
const ROBOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/robot-base.obj");

fn run(args: &[&str], dir: &Path) {
    let out = common::wraptree(args, dir);
    assert!(
        out.status.success(),
        "wraptree {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The checker's report on `rrd`.
fn report(rrd: &Path) -> Value {
    let out = common::python()
        .arg(CHECK)
        .arg(rrd)
        .output()
        .expect("the readers' Python runs");
    assert!(
        out.status.success(),
        "the blueprint checker failed on {}:\n{}",
        rrd.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("the checker prints JSON")
}

/// Asserts what the module doc says of `rrd`, whose layout has `views` views. Every blueprint
/// in the file (the one sent at the start, shown while a large file loads, and the one fitted
/// at the end) shows something in every view with the eye framing the scene; the last one also
/// has every plot's x range and value range, and nothing else to report.
fn assert_first_look(rrd: &Path, views: usize) {
    let r = report(rrd);
    let blueprints = r["blueprints"].as_array().expect("blueprints");
    assert!(!blueprints.is_empty(), "{}: no blueprint", rrd.display());
    let mut complete = 0;
    for b in blueprints {
        assert_eq!(b["timeline"], "merge", "{}: {b}", rrd.display());
        let vs = b["views"].as_array().expect("views");
        assert_eq!(vs.len(), views, "{}: views {vs:?}", rrd.display());
        let mut all_clean = true;
        for v in vs {
            for p in v["problems"].as_array().unwrap() {
                let p = p.as_str().unwrap();
                let allowed_while_loading = p.starts_with("no x range");
                assert!(
                    allowed_while_loading,
                    "{}: view {:?}: {p}",
                    rrd.display(),
                    v["name"]
                );
                all_clean = false;
            }
        }
        let plots = vs.iter().filter(|v| v["class"] == "TimeSeries").count() as u64;
        let ranged = b["y_ranges"].as_u64().unwrap_or(0);
        // The SAH plot of a refined run has no fixed value range.
        if all_clean && ranged + 1 >= plots {
            complete += 1;
        }
    }
    assert!(
        complete >= 1,
        "{}: no blueprint with every range fitted: {r}",
        rrd.display()
    );
}

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

#[test]
fn a_recording_opens_on_every_view_populated_at_every_detail() {
    let dir = tmp();
    for (detail, views) in [("levels", 7), ("merges", 6), ("full", 7)] {
        run(
            &["record", ROBOT, "--detail", detail, "-o", detail],
            dir.path(),
        );
        assert_first_look(&dir.path().join(format!("{detail}.rrd")), views);
    }
}

#[test]
fn a_refined_recording_shows_the_refinement_on_the_merge_timeline() {
    let dir = tmp();
    run(&["record", ROBOT, "--refine", "-o", "refined"], dir.path());
    assert_first_look(&dir.path().join("refined.rrd"), 8);
}

#[test]
fn a_partitioned_recording_opens_populated() {
    let dir = tmp();
    run(
        &[
            "scene", "soup", "-n", "20000", "--seed", "3", "-o", "soup.obj",
        ],
        dir.path(),
    );
    run(
        &[
            "record",
            "soup.obj",
            "--schedule",
            "partitioned",
            "-o",
            "part",
        ],
        dir.path(),
    );
    assert_first_look(&dir.path().join("part.rrd"), 7);
}

/// Records the robot base and re-weights it; returns the directory and the two `.mcap` files.
fn two_runs() -> (tempfile::TempDir, PathBuf, PathBuf) {
    let dir = tmp();
    run(&["record", ROBOT, "-o", "base"], dir.path());
    run(
        &["replay", "base.mcap", "--c", "0.5", "-o", "c05"],
        dir.path(),
    );
    let (a, b) = (dir.path().join("base.mcap"), dir.path().join("c05.mcap"));
    (dir, a, b)
}

#[test]
fn comparisons_open_with_both_runs_populated() {
    let (dir, _, _) = two_runs();
    // replay --a/--b/--c: two 3D views, four plots, the log.
    assert_first_look(&dir.path().join("c05.compare.rrd"), 7);
    run(
        &["compare", "base.mcap", "c05.mcap", "-o", "pair"],
        dir.path(),
    );
    assert_first_look(&dir.path().join("pair.rrd"), 7);
    let r = report(&dir.path().join("pair.rrd"));
    let names: Vec<&str> = r["blueprints"][0]["views"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["class"] == "3D")
        .map(|v| v["name"].as_str().unwrap())
        .collect();
    assert!(
        names[0].contains("A1 B1 C0") && names[1].contains("A1 B1 C0.5"),
        "{names:?}"
    );
}

#[test]
fn a_sweep_writes_its_distinct_settings_side_by_side() {
    let dir = tmp();
    run(
        &[
            "sweep", ROBOT, "--a", "1", "--b", "1", "--c", "0,0.5,1", "--cost", "diameter",
            "--repeat", "1", "-o", "sw",
        ],
        dir.path(),
    );
    let r = report(&dir.path().join("sw/compare.rrd"));
    let views = r["blueprints"][0]["views"].as_array().unwrap();
    let spatial = views.iter().filter(|v| v["class"] == "3D").count();
    assert!((2..=3).contains(&spatial), "{views:?}");
    assert_first_look(&dir.path().join("sw/compare.rrd"), spatial + 5);
}

#[test]
fn compare_refuses_recordings_of_different_scenes() {
    let dir = tmp();
    run(&["record", ROBOT, "-o", "robot"], dir.path());
    let lamp = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/lamp.obj");
    run(&["record", lamp, "-o", "lamp"], dir.path());
    let out = common::wraptree(&["compare", "robot.mcap", "lamp.mcap"], dir.path());
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    assert!(err.contains("different scenes"), "{err}");
    assert!(!dir.path().join("robot.compare.rrd").exists());
}
