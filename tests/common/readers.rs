//! The independent recording readers the tests run (the `rerun` CLI and Python package from
//! `rerun-sdk`, `mcap`, `mcap-protobuf-support`, `foxglove-schemas-protobuf`), provisioned by
//! the tests themselves so that `cargo test --release` alone works on a fresh machine.
//!
//! On first use a virtual environment is made from `.ci/requirements.txt` under the target
//! directory (`$CARGO_TARGET_TMPDIR/readers-<hash of requirements.txt>`, so a changed
//! requirements file gets a new one) with `python3 -m venv` and `pip install -r`. Test binaries
//! that start at once take a file lock (`readers-<hash>.lock`) around the check and the build;
//! the environment counts as built only once the marker file `ready` is written, last, so a
//! build interrupted half-way is removed and made again. Later runs reuse it (a check of one
//! file). Failing to build it fails the test with one line saying which step failed and why.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use sha2::{Digest, Sha256};

/// The requirements file the environment is made from.
fn requirements() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(".ci/requirements.txt")
}

/// The environment's directory, named after the requirements' content.
fn venv_dir(requirements: &[u8]) -> PathBuf {
    let hash = Sha256::digest(requirements);
    let hex: String = hash[..8].iter().map(|b| format!("{b:02x}")).collect();
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("readers-{hex}"))
}

/// Runs `cmd`; on failure returns one line naming `what` and the last line it printed.
fn run(what: &str, cmd: &mut Command) -> Result<(), String> {
    let out = cmd
        .output()
        .map_err(|e| format!("{what}: cannot start it ({e})"))?;
    if out.status.success() {
        return Ok(());
    }
    let text = format!(
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let last = text.lines().rev().find(|l| !l.trim().is_empty());
    Err(format!(
        "{what} failed ({}): {}",
        out.status,
        last.unwrap_or("no output").trim()
    ))
}

/// Makes the environment at `dir` unless it is ready; returns its `bin` directory.
fn provision() -> Result<PathBuf, String> {
    let req = requirements();
    let bytes = std::fs::read(&req).map_err(|e| format!("{}: {e}", req.display()))?;
    let dir = venv_dir(&bytes);
    let bin = dir.join("bin");
    let ready = dir.join("ready");
    if ready.exists() {
        return Ok(bin);
    }
    let parent = dir.parent().expect("the venv has a parent");
    std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    let lock_path = dir.with_extension("lock");
    let lock =
        std::fs::File::create(&lock_path).map_err(|e| format!("{}: {e}", lock_path.display()))?;
    lock.lock()
        .map_err(|e| format!("{}: cannot lock: {e}", lock_path.display()))?;
    // Another test binary may have built it while this one waited for the lock.
    if ready.exists() {
        return Ok(bin);
    }
    if dir.exists() {
        std::fs::remove_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    run(
        "python3 -m venv (Debian: apt-get install python3-venv)",
        Command::new("python3").arg("-m").arg("venv").arg(&dir),
    )?;
    run(
        &format!("pip install -r {}", req.display()),
        Command::new(bin.join("python"))
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--disable-pip-version-check",
                "-r",
            ])
            .arg(&req),
    )?;
    std::fs::write(&ready, &bytes).map_err(|e| format!("{}: {e}", ready.display()))?;
    Ok(bin)
}

/// The environment's `bin` directory; panics with one line when it cannot be made (once per
/// test binary: later calls repeat the same line).
fn bin() -> &'static Path {
    static BIN: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    match BIN.get_or_init(provision) {
        Ok(bin) => bin,
        Err(e) => panic!("cannot provision the Python readers for the tests: {e}"),
    }
}

/// A command running the environment's Python interpreter.
pub fn python() -> Command {
    Command::new(bin().join("python"))
}

/// A command running the environment's `rerun` CLI (PyPI `rerun-sdk`).
pub fn rerun() -> Command {
    Command::new(bin().join("rerun"))
}
