//! Scene loading and generation: the committed generated scenes, the bad-input corpus in
//! `tests/data/bad/`, the polygon and polyhedra rules, determinism, the generators and OBJ round
//! trips. Every bundled scene's load and count is in `bundled_scenes.rs`.

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use wraptree::geom::P3;
use wraptree::scene::generate::{self, by_name, lamp, replicate, robot_base, soup};
use wraptree::scene::{LoadOptions, Loaded, PrimitiveKind, Scene, load_bytes, load_path};

const POLYGONS: LoadOptions = LoadOptions {
    polyhedra: false,
    strict: false,
    up: None,
};
const POLYHEDRA: LoadOptions = LoadOptions {
    polyhedra: true,
    strict: false,
    up: None,
};
const STRICT: LoadOptions = LoadOptions {
    polyhedra: true,
    strict: true,
    up: None,
};

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

fn load_str(name: &str, text: &str, opts: LoadOptions) -> Result<Loaded, String> {
    load_bytes(name, text.as_bytes().to_vec(), &opts).map_err(|e| e.to_string())
}

/// Vertex positions of every primitive, in order.
fn prim_points(s: &Scene) -> Vec<Vec<P3>> {
    (0..s.len())
        .map(|i| s.prim_vertices(i).copied().collect())
        .collect()
}

/// Vertex positions of every primitive as a sorted set (order-free comparison).
fn prim_point_sets(s: &Scene) -> Vec<Vec<[u64; 3]>> {
    (0..s.len())
        .map(|i| {
            let mut v: Vec<[u64; 3]> = s
                .prim_vertices(i)
                .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                .collect();
            v.sort_unstable();
            v.dedup();
            v
        })
        .collect()
}

fn all_finite(s: &Scene) -> bool {
    s.points.iter().all(|p| p.iter().all(|c| c.is_finite()))
}

fn obj_text(s: &Scene) -> Vec<u8> {
    let mut out = Vec::new();
    s.write_obj(&mut out).unwrap();
    out
}

#[test]
fn committed_generated_scenes_match_the_generators() {
    for (name, scene) in [
        ("robot-base.obj", robot_base()),
        ("lamp.obj", lamp()),
        ("lamps5.obj", replicate(&lamp(), 5, 1)),
    ] {
        let l = load_path(&repo(&format!("scenes/{name}")), &POLYGONS).unwrap();
        assert!(l.warnings.is_empty(), "{name}: {:?}", l.warnings);
        assert_eq!(prim_points(&l.scene), prim_points(&scene), "{name}");
    }
}

#[test]
fn mug_keeps_its_planar_quads_as_polygons() {
    // 408 quads and 48 triangles; 273 quads are non-planar beyond 1e-6 of their diameter.
    let l = load_path(&repo("scenes/mug.obj"), &POLYGONS).unwrap();
    assert_eq!(
        l.warnings,
        ["mug.obj: split 273 non-planar and 0 non-convex faces into 546 triangles"]
    );
    let sizes: Vec<usize> = (0..l.scene.len()).map(|i| l.scene.prim(i).len()).collect();
    assert_eq!(sizes.iter().filter(|&&n| n == 4).count(), 408 - 273);
    assert_eq!(sizes.iter().filter(|&&n| n == 3).count(), 48 + 546);
    for (i, &n) in sizes.iter().enumerate() {
        assert_eq!(
            l.scene.prim_tris(i).len(),
            n - 2,
            "a convex n-gon is drawn as a fan"
        );
    }
}

#[test]
fn non_convex_and_non_planar_faces_are_split_with_a_warning() {
    let text = "\
v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0
v 0 0 1\nv 1 0 1\nv 1 1 1.3\nv 0 1 1
v 5 0 0\nv 6 0 0\nv 6 1 0\nv 5 1 0\nv 5.5 1.5 0
f 1 2 3 4 5 6
f 7 8 9 10
f 11 12 13 15 14
";
    let l = load_str("split.obj", text, POLYGONS).unwrap();
    assert_eq!(l.scene.len(), 4 + 2 + 1);
    assert_eq!(
        l.warnings,
        ["split.obj: split 1 non-planar and 1 non-convex faces into 6 triangles"]
    );
    // The L's four triangles lie inside the L and cover its area (3).
    let mut area = 0.0;
    for i in 0..4 {
        let v: Vec<P3> = l.scene.prim_vertices(i).copied().collect();
        assert_eq!(v.len(), 3);
        let c = (v[0].coords + v[1].coords + v[2].coords) / 3.0;
        assert!(c.x < 1.0 || c.y < 1.0, "triangle {i} outside the L");
        area += (v[1] - v[0]).cross(&(v[2] - v[0])).norm() / 2.0;
    }
    assert!((area - 3.0).abs() < 1e-12);
    // The convex pentagon stays one polygon, in file order.
    assert_eq!(l.scene.prim(6).len(), 5);
    let first: Vec<P3> = l.scene.prim_vertices(6).copied().collect();
    assert_eq!(first[0], P3::new(5.0, 0.0, 0.0));
    assert_eq!(first[3], P3::new(5.5, 1.5, 0.0));
}

