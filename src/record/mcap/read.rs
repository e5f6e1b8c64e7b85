//! Reads a wraptree `.mcap` recording back: the run's metadata, the embedded scene and the
//! grouping events (what `wraptree replay` rebuilds the Subset Tree from).
//!
//! The file is read in one validated linear pass (mcap's sans-io reader with chunk,
//! data-section and summary CRC checks and a record length limit), so truncated or corrupted
//! files give an error, never a panic, and no index offset from the file is trusted.

use super::messages::{
    DormantEvent, FinishEvent, MergeEvent, PartEvent, RefineStepEvent, RoundEvent,
};
use super::metadata;
use crate::geom::Aabb;
use crate::grouping::{EventLog, Merge, Part, ResolvedParams, SubsetTree};
use crate::record::Detail;
use crate::scene::{LoadOptions, Loaded, Scene, load_bytes_until};
use crate::stop::{Interrupted, Stop, is_interrupted};
use anyhow::{Context, Result, anyhow, bail};
use mcap::records::Record;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use sha2::{Digest, Sha256};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// What a recording holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Recorded {
    /// The `wraptree` metadata record (see [`metadata::KEYS`]).
    pub metadata: BTreeMap<String, String>,
    /// The `wraptree.timing` record (empty for reproducible recordings).
    pub timing: BTreeMap<String, String>,
    /// The run's parameters.
    pub params: ResolvedParams,
    /// What the recording holds.
    pub detail: Detail,
    /// Scene name.
    pub scene_name: String,
    /// File name of the embedded scene.
    pub scene_file_name: String,
    /// The embedded scene file's bytes.
    pub scene_bytes: Vec<u8>,
    /// The options the scene was loaded with (`--polyhedra`, `--strict`).
    pub load_options: LoadOptions,
    /// Number of primitives N.
    pub primitives: u32,
    /// Rounds run.
    pub rounds: u32,
    /// Whether grouping reached the root (false for an interrupted run).
    pub complete: bool,
    /// Every merge, in order (N − 1 when complete).
    pub merges: Vec<Merge>,
    /// (round, dlimit, glimit, active count, dormant count, eligible pairs) per round start.
    pub round_starts: Vec<(u32, f64, f64, u32, u32, u64)>,
    /// (round, merges, new dlimit, new glimit) per doubling.
    pub doublings: Vec<(u32, u32, f64, f64)>,
    /// (round, body) of bodies going dormant; only recorded with merge detail.
    pub dormant: Vec<(u32, u32)>,
    /// Root body id, once finished.
    pub root: Option<u32>,
    /// The refinement's parameters and outcome, when the tree was refined (`record --refine`).
    pub refine: Option<metadata::RefineSummary>,
    /// Every refinement step, in order.
    pub refine_steps: Vec<crate::refine::Step>,
    /// Every part announced, in order (runs with parts: partitioned, pre-grouped).
    pub parts: Vec<Part>,
}

impl Recorded {
    /// The Subset Tree rebuilt from the recorded merges alone, with the leaf boxes and
    /// diameters of `scene` (the embedded scene, loaded). Fails unless the merges form one tree.
    pub fn tree(&self, scene: &Scene) -> Result<SubsetTree, String> {
        let boxes: Vec<Aabb> = (0..scene.len()).map(|i| scene.prim_aabb(i)).collect();
        let diam = boxes.iter().map(Aabb::diameter).collect();
        let merges: Vec<_> = self
            .merges
            .iter()
            .map(|m| (m.a, m.b, m.aabb, m.diameter))
            .collect();
        SubsetTree::from_merges(boxes, diam, &merges)
    }

    /// The recorded events as an [`EventLog`] (dormant bodies only with merge detail).
    pub fn event_log(&self) -> EventLog {
        EventLog {
            merges: self.merges.clone(),
            rounds: self.round_starts.clone(),
            dormant: self.dormant.clone(),
            doublings: self.doublings.clone(),
            root: self.root,
            refine_start: self.refine.map(|r| (r.params, r.sah_before)),
            refine: self.refine_steps.clone(),
            parts: self.parts.clone(),
        }
    }
}

/// Raw content gathered by the linear pass.
#[derive(Default)]
struct Raw {
    schemas: HashMap<u16, String>,
    channels: HashMap<u16, (String, u16, String)>,
    metadata: Vec<(String, BTreeMap<String, String>)>,
    /// (name, media type, data) of every attachment.
    attachments: Vec<(String, String, Vec<u8>)>,
    /// The most bytes a record, or the attached scene decompressed, may hold.
    limit: usize,
    merges: Vec<Merge>,
    /// Per merge, its AABB when the message holds one (else the children's boxes give it).
    boxes: Vec<Option<Aabb>>,
    rounds: Vec<RoundEvent>,
    dormant: Vec<DormantEvent>,
    finish: Option<FinishEvent>,
    refine: Vec<crate::refine::Step>,
    parts: Vec<Part>,
}

