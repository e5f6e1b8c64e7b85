//! Fuzzing the `.mcap` reading path of `wraptree replay` with mutations of real recordings.
//!
//! Two small recordings are made in memory (a finished one and one stopped after a few merges).
//! Each case either mutates the file's bytes (flips, truncations, splices, zeroed ranges, huge
//! length fields), which the validating reader must reject, or decodes its records, mutates
//! them (metadata values and keys, message payloads, dropped/duplicated/reordered messages,
//! schema names, the embedded scene with or without a matching hash) and writes a valid MCAP
//! again, which reaches the metadata, protobuf and merge checks behind the CRCs.
//! `read_recording` must never panic: it returns a recording, which then goes through replay's
//! own steps (load the embedded scene, rebuild the Subset Tree from the merges) without panicking,
//! or an error whose text is one line starting with the file's path.
//!
//! Cases: 1,536 by default; `WRAPTREE_FUZZ_CASES=N` runs a longer campaign and
//! `WRAPTREE_FUZZ_SEED=N` changes the (otherwise fixed) random stream (`docs/stability.md`,
//! "Fuzzing").

mod common;

use mcap::records::{MessageHeader, Record};
use proptest::prelude::*;
use proptest::test_runner::{TestCaseError, TestRunner};
use sha2::{Digest, Sha256};
use std::borrow::Cow;
use std::cell::Cell;
use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;
use wraptree::grouping::{Budget, Event, Observer, Params, Tee, group_within};
use wraptree::record::mcap::{McapRecorder, metadata, read_recording};
use wraptree::record::{Detail, Outcome, RunInfo};
use wraptree::scene::{LoadOptions, Loaded, load_bytes};
use wraptree::wrap::{SphereMethod, sphere_tree};

/// Cases per run unless `WRAPTREE_FUZZ_CASES` says otherwise.
const DEFAULT_CASES: u32 = 1536;

/// This target's case count and runner.
fn runner(salt: u64) -> (u32, TestRunner) {
    common::fuzz_runner(salt, DEFAULT_CASES)
}

/// Sets `stop` once `after` merges were seen.
struct StopAfter<'a> {
    after: u32,
    stop: &'a AtomicBool,
}

impl Observer for StopAfter<'_> {
    fn on_event(&mut self, e: &Event<'_>) {
        if let Event::Merge(m) = e
            && m.step + 1 >= self.after
        {
            self.stop.store(true, Ordering::Relaxed);
        }
    }
}

/// A reproducible `.mcap` recording of `loaded` at level detail, stopped after `stop_after`
/// merges when given.
fn recording(loaded: &Loaded, stop_after: Option<u32>) -> Vec<u8> {
    let params = Params::default().resolve(&loaded.scene);
    let info = RunInfo {
        scene: &loaded.scene,
        source: &loaded.source,
        params: &params,
        detail: Detail::Levels,
    };
    let mut rec = McapRecorder::new(Cursor::new(Vec::new()), &info).unwrap();
    rec.set_reproducible(true);
    let stop = AtomicBool::new(false);
    let budget = Budget {
        stop: Some(&stop),
        ..Budget::default()
    };
    let watch = StopAfter {
        after: stop_after.unwrap_or(u32::MAX),
        stop: &stop,
    };
    let result = group_within(&loaded.scene, &params, Tee(&mut rec, watch), &budget);
    let spheres;
    let outcome = match &result {
        Ok(g) => {
            spheres = sphere_tree(&g.tree, &loaded.scene, SphereMethod::default());
            Outcome {
                spheres: Some(&spheres),
                ..Outcome::finished(g)
            }
        }
        Err(s) => Outcome {
            grouping: None,
            spheres: None,
            wrappers: None,
            cover: None,
            merges: s.merges,
            rounds: s.rounds,
            seconds: 0.0,
            stopped: Some(*s),
        },
    };
    rec.finish(&outcome).unwrap().into_inner()
}

/// The records of a recording that `replay` interprets, in file order.
#[derive(Clone, Debug, Default)]
struct Model {
    schemas: Vec<(u16, String, String, Vec<u8>)>,
    channels: Vec<(u16, u16, String, String)>,
    messages: Vec<(MessageHeader, Vec<u8>)>,
    attachments: Vec<(String, String, Vec<u8>)>,
    metadata: Vec<(String, BTreeMap<String, String>)>,
}

