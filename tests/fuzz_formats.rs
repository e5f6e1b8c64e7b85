//! Fuzzing the STL, PLY, glTF/GLB, COLLADA and URDF readers with mutations of valid files, as
//! `tests/fuzz_obj.rs` does for OBJ.
//!
//! Seeds: real files of `tests/data/formats/` (binary and ASCII STL, binary and ASCII PLY, a
//! GLB with a node hierarchy, a `.gltf` with data URIs, a COLLADA scene of nested nodes) and a
//! URDF of shapes and joints. Each
//! case applies a few mutations: byte flips, 32-bit little-endian words written anywhere (counts,
//! lengths, offsets, indices), truncations, splices of another seed, replaced number tokens,
//! deleted and duplicated lines. `wraptree::scene::load_bytes` must never panic: it accepts a
//! valid scene (finite points, indices in range, triangles within their primitive) or returns
//! an error whose text is one line starting with the file name.
//!
//! Cases: 16,384 by default; `WRAPTREE_FUZZ_CASES=N` and `WRAPTREE_FUZZ_SEED=N` as for the OBJ
//! target (`docs/stability.md`, "Fuzzing").

mod common;

use common::mutate::{at, delete_or_duplicate_line, number_tokens};

use proptest::prelude::*;
use proptest::test_runner::TestCaseError;
use std::cell::Cell;
use std::path::Path;
use wraptree::scene::{LoadOptions, Scene, load_bytes};

const DEFAULT_CASES: u32 = 16384;

fn data(name: &str) -> Vec<u8> {
    std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/formats")
            .join(name),
    )
    .unwrap()
}

/// A binary STL of the first `n` triangles of `idler_riser.STL` (its "solid" header kept).
fn small_binary_stl(n: usize) -> Vec<u8> {
    let full = data("idler_riser.STL");
    let mut b = full[..84 + 50 * n].to_vec();
    b[80..84].copy_from_slice(&(n as u32).to_le_bytes());
    b
}

const URDF: &str = r#"<?xml version="1.0"?>
<robot name="fuzz">
  <link name="base"><visual><geometry><box size="0.6 0.2 0.1"/></geometry></visual></link>
  <link name="arm"><visual><origin xyz="0 0 0.3" rpy="0 1.57 0"/>
    <geometry><cylinder radius="0.05" length="0.6"/></geometry></visual></link>
  <link name="hand"><collision><geometry><sphere radius="0.1"/></geometry></collision>
    <visual><geometry><capsule radius="0.04" length="0.1"/></geometry></visual></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.05"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="wrist" type="prismatic"><parent link="arm"/><child link="hand"/>
    <origin xyz="0 0 0.6"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.1" effort="1" velocity="1"/>
    <mimic joint="shoulder" multiplier="0.5" offset="0.1"/></joint>
</robot>
"#;

/// An OFF cube: comments, counts on the keyword's line, quads with colours after them.
const OFF: &str = "# a cube\nCOFF 8 6 12\n0 0 0 1 0 0 1\n1 0 0 1 0 0 1\n1 1 0 1 0 0 1\n\
0 1 0 1 0 0 1\n0 0 1 1 0 0 1\n1 0 1 1 0 0 1\n1 1 1 1 0 0 1\n0 1 1 1 0 0 1\n\
4 0 3 2 1 255 0 0\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6 # side\n4 1 2 6 5\n4 3 0 4 7\n";

/// Valid files to mutate, each with its name (which picks the reader).
fn seeds() -> Vec<(&'static str, Vec<u8>)> {
    vec![
        ("seed.stl", small_binary_stl(12)),
        ("seed.stl", data("multibody.stl")),
        ("seed.ply", data("mirror.ply")),
        ("seed.ply", data("cube_blender_uv.ply")),
        ("seed.off", OFF.as_bytes().to_vec()),
        ("seed.glb", data("nested.glb")),
        ("seed.gltf", data("rgb_cube_with_primitives.gltf")),
        ("seed.urdf", URDF.as_bytes().to_vec()),
        ("seed.dae", data("two_parts.dae")),
    ]
}