/// The schema each decoded topic must carry.
const TYPED_TOPICS: &[(&str, &str)] = &[
    ("/grouping/merge", "mergeevent.MergeEvent"),
    ("/grouping/round", "roundevent.RoundEvent"),
    ("/grouping/dormant", "dormantevent.DormantEvent"),
    ("/grouping/finish", "finishevent.FinishEvent"),
    ("/refine/step", "refinestepevent.RefineStepEvent"),
    ("/grouping/part", "partevent.PartEvent"),
];

impl Raw {
    fn message(&mut self, channel_id: u16, data: &[u8]) -> Result<(), String> {
        let Some((topic, schema_id, encoding)) = self.channels.get(&channel_id) else {
            return Err(format!("message on unknown channel {channel_id}"));
        };
        let Some(&(_, want)) = TYPED_TOPICS.iter().find(|(t, _)| t == topic) else {
            return Ok(());
        };
        let schema = self.schemas.get(schema_id).map_or("", String::as_str);
        if schema != want || encoding != "protobuf" {
            return Err(format!(
                "{topic} has schema {schema:?} ({encoding}), expected {want} (protobuf)"
            ));
        }
        let bad = |e: String| format!("bad {topic} message: {e}");
        match topic.as_str() {
            "/grouping/merge" => {
                let decoded = MergeEvent::decode(data).and_then(|e| e.to_merge());
                let (merge, aabb) = decoded.map_err(bad)?;
                self.merges.push(merge);
                self.boxes.push(aabb);
            }
            "/grouping/round" => self.rounds.push(RoundEvent::decode(data).map_err(bad)?),
            "/grouping/dormant" => self.dormant.push(DormantEvent::decode(data).map_err(bad)?),
            "/refine/step" => self.refine.push(crate::refine::Step::from(
                &RefineStepEvent::decode(data).map_err(bad)?,
            )),
            "/grouping/part" => {
                let e = PartEvent::decode(data).map_err(bad)?;
                self.parts.push(Part::try_from(&e).map_err(bad)?);
            }
            _ => self.finish = Some(FinishEvent::decode(data).map_err(bad)?),
        }
        Ok(())
    }

    fn record(&mut self, rec: Record<'_>) -> Result<(), String> {
        match rec {
            Record::Schema { header, .. } => {
                self.schemas.insert(header.id, header.name);
            }
            Record::Channel(c) => {
                self.channels
                    .insert(c.id, (c.topic, c.schema_id, c.message_encoding));
            }
            Record::Message { header, data } => self.message(header.channel_id, &data)?,
            Record::Attachment { header, data, .. } => {
                self.attachments
                    .push((header.name, header.media_type, data.into_owned()))
            }
            Record::Metadata(m) => self.metadata.push((m.name, m.metadata)),
            _ => {}
        }
        Ok(())
    }
}