#[test]
fn degenerate_faces_are_dropped_with_a_warning() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 3 0 1e-16\n\
                f 1 2 3\nf 1 2 1\nf 1 2 4\nf 2 4 5\nf 1 2\nf 3 3 3 3\n";
    let l = load_str("degenerate.obj", text, POLYGONS).unwrap();
    assert_eq!(l.scene.len(), 1);
    assert_eq!(
        l.warnings,
        [
            "degenerate.obj: dropped 5 degenerate faces (fewer than 3 distinct vertices or zero area)"
        ]
    );
}

/// A face written twice (once per winding, as double-sided exports write it) and a duplicated
/// vertex position: the loader names the file and counts the coincident primitives.
#[test]
fn coincident_faces_are_counted_in_a_warning() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 0\nv 2 0 0\nv 0 2 0\n\
                f 1 2 3\nf 3 2 4\nf 4 5 6\n";
    let l = load_str("double.obj", text, POLYGONS).unwrap();
    assert_eq!(l.scene.len(), 3);
    assert_eq!(
        l.warnings,
        [
            "double.obj: 2 of 3 primitives have the same vertices as another (double-sided \
             faces or duplicated parts); such pairs tie in every Cost and query, which slows the \
             hull p-set and bench's queries"
        ]
    );
}

const CUBE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";

#[test]
fn polyhedra_groups_become_labelled_convex_polyhedra() {
    let text = format!(
        "{CUBE}v 3 0 0\nv 4 0 0\nv 3 1 0\nv 3 0 1\n\
         o cube\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n\
         o tet\nf 9 11 10\nf 9 10 12\nf 10 11 12\nf 11 9 12\n"
    );
    let l = load_str("two.obj", &text, STRICT).unwrap();
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    assert_eq!(l.scene.len(), 2);
    assert_eq!(l.scene.kind, Some(PrimitiveKind::Polyhedron));
    assert_eq!(l.scene.labels, ["cube", "tet"]);
    assert_eq!((l.scene.prim(0).len(), l.scene.prim_tris(0).len()), (8, 12));
    assert_eq!((l.scene.prim(1).len(), l.scene.prim_tris(1).len()), (4, 4));
}

#[test]
fn non_convex_group_is_hulled_with_a_warning_and_refused_when_strict() {
    // A cube whose top is dented down to an interior point.
    let text = format!(
        "{CUBE}v 0.5 0.5 0.5\no dented\n\
         f 1 4 3 2\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n\
         f 5 6 9\nf 6 7 9\nf 7 8 9\nf 8 5 9\n"
    );
    let l = load_str("dent.obj", &text, POLYHEDRA).unwrap();
    assert_eq!(l.scene.len(), 1);
    assert_eq!(l.warnings.len(), 1);
    assert!(l.warnings[0].contains("'dented'") && l.warnings[0].starts_with("dent.obj: "));
    assert_eq!(
        l.scene.prim(0).len(),
        8,
        "the hull drops the interior point"
    );
    assert!(
        l.scene
            .prim_vertices(0)
            .all(|p| *p != P3::new(0.5, 0.5, 0.5))
    );
    assert_eq!(l.scene.prim_tris(0).len(), 12);
    let e = load_str("dent.obj", &text, STRICT).unwrap_err();
    assert!(e.starts_with("dent.obj: ") && e.contains("'dented'"), "{e}");
    // In polygon mode the same faces are all fine.
    assert_eq!(
        load_str("dent.obj", &text, POLYGONS).unwrap().scene.len(),
        9
    );
}

#[test]
fn flat_group_is_kept_as_drawn_with_a_warning() {
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\ng sheet\nf 1 2 3 4\n";
    let l = load_str("flat.obj", text, STRICT).unwrap();
    assert_eq!(l.scene.len(), 1);
    assert_eq!((l.scene.prim(0).len(), l.scene.prim_tris(0).len()), (4, 2));
    assert_eq!(l.warnings.len(), 1);
    assert!(l.warnings[0].contains("flat") && l.warnings[0].contains("'sheet'"));
}

