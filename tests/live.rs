//! Live viewing (`record --connect`, `--serve`, `--spawn`, `--foxglove-ws`) against real
//! receivers: the `rerun` CLI of PyPI's `rerun-sdk==0.36.3` (a gRPC receiver saving to an `.rrd`,
//! and `rerun download` as a late viewer of `--serve`), and a Python Foxglove WebSocket client
//! (`tests/foxglove_ws_client.py`, the `websockets` package), both provisioned by the tests
//! (`common::readers`). What a viewer receives must be the recording the file holds; the files
//! must be the same with and without a live stream; a missing viewer must not hold the run up.
//!
//! Every port is a free one picked here (the `--spawn` test needs the SDK's default port 9876 and
//! says so when it is taken), every wait has a deadline, and every process started here is ended
//! by its id, also when a test fails.

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufRead, BufReader};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

use common::scene;
use sha2::{Digest, Sha256};

/// A port nobody listens on right now.
fn free_port() -> u16 {
    let l = TcpListener::bind("127.0.0.1:0").expect("a free port");
    l.local_addr().unwrap().port()
}

/// A child process that is ended (SIGTERM, then SIGKILL) when dropped, so that a failing test
/// leaves nothing behind.
struct Proc {
    child: Child,
    name: &'static str,
}

impl Proc {
    fn start(name: &'static str, cmd: &mut Command) -> Proc {
        let child = cmd
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {name}: {e}"));
        Proc { child, name }
    }

