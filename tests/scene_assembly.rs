//! `wraptree scene assembly`: rigid, randomly rotated copies of real parts, the same bytes for
//! the same seed, and one clear error line for a bad `--part`.

mod common;

use std::path::Path;
use wraptree::scene::Scene;
use wraptree::scene::assembly::{Part, assemble, load_part, parse_part};
use wraptree::scene::load::{LoadOptions, load_path};

fn scenes() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .display()
        .to_string()
}

fn part_args() -> Vec<String> {
    let s = scenes();
    vec![
        "--part".into(),
        format!("{s}/kuka-link0.obj:5"),
        "--part".into(),
        format!("{s}/mug.obj:3"),
    ]
}

fn generate(dir: &Path, out: &str, seed: &str) -> std::process::Output {
    let mut args = vec!["scene", "assembly", "--seed", seed, "-o", out];
    let parts = part_args();
    args.extend(parts.iter().map(String::as_str));
    common::wraptree(&args, dir)
}

#[test]
fn same_seed_same_bytes_other_seed_other_placement() {
    let dir = tempfile::tempdir().unwrap();
    for (out, seed) in [("a.obj", "4"), ("b.obj", "4"), ("c.obj", "5")] {
        let o = generate(dir.path(), out, seed);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let read = |f: &str| std::fs::read(dir.path().join(f)).unwrap();
    assert_eq!(read("a.obj"), read("b.obj"));
    assert_ne!(read("a.obj"), read("c.obj"));
}

/// Every edge of every triangle of each copy, in the part's order.
fn edge_lengths(scene: &Scene, prims: std::ops::Range<usize>) -> Vec<f64> {
    prims
        .flat_map(|i| scene.prim_tris(i).to_vec())
        .flat_map(|[a, b, c]| [(a, b), (b, c), (c, a)])
        .map(|(a, b)| (scene.points[a as usize] - scene.points[b as usize]).norm())
        .collect()
}

#[test]
fn copies_are_rigid_and_count_every_triangle() {
    let dir = tempfile::tempdir().unwrap();
    let o = generate(dir.path(), "asm.obj", "9");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = scenes();
    let parts: Vec<(Scene, usize)> = [("kuka-link0.obj", 5), ("mug.obj", 3)]
        .iter()
        .map(|(f, k)| {
            let p = load_path(&Path::new(&s).join(f), &LoadOptions::default()).unwrap();
            (p.scene, *k)
        })
        .collect();
    let asm = load_path(&dir.path().join("asm.obj"), &LoadOptions::default())
        .unwrap()
        .scene;
    let expected: usize = parts.iter().map(|(p, k)| p.len() * k).sum();
    assert_eq!(asm.len(), expected);
    let mut at = 0;
    for (part, copies) in &parts {
        let want = edge_lengths(part, 0..part.len());
        for _ in 0..*copies {
            let got = edge_lengths(&asm, at..at + part.len());
            assert_eq!(got.len(), want.len());
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).abs() <= 1e-9 * w.max(1e-300), "edge {g} vs {w}");
            }
            at += part.len();
        }
    }
    // Placed apart: the copies' boxes do not all coincide.
    let first = asm.prim_aabb(0).center();
    let other = asm.prim_aabb(parts[0].0.len()).center();
    assert!((first - other).norm() > 0.0);
}

#[test]
fn library_assembly_keeps_object_per_copy() {
    let p = load_part(&format!("{}/mug.obj:4", scenes())).unwrap();
    let n = p.scene.len();
    let (scene, names) = assemble(&[p], 1).unwrap();
    assert_eq!(names.len(), 4);
    assert_eq!(scene.len(), 4 * n);
    assert_eq!(scene.object(0), 0);
    assert_eq!(scene.object(4 * n - 1), 3);
    let lamp = Part {
        scene: wraptree::scene::generate::lamp(),
        copies: 2,
    };
    assert_eq!(assemble(&[lamp], 3).unwrap().0.len(), 2 * 626);
}

#[test]
fn bad_part_specs_are_one_error_line() {
    for spec in ["mug.obj", "mug.obj:x", "mug.obj:0", ":3"] {
        let e = parse_part(spec).unwrap_err();
        assert!(e.contains(spec) && !e.contains('\n'), "{e}");
    }
    assert_eq!(
        parse_part("dir:with/colon.obj:2").unwrap(),
        ("dir:with/colon.obj".into(), 2)
    );
    let dir = tempfile::tempdir().unwrap();
    for (part, says) in [
        ("missing.obj:3", "missing.obj"),
        ("mug.obj:many", "mug.obj:many"),
    ] {
        let o = common::wraptree(
            &["scene", "assembly", "--part", part, "-o", "x.obj"],
            dir.path(),
        );
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success());
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.starts_with("error: ") && err.contains(says), "{err}");
        assert!(!dir.path().join("x.obj").exists());
    }
    let o = common::wraptree(&["scene", "assembly", "-o", "x.obj"], dir.path());
    assert!(String::from_utf8_lossy(&o.stderr).contains("needs at least one --part"));
}
