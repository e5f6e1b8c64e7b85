//! The live Foxglove stream: the `.mcap`'s channels and messages served over the Foxglove
//! WebSocket protocol by the `foxglove` crate's server (`--foxglove-ws`).
//!
//! The `.mcap` recorder tees each schema, channel and encoded message to an [`McapTee`], which
//! queues it (a queue bounded in bytes) without waiting; a thread of ours logs the messages to the server's
//! channels. The server keeps a bounded queue per client and drops a slow client's oldest
//! messages. The protocol has no history, so the thread keeps the latest message of every
//! topic, and a client that subscribes to a topic is sent that message first: a late client
//! still gets the scene, every level, the last round and merge.

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc::{SyncSender, sync_channel};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use anyhow::{Context as _, Result, anyhow, bail};
use foxglove::websocket::{ChannelView, Client, ServerListener};
use foxglove::{ChannelBuilder, ChannelId, Context, PartialMetadata, RawChannel, Schema, SinkId};
use foxglove::{WebSocketServer, WebSocketServerHandle};

use super::queue::{Counts, Lossy, wait_while_progressing};

/// The default address of `--foxglove-ws`: the `foxglove` crate's.
pub const DEFAULT_ADDR: &str = "127.0.0.1:8765";

/// Messages the server queues per client before it drops the client's oldest.
const CLIENT_BACKLOG: usize = 16384;

enum Item {
    Schema {
        tee: u32,
        id: u16,
        schema: Schema,
    },
    Channel {
        tee: u32,
        id: u16,
        schema: u16,
        topic: String,
        encoding: String,
    },
    Message {
        tee: u32,
        channel: u16,
        log_time: u64,
        data: Vec<u8>,
    },
    Flush(SyncSender<()>),
}

/// The latest message of a channel, sent first to each client that subscribes to it.
struct Latched {
    channel: Arc<RawChannel>,
    data: Arc<[u8]>,
    log_time: u64,
}

/// What the forwarding thread and the server's subscription callbacks share.
///
/// The server registers a subscription before it tells the listener, so a message logged to
/// the whole channel in between would reach the client and then come again as the latched
/// one. Messages therefore go to each client by its sink, and only to clients already sent
/// the latched message: each client gets every message of a channel once and in order.
#[derive(Default)]
struct Shared {
    latest: HashMap<ChannelId, Latched>,
    clients: HashMap<ChannelId, Vec<SinkId>>,
}

type Latest = Arc<Mutex<Shared>>;

/// Sends the latched message of a channel to a client that subscribes to it, then lets the
/// forwarding thread send it the rest.
struct Latch(Latest);

impl ServerListener for Latch {
    fn on_subscribe(&self, client: Client, channel: ChannelView) {
        let Some(sink) = client.sink_id() else {
            return;
        };
        let mut shared = self.0.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(l) = shared.latest.get(&channel.id()) {
            let meta = PartialMetadata::with_log_time(l.log_time);
            l.channel.log_with_meta_to_sink(&l.data, meta, Some(sink));
        }
        let clients = shared.clients.entry(channel.id()).or_default();
        if !clients.contains(&sink) {
            clients.push(sink);
        }
    }

    fn on_unsubscribe(&self, client: Client, channel: ChannelView) {
        let mut shared = self.0.lock().unwrap_or_else(PoisonError::into_inner);
        if let (Some(sink), Some(clients)) =
            (client.sink_id(), shared.clients.get_mut(&channel.id()))
        {
            clients.retain(|&c| c != sink);
        }
    }
}

/// A started Foxglove WebSocket server, its queue and forwarding thread.
pub(super) struct Server {
    queue: Arc<Lossy<Item>>,
    handle: Mutex<Option<WebSocketServerHandle>>,
    url: String,
    tees: AtomicU32,
}

impl Server {
    /// Starts the server on `addr` (`HOST:PORT`; port 0 picks a free one), with a queue of
    /// `cap` bytes. Err: a malformed address, one that cannot be listened on.
    pub(super) fn start(addr: &str, cap: usize) -> Result<Server> {
        let (host, port) = host_port(addr).with_context(|| format!("--foxglove-ws {addr}"))?;
        let ctx = Context::new();
        let latest: Latest = Arc::default();
        let handle = WebSocketServer::new()
            .name("wraptree")
            .bind(host.clone(), port)
            .context(&ctx)
            .listener(Arc::new(Latch(latest.clone())))
            .message_backlog_size(CLIENT_BACKLOG)
            .start_blocking()
            .map_err(|e| anyhow!("--foxglove-ws {addr}: cannot listen: {e}"))?;
        let shown = match host.as_str() {
            "0.0.0.0" | "::" => "127.0.0.1".to_string(),
            h if h.contains(':') => format!("[{h}]"),
            h => h.to_string(),
        };
        let url = format!("ws://{shown}:{}", handle.port());
        let queue = Arc::new(Lossy::new(cap));
        let q = queue.clone();
        std::thread::Builder::new()
            .name("foxglove-live".into())
            .spawn(move || forward(&q, &ctx, &latest))
            .context("cannot start the live Foxglove thread")?;
        Ok(Server {
            queue,
            handle: Mutex::new(Some(handle)),
            url,
            tees: AtomicU32::new(0),
        })
    }

    /// Where clients connect: `ws://HOST:PORT`.
    pub(super) fn url(&self) -> &str {
        &self.url
    }