    /// Sends SIGTERM and waits (at most `limit`) for the exit status.
    fn terminate(&mut self, limit: Duration) -> std::process::ExitStatus {
        signal(&self.child, libc::SIGTERM);
        let start = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().expect("try_wait") {
                return status;
            }
            assert!(
                start.elapsed() < limit,
                "{} did not exit within {limit:?} of SIGTERM",
                self.name
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        if matches!(self.child.try_wait(), Ok(None)) {
            signal(&self.child, libc::SIGTERM);
            std::thread::sleep(Duration::from_millis(200));
            let _ = self.child.kill();
        }
        let _ = self.child.wait();
    }
}

fn signal(child: &Child, sig: i32) {
    // SAFETY: `kill` has no memory preconditions; the id is our own child's, not yet reaped.
    unsafe {
        libc::kill(child.id() as i32, sig);
    }
}

/// The lines a child prints on a pipe, read on a thread of their own.
struct Lines {
    rx: Receiver<String>,
    seen: Vec<String>,
}

impl Lines {
    fn of(pipe: impl std::io::Read + Send + 'static) -> Lines {
        let (tx, rx) = channel();
        std::thread::spawn(move || {
            for line in BufReader::new(pipe).lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Lines {
            rx,
            seen: Vec::new(),
        }
    }

    /// The first line (from now on) that contains `text`, waiting at most `limit`.
    fn expect(&mut self, text: &str, limit: Duration) -> String {
        let end = Instant::now() + limit;
        loop {
            let left = end.saturating_duration_since(Instant::now());
            match self.rx.recv_timeout(left) {
                Ok(line) => {
                    self.seen.push(line.clone());
                    if line.contains(text) {
                        return line;
                    }
                }
                Err(_) => panic!(
                    "no line with {text:?} within {limit:?}; got:\n{}",
                    self.seen.join("\n")
                ),
            }
        }
    }
}

/// `wraptree record ARGS` in `dir`, its stdout piped and read line by line.
fn start_record(dir: &Path, args: &[&str]) -> (Proc, Lines) {
    let mut p = Proc::start(
        "wraptree record",
        Command::new(env!("CARGO_BIN_EXE_wraptree"))
            .arg("record")
            .args(args)
            .current_dir(dir)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit()),
    );
    let lines = Lines::of(p.child.stdout.take().unwrap());
    (p, lines)
}

/// Runs `wraptree` with `args` in `dir`, failing the test if it takes over 2 minutes.
fn wraptree(dir: &Path, args: &[&str]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_wraptree"));
    cmd.args(args).current_dir(dir);
    common::output_within(cmd, &format!("wraptree {}", args.join(" ")), LIMIT)
}

/// How long any one child command of these tests may take.
const LIMIT: Duration = Duration::from_secs(120);

/// The `rerun` executable itself (the venv's `bin/rerun` is a Python wrapper that runs it as a
/// child, which a signal to the wrapper would leave running).
fn rerun_exe() -> PathBuf {
    let out = common::python()
        .args([
            "-c",
            "import os, rerun_cli; print(os.path.join(os.path.dirname(rerun_cli.__file__), 'rerun'))",
        ])
        .output()
        .expect("python runs");
    assert!(out.status.success(), "{out:?}");
    let path = PathBuf::from(String::from_utf8(out.stdout).unwrap().trim());
    assert!(path.exists(), "{} missing", path.display());
    path
}

/// `rerun rrd compare A B`: the same data (ignoring only `log_time`, which wraptree turns off).
fn same_recording(a: &Path, b: &Path) -> Result<(), String> {
    // Unordered: a file written alone holds its per-merge batches back until the levels are
    // written (`record::rrd`), a live one sends them as they fill; the data is the same.
    let mut cmd = common::rerun();
    cmd.args(["rrd", "compare", "--unordered"]).args([a, b]);
    let out = common::output_within(cmd, "rerun rrd compare", LIMIT);
    if out.status.success() {
        Ok(())
    } else {
        Err(format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ))
    }
}

/// Waits (at most `limit`) until the `.rrd` that a receiver is writing at `received` holds the
/// same recording as `file`.
fn wait_for_same_recording(file: &Path, received: &Path, limit: Duration) {
    let start = Instant::now();
    let mut last = String::from("nothing received");
    while start.elapsed() < limit {
        if received.exists() {
            match same_recording(file, received) {
                Ok(()) => return,
                Err(e) => last = e,
            }
        }
        std::thread::sleep(Duration::from_millis(300));
    }
    panic!(
        "{} never held the recording of {} within {limit:?}; last difference:\n{last}",
        received.display(),
        file.display()
    );
}

/// Entity paths and row counts of the recording in an `.rrd`, from the Python `RrdReader`.
fn entities(rrd: &Path) -> BTreeMap<String, u64> {
    const READER: &str = r#"
import json, sys, warnings
warnings.simplefilter("ignore")
from rerun.experimental import RrdReader
out = {}
for c in RrdReader(sys.argv[1]).stream():
    out[c.entity_path] = out.get(c.entity_path, 0) + c.num_rows
print(json.dumps(out))
"#;
    let mut cmd = common::python();
    cmd.args(["-c", READER]).arg(rrd);
    let out = common::output_within(cmd, "RrdReader", LIMIT);
    assert!(
        out.status.success(),
        "RrdReader on {}: {out:?}",
        rrd.display()
    );
    serde_json::from_slice(&out.stdout).expect("a JSON object")
}

/// The primitives of a scene, from `wraptree group --json`.
fn primitives(dir: &Path, scene: &str) -> u64 {
    let out = wraptree(dir, &["group", scene, "--json"]);
    assert!(out.status.success(), "{out:?}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    v["primitives"].as_u64().expect("primitives")
}

/// A viewer-less `rerun` listening on `port` that saves what it receives to `received`, once it
/// accepts connections.
fn save_receiver(port: u16, received: &Path) -> Proc {
    let receiver = Proc::start(
        "rerun --save",
        Command::new(rerun_exe())
            .args(["--port", &port.to_string(), "--save"])
            .arg(received)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null()),
    );
    wait_for_port(port, Duration::from_secs(30));
    receiver
}

#[test]
fn connect_streams_to_a_rerun_receiver_the_recording_the_file_holds() {
    let dir = tempfile::tempdir().unwrap();
    let port = free_port();
    let received = dir.path().join("received.rrd");
    let mut receiver = save_receiver(port, &received);
    let url = format!("--connect=rerun+http://127.0.0.1:{port}/proxy");
    let lamp = scene("lamp.obj");
    let out = wraptree(dir.path(), &["record", &lamp, "-o", "live", &url]);
    assert!(out.status.success(), "{out:?}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("live Rerun: streaming to rerun+http://127.0.0.1:"),
        "{stdout}"
    );
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    // The viewer got the whole recording: the same data as the file, entity by entity.
    let file = dir.path().join("live.rrd");
    wait_for_same_recording(&file, &received, Duration::from_secs(60));
    let got = entities(&received);
    assert_eq!(got, entities(&file));
    let n = primitives(dir.path(), &lamp);
    assert!(got["/series/cost"] >= n - 1, "every merge's row: {got:?}");
    assert!(got.contains_key("/levels/spheres"), "{got:?}");
    receiver.terminate(Duration::from_secs(10));

    // The file is the same recording as one written without a live stream.
    let out = wraptree(dir.path(), &["record", &lamp, "-o", "plain"]);
    assert!(out.status.success(), "{out:?}");
    same_recording(&dir.path().join("plain.rrd"), &file).unwrap();
}

#[test]
fn serve_keeps_the_whole_run_for_a_viewer_that_connects_after_it() {
    let dir = tempfile::tempdir().unwrap();
    let port = free_port();
    let base = scene("robot-base.obj");
    let serve = format!("--serve=127.0.0.1:{port}");
    let (mut rec, mut lines) = start_record(dir.path(), &[&base, "-o", "served", &serve]);
    let url = format!("rerun+http://127.0.0.1:{port}/proxy");
    let line = lines.expect("live Rerun: serving", Duration::from_secs(30));
    assert!(line.contains(&format!("rerun --connect {url}")), "{line}");
    // The run is over and its files written before the viewer comes.
    lines.expect("still serving it until Ctrl-C", Duration::from_secs(60));
    let file = dir.path().join("served.rrd");
    assert!(file.exists());

    let late = dir.path().join("late");
    let mut viewer = Proc::start(
        "rerun download",
        Command::new(rerun_exe())
            .arg("download")
            .arg(&url)
            .arg("-o")
            .arg(&late)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null()),
    );
    wait_for_same_recording(&file, &late.join("output.rrd"), Duration::from_secs(60));
    viewer.terminate(Duration::from_secs(10));

