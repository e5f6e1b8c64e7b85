//! The `.mcap` of a comparison ([`crate::record::compare`]), for Foxglove with
//! `recordings/foxglove-compare-layout.json`.
//!
//! Topics: `/scene` (the scene, at 0), and per run i: `/runs/<i>/merge` (every merge, the
//! `/grouping/merge` message), `/runs/<i>/bodies` (the merged pair and new body, for the last
//! [`BODIES_CAP`](crate::record::BODIES_CAP) merges and around the first divergence) and `/runs/<i>/divergence` (the pair
//! run i merges at the first divergence); `/compare/log` (`foxglove.Log`: the runs, the
//! divergence, each run's finish). Merge k of every run is at log time k + 1 ms, so the runs
//! share one timeline; the file is chunked, zstd-compressed, and the same runs give the same bytes.

use std::collections::BTreeMap;
use std::io::BufWriter;

use anyhow::{Context, Result, anyhow};
use foxglove::Encode;
use foxglove::messages::{Log, SceneUpdate, Timestamp};

use super::messages::MergeEvent;
use super::scene_msgs;
use super::{CHUNK_SIZE, LIBRARY, PROFILE, ZSTD_LEVEL};
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

struct Writer<W: std::io::Write + std::io::Seek> {
    mcap: mcap::Writer<W>,
    seq: BTreeMap<u16, u32>,
    buf: Vec<u8>,
}

impl<W: std::io::Write + std::io::Seek> Writer<W> {
    fn topic<T: Encode>(&mut self, name: &str) -> Result<u16> {
        let s = T::get_schema().ok_or_else(|| anyhow!("message type without a schema"))?;
        let schema = self.mcap.add_schema(&s.name, &s.encoding, &s.data)?;
        Ok(self
            .mcap
            .add_channel(schema, name, "protobuf", &BTreeMap::new())?)
    }

    fn emit<T: Encode>(&mut self, channel: u16, t_ns: u64, msg: &T) -> Result<()> {
        self.buf.clear();
        msg.encode(&mut self.buf)
            .map_err(|e| anyhow!("encoding a message: {e}"))?;
        let seq = self.seq.entry(channel).or_insert(0);
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: *seq,
            log_time: t_ns,
            publish_time: t_ns,
        };
        *seq += 1;
        self.mcap.write_to_known_channel(&header, &self.buf)?;
        Ok(())
    }
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
    let options = mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Zstd))
        .compression_level(ZSTD_LEVEL)
        .chunk_size(Some(CHUNK_SIZE))
        .use_chunks(true)
        .profile(PROFILE)
        .library(LIBRARY);
    let mut w = Writer {
        mcap: options.create(BufWriter::new(file.file()?))?,
        seq: BTreeMap::new(),
        buf: Vec::new(),
    };
    let scene_topic = w.topic::<SceneUpdate>("/scene")?;
    let log_topic = w.topic::<Log>("/compare/log")?;
    w.emit(scene_topic, 0, &scene_msgs::scene_update(scene))?;

    let first = earliest_divergence(runs);
    for (i, run) in runs.iter().enumerate() {
        write_run(&mut w, i, run, scene, first)?;
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
        w.emit(log_topic, t, &log)?;
    }
    w.mcap.finish()?;
    let inner = w
        .mcap
        .into_inner()
        .into_inner()
        .map_err(|e| e.into_error())?;
    inner.sync_all()?;
    Ok(())
}

/// Run `i`'s merges, drawn boxes and divergence mark.
fn write_run<W: std::io::Write + std::io::Seek>(
    w: &mut Writer<W>,
    i: usize,
    run: &CompareRun<'_>,
    scene: &Scene,
    first: Option<usize>,
) -> Result<()> {
    let merge_topic = w.topic::<MergeEvent>(&format!("/runs/{i}/merge"))?;
    let bodies_topic = w.topic::<SceneUpdate>(&format!("/runs/{i}/bodies"))?;
    let divergence_topic = w.topic::<SceneUpdate>(&format!("/runs/{i}/divergence"))?;
    let n = scene.len();
    let mut boxes: Vec<_> = (0..n).map(|p| scene.prim_aabb(p)).collect();
    for (k, m) in run.merges.iter().enumerate() {
        w.emit(merge_topic, at(k), &MergeEvent::from(m))?;
        let near = first.is_some_and(|f| k.abs_diff(f) <= AROUND);
        if let (true, Some(a), Some(b)) = (
            boxes_drawn(m.step, n) || near,
            boxes.get(m.a as usize),
            boxes.get(m.b as usize),
        ) {
            let mut e = scene_msgs::entity("merge", at(k));
            e.cubes = vec![
                scene_msgs::cube(a, scene_msgs::PAIR_COLOR),
                scene_msgs::cube(b, scene_msgs::PAIR_COLOR),
                scene_msgs::cube(&m.aabb, scene_msgs::NEW_COLOR),
            ];
            w.emit(bodies_topic, at(k), &scene_msgs::update(vec![e]))?;
        }
        if first == Some(k) {
            let mut e = scene_msgs::entity("divergence", at(k));
            e.cubes = vec![scene_msgs::cube(&m.aabb, DIVERGENCE_COLOR)];
            w.emit(divergence_topic, at(k), &scene_msgs::update(vec![e]))?;
        }
        boxes.push(m.aabb);
    }
    Ok(())
}
