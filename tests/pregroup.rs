//! Pre-grouping and instancing (the paper's §1.3 speed-ups): components and copies found on
//! hand-made scenes, valid trees identical for any thread count, recordings that replay.

mod common;

use common::{check_tree, wraptree};
use nalgebra::{Rotation3, Vector3};
use wraptree::geom::{P3, V3};
use wraptree::grouping::{
    self, EventLog, Grouping, Merge, Mode, Params, PartKind, Pregroup, pregroup::MIN_PART,
};
use wraptree::scene::{PrimitiveKind, Scene, components, generate};

/// A closed, slightly irregular prism of `sides` quads and two caps (sides + 2 polygons, all
/// sharing vertices: one connected component), its points mapped by `f`.
fn prism(s: &mut Scene, sides: usize, f: impl Fn(P3) -> P3) {
    let base = s.points.len() as u32;
    for ring in 0..2 {
        for j in 0..sides {
            let a = std::f64::consts::TAU * j as f64 / sides as f64;
            // Radius varies with j so that the part has no rotational symmetry.
            let r = 1.0 + 0.05 * j as f64;
            s.points
                .push(f(P3::new(r * a.cos(), r * a.sin(), 2.0 * ring as f64)));
        }
    }
    let n = sides as u32;
    for j in 0..n {
        let k = (j + 1) % n;
        let q = [base + j, base + k, base + n + k, base + n + j];
        s.push(
            PrimitiveKind::Polygon,
            &q,
            &[[q[0], q[1], q[2]], [q[0], q[2], q[3]]],
        );
    }
    for cap in 0..2 {
        let mut v: Vec<u32> = (0..n).map(|j| base + cap * n + j).collect();
        if cap == 0 {
            v.reverse();
        }
        let tris: Vec<[u32; 3]> = (1..v.len() - 1).map(|k| [v[0], v[k], v[k + 1]]).collect();
        s.push(PrimitiveKind::Polygon, &v, &tris);
    }
}

const SIDES: usize = 16;

fn rot(axis: [f64; 3], angle: f64) -> Rotation3<f64> {
    Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(Vector3::new(axis[0], axis[1], axis[2])),
        angle,
    )
}

/// A (the part), B and C (moved and rotated copies), D (a mirrored copy), E (a near-copy, one
/// vertex off by 1e-3 of its size), F+G (two parts touching at one vertex: one component).
fn hand_made() -> Scene {
    let mut s = Scene::new("hand-made");
    prism(&mut s, SIDES, |p| p);
    let (r1, t1) = (rot([1.0, 2.0, 3.0], 0.9), V3::new(10.0, 0.0, 0.0));
    prism(&mut s, SIDES, |p| r1 * p + t1);
    let (r2, t2) = (rot([0.0, -1.0, 0.5], 2.5), V3::new(0.0, 10.0, 1.0));
    prism(&mut s, SIDES, |p| r2 * p + t2);
    prism(&mut s, SIDES, |p| {
        P3::new(-p.x, p.y, p.z) + V3::new(0.0, 0.0, 10.0)
    });
    let e_start = s.points.len();
    prism(&mut s, SIDES, |p| p + V3::new(10.0, 10.0, 0.0));
    s.points[e_start + 3].x += 3e-3;
    prism(&mut s, SIDES, |p| p + V3::new(-10.0, 0.0, 0.0));
    // G's first vertex lands exactly on F's (up to rounding of the motion): they touch.
    let f0 = s.points[s.points.len() - 2 * SIDES];
    let g_shift = f0 - rot([0.0, 0.0, 1.0], 1.0) * P3::new(1.0, 0.0, 0.0);
    prism(&mut s, SIDES, |p| rot([0.0, 0.0, 1.0], 1.0) * p + g_shift);
    s
}

fn params(pregroup: Pregroup, instancing: bool) -> Params {
    Params {
        mode: Mode {
            pregroup,
            instancing,
            ..Mode::default()
        },
        ..Params::default()
    }
}

fn run_on(threads: usize, scene: &Scene, p: &Params) -> (Grouping, EventLog) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| common::run(scene, p))
}

/// A part's merges with ids made local: its leaves by rank, its new bodies from `leaves`.
fn local_shape(merges: &[Merge], leaves: &[u32]) -> Vec<[u32; 2]> {
    let first = merges[0].new;
    let k = leaves.len() as u32;
    let local = |x: u32| match leaves.binary_search(&x) {
        Ok(i) => i as u32,
        Err(_) => k + (x - first),
    };
    merges.iter().map(|m| [local(m.a), local(m.b)]).collect()
}