#[test]
fn loading_the_same_bytes_twice_gives_the_same_scene() {
    for (name, opts) in [
        ("kuka-link0.obj", POLYGONS),
        ("random-urdf-782.obj", POLYHEDRA),
    ] {
        let bytes = std::fs::read(repo(&format!("scenes/{name}"))).unwrap();
        let a = load_bytes(name, bytes.clone(), &opts).unwrap();
        let b = load_bytes(name, a.source.bytes.clone(), &a.source.options).unwrap();
        assert_eq!(a.scene.points, b.scene.points);
        assert_eq!(a.scene.prim_points, b.scene.prim_points);
        assert_eq!(a.scene.prim_start, b.scene.prim_start);
        assert_eq!(a.scene.tris, b.scene.tris);
        assert_eq!(a.scene.labels, b.scene.labels);
        assert_eq!(a.warnings, b.warnings);
        assert_eq!(a.source, b.source);
    }
}

#[test]
fn source_keeps_the_bytes_options_and_sha256() {
    let l = load_str("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", POLYHEDRA).unwrap();
    assert_eq!(l.source.bytes, b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    assert_eq!(l.source.options, POLYHEDRA);
    use sha2::Digest;
    let want: String = sha2::Sha256::digest(&l.source.bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    assert_eq!(l.source.sha256, want);
    assert_eq!(l.source.sha256.len(), 64);
}

#[test]
fn every_bad_file_is_a_one_line_error_naming_the_file() {
    let dir = repo("tests/data/bad");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "obj") {
            continue;
        }
        n += 1;
        assert!(
            BAD.iter().any(|b| path.ends_with(b.0)),
            "{path:?} has no row in BAD"
        );
        // In polyhedra mode a collinear group is a valid (degenerate) primitive.
        let modes: &[LoadOptions] = if path.ends_with("degenerate-only.obj") {
            &[POLYGONS]
        } else {
            &[POLYGONS, POLYHEDRA]
        };
        for &opts in modes {
            let e = load_path(&path, &opts).expect_err(&path.display().to_string());
            let msg = e.to_string();
            assert!(msg.starts_with(&path.display().to_string()), "{msg}");
            assert!(!msg.contains('\n'), "{msg}");
        }
    }
    assert_eq!(
        n,
        BAD.len(),
        "every file in tests/data/bad/ needs a row in BAD"
    );
}

/// Each bad file and (part of) the problem its error must report.
#[rustfmt::skip]
const BAD: &[(&str, &str)] = &[
    ("nan-vertex.obj", "vertex 3 has a non-finite coordinate (nan) (line 4)"),
    ("inf-vertex.obj", "vertex 3 has a non-finite coordinate (inf)"),
    ("overflow-vertex.obj", "vertex 2 has a non-finite coordinate (1e999)"),
    ("huge-coordinate.obj", "vertex 2 has a coordinate beyond"),
    ("zero-weight.obj", "vertex 1 has weight w = 0"),
    ("empty.obj", "no faces"),
    ("comments-only.obj", "no faces"),
    ("vertices-only.obj", "no faces"),
    ("truncated-face.obj", "no faces (1 faces with fewer than 3 vertices were dropped)"),
    ("degenerate-only.obj", "no faces (all 3 faces are degenerate)"),
    ("index-out-of-range.obj", "face 2 refers to vertex 90 but the file has 3 vertices"),
    ("huge-index.obj", "face 1 refers to vertex 2000000000 but the file has 3 vertices"),
    ("index-zero.obj", "face 1 uses vertex index 0"),
    ("relative-before-first.obj", "relative vertex index -5, which reaches before"),
    ("index-overflow.obj", "not a valid OBJ file (line 4: bad face vertex"),
    ("bad-face-token.obj", "not a valid OBJ file (line 4: bad face vertex \"three\")"),
    ("too-many-slashes.obj", "bad face vertex \"1/1/1/1\""),
    ("bad-number.obj", "not a valid OBJ file (line 2: bad number \"zero\")"),
    ("short-vertex.obj", "line 2: vertex 2 needs 3 coordinates"),
    ("truncated-file.obj", "line 5: vertex 4 needs 3 coordinates"),
    ("nul-byte.obj", "line 2: bad number"),
    ("binary-garbage.obj", "not a valid OBJ file (line 2: not UTF-8 text)"),
    ("pybullet-168-nan.obj", "vertex 1 has a non-finite coordinate (nan) (line 5)"),
];

