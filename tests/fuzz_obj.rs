//! Fuzzing the OBJ loader with mutations of valid files (the loader's grammar-driven and
//! random-byte property tests are in `tests/scene_loading.rs`).
//!
//! Each case takes a valid OBJ text (bundled scenes cut to their first faces, a generated grid,
//! a polyhedra file) and applies a few mutations: byte flips, truncations, splices of another
//! seed, huge, negative, zero and relative face indices, NaN/Inf/overflowing/subnormal
//! coordinates, long lines, deleted and duplicated lines. `wraptree::scene::load_bytes` must
//! never panic: either it accepts a valid scene (finite points, indices in range, triangles
//! within their primitive), which then groups within a budget, or it returns an error whose
//! text is one line starting with the file name.
//!
//! Cases: 16,384 by default; `WRAPTREE_FUZZ_CASES=N` runs a longer campaign and
//! `WRAPTREE_FUZZ_SEED=N` changes the (otherwise fixed) random stream (`docs/stability.md`,
//! "Fuzzing").

mod common;

use common::mutate::{at, delete_or_duplicate_line, lines, number_tokens};

use proptest::prelude::*;
use proptest::test_runner::{TestCaseError, TestRunner};
use std::cell::Cell;
use std::path::Path;
use std::time::{Duration, Instant};
use wraptree::grouping::{Budget, Params, group_within};
use wraptree::scene::{LoadOptions, Scene, load_bytes};

/// Cases per run unless `WRAPTREE_FUZZ_CASES` says otherwise.
const DEFAULT_CASES: u32 = 16384;

/// This target's case count and runner.
fn runner(salt: u64) -> (u32, TestRunner) {
    common::fuzz_runner(salt, DEFAULT_CASES)
}

/// The first `faces` faces of a bundled scene, with every vertex line before the last of them.
fn head_of(name: &str, faces: usize) -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    let text = std::fs::read_to_string(path).unwrap();
    let mut out = String::new();
    let mut seen = 0;
    for line in text.lines() {
        out.push_str(line);
        out.push('\n');
        if line.starts_with("f ") {
            seen += 1;
            if seen == faces {
                break;
            }
        }
    }
    out.into_bytes()
}

/// Valid OBJ texts to mutate, each with whether to load it as polyhedra.
fn seeds() -> Vec<(Vec<u8>, bool)> {
    vec![
        (head_of("robot-base.obj", 24), false),
        (head_of("mug.obj", 24), false),
        (head_of("random-urdf-000.obj", 400), true),
        (common::grid_obj(3, 3, 1.0, 0.05), false),
        (
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvn 0 0 1\ng a\nf 1/1/1 2/1/1 3/1/1\nf -4 -2 -1\n"
                .to_vec(),
            false,
        ),
    ]
}

