//! A sequential file writer that bypasses the page cache where the system allows it.
//!
//! Recordings are hundreds of megabytes written once and not read back by this process; the
//! page cache would copy every byte into a fresh page, which costs far more CPU than Linux's
//! `O_DIRECT` from an aligned buffer (`docs/recordings.md`, "How the files are written").
//! [`DirectWriter`] collects the stream in aligned 4 MiB blocks and hands each full block to an
//! I/O thread of its own, which writes it with `O_DIRECT` while the caller fills the next; the
//! last partial block is written through the page cache after the flag is cleared.
//!
//! Where `O_DIRECT` is missing (other systems) or refused (at open: tmpfs before Linux 6.6,
//! some network or FUSE file systems; at the first write with `EINVAL`: some devices), the I/O
//! thread carries on with ordinary writes to the same file: the same bytes, only the cost differs.

use std::fs::File;
use std::io::{self, Seek, SeekFrom, Write};
use std::path::Path;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::sync::{Arc, OnceLock};
use std::thread::JoinHandle;

/// Alignment of the buffers, of every direct write's length and of its file offset: the page
/// size, a multiple of every common logical block size (512 B, 4 KiB).
const ALIGN: usize = 4096;
/// Bytes collected before a block goes to the I/O thread.
const BLOCK: usize = 4 << 20;
/// Blocks queued for the I/O thread besides the one being filled.
const QUEUED: usize = 2;

/// An aligned block of `BLOCK` bytes inside a slightly larger allocation (a `Vec`'s heap
/// buffer does not move when the `Vec` is sent to another thread).
struct Block {
    mem: Vec<u8>,
    start: usize,
}

impl Block {
    /// A block whose data starts `skew` bytes past an aligned address (0 in use; tests skew it
    /// so that the kernel refuses the direct write).
    fn new(skew: usize) -> Block {
        let mem = vec![0u8; BLOCK + 2 * ALIGN];
        let start = mem.as_ptr().align_offset(ALIGN) + skew;
        Block { mem, start }
    }

    fn data(&self) -> &[u8] {
        &self.mem[self.start..self.start + BLOCK]
    }

    fn data_mut(&mut self) -> &mut [u8] {
        &mut self.mem[self.start..self.start + BLOCK]
    }
}

enum Job {
    /// Write the block's first `n` bytes (a multiple of `ALIGN`).
    Write(Block, usize),
    /// Write the block's first `n` bytes, whatever their length, and answer.
    Flush(Block, usize, SyncSender<io::Result<()>>),
}

/// A buffered, append-only writer of one file (see the [module docs](self)). Only
/// [`Seek::stream_position`] (and seeks to the current position) are supported, which is all a
/// writer that never goes back needs, e.g. the `mcap` crate with seeking disabled.
///
/// A write error of the I/O thread is returned by a later `write` or by `flush`. Call
/// [`Write::flush`] at the end: it writes the tail and reports any error. Dropping the writer
/// flushes too but cannot report an error.
pub struct DirectWriter {
    block: Option<Block>,
    /// Bytes collected in `block`.
    len: usize,
    /// Bytes accepted so far: the stream position.
    pos: u64,
    jobs: Option<SyncSender<Job>>,
    free: Receiver<Block>,
    failed: Arc<OnceLock<io::Error>>,
    io: Option<JoinHandle<u64>>,
}

impl DirectWriter {
    /// Creates or truncates `path` and opens it for writing with `O_DIRECT` where available,
    /// else without. Fails if the file cannot be opened or the I/O thread cannot be started.
    pub fn open(path: &Path) -> io::Result<DirectWriter> {
        let (file, direct) = match open(path, true) {
            Ok(f) => (f, true),
            Err(_) => (open(path, false)?, false),
        };
        Self::start(
            Out {
                file,
                direct,
                direct_bytes: 0,
            },
            0,
        )
    }

