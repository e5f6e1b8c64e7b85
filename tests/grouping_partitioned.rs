//! The partitioned schedule: valid trees on bundled and property-generated scenes, the same
//! result on 1 and 2 threads, the exact schedule's tree for a scene smaller than one chunk,
//! parts announced before their merges, `replay --verify` of a partitioned recording, the same
//! trees from primitive boxes; and the exact schedule's merge sequence unchanged by its parallel
//! round-start scan.

mod common;

use common::{check_tree, run, wraptree};
use proptest::prelude::*;
use std::sync::atomic::AtomicBool;
use wraptree::grouping::partitioned::{Chunking, group_with};
use wraptree::grouping::{
    Budget, EventLog, Mode, PSet, Params, PartKind, Schedule, StopReason, Weights, group,
    group_boxes, group_within,
};
use wraptree::scene::pathological as path;
use wraptree::scene::{LoadOptions, generate};

/// The chunking of a partitioned `mode`.
fn chunking(mode: &Mode) -> Chunking {
    *mode.schedule.chunking().expect("a partitioned schedule")
}

/// The chunking an older recording's `wraptree` record `m` (without `format_version`) is read
/// with.
fn legacy(m: &std::collections::BTreeMap<String, String>) -> anyhow::Result<Chunking> {
    use wraptree::record::mcap::metadata;
    let params = metadata::params(&metadata::current_form(m.clone())?)?;
    Ok(chunking(&params.mode))
}

fn partitioned(mut p: Params) -> Params {
    p.mode = Mode {
        schedule: Schedule::PARTITIONED,
        ..Mode::default()
    };
    p
}

/// `f` in a rayon pool of `threads` threads.
fn on<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

fn arb_params() -> impl Strategy<Value = Params> {
    (
        prop_oneof![Just(0.0), Just(1.0), Just(2.0)],
        prop_oneof![Just(0.0), Just(0.5), Just(1.0)],
        prop_oneof![Just(0.0), Just(1.0)],
        prop::option::of(0.01f64..20.0),
        prop::option::of(0.01f64..20.0),
        prop::option::of(any::<u64>()),
    )
        .prop_map(|(a, b, c, dlimit, glimit, seed)| {
            partitioned(Params {
                weights: Weights { a, b, c },
                dlimit,
                glimit,
                pset: PSet::Aabb,
                seed,
                mode: Mode::default(),
            })
        })
}

/// Parts come before their merges: each part's `first_step` is the number of merges before it,
/// it makes `bodies - keep` merges (all the rest for the top, which comes last; the merges of
/// identical boxes, first, up to the next part), ids in order.
fn check_parts(n: usize, log: &EventLog) {
    let mut step = 0u32;
    for (i, p) in log.parts.iter().enumerate() {
        assert_eq!(p.id as usize, i);
        assert_eq!(p.first_step, step, "part {i} starts where the last ended");
        if p.kind == PartKind::Twins {
            assert_eq!(i, 0, "identical boxes come first");
            let end = log.parts.get(1).map_or(n as u32 - 1, |q| q.first_step);
            assert!(end > 0 && end < p.bodies, "part {i} merges something");
            step = end;
            continue;
        }
        let keep = match p.kind {
            PartKind::Chunk { keep, .. } => keep,
            PartKind::Top => {
                assert_eq!(i + 1, log.parts.len(), "the top comes last");
                1
            }
            k => panic!("unexpected part kind {k:?}"),
        };
        assert!(keep < p.bodies, "part {i} merges something");
        step += p.bodies - keep;
    }
    assert_eq!(step as usize, n - 1, "the parts hold every merge");
}

#[test]
fn bundled_scenes_give_valid_trees_on_1_and_2_threads() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    files.sort();
    assert!(files.len() >= 5);
    for f in files {
        let scene = wraptree::scene::load_path(&f, &LoadOptions::default())
            .unwrap()
            .scene;
        let params = partitioned(Params::default());
        let (g1, log1) = on(1, || run(&scene, &params));
        check_tree(&scene, &g1, &log1);
        if scene.len() > 1 {
            check_parts(scene.len(), &log1);
        }
        let (g2, log2) = on(2, || run(&scene, &params));
        assert_eq!(g1.tree, g2.tree, "{}", f.display());
        assert_eq!(log1, log2, "{}", f.display());
    }
}

