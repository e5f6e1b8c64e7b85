//! A requested [`Stop`] ends `bench` and `stress` early without their output, and the sampled
//! tightness of `bench` is deterministic for any thread count and near the value over every
//! node.

use wraptree::metrics::compare::{Options, Row, Step, Wrapper, evaluate};
use wraptree::metrics::report::write_bench;
use wraptree::metrics::stress::{self, StressOptions};
use wraptree::peers::Method;
use wraptree::scene::{Scene, generate};
use wraptree::stop::{Stop, is_interrupted};
use wraptree::wrap::SphereMethod;

fn options(tightness_nodes: usize) -> Options {
    Options {
        methods: vec![Method::Grouping, Method::MedianSplit],
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
    // Stopped right after the first tightness: no query, no second method.
    assert!(matches!(
        steps.last(),
        Some(Step::Tightness(Method::Grouping, _))
    ));
    assert!(!steps.contains(&Step::Build(Method::MedianSplit)));
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