/// One edit of an OBJ text.
#[derive(Clone, Debug)]
enum Mutation {
    /// XOR the byte at (position × len) with a non-zero mask.
    Flip(f64, u8),
    /// Keep the first (fraction × len) bytes.
    Truncate(f64),
    /// Replace bytes [a, b) (fractions of len) by bytes [c, d) of seed `s`.
    Splice(f64, f64, usize, f64, f64),
    /// Replace the k-th number token (mod the count) by this text.
    Token(usize, &'static str),
    /// Insert a line of `n` copies of a character pattern at (fraction × lines).
    LongLine(f64, usize, &'static str),
    /// Delete the k-th line (mod the count).
    DeleteLine(usize),
    /// Duplicate the k-th line (mod the count).
    DuplicateLine(usize),
}

/// Replacements for number tokens: indices and coordinates that loaders get wrong.
const TOKENS: &[&str] = &[
    "0",
    "-1",
    "-2147483648",
    "2147483647",
    "4294967296",
    "99999999999999999999999",
    "-99999999999",
    "1/1/1/1",
    "1//",
    "//1",
    "nan",
    "-nan",
    "inf",
    "-inf",
    "NaN",
    "1e999",
    "-1e308",
    "1e100",
    "1e-320",
    "0x10",
    "1.5.5",
    "+",
    "",
    "\u{0}",
    "é",
];

fn mutation() -> impl Strategy<Value = Mutation> {
    let frac = || 0.0..1.0f64;
    prop_oneof![
        3 => (frac(), 1u8..=255).prop_map(|(p, m)| Mutation::Flip(p, m)),
        1 => frac().prop_map(Mutation::Truncate),
        1 => (frac(), frac(), 0usize..5, frac(), frac())
            .prop_map(|(a, b, s, c, d)| Mutation::Splice(a, b, s, c, d)),
        4 => (any::<usize>(), prop::sample::select(TOKENS)).prop_map(|(k, t)| Mutation::Token(k, t)),
        1 => (frac(), 1usize..200_000, prop::sample::select(&["f 1", " ", "v", "9", "1/"][..]))
            .prop_map(|(p, n, pat)| Mutation::LongLine(p, n, pat)),
        1 => any::<usize>().prop_map(Mutation::DeleteLine),
        1 => any::<usize>().prop_map(Mutation::DuplicateLine),
    ]
}

fn apply(text: &mut Vec<u8>, m: &Mutation, seeds: &[(Vec<u8>, bool)]) {
    match *m {
        Mutation::Flip(p, mask) if !text.is_empty() => {
            let i = at(p, text.len() - 1);
            text[i] ^= mask;
        }
        Mutation::Flip(..) => {}
        Mutation::Truncate(f) => text.truncate(at(f, text.len())),
        Mutation::Splice(a, b, s, c, d) => {
            let other = &seeds[s % seeds.len()].0;
            let (a, b) = (at(a.min(b), text.len()), at(a.max(b), text.len()));
            let (c, d) = (at(c.min(d), other.len()), at(c.max(d), other.len()));
            text.splice(a..b, other[c..d].iter().copied());
        }
        Mutation::Token(k, t) => {
            let toks = number_tokens(text, |b| {
                b.is_ascii_digit() || matches!(b, b'-' | b'+' | b'.' | b'e' | b'/')
            });
            if !toks.is_empty() {
                let (a, b) = toks[k % toks.len()];
                text.splice(a..b, t.bytes());
            }
        }
        Mutation::LongLine(p, n, pat) => {
            let ls = lines(text);
            let pos = if ls.is_empty() {
                0
            } else {
                ls[at(p, ls.len() - 1)].0
            };
            let mut line = pat.repeat(n).into_bytes();
            line.push(b'\n');
            text.splice(pos..pos, line);
        }
        Mutation::DeleteLine(k) | Mutation::DuplicateLine(k) => {
            let delete = matches!(m, Mutation::DeleteLine(_));
            delete_or_duplicate_line(text, k, delete);
        }
    }
}

/// Checks what an accepted scene promises its users.
fn check_scene(s: &Scene) -> Result<(), TestCaseError> {
    prop_assert!(!s.is_empty(), "an accepted scene has primitives");
    prop_assert!(
        s.points
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite() && c.abs() <= 1e100)),
        "finite coordinates within ±1e100"
    );
    for i in 0..s.len() {
        let prim = s.prim(i);
        prop_assert!(!prim.is_empty());
        prop_assert!(prim.iter().all(|&v| (v as usize) < s.points.len()));
        for t in s.prim_tris(i) {
            prop_assert!(t.iter().all(|v| prim.contains(v)), "triangle {t:?} of {i}");
        }
    }
    Ok(())
}

#[test]
fn mutated_obj_files_load_or_fail_with_one_line() {
    let seeds = seeds();
    for (text, polyhedra) in &seeds {
        let opts = LoadOptions {
            polyhedra: *polyhedra,
            strict: false,
            up: None,
        };
        load_bytes("seed.obj", text.clone(), &opts).expect("every seed is valid");
    }
    let (cases, mut runner) = runner(0x0b1);
    // Counted over every case tried (shrinking included, but a shrink only follows a failure).
    let (accepted, rejected, stopped) = (Cell::new(0u32), Cell::new(0u32), Cell::new(0u32));
    let bump = |c: &Cell<u32>| c.set(c.get() + 1);
    let strategy = (
        0..seeds.len(),
        prop::collection::vec(mutation(), 1..4),
        any::<bool>(),
    );
    let start = Instant::now();
    let result = runner.run(&strategy, |(s, edits, strict)| {
        let (mut text, polyhedra) = seeds[s].clone();
        for m in &edits {
            apply(&mut text, m, &seeds);
        }
        let opts = LoadOptions {
            polyhedra,
            strict,
            up: None,
        };
        match load_bytes("mutant.obj", text, &opts) {
            Ok(l) => {
                check_scene(&l.scene)?;
                let params = Params::default().resolve(&l.scene);
                let budget = Budget {
                    deadline: Some(Instant::now() + Duration::from_secs(5)),
                    max_pairs: Some(10_000_000),
                    ..Budget::default()
                };
                match group_within(&l.scene, &params, (), &budget) {
                    Ok(g) => prop_assert_eq!(g.tree.leaves(), l.scene.len()),
                    Err(_) => bump(&stopped),
                }
                bump(&accepted);
            }
            Err(e) => {
                let msg = format!("{e:#}");
                prop_assert!(
                    msg.starts_with("mutant.obj: ") && !msg.contains('\n'),
                    "{msg:?}"
                );
                bump(&rejected);
            }
        }
        Ok(())
    });
    let (accepted, rejected, stopped) = (accepted.get(), rejected.get(), stopped.get());
    eprintln!(
        "fuzz_obj: {cases} cases, {accepted} accepted ({stopped} of them stopped by the grouping \
         budget), {rejected} rejected, {:.1} s",
        start.elapsed().as_secs_f64()
    );
    if let Err(e) = result {
        panic!("{e}");
    }
    assert_eq!(stopped, 0, "accepted scenes group within the budget");
    assert!(
        accepted > cases / 20 && rejected > cases / 20,
        "the mutations both keep and break files"
    );
}
