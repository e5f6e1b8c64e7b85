//! The live Rerun stream: a [`LogSink`] that the `.rrd` recorder's stream tees to beside its file
//! sink, and a thread that forwards what it gets to a viewer (`--connect`, `--spawn`) or to a
//! gRPC server of our own (`--serve`).
//!
//! The sink never waits: it puts each message on a queue bounded in bytes and returns, so the
//! file is written at its own pace. The forwarding thread hands the messages to the SDK's gRPC
//! client or server, which may block on a slow or absent viewer; then the queue fills and
//! recording data is dropped from the live stream (counted), never from the file. Store info and
//! blueprint messages are never dropped.

use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use anyhow::{Context as _, Result, anyhow, bail};
use rerun::external::re_uri::{ProxyUri, RedapUri};
use rerun::grpc_server::GrpcServerSink;
use rerun::log::LogMsg;
use rerun::sink::{GrpcSink, GrpcSinkConnectionState, LogSink, SinkFlushError};
use rerun::{MemoryLimit, PlaybackBehavior, ServerOptions};

use super::queue::{Counts, Lossy, wait_while_progressing};

/// Where the live Rerun stream goes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RerunLive {
    /// Stream to a Rerun viewer (or gRPC server) that listens at this `rerun+http://…/proxy` URL
    /// (`--connect`).
    Connect(String),
    /// Host a gRPC server at this address that viewers connect to, now or later (`--serve`). It
    /// keeps what it was sent, up to `memory_limit` (`16GB`, `25%` of the RAM, `unlimited`),
    /// so that a late viewer gets the whole run; above the limit it drops the oldest recording
    /// data first, then the oldest static data (the scene); the store info and the layout stay.
    Serve {
        /// Address to listen on.
        addr: SocketAddr,
        /// How much of the stream the server keeps for late viewers.
        memory_limit: String,
    },
    /// Start the `rerun` executable on `PATH` (or reuse a viewer already listening on the
    /// default port) and stream to it (`--spawn`).
    Spawn,
}

/// The default URL of `--connect` and the port of `--serve` and `--spawn`: the SDK's.
pub const DEFAULT_CONNECT_URL: &str = rerun::DEFAULT_CONNECT_URL;

/// How long a flush of the viewer connection may take at the end of a run.
const FLUSH_TIMEOUT: Duration = Duration::from_secs(10);

/// How long a viewer may take to answer the first connection before the end of a run gives up
/// on it.
const CONNECT_TIMEOUT: Duration = Duration::from_secs(5);

/// How long the end of the program waits for the viewer connection to close.
const CLOSE_TIMEOUT: Duration = Duration::from_secs(5);

/// How long `--spawn` waits for the viewer to listen.
const SPAWN_BIND_WAIT: Duration = Duration::from_secs(10);

enum Item {
    Msg(LogMsg),
    Flush(SyncSender<Result<(), String>>),
}

/// Who takes the messages: the SDK's gRPC client or its gRPC server.
enum Inner {
    Client(Arc<GrpcSink>),
    Server(GrpcServerSink),
}

impl Inner {
    fn send(&self, msg: LogMsg) {
        match self {
            Inner::Client(c) => c.send(msg),
            Inner::Server(s) => s.send(msg),
        }
    }

    fn flush(&self) -> Result<(), String> {
        let r = match self {
            Inner::Client(c) => c.flush_blocking(FLUSH_TIMEOUT),
            Inner::Server(s) => s.flush_blocking(FLUSH_TIMEOUT),
        };
        r.map_err(|e| match e {
            SinkFlushError::Timeout => format!("no answer within {} s", FLUSH_TIMEOUT.as_secs()),
            SinkFlushError::Failed { message } => message,
        })
    }
}

/// A started live Rerun stream: its queue, and the thread that forwards it.
pub(super) struct Forwarder {
    queue: Arc<Lossy<Item>>,
    /// The gRPC client, for its connection state (`--connect`, `--spawn`).
    client: Option<Arc<GrpcSink>>,
    /// Where viewers connect (`--serve`) or where the stream goes.
    url: String,
    serving: bool,
    /// Set by [`Forwarder::finish`]: the report is given once, and whether everything was
    /// handed over.
    finished: Mutex<Option<(Vec<String>, bool)>>,
    /// Answered by the thread when it has closed the connection or stopped the server.
    ended: Mutex<Receiver<()>>,
}

