//! The `.mcap` recorder and reader: what `read_recording` gets back equals the run, two
//! reproducible recordings are byte-identical, bad files give one clear error line, and an
//! independent Python reader (`tests/mcap_check.py`, PyPI `mcap` + `mcap-protobuf-support` +
//! `foxglove-schemas-protobuf`) decodes every message and checks every level covers the scene.
//! The readers are provisioned by the tests (`common::readers`); failing that fails the test.

mod common;

use std::io::{BufWriter, Cursor, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::process::Command;

use wraptree::geom::V3;
use wraptree::grouping::{Event, EventLog, Grouping, Observer, Params, ResolvedParams, Tee, group};
use wraptree::record::mcap::{McapRecorder, metadata, read_recording};
use wraptree::record::{Detail, Outcome, RunInfo};
use wraptree::scene::{LoadOptions, Loaded, generate, load_bytes};
use wraptree::wrap::{SphereMethod, WrapperKind, Wrappers, sphere_tree};

fn load_grid() -> Loaded {
    load_bytes(
        "grid.obj",
        common::grid_obj(10, 6, 1.7, 0.05),
        &LoadOptions::default(),
    )
    .expect("grid loads")
}

/// What the recorder is told about a run of `loaded` with `resolved` at `detail`.
fn run_info<'a>(loaded: &'a Loaded, resolved: &'a ResolvedParams, detail: Detail) -> RunInfo<'a> {
    RunInfo {
        scene: &loaded.scene,
        source: &loaded.source,
        params: resolved,
        detail,
    }
}

/// Forwards only the first `left` events (an interrupted run).
struct FirstEvents<O> {
    left: usize,
    inner: O,
}

impl<O: Observer> Observer for FirstEvents<O> {
    fn on_event(&mut self, e: &Event<'_>) {
        if self.left > 0 {
            self.left -= 1;
            self.inner.on_event(e);
        }
    }
}

/// Groups `loaded` while recording to `path`; `cut` stops forwarding after that many events
/// and then finishes as an interrupted run.
fn record(
    loaded: &Loaded,
    path: &Path,
    detail: Detail,
    reproducible: bool,
    cut: Option<usize>,
) -> (Grouping, EventLog) {
    let params = Params::default();
    let resolved = params.resolve(&loaded.scene);
    let info = run_info(loaded, &resolved, detail);
    let file = std::fs::File::create(path).unwrap();
    let mut rec = McapRecorder::new(BufWriter::new(file), &info).unwrap();
    rec.set_reproducible(reproducible);
    let mut log = EventLog::default();
    let g = match cut {
        None => group(&loaded.scene, &params, Tee(&mut rec, &mut log)),
        Some(left) => group(
            &loaded.scene,
            &params,
            FirstEvents {
                left,
                inner: Tee(&mut rec, &mut log),
            },
        ),
    };
    let spheres = sphere_tree(&g.tree, &loaded.scene, SphereMethod::default());
    let outcome = Outcome {
        grouping: cut.is_none().then_some(&g),
        spheres: Some(&spheres),
        wrappers: None,
        cover: None,
        merges: log.merges.len() as u32,
        rounds: log.rounds.len() as u32,
        seconds: 0.25,
        stopped: None,
    };
    let mut out = rec.finish(&outcome).unwrap();
    out.flush().unwrap();
    (g, log)
}

/// Runs the independent Python checker; returns (success, stdout + stderr).
fn python_check(path: &Path, n: usize) -> (bool, String) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/mcap_check.py");
    let out = common::python()
        .arg(&script)
        .arg(path)
        .arg(n.to_string())
        .output()
        .expect("the readers' Python runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert_ne!(out.status.code(), Some(2), "Python modules missing: {text}");
    (out.status.success(), text)
}

#[test]
fn full_recording_reads_back_and_passes_the_python_checker() {
    let dir = tempfile::tempdir().unwrap();
    let loaded = load_grid();
    let n = loaded.scene.len();
    let path = dir.path().join("grid.mcap");
    let (g, log) = record(&loaded, &path, Detail::Full, false, None);
    assert_eq!(log.merges.len(), n - 1);
    assert!(log.doublings.len() >= 2, "the grid needs several rounds");

    let rec = read_recording(&path).unwrap();
    assert_eq!(rec.merges, log.merges);
    assert_eq!(rec.event_log(), log);
    assert_eq!(rec.scene_bytes, loaded.source.bytes);
    assert_eq!(rec.scene_file_name, "grid.obj");
    assert_eq!(rec.params, Params::default().resolve(&loaded.scene));
    assert_eq!(
        (rec.detail, rec.complete, rec.rounds),
        (Detail::Full, true, g.rounds)
    );
    assert_eq!(
        (rec.primitives as usize, rec.load_options),
        (n, LoadOptions::default())
    );
    for key in metadata::KEYS {
        assert!(rec.metadata.contains_key(*key), "metadata lacks {key}");
    }
    assert_eq!(metadata::params(&rec.metadata).unwrap(), rec.params);
    // Parameters the round loop cannot run with are rejected on reading (GLimit0 = 0 would
    // never finish a disconnected scene in `replay --verify`).
    for (key, bad) in [("glimit0", "0"), ("dlimit0", "NaN"), ("c", "-1")] {
        let mut m = rec.metadata.clone();
        m.insert(key.into(), bad.into());
        let err = metadata::params(&m).unwrap_err().to_string();
        assert!(err.contains(key), "{err}");
    }
    assert_eq!(rec.metadata["depth_max"], g.tree.depth_max().to_string());
    assert_eq!(rec.metadata["scene_sha256"], loaded.source.sha256);
    assert_eq!(rec.timing["seconds"], "0.25");

    // The embedded scene and parameters re-create the same run.
    let again = load_bytes(
        &rec.scene_file_name,
        rec.scene_bytes.clone(),
        &rec.load_options,
    )
    .unwrap();
    let mut log2 = EventLog::default();
    group(&again.scene, &Params::default(), &mut log2);
    assert_eq!(log2.merges, rec.merges);

    let (ok, text) = python_check(&path, n);
    assert!(ok, "{text}");
    assert!(text.contains(&format!("{} merges", n - 1)), "{text}");
    // The checker is not vacuous: a wrong N fails it.
    let (ok, text) = python_check(&path, n + 1);
    assert!(!ok && text.contains("FAIL"), "{text}");
}

#[test]
fn every_detail_level_passes_the_python_checker() {
    let dir = tempfile::tempdir().unwrap();
    let loaded = load_grid();
    let n = loaded.scene.len();
    for detail in [Detail::Levels, Detail::Merges] {
        let path = dir.path().join(format!("grid-{detail:?}.mcap"));
        let (_, log) = record(&loaded, &path, detail, true, None);
        let rec = read_recording(&path).unwrap();
        assert_eq!(rec.merges, log.merges);
        assert_eq!(rec.detail, detail);
        assert_eq!(
            rec.dormant.is_empty(),
            !detail.merges() || log.dormant.is_empty()
        );
        let (ok, text) = python_check(&path, n);
        assert!(ok, "{detail:?}: {text}");
        assert_eq!(text.contains(", 0 levels,"), !detail.levels(), "{text}");
    }
}

#[test]
fn reproducible_recordings_are_byte_identical() {
    let dir = tempfile::tempdir().unwrap();
    let loaded = load_grid();
    let paths: Vec<PathBuf> = (0..2)
        .map(|i| dir.path().join(format!("r{i}.mcap")))
        .collect();
    for p in &paths {
        record(&loaded, p, Detail::Full, true, None);
    }
    let (a, b) = (
        std::fs::read(&paths[0]).unwrap(),
        std::fs::read(&paths[1]).unwrap(),
    );
    assert!(a == b, "two reproducible recordings differ");
    assert!(read_recording(&paths[0]).unwrap().timing.is_empty());
}

#[test]
fn interrupted_run_is_readable_and_incomplete() {
    let dir = tempfile::tempdir().unwrap();
    let loaded = load_grid();
    let path = dir.path().join("cut.mcap");
    let (_, log) = record(&loaded, &path, Detail::Full, true, Some(20));
    assert!(!log.merges.is_empty() && log.merges.len() < loaded.scene.len() - 1);
    let rec = read_recording(&path).unwrap();
    assert!(!rec.complete);
    assert_eq!(rec.metadata["complete"], "false");
    assert_eq!(rec.merges, log.merges);
    assert_eq!(rec.root, None);
}

#[test]
fn tiny_and_polyhedra_scenes_record() {
    let dir = tempfile::tempdir().unwrap();
    let tetra = |o: &str, x: f64, v: usize| {
        format!(
            "o {o}\nv {x} 0 0\nv {} 0 0\nv {x} 1 0\nv {x} 0 1\nf {a} {c} {b}\nf {a} {b} {d}\nf {a} {d} {c}\nf {b} {c} {d}\n",
            x + 1.0,
            a = v + 1,
            b = v + 2,
            c = v + 3,
            d = v + 4
        )
    };
    let cases = [
        (
            "one.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_vec(),
            LoadOptions::default(),
        ),
        (
            "two.obj",
            (tetra("left", 0.0, 0) + &tetra("right", 3.0, 4)).into_bytes(),
            LoadOptions {
                polyhedra: true,
                strict: true,
                up: None,
            },
        ),
    ];
    for (name, obj, options) in cases {
        let loaded = load_bytes(name, obj, &options).unwrap();
        let n = loaded.scene.len();
        let path = dir.path().join(format!("{name}.mcap"));
        let (g, log) = record(&loaded, &path, Detail::Full, true, None);
        let rec = read_recording(&path).unwrap();
        assert_eq!(
            (rec.merges.len(), rec.load_options, rec.complete),
            (n - 1, options, true)
        );
        assert_eq!(rec.event_log(), log);
        assert_eq!(rec.metadata["depth_max"], g.tree.depth_max().to_string());
        let (ok, text) = python_check(&path, n);
        assert!(ok, "{name}: {text}");
    }
}

/// Asserts reading `path` fails with one line naming the file.
fn assert_clear_error(path: &Path, what: &str) -> String {
    let err = match read_recording(path) {
        Ok(_) => panic!("{what}: read_recording accepted a bad file"),
        Err(e) => format!("{e:#}"),
    };
    let name = path.display().to_string();
    assert!(
        err.contains(&name),
        "{what}: error does not name the file: {err}"
    );
    assert!(!err.contains('\n'), "{what}: error spans lines: {err}");
    err
}

#[test]
fn bad_files_give_one_clear_error_line() {
    let dir = tempfile::tempdir().unwrap();
    let loaded = load_grid();
    let good = dir.path().join("good.mcap");
    record(&loaded, &good, Detail::Full, true, None);
    let bytes = std::fs::read(&good).unwrap();
    let bad = dir.path().join("bad.mcap");

    std::fs::write(&bad, &bytes[..bytes.len() / 2]).unwrap();
    let e = assert_clear_error(&bad, "truncated");
    assert!(e.contains("truncated"), "{e}");

    // Every single-byte corruption, at positions spread over the whole file, is caught.
    let step = (bytes.len() / 150).max(1);
    for pos in (0..bytes.len()).step_by(step).chain([bytes.len() - 1]) {
        let mut c = bytes.clone();
        c[pos] ^= 0x5a;
        std::fs::write(&bad, &c).unwrap();
        assert_clear_error(&bad, &format!("byte {pos} of {} corrupted", bytes.len()));
    }

    std::fs::write(&bad, b"v 0 0 0\nf 1 1 1\n").unwrap();
    assert!(assert_clear_error(&bad, "not mcap").contains("not an MCAP file"));
    assert!(
        assert_clear_error(&dir.path().join("missing.mcap"), "missing").contains("cannot read")
    );

    // A valid MCAP from another program.
    let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
    let ch = w
        .add_channel(0, "/grouping/merge", "json", &Default::default())
        .unwrap();
    let header = mcap::records::MessageHeader {
        channel_id: ch,
        sequence: 0,
        log_time: 1,
        publish_time: 1,
    };
    w.write_to_known_channel(&header, b"{}").unwrap();
    w.finish().unwrap();
    std::fs::write(&bad, w.into_inner().into_inner()).unwrap();
    let e = assert_clear_error(&bad, "foreign");
    assert!(
        e.contains("schema") || e.contains("not a wraptree recording"),
        "{e}"
    );

    let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
    w.finish().unwrap();
    std::fs::write(&bad, w.into_inner().into_inner()).unwrap();
    assert!(assert_clear_error(&bad, "empty foreign").contains("not a wraptree recording"));
}

/// A sink that fails once `limit` bytes were written.
struct FailAfter {
    inner: Cursor<Vec<u8>>,
    limit: u64,
}

impl Write for FailAfter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.inner.position() + buf.len() as u64 > self.limit {
            return Err(std::io::Error::other("disk full"));
        }
        self.inner.write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl Seek for FailAfter {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.inner.seek(pos)
    }
}

