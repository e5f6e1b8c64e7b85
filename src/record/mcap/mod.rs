//! Foxglove `.mcap` recordings of a grouping run ([`McapRecorder`]) and their reader
//! ([`read_recording`], used by `wraptree replay`). Topics, compression, log times and metadata
//! are listed in `docs/recordings.md`, "`.mcap` (Foxglove)" and "Metadata".
//!
//! The file is chunked with every CRC on and written front to back; chunks are compressed as
//! [`Compression`] says, single-threaded, so the same run gives the same bytes on every machine.
//! Geometry uses `foxglove.SceneUpdate`, grouping events small protobuf messages derived with
//! `foxglove::Encode` ([`messages`]); every entity is in frame `world`. The scene file is
//! attached, and two metadata records describe the run ([`metadata`]); `wraptree.timing`, the
//! only wall-clock value, is left out by [`McapRecorder::set_reproducible`].
//!
//! **Log times** are synthetic and monotonic: the scene at 0, the k-th grouping event (every
//! event, written at this detail or not) at k ms, then `/levels/<d>` at (events + 1 + d) ms and
//! `/cover` at (events + 2 + depth max) ms. Sequence numbers count from 0 on each channel.

mod compare;
mod levels;
pub mod messages;
pub mod metadata;
mod read;
pub mod scene_msgs;
pub(crate) mod spherize;

pub use compare::write_comparison_mcap;
pub use read::{Recorded, read_recording, read_with_scene, read_with_scene_until};

use crate::events::{RefineParams, Step};
use crate::geom::Aabb;
use crate::grouping::{Event, Merge, Observer, Part};
use crate::record::live::foxglove::McapTee;
use crate::record::{Detail, Outcome, RunInfo};
use crate::stop::Stop;
use anyhow::{Context, Result, anyhow};
use foxglove::Encode;
use foxglove::messages::SceneUpdate;
use messages::{DormantEvent, FinishEvent, MergeEvent, PartEvent, RefineStepEvent, RoundEvent};
use std::collections::BTreeMap;
use std::io::{Seek, Write};

/// LZ4 level of every chunk with [`Compression::Lz4`]: 0, the fast (not high-compression)
/// mode.
pub const LZ4_LEVEL: u32 = 0;
/// Zstandard level of every chunk with [`Compression::Zstd`] and of the attached scene
/// (`docs/recordings.md`, "Sizes").
pub const ZSTD_LEVEL: u32 = 3;

/// How the `.mcap`'s chunks are compressed (`record --mcap-compression`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Compression {
    /// Zstandard, level [`ZSTD_LEVEL`], single-threaded: the smallest (also accepted as `auto`,
    /// its former name).
    #[default]
    #[value(alias = "auto")]
    Zstd,
    /// LZ4 frames, fast mode ([`LZ4_LEVEL`]), single-threaded: faster, larger.
    Lz4,
    /// Not at all, the scene attached as it is: the fastest to write and to read.
    None,
}

/// Target uncompressed chunk size.
pub const CHUNK_SIZE: u64 = 1 << 20;
/// Media type of the embedded scene, attached as it is (`--mcap-compression none`).
pub const SCENE_MEDIA_TYPE: &str = "model/obj";
/// Media type of the embedded scene compressed with Zstandard, attached as
/// `<scene file>`[`ZSTD_SUFFIX`].
pub const ZSTD_MEDIA_TYPE: &str = "application/zstd";
/// Appended to the scene file's name when it is attached compressed.
pub const ZSTD_SUFFIX: &str = ".zst";
/// The MCAP header's profile (none of the registered profiles applies).
pub const PROFILE: &str = "";
/// The MCAP header's library string.
pub const LIBRARY: &str = concat!("wraptree ", env!("CARGO_PKG_VERSION"), " (mcap-rs 0.26)");
const MS: u64 = 1_000_000;
/// Without [`McapRecorder::set_all_levels`], levels are written from the root down to the
/// last whose cut is less than this share leaves (level 0 always): the first cut that is half
/// leaves or more, and every deeper one, is mostly the scene itself, and each level repeats its
/// leaves' geometry.
pub const LEVEL_LEAF_SHARE: f64 = 0.5;
pub use crate::record::{ACTIVE_CAP, BODIES_CAP};

