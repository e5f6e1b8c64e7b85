//! Checking [`RecordOptions`] before a run, as `record` gives them from its flags.

use super::RecordOptions;
use crate::wrap::cover::solve::CoverLimit;
use anyhow::{Result, bail};

impl RecordOptions {
    /// Checks what [`record`](super::record) would reject only after loading and grouping: a
    /// cover budget of 0, a cover without levels, a refinement batch outside (0, 1], a treelet outside 3 to 7 leaves. The errors
    /// name the command-line flags.
    pub fn check(&self) -> Result<()> {
        if let Some((CoverLimit::Budget(0), _)) = self.cover {
            bail!("--cover-budget must be ≥ 1 (a cover needs at least one wrapper)");
        }
        if self.cover.is_some() && !self.detail.levels() {
            bail!(
                "--cover-tolerance/--cover-budget need --detail levels or full (the cover is a level)"
            );
        }
        if let Some(r) = &self.refine
            && !(r.batch > 0.0 && r.batch <= 1.0)
        {
            bail!("--refine-batch must be in (0, 1], got {}", r.batch);
        }
        if let Some(r) = &self.refine
            && !(3..=7).contains(&r.treelet)
        {
            bail!("--refine-treelet must be 3 to 7 leaves, got {}", r.treelet);
        }
        if let Some(r) = &self.refine
            && (1..3).contains(&r.treelet_min)
        {
            bail!(
                "--refine-treelet-min must be 0 (by the tree's size) or at least 3 leaves, got {}",
                r.treelet_min
            );
        }
        Ok(())
    }
}