    fn start(out: Out, skew: usize) -> io::Result<DirectWriter> {
        let (jobs, todo) = sync_channel::<Job>(QUEUED);
        let (give, free) = sync_channel::<Block>(QUEUED + 1);
        for _ in 0..QUEUED {
            give.send(Block::new(skew)).expect("room for every block");
        }
        let failed = Arc::new(OnceLock::new());
        let seen = Arc::clone(&failed);
        let io = std::thread::Builder::new()
            .name("direct-io".into())
            .spawn(move || out.run(todo, give, &seen))?;
        Ok(DirectWriter {
            block: Some(Block::new(skew)),
            len: 0,
            pos: 0,
            jobs: Some(jobs),
            free,
            failed,
            io: Some(io),
        })
    }

    /// The I/O thread's first error, as a new error of the same kind and cause.
    fn error(&self) -> Option<io::Error> {
        self.failed.get().map(copy)
    }

    /// Sends the block, `n` bytes full, as `job`, and takes an empty one.
    fn hand_over(&mut self, job: impl FnOnce(Block, usize) -> Job) -> io::Result<()> {
        let gone = || io::Error::other("the I/O thread has stopped");
        let block = self.block.take().ok_or_else(gone)?;
        let jobs = self.jobs.as_ref().ok_or_else(gone)?;
        jobs.send(job(block, self.len)).map_err(|_| gone())?;
        self.len = 0;
        self.block = Some(self.free.recv().map_err(|_| gone())?);
        Ok(())
    }

    /// Ends the I/O thread; returns how many bytes bypassed the page cache.
    fn stop(&mut self) -> u64 {
        drop(self.jobs.take());
        self.io.take().map_or(0, |h| h.join().unwrap_or(0))
    }

    /// Flushes and ends the writer; returns how many of its bytes bypassed the page cache.
    pub fn close(mut self) -> io::Result<u64> {
        self.flush()?;
        Ok(self.stop())
    }
}

/// A new error of the same OS code, or else of the same kind and message (`io::Error` is not
/// `Clone`, and the I/O thread's first error is returned to every later call).
fn copy(e: &io::Error) -> io::Error {
    match e.raw_os_error() {
        Some(code) => io::Error::from_raw_os_error(code),
        None => io::Error::new(e.kind(), e.to_string()),
    }
}

/// The file, as the I/O thread writes it.
struct Out {
    file: File,
    /// `O_DIRECT` is set on `file`.
    direct: bool,
    /// Bytes written with `O_DIRECT`.
    direct_bytes: u64,
}

impl Out {
    /// The I/O thread: writes each job's bytes in order until the writer is dropped, keeps the
    /// first error in `failed` (and writes nothing after it), returns every block and answers
    /// every flush. Returns how many bytes bypassed the page cache.
    fn run(
        mut self,
        todo: Receiver<Job>,
        give: SyncSender<Block>,
        failed: &OnceLock<io::Error>,
    ) -> u64 {
        for job in todo {
            let (block, n, answer) = match job {
                Job::Write(b, n) => (b, n, None),
                Job::Flush(b, n, a) => (b, n, Some(a)),
            };
            if failed.get().is_none() {
                let mut r = self.write(&block.data()[..n]);
                if answer.is_some() {
                    r = r.and_then(|()| self.file.flush());
                }
                if let Err(e) = r {
                    let _ = failed.set(e);
                }
            }
            if let Some(a) = answer {
                let _ = a.send(failed.get().map_or(Ok(()), |e| Err(copy(e))));
            }
            let _ = give.send(block);
        }
        self.direct_bytes
    }

