//! `bench` times builds by the protocol of the published tables: rounds that build every
//! method once in turn, each method keeping its fastest build, on a thread of the rayon pool;
//! its table's `/ PLOC` column is the ratio of the same rows' build times.

use wraptree::grouping::Params;
use wraptree::metrics::compare::{Options, Step, Wrapper, evaluate};
use wraptree::metrics::report::bench_table;
use wraptree::metrics::timing::fastest_builds;
use wraptree::peers::{self, Method};
use wraptree::scene::generate;
use wraptree::stop::{Stop, is_interrupted};

#[test]
fn every_method_is_built_once_per_round_in_turn_and_keeps_its_fastest_build() {
    let scene = generate::robot_base();
    let methods = [Method::GROUPING, Method::FAST, Method::OBVHS_PLOC];
    // The clock, per call in order: grouping's fastest in round 3, the fast path's in round 2
    // (tied in round 4: the first is kept), PLOC's in round 1.
    let clock = [
        [5.0, 4.0, 1.0],
        [6.0, 2.0, 3.0],
        [4.0, 3.0, 2.0],
        [7.0, 2.0, 1.5],
    ];
    let mut calls = Vec::new();
    let mut on_pool = true;
    let built = fastest_builds(&methods, 4, &Stop::new(), |m| {
        on_pool &= rayon::current_thread_index().is_some();
        let i = calls.len();
        calls.push(m);
        let mut b = peers::build(m, &scene, &Params::default())?;
        b.seconds = clock[i / 3][i % 3];
        // Which call this build was.
        b.refine_seconds = i as f64;
        Ok(b)
    })
    .unwrap();
    assert_eq!(calls, methods.repeat(4), "rounds of every method in turn");
    assert!(on_pool, "every build runs on a thread of the pool");
    let kept: Vec<(Method, f64, f64)> = built
        .iter()
        .map(|b| (b.method, b.seconds, b.refine_seconds))
        .collect();
    assert_eq!(
        kept,
        [
            (Method::GROUPING, 4.0, 6.0),
            (Method::FAST, 2.0, 4.0),
            (Method::OBVHS_PLOC, 1.0, 2.0),
        ]
    );
    for b in &built {
        assert_eq!(b.tree.leaves(), scene.len(), "{}", b.method.name());
    }
}

#[test]
fn a_stop_ends_the_rounds_before_the_next_build() {
    let scene = generate::soup(50, 1);
    let stop = Stop::new();
    let mut calls = 0;
    let r = fastest_builds(&[Method::GROUPING, Method::OBVHS_PLOC], 5, &stop, |m| {
        calls += 1;
        if calls == 3 {
            stop.request();
        }
        peers::build(m, &scene, &Params::default())
    });
    assert!(is_interrupted(&r.expect_err("stopped")));
    assert_eq!(calls, 3);
}

#[test]
fn bench_builds_in_rounds_before_its_wrappers_and_its_table_divides_by_ploc_s_time() {
    let scene = generate::replicate(&generate::robot_base(), 3, 1);
    let opts = Options {
        methods: vec![Method::FAST, Method::OBVHS_PLOC],
        wrappers: vec![Wrapper::Box],
        repeat: 3,
        tightness_max_n: 0,
        ..Options::default()
    };
    let mut steps = Vec::new();
    let rows = evaluate(&scene, &opts, &Stop::new(), &mut |s| steps.push(s)).unwrap();
    let builds: Vec<Step> = steps.iter().copied().take(6).collect();
    let rounds: Vec<Step> = [Method::FAST, Method::OBVHS_PLOC]
        .repeat(3)
        .into_iter()
        .map(Step::Build)
        .collect();
    assert_eq!(
        builds, rounds,
        "rounds of every method in turn, then the rest"
    );
    assert!(!steps[6..].iter().any(|s| matches!(s, Step::Build(_))));
    // The table's `/ PLOC` column: each row's build time over PLOC's row's.
    let build_s = |m: Method| rows.iter().find(|r| r.method == m.name()).unwrap().build_s;
    let (fast, ploc) = (build_s(Method::FAST), build_s(Method::OBVHS_PLOC));
    let table = bench_table(&rows.iter().collect::<Vec<_>>());
    let header: Vec<&str> = table
        .lines()
        .next()
        .unwrap()
        .split('|')
        .map(str::trim)
        .collect();
    let col = header
        .iter()
        .position(|&c| c == "/ PLOC")
        .expect("a / PLOC column");
    let cell = |method: &str| -> String {
        let line = table
            .lines()
            .find(|l| l.starts_with(&format!("| {method} |")))
            .unwrap();
        line.split('|').nth(col).unwrap().trim().to_string()
    };
    assert_eq!(cell("fast"), format!("{:.2}", fast / ploc));
    assert_eq!(cell("obvhs-ploc"), "1.00");
    // Without PLOC among the methods the column is left empty.
    let fast_rows: Vec<_> = rows.iter().filter(|r| r.method == "fast").collect();
    let alone = bench_table(&fast_rows);
    let line = alone.lines().nth(2).unwrap();
    assert_eq!(line.split('|').nth(col).unwrap().trim(), "");
}