impl Forwarder {
    /// Starts the stream `how`, with a queue of `cap` bytes. Err: an unparsable URL, an address
    /// that cannot be listened on, no `rerun` executable for `--spawn`.
    pub(super) fn start(how: &RerunLive, cap: usize) -> Result<Forwarder> {
        let (inner, url, serving) = match how {
            RerunLive::Connect(url) => {
                let uri = proxy_uri(url).with_context(|| format!("--connect {url}"))?;
                let url = uri.to_string();
                (Inner::Client(Arc::new(GrpcSink::new(uri))), url, false)
            }
            RerunLive::Serve { addr, memory_limit } => serve(*addr, memory_limit)?,
            RerunLive::Spawn => {
                let url = spawn()?;
                let uri = proxy_uri(&url)?;
                (Inner::Client(Arc::new(GrpcSink::new(uri))), url, false)
            }
        };
        let client = match &inner {
            Inner::Client(c) => Some(c.clone()),
            Inner::Server(_) => None,
        };
        let queue = Arc::new(Lossy::new(cap));
        let q = queue.clone();
        let (end, ended) = sync_channel(1);
        std::thread::Builder::new()
            .name("rerun-live".into())
            .spawn(move || {
                forward(&q, inner);
                let _ = end.send(());
            })
            .context("cannot start the live Rerun thread")?;
        Ok(Forwarder {
            queue,
            client,
            url,
            serving,
            finished: Mutex::new(None),
            ended: Mutex::new(ended),
        })
    }

    /// A sink for a recording stream that feeds this live stream without waiting.
    pub(super) fn sink(&self) -> Box<dyn LogSink> {
        Box::new(LiveSink(self.queue.clone()))
    }

    /// Where viewers connect, or where the stream goes.
    pub(super) fn url(&self) -> &str {
        &self.url
    }

    /// Whether this is a server that viewers connect to (`--serve`).
    pub(super) fn serving(&self) -> bool {
        self.serving
    }

    /// Hands what is queued to the viewer or server, waiting while it takes messages (and at most
    /// [`FLUSH_TIMEOUT`] for the last ones), then reports what did not get through. The stream
    /// stays open: a server keeps serving.
    pub(super) fn finish(&self, patience: Duration) -> Vec<String> {
        let mut finished = self.finished.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some((lines, _)) = &*finished {
            return lines.clone();
        }
        let (done, answer) = sync_channel(1);
        self.queue.push(Item::Flush(done), 0, false);
        let progress = || self.queue.progress().0;
        let unreachable = |after| {
            let client = self.client.as_ref()?;
            unreachable(client, &self.url, after)
        };
        let abort = || unreachable(CONNECT_TIMEOUT);
        let flushed = match wait_while_progressing(&answer, progress, abort, patience) {
            Ok(Ok(())) => Ok(()),
            Ok(Err(e)) => Err(unreachable(Duration::ZERO)
                .unwrap_or_else(|| format!("{} did not take the stream: {e}", self.url))),
            Err(Some(why)) => Err(why),
            Err(None) => Err(format!("{} stopped taking the stream", self.url)),
        };
        let mut lines = Vec::new();
        let whole = flushed.is_ok();
        if let Err(why) = flushed {
            let (_, left) = self.queue.progress();
            let rest = if left > 0 {
                format!(", {left} messages not sent")
            } else {
                String::new()
            };
            lines.push(format!("live Rerun: {why}{rest}; the files are complete"));
        }
        let Counts { offered, dropped } = self.queue.counts();
        if dropped > 0 {
            lines.push(format!(
                "live Rerun: {dropped} of {offered} messages left out of the live stream (the \
                 viewer was slower than the run); the files are complete"
            ));
        }
        *finished = Some((lines.clone(), whole));
        lines
    }
}

impl Drop for Forwarder {
    /// Ends the stream: the thread sends what is queued, then closes the connection or stops the
    /// server. After a [`Forwarder::finish`] that handed everything over it is waited for (a few
    /// seconds at most), so that the viewer sees the stream end cleanly; otherwise not, and the
    /// client is dropped on a thread of its own (a vanished viewer could hold it forever).
    fn drop(&mut self) {
        self.queue.close();
        let finished = self
            .finished
            .get_mut()
            .unwrap_or_else(PoisonError::into_inner);
        if finished.as_ref().is_some_and(|(_, whole)| *whole) {
            let ended = self.ended.get_mut().unwrap_or_else(PoisonError::into_inner);
            let _ = ended.recv_timeout(CLOSE_TIMEOUT);
        } else if let Some(client) = self.client.take() {
            // The SDK's client flushes without a time limit when its last handle drops, which
            // a silent viewer never answers: that drop goes to a thread nobody waits for.
            let _ = std::thread::Builder::new()
                .name("rerun-close".into())
                .spawn(move || drop(client));
        }
    }
}

