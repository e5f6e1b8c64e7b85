//! The `wraptree` binary end to end: outputs, error lines, exit codes, nothing clobbered.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn wraptree(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_wraptree"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the binary runs")
}

fn scene(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn group_json_has_the_tree() {
    let dir = tempfile::tempdir().unwrap();
    let out = wraptree(&["group", &scene("robot-base.obj"), "--json"], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let n = v["primitives"].as_u64().unwrap() as usize;
    assert_eq!(n, 276);
    let parent = v["parent"].as_array().unwrap();
    assert_eq!(parent.len(), 2 * n - 1);
    assert_eq!(parent.iter().filter(|p| p.as_i64() == Some(-1)).count(), 1);
    assert_eq!(parent[2 * n - 2].as_i64(), Some(-1));
    for k in ["rounds", "depth_max", "depth_mean", "seconds"] {
        assert!(v[k].is_number(), "{k}");
    }
}

#[test]
fn bad_scene_inputs_give_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    let missing = wraptree(&["group", "no-such-file.obj"], dir.path());
    common::assert_one_line_error(&missing, "no-such-file.obj");
    let bad = dir.path().join("nan.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let out = wraptree(&["record", "nan.obj", "-o", "rec"], dir.path());
    common::assert_one_line_error(&out, "nan.obj");
    assert!(!dir.path().join("rec.rrd").exists() && !dir.path().join("rec.mcap").exists());
    let out = wraptree(
        &["group", &scene("robot-base.obj"), "--a", "-1"],
        dir.path(),
    );
    common::assert_one_line_error(&out, "--a");
}

fn record(dir: &Path, prefix: &str, extra: &[&str]) -> Output {
    let s = scene("robot-base.obj");
    let mut args = vec!["record", s.as_str(), "-o", prefix];
    args.extend_from_slice(extra);
    wraptree(&args, dir)
}

#[test]
fn record_never_clobbers_without_force() {
    let dir = tempfile::tempdir().unwrap();
    let out = record(dir.path(), "rb", &["--detail", "levels"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mcap = dir.path().join("rb.mcap");
    let before = std::fs::read(&mcap).unwrap();
    let again = record(dir.path(), "rb", &[]);
    common::assert_one_line_error(&again, "already exists");
    assert_eq!(std::fs::read(&mcap).unwrap(), before, "untouched");
    let forced = record(dir.path(), "rb", &["--force"]);
    assert!(forced.status.success());
    assert_ne!(
        std::fs::read(&mcap).unwrap(),
        before,
        "replaced (full detail is larger)"
    );
    let leftovers: Vec<PathBuf> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(
        leftovers.is_empty(),
        "no temporary files left: {leftovers:?}"
    );
    let missing_dir = record(dir.path(), "nowhere/rb", &[]);
    common::assert_one_line_error(&missing_dir, "does not exist");
}

#[test]
fn reproducible_recordings_are_byte_identical_and_replay_verifies() {
    let dir = tempfile::tempdir().unwrap();
    assert!(
        record(dir.path(), "a", &["--reproducible"])
            .status
            .success()
    );
    assert!(
        record(dir.path(), "b", &["--reproducible"])
            .status
            .success()
    );
    let (a, b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let out = wraptree(&["replay", "a.mcap", "--verify"], dir.path());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text} {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("identical (275 merges)"), "{text}");
    let out = wraptree(&["replay", "a.mcap", "--c", "1", "-o", "c1"], dir.path());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("depth max")
            && dir.path().join("c1.rrd").exists()
            && dir.path().join("c1.mcap").exists()
    );
}

#[test]
fn replay_rejects_broken_and_foreign_files() {
    let dir = tempfile::tempdir().unwrap();
    assert!(
        record(dir.path(), "ok", &["--detail", "levels"])
            .status
            .success()
    );
    let bytes = std::fs::read(dir.path().join("ok.mcap")).unwrap();
    std::fs::write(dir.path().join("cut.mcap"), &bytes[..bytes.len() / 2]).unwrap();
    let mut flipped = bytes.clone();
    for b in flipped[200..260].iter_mut() {
        *b ^= 0x5a;
    }
    std::fs::write(dir.path().join("flip.mcap"), &flipped).unwrap();
    std::fs::write(dir.path().join("junk.mcap"), b"\x89not an mcap file at all").unwrap();
    std::fs::write(
        dir.path().join("scene.mcap"),
        std::fs::read(scene("robot-base.obj")).unwrap(),
    )
    .unwrap();
    for f in [
        "cut.mcap",
        "flip.mcap",
        "junk.mcap",
        "scene.mcap",
        "absent.mcap",
    ] {
        let out = wraptree(&["replay", f, "--verify"], dir.path());
        common::assert_one_line_error(&out, f);
    }
}

/// SIGINT mid-run: exit 130, files set aside as `.incomplete`, readable, marked incomplete.
#[test]
fn interrupted_recording_keeps_what_was_recorded() {
    let dir = tempfile::tempdir().unwrap();
    let made = wraptree(
        &["scene", "soup", "-n", "200000", "-o", "big.obj"],
        dir.path(),
    );
    assert!(made.status.success());
    let child = Command::new(env!("CARGO_BIN_EXE_wraptree"))
        .args(["record", "big.obj", "-o", "big", "--detail", "levels"])
        .current_dir(dir.path())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // The handler is installed before loading; whether the signal lands while loading or while
    // grouping, the run stops before the root (200k triangles take over a second to load and group).
    std::thread::sleep(std::time::Duration::from_millis(400));
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(130),
        "interrupted exit code; stderr: {err}"
    );
    assert!(
        !dir.path().join("big.mcap").exists(),
        "no complete-looking file"
    );
    let rep = wraptree(&["replay", "big.incomplete.mcap", "--verify"], dir.path());
    let text = String::from_utf8_lossy(&rep.stdout);
    assert!(
        rep.status.success(),
        "{text} {}",
        String::from_utf8_lossy(&rep.stderr)
    );
    assert!(text.contains("incomplete recording"), "{text}");
    let verify = Command::new("rerun")
        .args(["rrd", "verify"])
        .arg(dir.path().join("big.incomplete.rrd"))
        .output();
    let verify = verify.expect("the rerun CLI (pip install rerun-sdk==0.36.3) is needed");
    assert!(
        verify.status.success(),
        "{}",
        String::from_utf8_lossy(&verify.stderr)
    );
}

#[test]
fn wrap_json_reports_every_kind_with_levels_and_containment() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "wrap",
        &scene("robot-base.obj"),
        "--json",
        "--samples",
        "16",
    ];
    let out = wraptree(&args, dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["primitives"].as_u64(), Some(276));
    assert_eq!(v["sphere_method"].as_str(), Some("aabb-center"));
    let depth = v["depth_max"].as_u64().unwrap() as usize;
    let kinds: Vec<&str> = v["wrappers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["kind"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["sphere", "hull", "box", "obb"]);
    for w in v["wrappers"].as_array().unwrap() {
        let c = &w["containment"];
        assert_eq!(c["holds"].as_bool(), Some(true), "{w}");
        assert!(w["build_seconds"].as_f64().unwrap() >= 0.0);
        let levels = w["levels"].as_array().unwrap();
        assert_eq!(levels.len(), depth + 1, "one row per level");
        assert_eq!(levels[0]["nodes"].as_u64(), Some(1), "the root alone");
        assert_eq!(levels[depth]["nodes"].as_u64(), Some(276), "every leaf");
        for l in levels {
            for k in ["volume", "error_max", "error_mean"] {
                assert!(l[k].as_f64().unwrap() >= 0.0, "{k}: {l}");
            }
        }
    }
    let bad = wraptree(
        &["wrap", &scene("robot-base.obj"), "--wrapper", "cone"],
        dir.path(),
    );
    common::assert_one_line_error(&bad, "valid: sphere, hull, box");
}

#[test]
fn bad_cover_values_give_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    for (extra, what) in [
        (&["--cover-tolerance", "-1"][..], "-1"),
        (
            &["--cover-tolerance", "1", "--cover-budget", "3"][..],
            "--cover-budget",
        ),
        (&["--cover-budget", "0"][..], "--cover-budget"),
        (
            &["--cover-budget", "3", "--detail", "merges"][..],
            "--detail",
        ),
    ] {
        let out = record(dir.path(), "c", extra);
        common::assert_one_line_error(&out, what);
        assert!(!dir.path().join("c.rrd").exists() && !dir.path().join("c.mcap").exists());
    }
}