    /// Writes `data` at the end of the file: a whole number of aligned blocks directly, the
    /// rest through the page cache (with `O_DIRECT` cleared for good). After an error, writes
    /// nothing more.
    fn write(&mut self, data: &[u8]) -> io::Result<()> {
        let mut done = 0;
        while done < data.len() {
            if self.direct && !(data.len() - done).is_multiple_of(ALIGN) {
                self.set_direct(false)?;
            }
            match self.file.write(&data[done..]) {
                Ok(0) => return Err(io::ErrorKind::WriteZero.into()),
                Ok(k) => {
                    done += k;
                    if self.direct {
                        self.direct_bytes += k as u64;
                    }
                    // A short direct write leaves an unaligned offset for the next one.
                    if self.direct && !k.is_multiple_of(ALIGN) {
                        self.set_direct(false)?;
                    }
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) if self.direct && e.raw_os_error() == Some(libc::EINVAL) => {
                    self.set_direct(false)?;
                }
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }

    #[cfg(target_os = "linux")]
    fn set_direct(&mut self, on: bool) -> io::Result<()> {
        use std::os::fd::AsRawFd;
        let fd = self.file.as_raw_fd();
        // SAFETY: fcntl on a descriptor this writer owns, with integer arguments only.
        let flags = unsafe { libc::fcntl(fd, libc::F_GETFL) };
        if flags < 0 {
            return Err(io::Error::last_os_error());
        }
        let flags = if on {
            flags | libc::O_DIRECT
        } else {
            flags & !libc::O_DIRECT
        };
        // SAFETY: as above.
        if unsafe { libc::fcntl(fd, libc::F_SETFL, flags) } < 0 {
            return Err(io::Error::last_os_error());
        }
        self.direct = on;
        Ok(())
    }

    /// Without `O_DIRECT` the writer is never direct.
    #[cfg(not(target_os = "linux"))]
    fn set_direct(&mut self, _on: bool) -> io::Result<()> {
        self.direct = false;
        Ok(())
    }
}

#[cfg(target_os = "linux")]
fn open(path: &Path, direct: bool) -> io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt;
    let mut o = std::fs::OpenOptions::new();
    o.write(true).create(true).truncate(true);
    if direct {
        o.custom_flags(libc::O_DIRECT);
    }
    o.open(path)
}

#[cfg(not(target_os = "linux"))]
fn open(path: &Path, direct: bool) -> io::Result<File> {
    if direct {
        return Err(io::ErrorKind::Unsupported.into());
    }
    std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(true)
        .open(path)
}

impl Write for DirectWriter {
    fn write(&mut self, data: &[u8]) -> io::Result<usize> {
        if let Some(e) = self.error() {
            return Err(e);
        }
        if self.len == BLOCK {
            self.hand_over(Job::Write)?;
        }
        let len = self.len;
        let k = data.len().min(BLOCK - len);
        let block = self.block.as_mut().ok_or(io::ErrorKind::BrokenPipe)?;
        block.data_mut()[len..len + k].copy_from_slice(&data[..k]);
        self.len += k;
        self.pos += k as u64;
        Ok(k)
    }

    /// Writes everything collected (the tail through the page cache) and waits for it.
    fn flush(&mut self) -> io::Result<()> {
        let (answer, result) = sync_channel(1);
        self.hand_over(|b, n| Job::Flush(b, n, answer))?;
        match result.recv() {
            Ok(r) => r,
            Err(_) => self.error().map_or(Ok(()), Err),
        }
    }
}

impl Seek for DirectWriter {
    /// Only the current position can be asked for or sought to.
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        match pos {
            SeekFrom::Current(0) => Ok(self.pos),
            SeekFrom::Start(p) if p == self.pos => Ok(self.pos),
            _ => Err(io::Error::new(
                io::ErrorKind::Unsupported,
                "an append-only writer cannot seek",
            )),
        }
    }
}