#[test]
fn bad_files_report_the_specific_problem() {
    for &(name, want) in BAD {
        let e = load_path(&repo(&format!("tests/data/bad/{name}")), &POLYGONS).unwrap_err();
        let msg = e.to_string();
        assert!(msg.ends_with(&format!("{name}: {}", e.problem)), "{msg}");
        assert!(
            e.problem.contains(want),
            "{name}: got {msg:?}, want {want:?}"
        );
    }
}

#[test]
fn valid_relative_indices_crlf_weights_and_colours_load() {
    let text = "o a\r\nv 0 0 0 2\r\nv 2 0 0 2\r\nv 0 2 0 2\r\nf -3 -2 -1\r\n\
                v 5 0 0 1 0 0\r\nv 6 0 0 0 1 0\r\nv 5 1 0 0 0 1\r\nf -3/1/1 -2//2 -1/2\r\n\
                vt 0 0\r\nvn 0 0 1\r\nl 1 2 3\r\nmtllib none.mtl\r\nusemtl x\r\n";
    let l = load_str("rel.obj", text, POLYGONS).unwrap();
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    assert_eq!(l.scene.len(), 2, "the polyline `l 1 2 3` is not a face");
    let v: Vec<P3> = l.scene.prim_vertices(0).copied().collect();
    assert_eq!(
        v,
        [
            P3::new(0.0, 0.0, 0.0),
            P3::new(1.0, 0.0, 0.0),
            P3::new(0.0, 1.0, 0.0)
        ]
    );
    assert_eq!(
        l.scene.prim_vertices(1).next(),
        Some(&P3::new(5.0, 0.0, 0.0))
    );
}

#[test]
fn missing_file_is_a_read_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("nope.obj");
    let e = load_path(&path, &POLYGONS).unwrap_err().to_string();
    assert_eq!(
        e,
        format!("{}: cannot read: No such file or directory", path.display())
    );
    let e = load_path(dir.path(), &POLYGONS).unwrap_err().to_string();
    assert!(e.contains("cannot read"), "{e}");
}

#[test]
fn generators_have_the_paper_counts() {
    assert_eq!(robot_base().len(), 276);
    assert_eq!(lamp().len(), 626);
    assert_eq!(replicate(&lamp(), 5, 7).len(), 3130);
    assert_eq!(replicate(&robot_base(), 44, 7).len(), 12_144);
    assert_eq!(by_name("lamps", None, None, 1).unwrap().len(), 3130);
    assert_eq!(by_name("robot-bases", None, None, 1).unwrap().len(), 12_144);
    assert_eq!(
        by_name("robot-bases", None, None, 1).unwrap().name,
        "robot-bases44"
    );
    assert_eq!(by_name("lamps", Some(2), None, 1).unwrap().name, "lamps2");
    assert_eq!(by_name("soup", None, None, 1).unwrap().len(), 10_000);
    assert_eq!(by_name("soup", None, Some(7), 1).unwrap().len(), 7);
    assert_eq!(
        by_name("robot-base", None, None, 1).unwrap().name,
        "robot-base"
    );
    let e = by_name("teapot", None, None, 0).unwrap_err();
    for k in generate::KINDS {
        assert!(e.contains(k), "{e}");
    }
    assert!(by_name("lamp", Some(3), None, 0).is_err());
    assert!(by_name("lamps", None, Some(3), 0).is_err());
    assert!(by_name("soup", None, Some(0), 0).is_err());
}

#[test]
fn generators_are_seeded_and_reproducible() {
    let a = replicate(&robot_base(), 44, 3);
    let b = replicate(&robot_base(), 44, 3);
    let c = replicate(&robot_base(), 44, 4);
    assert_eq!(a.points, b.points);
    assert_ne!(a.points, c.points);
    assert_eq!(a.prim_points, c.prim_points);
    // The first copy stays in place; the others move.
    let base = robot_base();
    assert_eq!(a.points[..base.points.len()], base.points[..]);
    assert_ne!(
        a.points[base.points.len()..2 * base.points.len()],
        base.points[..]
    );
    assert_eq!(soup(1000, 9).points, soup(1000, 9).points);
    assert_ne!(soup(1000, 9).points, soup(1000, 10).points);
    assert_eq!(lamp().points, lamp().points);
}