/// A channel and its next sequence number.
#[derive(Clone, Copy, Debug)]
struct Topic {
    id: u16,
    seq: u32,
}

/// Channels registered for the grouping events.
#[derive(Clone, Copy, Debug)]
struct Topics {
    round: Topic,
    merge: Topic,
    finish: Topic,
    /// `/grouping/active` and `/grouping/dormant` with per-merge detail.
    detail: Option<[Topic; 2]>,
    /// `/grouping/bodies` with `--detail full`.
    bodies: Option<Topic>,
    /// `/grouping/part`, added at the first part (runs without parts do not have it).
    part: Option<Topic>,
}

/// Writes a grouping run to an `.mcap` file; feed it events as an [`Observer`], then call
/// [`McapRecorder::finish`].
///
/// `W` is written in many small pieces: give it a buffered writer (`record` uses a
/// [`DirectWriter`](crate::record::direct::DirectWriter), tests a `BufWriter`). Write errors do
/// not panic: the first one is kept, later events are ignored, and `finish` returns it.
pub struct McapRecorder<'a, W: Write + Seek> {
    writer: Out<W>,
    info: RunInfo<'a>,
    topics: Topics,
    /// The `/scene` channel, written once by [`McapRecorder::write_scene`].
    scene_topic: Topic,
    scene_update: u16,
    /// AABB of every body seen so far, indexed by body id.
    bodies: Vec<Aabb>,
    events: u64,
    /// The refinement seen so far (`record --refine`) and its `/refine/step` channel.
    refine: Option<(metadata::RefineSummary, Topic)>,
    reproducible: bool,
    all_levels: bool,
    /// Whether the scene is attached as it is (`--mcap-compression none`), not compressed.
    raw_scene: bool,
    /// Obeyed while the scene is compressed ([`McapRecorder::set_stop`]).
    stop: Stop,
    error: Option<anyhow::Error>,
    buf: Vec<u8>,
}

/// The MCAP writer, and the live Foxglove stream (`record --foxglove-ws`) that gets a copy of
/// every schema, channel and message written through [`add_schema`], [`add_topic`] and
/// [`emit`]. The file's bytes do not depend on it.
struct Out<W: Write + Seek> {
    mcap: mcap::Writer<W>,
    live: Option<McapTee>,
}

impl Out<std::io::BufWriter<std::fs::File>> {
    /// Ends the file (summary, footer), flushes it and syncs it to disk.
    fn finish_file(mut self) -> anyhow::Result<()> {
        self.mcap.finish()?;
        let file = self
            .mcap
            .into_inner()
            .into_inner()
            .map_err(|e| e.into_error())?;
        file.sync_all()?;
        Ok(())
    }
}

impl<W: Write + Seek> std::ops::Deref for Out<W> {
    type Target = mcap::Writer<W>;
    fn deref(&self) -> &mcap::Writer<W> {
        &self.mcap
    }
}

impl<W: Write + Seek> std::ops::DerefMut for Out<W> {
    fn deref_mut(&mut self) -> &mut mcap::Writer<W> {
        &mut self.mcap
    }
}

fn add_schema<T: Encode, W: Write + Seek>(w: &mut Out<W>) -> Result<u16> {
    let s = T::get_schema().ok_or_else(|| anyhow!("message type without a schema"))?;
    let id = w.mcap.add_schema(&s.name, &s.encoding, &s.data)?;
    if let Some(live) = &w.live {
        live.schema(id, &s.name, &s.encoding, &s.data);
    }
    Ok(id)
}

