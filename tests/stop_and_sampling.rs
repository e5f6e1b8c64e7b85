//! A requested [`Stop`] ends `bench`, `stress`, `snapshot`, `cover`, `wrap` and `compare`
//! early without their output, and every Wrapper Tree builder, measure and loader at once; a
//! `sweep` setting
//! over its grouping limits is left out, and the sampled tightness of `bench` and `wrap` is
//! deterministic for any thread count and near the value over every node.

use wraptree::grouping::{CostMeasure, Limits, Params, group};
use wraptree::metrics::compare::{Options, Row, Step, Wrapper, evaluate};
use wraptree::metrics::report::write_bench;
use wraptree::metrics::stress::{self, StressOptions};
use wraptree::metrics::sweep::{SweepRuns, grid, sweep};
use wraptree::peers::Method;
use wraptree::scene::{Scene, generate};
use wraptree::stop::{Interrupted, Stop, is_interrupted};
use wraptree::wrap::{
    LevelStats, SphereMethod, WrapperKind, WrapperTree, Wrappers, containment_excess_until,
    hull_tree, hull_tree_until, level_tightness, level_tightness_sampled, obb_tree_until,
    sphere_tree_until,
};

fn options(tightness_nodes: usize) -> Options {
    Options {
        methods: vec![Method::GROUPING, Method::MEDIAN_SPLIT],
        wrappers: vec![Wrapper::Box, Wrapper::Sphere(SphereMethod::AabbCenter)],
        repeat: 1,
        tightness_nodes,
        ..Options::default()
    }
}

fn scene() -> Scene {
    generate::replicate(&generate::robot_base(), 6, 1)
}

fn rows_on(threads: usize, opts: &Options) -> Vec<Row> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| evaluate(&scene(), opts, &Stop::new(), &mut |_| {}).unwrap())
}

#[test]
fn bench_stops_at_the_next_step_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("results.csv");
    std::fs::write(&csv, "previous results\n").unwrap();
    let stop = Stop::new();
    let mut steps = Vec::new();
    let r = evaluate(&scene(), &options(4), &stop, &mut |step| {
        steps.push(step);
        if matches!(step, Step::Tightness(..)) {
            stop.request();
        }
    });
    let e = r.expect_err("a requested stop ends the run");
    assert!(is_interrupted(&e), "{e}");
    // Stopped right after the first tightness: no query, nothing measured on the second
    // method's tree (both were built first, in rounds).
    assert!(matches!(
        steps.last(),
        Some(Step::Tightness(Method::GROUPING, _))
    ));
    assert!(steps.contains(&Step::Build(Method::MEDIAN_SPLIT)));
    assert!(
        !steps
            .iter()
            .any(|s| matches!(s, Step::Wrapper(Method::MEDIAN_SPLIT, _)))
    );
    // The command writes only finished rows: the previous file stays as it was.
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), "previous results\n");
    // A finished run replaces it.
    let rows = evaluate(&scene(), &options(4), &Stop::new(), &mut |_| {}).unwrap();
    write_bench(dir.path(), &rows, true).unwrap();
    assert_ne!(std::fs::read_to_string(&csv).unwrap(), "previous results\n");
}

#[test]
fn stress_stops_after_the_case_at_hand_without_a_report() {
    let stop = Stop::new();
    let mut scenes = 0;
    let opts = StressOptions {
        quick: true,
        ..StressOptions::default()
    };
    let r = stress::run(&opts, &stop, &mut |_| {
        scenes += 1;
        stop.request();
    });
    let e = r.expect_err("a requested stop ends the run");
    assert!(is_interrupted(&e), "{e}");
    assert_eq!(scenes, 1, "no scene after the stop");
}

#[test]
fn sampled_tightness_is_deterministic_and_near_every_node() {
    let opts = options(4);
    let one = rows_on(1, &opts);
    let two = rows_on(2, &opts);
    let tight = |rows: &[Row]| -> Vec<(Option<f64>, Vec<f64>)> {
        rows.iter()
            .map(|r| (r.tightness, r.tightness_levels.clone()))
            .collect()
    };
    assert_eq!(tight(&one), tight(&two), "same values for 1 and 2 threads");
    let full = rows_on(2, &options(0));
    for (row, every) in one.iter().zip(&full) {
        let (s, f) = (row.tightness.unwrap(), every.tightness.unwrap());
        assert!(f > 0.0);
        let case = format!("{} {}", row.method, row.wrapper);
        assert!(
            (s - f).abs() <= 0.15 * f,
            "{case}: sampled {s}, every node {f}"
        );
    }
}

