//! Budgets on the grouping phase (`grouping::Budget`): a stopped run is a prefix of the
//! unlimited one, says which limit stopped it, and counts pairs as `Stats::eligible_pairs`.

mod common;

use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};
use wraptree::grouping::{
    Budget, EventLog, PSet, Params, StopReason, Stopped, group, group_within,
};
use wraptree::scene::{LoadOptions, Loaded, load_bytes};

fn grid() -> Loaded {
    load_bytes(
        "grid.obj",
        common::grid_obj(12, 9, 1.7, 0.05),
        &LoadOptions::default(),
    )
    .unwrap()
}

/// Runs `loaded` within `budget`; returns the outcome and the events seen.
fn within(loaded: &Loaded, pset: PSet, budget: &Budget<'_>) -> (Result<u32, Stopped>, EventLog) {
    let params = Params {
        pset,
        ..Params::default()
    }
    .resolve(&loaded.scene);
    let mut log = EventLog::default();
    let r = group_within(&loaded.scene, &params, &mut log, budget).map(|g| g.rounds);
    (r, log)
}

#[test]
fn max_pairs_stops_at_the_first_scan_that_exceeds_it_and_keeps_a_prefix() {
    let loaded = grid();
    for pset in [PSet::Aabb, PSet::Hull] {
        let params = Params {
            pset,
            ..Params::default()
        };
        let mut full = EventLog::default();
        let g = group(&loaded.scene, &params, &mut full);
        let total = g.stats.eligible_pairs;
        assert_eq!(total, full.rounds.iter().map(|r| r.5).sum::<u64>());
        // Exactly the pairs the run needs: it completes.
        let exact = Budget {
            max_pairs: Some(total),
            ..Budget::default()
        };
        let (r, log) = within(&loaded, pset, &exact);
        assert_eq!(r, Ok(g.rounds), "{pset:?}");
        assert_eq!(log.merges, full.merges);
        // Every smaller budget stops, after a prefix of the same merges, at the round whose
        // scan crossed it.
        for max in [0, 1, total / 3, total - 1] {
            let b = Budget {
                max_pairs: Some(max),
                ..Budget::default()
            };
            let (r, log) = within(&loaded, pset, &b);
            let s = r.expect_err("a smaller budget stops");
            assert_eq!(s.reason, StopReason::MaxPairs);
            assert!(s.eligible_pairs > max, "{s:?} max {max}");
            assert_eq!(s.merges as usize, log.merges.len());
            assert_eq!(s.rounds as usize, log.rounds.len());
            assert_eq!(log.merges[..], full.merges[..log.merges.len()]);
            assert_eq!(log.rounds[..], full.rounds[..log.rounds.len()]);
            let before: u64 = log.rounds.iter().map(|r| r.5).sum();
            assert!(before <= max, "the announced rounds fit the budget");
            assert!(log.root.is_none());
        }
    }
}

#[test]
fn deadline_and_stop_flag_say_why_they_stopped() {
    let loaded = grid();
    let past = Budget {
        deadline: Some(Instant::now()),
        ..Budget::default()
    };
    let (r, log) = within(&loaded, PSet::Aabb, &past);
    let s = r.unwrap_err();
    assert_eq!(
        (s.reason, s.merges, s.rounds),
        (StopReason::MaxSeconds, 0, 0)
    );
    assert!(log.merges.is_empty() && log.rounds.is_empty());
    let flag = AtomicBool::new(true);
    let stop = Budget {
        stop: Some(&flag),
        deadline: Some(Instant::now() + Duration::from_secs(3600)),
        max_pairs: Some(u64::MAX),
    };
    let s = within(&loaded, PSet::Aabb, &stop).0.unwrap_err();
    assert_eq!(s.reason, StopReason::Interrupted);
    let far = Budget {
        deadline: Some(Instant::now() + Duration::from_secs(3600)),
        ..Budget::default()
    };
    assert!(within(&loaded, PSet::Aabb, &far).0.is_ok());
    for r in [
        StopReason::Interrupted,
        StopReason::MaxSeconds,
        StopReason::MaxPairs,
    ] {
        assert_eq!(StopReason::from_name(r.name()), Some(r));
    }
}
