//! The Foxglove layouts shipped in `recordings/` (importable in Foxglove and Lichtblick): their
//! panel trees are well formed, and every topic and message field they name exists in a
//! recording of the kind they are for (`foxglove-layout.json`: `wraptree record`;
//! `foxglove-compare-layout.json`: the `.compare.mcap` of `wraptree replay --a/--b/--c`),
//! checked with the independent Python `mcap` reader (provisioned by the tests,
//! `common::readers`).

mod common;

use std::collections::BTreeSet;
use std::path::Path;

use serde_json::Value;

const LAYOUT: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/recordings/foxglove-layout.json"
);
const COMPARE_LAYOUT: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/recordings/foxglove-compare-layout.json"
);

/// For each `[topic, field path]` of `argv[2]` (a JSON list; an empty path names the topic
/// alone), checks that the recording `argv[1]` has a message on the topic and that the path
/// leads to a number in its first one; prints one line per failure.
const CHECK: &str = r#"
import json, sys
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory
wanted = json.loads(sys.argv[2])
first = {}
with open(sys.argv[1], "rb") as f:
    reader = make_reader(f, decoder_factories=[DecoderFactory()])
    for _, channel, _, msg in reader.iter_decoded_messages():
        first.setdefault(channel.topic, msg)
bad = []
for topic, path in wanted:
    if topic not in first:
        bad.append(f"{topic}: no message in the recording")
        continue
    value = first[topic]
    for part in filter(None, path.split(".")):
        if part not in {fd.name for fd in value.DESCRIPTOR.fields}:
            bad.append(f"{topic}.{path}: the message has no field {part!r}")
            break
        value = getattr(value, part)
    else:
        if path and not isinstance(value, (int, float)):
            bad.append(f"{topic}.{path}: not a number ({type(value).__name__})")
print("\n".join(bad))
sys.exit(1 if bad else 0)
"#;

/// Panel ids named by the leaves of a mosaic layout tree.
fn panel_ids(node: &Value, out: &mut Vec<String>) {
    match node {
        Value::String(id) => out.push(id.clone()),
        Value::Object(split) => {
            let direction = split.get("direction").and_then(Value::as_str);
            assert!(
                matches!(direction, Some("row" | "column")),
                "split without a row/column direction: {split:?}"
            );
            for side in ["first", "second"] {
                panel_ids(&split[side], out);
            }
        }
        other => panic!("unexpected layout node {other}"),
    }
}

/// Every `(topic, field path)` the layout names: 3D panels' topics, Plot paths
/// (`/topic.field`), Table and Raw Messages topics.
fn named_paths(layout: &Value) -> BTreeSet<(String, String)> {
    let configs = layout["configById"]
        .as_object()
        .expect("configById is an object");
    let mut out = BTreeSet::new();
    for (id, config) in configs {
        let kind = id.split('!').next().unwrap_or_default();
        match kind {
            "3D" => {
                let topics = config["topics"].as_object().expect("3D panel topics");
                assert!(!topics.is_empty(), "{id} shows no topic");
                out.extend(topics.keys().map(|t| (t.clone(), String::new())));
            }
            "Plot" => {
                let paths = config["paths"].as_array().expect("Plot panel paths");
                assert!(!paths.is_empty(), "{id} plots nothing");
                for p in paths {
                    let value = p["value"].as_str().expect("plot path value");
                    let (topic, field) = value
                        .split_once('.')
                        .unwrap_or_else(|| panic!("{id}: {value} names no field"));
                    out.insert((topic.to_string(), field.to_string()));
                }
            }
            "Table" | "RawMessages" => {
                let topic = config["topicPath"].as_str().expect("topicPath");
                out.insert((topic.to_string(), String::new()));
            }
            _ => panic!("{id}: a panel kind this test does not know"),
        }
    }
    out
}

fn record(dir: &Path) -> std::path::PathBuf {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/robot-base.obj");
    let out = common::wraptree(&["record", scene, "-o", "rb"], dir);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    dir.join("rb.mcap")
}

#[test]
fn layout_panels_are_laid_out_once_each() {
    let layout: Value =
        serde_json::from_str(&std::fs::read_to_string(LAYOUT).unwrap()).expect("layout is JSON");
    let mut ids = Vec::new();
    panel_ids(&layout["layout"], &mut ids);
    let configured: BTreeSet<String> = layout["configById"]
        .as_object()
        .expect("configById")
        .keys()
        .cloned()
        .collect();
    let laid_out: BTreeSet<String> = ids.iter().cloned().collect();
    assert_eq!(laid_out.len(), ids.len(), "a panel appears twice: {ids:?}");
    assert_eq!(
        laid_out, configured,
        "laid-out panels against configured ones"
    );
    let kinds: BTreeSet<&str> = ids.iter().filter_map(|id| id.split('!').next()).collect();
    for kind in ["3D", "Plot", "Table"] {
        assert!(kinds.contains(kind), "no {kind} panel");
    }
    let paths = named_paths(&layout);
    for field in ["cost", "diameter", "fill", "balance"] {
        assert!(
            paths.contains(&("/grouping/merge".into(), field.into())),
            "no plot of /grouping/merge.{field}"
        );
    }
    for field in ["dlimit", "glimit"] {
        assert!(
            paths.contains(&("/grouping/round".into(), field.into())),
            "no plot of /grouping/round.{field}"
        );
    }
    assert!(paths.contains(&("/scene".into(), String::new())));
    assert!(paths.iter().any(|(t, _)| t.starts_with("/levels/")));
}

/// Checks that every topic and field `layout` names is in `mcap`.
fn assert_in_recording(layout: &str, mcap: &Path) {
    let layout: Value =
        serde_json::from_str(&std::fs::read_to_string(layout).unwrap()).expect("layout is JSON");
    let wanted: Vec<(String, String)> = named_paths(&layout).into_iter().collect();
    let out = common::python()
        .args(["-c", CHECK])
        .arg(mcap)
        .arg(serde_json::to_string(&wanted).unwrap())
        .output()
        .expect("the readers' Python runs");
    assert!(
        out.status.success(),
        "the layout names what the recording lacks:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn every_topic_and_field_of_the_layout_is_in_a_recording() {
    let dir = tempfile::tempdir().unwrap();
    let mcap = record(dir.path());
    assert_in_recording(LAYOUT, &mcap);
}

#[test]
fn the_comparison_layout_shows_both_runs_of_a_comparison() {
    let layout: Value = serde_json::from_str(&std::fs::read_to_string(COMPARE_LAYOUT).unwrap())
        .expect("layout is JSON");
    let mut ids = Vec::new();
    panel_ids(&layout["layout"], &mut ids);
    assert_eq!(ids.len(), layout["configById"].as_object().unwrap().len());
    let paths = named_paths(&layout);
    for run in ["/runs/0", "/runs/1"] {
        for topic in ["bodies", "divergence"] {
            assert!(paths.contains(&(format!("{run}/{topic}"), String::new())));
        }
        assert!(paths.contains(&(format!("{run}/merge"), "cost".into())));
    }
    let dir = tempfile::tempdir().unwrap();
    let mcap = record(dir.path());
    let out = common::wraptree(
        &[
            "replay",
            mcap.to_str().unwrap(),
            "--c",
            "0.5",
            "-o",
            "rb-c05",
        ],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_in_recording(COMPARE_LAYOUT, &dir.path().join("rb-c05.compare.mcap"));
}
