//! The `.mcap` of a comparison ([`crate::record::compare`]), for Foxglove with
//! `recordings/foxglove-compare-layout.json`.
//!
//! Topics: `/scene` (the scene, at 0), and per run i: `/runs/<i>/merge` (every merge, the
//! `/grouping/merge` message), `/runs/<i>/bodies` (the merged pair and new body, for the last
//! [`BODIES_CAP`](crate::record::BODIES_CAP) merges and around the first divergence) and `/runs/<i>/divergence` (the pair
//! run i merges at the first divergence); `/compare/log` (`foxglove.Log`: the runs, the
//! divergence, each run's finish). Merge k of every run is at log time k + 1 ms, so the runs
//! share one timeline; the file is chunked, zstd-compressed, and the same runs give the same bytes.

use std::io::{BufWriter, Seek, Write};

use anyhow::{Context, Result};
use foxglove::messages::{Log, SceneUpdate, Timestamp};

use super::messages::MergeEvent;
use super::scene_msgs;
use super::{Out, Topic, ZSTD_LEVEL, add_schema, add_topic, emit, write_options};
use crate::output::Pending;
use crate::record::boxes_drawn;
use crate::record::compare::{CompareRun, LogLine, earliest_divergence, log_lines};
use crate::scene::Scene;

/// Magenta of the divergence's box.
const DIVERGENCE_COLOR: [f64; 4] = [1.0, 0.0, 1.0, 0.6];
/// Merges drawn before and after the first divergence, besides the last [`BODIES_CAP`](crate::record::BODIES_CAP).
const AROUND: usize = 256;

/// Log time of merge `k`, in ns.
fn at(k: usize) -> u64 {
    (k as u64 + 1) * 1_000_000
}

/// Writes the `.mcap` comparison of `runs` over `scene` (named `scene_name`) into `file`.
pub fn write_comparison_mcap(
    file: &Pending,
    scene: &Scene,
    scene_name: &str,
    runs: &[CompareRun<'_>],
) -> Result<()> {
    let name = file.dest().display().to_string();
    write(file, scene, scene_name, runs)
        .with_context(|| format!("{name}: cannot write the MCAP comparison"))
}

fn write(file: &Pending, scene: &Scene, scene_name: &str, runs: &[CompareRun<'_>]) -> Result<()> {
    let options = write_options(Some(mcap::Compression::Zstd), ZSTD_LEVEL);
    let mut w = Out {
        mcap: options.create(BufWriter::new(file.file()?))?,
        live: None,
    };
    let buf = &mut Vec::new();
    let scene_update = add_schema::<SceneUpdate, _>(&mut w)?;
    let mut scene_topic = add_topic(&mut w, scene_update, "/scene")?;
    let log_schema = add_schema::<Log, _>(&mut w)?;
    let mut log_topic = add_topic(&mut w, log_schema, "/compare/log")?;
    emit(
        &mut w,
        buf,
        &mut scene_topic,
        0,
        &scene_msgs::scene_update(scene),
    )?;

    let first = earliest_divergence(runs);
    let merge_schema = add_schema::<MergeEvent, _>(&mut w)?;
    for (i, run) in runs.iter().enumerate() {
        let mut topic =
            |name: &str, schema| add_topic(&mut w, schema, &format!("/runs/{i}/{name}"));
        let topics = [
            topic("merge", merge_schema)?,
            topic("bodies", scene_update)?,
            topic("divergence", scene_update)?,
        ];
        write_run(&mut w, buf, topics, run, scene, first)?;
    }
    let heading = LogLine {
        merge: 0,
        warn: false,
        text: format!("{scene_name}: {} runs", runs.len()),
    };
    for l in std::iter::once(heading).chain(log_lines(runs)) {
        use foxglove::messages::log::Level;
        // The runs' lines at 0, the others at their merge's log time.
        let t = if l.merge == 0 && !l.warn {
            0
        } else {
            at(l.merge)
        };
        let level = if l.warn { Level::Warning } else { Level::Info };
        let log = Log {
            timestamp: Some(Timestamp::new(
                (t / 1_000_000_000) as u32,
                (t % 1_000_000_000) as u32,
            )),
            level: level as i32,
            message: l.text,
            name: "wraptree compare".into(),
            file: String::new(),
            line: 0,
        };
        emit(&mut w, buf, &mut log_topic, t, &log)?;
    }
    w.finish_file()
}

/// A run's merges, drawn boxes and divergence mark, on its `[merge, bodies, divergence]`
/// topics.
fn write_run<W: Write + Seek>(
    w: &mut Out<W>,
    buf: &mut Vec<u8>,
    [mut merge_topic, mut bodies_topic, mut divergence_topic]: [Topic; 3],
    run: &CompareRun<'_>,
    scene: &Scene,
    first: Option<usize>,
) -> Result<()> {
    let n = scene.len();
    let mut boxes: Vec<_> = (0..n).map(|p| scene.prim_aabb(p)).collect();
    for (k, m) in run.merges.iter().enumerate() {
        emit(w, buf, &mut merge_topic, at(k), &MergeEvent::from(m))?;
        let near = first.is_some_and(|f| k.abs_diff(f) <= AROUND);
        if let (true, Some(a), Some(b)) = (
            boxes_drawn(m.step, n) || near,
            boxes.get(m.a as usize),
            boxes.get(m.b as usize),
        ) {
            let update = scene_msgs::merge_boxes(a, b, &m.aabb, at(k));
            emit(w, buf, &mut bodies_topic, at(k), &update)?;
        }
        if first == Some(k) {
            let mut e = scene_msgs::entity("divergence", at(k));
            e.cubes = vec![scene_msgs::cube(&m.aabb, DIVERGENCE_COLOR)];
            let update = scene_msgs::update(vec![e]);
            emit(w, buf, &mut divergence_topic, at(k), &update)?;
        }
        boxes.push(m.aabb);
    }
    Ok(())
}
