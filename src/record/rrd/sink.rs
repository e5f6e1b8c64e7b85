//! `.rrd` files written by a sink of our own: the SDK's encoder (the same bytes as its
//! `FileSink`) on a writer thread, into a [`DirectWriter`] that bypasses the page cache.
//!
//! Besides the cost (`docs/recordings.md`, "How the files are written"), two behaviours of the
//! SDK's `FileSink` in 0.36.3 made us write this: its writer thread stops at the first write error
//! and only logs it, and a flush queued behind the failed write is never answered, so
//! `flush_blocking` (and dropping the stream after it) waits forever. [`DirectSink`] keeps the
//! first error, drops later messages instead of blocking, answers every flush, and [`close`]
//! returns that error with the system's reason. After a clean end [`close`] still reads the footer
//! back (the stream footer at the end of the file must parse and the RRD footer it points at must
//! match its CRC), an independent check that the file is whole.

use std::fs::File;
use std::io::{Read as _, Seek as _, SeekFrom, Write as _};
use std::path::Path;
use std::sync::mpsc::{SyncSender, sync_channel};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use anyhow::bail;
use rerun::external::re_build_info::CrateVersion;
use rerun::external::re_log_encoding::{
    Decodable as _, EncodingOptions, StreamFooter, rrd::Encoder,
};
use rerun::external::re_log_types::LogMsg;
use rerun::sink::{LogSink, SinkFlushError};
use rerun::{RecordingStream, RecordingStreamBuilder};

use crate::record::direct::DirectWriter;

/// Messages in flight to the writer thread before `send` waits.
const IN_FLIGHT: usize = 1024;

/// How the writer thread ended: `None` while it runs, then its first error or success.
#[derive(Clone, Default)]
pub(super) struct Status(Arc<Mutex<Option<Result<(), String>>>>);

impl Status {
    fn set(&self, r: Result<(), String>) {
        *self.0.lock().unwrap_or_else(PoisonError::into_inner) = Some(r);
    }

    fn get(&self) -> Option<Result<(), String>> {
        self.0
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }
}

enum Cmd {
    Send(LogMsg),
    Flush(SyncSender<Result<(), String>>),
}

/// A [`LogSink`] that encodes every message into one file on a thread of its own.
struct DirectSink {
    tx: Mutex<Option<SyncSender<Cmd>>>,
    thread: Mutex<Option<std::thread::JoinHandle<()>>>,
}

impl DirectSink {
    fn start(path: &Path, status: Status) -> anyhow::Result<DirectSink> {
        let writer = DirectWriter::open(path)?;
        let options = EncodingOptions::PROTOBUF_COMPRESSED;
        let mut encoder = Encoder::new_eager(CrateVersion::LOCAL, options, writer)?;
        let (tx, rx) = sync_channel::<Cmd>(IN_FLIGHT);
        let thread = std::thread::Builder::new()
            .name("rrd-writer".into())
            .spawn(move || {
                let mut failed: Option<String> = None;
                for cmd in rx {
                    match cmd {
                        Cmd::Send(msg) if failed.is_none() => {
                            if let Err(e) = encoder.append(&msg) {
                                failed = Some(root(&e));
                            }
                        }
                        Cmd::Send(_) => {}
                        Cmd::Flush(done) => {
                            let r = match &failed {
                                Some(e) => Err(e.clone()),
                                None => encoder.flush_blocking().map_err(|e| root(&e)),
                            };
                            let _ = done.send(r);
                        }
                    }
                }
                let end = match failed {
                    Some(e) => Err(e),
                    None => end(encoder),
                };
                status.set(end);
            })?;
        Ok(DirectSink {
            tx: Mutex::new(Some(tx)),
            thread: Mutex::new(Some(thread)),
        })
    }

    fn send_cmd(&self, cmd: Cmd) -> bool {
        let tx = self.tx.lock().unwrap_or_else(PoisonError::into_inner);
        tx.as_ref().is_some_and(|tx| tx.send(cmd).is_ok())
    }
}

/// Writes the footer and the buffered tail.
fn end(mut encoder: Encoder<DirectWriter>) -> Result<(), String> {
    encoder.finish().map_err(|e| root(&e))?;
    let mut writer = encoder.into_inner().map_err(|e| root(&e))?;
    writer.flush().map_err(|e| e.to_string())
}