#[test]
fn replicas_overlap_somewhat() {
    let base = lamp();
    let s = replicate(&base, 5, 0);
    let boxes: Vec<_> = (0..5)
        .map(|k| {
            let n = base.points.len();
            wraptree::geom::Aabb::from_points(&s.points[k * n..(k + 1) * n])
        })
        .collect();
    let touching = (1..5)
        .filter(|&k| (0..k).any(|j| boxes[j].gap_linf(&boxes[k]) == 0.0))
        .count();
    assert!(touching >= 2, "copies are too far apart");
    let whole = s.aabb().diameter();
    assert!(
        whole < 4.0 * base.aabb().diameter(),
        "copies are spread too far"
    );
}

#[test]
fn soup_has_n_triangles_in_the_unit_cube() {
    let s = soup(1_000_000, 1);
    assert_eq!(s.len(), 1_000_000);
    assert_eq!(s.tris.len(), 1_000_000);
    assert_eq!(s.name, "soup1000000");
    let b = s.aabb();
    assert!(
        b.min.iter().all(|&c| c > -0.02) && b.max.iter().all(|&c| c < 1.02),
        "{b:?}"
    );
    let small = soup(20, 1);
    assert!((0..20).all(|i| small.prim(i).len() == 3 && small.prim_tris(i).len() == 1));
    assert!(soup(0, 1).is_empty());
}

#[test]
fn generated_polygons_are_planar_convex_and_round_trip_through_obj() {
    for s in [
        robot_base(),
        lamp(),
        replicate(&lamp(), 5, 2),
        soup(2000, 5),
    ] {
        let l = load_bytes("gen.obj", obj_text(&s), &POLYGONS).unwrap();
        assert!(l.warnings.is_empty(), "{}: {:?}", s.name, l.warnings);
        assert_eq!(l.scene.len(), s.len(), "{}", s.name);
        assert_eq!(prim_points(&l.scene), prim_points(&s), "{}", s.name);
    }
}

#[test]
fn polyhedra_round_trip_through_obj() {
    let a = load_path(&repo("scenes/random-urdf-350.obj"), &POLYHEDRA).unwrap();
    let b = load_bytes("again.obj", obj_text(&a.scene), &STRICT).unwrap();
    assert_eq!(b.scene.len(), a.scene.len());
    assert_eq!(b.scene.labels, a.scene.labels);
    assert_eq!(prim_point_sets(&b.scene), prim_point_sets(&a.scene));
}

/// One line of OBJ-like text, valid or not (mostly faces over the first few vertices).
fn obj_line() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => "f( -?[1-4](/[0-9]?){0,2}){3,6}",
        1 => "v( -?[0-9]{1,2}(\\.[0-9])?| nan| inf| 1e999| x){0,7}",
        1 => "f( -?[0-9]{1,2}(/-?[0-9]?){0,3}| 99999999999){0,6}",
        1 => "(o|g)( [a-z]{0,3})?",
        1 => "(vt|vn|l|p|s|usemtl|mtllib|#)( [ -~]{0,8})?",
        1 => "[ -~]{0,12}",
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn obj_loading_never_panics_and_errors_name_the_file(
        verts in prop::collection::vec("v -?[0-9](\\.[0-9]{1,3})? -?[0-9] -?[0-9]\\.[0-9]", 4..12),
        lines in prop::collection::vec(obj_line(), 0..16),
        polyhedra in any::<bool>(),
        strict in any::<bool>(),
    ) {
        let text = [verts, lines].concat().join("\n");
        let opts = LoadOptions {
            polyhedra,
            strict,
            up: None,
        };
        match load_bytes("fuzz.obj", text.clone().into_bytes(), &opts) {
            Ok(l) => {
                prop_assert!(!l.scene.is_empty());
                prop_assert!(all_finite(&l.scene));
                for i in 0..l.scene.len() {
                    prop_assert!(l.scene.prim(i).iter().all(|&v| (v as usize) < l.scene.points.len()));
                }
                let again = load_bytes("fuzz.obj", text.into_bytes(), &opts).unwrap();
                prop_assert_eq!(again.scene.points, l.scene.points);
            }
            Err(e) => {
                let msg = e.to_string();
                prop_assert!(msg.starts_with("fuzz.obj: ") && !msg.contains('\n'), "{}", msg);
            }
        }
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        if let Err(e) = load_bytes("bytes.obj", bytes, &POLYGONS) {
            prop_assert!(e.to_string().starts_with("bytes.obj: "));
        }
    }
}