impl Model {
    fn parse(bytes: &[u8]) -> Model {
        let mut m = Model::default();
        for rec in mcap::read::ChunkFlattener::new(bytes).unwrap() {
            match rec.unwrap() {
                Record::Schema { header, data } if !m.schemas.iter().any(|s| s.0 == header.id) => {
                    m.schemas
                        .push((header.id, header.name, header.encoding, data.into_owned()));
                }
                Record::Channel(c) if !m.channels.iter().any(|x| x.0 == c.id) => {
                    m.channels
                        .push((c.id, c.schema_id, c.topic, c.message_encoding));
                }
                Record::Message { header, data } => m.messages.push((header, data.into_owned())),
                Record::Attachment { header, data, .. } => {
                    m.attachments
                        .push((header.name, header.media_type, data.into_owned()))
                }
                Record::Metadata(x) => m.metadata.push((x.name, x.metadata)),
                _ => {}
            }
        }
        m
    }

    /// A valid MCAP file holding the model's records.
    fn write(&self) -> Vec<u8> {
        let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
        for (id, name, enc, data) in &self.schemas {
            w.add_schema_with_id(*id, name, enc, data).unwrap();
        }
        let known: Vec<u16> = self.schemas.iter().map(|s| s.0).collect();
        let mut channels = Vec::new();
        for (id, schema, topic, enc) in &self.channels {
            let schema = if known.contains(schema) { *schema } else { 0 };
            w.add_channel_with_id(*id, schema, topic, enc, &BTreeMap::new())
                .unwrap();
            channels.push(*id);
        }
        for (h, data) in &self.messages {
            if channels.contains(&h.channel_id) {
                w.write_to_known_channel(h, data).unwrap();
            }
        }
        for (name, media, data) in &self.attachments {
            w.attach(&mcap::Attachment {
                log_time: 0,
                create_time: 0,
                name: name.clone(),
                media_type: media.clone(),
                data: Cow::Borrowed(data),
            })
            .unwrap();
        }
        for (name, m) in &self.metadata {
            w.write_metadata(&mcap::records::Metadata {
                name: name.clone(),
                metadata: m.clone(),
            })
            .unwrap();
        }
        w.finish().unwrap();
        w.into_inner().into_inner()
    }
}

/// Values that metadata parsers get wrong.
const VALUES: &[&str] = &[
    "",
    "nan",
    "-nan",
    "inf",
    "-1",
    "0",
    "1",
    "1e999",
    "-0",
    "true",
    "false",
    "none",
    "aabb",
    "hull",
    "levels",
    "full",
    "18446744073709551616",
    "4294967295",
    "4294967296",
    "0x10",
    "é",
    "1 2",
];