    /// Waits until a client is connected or `stop` is set.
    pub(super) fn wait_for_client(&self, stop: &AtomicBool) {
        loop {
            let clients = self
                .handle
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .as_ref()
                .map_or(0, |h| h.client_count());
            if clients > 0 || stop.load(Ordering::Relaxed) {
                return;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// A tee for one `.mcap` recorder.
    pub(super) fn tee(&self) -> McapTee {
        McapTee {
            queue: self.queue.clone(),
            id: self.tees.fetch_add(1, Ordering::Relaxed),
        }
    }

    /// Waits until what is queued has been handed to the server (a few milliseconds: the server
    /// does not wait for clients), then reports what the queue dropped.
    pub(super) fn finish(&self, patience: Duration) -> Vec<String> {
        let (done, answer) = sync_channel(1);
        self.queue.push(Item::Flush(done), 0, false);
        let progress = || self.queue.progress().0;
        let mut lines = Vec::new();
        if wait_while_progressing(&answer, progress, || None, patience).is_err() {
            lines.push("live Foxglove: the server stopped taking messages".to_string());
        }
        let Counts { offered, dropped } = self.queue.counts();
        if dropped > 0 {
            lines.push(format!(
                "live Foxglove: {dropped} of {offered} messages left out of the live stream; \
                 the files are complete"
            ));
        }
        lines
    }
}

impl Drop for Server {
    /// Stops the server (its clients are disconnected) and ends the forwarding thread.
    fn drop(&mut self) {
        self.queue.close();
        let handle = self
            .handle
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take();
        if let Some(h) = handle {
            h.stop().detach_all();
        }
    }
}

/// `HOST:PORT` (an IPv6 host in brackets).
fn host_port(addr: &str) -> Result<(String, u16)> {
    let Some((host, port)) = addr.rsplit_once(':') else {
        bail!("expected HOST:PORT");
    };
    let port = port
        .parse::<u16>()
        .map_err(|_| anyhow!("expected HOST:PORT, the port a number below 65536"))?;
    let host = host.trim_start_matches('[').trim_end_matches(']');
    if host.is_empty() {
        bail!("expected HOST:PORT");
    }
    Ok((host.to_string(), port))
}

/// The forwarding thread: schemas and channels registered with the server's context, messages
/// sent to the channel's admitted clients and kept as its latest.
fn forward(queue: &Lossy<Item>, ctx: &Arc<Context>, latest: &Latest) {
    let mut schemas: HashMap<(u32, u16), Schema> = HashMap::new();
    let mut channels: HashMap<(u32, u16), Arc<RawChannel>> = HashMap::new();
    while let Some(item) = queue.pop() {
        match item {
            Item::Schema { tee, id, schema } => {
                schemas.insert((tee, id), schema);
            }
            Item::Channel {
                tee,
                id,
                schema,
                topic,
                encoding,
            } => {
                // The context returns the channel already there for a topic with this schema
                // (a second recording to the same server).
                let built = ChannelBuilder::new(topic)
                    .context(ctx)
                    .message_encoding(encoding)
                    .schema(schemas.get(&(tee, schema)).cloned())
                    .build_raw();
                if let Ok(channel) = built {
                    channels.insert((tee, id), channel);
                }
            }
            Item::Message {
                tee,
                channel,
                log_time,
                data,
            } => {
                if let Some(ch) = channels.get(&(tee, channel)) {
                    let data: Arc<[u8]> = data.into();
                    let mut shared = latest.lock().unwrap_or_else(PoisonError::into_inner);
                    let meta = PartialMetadata::with_log_time(log_time);
                    for &sink in shared.clients.get(&ch.id()).into_iter().flatten() {
                        ch.log_with_meta_to_sink(&data, meta, Some(sink));
                    }
                    let channel = ch.clone();
                    shared.latest.insert(
                        ch.id(),
                        Latched {
                            channel,
                            data,
                            log_time,
                        },
                    );
                }
            }
            Item::Flush(done) => {
                let _ = done.send(());
            }
        }
    }
}

/// What an `.mcap` recorder sends to the live Foxglove stream: a copy of each schema, channel
/// and encoded message it writes. Never waits; above the queue's cap messages are left out of
/// the live stream (never out of the file).
#[derive(Clone)]
pub struct McapTee {
    queue: Arc<Lossy<Item>>,
    id: u32,
}

impl std::fmt::Debug for McapTee {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("McapTee").field("id", &self.id).finish()
    }
}

impl McapTee {
    /// A schema the recording registered as `id`.
    pub fn schema(&self, id: u16, name: &str, encoding: &str, data: &[u8]) {
        let schema = Schema::new(name, encoding, data.to_vec());
        let item = Item::Schema {
            tee: self.id,
            id,
            schema,
        };
        self.queue.push(item, data.len(), false);
    }

    /// A channel the recording registered as `id`, with schema `schema`.
    pub fn channel(&self, id: u16, schema: u16, topic: &str, encoding: &str) {
        let item = Item::Channel {
            tee: self.id,
            id,
            schema,
            topic: topic.to_string(),
            encoding: encoding.to_string(),
        };
        self.queue.push(item, topic.len(), false);
    }

    /// A message written on channel `channel` at `log_time` (ns).
    pub fn message(&self, channel: u16, log_time: u64, data: &[u8]) {
        let item = Item::Message {
            tee: self.id,
            channel,
            log_time,
            data: data.to_vec(),
        };
        self.queue.push(item, data.len(), true);
    }
}

#[cfg(test)]
mod tests {
    use super::host_port;

    #[test]
    fn addresses_are_host_and_port() {
        assert_eq!(
            host_port("127.0.0.1:8765").unwrap(),
            ("127.0.0.1".into(), 8765)
        );
        assert_eq!(host_port("[::1]:0").unwrap(), ("::1".into(), 0));
        assert!(host_port("8765").is_err());
        assert!(host_port(":8765").is_err());
        assert!(host_port("host:99999").is_err());
    }
}