#[test]
fn components_and_copies_are_found_on_a_hand_made_scene() {
    let s = hand_made();
    let part = SIDES + 2;
    let c = components::connected(&s);
    assert_eq!(c.len(), 6, "A, B, C, D, E and F+G");
    assert_eq!(c.get(5).len(), 2 * part, "touching parts are one component");
    assert_eq!(c.get(1), (part as u32..2 * part as u32).collect::<Vec<_>>());

    let (g, log) = common::run(&s, &params(Pregroup::Connected, true));
    check_tree(&s, &g, &log);
    let report = g.pregrouping.expect("a pre-grouped run reports");
    assert_eq!((report.components, report.parts), (6, 6));
    assert_eq!(
        report.copies, 2,
        "B and C; not the mirror D nor the near-copy E"
    );
    assert_eq!(report.classes, 1);
    assert_eq!(report.primitives_saved as usize, 2 * part);
    let kinds: Vec<PartKind> = log.parts.iter().map(|p| p.kind).collect();
    assert!(matches!(kinds[0], PartKind::Component { index: 0 }));
    for (k, r) in [
        (1, rot([1.0, 2.0, 3.0], 0.9)),
        (2, rot([0.0, -1.0, 0.5], 2.5)),
    ] {
        let PartKind::Copy {
            of,
            rotation,
            translation,
        } = kinds[k]
        else {
            panic!("part {k} is a copy: {:?}", kinds[k]);
        };
        assert_eq!(of, 0);
        let m = r.matrix();
        for i in 0..9 {
            assert!(
                (rotation[i] - m[(i / 3, i % 3)]).abs() < 1e-9,
                "{rotation:?}"
            );
        }
        assert!(translation.iter().all(|x| x.is_finite()));
    }
    for k in 3..6 {
        assert!(matches!(kinds[k], PartKind::Component { .. }), "{kinds:?}");
    }
    assert_eq!(kinds[6], PartKind::Top);
    assert_eq!(log.parts[6].bodies, 6);
    // Each copy has A's shape over its own primitives, with its own (rotated) boxes.
    let merges_of = |p: usize| {
        let first = log.parts[p].first_step as usize;
        &log.merges[first..first + part - 1]
    };
    let shape_a = local_shape(merges_of(0), c.get(0));
    for k in 1..3 {
        assert_eq!(local_shape(merges_of(k), c.get(k)), shape_a);
        let root = merges_of(k).last().unwrap();
        let own = c.get(k).iter().fold(wraptree::geom::Aabb::EMPTY, |b, &i| {
            b.merge(&s.prim_aabb(i as usize))
        });
        assert_eq!(root.aabb, own, "the copy's root box is its own geometry's");
    }
}

#[test]
fn trees_are_valid_and_identical_for_one_and_two_threads() {
    let scenes = [
        hand_made(),
        generate::replicate(&generate::robot_base(), 3, 1),
        generate::replicate(&generate::lamp(), 2, 4),
    ];
    for s in &scenes {
        for (pregroup, instancing) in [
            (Pregroup::Connected, false),
            (Pregroup::Connected, true),
            (Pregroup::Objects, false),
            (Pregroup::Objects, true),
        ] {
            let p = params(pregroup, instancing);
            let (g1, log1) = run_on(1, s, &p);
            let (g2, log2) = run_on(2, s, &p);
            check_tree(s, &g1, &log1);
            assert_eq!(g1.tree, g2.tree, "{} {pregroup:?} {instancing}", s.name);
            assert_eq!(log1, log2, "{} {pregroup:?} {instancing}", s.name);
            assert_eq!(g1.pregrouping.unwrap().threads, 1);
            assert_eq!(g2.pregrouping.unwrap().threads, 2);
            // The silent run makes the same tree as the listened-to one.
            let silent = run_on(2, s, &p).0;
            assert_eq!(grouping::group(s, &p, ()).tree, silent.tree);
        }
    }
}

#[test]
fn replicas_are_found_as_objects_and_as_copies() {
    let s = generate::replicate(&generate::robot_base(), 4, 1);
    let (g, log) = common::run(&s, &params(Pregroup::Objects, true));
    check_tree(&s, &g, &log);
    let r = g.pregrouping.unwrap();
    assert_eq!((r.components, r.parts, r.copies, r.classes), (4, 4, 3, 1));
    assert_eq!(r.primitives_saved, 3 * 276);
    let (g, log) = common::run(&s, &params(Pregroup::Connected, true));
    check_tree(&s, &g, &log);
    let r = g.pregrouping.unwrap();
    // Per base: cylinder, washer, boss, six bolt heads (copies of one another) and the box.
    assert_eq!((r.components, r.parts, r.loose), (40, 40, 0));
    assert_eq!((r.classes, r.copies), (5, 35));
    const { assert!(MIN_PART <= 6, "the 6-face box is a part") };
}