/// Flattens an error and its sources into one line.
fn one_line(e: &dyn std::error::Error) -> String {
    let mut s = e.to_string();
    let mut src = e.source();
    while let Some(cause) = src {
        s.push_str(": ");
        s.push_str(&cause.to_string());
        src = cause.source();
    }
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Describes an MCAP-level failure for a user.
fn describe(e: &mcap::McapError) -> String {
    use mcap::McapError as E;
    let what = match e {
        E::UnexpectedEof | E::UnexpectedEoc => "truncated MCAP file",
        E::BadMagic => "not an MCAP file",
        E::BadChunkCrc { .. }
        | E::BadDataCrc { .. }
        | E::BadSummaryCrc { .. }
        | E::BadAttachmentCrc { .. } => "corrupted MCAP file (checksum mismatch)",
        _ => "corrupted or unreadable MCAP file",
    };
    format!("{what}: {}", one_line(e))
}

/// One validated pass over every record of `bytes`, ending early (with an error) once `stop` is
/// requested.
fn scan(bytes: &[u8], stop: &Stop) -> Result<Raw, String> {
    let limit = bytes.len().saturating_mul(64).max(64 << 20);
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_prevalidate_chunk_crcs(true)
            .with_validate_chunk_crcs(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_check_finishes_after_end_magic(true)
            .with_record_length_limit(limit),
    );
    let mut raw = Raw {
        limit,
        ..Raw::default()
    };
    let mut rest = bytes;
    let mut events = 0usize;
    while let Some(event) = reader.next_event() {
        stop.check_every(events).map_err(|e| e.to_string())?;
        events += 1;
        match event.map_err(|e| describe(&e))? {
            LinearReadEvent::ReadRequest(n) => {
                let k = n.min(rest.len());
                reader.insert(k).copy_from_slice(&rest[..k]);
                reader.notify_read(k);
                rest = &rest[k..];
            }
            LinearReadEvent::Record { data, opcode } => {
                let rec = mcap::parse_record(opcode, data).map_err(|e| describe(&e))?;
                raw.record(rec)?;
            }
        }
    }
    Ok(raw)
}

/// Checks the merges form the sequence a run of N primitives makes.
fn check_merges(merges: &[Merge], n: u32, complete: bool) -> Result<(), String> {
    if complete && merges.len() as u64 + 1 != u64::from(n) {
        return Err(format!(
            "complete run of {n} primitives holds {} merges",
            merges.len()
        ));
    }
    for (i, m) in merges.iter().enumerate() {
        let i = i as u32;
        if m.step != i
            || u64::from(m.new) != u64::from(n) + u64::from(i)
            || m.a >= m.b
            || m.b >= m.new
        {
            return Err(format!(
                "merge {i} is inconsistent (step {}, bodies {} + {} -> {})",
                m.step, m.a, m.b, m.new
            ));
        }
    }
    Ok(())
}

/// The embedded scene loaded as recorded. Err: it does not load, or has another number of
/// primitives than the metadata says.
fn load_scene(
    name: &str,
    bytes: &[u8],
    options: &LoadOptions,
    primitives: u32,
    stop: &Stop,
) -> Result<Loaded> {
    let loaded = load_bytes_until(name, bytes.to_vec(), options, stop)
        .context("the embedded scene does not load")?;
    if loaded.scene.len() as u64 != u64::from(primitives) {
        bail!(
            "the embedded scene has {} primitives, the metadata says {primitives}",
            loaded.scene.len()
        );
    }
    Ok(loaded)
}

/// Gives each merge whose message left its AABB out the union of its children's boxes: the
/// primitives' of `scene`, then the earlier merges'. The merges must be consistent
/// ([`check_merges`]).
fn fill_boxes(merges: &mut [Merge], boxes: &[Option<Aabb>], scene: &Scene) {
    let mut body: Vec<Aabb> = (0..scene.len()).map(|i| scene.prim_aabb(i)).collect();
    for (m, aabb) in merges.iter_mut().zip(boxes) {
        let (a, b) = (body[m.a as usize], body[m.b as usize]);
        m.aabb = aabb.unwrap_or_else(|| a.merge(&b));
        body.push(m.aabb);
    }
}

/// Checks what was read against the run record, loads the embedded scene and assembles the
/// [`Recorded`] run.
fn interpret(mut raw: Raw, stop: &Stop) -> Result<(Recorded, Loaded)> {
    let (m, timing) = run_and_timing(raw.metadata)?;
    // Older recordings' settings filled in, once; a newer format is an error here.
    let m = metadata::current_form(m)?;
    let (scene_file_name, scene_bytes) = embedded_scene(raw.attachments, &m, raw.limit)?;
    let complete = metadata::parse::<bool>(&m, "complete")?;
    let primitives = metadata::parse::<u32>(&m, "primitives")?;
    check_merges(&raw.merges, primitives, complete).map_err(|e| anyhow!(e))?;
    let load_options = LoadOptions {
        polyhedra: metadata::parse(&m, "polyhedra")?,
        strict: metadata::parse(&m, "strict")?,
        // Written only when the scene was loaded with an up axis (`--up`).
        up: match m.contains_key("up") {
            true => Some(metadata::parse(&m, "up")?),
            false => None,
        },
    };
    let loaded = load_scene(
        &scene_file_name,
        &scene_bytes,
        &load_options,
        primitives,
        stop,
    )?;
    fill_boxes(&mut raw.merges, &raw.boxes, &loaded.scene);
    let refine = metadata::refine(&m)?;
    check_refine_steps(&raw.refine, refine.map_or(0, |r| r.steps as usize))?;
    let round_starts = raw.rounds.iter().filter(|r| !r.doubling);
    let rounds = match m.get("rounds") {
        Some(_) => metadata::parse(&m, "rounds")?,
        None => round_starts.clone().count() as u32,
    };
    let recorded = Recorded {
        params: metadata::params(&m)?,
        detail: metadata::detail(&m)?,
        scene_name: metadata::get(&m, "scene")?.to_string(),
        load_options,
        scene_file_name,
        scene_bytes,
        primitives,
        rounds,
        complete,
        merges: raw.merges,
        round_starts: round_starts
            .map(|r| (r.round, r.dlimit, r.glimit, r.active, r.dormant, r.pairs))
            .collect(),
        doublings: raw
            .rounds
            .iter()
            .filter(|r| r.doubling)
            .map(|r| (r.round, r.merges, r.dlimit, r.glimit))
            .collect(),
        dormant: raw.dormant.iter().map(|d| (d.round, d.body)).collect(),
        root: raw.finish.map(|f| f.root),
        refine,
        refine_steps: raw.refine,
        parts: raw.parts,
        metadata: m,
        timing,
    };
    Ok((recorded, loaded))
}

/// A metadata record's keys and values.
type KeyValues = BTreeMap<String, String>;

/// The run record (the first `wraptree` one) and the timing record (empty when left out).
/// Err: no run record.
fn run_and_timing(records: Vec<(String, KeyValues)>) -> Result<(KeyValues, KeyValues)> {
    let mut meta = None;
    let mut timing = BTreeMap::new();
    for (name, m) in records {
        match name.as_str() {
            metadata::RUN if meta.is_none() => meta = Some(m),
            metadata::TIMING => timing = m,
            _ => {}
        }
    }
    let m = meta.ok_or_else(|| {
        anyhow!(
            "not a wraptree recording (no `{}` metadata record)",
            metadata::RUN
        )
    })?;
    Ok((m, timing))
}

/// The attached scene file named by the run record `m`, with its name: attached as it is, or
/// compressed with Zstandard as `<name>.zst` (decompressed to at most `limit` bytes). Err:
/// missing, not decompressing, or its SHA-256 is not the recorded one.
fn embedded_scene(
    attachments: Vec<(String, String, Vec<u8>)>,
    m: &KeyValues,
    limit: usize,
) -> Result<(String, Vec<u8>)> {
    let scene_file_name = metadata::get(m, "scene_file")?.to_string();
    let compressed = format!("{scene_file_name}{}", super::ZSTD_SUFFIX);
    let mut found = None;
    for (name, media_type, data) in attachments {
        if name == scene_file_name {
            found = Some(data);
            break;
        }
        if name == compressed && media_type == super::ZSTD_MEDIA_TYPE {
            found = Some(decompress(&data, limit).map_err(|e| {
                anyhow!("the embedded scene `{compressed}` does not decompress: {e}")
            })?);
            break;
        }
    }
    let scene_bytes =
        found.ok_or_else(|| anyhow!("the embedded scene `{scene_file_name}` is missing"))?;
    let sha256: String = Sha256::digest(&scene_bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    if !sha256.eq_ignore_ascii_case(metadata::get(m, "scene_sha256")?) {
        bail!("the embedded scene `{scene_file_name}` does not match its recorded sha256");
    }
    Ok((scene_file_name, scene_bytes))
}

/// Decompresses a Zstandard stream of at most `limit` bytes.
fn decompress(data: &[u8], limit: usize) -> Result<Vec<u8>, String> {
    use std::io::Read as _;
    let decoder = zstd::stream::read::Decoder::new(data).map_err(|e| one_line(&e))?;
    let mut out = Vec::new();
    decoder
        .take(limit as u64 + 1)
        .read_to_end(&mut out)
        .map_err(|e| one_line(&e))?;
    if out.len() > limit {
        return Err(format!("more than {limit} bytes"));
    }
    Ok(out)
}

/// Checks that the refinement steps are the `steps_named` of the metadata, numbered in order.
fn check_refine_steps(steps: &[crate::refine::Step], steps_named: usize) -> Result<()> {
    if steps.len() != steps_named || steps.iter().enumerate().any(|(i, s)| s.step as usize != i) {
        bail!(
            "the recording holds {} refinement steps, its metadata says {steps_named}",
            steps.len()
        );
    }
    Ok(())
}

/// Reads a wraptree `.mcap` recording. Truncated, corrupted or foreign files give one error line
/// naming the file and the problem.
pub fn read_recording(path: &Path) -> Result<Recorded> {
    read_with_scene(path).map(|(recorded, _)| recorded)
}

/// Reads a wraptree `.mcap` recording and its embedded scene, loaded with the recorded options
/// ([`read_recording`]); an embedded scene that does not load or does not match the metadata is
/// one error line too.
pub fn read_with_scene(path: &Path) -> Result<(Recorded, Loaded)> {
    read_with_scene_until(path, &Stop::new())
}

/// [`read_with_scene`], its passes checking `stop` (Err: [`Interrupted`]).
pub fn read_with_scene_until(path: &Path, stop: &Stop) -> Result<(Recorded, Loaded)> {
    let name = path.display();
    let bytes =
        std::fs::read(path).map_err(|e| anyhow!("{name}: cannot read: {}", one_line(&e)))?;
    let raw = match scan(&bytes, stop) {
        Err(_) if stop.is_requested() => return Err(Interrupted.into()),
        raw => raw.map_err(|e| anyhow!("{name}: {e}"))?,
    };
    interpret(raw, stop).map_err(|e| {
        if is_interrupted(&e) {
            return e;
        }
        anyhow!(
            "{name}: {}",
            format!("{e:#}")
                .split_whitespace()
                .collect::<Vec<_>>()
                .join(" ")
        )
    })
}