#[derive(Clone, Debug)]
enum Mutation {
    /// XOR the byte at (position × len) with a non-zero mask.
    Flip(f64, u8),
    /// Write a little-endian 32-bit word at (position × len).
    Word(f64, u32),
    /// Keep the first (fraction × len) bytes.
    Truncate(f64),
    /// Replace bytes [a, b) (fractions of len) by bytes [c, d) of seed `s`.
    Splice(f64, f64, usize, f64, f64),
    /// Replace the k-th number token (mod the count) by this text.
    Token(usize, &'static str),
    /// Delete the k-th line (mod the count).
    DeleteLine(usize),
    /// Duplicate the k-th line (mod the count).
    DuplicateLine(usize),
}

const TOKENS: &[&str] = &[
    "0",
    "-1",
    "1",
    "2",
    "3",
    "255",
    "256",
    "65535",
    "4294967295",
    "4294967296",
    "-2147483648",
    "99999999999999999999",
    "nan",
    "inf",
    "-inf",
    "1e999",
    "1e-320",
    "1e100",
    "0.5",
    "",
    "x",
];

const WORDS: &[u32] = &[
    0,
    1,
    3,
    12,
    255,
    65535,
    0x7fff_ffff,
    0xffff_ffff,
    0x8000_0000,
];

fn mutation() -> impl Strategy<Value = Mutation> {
    let frac = || 0.0..1.0f64;
    prop_oneof![
        3 => (frac(), 1u8..=255).prop_map(|(p, m)| Mutation::Flip(p, m)),
        2 => (frac(), prop_oneof![prop::sample::select(WORDS), any::<u32>()])
            .prop_map(|(p, w)| Mutation::Word(p, w)),
        1 => frac().prop_map(Mutation::Truncate),
        1 => (frac(), frac(), 0usize..9, frac(), frac())
            .prop_map(|(a, b, s, c, d)| Mutation::Splice(a, b, s, c, d)),
        3 => (any::<usize>(), prop::sample::select(TOKENS)).prop_map(|(k, t)| Mutation::Token(k, t)),
        1 => any::<usize>().prop_map(Mutation::DeleteLine),
        1 => any::<usize>().prop_map(Mutation::DuplicateLine),
    ]
}

fn apply(text: &mut Vec<u8>, m: &Mutation, seeds: &[(&str, Vec<u8>)]) {
    match *m {
        Mutation::Flip(p, mask) if !text.is_empty() => {
            let i = at(p, text.len() - 1);
            text[i] ^= mask;
        }
        Mutation::Word(p, w) if text.len() >= 4 => {
            let i = at(p, text.len() - 4);
            text[i..i + 4].copy_from_slice(&w.to_le_bytes());
        }
        Mutation::Flip(..) | Mutation::Word(..) => {}
        Mutation::Truncate(f) => text.truncate(at(f, text.len())),
        Mutation::Splice(a, b, s, c, d) => {
            let other = &seeds[s % seeds.len()].1;
            let (a, b) = (at(a.min(b), text.len()), at(a.max(b), text.len()));
            let (c, d) = (at(c.min(d), other.len()), at(c.max(d), other.len()));
            text.splice(a..b, other[c..d].iter().copied());
        }
        Mutation::Token(k, t) => {
            let toks = number_tokens(text, |b| {
                b.is_ascii_digit() || matches!(b, b'-' | b'+' | b'.' | b'e')
            });
            if !toks.is_empty() {
                let (a, b) = toks[k % toks.len()];
                text.splice(a..b, t.bytes());
            }
        }
        Mutation::DeleteLine(k) | Mutation::DuplicateLine(k) => {
            let delete = matches!(m, Mutation::DeleteLine(_));
            delete_or_duplicate_line(text, k, delete);
        }
    }
}

fn check_scene(s: &Scene) -> Result<(), TestCaseError> {
    prop_assert!(!s.is_empty());
    prop_assert!(
        s.points
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite() && c.abs() <= 1e100))
    );
    prop_assert_eq!(s.objects.len(), s.len());
    for i in 0..s.len() {
        let prim = s.prim(i);
        prop_assert!(prim.len() >= 3 || s.kind == Some(wraptree::scene::PrimitiveKind::Polyhedron));
        prop_assert!(prim.iter().all(|&v| (v as usize) < s.points.len()));
        for t in s.prim_tris(i) {
            prop_assert!(t.iter().all(|v| prim.contains(v)), "triangle {t:?} of {i}");
        }
    }
    Ok(())
}

#[test]
fn mutated_stl_ply_off_gltf_dae_and_urdf_files_load_or_fail_with_one_line() {
    let seeds = seeds();
    for (name, bytes) in &seeds {
        load_bytes(name, bytes.clone(), &LoadOptions::default())
            .unwrap_or_else(|e| panic!("seed {name} must load: {e}"));
    }
    let (cases, mut runner) = common::fuzz_runner(0xf0f, DEFAULT_CASES);
    let (accepted, rejected) = (Cell::new(0u32), Cell::new(0u32));
    let bump = |c: &Cell<u32>| c.set(c.get() + 1);
    let strategy = (
        0..seeds.len(),
        prop::collection::vec(mutation(), 1..4),
        any::<bool>(),
    );
    let result = runner.run(&strategy, |(s, edits, polyhedra)| {
        let (name, mut bytes) = seeds[s].clone();
        for m in &edits {
            apply(&mut bytes, m, &seeds);
        }
        let opts = LoadOptions {
            polyhedra,
            ..LoadOptions::default()
        };
        match load_bytes(name, bytes, &opts) {
            Ok(l) => {
                check_scene(&l.scene)?;
                bump(&accepted);
            }
            Err(e) => {
                let msg = format!("{e:#}");
                prop_assert!(
                    msg.starts_with(&format!("{name}: ")) && !msg.contains('\n'),
                    "{msg:?}"
                );
                bump(&rejected);
            }
        }
        Ok(())
    });
    eprintln!(
        "{cases} cases: {} accepted, {} rejected with one line",
        accepted.get(),
        rejected.get()
    );
    result.unwrap();
    assert!(accepted.get() > 0 && rejected.get() > 0);
}