/// Records `loaded` at full detail into `sink`, chunks uncompressed (so that a few MB of scene
/// give a file of several chunks), returning `finish`'s result (or `start`'s error).
fn record_into<W: Write + Seek>(loaded: &Loaded, sink: W) -> anyhow::Result<W> {
    let params = Params::default();
    let resolved = params.resolve(&loaded.scene);
    let info = run_info(loaded, &resolved, Detail::Full);
    let mut rec = McapRecorder::start(sink, &info, wraptree::record::mcap::Compression::None)?;
    rec.write_scene();
    let g = group(&loaded.scene, &params, &mut rec);
    let spheres = sphere_tree(&g.tree, &loaded.scene, SphereMethod::default());
    let outcome = Outcome {
        spheres: Some(&spheres),
        ..Outcome::finished(&g)
    };
    rec.finish(&outcome)
}

#[test]
fn write_errors_are_returned_not_panicked() {
    // Lamps: several MB, so chunks are flushed while events arrive, not only at the end.
    let scene = generate::by_name("lamps", None, None, 1).unwrap();
    let mut obj = Vec::new();
    scene.write_obj(&mut obj).unwrap();
    let loaded = load_bytes("lamps.obj", obj, &LoadOptions::default()).unwrap();
    let full = record_into(&loaded, Cursor::new(Vec::new()))
        .unwrap()
        .into_inner()
        .len() as u64;
    assert!(
        full > 1 << 20,
        "the run spans several chunks ({full} bytes)"
    );
    for limit in [0, 100_000, full / 2, full - 10] {
        let sink = FailAfter {
            inner: Cursor::new(Vec::new()),
            limit,
        };
        let e = record_into(&loaded, sink)
            .err()
            .expect("a failing sink gives an error");
        assert!(
            format!("{e:#}").contains("disk full"),
            "limit {limit}: {e:#}"
        );
    }
}