/// The innermost cause: the system's reason for a write error.
fn root(e: &(dyn std::error::Error + 'static)) -> String {
    let mut e = e;
    while let Some(s) = e.source() {
        e = s;
    }
    e.to_string()
}

impl LogSink for DirectSink {
    fn send(&self, msg: LogMsg) {
        self.send_cmd(Cmd::Send(msg));
    }

    fn flush_blocking(&self, timeout: Duration) -> Result<(), SinkFlushError> {
        let (done, answer) = sync_channel(1);
        if !self.send_cmd(Cmd::Flush(done)) {
            return Err(SinkFlushError::failed("the .rrd writer has stopped"));
        }
        match answer.recv_timeout(timeout) {
            Ok(r) => r.map_err(SinkFlushError::failed),
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => Err(SinkFlushError::Timeout),
            Err(_) => Err(SinkFlushError::failed("the .rrd writer has stopped")),
        }
    }

    fn defers_finalization_to_shutdown(&self) -> bool {
        true
    }
}

impl Drop for DirectSink {
    /// Ends the stream: the writer thread writes the footer and the tail, then is joined.
    fn drop(&mut self) {
        drop(
            self.tx
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .take(),
        );
        if let Some(t) = self
            .thread
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take()
        {
            let _ = t.join();
        }
    }
}

/// Creates (or truncates) `path` and starts a stream saving to it, without the wall-clock
/// `log_time` and `log_tick` timelines; [`close`] ends it and reports how the writing went.
/// With a `live` sink the stream sends every message to both (the SDK's `MultiSink`): the file
/// gets the same messages as without it.
pub(super) fn save(
    builder: RecordingStreamBuilder,
    path: &Path,
    live: Option<Box<dyn LogSink>>,
) -> anyhow::Result<(RecordingStream, Status)> {
    let status = Status::default();
    let sink: Box<dyn LogSink> = Box::new(DirectSink::start(path, status.clone())?);
    let sinks = std::iter::once(sink).chain(live).collect::<Vec<_>>();
    let rec = builder.enabled(true).set_sinks(sinks)?;
    rec.set_log_time_enabled(false);
    rec.set_log_tick_enabled(false);
    Ok((rec, status))
}

/// Ends the file (dropping the last handle drains the SDK's pipeline, then the sink writes the
/// footer) and returns the writer's first error, or checks that the footer reached `path`
/// intact. `rec` must be the last handle.
pub(super) fn close(rec: RecordingStream, status: &Status, path: &Path) -> anyhow::Result<()> {
    drop(rec);
    match status.get() {
        Some(Err(e)) => bail!("{e}"),
        None => bail!("the .rrd writer stopped before the end"),
        Some(Ok(())) => check_footer(path).or_else(|e| bail!("{e}")),
    }
}

/// Checks that `path` ends with an RRD stream footer whose RRD footer is in the file and
/// matches its CRC: the last thing the writer thread writes.
fn check_footer(path: &Path) -> Result<(), String> {
    let incomplete = |why: &str| format!("the recording is incomplete ({why})");
    let mut file = File::open(path).map_err(|e| e.to_string())?;
    let len = file.metadata().map_err(|e| e.to_string())?.len();
    let tail = StreamFooter::ENCODED_SIZE_BYTES as u64;
    if len < tail {
        return Err(incomplete("no footer"));
    }
    let mut buf = vec![0; StreamFooter::ENCODED_SIZE_BYTES];
    file.seek(SeekFrom::Start(len - tail))
        .and_then(|_| file.read_exact(&mut buf))
        .map_err(|e| e.to_string())?;
    let footer = StreamFooter::from_rrd_bytes(&buf).map_err(|_| incomplete("no footer"))?;
    let entry = footer
        .entries
        .first()
        .ok_or_else(|| incomplete("empty footer"))?;
    let span = entry.rrd_footer_byte_span_from_start_excluding_header;
    if span.start.checked_add(span.len).is_none_or(|end| end > len) {
        return Err(incomplete("footer points past the end"));
    }
    let mut payload = vec![0; span.len as usize];
    file.seek(SeekFrom::Start(span.start))
        .and_then(|_| file.read_exact(&mut payload))
        .map_err(|e| e.to_string())?;
    if StreamFooter::compute_crc(&payload) != entry.crc_excluding_header {
        return Err(incomplete("footer CRC mismatch"));
    }
    Ok(())
}