impl Drop for DirectWriter {
    fn drop(&mut self) {
        if self.len > 0 {
            let _ = self.flush();
        }
        self.stop();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bytes that differ at every offset of a long stretch.
    fn pattern(n: usize, seed: u64) -> Vec<u8> {
        let mut x = seed | 1;
        (0..n)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                x as u8
            })
            .collect()
    }

    /// Writes pieces of the given sizes through `w`, checks the file holds exactly them, and
    /// returns how many bytes bypassed the page cache.
    fn round_trip(mut w: DirectWriter, path: &Path, sizes: &[usize]) -> u64 {
        let mut all = Vec::new();
        for (i, &n) in sizes.iter().enumerate() {
            let piece = pattern(n, i as u64 + 7);
            w.write_all(&piece).unwrap();
            all.extend_from_slice(&piece);
            assert_eq!(w.stream_position().unwrap(), all.len() as u64);
        }
        let direct = w.close().unwrap();
        assert_eq!(std::fs::read(path).unwrap(), all);
        direct
    }

    const SIZES: [usize; 7] = [1, 4095, 4097, BLOCK - 3, 9 << 20, 17, 3 * ALIGN];

    /// An empty file `name` in a new temporary directory (kept alive by the first value).
    fn empty_file(name: &str) -> (tempfile::TempDir, std::path::PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(name);
        std::fs::write(&path, b"").unwrap();
        (dir, path)
    }

    /// The test directory's file system takes `O_DIRECT` at open.
    fn takes_direct(path: &Path) -> bool {
        open(path, true).is_ok()
    }

    #[test]
    fn the_file_holds_exactly_what_was_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.bin");
        std::fs::write(&path, b"old contents, longer than nothing").unwrap();
        let direct = round_trip(DirectWriter::open(&path).unwrap(), &path, &SIZES);
        if takes_direct(&path) {
            // Every whole block went around the page cache, the tail through it.
            let total: usize = SIZES.iter().sum();
            assert_eq!(direct, (total / BLOCK * BLOCK) as u64);
        }
        // An empty stream truncates; a flush in the middle keeps the bytes in order.
        assert_eq!(
            round_trip(DirectWriter::open(&path).unwrap(), &path, &[]),
            0
        );
        let mut w = DirectWriter::open(&path).unwrap();
        w.write_all(b"head ").unwrap();
        w.flush().unwrap();
        w.write_all(b"tail").unwrap();
        drop(w);
        assert_eq!(std::fs::read(&path).unwrap(), b"head tail");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_refused_direct_write_falls_back_to_the_page_cache() {
        let (_dir, path) = empty_file("b.bin");
        let Ok(file) = open(&path, true) else {
            return; // this file system refuses O_DIRECT at open: `open` already falls back
        };
        // Blocks one byte off alignment: Linux refuses the direct write with EINVAL (tmpfs,
        // which takes O_DIRECT since Linux 6.6, does not check alignment).
        let out = Out {
            file,
            direct: true,
            direct_bytes: 0,
        };
        let direct = round_trip(DirectWriter::start(out, 1).unwrap(), &path, &SIZES);
        // SAFETY: statfs fills the zeroed struct; the path is a valid C string.
        let tmpfs = unsafe {
            let c = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).unwrap();
            let mut st: libc::statfs = std::mem::zeroed();
            libc::statfs(c.as_ptr(), &mut st) == 0 && st.f_type == libc::TMPFS_MAGIC
        };
        assert!(tmpfs || direct == 0, "the writer fell back");
    }

    #[test]
    fn seeking_anywhere_but_here_is_refused() {
        let (_dir, path) = empty_file("c.bin");
        let mut w = DirectWriter::open(&path).unwrap();
        w.write_all(b"abc").unwrap();
        assert_eq!(w.seek(SeekFrom::Start(3)).unwrap(), 3);
        assert!(w.seek(SeekFrom::Start(0)).is_err());
        assert!(w.seek(SeekFrom::End(0)).is_err());
        w.close().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"abc");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_write_error_is_returned_by_a_later_write_or_the_flush() {
        let (_dir, path) = empty_file("d.bin");
        // A read-only descriptor: every write fails with EBADF.
        let out = Out {
            file: File::open(&path).unwrap(),
            direct: false,
            direct_bytes: 0,
        };
        let mut w = DirectWriter::start(out, 0).unwrap();
        let piece = pattern(3 * BLOCK, 1);
        let err = w.write_all(&piece).and_then(|()| w.flush()).unwrap_err();
        assert_eq!(err.raw_os_error(), Some(libc::EBADF), "{err}");
        assert!(w.write_all(b"x").and_then(|()| w.flush()).is_err());
    }
}
