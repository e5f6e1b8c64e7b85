//! Watching a run while it is recorded (`record --connect`, `--serve`, `--spawn`,
//! `--foxglove-ws`); how each mode works and what a late viewer gets is in
//! `docs/recordings.md`, "Live viewing".
//!
//! [`Live::start`] starts what [`LiveOptions`] asks for before the run; the recorders then tee
//! to it: the `.rrd`'s recording stream sends every message to its file sink and to a live
//! sink ([`rerun`]), the `.mcap` recorder copies every schema, channel and message it writes
//! to the Foxglove server ([`foxglove`]). Neither waits for a viewer: each live stream has a
//! queue bounded in bytes and a thread of its own, and what does not fit is left out of the live
//! stream, never out of the files, which are written exactly as without a live stream.

pub mod foxglove;
mod queue;
pub mod rerun;

pub use rerun::{DEFAULT_CONNECT_URL, RerunLive};

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::Result;

/// Bytes of messages each live stream may hold for a viewer that is slower than the run.
pub const QUEUE_BYTES: usize = 512 << 20;

/// How long [`Live::finish`] waits for a viewer that stopped taking messages.
const PATIENCE: Duration = Duration::from_secs(15);

/// What to stream live.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LiveOptions {
    /// Where the Rerun stream goes, if anywhere.
    pub rerun: Option<RerunLive>,
    /// `HOST:PORT` for a Foxglove WebSocket server of the `.mcap`'s topics, if any.
    pub foxglove: Option<String>,
    /// Bytes each live stream may queue for a slow viewer ([`QUEUE_BYTES`]).
    pub queue_bytes: usize,
}

impl Default for LiveOptions {
    /// Nothing live.
    fn default() -> Self {
        LiveOptions {
            rerun: None,
            foxglove: None,
            queue_bytes: QUEUE_BYTES,
        }
    }
}

/// The started live streams; pass it in [`RecordOptions::live`](super::RecordOptions::live).
/// Cheap to clone; the servers stop when the last clone is dropped. `Live::default()` streams
/// nothing.
#[derive(Clone, Default)]
pub struct Live {
    rerun: Option<Arc<rerun::Forwarder>>,
    foxglove: Option<Arc<foxglove::Server>>,
}

impl std::fmt::Debug for Live {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Live")
            .field("rerun", &self.rerun.as_ref().map(|r| r.url()))
            .field("foxglove", &self.foxglove.as_ref().map(|s| s.url()))
            .finish()
    }
}

impl Live {
    /// Starts the live streams `opts` asks for: connects to (or spawns) the Rerun viewer, starts
    /// the servers. Err, with the flag's name: an unparsable URL or address, an address that
    /// cannot be listened on, no `rerun` executable on `PATH` for `--spawn`.
    pub fn start(opts: &LiveOptions) -> Result<Live> {
        let rerun = opts
            .rerun
            .as_ref()
            .map(|how| rerun::Forwarder::start(how, opts.queue_bytes).map(Arc::new))
            .transpose()?;
        let foxglove = opts
            .foxglove
            .as_deref()
            .map(|addr| foxglove::Server::start(addr, opts.queue_bytes).map(Arc::new))
            .transpose()?;
        Ok(Live { rerun, foxglove })
    }

    /// Whether anything is streamed live.
    pub fn is_on(&self) -> bool {
        self.rerun.is_some() || self.foxglove.is_some()
    }

    /// Whether a server waits for viewers (`--serve`, `--foxglove-ws`): one worth keeping up
    /// after the run ([`Live::keep_serving`]).
    pub fn serves(&self) -> bool {
        self.rerun.as_ref().is_some_and(|r| r.serving()) || self.foxglove.is_some()
    }

    /// One line per live stream: where it goes, or where to connect to it.
    pub fn describe(&self) -> Vec<String> {
        let mut lines = Vec::new();
        if let Some(r) = &self.rerun {
            lines.push(if r.serving() {
                format!(
                    "live Rerun: serving {}: `rerun --connect {}` (from another machine: its \
                     address, or an SSH tunnel)",
                    r.url(),
                    r.url()
                )
            } else {
                format!("live Rerun: streaming to {}", r.url())
            });
        }
        if let Some(s) = &self.foxglove {
            lines.push(format!(
                "live Foxglove: serving {} (Foxglove: Open connection → Foxglove WebSocket)",
                s.url()
            ));
        }
        lines
    }

    /// The Rerun URL: where the stream goes, or where viewers connect.
    pub fn rerun_url(&self) -> Option<&str> {
        self.rerun.as_ref().map(|r| r.url())
    }

    /// The Foxglove WebSocket URL, `ws://HOST:PORT`.
    pub fn foxglove_url(&self) -> Option<&str> {
        self.foxglove.as_ref().map(|s| s.url())
    }

    /// After the run: hands what the streams still hold to the viewers, waiting while they take
    /// it (up to 15 s without progress), and returns a line for each problem (a viewer that
    /// was not there or went away, messages left out). The servers keep serving.
    pub fn finish(&self) -> Vec<String> {
        let mut lines = Vec::new();
        if let Some(r) = &self.rerun {
            lines.extend(r.finish(PATIENCE));
        }
        if let Some(s) = &self.foxglove {
            lines.extend(s.finish(PATIENCE));
        }
        lines
    }

    /// Blocks until `stop` is set (Ctrl-C, SIGTERM): the servers keep serving the finished run
    /// to viewers that connect late.
    pub fn keep_serving(&self, stop: &AtomicBool) {
        while !stop.load(Ordering::Relaxed) {
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// Blocks until a client is connected to the Foxglove server (at once without one), or
    /// `stop` is set: started before the run, it lets a Foxglove client, which gets no history,
    /// see the run from its start (`record --foxglove-wait`).
    pub fn wait_for_foxglove_client(&self, stop: &AtomicBool) {
        if let Some(s) = &self.foxglove {
            s.wait_for_client(stop);
        }
    }

    /// A sink for the `.rrd`'s recording stream that feeds the live Rerun stream.
    pub(crate) fn rerun_sink(&self) -> Option<Box<dyn ::rerun::sink::LogSink>> {
        self.rerun.as_ref().map(|r| r.sink())
    }

    /// A tee for an `.mcap` recorder that feeds the live Foxglove stream.
    pub fn mcap_tee(&self) -> Option<foxglove::McapTee> {
        self.foxglove.as_ref().map(|s| s.tee())
    }
}
