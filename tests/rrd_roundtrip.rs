//! The `.rrd` recorder, read back by independent readers from PyPI's `rerun-sdk==0.36.3`
//! (provisioned by the tests, `common::readers`): `rerun rrd verify` must accept each file, and the package's
//! `rerun.experimental.RrdReader` lists its stores, entities, timelines and time values.
//! Missing tools make these tests fail, never pass.

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::Command;

use wraptree::grouping::{EventLog, Grouping, Params, Tee, Weights, group};
use wraptree::record::rrd::RrdRecorder;
use wraptree::record::{Detail, Outcome, RunInfo};
use wraptree::scene::{LoadOptions, Loaded, generate, load_bytes};
use wraptree::wrap::{SphereMethod, WrapperKind, Wrappers};

/// Prints a JSON summary of the first recording store of the file in `argv[1]`.
const READER: &str = r#"
import json, sys
from rerun.experimental import RrdReader
r = RrdReader(sys.argv[1])
out = {"recordings": [[s.application_id, s.recording_id] for s in r.recordings()],
       "blueprints": len(r.blueprints()), "entities": {}}
for c in r.stream():
    e = out["entities"].setdefault(c.entity_path,
        {"rows": 0, "static": False, "timelines": [], "merge": [], "level": [], "round": [],
         "lens": []})
    e["rows"] += c.num_rows
    e["static"] = e["static"] or c.is_static
    for t in c.timeline_names:
        if t not in e["timelines"]:
            e["timelines"].append(t)
    rb = c.to_record_batch()
    for t in ("merge", "level", "round"):
        if t in rb.schema.names:
            e[t] += rb.column(t).to_pylist()
    for name in ("Scalars:scalars", "Boxes3D:centers"):
        if name in rb.schema.names and not c.is_static:
            e["lens"] += [len(v) for v in rb.column(name).to_pylist()]
print(json.dumps(out))
"#;

#[derive(serde::Deserialize)]
struct Summary {
    recordings: Vec<(String, String)>,
    blueprints: usize,
    entities: BTreeMap<String, Entity>,
}

#[derive(serde::Deserialize)]
struct Entity {
    rows: usize,
    #[serde(rename = "static")]
    is_static: bool,
    timelines: Vec<String>,
    merge: Vec<i64>,
    level: Vec<i64>,
    round: Vec<i64>,
    /// Per temporal row, the number of scalars (`Scalars`) or boxes (`Boxes3D`).
    lens: Vec<usize>,
}

struct Run {
    grouping: Grouping,
    log: EventLog,
    summary: Summary,
}

/// Groups `loaded` while recording it to `path` at `detail`, with the Wrapper Trees of `kinds`.
fn write(
    path: &Path,
    loaded: &Loaded,
    detail: Detail,
    params: &Params,
    kinds: &[WrapperKind],
) -> (Grouping, EventLog) {
    let scene = &loaded.scene;
    let resolved = params.resolve(scene);
    let info = RunInfo {
        scene,
        source: &loaded.source,
        params: &resolved,
        detail,
    };
    let mut recorder = RrdRecorder::new(path, &info).expect("recorder starts");
    let mut log = EventLog::default();
    let grouping = group(scene, params, Tee(&mut recorder, &mut log));
    let mut wrappers = Wrappers::build(&grouping.tree, scene, kinds, SphereMethod::default());
    let spheres = wrappers.spheres.take().unwrap_or_default();
    let outcome = Outcome {
        spheres: Some(&spheres),
        wrappers: Some(&wrappers),
        merges: log.merges.len() as u32,
        ..Outcome::finished(&grouping)
    };
    recorder.finish(&outcome).expect("recording finishes");
    (grouping, log)
}

