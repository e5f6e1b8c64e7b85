//! Write errors part-way through a recording, made real with the file-size limit
//! (`ulimit -f`, `SIGXFSZ` ignored so writes fail with `EFBIG`): at every point the run fails
//! with one line naming the file and the reason, and an existing recording is left untouched.

#![cfg(target_os = "linux")]

mod common;

use std::path::Path;
use std::process::Command;

/// `wraptree record` under a file-size limit of `kib` KiB, killed if it takes a minute (a hang
/// on the write error, which the SDK's own flush would do).
fn record_limited(dir: &Path, kib: u64, scene: &Path) -> std::process::Output {
    let exe = env!("CARGO_BIN_EXE_wraptree");
    let script = format!(
        "trap '' XFSZ; ulimit -f {kib}; exec timeout -s KILL 60 \"$0\" record \"$1\" -o rec --force --detail full"
    );
    Command::new("bash")
        .arg("-c")
        .arg(script)
        .arg(exe)
        .arg(scene)
        .current_dir(dir)
        .output()
        .expect("bash runs")
}

#[test]
fn a_write_error_at_any_point_is_one_line_and_keeps_the_old_recording() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/lamps5.obj");
    let dir = tempfile::tempdir().unwrap();
    let record = |detail: &str, prefix: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_wraptree"))
            .args(["record", "--detail", detail, "-o", prefix])
            .arg(&scene)
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    record("levels", "rec");
    let rrd = std::fs::read(dir.path().join("rec.rrd")).unwrap();
    let mcap = std::fs::read(dir.path().join("rec.mcap")).unwrap();
    record("full", "big");
    let largest = ["big.rrd", "big.mcap"]
        .iter()
        .map(|f| std::fs::metadata(dir.path().join(f)).unwrap().len())
        .max()
        .unwrap();
    // From the first header write to the last footer bytes of the larger file.
    let limits = [
        1,
        16,
        256,
        largest / 2048,
        largest / 1024 - 8,
        largest / 1024 - 1,
    ];
    for kib in limits {
        let out = record_limited(dir.path(), kib, &scene);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{kib} KiB: must fail: {err}");
        common::assert_one_line_error(&out, "rec.");
        assert!(
            err.contains("File too large"),
            "{kib} KiB: the reason: {err}"
        );
        assert_eq!(
            std::fs::read(dir.path().join("rec.rrd")).unwrap(),
            rrd,
            "{kib} KiB: the old .rrd is kept"
        );
        assert_eq!(
            std::fs::read(dir.path().join("rec.mcap")).unwrap(),
            mcap,
            "{kib} KiB: the old .mcap is kept"
        );
    }
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
}
