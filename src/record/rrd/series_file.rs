//! A plain `.rrd` for benchmark and sweep results: a [`RecordingStream`] on the same
//! error-reporting file sink as the grouping recorder, without wall-clock time, written to a
//! temporary file and moved into place by [`SeriesFile::commit`].

use super::sink::RrdFile;
use crate::record::output::Pending;
use rerun::RecordingStream;
use std::path::{Path, PathBuf};

/// An `.rrd` being written.
pub struct SeriesFile {
    rec: RecordingStream,
    file: RrdFile,
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
        let file = RrdFile::create(pending.path())?;
        let mut builder = rerun::RecordingStreamBuilder::new(app)
            .recording_id(app.to_string())
            .enabled(true);
        if let Some(b) = blueprint {
            builder = builder.with_blueprint(b);
        }
        let rec =
            builder.set_sinks(vec![Box::new(file.clone()) as Box<dyn rerun::sink::LogSink>])?;
        rec.set_log_time_enabled(false);
        rec.set_log_tick_enabled(false);
        Ok(SeriesFile { rec, file, pending })
    }

    /// The stream to log to.
    pub fn rec(&self) -> &RecordingStream {
        &self.rec
    }

    /// Flushes and closes the file and moves it into place; returns its path.
    pub fn commit(self) -> anyhow::Result<PathBuf> {
        let dest = self.pending.dest().to_path_buf();
        self.rec
            .flush_blocking()
            .map_err(|e| anyhow::anyhow!("{}: {e}", dest.display()))?;
        drop(self.rec);
        self.file
            .close()
            .map_err(|e| anyhow::anyhow!("{}: {e}", dest.display()))?;
        self.pending.commit()
    }
}