/// `wrap`'s sampled levels: with 0 nodes per depth exactly the every-node levels; with a sample
/// as large as every depth the same up to rounding; with a small one the same volumes and
/// counts, the error means near the every-node ones, and the same for 1 and 2 threads.
#[test]
fn wrap_levels_sampled_match_every_node() {
    let on = |threads: usize, f: &(dyn Fn() -> Vec<Vec<LevelStats>> + Sync)| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(f)
    };
    for (scene, per_depth) in [(generate::lamp(), 1 << 20), (scene(), 64)] {
        let tree = group(&scene, &Params::default(), ()).tree;
        let hulls = hull_tree(&tree, &scene);
        let w = Wrappers::build(&tree, &scene, &WrapperKind::ALL, SphereMethod::AabbCenter);
        let levels = |per_depth: usize| {
            w.trees()
                .into_iter()
                .map(|t| {
                    let how = (per_depth, 1);
                    level_tightness_sampled(&tree, &scene, t, &hulls, 16, how, &Stop::new())
                        .unwrap()
                })
                .collect::<Vec<_>>()
        };
        let every: Vec<_> = w
            .trees()
            .into_iter()
            .map(|t| level_tightness(&tree, &scene, t, &hulls, 16, &Stop::new()).unwrap())
            .collect();
        assert_eq!(levels(0), every);
        let sampled = on(1, &|| levels(per_depth));
        assert_eq!(sampled, on(2, &|| levels(per_depth)), "1 and 2 threads");
        for (ks, ke) in sampled.iter().zip(&every) {
            // Over the levels: near the every-node means (each level alone: within a half).
            let sum = |l: &[LevelStats]| l.iter().map(|x| x.error_mean).sum::<f64>();
            let (s_all, e_all) = (sum(ks), sum(ke));
            assert!((s_all - e_all).abs() <= 0.1 * e_all, "{s_all} vs {e_all}");
            for (s, e) in ks.iter().zip(ke) {
                let same = (s.depth, s.nodes, s.interior, s.volume, s.reference_volume);
                assert_eq!(
                    same,
                    (e.depth, e.nodes, e.interior, e.volume, e.reference_volume)
                );
                assert_eq!(s.volume_ratio, e.volume_ratio);
                let tol = if per_depth > 64 { 1e-9 } else { 0.5 };
                let at = format!("{} depth {}", scene.name, s.depth);
                assert!(
                    (s.error_mean - e.error_mean).abs() <= tol * e.error_mean + 1e-12,
                    "{at}: mean {} vs {}",
                    s.error_mean,
                    e.error_mean
                );
                if per_depth > 64 {
                    assert!(
                        (s.error_max - e.error_max).abs() <= 1e-9 * e.error_max,
                        "{at}"
                    );
                }
            }
        }
    }
}

/// A setting whose grouping exceeds the limits is left out with the reason; the others give
/// rows, and a requested stop ends the sweep.
#[test]
fn sweep_leaves_out_settings_over_their_limits() {
    let scene = generate::lamp();
    let settings = grid(&[1.0], &[1.0], &[0.0], &[CostMeasure::Diameter]);
    let run = |limits: Limits, stop: &Stop| {
        let runs = SweepRuns {
            repeat: 1,
            seed: 1,
            limits,
        };
        let mut merges = 0;
        let swept = sweep(
            &scene,
            &settings,
            &Params::default(),
            &runs,
            stop,
            |_, _, m| {
                merges += m.len();
                Ok(())
            },
        );
        (swept, merges)
    };
    let (all, merges) = run(Limits::default(), &Stop::new());
    let all = all.unwrap();
    assert_eq!((all.rows.len(), all.left_out.len()), (1, 0));
    assert_eq!(merges, scene.len() - 1);
    let few = Limits {
        max_seconds: None,
        max_pairs: Some(1),
    };
    let (none, merges) = run(few, &Stop::new());
    let none = none.unwrap();
    assert!(none.rows.is_empty() && merges == 0);
    assert_eq!(none.left_out.len(), 1);
    assert!(
        none.left_out[0].1.contains("--max-pairs 1"),
        "{:?}",
        none.left_out
    );
    let stop = Stop::new();
    stop.request();
    let e = run(Limits::default(), &stop)
        .0
        .expect_err("a requested stop ends the sweep");
    assert!(is_interrupted(&e), "{e}");
}