fn add_topic<W: Write + Seek>(w: &mut Out<W>, schema: u16, name: &str) -> Result<Topic> {
    let id = w
        .mcap
        .add_channel(schema, name, "protobuf", &BTreeMap::new())?;
    if let Some(live) = &w.live {
        live.channel(id, schema, name, "protobuf");
    }
    Ok(Topic { id, seq: 0 })
}

/// The options of every `.mcap` this crate writes: chunks of [`CHUNK_SIZE`] compressed as
/// given, every CRC on, written front to back.
fn write_options(compression: Option<mcap::Compression>, level: u32) -> mcap::WriteOptions {
    mcap::WriteOptions::new()
        .compression(compression)
        .compression_level(level)
        // One thread: zstd's multithreaded mode gives other bytes than its single-threaded one.
        .compression_threads(0)
        .chunk_size(Some(CHUNK_SIZE))
        .use_chunks(true)
        // Each chunk is built in memory and then appended: the file is written front to
        // back, never rewound (so it can bypass the page cache, `record::direct`).
        .disable_seeking(true)
        .profile(PROFILE)
        .library(LIBRARY)
        .calculate_chunk_crcs(true)
        .calculate_data_section_crc(true)
        .calculate_summary_section_crc(true)
        .calculate_attachment_crcs(true)
}

/// Encodes `msg` into `buf` and writes it on `topic` at `t_ns`.
fn emit<T: Encode, W: Write + Seek>(
    w: &mut Out<W>,
    buf: &mut Vec<u8>,
    topic: &mut Topic,
    t_ns: u64,
    msg: &T,
) -> Result<()> {
    buf.clear();
    msg.encode(buf)
        .map_err(|e| anyhow!("encoding a message: {e}"))?;
    let header = mcap::records::MessageHeader {
        channel_id: topic.id,
        sequence: topic.seq,
        log_time: t_ns,
        publish_time: t_ns,
    };
    topic.seq += 1;
    w.mcap.write_to_known_channel(&header, buf)?;
    if let Some(live) = &w.live {
        live.message(topic.id, t_ns, buf);
    }
    Ok(())
}

impl<'a, W: Write + Seek> McapRecorder<'a, W> {
    /// Starts a recording with the default [`Compression`]: writes the header, schemas, channels, the
    /// `/scene` message and the scene attachment ([`McapRecorder::start`] then
    /// [`McapRecorder::write_scene`]).
    pub fn new(writer: W, info: &RunInfo<'a>) -> Result<Self> {
        let mut rec = Self::start(writer, info, Compression::default())?;
        rec.write_scene();
        match rec.error.take() {
            Some(e) => Err(e),
            None => Ok(rec),
        }
    }

    /// Starts a recording whose chunks are compressed with `compression`: writes the header,
    /// schemas and channels (small; a buffered writer holds them), but not yet the scene.
    pub fn start(writer: W, info: &RunInfo<'a>, compression: Compression) -> Result<Self> {
        Self::start_live(writer, info, compression, None)
    }