#[test]
fn large_soup_is_the_same_on_1_and_2_threads_and_close_to_exact() {
    let scene = generate::soup(30_000, 7);
    let params = partitioned(Params::default());
    let (g1, log1) = on(1, || run(&scene, &params));
    check_tree(&scene, &g1, &log1);
    check_parts(scene.len(), &log1);
    let (g2, log2) = on(2, || run(&scene, &params));
    assert_eq!(g1.tree, g2.tree);
    assert_eq!(log1, log2);
    // Without a listener the tree is the same.
    let silent = on(2, || group(&scene, &params, ()));
    assert_eq!(silent.tree, g1.tree);
    assert_eq!(silent.rounds, g1.rounds);
    // The chunks' trees are the exact grouping's in quality terms (SAH within 5 %).
    let exact = group(&scene, &Params::default(), ());
    let (s_p, s_e) = (
        wraptree::metrics::sah(&g1.tree),
        wraptree::metrics::sah(&exact.tree),
    );
    assert!(s_p < 1.05 * s_e, "SAH partitioned {s_p} vs exact {s_e}");
}

#[test]
fn grouping_from_boxes_gives_the_scenes_tree() {
    // What the bench times: the tree, counters and resolved limits of `group` on both schedules.
    let scene = generate::soup(20_000, 5);
    let boxes: Vec<_> = (0..scene.len()).map(|i| scene.prim_aabb(i)).collect();
    for params in [Params::default(), partitioned(Params::default())] {
        let from_scene = group(&scene, &params, ());
        let resolved = params.resolve_boxes(&boxes);
        assert_eq!(resolved, params.resolve(&scene));
        let from_boxes = group_boxes(boxes.clone(), &resolved, ());
        assert_eq!(from_boxes.tree, from_scene.tree, "{:?}", params.mode);
        assert_eq!(from_boxes.stats, from_scene.stats);
        assert_eq!(from_boxes.rounds, from_scene.rounds);
    }
}

#[test]
fn exact_schedule_is_the_same_with_the_parallel_scan() {
    // Above the parallel scan's threshold of active bodies, with and without ties by seed.
    let scene = generate::soup(20_000, 3);
    for seed in [None, Some(11)] {
        let params = Params {
            seed,
            ..Params::default()
        };
        let (g1, log1) = on(1, || run(&scene, &params));
        let (g2, log2) = on(2, || run(&scene, &params));
        assert_eq!(log1, log2, "seed {seed:?}");
        assert_eq!(g1.stats, g2.stats, "seed {seed:?}");
        assert_eq!(g1.tree, g2.tree);
    }
}

#[test]
fn a_scene_smaller_than_a_chunk_gets_the_exact_tree() {
    // The default chunk (δ = 4) and a wide one, so that the brute-force step meets scenes of
    // up to 63 primitives; and a root share of 40, whose scenes of up to 60 primitives are one
    // subproblem ([`Chunking::whole`]).
    for (chunking, max_n) in [
        (
            Chunking::DEFAULT.for_size(usize::MAX),
            Chunking::LARGE_DELTA as usize,
        ),
        (
            Chunking {
                top: 40,
                ..Chunking::DEFAULT
            },
            60,
        ),
        (
            Chunking {
                delta: 64,
                ..Chunking::DEFAULT
            },
            64,
        ),
    ] {
        let mut runner = proptest::test_runner::TestRunner::deterministic();
        runner
            .run(
                &(common::arb_triangles(1, max_n), arb_params()),
                |(scene, params)| {
                    let exact = Params {
                        mode: Mode::default(),
                        ..params.clone()
                    };
                    let resolved = params.resolve(&scene);
                    let mut lp = EventLog::default();
                    let gp = group_with(&scene, &resolved, &chunking, &mut lp, &Budget::default())
                        .unwrap();
                    let (ge, le) = run(&scene, &exact);
                    prop_assert_eq!(&gp.tree, &ge.tree);
                    let pairs = |l: &EventLog| {
                        l.merges
                            .iter()
                            .map(|m| (m.a, m.b, m.round, m.cost.to_bits(), m.active))
                            .collect::<Vec<_>>()
                    };
                    prop_assert_eq!(pairs(&lp), pairs(&le));
                    prop_assert_eq!(&lp.dormant, &le.dormant);
                    prop_assert_eq!(gp.rounds, ge.rounds);
                    prop_assert_eq!(le.parts.len(), 0);
                    prop_assert_eq!(lp.parts.len(), usize::from(scene.len() > 1));
                    Ok(())
                },
            )
            .unwrap();
    }
}