#[test]
fn snapshot_cover_and_wrap_obey_a_stop_and_write_nothing() {
    use wraptree::render::snapshot::{SnapshotOptions, draw, regroup};
    use wraptree::wrap::cover::solve::{CoverLimit, cover_scene};
    use wraptree::wrap::report::{Measured, report};
    let scene = scene();
    let params = Params::default();
    let tree = group(&scene, &params, ()).tree;
    let (go, stopped) = (Stop::new(), Stop::new());
    stopped.request();
    // Snapshot: the grouping, then the pictures; an earlier frame is left as it was.
    let resolved = params.resolve(&scene);
    let e = regroup(&scene, &resolved, None, &stopped).expect_err("stopped");
    assert!(is_interrupted(&e), "{e}");
    assert_eq!(regroup(&scene, &resolved, None, &go).unwrap().0.tree, tree);
    let dir = tempfile::tempdir().unwrap();
    let earlier = dir.path().join("frame-00-input.png");
    std::fs::write(&earlier, "an earlier frame").unwrap();
    let opts = SnapshotOptions {
        force: true,
        ..SnapshotOptions::default()
    };
    let e = draw(&scene, &tree, &opts, dir.path(), &stopped).expect_err("stopped");
    assert!(is_interrupted(&e), "{e}");
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(left.len(), 1, "{left:?}");
    assert_eq!(std::fs::read(&earlier).unwrap(), b"an earlier frame");
    assert!(draw(&scene, &tree, &opts, dir.path(), &go).is_ok());
    // Cover: grouping, wrappers, their measuring.
    let kinds = [WrapperKind::Sphere, WrapperKind::Box];
    let e =
        cover_scene(&scene, &params, CoverLimit::Budget(8), &kinds, &stopped).expect_err("stopped");
    assert!(is_interrupted(&e), "{e}");
    assert!(cover_scene(&scene, &params, CoverLimit::Budget(8), &kinds, &go).is_ok());
    // Wrap: each kind's report.
    let how = Measured {
        method: SphereMethod::AabbCenter,
        samples: 16,
        per_depth: 4,
    };
    assert!(report(&tree, &scene, &kinds, how, &stopped).is_err());
    assert_eq!(report(&tree, &scene, &kinds, how, &go).unwrap().len(), 2);
}

#[test]
fn a_comparison_stopped_before_both_files_are_complete_writes_neither() {
    use wraptree::grouping::EventLog;
    use wraptree::record::compare::{CompareRun, write_comparison};
    let scene = scene();
    let mut log = EventLog::default();
    let tree = group(&scene, &Params::default(), &mut log).tree;
    let run = |label: &str| CompareRun {
        label: label.into(),
        merges: &log.merges,
        tree: Some(&tree),
    };
    let runs = [run("a"), run("b")];
    let dir = tempfile::tempdir().unwrap();
    let prefix = dir.path().join("pair");
    let (go, stopped) = (Stop::new(), Stop::new());
    stopped.request();
    let e = write_comparison(&prefix, &scene, "s", &runs, false, &stopped).expect_err("stopped");
    assert!(is_interrupted(&e), "{e}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    let written = write_comparison(&prefix, &scene, "s", &runs, false, &go).unwrap();
    assert!(written.iter().all(|p| p.is_file()));
}

#[test]
fn a_requested_stop_ends_every_wrapper_builder_measure_and_loader_at_once() {
    let scene = scene();
    let tree = group(&scene, &Params::default(), ()).tree;
    let hulls = hull_tree(&tree, &scene);
    let stop = Stop::new();
    stop.request();
    for m in [
        SphereMethod::Merged,
        SphereMethod::AabbCenter,
        SphereMethod::Ritter,
        SphereMethod::Minimum,
    ] {
        assert_eq!(
            sphere_tree_until(&tree, &scene, m, &stop).err(),
            Some(Interrupted)
        );
    }
    assert_eq!(
        hull_tree_until(&tree, &scene, &stop).err(),
        Some(Interrupted)
    );
    assert_eq!(
        obb_tree_until(&tree, &scene, None, &stop).err(),
        Some(Interrupted)
    );
    let built = Wrappers::build_until(
        &tree,
        &scene,
        &WrapperKind::ALL,
        SphereMethod::Merged,
        &stop,
    );
    assert_eq!(built.err(), Some(Interrupted));
    let boxes = WrapperTree::Boxes(&tree.aabb);
    assert_eq!(
        containment_excess_until(&tree, &scene, boxes, &stop),
        Err(Interrupted)
    );
    let levels = level_tightness_sampled(&tree, &scene, boxes, &hulls, 16, (64, 1), &stop);
    assert_eq!(levels, Err(Interrupted));
    // The same calls with a token nobody requested finish.
    let go = Stop::new();
    assert!(containment_excess_until(&tree, &scene, boxes, &go).is_ok());
    // Loading: the error names the file, and its source is the stop.
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_vec();
    let opts = wraptree::scene::LoadOptions::default();
    let e = wraptree::scene::load_bytes_until("t.obj", obj.clone(), &opts, &stop).unwrap_err();
    assert_eq!(e.kind, wraptree::scene::LoadErrorKind::Interrupted);
    assert!(is_interrupted(&anyhow::Error::new(e.clone())), "{e}");
    assert_eq!(e.to_string(), "t.obj: interrupted");
    assert!(wraptree::scene::load_bytes_until("t.obj", obj, &opts, &go).is_ok());
}