/// The paper-like scenes at full detail: robot base (276), lamps ×5 (3,130) and robot bases ×44
/// (12,144, whose recording must stay ≤ 20 MB). Sizes and times go to stdout
/// (`-- --nocapture`).
#[test]
fn paper_scene_recordings_are_small() {
    let dir = tempfile::tempdir().unwrap();
    for kind in ["robot-base", "lamps", "robot-bases"] {
        let scene = generate::by_name(kind, None, None, 1).unwrap();
        let mut obj = Vec::new();
        scene.write_obj(&mut obj).unwrap();
        let loaded = load_bytes(&format!("{kind}.obj"), obj, &LoadOptions::default()).unwrap();
        let path = dir.path().join(format!("{kind}.mcap"));
        let start = std::time::Instant::now();
        let (_, log) = record(&loaded, &path, Detail::Full, true, None);
        let seconds = start.elapsed().as_secs_f64();
        let size = std::fs::metadata(&path).unwrap().len();
        println!(
            "{kind}: {} primitives, {size} bytes, {seconds:.3} s grouping + recording",
            loaded.scene.len()
        );
        assert_eq!(log.merges.len(), loaded.scene.len() - 1);
        assert_eq!(read_recording(&path).unwrap().merges, log.merges);
        assert!(size <= 20_000_000, "{kind}: {size} bytes");
    }
}

