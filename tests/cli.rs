//! The `wraptree` binary end to end: outputs, error lines, exit codes, nothing clobbered.

mod common;

use common::{scene, wraptree};

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

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
    soup(dir.path(), "big.obj", 200_000);
    let out = record_big_then_signal(dir.path(), &[], "-INT");
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
    common::assert_rrd_verifies(&dir.path().join("big.incomplete.rrd"));
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

/// The files of `dir` (names), sorted.
fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

/// Every corrupt recording in `tests/data/bad/` (and a valid `.rrd`, which `replay` does not
/// read): one error line naming the file, non-zero exit, no panic, nothing written.
#[test]
fn corrupt_recordings_give_one_line_and_write_nothing() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let bad = root.join("tests/data/bad");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&bad)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rrd" || e == "mcap"))
        .collect();
    files.sort();
    assert!(files.len() >= 8, "the corpus has its recordings: {files:?}");
    files.push(root.join("recordings/example.rrd"));
    let dir = tempfile::tempdir().unwrap();
    for f in &files {
        let name = f.file_name().unwrap().to_string_lossy().to_string();
        let path = f.display().to_string();
        let mut runs = vec![
            vec!["replay", &path, "--verify"],
            vec!["replay", &path, "--a", "2"],
        ];
        if name.ends_with(".mcap") {
            // `snapshot` reads `.mcap` recordings; other names are scenes.
            runs.push(vec!["snapshot", &path, "-o", "out"]);
        }
        for args in runs {
            let out = wraptree(&args, dir.path());
            common::assert_one_line_error(&out, &name);
            assert!(files_in(dir.path()).is_empty(), "{args:?} wrote files");
        }
        let out = wraptree(&["replay", &path], dir.path());
        let err = String::from_utf8_lossy(&out.stderr);
        if f.extension().is_some_and(|e| e == "rrd") {
            assert!(err.contains("Rerun") || err.contains("empty"), "{err}");
        }
    }
    let out = wraptree(
        &["replay", &files[files.len() - 1].display().to_string()],
        dir.path(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("a Rerun .rrd recording, not an MCAP file") && err.contains("example.mcap"),
        "a valid .rrd points to its .mcap: {err}"
    );
}