/// Records the grid scene at `detail` with the Wrapper Trees of `kinds`, checks the file with
/// the CLI and summarises it with the Python reader.
fn record(dir: &Path, detail: Detail, params: &Params, kinds: &[WrapperKind]) -> Run {
    let loaded = load_bytes(
        "grid.obj",
        common::grid_obj(8, 6, 1.5, 0.0),
        &LoadOptions::default(),
    )
    .expect("grid scene loads");
    let path = dir.join(format!("grid-{detail:?}.rrd"));
    let (grouping, log) = write(&path, &loaded, detail, params, kinds);

    let summary = summarize(&path);
    Run {
        grouping,
        log,
        summary,
    }
}

/// Checks `path` with `rerun rrd verify` and summarises it with the Python reader.
fn summarize(path: &Path) -> Summary {
    common::assert_rrd_verifies(path);
    let out = common::python()
        .args(["-c", READER])
        .arg(path)
        .output()
        .expect("the readers' Python runs");
    assert!(
        out.status.success(),
        "the Python reader failed on {}:\n{}",
        path.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("reader prints JSON")
}

fn range(n: usize) -> Vec<i64> {
    (0..n as i64).collect()
}

fn sorted(mut v: Vec<i64>) -> Vec<i64> {
    v.sort();
    v
}

/// The `levels/*` wrapper entities of the Wrapper Tree `kinds`.
fn wrapper_entities(kinds: &[WrapperKind]) -> Vec<&'static str> {
    kinds
        .iter()
        .map(|k| match k {
            WrapperKind::Sphere => "/levels/spheres",
            WrapperKind::Hull => "/levels/hulls",
            WrapperKind::Box => "/levels/boxes",
            WrapperKind::Obb => "/levels/obbs",
        })
        .collect()
}

/// Checks one recording's entities, timelines and row counts against its event log; `kinds`
/// are the Wrapper Trees it was recorded with.
fn check(run: &Run, detail: Detail, kinds: &[WrapperKind]) {
    let s = &run.summary;
    let n = run.grouping.tree.leaves();
    assert_eq!(s.recordings.len(), 1, "one recording store");
    assert_eq!(s.recordings[0].0, "wraptree");
    assert!(s.blueprints >= 1, "the file carries a blueprint");
    assert!(
        run.log.doublings.len() >= 2,
        "the scene exercises DLimit doublings"
    );

    let mut want: BTreeSet<&str> = [
        "/scene/primitives",
        "/log/doublings",
        "/series/cost",
        "/series/limits",
        "/series/fill_balance",
        "/series/queue_len",
    ]
    .into();
    if detail.merges() {
        want.extend(["/grouping/merge", "/grouping/active"]);
    }
    let tree = &run.grouping.tree;
    let leaf_depths: BTreeSet<u32> = (0..n).map(|x| tree.depth[x]).collect();
    let leaf_entities: Vec<String> = leaf_depths
        .iter()
        .map(|k| format!("/levels/leaves/{k}"))
        .collect();
    if detail.levels() {
        want.extend(leaf_entities.iter().map(String::as_str));
        want.extend(wrapper_entities(kinds));
    }
    let data: BTreeSet<&str> = s
        .entities
        .keys()
        .map(String::as_str)
        .filter(|e| {
            !e.starts_with("/__properties")
                && !["/", "/scene", "/grouping", "/levels", "/refine"].contains(e)
        })
        .collect();
    assert_eq!(data, want, "entity paths at {detail:?}");

    let timelines: BTreeSet<&str> = s
        .entities
        .values()
        .flat_map(|e| e.timelines.iter().map(String::as_str))
        .collect();
    let mut want_tl: BTreeSet<&str> = ["merge", "round"].into();
    if detail.levels() {
        want_tl.insert("level");
    }
    assert_eq!(
        timelines, want_tl,
        "timelines at {detail:?} (no log_time, no log_tick)"
    );

    assert!(s.entities["/scene/primitives"].is_static);
    for (series, k) in [
        ("cost", 1),
        ("limits", 3),
        ("fill_balance", 2),
        ("queue_len", 1),
    ] {
        let e = &s.entities[&format!("/series/{series}")];
        assert_eq!(e.lens, vec![k; n - 1], "{series}: {k} scalars per row");
        let temporal = e.rows - usize::from(e.is_static);
        assert_eq!(temporal, n - 1, "{series}: one row per merge");
        assert_eq!(
            sorted(e.merge.clone()),
            range(n - 1),
            "{series}: merge ticks 0..N-1"
        );
    }
    let text = &s.entities["/log/doublings"];
    assert_eq!(
        text.rows,
        run.log.rounds.len() + run.log.doublings.len() + 1
    );
    if detail.merges() {
        let e = &s.entities["/grouping/merge"];
        assert_eq!(sorted(e.merge.clone()), range(n - 1));
        assert_eq!(
            e.lens,
            vec![3; n - 1],
            "the pair and the new body per merge"
        );
        let rounds: Vec<i64> = run.log.merges.iter().map(|m| m.round as i64).collect();
        assert_eq!(sorted(e.round.clone()), sorted(rounds));
        let active = &s.entities["/grouping/active"];
        assert_eq!(
            sorted(active.round.clone()),
            range(run.log.rounds.len()),
            "one active set per round"
        );
    }
    if detail.levels() {
        let levels = range(tree.depth_max() as usize + 1);
        // The preview level: the shallowest whose cut has 64 nodes, else the deepest.
        let preview = (0..=tree.depth_max())
            .find(|&d| tree.level(d).len() >= 64)
            .unwrap_or(tree.depth_max());
        for e in wrapper_entities(kinds) {
            let e = &s.entities[e];
            assert_eq!(sorted(e.level.clone()), levels, "one row per level");
            assert_eq!(e.merge, [0, 0], "level 0 and the preview at merge 0");
            assert_eq!(e.round, [0, 0], "level 0 and the preview at round 0");
        }
        for (k, e) in leaf_depths.iter().zip(&leaf_entities) {
            let e = &s.entities[e];
            assert_eq!(e.level, [i64::from(*k)], "{k}: one row, at its depth");
            let preview_ticks = if *k <= preview { vec![0] } else { vec![] };
            assert_eq!(e.merge, preview_ticks, "depth {k} in the preview");
            assert_eq!(e.round, preview_ticks, "depth {k} in the preview");
        }
    }
}