#[test]
fn with_delta_2_nodes_merge_their_halves_the_same_on_any_thread_count() {
    // δ = 2 (the fast path's): below the root share every node keeps one body; the tree is
    // valid, announced in full, and the same on 1 and 2 threads.
    let scene = generate::soup(3_000, 13);
    let resolved = Params::default().resolve(&scene);
    let run = |threads| {
        let chunking = Chunking {
            top: 32,
            delta: 2,
            ..Chunking::DEFAULT
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut log = EventLog::default();
        let g = pool
            .install(|| group_with(&scene, &resolved, &chunking, &mut log, &Budget::default()))
            .unwrap();
        check_tree(&scene, &g, &log);
        g.tree
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn the_fast_path_merges_identical_boxes_first_the_same_on_any_thread_count() {
    // Every triangle twice (double-sided faces), three times, and 300 copies of one triangle:
    // the fast path merges identical boxes first, announced as one part, then splits the rest.
    let mut fast = Params::default();
    fast.mode.schedule = Schedule::FAST;
    let cases = [
        (path::duplicates(4_000, 2, 3), 2_000, 4_000),
        (path::duplicates(900, 3, 5), 600, 900),
        (path::coincident(300), 299, 300),
    ];
    for (scene, merges, bodies) in cases {
        let (g1, log1) = on(1, || run(&scene, &fast));
        check_tree(&scene, &g1, &log1);
        check_parts(scene.len(), &log1);
        let twins = &log1.parts[0];
        assert_eq!((twins.kind, twins.bodies), (PartKind::Twins, bodies));
        let end = log1
            .parts
            .get(1)
            .map_or(scene.len() - 1, |p| p.first_step as usize);
        assert_eq!(end, merges, "{}", scene.name);
        assert_eq!(g1.stats.identical, merges as u64, "{}", scene.name);
        for m in &log1.merges[..end] {
            let aabb = &g1.tree.aabb;
            assert_eq!(aabb[m.a as usize], aabb[m.b as usize], "{}", scene.name);
            assert_eq!((m.round, m.fill), (0, 0.5));
        }
        let (g2, log2) = on(2, || run(&scene, &fast));
        assert_eq!(g1.tree, g2.tree, "{}", scene.name);
        assert_eq!(log1, log2, "{}", scene.name);
        let silent = on(2, || group(&scene, &fast, ()));
        assert_eq!(silent.tree, g1.tree, "{}", scene.name);
    }
    // A scene without identical boxes gets the tree it got without the twins step; with them
    // off, a doubled scene is split whole (another valid tree, no twins part).
    let mut off = fast.clone();
    off.mode.schedule = Schedule::Partitioned(Chunking {
        twins: false,
        ..Chunking::FAST
    });
    let soup = generate::soup(3_000, 9);
    let (with, log) = run(&soup, &fast);
    assert_eq!(with.tree, group(&soup, &off, ()).tree);
    assert!(log.parts.iter().all(|p| p.kind != PartKind::Twins));
    let doubled = path::duplicates(2_000, 2, 4);
    let (g, log) = run(&doubled, &off);
    check_tree(&doubled, &g, &log);
    assert!(log.parts.iter().all(|p| p.kind != PartKind::Twins));
    assert_eq!((with.stats.identical, g.stats.identical), (0, 0));
    // `group` says how many such merges the fast path made, and only when it made some.
    let dir = tempfile::tempdir().unwrap();
    let mut obj = Vec::new();
    doubled.write_obj(&mut obj).unwrap();
    std::fs::write(dir.path().join("d.obj"), obj).unwrap();
    let text = common::printed(&["group", "d.obj", "--fast"], dir.path());
    assert!(
        text.contains("identical   1000 merges of neighbours with identical boxes"),
        "{text}"
    );
    let text = common::printed(&["group", "d.obj", "--schedule", "partitioned"], dir.path());
    assert!(!text.contains("identical"), "{text}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn generated_scenes_give_valid_trees_identical_on_1_and_2_threads(
        scene in common::arb_triangles(1, 400),
        params in arb_params(),
    ) {
        // The default chunking gives these scenes (≤ `top` primitives) the exact tree; AAC's
        // reduction alone and a small root share run the chunks (of δ = 4, the default's for
        // large scenes).
        let resolved = params.resolve(&scene);
        for top in [Chunking::DEFAULT.top, 0, 100] {
            let chunking = Chunking { top, ..Chunking::DEFAULT.for_size(usize::MAX) };
            let run = || {
                let mut log = EventLog::default();
                let g = group_with(&scene, &resolved, &chunking, &mut log, &Budget::default());
                (g.unwrap(), log)
            };
            let (g1, log1) = on(1, run);
            check_tree(&scene, &g1, &log1);
            if scene.len() > 1 {
                check_parts(scene.len(), &log1);
            }
            let (g2, log2) = on(2, run);
            prop_assert_eq!(&g1.tree, &g2.tree);
            prop_assert_eq!(&log1, &log2);
        }
    }
}

#[test]
fn hull_pset_runs_the_exact_schedule() {
    let scene = generate::soup(200, 5);
    let params = partitioned(Params {
        pset: PSet::Hull,
        ..Params::default()
    });
    let exact = Params {
        pset: PSet::Hull,
        ..Params::default()
    };
    let (gp, lp) = run(&scene, &params);
    let (ge, le) = run(&scene, &exact);
    assert_eq!(gp.tree, ge.tree);
    assert_eq!(lp.merges, le.merges);
}

#[test]
fn the_cli_refuses_a_partitioned_schedule_of_hulls_instead_of_reporting_one() {
    // The library runs the exact schedule for hulls (above); `group` used to print a
    // partitioned schedule with its chunks for that run.
    let dir = common::soup_dir(300, 2);
    for args in [
        &["--schedule", "partitioned"][..],
        &["--schedule", "partitioned", "--chunk-delta", "64"],
        &["--fast"],
    ] {
        let out = wraptree(
            &[&["group", "s.obj", "--pset", "hull"][..], args].concat(),
            dir.path(),
        );
        common::assert_one_line_error(&out, "needs --pset aabb (the hull p-set has no partitioned");
    }
    let out = wraptree(
        &["record", "s.obj", "--fast", "--pset", "hull", "-o", "h"],
        dir.path(),
    );
    common::assert_one_line_error(&out, "--fast needs --pset aabb");
    assert!(!dir.path().join("h.mcap").exists() && !dir.path().join("h.rrd").exists());
    let text = common::printed(&["group", "s.obj", "--pset", "hull"], dir.path());
    assert!(text.contains("schedule    Exact"), "{text}");
}

#[test]
fn a_stopped_run_reports_a_prefix_of_the_merges() {
    let scene = generate::soup(5_000, 9);
    let params = partitioned(Params::default()).resolve(&scene);
    let stop = AtomicBool::new(true);
    let budget = Budget {
        stop: Some(&stop),
        ..Budget::default()
    };
    let mut log = EventLog::default();
    let s = group_within(&scene, &params, &mut log, &budget).unwrap_err();
    assert_eq!(s.reason, StopReason::Interrupted);
    assert_eq!(s.merges as usize, log.merges.len());
    assert_eq!(log.root, None);
    let budget = Budget {
        max_pairs: Some(100),
        ..Budget::default()
    };
    let mut cut = EventLog::default();
    let s = group_within(&scene, &params, &mut cut, &budget).unwrap_err();
    assert_eq!(s.reason, StopReason::MaxPairs);
    let (_, full) = run(&scene, &partitioned(Params::default()));
    assert!(cut.merges.len() < full.merges.len());
    assert_eq!(cut.merges[..], full.merges[..cut.merges.len()]);
}

/// The recording `path` that the command whose output is `out` wrote (which must have succeeded).
fn recorded(
    out: &std::process::Output,
    path: &std::path::Path,
) -> wraptree::record::mcap::Recorded {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    wraptree::record::mcap::read_recording(path).unwrap()
}

#[test]
fn replay_verifies_a_partitioned_recording() {
    // More primitives than one subproblem takes (`Chunking::whole`), so chunks are recorded.
    let n = 13_000;
    assert!(!Chunking::DEFAULT.whole(n));
    let dir = common::soup_dir(n, 4);
    let scene = wraptree::scene::load_path(&dir.path().join("s.obj"), &LoadOptions::default())
        .unwrap()
        .scene;
    let out = wraptree(
        &[
            "record",
            "s.obj",
            "-o",
            "p",
            "--schedule",
            "partitioned",
            "--detail",
            "merges",
            "--threads",
            "2",
        ],
        dir.path(),
    );
    let rec = recorded(&out, &dir.path().join("p.mcap"));
    assert!(rec.params.mode.schedule.is_partitioned());
    // δ by the scene's size: chunks of up to 4,096 primitives.
    assert_eq!(rec.params.mode.schedule.chunking().unwrap().delta, 4096);
    assert!(rec.parts.len() > 2, "{} parts recorded", rec.parts.len());
    let (_, log) = run(&scene, &partitioned(Params::default()));
    assert_eq!(rec.parts, log.parts);
    let out = wraptree(&["replay", "p.mcap", "--verify"], dir.path());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("verified"),
        "{text} {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = wraptree(
        &[
            "group",
            "s.obj",
            "--schedule",
            "partitioned",
            "--threads",
            "1",
        ],
        dir.path(),
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Partitioned on 1 thread"), "{text}");
    assert!(!text.contains("grouped whole"), "{text}");
    assert!(
        text.contains("δ = 4096, ε = 0.5, root share 8192, SAH cuts up to 256 primitives"),
        "{text}"
    );
    let out = wraptree(&["group", "s.obj", "--threads", "0"], dir.path());
    common::assert_one_line_error(&out, "--threads");
}

#[test]
fn a_chosen_root_share_epsilon_and_sah_cuts_are_recorded_and_replayed() {
    // Whole under the default share (`Chunking::whole`), split under a share of 256 into
    // chunks of 4.
    let n = 3_000;
    assert!(Chunking::DEFAULT.whole(n));
    let dir = common::soup_dir(n, 6);
    let args = [
        "record",
        "s.obj",
        "--schedule",
        "partitioned",
        "--chunk-delta",
        "4",
        "-o",
    ];
    let out = wraptree(
        &[&args[..], &["p", "--chunk-top", "256"]].concat(),
        dir.path(),
    );
    let rec = recorded(&out, &dir.path().join("p.mcap"));
    assert_eq!(rec.params.mode.schedule.chunking().unwrap().top, 256);
    assert!(rec.parts.len() > 10, "{} parts recorded", rec.parts.len());
    let out = wraptree(&["replay", "p.mcap", "--verify"], dir.path());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("verified"), "{text}");
    // AAC's fast ε (the default before ε = 0.5) gives another run, recorded and reproduced.
    let out = wraptree(
        &[
            &args[..],
            &["e", "--chunk-top", "256", "--chunk-epsilon", "0.2"],
        ]
        .concat(),
        dir.path(),
    );
    let rec_e = recorded(&out, &dir.path().join("e.mcap"));
    assert_eq!(rec_e.params.mode.schedule.chunking().unwrap().epsilon, 0.2);
    assert_ne!(rec_e.merges, rec.merges);
    let out = wraptree(&["replay", "e.mcap", "--verify"], dir.path());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("verified"), "{text}");
    // Morton cuts throughout (`--chunk-sah 0`): another run, recorded and reproduced; a
    // recording without a `chunk_sah` key reads as one.
    let out = wraptree(
        &[&args[..], &["m", "--chunk-top", "256", "--chunk-sah", "0"]].concat(),
        dir.path(),
    );
    let rec_m = recorded(&out, &dir.path().join("m.mcap"));
    assert_eq!(
        rec.params.mode.schedule.chunking().unwrap().sah_below,
        Chunking::DEFAULT.sah_below
    );
    assert_eq!(rec_m.params.mode.schedule.chunking().unwrap().sah_below, 0);
    assert_ne!(rec_m.merges, rec.merges);
    let out = wraptree(&["replay", "m.mcap", "--verify"], dir.path());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("verified"), "{text}");
    // A recording without `format_version` (older) and without `chunk_sah` was cut at Morton
    // bits throughout.
    let mut old = rec.metadata.clone();
    assert_eq!(old.remove("format_version").as_deref(), Some("1"));
    old.insert("chunk_max".into(), "0".into());
    old.remove("chunk_sah");
    assert_eq!(legacy(&old).unwrap().sah_below, 0);
    // The largest chunk was recorded as 0 (= δ) before it was dropped; an older recording
    // without it made chunks of fewer than δ primitives, which no longer runs: one error.
    let mut fewer = old.clone();
    fewer.remove("chunk_max");
    let err = legacy(&fewer).unwrap_err().to_string();
    assert!(err.contains("chunks of fewer than δ"), "{err}");
    // δ is recorded and read back as the run used it (4 here, 2 on the fast path), and an
    // older partitioned recording without it was made with 4.
    assert_eq!(
        rec.metadata.get("chunk_delta").map(String::as_str),
        Some("4")
    );
    old.remove("chunk_delta");
    assert_eq!(legacy(&old).unwrap().delta, 4);
    // A newer format is one error naming the versions.
    let mut newer = rec.metadata.clone();
    newer.insert("format_version".into(), "2".into());
    let err = wraptree::record::mcap::metadata::current_form(newer)
        .unwrap_err()
        .to_string();
    assert!(err.contains("format_version is 2, newer than"), "{err}");
    // A current recording lacking a key is an error naming it, not a guess.
    let mut lacking = rec.metadata.clone();
    lacking.remove("chunk_sah");
    let lacking = wraptree::record::mcap::metadata::current_form(lacking).unwrap();
    let err = wraptree::record::mcap::metadata::params(&lacking).unwrap_err();
    assert!(err.to_string().contains("lacks `chunk_sah`"), "{err}");
    // A bad value gives one error naming the key.
    let rejects = |key: &str, value: &str, why: &str| {
        let mut bad = old.clone();
        bad.insert(key.into(), value.into());
        let err = legacy(&bad).unwrap_err();
        assert!(err.to_string().contains(why), "{err}");
    };
    rejects(
        "chunk_delta",
        "1",
        "--chunk-delta (δ) must be at least 2 (or 0: by the scene's size), got 1",
    );
    // The largest range that tries every partition: 0 by default, 4 on the fast path; a
    // recording without it was cut by sweeps.
    assert_eq!(rec.metadata.get("chunk_few").map(String::as_str), Some("0"));
    rejects("chunk_few", "5", "chunk_few must be at most 4, got 5");
    let out = wraptree(&["record", "s.obj", "--fast", "-o", "q"], dir.path());
    let rec_q = recorded(&out, &dir.path().join("q.mcap"));
    assert_eq!(
        rec_q.params.mode.schedule.chunking().unwrap().delta,
        Chunking::FAST.delta
    );
    assert_eq!(Chunking::FAST.delta, 2);
    assert_eq!(
        rec_q.metadata.get("chunk_few").map(String::as_str),
        Some("4")
    );
    // Identical neighbours merged first: false by default, true on the fast path; a recording
    // without the key merged none first.
    assert_eq!(
        rec.metadata.get("chunk_twins").map(String::as_str),
        Some("false")
    );
    assert_eq!(
        rec_q.metadata.get("chunk_twins").map(String::as_str),
        Some("true")
    );
    assert!(rec_q.params.mode.schedule.chunking().unwrap().twins);
    rejects(
        "chunk_twins",
        "yes",
        "metadata has a bad `chunk_twins`: \"yes\"",
    );
    let mut fast_old = rec_q.metadata.clone();
    fast_old.remove("format_version");
    fast_old.insert("chunk_max".into(), "0".into());
    fast_old.remove("chunk_few");
    fast_old.remove("chunk_twins");
    let old_fast = legacy(&fast_old).unwrap();
    assert_eq!(old_fast.few, 0);
    assert!(!old_fast.twins);
    let out = wraptree(&["replay", "q.mcap", "--verify"], dir.path());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("verified"), "{text}");
    let out = wraptree(
        &[&args[..], &["f", "--chunk-epsilon", "0.7"]].concat(),
        dir.path(),
    );
    common::assert_one_line_error(&out, "--chunk-epsilon must be in [0, 0.5]");
    // The default share groups this scene whole: one part, the top.
    let out = wraptree(&[&args[..], &["d"]].concat(), dir.path());
    let rec = recorded(&out, &dir.path().join("d.mcap"));
    assert_eq!(
        rec.params.mode.schedule.chunking().unwrap().top,
        Chunking::DEFAULT.top
    );
    assert_eq!(rec.parts.len(), 1);
    let out = wraptree(&["group", "s.obj", "--chunk-top", "64"], dir.path());
    common::assert_one_line_error(&out, "--chunk-top needs --schedule partitioned");
    let out = wraptree(&["group", "s.obj", "--chunk-epsilon", "0.2"], dir.path());
    common::assert_one_line_error(&out, "--chunk-epsilon needs --schedule partitioned");
    let out = wraptree(&["group", "s.obj", "--chunk-sah", "0"], dir.path());
    common::assert_one_line_error(&out, "--chunk-sah needs --schedule partitioned");
}

