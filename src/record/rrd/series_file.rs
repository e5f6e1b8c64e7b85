//! A plain `.rrd` for benchmark and sweep results: a [`RecordingStream`] saved and checked like
//! the grouping recorder's, without wall-clock time, written to a temporary file and moved into
//! place by [`SeriesFile::commit`].

use super::sink;
use crate::output::Pending;
use rerun::RecordingStream;
use std::path::{Path, PathBuf};

/// An `.rrd` being written.
pub struct SeriesFile {
    rec: RecordingStream,
    status: sink::Status,
    pending: Pending,
}

impl SeriesFile {
    /// Starts `dest` (replaced on commit only if `force` or absent) for application `app`,
    /// with a fixed recording id so the same results give the same recording identity, and the
    /// layout `blueprint` if given.
    pub fn create(
        dest: &Path,
        app: &'static str,
        force: bool,
        blueprint: Option<rerun::blueprint::Blueprint>,
    ) -> anyhow::Result<SeriesFile> {
        let pending = Pending::create(dest, force)?;
        let mut builder = rerun::RecordingStreamBuilder::new(app).recording_id(app.to_string());
        if let Some(b) = blueprint {
            builder = builder.with_blueprint(b);
        }
        let (rec, status) = sink::save(builder, pending.path(), None)
            .map_err(|e| anyhow::anyhow!("{}: {}", dest.display(), e.root_cause()))?;
        Ok(SeriesFile {
            rec,
            status,
            pending,
        })
    }

    /// The stream to log to.
    pub fn rec(&self) -> &RecordingStream {
        &self.rec
    }

    /// Flushes and closes the file and moves it into place; returns its path.
    pub fn commit(self) -> anyhow::Result<PathBuf> {
        self.finish()?.commit()
    }

    /// Flushes and closes the file, not yet moved into place.
    pub fn finish(self) -> anyhow::Result<Pending> {
        let dest = self.pending.dest().to_path_buf();
        sink::close(self.rec, &self.status, self.pending.path())
            .map_err(|e| anyhow::anyhow!("{}: {e}", dest.display()))?;
        Ok(self.pending)
    }
}
