//! The `.rrd` file sink: the SDK's RRD encoder (`re_log_encoding::Encoder`, the one behind
//! `RecordingStreamBuilder::save`) writing synchronously on the SDK's forwarding thread, with
//! every I/O error kept and reported.
//!
//! Why not `save`: in SDK 0.36.3 the `FileSink` writer thread exits on a write error (disk
//! full) while the flush request queued behind it is never answered, so `flush_blocking` and
//! even dropping the stream block forever. Here a failed write is remembered, later messages
//! are dropped, and `flush_blocking` and [`RrdFile::close`] return the error.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use rerun::external::re_log_encoding::{CrateVersion, Encoder, EncodingOptions};
use rerun::log::LogMsg;
use rerun::sink::{LogSink, SinkFlushError};

type RrdEncoder = Encoder<BufWriter<File>>;

#[derive(Default)]
struct State {
    /// `None` once closed or after the first error.
    encoder: Option<RrdEncoder>,
    /// The first write error.
    error: Option<String>,
}

/// A handle on an `.rrd` file being written; clones share the file.
#[derive(Clone)]
pub(super) struct RrdFile(Arc<Mutex<State>>);

impl RrdFile {
    /// Creates (or truncates) `path` and writes the RRD stream header.
    pub(super) fn create(path: &Path) -> anyhow::Result<RrdFile> {
        let file = BufWriter::with_capacity(1 << 20, File::create(path)?);
        let encoder = Encoder::new_eager(
            CrateVersion::LOCAL,
            EncodingOptions::PROTOBUF_COMPRESSED,
            file,
        )?;
        Ok(RrdFile(Arc::new(Mutex::new(State {
            encoder: Some(encoder),
            error: None,
        }))))
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        self.0
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Writes the end-of-stream marker and footer, flushes and syncs the file; returns the
    /// first error met since [`RrdFile::create`].
    pub(super) fn close(&self) -> anyhow::Result<()> {
        let mut state = self.lock();
        if let Some(err) = &state.error {
            anyhow::bail!("{err}");
        }
        let Some(mut encoder) = state.encoder.take() else {
            anyhow::bail!("the file was already closed");
        };
        encoder.finish()?;
        let file = encoder
            .into_inner()?
            .into_inner()
            .map_err(|e| e.into_error())?;
        file.sync_all()?;
        Ok(())
    }
}

impl LogSink for RrdFile {
    fn send(&self, msg: LogMsg) {
        let mut state = self.lock();
        if let Some(encoder) = state.encoder.as_mut()
            && let Err(err) = encoder.append(&msg)
        {
            state.error = Some(err.to_string());
            // Unwrapping the writer keeps the encoder's drop from writing a footer after the
            // failure; the file is closed here.
            if let Some(broken) = state.encoder.take() {
                drop(broken.into_inner());
            }
        }
    }

    fn flush_blocking(&self, _timeout: Duration) -> Result<(), SinkFlushError> {
        let mut state = self.lock();
        if let Some(err) = &state.error {
            return Err(SinkFlushError::failed(err.clone()));
        }
        if let Some(encoder) = state.encoder.as_mut()
            && let Err(err) = encoder.flush_blocking()
        {
            let err = err.to_string();
            state.error = Some(err.clone());
            return Err(SinkFlushError::failed(err));
        }
        Ok(())
    }
}
