//! `.rrd` files through the SDK's own file sink (`RecordingStreamBuilder::save`), plus the two
//! checks that sink leaves to its caller.
//!
//! In SDK 0.36.3 the `FileSink` writer thread stops at its first write error and only logs it.
//! A flush request already queued behind the failed write is then never answered, so
//! `flush_blocking` (and dropping the stream after it) waits forever; a failure while the
//! footer is written at shutdown is not reported at all (both seen with `ulimit -f`). [`close`]
//! therefore never flushes: it drops the stream, which drains the SDK's pipeline, makes the
//! writer thread write the footer and joins it, then reads the footer back: the stream footer
//! at the end of the file must parse and the RRD footer it points at must match its CRC. A
//! failure becomes one error carrying the operating system's reason, found by a probe write
//! (see [`write_probe`]).

use std::fs::File;
use std::io::{Read as _, Seek as _, SeekFrom, Write as _};
use std::path::Path;

use anyhow::bail;
use rerun::external::re_log_encoding::{Decodable as _, StreamFooter};
use rerun::{RecordingStream, RecordingStreamBuilder};

/// Creates (or truncates) `path` and starts a stream saving to it with the SDK's file sink,
/// without the wall-clock `log_time` and `log_tick` timelines.
pub(super) fn save(
    builder: RecordingStreamBuilder,
    path: &Path,
) -> anyhow::Result<RecordingStream> {
    let rec = builder.enabled(true).save(path)?;
    rec.set_log_time_enabled(false);
    rec.set_log_tick_enabled(false);
    Ok(rec)
}

/// Ends the file (dropping the last handle drains the SDK's pipeline and writes the footer)
/// and checks that the footer reached `path` intact. `rec` must be the last handle.
pub(super) fn close(rec: RecordingStream, path: &Path) -> anyhow::Result<()> {
    drop(rec);
    if let Err(err) = check_footer(path) {
        bail!("{}", write_probe(path).unwrap_or(err));
    }
    Ok(())
}

/// Checks that `path` ends with an RRD stream footer whose RRD footer is in the file and
/// matches its CRC: the last thing the SDK's writer thread writes.
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

/// The reason writes to `path` fail, if they do: appends and syncs one block, then truncates
/// it away. Used only after the SDK's writer has stopped, to turn its "shut down prematurely"
/// into the operating system's reason (no space left, file too large, I/O error).
fn write_probe(path: &Path) -> Option<String> {
    let mut file = std::fs::OpenOptions::new().append(true).open(path).ok()?;
    let len = file.metadata().ok()?.len();
    let result = file.write_all(&[0; 4096]).and_then(|()| file.sync_data());
    file.set_len(len).ok();
    result
        .err()
        .map(|e| format!("the SDK's file writer stopped: {e}"))
}