    /// As [`McapRecorder::start`], also copying every schema, channel and message written to
    /// `live`, the live Foxglove stream (`record --foxglove-ws`), if given. The file is the same
    /// with or without it.
    pub fn start_live(
        writer: W,
        info: &RunInfo<'a>,
        compression: Compression,
        live: Option<McapTee>,
    ) -> Result<Self> {
        let (compression, level) = match compression {
            Compression::None => (None, 0),
            Compression::Lz4 => (Some(mcap::Compression::Lz4), LZ4_LEVEL),
            Compression::Zstd => (Some(mcap::Compression::Zstd), ZSTD_LEVEL),
        };
        let options = write_options(compression, level);
        let mcap = options.create(writer).context("starting the MCAP file")?;
        let mut w = Out { mcap, live };
        let scene_update = add_schema::<SceneUpdate, W>(&mut w)?;
        let round_schema = add_schema::<RoundEvent, W>(&mut w)?;
        let merge_schema = add_schema::<MergeEvent, W>(&mut w)?;
        let finish_schema = add_schema::<FinishEvent, W>(&mut w)?;
        let scene_topic = add_topic(&mut w, scene_update, "/scene")?;
        let topics = Topics {
            round: add_topic(&mut w, round_schema, "/grouping/round")?,
            merge: add_topic(&mut w, merge_schema, "/grouping/merge")?,
            finish: add_topic(&mut w, finish_schema, "/grouping/finish")?,
            detail: if info.detail.merges() {
                let dormant_schema = add_schema::<DormantEvent, W>(&mut w)?;
                Some([
                    add_topic(&mut w, scene_update, "/grouping/active")?,
                    add_topic(&mut w, dormant_schema, "/grouping/dormant")?,
                ])
            } else {
                None
            },
            bodies: if info.detail == Detail::Full {
                Some(add_topic(&mut w, scene_update, "/grouping/bodies")?)
            } else {
                None
            },
            part: None,
        };
        let scene = info.scene;
        let mut bodies = Vec::with_capacity(2 * scene.len());
        bodies.extend((0..scene.len()).map(|i| scene.prim_aabb(i)));
        Ok(McapRecorder {
            writer: w,
            info: *info,
            topics,
            scene_update,
            bodies,
            events: 0,
            refine: None,
            reproducible: false,
            all_levels: false,
            raw_scene: compression.is_none(),
            stop: Stop::new(),
            error: None,
            buf: Vec::new(),
            scene_topic,
        })
    }

    /// Writes the `/scene` message (every primitive, once) and attaches the scene file
    /// (compressed unless the chunks are not); must
    /// come before the first event. A failure is kept and returned by [`McapRecorder::finish`],
    /// like a write error during the run.
    pub fn write_scene(&mut self) {
        if self.error.is_none()
            && let Err(e) = self.try_write_scene()
        {
            self.error = Some(e);
        }
    }

    fn try_write_scene(&mut self) -> Result<()> {
        let update = scene_msgs::scene_update(self.info.scene);
        emit(
            &mut self.writer,
            &mut self.buf,
            &mut self.scene_topic,
            0,
            &update,
        )?;
        let source = &self.info.source;
        let (name, media_type, data) = if self.raw_scene {
            let data = std::borrow::Cow::Borrowed(&source.bytes[..]);
            (source.file_name.clone(), SCENE_MEDIA_TYPE, data)
        } else {
            let data =
                compress_until(&source.bytes, &self.stop).context("compressing the scene")?;
            let name = format!("{}{ZSTD_SUFFIX}", source.file_name);
            (name, ZSTD_MEDIA_TYPE, std::borrow::Cow::Owned(data))
        };
        self.writer
            .attach(&mcap::Attachment {
                log_time: 0,
                create_time: 0,
                name,
                media_type: media_type.to_string(),
                data,
            })
            .context("attaching the scene")?;
        Ok(())
    }

    /// Ends the scene's compression early once `stop` is requested: [`McapRecorder::finish`]
    /// then fails with [`Interrupted`](crate::stop::Interrupted).
    pub fn set_stop(&mut self, stop: Stop) {
        self.stop = stop;
    }

    /// Leaves out the `wraptree.timing` record, the only wall-clock value, so two recordings of
    /// the same run are byte-identical.
    pub fn set_reproducible(&mut self, on: bool) {
        self.reproducible = on;
    }

    /// Writes every level down to the deepest (`record --all-levels`) instead of stopping
    /// before the first whose cut is [`LEVEL_LEAF_SHARE`] leaves.
    pub fn set_all_levels(&mut self, on: bool) {
        self.all_levels = on;
    }