/// Records `loaded` at full detail with `wrappers` (spheres from them) to `path`.
fn record_wrappers(loaded: &Loaded, path: &Path, g: &Grouping, wrappers: &Wrappers) {
    let resolved = Params::default().resolve(&loaded.scene);
    let info = run_info(loaded, &resolved, Detail::Levels);
    let file = std::fs::File::create(path).unwrap();
    let mut rec = McapRecorder::new(BufWriter::new(file), &info).unwrap();
    let mut log = EventLog::default();
    group(&loaded.scene, &Params::default(), Tee(&mut rec, &mut log));
    let outcome = Outcome {
        spheres: wrappers.spheres.as_deref(),
        wrappers: Some(wrappers),
        merges: log.merges.len() as u32,
        rounds: log.rounds.len() as u32,
        ..Outcome::finished(g)
    };
    rec.finish(&outcome).unwrap().flush().unwrap();
}

/// Every wrapper kind's levels cover the scene in the Python checker (hulls by their face
/// planes, boxes and oriented boxes by their poses), and hulls shrunk by 20 % fail it.
#[test]
fn every_wrapper_kind_passes_the_python_checker() {
    let scene = generate::by_name("robot-base", None, None, 1).unwrap();
    let mut obj = Vec::new();
    scene.write_obj(&mut obj).unwrap();
    let loaded = load_bytes("robot-base.obj", obj, &LoadOptions::default()).unwrap();
    let n = loaded.scene.len();
    let g = group(&loaded.scene, &Params::default(), ());
    let kinds = WrapperKind::ALL;
    let mut wrappers = Wrappers::build(&g.tree, &loaded.scene, &kinds, SphereMethod::default());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("all.mcap");
    record_wrappers(&loaded, &path, &g, &wrappers);
    let (ok, text) = python_check(&path, n);
    assert!(ok, "{text}");
    for kind in ["spheres", "hulls", "boxes", "obbs"] {
        assert!(text.contains(&format!(" {kind}")), "{kind} checked: {text}");
    }

    for h in wrappers.hulls.as_mut().unwrap().iter_mut().skip(n) {
        let c = h.vertices.iter().map(|p| p.coords).sum::<V3>() / h.vertices.len() as f64;
        for p in &mut h.vertices {
            p.coords = c + (p.coords - c) * 0.8;
        }
    }
    let path = dir.path().join("shrunk.mcap");
    record_wrappers(&loaded, &path, &g, &wrappers);
    let (ok, text) = python_check(&path, n);
    assert!(!ok && text.contains("in no hulls"), "{text}");
}

