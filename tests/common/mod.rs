//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod mutate;
pub mod readers;

#[allow(unused_imports)]
pub use readers::{python, rerun};

use proptest::prelude::*;
use wraptree::geom::P3;
use wraptree::grouping::{EventLog, Grouping, Params, SubsetTree, group};
use wraptree::scene::{PrimitiveKind, Scene};

/// The path of the bundled scene `name` (under `scenes/`), as a string argument.
pub fn scene(name: &str) -> String {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
        .display()
        .to_string()
}

/// Runs the `wraptree` binary with `args` in `dir` and returns its output.
pub fn wraptree(args: &[&str], dir: &std::path::Path) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_wraptree"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the binary runs")
}

/// What the `wraptree` binary printed on stdout, run with `args` in `dir`; panics (with its
/// stderr) if it failed.
pub fn printed(args: &[&str], dir: &std::path::Path) -> String {
    let out = wraptree(args, dir);
    assert!(
        out.status.success(),
        "wraptree {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Runs `cmd` to its end like `Command::output`, but panics (naming `what`) if it has not
/// ended within `limit`, after killing it: a stuck child fails its test instead of holding the
/// whole run.
pub fn output_within(
    mut cmd: std::process::Command,
    what: &str,
    limit: std::time::Duration,
) -> std::process::Output {
    use std::io::Read;
    use std::process::Stdio;
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start {what}: {e}"));
    // Read on threads that hand their bytes over a channel, so that a grandchild keeping a
    // pipe open cannot hold the caller either.
    let drain = |mut r: Box<dyn Read + Send>| {
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut v = Vec::new();
            let _ = r.read_to_end(&mut v);
            let _ = tx.send(v);
        });
        rx
    };
    let out = drain(Box::new(child.stdout.take().expect("piped")));
    let err = drain(Box::new(child.stderr.take().expect("piped")));
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("try_wait") {
            break status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what} did not end within {limit:?}");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let left = |rx: std::sync::mpsc::Receiver<Vec<u8>>| {
        let wait = limit.saturating_sub(start.elapsed()) + std::time::Duration::from_secs(5);
        rx.recv_timeout(wait)
            .unwrap_or_else(|_| panic!("{what} ended but its output stayed open"))
    };
    std::process::Output {
        status,
        stdout: left(out),
        stderr: left(err),
    }
}

/// A scene of right triangles with legs `size` whose right-angle corners are `corners`.
pub fn triangles(corners: &[[f64; 3]], size: f64) -> Scene {
    let mut s = Scene::new("triangles");
    for c in corners {
        let base = s.points.len() as u32;
        s.points.push(P3::new(c[0], c[1], c[2]));
        s.points.push(P3::new(c[0] + size, c[1], c[2]));
        s.points.push(P3::new(c[0], c[1] + size, c[2]));
        s.push(
            PrimitiveKind::Polygon,
            &[base, base + 1, base + 2],
            &[[base, base + 1, base + 2]],
        );
    }
    s
}

/// Random triangles for property tests, `min_n..max_n` of them: corners in [-50, 50]³, edge
/// vectors up to 3 long per axis, some axes exactly 0 (degenerate triangles included).
pub fn arb_triangles(min_n: usize, max_n: usize) -> impl Strategy<Value = Scene> {
    let coord = -50.0f64..50.0;
    let edge = prop_oneof![Just(0.0f64), -3.0f64..3.0];
    let tri = (
        [coord.clone(), coord.clone(), coord],
        [edge.clone(), edge.clone(), edge.clone()],
        [edge.clone(), edge.clone(), edge],
    );
    prop::collection::vec(tri, min_n..max_n).prop_map(|t| {
        let mut s = Scene::new("prop");
        for (c, u, v) in t {
            let b = s.points.len() as u32;
            let c = P3::new(c[0], c[1], c[2]);
            s.points.push(c);
            s.points.push(c + nalgebra::Vector3::from(u));
            s.points.push(c + nalgebra::Vector3::from(v));
            s.push(
                PrimitiveKind::Polygon,
                &[b, b + 1, b + 2],
                &[[b, b + 1, b + 2]],
            );
        }
        s
    })
}

/// Groups `scene` and returns the result with the full event log.
pub fn run(scene: &Scene, params: &Params) -> (Grouping, EventLog) {
    let mut log = EventLog::default();
    let g = group(scene, params, &mut log);
    (g, log)
}