    // Ctrl-C (here SIGTERM) ends the serving; the run's exit code stands.
    let status = rec.terminate(Duration::from_secs(30));
    assert!(status.success(), "{status:?}");
}

#[test]
fn foxglove_client_receives_the_mcap_topics_live_and_the_mcap_is_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let out = wraptree(
        dir.path(),
        &[
            "scene", "soup", "-n", "4000", "--seed", "7", "-o", "soup.obj",
        ],
    );
    assert!(out.status.success(), "{out:?}");
    let args = ["soup.obj", "--reproducible", "-o", "live"];
    let live_args = ["--foxglove-ws=127.0.0.1:0", "--foxglove-wait"];
    let all: Vec<&str> = args.iter().chain(&live_args).copied().collect();
    let (mut rec, mut lines) = start_record(dir.path(), &all);
    let line = lines.expect("live Foxglove: serving ws://", Duration::from_secs(30));
    let url = line
        .split_whitespace()
        .find(|w| w.starts_with("ws://"))
        .expect("a ws:// URL")
        .to_string();
    // The run waits for this client, so it sees the run from its start; it stops once told
    // that the run is over (all messages handed to the server) and nothing more comes.
    let json = dir.path().join("client.json");
    let stop = dir.path().join("client.stop");
    let mut client = Proc::start(
        "foxglove_ws_client.py",
        common::python()
            .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/foxglove_ws_client.py"))
            .arg(&url)
            .arg(&json)
            .arg("120")
            .arg(&stop)
            .stdin(Stdio::null()),
    );
    lines.expect("still serving it until Ctrl-C", Duration::from_secs(120));
    std::fs::write(&stop, "").unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(status) = client.child.try_wait().unwrap() {
            break status;
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the client did not stop"
        );
        std::thread::sleep(Duration::from_millis(50));
    };
    assert!(status.success(), "the client failed: {status:?}");
    let status = rec.terminate(Duration::from_secs(30));
    assert!(status.success(), "{status:?}");

    // Without the live stream the .mcap is byte for byte the same.
    let out = wraptree(
        dir.path(),
        &["record", "soup.obj", "--reproducible", "-o", "plain"],
    );
    assert!(out.status.success(), "{out:?}");
    let file = std::fs::read(dir.path().join("live.mcap")).unwrap();
    assert!(file == std::fs::read(dir.path().join("plain.mcap")).unwrap());

    let got: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let mcap = Mcap::read(&file);
    assert_eq!(got["subprotocol"], "foxglove.sdk.v1");
    assert_eq!(got["server"], "wraptree");
    // The client was offered every channel of the file, with the file's schemas.
    let channels: BTreeMap<String, String> =
        serde_json::from_value(got["channels"].clone()).unwrap();
    assert_eq!(channels, mcap.channels);
    // Every message it received is one of the file's, byte for byte, at the same log time.
    let messages: Vec<(String, u64, String)> =
        serde_json::from_value(got["messages"].clone()).unwrap();
    let mut topics = BTreeSet::new();
    for m in &messages {
        assert!(mcap.messages.contains(m), "not in the file: {m:?}");
        topics.insert(m.0.clone());
    }
    // It got the scene, every level and the finish, and (subscribed before the first merges
    // came) most merges: live, as the run went.
    for topic in mcap.channels.keys() {
        if topic == "/scene" || topic.starts_with("/levels/") || topic == "/grouping/finish" {
            assert!(topics.contains(topic), "nothing on {topic}");
        }
    }
    let merges = mcap.count("/grouping/merge");
    let steps: Vec<u64> = serde_json::from_value(got["merge_steps"].clone()).unwrap();
    assert!(
        steps.len() as u64 * 2 > merges,
        "{} of {merges} merges received",
        steps.len()
    );
    assert!(steps.windows(2).all(|w| w[0] < w[1]), "merges in order");
    assert_eq!(got["finish"]["merges"].as_u64(), Some(merges));
}