#[test]
fn a_chosen_chunk_size_is_recorded_replayed_and_checked() {
    let dir = common::soup_dir(3_000, 6);
    let args = [
        "record",
        "s.obj",
        "--schedule",
        "partitioned",
        "--chunk-top",
        "256",
    ];
    let out = wraptree(
        &[&args[..], &["--chunk-delta", "4", "-o", "d"]].concat(),
        dir.path(),
    );
    let rec_d = recorded(&out, &dir.path().join("d.mcap"));
    let out = wraptree(
        &[&args[..], &["--chunk-delta", "64", "-o", "c"]].concat(),
        dir.path(),
    );
    let rec = recorded(&out, &dir.path().join("c.mcap"));
    assert_eq!(rec.params.mode.schedule.chunking().unwrap().delta, 64);
    assert_eq!(
        rec.metadata.get("chunk_delta").map(String::as_str),
        Some("64")
    );
    // Chunks of up to 64 primitives, each grouped by the exact step: other merges, fewer parts.
    assert_ne!(rec.merges, rec_d.merges);
    assert!(rec.parts.len() < rec_d.parts.len());
    let out = wraptree(&["replay", "c.mcap", "--verify"], dir.path());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("verified"), "{text}");
    // A chunk as large as the scene is the exact schedule's run.
    let out = wraptree(
        &[&args[..], &["--chunk-delta", "3000", "-o", "w"]].concat(),
        dir.path(),
    );
    let whole = recorded(&out, &dir.path().join("w.mcap"));
    let out = wraptree(&["record", "s.obj", "-o", "e"], dir.path());
    let exact = recorded(&out, &dir.path().join("e.mcap"));
    assert_eq!(whole.merges, exact.merges);
    // δ by the scene's size (the default) is 4,096 here: one chunk, the exact run's merges,
    // recorded as the δ used.
    let out = wraptree(&[&args[..], &["-o", "s"]].concat(), dir.path());
    let by_size = recorded(&out, &dir.path().join("s.mcap"));
    assert_eq!(by_size.params.mode.schedule.chunking().unwrap().delta, 4096);
    assert_eq!(by_size.merges, exact.merges);
    // `group` says when the scene is one subproblem (at most 1.5 × the root share), where no
    // chunk setting changes the tree.
    let partitioned = ["group", "s.obj", "--schedule", "partitioned"];
    let text = common::printed(
        &[&partitioned[..], &["--chunk-delta", "64"]].concat(),
        dir.path(),
    );
    assert!(
        text.contains("δ = 64") && text.contains("grouped whole"),
        "{text}"
    );
    let text = common::printed(&["group", "s.obj", "--fast"], dir.path());
    assert!(
        text.contains("δ = 2") && !text.contains("grouped whole"),
        "{text}"
    );
    let out = wraptree(&["group", "s.obj", "--chunk-delta", "64"], dir.path());
    common::assert_one_line_error(&out, "--chunk-delta needs --schedule partitioned");
    let out = wraptree(
        &["group", "s.obj", "--fast", "--chunk-delta", "1"],
        dir.path(),
    );
    common::assert_one_line_error(
        &out,
        "--chunk-delta (δ) must be at least 2 (or 0: by the scene's size), got 1",
    );
}