    /// Writes one event at its log time (the k-th event at k ms) on its topics.
    fn record(&mut self, event: &Event<'_>) -> Result<()> {
        let t = self.events * MS;
        let (w, buf) = (&mut self.writer, &mut self.buf);
        match *event {
            Event::RoundStart {
                round,
                dlimit,
                glimit,
                active,
                dormant,
                pairs,
            } => {
                let msg = RoundEvent {
                    doubling: false,
                    round,
                    dlimit,
                    glimit,
                    active: active.len() as u32,
                    dormant,
                    pairs,
                    merges: 0,
                };
                emit(w, buf, &mut self.topics.round, t, &msg)?;
                self.record_active(t, active)
            }
            Event::Merge(m) => self.record_merge(t, &m),
            Event::Dormant {
                round,
                body,
                diameter,
            } => match self.topics.detail.as_mut() {
                Some([_, dormant_topic]) => {
                    let msg = DormantEvent {
                        round,
                        body,
                        diameter,
                    };
                    emit(w, buf, dormant_topic, t, &msg)
                }
                None => Ok(()),
            },
            Event::Doubling {
                round,
                merges,
                dlimit,
                glimit,
            } => {
                let msg = RoundEvent {
                    doubling: true,
                    round,
                    dlimit,
                    glimit,
                    active: 0,
                    dormant: 0,
                    pairs: 0,
                    merges,
                };
                emit(w, buf, &mut self.topics.round, t, &msg)
            }
            Event::Part(p) => self.record_part(t, &p),
            Event::RefineStart { params, sah } => self.start_refine(params, sah),
            Event::Refine(step) => self.record_refine_step(t, &step),
            Event::Finish {
                root,
                rounds,
                merges,
            } => {
                let msg = FinishEvent {
                    root,
                    rounds,
                    merges,
                };
                emit(w, buf, &mut self.topics.finish, t, &msg)
            }
        }
    }

    /// With per-merge detail, a round's active bodies as boxes on `/grouping/active` (an empty
    /// update above [`ACTIVE_CAP`] of them).
    fn record_active(&mut self, t: u64, active: &[u32]) -> Result<()> {
        let Some([active_topic, _]) = self.topics.detail.as_mut() else {
            return Ok(());
        };
        let shown = if active.len() > ACTIVE_CAP {
            &[][..]
        } else {
            active
        };
        let mut e = scene_msgs::entity("active", t);
        let bodies = &self.bodies;
        e.cubes = shown
            .iter()
            .map(|&id| {
                let b = bodies.get(id as usize).copied().unwrap_or(Aabb::EMPTY);
                scene_msgs::cube(&b, scene_msgs::ACTIVE_COLOR)
            })
            .collect();
        let update = scene_msgs::update(vec![e]);
        emit(&mut self.writer, &mut self.buf, active_topic, t, &update)
    }

    /// A merge on `/grouping/merge`, its AABB left out when it is the union of the pair's;
    /// keeps the new body's box, and with `--detail full` draws the pair and the new body on
    /// `/grouping/bodies` for the last [`BODIES_CAP`] merges.
    fn record_merge(&mut self, t: u64, m: &Merge) -> Result<()> {
        let (w, buf) = (&mut self.writer, &mut self.buf);
        let get = |id: u32| self.bodies.get(id as usize);
        let msg = match (get(m.a), get(m.b)) {
            (Some(a), Some(b)) if a.merge(b) == m.aabb => MergeEvent::from(m).without_box(),
            _ => MergeEvent::from(m),
        };
        emit(w, buf, &mut self.topics.merge, t, &msg)?;
        let new = m.new as usize;
        if self.bodies.len() <= new {
            self.bodies.resize(new + 1, Aabb::EMPTY);
        }
        self.bodies[new] = m.aabb;
        let drawn = crate::record::boxes_drawn(m.step, self.info.scene.len());
        if let Some(bodies_topic) = self.topics.bodies.as_mut().filter(|_| drawn) {
            let get = |id: u32| self.bodies.get(id as usize).copied().unwrap_or(Aabb::EMPTY);
            let update = scene_msgs::merge_boxes(&get(m.a), &get(m.b), &m.aabb, t);
            emit(w, buf, bodies_topic, t, &update)?;
        }
        Ok(())
    }

