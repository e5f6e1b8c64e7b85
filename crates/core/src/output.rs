//! Output files that appear whole or not at all.
//!
//! Data goes to a temporary file in the destination's directory, renamed over the destination
//! only once it is complete; an existing file is replaced only when the caller allows it. A
//! failed or interrupted write leaves the old file untouched.
//!
//! Unfinished outputs (temporary files not yet moved into place, directories made for an
//! output) are registered, so that a process ended by a stop request it could not obey in time
//! takes them away first ([`discard_unfinished`]).

use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard};

/// The unfinished outputs of the process: temporary files, then directories made (deepest
/// first within each [`output_dir`] call).
struct Unfinished {
    files: Vec<PathBuf>,
    dirs: Vec<PathBuf>,
}

static UNFINISHED: Mutex<Unfinished> = Mutex::new(Unfinished {
    files: Vec::new(),
    dirs: Vec::new(),
});

/// The registry, whatever a panicking holder left it as.
fn unfinished() -> MutexGuard<'static, Unfinished> {
    UNFINISHED.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes every unfinished output of the process (temporary files, then the directories made
/// for outputs that are empty then) and keeps any other thread from moving a file into place
/// afterwards: for a process about to exit on a stop request that its current step does not
/// check. Returns how many files it removed.
pub fn discard_unfinished() -> usize {
    let guard = unfinished();
    let removed = guard
        .files
        .iter()
        .filter(|f| std::fs::remove_file(f).is_ok())
        .count();
    for d in guard.dirs.iter().rev() {
        let _ = std::fs::remove_dir(d);
    }
    // Held until the process exits: a commit waiting for it never moves its file into place.
    std::mem::forget(guard);
    removed
}

/// A file being written; [`Pending::commit`] moves it into place.
#[derive(Debug)]
pub struct Pending {
    tmp: tempfile::NamedTempFile,
    dest: PathBuf,
    /// Set by [`Pending::sync`]; [`Pending::commit`] then does not sync again.
    synced: AtomicBool,
}

impl Pending {
    /// Starts writing `dest`. Fails when its directory is missing or unwritable, or when it
    /// exists and `force` is false.
    pub fn create(dest: &Path, force: bool) -> Result<Pending> {
        if dest.exists() && !force {
            bail!(
                "{}: already exists (use --force to replace it)",
                dest.display()
            );
        }
        let dir = match dest.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        if !dir.is_dir() {
            bail!(
                "{}: output directory {} does not exist",
                dest.display(),
                dir.display()
            );
        }
        let name = dest.file_name().and_then(|n| n.to_str()).unwrap_or("out");
        let tmp = tempfile::Builder::new()
            .prefix(&format!(".{name}."))
            .suffix(".tmp")
            .tempfile_in(dir)
            .with_context(|| {
                format!(
                    "{}: cannot create a file in {}",
                    dest.display(),
                    dir.display()
                )
            })?;
        // The temporary file is created private (0600); it gets the finished file's ordinary
        // permissions now, so that changing them does not cost one more sync at commit.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let perms = std::fs::Permissions::from_mode(0o644);
            tmp.as_file()
                .set_permissions(perms)
                .with_context(|| format!("{}: cannot set permissions", dest.display()))?;
        }
        unfinished().files.push(tmp.path().to_path_buf());
        Ok(Pending {
            tmp,
            dest: dest.to_path_buf(),
            synced: AtomicBool::new(false),
        })
    }

    /// Starts writing `dest` ([`Pending::create`]) and writes `bytes`, not yet committed.
    pub fn with_bytes(dest: &Path, bytes: &[u8], force: bool) -> Result<Pending> {
        use std::io::Write;
        let p = Pending::create(dest, force)?;
        p.file()?
            .write_all(bytes)
            .with_context(|| format!("{}: write failed", dest.display()))?;
        Ok(p)
    }

    /// Path of the temporary file (for writers that open paths themselves).
    pub fn path(&self) -> &Path {
        self.tmp.path()
    }

    /// The final destination.
    pub fn dest(&self) -> &Path {
        &self.dest
    }

    /// A second handle on the temporary file, for writing.
    pub fn file(&self) -> Result<std::fs::File> {
        self.tmp
            .reopen()
            .with_context(|| format!("{}: cannot open for writing", self.path().display()))
    }

    /// Syncs the temporary file's data and metadata to disk after its last write, so that
    /// [`Pending::commit`] need not; lets two files be synced at the same time before either is
    /// moved.
    pub fn sync(&self) -> Result<()> {
        self.tmp
            .as_file()
            .sync_all()
            .with_context(|| format!("{}: cannot sync", self.dest.display()))?;
        self.synced.store(true, Ordering::Release);
        Ok(())
    }

    /// Syncs the temporary file (unless [`Pending::sync`] did) and renames it over the
    /// destination.
    pub fn commit(self) -> Result<PathBuf> {
        self.commit_to(None)
    }

    /// Like [`Pending::commit`] but to `other` instead of the destination (used to set an
    /// interrupted recording aside without touching an existing one).
    pub fn commit_to(self, other: Option<&Path>) -> Result<PathBuf> {
        let dest = other.map(Path::to_path_buf).unwrap_or(self.dest);
        if !self.synced.load(Ordering::Acquire) {
            self.tmp
                .as_file()
                .sync_all()
                .with_context(|| format!("{}: cannot sync", dest.display()))?;
        }
        let tmp_path = self.tmp.path().to_path_buf();
        // Held across the rename, so that [`discard_unfinished`] sees the file whole or not.
        let mut registry = unfinished();
        registry.files.retain(|f| *f != tmp_path);
        self.tmp.persist(&dest).map_err(|e| {
            anyhow::anyhow!("{}: cannot move into place: {}", dest.display(), e.error)
        })?;
        Ok(dest)
    }
}