/// `Some(line)` when the client has tried to reach its server for longer than `after` in vain,
/// or lost it.
fn unreachable(client: &GrpcSink, url: &str, after: Duration) -> Option<String> {
    match client.status() {
        GrpcSinkConnectionState::Connecting { started } if started.elapsed() >= after => {
            Some(format!("no Rerun viewer answered at {url}"))
        }
        GrpcSinkConnectionState::Disconnected(Err(e)) => {
            Some(format!("the viewer at {url} went away ({e})"))
        }
        _ => None,
    }
}

/// The forwarding thread: every queued message to `inner`, in order, until the queue closes.
fn forward(queue: &Lossy<Item>, inner: Inner) {
    while let Some(item) = queue.pop() {
        match item {
            Item::Msg(msg) => inner.send(msg),
            Item::Flush(done) => {
                let _ = done.send(inner.flush());
            }
        }
    }
    // Dropping the client flushes it; dropping the server stops it.
    drop(inner);
}

/// A `rerun+http://HOST:PORT/proxy` URL. Err: not such a URL.
fn proxy_uri(url: &str) -> Result<ProxyUri> {
    match url.parse::<RedapUri>() {
        Ok(RedapUri::Proxy(uri)) => Ok(uri),
        Ok(_) => bail!("not a Rerun viewer URL (rerun+http://HOST:PORT/proxy)"),
        Err(e) => bail!("not a Rerun viewer URL (rerun+http://HOST:PORT/proxy): {e}"),
    }
}

/// Starts the SDK's gRPC server at `addr`; checks first that the address can be listened on (the
/// server binds on a thread of its own, where an error would only be logged).
fn serve(addr: SocketAddr, memory_limit: &str) -> Result<(Inner, String, bool)> {
    if addr.port() == 0 {
        bail!("--serve {addr}: give a port (the server cannot report one it picked)");
    }
    let limit = MemoryLimit::parse(memory_limit)
        .map_err(|e| anyhow!("--serve-memory-limit {memory_limit}: {e}"))?;
    drop(TcpListener::bind(addr).with_context(|| format!("--serve {addr}: cannot listen"))?);
    let options = ServerOptions {
        playback_behavior: PlaybackBehavior::OldestFirst,
        memory_limit: limit,
        ..ServerOptions::default()
    };
    let server = GrpcServerSink::new(&addr.ip().to_string(), addr.port(), options)
        .map_err(|e| anyhow!("--serve {addr}: {e}"))?;
    let shown = if addr.ip().is_unspecified() {
        SocketAddr::new([127, 0, 0, 1].into(), addr.port())
    } else {
        addr
    };
    Ok((
        Inner::Server(server),
        format!("rerun+http://{shown}/proxy"),
        true,
    ))
}

/// Starts `rerun` from `PATH` on the SDK's default port, unless something listens there already,
/// and waits until it listens. Returns its URL.
fn spawn() -> Result<String> {
    let opts = rerun::SpawnOptions {
        hide_welcome_screen: true,
        ..Default::default()
    };
    let info = rerun::spawn(&opts).map_err(|e| match e {
        rerun::SpawnError::ExecutableNotFoundInPath { .. } => anyhow!(
            "--spawn: no `rerun` executable on PATH (`pip install rerun-sdk==0.36.3` installs \
             the viewer); or start a viewer yourself and use --connect"
        ),
        e => anyhow!("--spawn: cannot start the Rerun viewer: {}", one_line(&e)),
    })?;
    let addr = SocketAddr::new([127, 0, 0, 1].into(), info.port);
    let start = Instant::now();
    while TcpStream::connect_timeout(&addr, Duration::from_millis(200)).is_err() {
        if start.elapsed() > SPAWN_BIND_WAIT {
            bail!(
                "--spawn: the Rerun viewer did not listen on {addr} within {} s",
                SPAWN_BIND_WAIT.as_secs()
            );
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    Ok(format!("rerun+http://{addr}/proxy"))
}

/// The first line of an error's message.
fn one_line(e: &dyn std::fmt::Display) -> String {
    e.to_string().lines().next().unwrap_or_default().to_string()
}

/// The sink the recording stream tees to: queues each message and returns at once.
struct LiveSink(Arc<Lossy<Item>>);

impl LogSink for LiveSink {
    fn send(&self, msg: LogMsg) {
        // Recording data may be left out of the live stream; the store info, the blueprint and
        // its activation may not (a viewer cannot show the run without them).
        let (bytes, droppable) = match &msg {
            LogMsg::ArrowMsg(store, arrow) => {
                (arrow.batch.get_array_memory_size(), store.is_recording())
            }
            _ => (256, false),
        };
        self.0.push(Item::Msg(msg), bytes, droppable);
    }

    /// Returns at once: the live stream is flushed by [`Forwarder::finish`], never on the
    /// file's behalf.
    fn flush_blocking(&self, _timeout: Duration) -> Result<(), SinkFlushError> {
        Ok(())
    }
}
