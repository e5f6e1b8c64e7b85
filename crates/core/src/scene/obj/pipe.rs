//! The pre-pass and `tobj`'s parse of a large file at once: the pre-pass ([`super::scan`]) runs
//! on a second thread and sends its cleaned text in blocks, which `tobj` reads as they come
//! ([`scan_then`]), so a large file loads in about the time of `tobj`'s parse, which is most of
//! the work.
//!
//! The results are those of the two run in turn: the pre-pass's error comes first, and `tobj`
//! reads the same bytes (up to where a failed pre-pass stopped, which is then not looked at).

use std::io::{BufRead, Read};
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};

/// Texts from this size up are scanned and parsed at once.
pub(super) const PIPELINE_FROM: usize = 1 << 20;
/// Bytes per block sent.
const BLOCK: usize = 1 << 20;
/// Blocks in flight before the pre-pass waits for `tobj`.
const IN_FLIGHT: usize = 8;

/// Where [`super::scan`] writes the cleaned text.
pub(super) trait Cleaned {
    /// Appends `s`.
    fn push_str(&mut self, s: &str);
}

impl Cleaned for String {
    #[inline]
    fn push_str(&mut self, s: &str) {
        String::push_str(self, s);
    }
}

/// Cleaned text sent in blocks; once the reader is gone, the rest is dropped.
struct Blocks {
    buf: Vec<u8>,
    tx: Option<SyncSender<Vec<u8>>>,
}

impl Blocks {
    fn send(&mut self) {
        let full = std::mem::replace(&mut self.buf, Vec::with_capacity(BLOCK + 256));
        if let Some(tx) = &self.tx
            && tx.send(full).is_err()
        {
            self.tx = None;
        }
    }
}

impl Cleaned for Blocks {
    #[inline]
    fn push_str(&mut self, s: &str) {
        self.buf.extend_from_slice(s.as_bytes());
        if self.buf.len() >= BLOCK {
            self.send();
        }
    }
}

impl Drop for Blocks {
    /// Sends the last, partial block; dropping the sender then ends the reader's stream.
    fn drop(&mut self) {
        if !self.buf.is_empty() {
            self.send();
        }
    }
}

/// The cleaned text as `tobj` reads it: the blocks in order, then the end.
pub(super) struct BlockReader {
    cur: Vec<u8>,
    pos: usize,
    rx: Option<Receiver<Vec<u8>>>,
}

impl Read for BlockReader {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        let n = {
            let avail = self.fill_buf()?;
            let n = avail.len().min(out.len());
            out[..n].copy_from_slice(&avail[..n]);
            n
        };
        self.consume(n);
        Ok(n)
    }
}

impl BufRead for BlockReader {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        while self.pos == self.cur.len() {
            match self.rx.as_ref().map(Receiver::recv) {
                Some(Ok(block)) => (self.cur, self.pos) = (block, 0),
                // The sender is gone: the end of the text.
                _ => break,
            }
        }
        Ok(&self.cur[self.pos..])
    }

    fn consume(&mut self, n: usize) {
        self.pos = (self.pos + n).min(self.cur.len());
    }
}

/// Scans `text` with `scan` and has `parse` read the cleaned text: at once on two threads for a
/// text of `pipeline_from` bytes or more ([`PIPELINE_FROM`]), one after the other below (and
/// when no thread can be started). Returns the scan's result (an error of the scan is returned
/// as such) with `parse`'s.
pub(super) fn scan_then<S, E, T>(
    text: &str,
    pipeline_from: usize,
    scan: impl Fn(&str, &mut dyn Cleaned) -> Result<S, E> + Sync,
    parse: impl FnOnce(&mut BlockReader) -> T,
) -> Result<(S, T), E>
where
    S: Send,
    E: Send,
{
    if text.len() < pipeline_from {
        return in_turn(text, &scan, parse);
    }
    let scan = &scan;
    let (tx, rx) = sync_channel(IN_FLIGHT);
    std::thread::scope(|s| {
        let started = std::thread::Builder::new()
            .name("obj-prepass".into())
            .spawn_scoped(s, move || {
                let mut blocks = Blocks {
                    buf: Vec::with_capacity(BLOCK + 256),
                    tx: Some(tx),
                };
                scan(text, &mut blocks)
            });
        let Ok(scanner) = started else {
            return in_turn(text, scan, parse);
        };
        let mut reader = BlockReader {
            cur: Vec::new(),
            pos: 0,
            rx: Some(rx),
        };
        let parsed = parse(&mut reader);
        // A parse that stopped early leaves the scan sending into nothing, not blocked.
        drop(reader);
        let scanned = scanner
            .join()
            .unwrap_or_else(|p| std::panic::resume_unwind(p))?;
        Ok((scanned, parsed))
    })
}