    /// A part on `/grouping/part`, the channel added at the run's first part.
    fn record_part(&mut self, t: u64, p: &Part) -> Result<()> {
        let w = &mut self.writer;
        let topic = match &mut self.topics.part {
            Some(topic) => topic,
            None => {
                let schema = add_schema::<PartEvent, W>(w)?;
                self.topics
                    .part
                    .insert(add_topic(w, schema, "/grouping/part")?)
            }
        };
        emit(w, &mut self.buf, topic, t, &PartEvent::from(p))
    }

    /// The refinement starts: adds `/refine/step` and its summary, at SAH `sah` so far.
    fn start_refine(&mut self, params: RefineParams, sah: f64) -> Result<()> {
        let w = &mut self.writer;
        let schema = add_schema::<RefineStepEvent, W>(w)?;
        let topic = add_topic(w, schema, "/refine/step")?;
        let summary = metadata::RefineSummary {
            params,
            steps: 0,
            sah_before: sah,
            sah_after: sah,
        };
        self.refine = Some((summary, topic));
        Ok(())
    }

    /// A kept refinement step on `/refine/step`, counted in the summary.
    fn record_refine_step(&mut self, t: u64, step: &Step) -> Result<()> {
        let (summary, topic) = self
            .refine
            .as_mut()
            .ok_or_else(|| anyhow!("refinement step before its start"))?;
        emit(
            &mut self.writer,
            &mut self.buf,
            topic,
            t,
            &RefineStepEvent::from(step),
        )?;
        summary.steps = step.step + 1;
        summary.sah_after = step.sah;
        Ok(())
    }

    /// Levels, metadata records and the summary section.
    fn write_tail(&mut self, outcome: &Outcome<'_>) -> Result<()> {
        let mut run = metadata::run_record(&self.info, outcome);
        if self.info.detail.levels() {
            let written = self.write_levels(outcome)?;
            if outcome.grouping.is_some() {
                run.insert(metadata::LEVELS_WRITTEN.into(), written.to_string());
            }
        }
        if let Some((summary, _)) = &self.refine {
            metadata::put_refine(&mut run, summary);
        }
        self.writer.write_metadata(&mcap::records::Metadata {
            name: metadata::RUN.to_string(),
            metadata: run,
        })?;
        if !self.reproducible {
            self.writer.write_metadata(&mcap::records::Metadata {
                name: metadata::TIMING.to_string(),
                metadata: metadata::timing_record(outcome),
            })?;
        }
        self.writer.finish()?;
        Ok(())
    }

    /// Writes the level snapshots (when the detail asks for them and the run finished), the
    /// metadata records, the summary and the footer, and returns the underlying writer, already
    /// flushed. Returns the first write error of the run instead, if any.
    pub fn finish(mut self, outcome: &Outcome<'_>) -> Result<W> {
        if let Some(e) = self.error.take() {
            return Err(e.context("writing the MCAP recording"));
        }
        self.write_tail(outcome)
            .context("writing the MCAP recording")?;
        Ok(self.writer.mcap.into_inner())
    }
}

impl<W: Write + Seek> Observer for McapRecorder<'_, W> {
    fn on_event(&mut self, event: &Event<'_>) {
        self.events += 1;
        if self.error.is_none()
            && let Err(e) = self.record(event)
        {
            self.error = Some(e);
        }
    }
}

/// `bytes` as one zstd frame at [`ZSTD_LEVEL`], fed in pieces of 1 MiB so that `stop` is seen
/// between them.
fn compress_until(bytes: &[u8], stop: &Stop) -> Result<Vec<u8>> {
    let mut z = zstd::stream::Encoder::new(Vec::with_capacity(bytes.len() / 4), ZSTD_LEVEL as i32)?;
    z.include_contentsize(true)?;
    z.set_pledged_src_size(Some(bytes.len() as u64))?;
    for piece in bytes.chunks(1 << 20) {
        stop.check()?;
        z.write_all(piece)?;
    }
    Ok(z.finish()?)
}