#[test]
fn record_cli_cover_level_passes_the_python_checker() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/robot-base.obj");
    let out = Command::new(env!("CARGO_BIN_EXE_wraptree"))
        .arg("record")
        .arg(&scene)
        .arg("-o")
        .arg(dir.path().join("rb"))
        .args(["--cover-tolerance", "2%", "--detail", "levels"])
        .output()
        .expect("the binary runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let path = dir.path().join("rb.mcap");
    let (ok, text) = python_check(&path, 276);
    assert!(ok && text.contains("cover wrappers"), "{text}");
    let m = read_recording(&path).expect("reads").metadata;
    let num = |k: &str| {
        m[k].parse::<f64>()
            .unwrap_or_else(|_| panic!("{k} = {}", m[k]))
    };
    assert!(num("cover_max_error") <= num("cover_tolerance") && num("cover_tolerance") > 0.0);
    assert!((1.0..276.0).contains(&num("cover_size")), "{m:?}");
    assert!(!m.contains_key("cover_budget"));
}

/// The chunks are compressed as asked (zstd by default), the scene is attached compressed
/// unless nothing is, and every kind reads back to the same run and scene.
#[test]
fn chunks_are_compressed_as_asked_and_read_back_alike() {
    use wraptree::record::mcap::Compression;
    assert_eq!(Compression::default(), Compression::Zstd);
    let loaded = load_grid();
    let params = Params::default();
    let resolved = params.resolve(&loaded.scene);
    let info = run_info(&loaded, &resolved, Detail::Full);
    let mut merges = Vec::new();
    let mut scenes = Vec::new();
    for (kind, name) in [
        (Compression::None, ""),
        (Compression::Lz4, "lz4"),
        (Compression::Zstd, "zstd"),
    ] {
        let mut rec = McapRecorder::start(Cursor::new(Vec::new()), &info, kind).unwrap();
        rec.write_scene();
        let g = group(&loaded.scene, &params, &mut rec);
        let bytes = rec.finish(&Outcome::finished(&g)).unwrap().into_inner();
        let summary = mcap::Summary::read(&bytes).unwrap().expect("a summary");
        assert!(!summary.chunk_indexes.is_empty());
        for c in &summary.chunk_indexes {
            assert_eq!(c.compression, name, "{kind:?}");
        }
        let attached: Vec<_> = summary
            .attachment_indexes
            .iter()
            .map(|a| (a.name.as_str(), a.media_type.as_str(), a.data_size))
            .collect();
        let file = &loaded.source.file_name;
        let size = loaded.source.bytes.len() as u64;
        match kind {
            Compression::None => assert_eq!(attached, [(file.as_str(), "model/obj", size)]),
            _ => {
                let zst = format!("{file}.zst");
                assert_eq!(attached.len(), 1, "{attached:?}");
                assert_eq!(attached[0].0, zst);
                assert_eq!(attached[0].1, "application/zstd");
                assert!(
                    attached[0].2 < size,
                    "{attached:?}, {size} bytes uncompressed"
                );
            }
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.mcap");
        std::fs::write(&path, &bytes).unwrap();
        let rec = read_recording(&path).unwrap();
        merges.push(rec.merges);
        scenes.push(rec.scene_bytes);
    }
    assert!(merges.iter().all(|m| *m == merges[0] && !m.is_empty()));
    assert!(scenes.iter().all(|s| *s == loaded.source.bytes));
}