/// [`scan_then`] one after the other: the whole cleaned text, then the parse.
fn in_turn<S, E, T>(
    text: &str,
    scan: &impl Fn(&str, &mut dyn Cleaned) -> Result<S, E>,
    parse: impl FnOnce(&mut BlockReader) -> T,
) -> Result<(S, T), E> {
    let mut cleaned = String::with_capacity(text.len());
    let scanned = scan(text, &mut cleaned)?;
    let mut reader = BlockReader {
        cur: cleaned.into_bytes(),
        pos: 0,
        rx: None,
    };
    Ok((scanned, parse(&mut reader)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Copies `text` to the cleaned text in pieces of `piece` bytes.
    fn copy(piece: usize) -> impl Fn(&str, &mut dyn Cleaned) -> Result<usize, String> + Sync {
        move |text: &str, out: &mut dyn Cleaned| {
            for chunk in text.as_bytes().chunks(piece) {
                out.push_str(std::str::from_utf8(chunk).map_err(|e| e.to_string())?);
            }
            Ok(text.len())
        }
    }

    #[test]
    fn the_parse_reads_what_the_scan_wrote_in_either_mode() {
        for len in [100, PIPELINE_FROM + 3 * BLOCK + 17] {
            let text: String = (0..len).map(|i| (b'a' + (i % 26) as u8) as char).collect();
            let (n, read) = scan_then(&text, PIPELINE_FROM, copy(4099), |r| {
                let mut s = String::new();
                r.read_to_string(&mut s).map(|_| s)
            })
            .unwrap();
            assert_eq!(n, len);
            assert_eq!(read.unwrap(), text);
        }
    }

    #[test]
    fn a_large_file_loads_the_same_at_once_as_in_turn() {
        use super::super::{LoadOptions, load_piped_from};
        // A 30,000-triangle soup in three named objects: ~3 MB of OBJ, so several blocks, each
        // cut inside a line.
        let mut text = Vec::new();
        crate::scene::generate::soup(30_000, 4)
            .write_obj(&mut text)
            .unwrap();
        let lines: Vec<&[u8]> = text.split_inclusive(|&b| b == b'\n').collect();
        let mut obj = Vec::new();
        for (i, line) in lines.iter().enumerate() {
            if i % (lines.len() / 3) == 0 {
                obj.extend_from_slice(format!("o part{i}\n").as_bytes());
            }
            obj.extend_from_slice(line);
        }
        assert!(obj.len() > 2 * BLOCK);
        let opts = LoadOptions::default();
        let both = |bytes: Vec<u8>| {
            let shown = |r: Result<super::super::Loaded, _>| {
                r.map(|l| format!("{:?} {:?} {}", l.scene, l.warnings, l.source.sha256))
            };
            let never = crate::stop::Stop::new();
            let at_once = shown(load_piped_from("soup.obj", bytes.clone(), &opts, 0, &never));
            let in_turn = shown(load_piped_from(
                "soup.obj",
                bytes,
                &opts,
                usize::MAX,
                &never,
            ));
            assert_eq!(at_once, in_turn);
            at_once
        };
        assert!(both(obj.clone()).is_ok());
        // A bad face index in the middle and a bad number at the end: the same error.
        let mid = obj.len() / 2
            + obj[obj.len() / 2..]
                .iter()
                .position(|&b| b == b'\n')
                .unwrap();
        let mut bad = obj.clone();
        bad.splice(mid + 1..mid + 1, b"f 1 2 0\n".iter().copied());
        assert!(both(bad).unwrap_err().problem.contains("face"));
        let mut bad = obj;
        bad.extend_from_slice(b"v 1 2 nope\n");
        assert!(both(bad).unwrap_err().problem.contains("bad number"));
    }

    #[test]
    fn the_scan_error_wins_and_a_parse_that_stops_early_does_not_block_the_scan() {
        let text = "x".repeat(PIPELINE_FROM + 20 * BLOCK);
        let failing = |_: &str, out: &mut dyn Cleaned| -> Result<(), String> {
            out.push_str(&"y".repeat(BLOCK));
            Err("line 2: bad".into())
        };
        let got = scan_then(&text, PIPELINE_FROM, failing, |r| {
            r.fill_buf().map(|b| b.len()).ok()
        });
        assert_eq!(got.unwrap_err(), "line 2: bad");
        // The parse reads one byte and stops; the scan goes on sending 21 blocks.
        let (n, first) = scan_then(&text, PIPELINE_FROM, copy(BLOCK / 2), |r| {
            let mut b = [0u8; 1];
            r.read(&mut b).map(|_| b[0])
        })
        .unwrap();
        assert_eq!((n, first.unwrap()), (text.len(), b'x'));
    }
}