#[test]
fn every_detail_reads_back_with_the_expected_entities_and_timelines() {
    let dir = tempfile::tempdir().unwrap();
    let params = Params::default();
    let mut ids = BTreeSet::new();
    let sphere = [WrapperKind::Sphere];
    // Levels with every wrapper kind: `levels/hulls`, `levels/boxes` and `levels/obbs` too.
    for (detail, kinds) in [
        (Detail::Levels, &WrapperKind::ALL[..]),
        (Detail::Merges, &sphere[..]),
        (Detail::Full, &sphere[..]),
    ] {
        let run = record(dir.path(), detail, &params, kinds);
        check(&run, detail, kinds);
        ids.insert(run.summary.recordings[0].1.clone());
    }
    assert_eq!(
        ids.len(),
        1,
        "the same scene and parameters share one recording id"
    );

    let other = Params {
        weights: Weights {
            a: 1.0,
            b: 1.0,
            c: 0.5,
        },
        ..Params::default()
    };
    let run = record(dir.path(), Detail::Levels, &other, &sphere);
    assert!(
        !ids.contains(&run.summary.recordings[0].1),
        "other parameters, other recording id"
    );
}

#[test]
fn an_unwritable_path_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let loaded = load_bytes(
        "grid.obj",
        common::grid_obj(8, 6, 1.5, 0.0),
        &LoadOptions::default(),
    )
    .unwrap();
    let params = Params::default().resolve(&loaded.scene);
    let info = RunInfo {
        scene: &loaded.scene,
        source: &loaded.source,
        params: &params,
        detail: Detail::Full,
    };
    let path = dir.path().join("missing").join("x.rrd");
    let err = RrdRecorder::new(&path, &info)
        .err()
        .expect("a missing directory fails");
    let msg = format!("{err:#}");
    assert!(
        msg.contains("missing/x.rrd"),
        "the error names the file: {msg}"
    );
}