/// What a test needs of an `.mcap`: each channel's schema name, and each message as (topic,
/// log time, SHA-256 of its bytes).
struct Mcap {
    channels: BTreeMap<String, String>,
    messages: BTreeSet<(String, u64, String)>,
}

impl Mcap {
    fn read(bytes: &[u8]) -> Mcap {
        let mut channels = BTreeMap::new();
        let mut messages = BTreeSet::new();
        for m in mcap::MessageStream::new(bytes).expect("an MCAP file") {
            let m = m.expect("a message");
            let schema = m.channel.schema.as_ref().map(|s| s.name.clone());
            channels.insert(m.channel.topic.clone(), schema.unwrap_or_default());
            let hash: String = Sha256::digest(&m.data)
                .iter()
                .map(|b| format!("{b:02x}"))
                .collect();
            messages.insert((m.channel.topic.clone(), m.log_time, hash));
        }
        Mcap { channels, messages }
    }

    fn count(&self, topic: &str) -> u64 {
        self.messages.iter().filter(|m| m.0 == topic).count() as u64
    }
}

#[test]
fn a_missing_viewer_holds_neither_the_run_nor_the_files_up() {
    let dir = tempfile::tempdir().unwrap();
    // Nobody listens at the first port; the second accepts connections and never answers.
    let closed = free_port();
    let silent = TcpListener::bind("127.0.0.1:0").unwrap();
    let silent_port = silent.local_addr().unwrap().port();
    let lamps = scene("lamps5.obj");
    for (port, prefix) in [(closed, "closed"), (silent_port, "silent")] {
        let url = format!("--connect=rerun+http://127.0.0.1:{port}/proxy");
        let start = Instant::now();
        let out = wraptree(dir.path(), &["record", &lamps, "-o", prefix, &url]);
        let took = start.elapsed();
        assert!(out.status.success(), "{out:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        // A silent viewer either never answers the final flush, or, when the client's buffer
        // fills first (the two layouts make a run's stream longer), stops taking messages.
        let why: &[&str] = if port == closed {
            &["no Rerun viewer answered at"]
        } else {
            &[
                "did not take the stream: no answer within 10 s",
                "stopped taking the stream",
            ]
        };
        assert!(
            stderr.starts_with("warning: live Rerun: ")
                && why.iter().any(|w| stderr.contains(w))
                && stderr.contains("the files are complete"),
            "{stderr}"
        );
        // The connection is given up 5 s after it was first tried, a flush after 10 s: neither
        // is waited for forever.
        assert!(took < Duration::from_secs(30), "{took:?}");
        same_recording(&dir.path().join(format!("{prefix}.rrd")), &{
            let plain = dir.path().join("plain.rrd");
            if !plain.exists() {
                let out = wraptree(dir.path(), &["record", &lamps, "-o", "plain"]);
                assert!(out.status.success(), "{out:?}");
            }
            plain
        })
        .unwrap();
    }
    drop(silent);
}

#[test]
fn spawn_starts_the_rerun_on_path_and_streams_to_it() {
    // `--spawn` uses the SDK's default port, as `rerun` users expect; a stand-in `rerun` on PATH
    // runs the real one as a viewer-less receiver that saves what it gets.
    if TcpListener::bind("127.0.0.1:9876").is_err() {
        eprintln!("port 9876 is taken: skipping the --spawn test");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("bin");
    std::fs::create_dir(&bin).unwrap();
    let received = dir.path().join("received.rrd");
    let pid = dir.path().join("rerun.pid");
    let script = format!(
        "#!/bin/sh\n\
         if [ \"$1\" = --version ]; then exec '{exe}' --version; fi\n\
         echo $$ > '{pid}'\n\
         exec '{exe}' --port 9876 --save '{out}' >/dev/null 2>&1\n",
        exe = rerun_exe().display(),
        pid = pid.display(),
        out = received.display(),
    );
    let fake = bin.join("rerun");
    std::fs::write(&fake, script).unwrap();
    std::fs::set_permissions(&fake, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let base = scene("robot-base.obj");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_wraptree"));
    cmd.args(["record", &base, "-o", "spawned", "--spawn"])
        .current_dir(dir.path())
        .env("PATH", path);
    let out = common::output_within(cmd, "wraptree record --spawn", LIMIT);
    let receiver_pid = std::fs::read_to_string(&pid).ok();
    let _kill = KillOnDrop(receiver_pid.as_deref().and_then(|p| p.trim().parse().ok()));
    assert!(out.status.success(), "{out:?}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("live Rerun: streaming to rerun+http://127.0.0.1:9876/proxy"),
        "{stdout}"
    );
    wait_for_same_recording(
        &dir.path().join("spawned.rrd"),
        &received,
        Duration::from_secs(60),
    );
}

/// Ends a process started by a stand-in script, by its id.
struct KillOnDrop(Option<i32>);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        if let Some(pid) = self.0 {
            // SAFETY: `kill` has no memory preconditions.
            unsafe {
                libc::kill(pid, libc::SIGTERM);
            }
        }
    }
}

fn wait_for_port(port: u16, limit: Duration) {
    let start = Instant::now();
    while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(start.elapsed() < limit, "nothing listens on {port}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

#[test]
fn bad_live_flags_give_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    let base = scene("robot-base.obj");
    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let taken_port = taken.local_addr().unwrap().port();
    let taken_serve = format!("--serve=127.0.0.1:{taken_port}");
    let taken_ws = format!("--foxglove-ws=127.0.0.1:{taken_port}");
    let cases: [(&[&str], &str); 6] = [
        (
            &["--connect=http://x"],
            "error: --connect http://x: not a Rerun viewer URL",
        ),
        (&[&taken_serve], "cannot listen"),
        (&[&taken_ws], "cannot listen"),
        (
            &["--foxglove-ws=nowhere"],
            "error: --foxglove-ws nowhere: expected HOST:PORT",
        ),
        (&["--serve=127.0.0.1:0"], "give a port"),
        (
            &["--serve=127.0.0.1:1", "--serve-memory-limit=lots"],
            "--serve-memory-limit lots",
        ),
    ];
    for (flags, expected) in cases {
        let mut args = vec!["record", base.as_str(), "-o", "x"];
        args.extend_from_slice(flags);
        let out = wraptree(dir.path(), &args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{flags:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{flags:?}: {stderr}");
        assert!(stderr.contains(expected), "{flags:?}: {stderr}");
    }
    assert!(!dir.path().join("x.rrd").exists());
    drop(taken);

    // --spawn without a `rerun` on PATH.
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_wraptree"));
    cmd.args(["record", &base, "-o", "x", "--spawn"])
        .current_dir(dir.path())
        .env("PATH", dir.path());
    let out = common::output_within(cmd, "wraptree record --spawn", LIMIT);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(
        stderr.trim(),
        "error: --spawn: no `rerun` executable on PATH (`pip install rerun-sdk==0.36.3` \
         installs the viewer); or start a viewer yourself and use --connect"
    );

    // One Rerun stream at a time; live options of replay need a re-weighted run.
    let out = wraptree(dir.path(), &["record", &base, "--connect", "--spawn"]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let out = wraptree(dir.path(), &["record", &base, "--serve-memory-limit=1GB"]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let out = wraptree(dir.path(), &["record", &base, "-o", "r", "--reproducible"]);
    assert!(out.status.success(), "{out:?}");
    let out = wraptree(dir.path(), &["replay", "r.mcap", "--connect"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("give --a, --b or --c"), "{stderr}");
}

#[test]
fn replay_reweighting_streams_its_run_too() {
    let dir = tempfile::tempdir().unwrap();
    let base = scene("robot-base.obj");
    let out = wraptree(dir.path(), &["record", &base, "-o", "r"]);
    assert!(out.status.success(), "{out:?}");
    let port = free_port();
    let received = dir.path().join("received.rrd");
    let mut receiver = save_receiver(port, &received);
    let url = format!("--connect=rerun+http://127.0.0.1:{port}/proxy");
    let out = wraptree(
        dir.path(),
        &["replay", "r.mcap", "--c", "0.5", "-o", "rw", &url],
    );
    assert!(out.status.success(), "{out:?}");
    wait_for_same_recording(
        &dir.path().join("rw.rrd"),
        &received,
        Duration::from_secs(60),
    );
    receiver.terminate(Duration::from_secs(10));
}