#[test]
fn larger_chunks_bring_an_assembly_s_tree_back_to_the_exact_one() {
    // 20 rigid copies of the robot base (5,520 polygons), split under a root share of 256: with
    // chunks of 4 the Morton split forces merges across copies that the exact run keeps apart;
    // chunks of 1,024, each grouped by the exact step, make those merges its own.
    let scene = generate::replicate(&generate::robot_base(), 20, 1);
    let resolved = Params::default().resolve(&scene);
    let exact = wraptree::grouping::sah(&group(&scene, &Params::default(), ()).tree);
    let sah_with = |delta: u32| {
        let chunking = Chunking {
            delta,
            top: 256,
            ..Chunking::DEFAULT
        };
        let mut log = EventLog::default();
        let g = group_with(&scene, &resolved, &chunking, &mut log, &Budget::default()).unwrap();
        check_tree(&scene, &g, &log);
        wraptree::grouping::sah(&g.tree) / exact
    };
    let (small, large) = (sah_with(4), sah_with(1024));
    assert!(small > 1.03, "δ = 4: {small}");
    assert!((0.99..=1.01).contains(&large), "δ = 1024: {large}");
}

#[test]
fn the_default_chunk_size_is_resolved_by_the_scene_s_size() {
    // δ = 0 (the default) is 4,096 up to 2^18 primitives and 4 above, resolved before the run
    // so that recordings hold the δ used; the exact schedule does not read it, and a given δ
    // stays as given.
    let boxes =
        |n: usize| vec![wraptree::geom::Aabb::from_points([&wraptree::geom::P3::origin()]); n];
    let delta = |p: &Params, n| chunking(&p.resolve_boxes(&boxes(n)).mode).delta;
    let p = partitioned(Params::default());
    assert_eq!(chunking(&p.mode).delta, 0);
    let at = Chunking::BY_SIZE_UP_TO;
    assert_eq!(delta(&p, at), 4096);
    assert_eq!(delta(&p, at + 1), 4);
    assert_eq!(
        Params::default().resolve_boxes(&boxes(10)).mode.schedule,
        Schedule::Exact
    );
    let mut given = partitioned(Params::default());
    given.mode.schedule = Schedule::Partitioned(Chunking {
        delta: 16,
        ..Chunking::DEFAULT
    });
    assert_eq!(delta(&given, 10), 16);
    let mut fast = Params::default();
    fast.mode.schedule = Schedule::FAST;
    assert_eq!(delta(&fast, 10), 2);
}