#[test]
fn a_full_recording_of_the_12144_polygon_scene_stays_under_20_mb() {
    let robots = generate::replicate(&generate::robot_base(), 44, 7);
    let mut obj = Vec::new();
    robots.write_obj(&mut obj).unwrap();
    let loaded = load_bytes("robots44.obj", obj, &LoadOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("robots44.rrd");
    let start = std::time::Instant::now();
    let kinds = [WrapperKind::Sphere, WrapperKind::Hull];
    write(&path, &loaded, Detail::Full, &Params::default(), &kinds);
    let bytes = std::fs::metadata(&path).unwrap().len();
    eprintln!(
        "{} primitives: full .rrd with spheres and hulls {:.2} MB in {:.2} s",
        loaded.scene.len(),
        bytes as f64 / 1e6,
        start.elapsed().as_secs_f64()
    );
    assert!(bytes <= 20_000_000, "{bytes} bytes exceed 20 MB");
}

/// A write error mid-run (`/dev/full` accepts the open and fails every write) is reported by
/// `new` or `finish` as one line naming the file, and nothing blocks.
#[cfg(target_os = "linux")]
#[test]
fn a_full_disk_is_a_clear_error() {
    let loaded = load_bytes(
        "grid.obj",
        common::grid_obj(8, 6, 1.5, 0.0),
        &LoadOptions::default(),
    )
    .unwrap();
    let params = Params::default();
    let resolved = params.resolve(&loaded.scene);
    let info = RunInfo {
        scene: &loaded.scene,
        source: &loaded.source,
        params: &resolved,
        detail: Detail::Full,
    };
    let path = Path::new("/dev/full");
    let err = match RrdRecorder::new(path, &info) {
        Err(err) => err,
        Ok(mut recorder) => {
            let g = group(&loaded.scene, &params, &mut recorder);
            recorder
                .finish(&Outcome::finished(&g))
                .expect_err("writing to /dev/full fails")
        }
    };
    let msg = format!("{err:#}");
    assert!(
        msg.starts_with("/dev/full: ") && msg.contains("No space left"),
        "{msg}"
    );
    assert!(!msg.contains('\n'), "one line: {msg}");
}

#[test]
fn record_cli_logs_the_cover_as_one_more_level() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/robot-base.obj");
    let prefix = dir.path().join("rb");
    let out = Command::new(env!("CARGO_BIN_EXE_wraptree"))
        .arg("record")
        .arg(&scene)
        .arg("-o")
        .arg(&prefix)
        .args([
            "--cover-tolerance",
            "2%",
            "--cover-kinds",
            "sphere,box,obb,hull",
        ])
        .output()
        .expect("the binary runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = summarize(&dir.path().join("rb.rrd"));
    let last = s
        .entities
        .iter()
        .filter(|(e, _)| e.starts_with("/levels/leaves/"))
        .flat_map(|(_, v)| v.level.iter().copied())
        .max()
        .unwrap();
    let cover: Vec<&str> = s
        .entities
        .keys()
        .map(String::as_str)
        .filter(|e| e.starts_with("/cover/") && *e != "/cover/summary")
        .collect();
    assert!(!cover.is_empty(), "cover entities: {:?}", s.entities.keys());
    for e in &cover {
        assert!(
            [
                "/cover/spheres",
                "/cover/boxes",
                "/cover/hulls",
                "/cover/leaves"
            ]
            .contains(e),
            "unexpected cover entity {e}"
        );
        assert_eq!(
            s.entities[*e].level,
            vec![last + 1],
            "{e}: one row at depth max + 1"
        );
    }
    assert!(s.entities["/cover/summary"].is_static);
    assert_eq!(
        s.entities["/levels"].level,
        vec![last + 1],
        "levels cleared under the cover"
    );
}