/// Checks the merge events against the tree, and the tree by [`SubsetTree::validate`]; panics
/// with a message on the first violation.
pub fn check_tree(scene: &Scene, g: &Grouping, log: &EventLog) {
    let n = scene.len();
    let t: &SubsetTree = &g.tree;
    assert_eq!(log.merges.len(), n - 1, "N - 1 merges");
    assert_eq!(t.len(), 2 * n - 1);
    let mut seen = vec![0u32; 2 * n - 1];
    for (i, m) in log.merges.iter().enumerate() {
        assert_eq!(m.step as usize, i);
        assert_eq!(m.new as usize, n + i);
        assert!(m.a < m.b && m.b < m.new, "children precede parent");
        seen[m.a as usize] += 1;
        seen[m.b as usize] += 1;
        assert_eq!(t.children_of(m.new), Some([m.a, m.b]));
    }
    for (x, c) in seen.iter().enumerate() {
        let want = if x == 2 * n - 2 { 0 } else { 1 };
        assert_eq!(*c, want, "node {x} is a child {c} times");
    }
    // The tree itself, by the library's validator.
    if let Err(e) = t.validate(scene) {
        panic!("invalid Subset Tree: {e}");
    }
}

/// OBJ text of `nx` × `ny` right triangles of four sizes on a grid spaced 1.5 in x and `dy` in y,
/// the third vertex of each raised by `lift`: the gaps exceed the first GLimit, so grouping needs
/// several DLimit doublings.
pub fn grid_obj(nx: usize, ny: usize, dy: f64, lift: f64) -> Vec<u8> {
    let mut s = String::from("# test grid\n");
    let mut v = 0;
    for i in 0..nx {
        for j in 0..ny {
            let (x, y, z) = (i as f64 * 1.5, j as f64 * dy, ((i + j) % 3) as f64 * 0.1);
            let size = 0.2 + 0.2 * ((i * 7 + j * 3) % 4) as f64;
            s += &format!(
                "v {x} {y} {z}\nv {} {y} {z}\nv {x} {} {}\n",
                x + size,
                y + size,
                z + lift
            );
            s += &format!("f {} {} {}\n", v + 1, v + 2, v + 3);
            v += 3;
        }
    }
    s.into_bytes()
}

/// A temporary directory holding `s.obj`, a generated soup of `n` triangles (seed `seed`).
pub fn soup_dir(n: usize, seed: u64) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let mut obj = Vec::new();
    wraptree::scene::generate::soup(n, seed)
        .write_obj(&mut obj)
        .unwrap();
    std::fs::write(dir.path().join("s.obj"), obj).unwrap();
    dir
}

/// Asserts a failed run with exactly one `error:` line on stderr mentioning `needle`, no panic.
pub fn assert_one_line_error(out: &std::process::Output, needle: &str) {
    assert!(!out.status.success(), "must fail");
    let err = String::from_utf8_lossy(&out.stderr);
    let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "one error line, got: {err}");
    assert!(
        errors[0].contains(needle),
        "{:?} should mention {needle}",
        errors[0]
    );
    assert!(!err.contains("panicked"), "no panic: {err}");
}

/// The number of cases and a deterministic proptest runner for one fuzz target: `default`
/// cases unless `WRAPTREE_FUZZ_CASES` says otherwise, seeded by `salt` XOR
/// `WRAPTREE_FUZZ_SEED` (0 if unset).
pub fn fuzz_runner(salt: u64, default: u32) -> (u32, proptest::test_runner::TestRunner) {
    use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<u64>().ok());
    let cases = env("WRAPTREE_FUZZ_CASES").map_or(default, |c| c as u32);
    let seed = env("WRAPTREE_FUZZ_SEED").unwrap_or(0) ^ salt;
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let config = Config {
        cases,
        failure_persistence: None,
        max_shrink_iters: 256,
        ..Config::default()
    };
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &bytes);
    (cases, TestRunner::new_with_rng(config, rng))
}

/// Asserts that `rerun rrd verify` (PyPI `rerun-sdk`, see [`readers`]) accepts `path`.
pub fn assert_rrd_verifies(path: &std::path::Path) {
    let verify = rerun()
        .args(["rrd", "verify"])
        .arg(path)
        .output()
        .expect("the rerun CLI runs");
    assert!(
        verify.status.success(),
        "rerun rrd verify {}: {}",
        path.display(),
        String::from_utf8_lossy(&verify.stderr)
    );
}