/// A structural or byte-level edit of a recording.
#[derive(Clone, Debug)]
enum Edit {
    /// Set the k-th key of the run record (among its keys and `metadata::KEYS`) to a value.
    MetaSet(usize, &'static str),
    /// Remove the k-th key of the run record.
    MetaDelete(usize),
    /// XOR a byte of the k-th message.
    MsgFlip(usize, f64, u8),
    /// Cut the k-th message to a fraction of its length.
    MsgTruncate(usize, f64),
    /// Drop the k-th message.
    MsgDrop(usize),
    /// Duplicate the k-th message.
    MsgDuplicate(usize),
    /// Swap two messages.
    MsgSwap(usize, usize),
    /// Rename the k-th schema.
    SchemaRename(usize),
    /// XOR a byte of the embedded scene with the mask, or cut the scene there without one;
    /// with `true` the recorded hash is updated to match (and a compressed scene is edited
    /// decompressed, else in its compressed bytes).
    Scene(f64, Option<u8>, bool),
}

/// A byte-level edit of the file (applied after the structural ones).
#[derive(Clone, Debug)]
enum Bytes {
    Flip(f64, u8),
    Truncate(f64),
    Splice(f64, f64, f64, f64),
    Zero(f64, usize),
    Huge(f64),
}

fn edit() -> impl Strategy<Value = Edit> {
    let f = || 0.0..1.0f64;
    let k = || any::<usize>();
    prop_oneof![
        4 => (k(), prop::sample::select(VALUES)).prop_map(|(k, v)| Edit::MetaSet(k, v)),
        1 => k().prop_map(Edit::MetaDelete),
        3 => (k(), f(), 1u8..=255).prop_map(|(k, p, m)| Edit::MsgFlip(k, p, m)),
        1 => (k(), f()).prop_map(|(k, p)| Edit::MsgTruncate(k, p)),
        1 => k().prop_map(Edit::MsgDrop),
        1 => k().prop_map(Edit::MsgDuplicate),
        1 => (k(), k()).prop_map(|(a, b)| Edit::MsgSwap(a, b)),
        1 => k().prop_map(Edit::SchemaRename),
        3 => (f(), prop::option::of(1u8..=255), any::<bool>())
            .prop_map(|(p, m, h)| Edit::Scene(p, m, h)),
    ]
}

fn bytes_edit() -> impl Strategy<Value = Bytes> {
    let f = || 0.0..1.0f64;
    prop_oneof![
        3 => (f(), 1u8..=255).prop_map(|(p, m)| Bytes::Flip(p, m)),
        2 => f().prop_map(Bytes::Truncate),
        1 => (f(), f(), f(), f()).prop_map(|(a, b, c, d)| Bytes::Splice(a, b, c, d)),
        1 => (f(), 1usize..64).prop_map(|(p, n)| Bytes::Zero(p, n)),
        1 => f().prop_map(Bytes::Huge),
    ]
}

fn at(f: f64, len: usize) -> usize {
    ((f * len as f64) as usize).min(len)
}

fn sha256_hex(b: &[u8]) -> String {
    Sha256::digest(b)
        .iter()
        .map(|x| format!("{x:02x}"))
        .collect()
}

fn apply(m: &mut Model, e: &Edit) {
    let run = m
        .metadata
        .iter_mut()
        .find(|(n, _)| n == metadata::RUN)
        .map(|(_, r)| r);
    match *e {
        Edit::MetaSet(k, v) => {
            if let Some(r) = run {
                let mut keys: Vec<String> = r.keys().cloned().collect();
                keys.extend(metadata::KEYS.iter().map(|s| s.to_string()));
                let key = keys[k % keys.len()].clone();
                r.insert(key, v.to_string());
            }
        }
        Edit::MetaDelete(k) => {
            if let Some(r) = run
                && !r.is_empty()
            {
                let key = r.keys().nth(k % r.len()).unwrap().clone();
                r.remove(&key);
            }
        }
        Edit::MsgFlip(k, p, mask) if !m.messages.is_empty() => {
            let n = m.messages.len();
            let data = &mut m.messages[k % n].1;
            if !data.is_empty() {
                let i = at(p, data.len() - 1);
                data[i] ^= mask;
            }
        }
        Edit::MsgTruncate(k, p) if !m.messages.is_empty() => {
            let n = m.messages.len();
            let data = &mut m.messages[k % n].1;
            data.truncate(at(p, data.len()));
        }
        Edit::MsgDrop(k) if !m.messages.is_empty() => {
            let n = m.messages.len();
            m.messages.remove(k % n);
        }
        Edit::MsgDuplicate(k) if !m.messages.is_empty() => {
            let n = m.messages.len();
            let x = m.messages[k % n].clone();
            m.messages.insert(k % n, x);
        }
        Edit::MsgSwap(a, b) if !m.messages.is_empty() => {
            let n = m.messages.len();
            m.messages.swap(a % n, b % n);
        }
        Edit::SchemaRename(k) if !m.schemas.is_empty() => {
            let n = m.schemas.len();
            m.schemas[k % n].1.push_str(".x");
        }
        Edit::Scene(p, mask, rehash) => {
            let Some(r) = run else { return };
            let Some(name) = r.get("scene_file").cloned() else {
                return;
            };
            let zst = format!("{name}.zst");
            let Some(att) = m.attachments.iter_mut().find(|a| a.0 == name || a.0 == zst) else {
                return;
            };
            // A compressed scene is edited decompressed and compressed again when the hash is
            // updated (reaching the scene loader), else (or when an earlier edit broke it) in its
            // compressed bytes (reaching the decompression and the hash check).
            let decompressed = (att.0 == zst && rehash)
                .then(|| zstd::decode_all(&att.2[..]).ok())
                .flatten();
            let recompress = decompressed.is_some();
            let mut plain = decompressed.unwrap_or_else(|| std::mem::take(&mut att.2));
            let data = &mut plain;
            match mask {
                Some(mask) if !data.is_empty() => {
                    let i = at(p, data.len() - 1);
                    data[i] ^= mask;
                }
                Some(_) => {}
                None => data.truncate(at(p, data.len())),
            }
            if rehash {
                r.insert("scene_sha256".into(), sha256_hex(data));
            }
            att.2 = match recompress {
                true => zstd::encode_all(&plain[..], 3).expect("compresses"),
                false => plain,
            };
        }
        _ => {}
    }
}

fn apply_bytes(b: &mut Vec<u8>, e: &Bytes) {
    let len = b.len();
    match *e {
        Bytes::Flip(p, mask) if len > 0 => b[at(p, len - 1)] ^= mask,
        Bytes::Truncate(p) => b.truncate(at(p, len)),
        Bytes::Splice(x, y, c, d) => {
            let (x, y) = (at(x.min(y), len), at(x.max(y), len));
            let (c, d) = (at(c.min(d), len), at(c.max(d), len));
            let piece = b[c..d].to_vec();
            b.splice(x..y, piece);
        }
        Bytes::Zero(p, n) => {
            let s = at(p, len);
            let e = (s + n).min(len);
            b[s..e].fill(0);
        }
        Bytes::Huge(p) if len >= 8 => {
            let s = at(p, len - 8);
            b[s..s + 8].copy_from_slice(&u64::MAX.to_le_bytes());
        }
        _ => {}
    }
}

/// What `replay` does with a recording after reading it; must not panic.
fn replay_steps(rec: &wraptree::record::mcap::Recorded) -> Result<(), TestCaseError> {
    prop_assert!(!rec.complete || rec.merges.len() as u64 + 1 == u64::from(rec.primitives));
    let Ok(loaded) = load_bytes(
        &rec.scene_file_name,
        rec.scene_bytes.clone(),
        &rec.load_options,
    ) else {
        return Ok(());
    };
    let s = &loaded.scene;
    if s.len() as u32 != rec.primitives {
        return Ok(());
    }
    if rec.complete {
        let _ = rec.tree(s);
    }
    Ok(())
}

#[test]
fn mutated_recordings_read_or_fail_with_one_line() {
    let loaded = load_bytes(
        "grid.obj",
        common::grid_obj(4, 3, 1.7, 0.05),
        &LoadOptions::default(),
    )
    .unwrap();
    let originals = [recording(&loaded, None), recording(&loaded, Some(4))];
    let models: Vec<Model> = originals.iter().map(|b| Model::parse(b)).collect();
    let dir = tempfile::tempdir().unwrap();
    for (i, b) in originals.iter().enumerate() {
        let p = dir.path().join(format!("orig{i}.mcap"));
        std::fs::write(&p, b).unwrap();
        let rec = read_recording(&p).expect("the originals read");
        assert_eq!(rec.complete, i == 0);
        let rewritten = dir.path().join(format!("rewritten{i}.mcap"));
        std::fs::write(&rewritten, models[i].write()).unwrap();
        let again = read_recording(&rewritten).expect("a rewritten original reads");
        assert_eq!(again.merges, rec.merges, "rewriting keeps the content");
    }
    let (cases, mut runner) = runner(0x3ca9);
    let (accepted, rejected) = (Cell::new(0u32), Cell::new(0u32));
    let bump = |c: &Cell<u32>| c.set(c.get() + 1);
    let path = dir.path().join("mutant.mcap");
    let strategy = (
        0..2usize,
        prop::collection::vec(edit(), 0..4),
        prop::collection::vec(bytes_edit(), 0..3),
    );
    let start = Instant::now();
    let result = runner.run(&strategy, |(which, edits, byte_edits)| {
        let mut bytes = if edits.is_empty() {
            originals[which].clone()
        } else {
            let mut m = models[which].clone();
            for e in &edits {
                apply(&mut m, e);
            }
            m.write()
        };
        for e in &byte_edits {
            apply_bytes(&mut bytes, e);
        }
        std::fs::write(&path, &bytes).unwrap();
        match read_recording(&path) {
            Ok(rec) => {
                replay_steps(&rec)?;
                bump(&accepted);
            }
            Err(e) => {
                let msg = format!("{e:#}");
                let want = format!("{}: ", path.display());
                prop_assert!(msg.starts_with(&want) && !msg.contains('\n'), "{msg:?}");
                bump(&rejected);
            }
        }
        Ok(())
    });
    let (accepted, rejected) = (accepted.get(), rejected.get());
    eprintln!(
        "fuzz_mcap: {cases} cases, {accepted} accepted, {rejected} rejected, {:.1} s",
        start.elapsed().as_secs_f64()
    );
    if let Err(e) = result {
        panic!("{e}");
    }
    assert!(
        accepted > cases / 50 && rejected > cases / 4,
        "the edits both keep and break recordings"
    );
}

/// `read_recording` names the file even for paths that do not exist or are directories.
#[test]
fn unreadable_paths_give_one_line() {
    let dir = tempfile::tempdir().unwrap();
    for p in [dir.path().join("absent.mcap"), dir.path().to_path_buf()] {
        let e = format!("{:#}", read_recording(Path::new(&p)).unwrap_err());
        assert!(
            e.starts_with(&p.display().to_string()) && !e.contains('\n'),
            "{e}"
        );
    }
}
