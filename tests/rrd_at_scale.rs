//! What the `.rrd` draws at scale: no active boxes at a round start with more than
//! `record::ACTIVE_CAP` active bodies (an empty `grouping/active` row, which clears the previous
//! round's boxes, and a note in the round's log line), every active body below the cap; the
//! merged pair and new body (`grouping/merge`) for the last `record::BODIES_CAP` merges. Read
//! back with PyPI's `rerun-sdk` (`RrdReader`, provisioned by the tests).

mod common;

use std::collections::BTreeMap;

use wraptree::record::{ACTIVE_CAP, BODIES_CAP};

/// Prints, as JSON, the `grouping/active` rows as `[round, boxes]`, the `grouping/merge` rows
/// as `[merge, boxes]` and the text log lines.
const READER: &str = r#"
import json, sys
from rerun.experimental import RrdReader
out = {"active": [], "merge": [], "log": []}
for c in RrdReader(sys.argv[1]).stream():
    if c.is_static:
        continue
    rb = c.to_record_batch()
    if c.entity_path == "/grouping/active":
        rounds = rb.column("round").to_pylist()
        boxes = rb.column("Boxes3D:centers").to_pylist()
        out["active"] += [[r, len(b or [])] for r, b in zip(rounds, boxes)]
    elif c.entity_path == "/grouping/merge":
        merges = rb.column("merge").to_pylist()
        boxes = rb.column("Boxes3D:centers").to_pylist()
        out["merge"] += [[m, len(b or [])] for m, b in zip(merges, boxes)]
    elif c.entity_path == "/log/doublings":
        out["log"] += [t for row in rb.column("TextLog:text").to_pylist() for t in row]
print(json.dumps(out))
"#;

#[derive(serde::Deserialize)]
struct Summary {
    active: Vec<(u32, usize)>,
    merge: Vec<(u32, usize)>,
    log: Vec<String>,
}

/// The active count of each round start logged as `round R: …, N active, …`, and whether its
/// line says the boxes were left out.
fn round_starts(log: &[String]) -> BTreeMap<u32, (usize, bool)> {
    let mut out = BTreeMap::new();
    for line in log {
        let Some(rest) = line.strip_prefix("round ") else {
            continue;
        };
        let (round, rest) = rest.split_once(':').expect("round R: …");
        let active = rest
            .split(", ")
            .find_map(|part| part.strip_suffix(" active"))
            .expect("the line gives the active count");
        out.insert(
            round.parse().unwrap(),
            (
                active.trim().parse().unwrap(),
                line.contains("boxes not drawn"),
            ),
        );
    }
    out
}

#[test]
fn boxes_are_left_out_above_the_caps_and_drawn_below() {
    let dir = tempfile::tempdir().unwrap();
    let n = 3 * ACTIVE_CAP;
    let count = n.to_string();
    let out = common::wraptree(
        &["scene", "soup", "-n", &count, "-o", "soup.obj"],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = common::wraptree(
        &["record", "soup.obj", "-o", "soup", "--detail", "merges"],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rrd = dir.path().join("soup.rrd");
    common::assert_rrd_verifies(&rrd);
    let read = common::python()
        .args(["-c", READER])
        .arg(&rrd)
        .output()
        .expect("the readers' Python runs");
    assert!(
        read.status.success(),
        "{}",
        String::from_utf8_lossy(&read.stderr)
    );
    let summary: Summary = serde_json::from_slice(&read.stdout).expect("reader prints JSON");
    let starts = round_starts(&summary.log);
    assert!(!starts.is_empty(), "no round start in the log");
    let rows: BTreeMap<u32, usize> = summary.active.iter().copied().collect();
    assert_eq!(rows.len(), summary.active.len(), "one active row per round");
    assert_eq!(
        rows.keys().collect::<Vec<_>>(),
        starts.keys().collect::<Vec<_>>(),
        "an active row at every round start"
    );
    let mut capped = 0;
    for (round, &(active, noted)) in &starts {
        let boxes = rows[round];
        if active > ACTIVE_CAP {
            capped += 1;
            assert_eq!(
                boxes, 0,
                "round {round}: {active} active, {boxes} boxes drawn"
            );
            assert!(
                noted,
                "round {round}: the log line does not say the boxes are left out"
            );
        } else {
            assert_eq!(boxes, active, "round {round}: every active body's box");
            assert!(
                !noted,
                "round {round}: under the cap, yet noted as left out"
            );
        }
    }
    assert!(capped > 0, "no round start above the cap: {starts:?}");
    // Merges 0..=n-2: boxes for the last BODIES_CAP, three each.
    let first = (n - 1 - BODIES_CAP as usize) as u32;
    let want: Vec<(u32, usize)> = (first..n as u32 - 1).map(|m| (m, 3)).collect();
    let mut got = summary.merge.clone();
    got.sort_unstable();
    assert_eq!(got, want, "grouping/merge rows (merge, boxes)");
    assert!(
        starts.values().any(|&(a, _)| a > 0 && a <= ACTIVE_CAP),
        "no round start drawn: {starts:?}"
    );
}