/// Writes `bytes` to `dest` atomically.
pub fn write_atomic(dest: &Path, bytes: &[u8], force: bool) -> Result<()> {
    Pending::with_bytes(dest, bytes, force)?.commit()?;
    Ok(())
}

/// The output prefix: `given`, or `recordings/<stem of scene_file><suffix>` (creating
/// `recordings/`). A given prefix's directory must exist ([`Pending::create`] says so).
pub fn output_prefix(given: Option<&Path>, scene_file: &str, suffix: &str) -> Result<PathBuf> {
    if let Some(p) = given {
        return Ok(p.to_path_buf());
    }
    let stem = Path::new(scene_file)
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "scene".into());
    std::fs::create_dir_all("recordings")
        .context("recordings: cannot create the default output directory")?;
    Ok(PathBuf::from("recordings").join(format!("{stem}{suffix}")))
}

/// `prefix` with `ext` appended (`recordings/lamp` + `.rrd`).
pub fn with_ext(prefix: &Path, ext: &str) -> PathBuf {
    let mut s = prefix.as_os_str().to_owned();
    s.push(ext);
    PathBuf::from(s)
}

/// An output directory, and the directories [`output_dir`] made for it: those are removed
/// again when it is dropped while still empty (a command that failed or was stopped before
/// writing leaves nothing behind).
#[derive(Debug)]
pub struct OutDir {
    path: PathBuf,
    /// The directories made, deepest first.
    made: Vec<PathBuf>,
}

impl std::ops::Deref for OutDir {
    type Target = Path;

    fn deref(&self) -> &Path {
        &self.path
    }
}

impl Drop for OutDir {
    fn drop(&mut self) {
        unfinished().dirs.retain(|d| !self.made.contains(d));
        for d in &self.made {
            // Fails, and so keeps the directory, once anything was written into it.
            if std::fs::remove_dir(d).is_err() {
                break;
            }
        }
    }
}

/// The output directory: `given` or `default`, created with its parents if missing; the
/// [`OutDir`] takes away the directories made here if they are still empty when it is dropped.
pub fn output_dir(given: Option<&Path>, default: &str) -> Result<OutDir> {
    let path = given.map_or_else(|| PathBuf::from(default), Path::to_path_buf);
    let made: Vec<PathBuf> = path
        .ancestors()
        .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
        .map(Path::to_path_buf)
        .collect();
    if !path.is_dir() {
        std::fs::create_dir_all(&path)
            .with_context(|| format!("{}: cannot create the output directory", path.display()))?;
    }
    // Shallowest first, so that [`discard_unfinished`] (which goes backwards) removes the
    // deepest first.
    unfinished().dirs.extend(made.iter().rev().cloned());
    Ok(OutDir { path, made })
}

/// Checks, before the work that produces them, that the files `paths` may be written: none is
/// the input file `input` (a path that cannot be resolved is none), and none exists unless
/// `force`.
pub fn check_new(paths: &[&Path], input: &Path, force: bool) -> Result<()> {
    let input = std::fs::canonicalize(input).ok();
    for p in paths {
        if input.is_some() && std::fs::canonicalize(p).ok() == input {
            anyhow::bail!("{}: is the input scene; choose another -o", p.display());
        }
    }
    check_absent(paths, force)
}

/// Checks, before the work that produces them, that none of the files `paths` exists unless
/// `force`.
pub fn check_absent<P: AsRef<Path>>(paths: &[P], force: bool) -> Result<()> {
    if force {
        return Ok(());
    }
    match paths.iter().map(AsRef::as_ref).find(|p| p.exists()) {
        Some(p) => anyhow::bail!(
            "{}: already exists (use --force to replace it)",
            p.display()
        ),
        None => Ok(()),
    }
}
