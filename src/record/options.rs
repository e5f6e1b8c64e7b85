//! Checking [`RecordOptions`] before a run, as `record` gives them from its flags.

use super::RecordOptions;
use crate::wrap::cover::solve::CoverLimit;
use anyhow::{Result, anyhow, bail};

impl RecordOptions {
    /// Checks what [`record`](super::record) would reject only after loading and grouping: a
    /// cover budget of 0, a cover without levels, refinement parameters that
    /// [`RefineParams::check`](crate::refine::RefineParams::check) refuses. The errors name the
    /// command-line flags.
    pub fn check(&self) -> Result<()> {
        if let Some((CoverLimit::Budget(0), _)) = self.cover {
            bail!("--cover-budget must be ≥ 1 (a cover needs at least one wrapper)");
        }
        if self.cover.is_some() && !self.detail.levels() {
            bail!(
                "--cover-tolerance/--cover-budget need --detail levels or full (the cover is a level)"
            );
        }
        if let Some(r) = &self.refine {
            r.check().map_err(|e| anyhow!("--{e}"))?;
        }
        Ok(())
    }
}
