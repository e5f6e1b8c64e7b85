//! The programs in `examples/` (users' tasks) run and do what they say. `cargo test` builds them next to the
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