#[test]
fn a_soup_of_single_triangles_groups_as_the_plain_run() {
    let s = generate::soup(3000, 5);
    let (plain, plain_log) = common::run(&s, &Params::default());
    let (pre, pre_log) = common::run(&s, &params(Pregroup::Connected, true));
    assert_eq!(pre.tree, plain.tree);
    assert_eq!(pre_log.merges, plain_log.merges);
    let r = pre.pregrouping.unwrap();
    assert_eq!((r.parts, r.loose), (0, 3000));
}

#[test]
fn objects_survive_writing_and_loading_obj() {
    let s = generate::replicate(&generate::lamp(), 3, 2);
    let mut bytes = Vec::new();
    s.write_obj(&mut bytes).unwrap();
    let loaded = wraptree::scene::load_bytes("lamps3.obj", bytes, &Default::default()).unwrap();
    assert_eq!(loaded.scene.objects, s.objects);
    assert_eq!(components::objects(&loaded.scene).len(), 3);
}

#[test]
fn welding_joins_vertices_within_the_tolerance_only() {
    let tri = |s: &mut Scene, a: P3| {
        let b = s.points.len() as u32;
        s.points
            .extend([a, a + V3::new(1.0, 0.0, 0.0), a + V3::new(0.0, 1.0, 0.0)]);
        s.push(
            PrimitiveKind::Polygon,
            &[b, b + 1, b + 2],
            &[[b, b + 1, b + 2]],
        );
    };
    for (offset, parts) in [(1e-9, 1), (1e-3, 2)] {
        let mut s = Scene::new("two");
        tri(&mut s, P3::origin());
        // The second triangle's corner sits `offset` from the first one's right-hand corner.
        tri(&mut s, P3::new(1.0 + offset, 0.0, 0.0));
        assert_eq!(components::connected(&s).len(), parts, "offset {offset}");
    }
}

#[test]
fn pregrouped_recordings_replay_identically() {
    let dir = tempfile::tempdir().unwrap();
    let out = wraptree(
        &["scene", "robot-bases", "--copies", "3", "-o", "rb3.obj"],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for (prefix, extra) in [
        ("conn", vec!["--pregroup", "connected"]),
        ("inst", vec!["--pregroup", "objects", "--instancing"]),
    ] {
        let mut args = vec!["record", "rb3.obj", "-o", prefix, "--detail", "levels"];
        args.extend(extra);
        let out = wraptree(&args, dir.path());
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let mcap = format!("{prefix}.mcap");
        let out = wraptree(&["replay", &mcap, "--verify"], dir.path());
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(text.contains("identical (827 merges)"), "{text}");
    }
    let out = wraptree(
        &[
            "group",
            "rb3.obj",
            "--pregroup",
            "objects",
            "--instancing",
            "--json",
        ],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let p = &v["pregrouping"];
    assert_eq!(p["copies"].as_u64(), Some(2));
    assert_eq!(p["classes"].as_u64(), Some(1));
    assert_eq!(p["primitives_saved"].as_u64(), Some(552));
    assert_eq!(v["parent"].as_array().unwrap().len(), 2 * 828 - 1);
    let args = [
        "group",
        "rb3.obj",
        "--pregroup",
        "connected",
        "--instancing",
    ];
    let text = common::printed(&args, dir.path());
    assert!(
        text.contains("instancing") && text.contains("copies"),
        "{text}"
    );
}

#[test]
fn bad_pregroup_flags_give_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    let s = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/robot-base.obj");
    let s = s.to_str().unwrap();
    let out = wraptree(&["group", s, "--instancing"], dir.path());
    common::assert_one_line_error(&out, "--instancing");
    let out = wraptree(&["group", s, "--pregroup", "sideways"], dir.path());
    common::assert_one_line_error(&out, "--pregroup");
    let out = wraptree(
        &["group", s, "--pregroup", "connected", "--pset", "hull"],
        dir.path(),
    );
    common::assert_one_line_error(&out, "--pregroup");
    let out = wraptree(
        &["record", s, "-o", "r", "--instancing", "--pregroup", "none"],
        dir.path(),
    );
    common::assert_one_line_error(&out, "--instancing");
    assert!(!dir.path().join("r.mcap").exists());
}