/// A soup of `n` triangles in the unit cube, written to `dir/name`.
fn soup(dir: &Path, name: &str, n: usize) {
    let out = wraptree(&["scene", "soup", "-n", &n.to_string(), "-o", name], dir);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Starts `record big.obj -o big --detail levels` (plus `extra`) in `dir`, sends it `signal`
/// 400 ms after the grouping has begun, and waits for it: the run stops before the root
/// (200k triangles take over a second to group).
fn record_big_then_signal(dir: &Path, extra: &[&str], signal: &str) -> Output {
    let child = Command::new(env!("CARGO_BIN_EXE_wraptree"))
        .args(["record", "big.obj", "-o", "big", "--detail", "levels"])
        .args(extra)
        .current_dir(dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Signalled once the grouping has begun: the `.mcap` being written holds the compressed
    // scene (written before the first merge, megabytes for this soup). A stop while the scene
    // is loaded or written may leave nothing, as nothing was recorded yet.
    let started = || {
        std::fs::read_dir(dir).unwrap().any(|e| {
            let e = e.unwrap();
            let name = e.file_name().to_string_lossy().into_owned();
            name.starts_with(".big.mcap") && e.metadata().is_ok_and(|m| m.len() > 4 << 20)
        })
    };
    let t = std::time::Instant::now();
    while !started() && t.elapsed() < std::time::Duration::from_secs(60) {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    std::thread::sleep(std::time::Duration::from_millis(400));
    let kill = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    child.wait_with_output().unwrap()
}

/// `--max-pairs`/`--max-seconds` stop a runaway grouping (GLimit spanning the whole soup):
/// `group` prints one error line and exits 3; `record` keeps an existing recording, writes the
/// partial one aside marked incomplete with the reason, which `replay` reports and verifies.
#[test]
fn budgets_stop_a_runaway_grouping() {
    let dir = tempfile::tempdir().unwrap();
    soup(dir.path(), "s.obj", 20_000);
    let out = wraptree(
        &["group", "s.obj", "--glimit", "10", "--max-pairs", "100000"],
        dir.path(),
    );
    common::assert_one_line_error(&out, "--max-pairs 100000");
    assert_eq!(out.status.code(), Some(3));
    assert!(out.stdout.is_empty());
    let out = wraptree(
        &["group", "s.obj", "--glimit", "10", "--max-seconds", "0.2"],
        dir.path(),
    );
    common::assert_one_line_error(&out, "--max-seconds 0.2");
    assert_eq!(out.status.code(), Some(3));
    for bad in ["0", "-1", "nan", "inf"] {
        let out = wraptree(&["group", "s.obj", "--max-seconds", bad], dir.path());
        common::assert_one_line_error(&out, "--max-seconds");
        assert_eq!(out.status.code(), Some(1));
    }
    // Within the budget the result is the same tree.
    let free = wraptree(&["group", &scene("robot-base.obj"), "--json"], dir.path());
    let limited = wraptree(
        &[
            "group",
            &scene("robot-base.obj"),
            "--json",
            "--max-pairs",
            "10000000",
            "--max-seconds",
            "600",
        ],
        dir.path(),
    );
    assert!(limited.status.success());
    let parent = |o: &Output| {
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["parent"].clone()
    };
    assert_eq!(parent(&free), parent(&limited));

    std::fs::write(dir.path().join("r.mcap"), b"old recording").unwrap();
    std::fs::write(dir.path().join("r.rrd"), b"old recording").unwrap();
    let args = [
        "record", "s.obj", "-o", "r", "--force", "--detail", "levels", "--glimit", "0.3",
    ];
    let out = wraptree(
        &[&args[..], &["--dlimit", "0.02", "--max-pairs", "3000000"]].concat(),
        dir.path(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("--max-pairs 3000000") && !err.contains("panicked"),
        "{err}"
    );
    for f in ["r.mcap", "r.rrd"] {
        assert_eq!(
            std::fs::read(dir.path().join(f)).unwrap(),
            b"old recording",
            "{f} kept"
        );
    }
    let rec =
        wraptree::record::mcap::read_recording(&dir.path().join("r.incomplete.mcap")).unwrap();
    assert!(!rec.complete);
    assert_eq!(rec.metadata["stop_reason"], "max-pairs");
    assert!(rec.metadata["stop_eligible_pairs"].parse::<u64>().unwrap() > 3_000_000);
    assert_eq!(rec.metadata["merges"], rec.merges.len().to_string());
    let rep = wraptree(&["replay", "r.incomplete.mcap", "--verify"], dir.path());
    let text = String::from_utf8_lossy(&rep.stdout);
    assert!(rep.status.success(), "{text}");
    assert!(
        text.contains("incomplete recording (stopped: max-pairs)"),
        "{text}"
    );
    assert!(
        text.contains("recorded merges match the re-run's first"),
        "{text}"
    );
    let leftovers: Vec<String> = files_in(dir.path())
        .into_iter()
        .filter(|f| f.ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

/// SIGTERM mid-run, as SIGINT: exit 130, an existing recording kept even with `--force`, the
/// partial files set aside as `.incomplete`, readable, marked incomplete as interrupted.
#[test]
fn terminated_recording_keeps_the_old_one_and_what_was_recorded() {
    let dir = tempfile::tempdir().unwrap();
    soup(dir.path(), "big.obj", 200_000);
    for f in ["big.mcap", "big.rrd"] {
        std::fs::write(dir.path().join(f), b"old recording").unwrap();
    }
    let out = record_big_then_signal(dir.path(), &["--force"], "-TERM");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for f in ["big.mcap", "big.rrd"] {
        assert_eq!(
            std::fs::read(dir.path().join(f)).unwrap(),
            b"old recording",
            "{f} kept"
        );
    }
    let rec =
        wraptree::record::mcap::read_recording(&dir.path().join("big.incomplete.mcap")).unwrap();
    assert!(!rec.complete);
    assert_eq!(rec.metadata["stop_reason"], "interrupted");
    let rep = wraptree(&["replay", "big.incomplete.mcap"], dir.path());
    let text = String::from_utf8_lossy(&rep.stdout);
    assert!(rep.status.success(), "{text}");
    assert!(
        text.contains("incomplete recording (stopped: interrupted)"),
        "{text}"
    );
    assert!(dir.path().join("big.incomplete.rrd").exists());
}
