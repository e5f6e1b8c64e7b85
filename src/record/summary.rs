//! What `wraptree record` prints about a recording it wrote.

use super::Written;
use crate::scene::Scene;
use std::path::Path;

impl Written {
    /// The run of `scene` in one line, without its end: Ok for a finished grouping (rounds,
    /// depth, time), Err for a stopped one (why, and that the files are marked incomplete).
    pub fn summary(&self, scene: &Scene) -> Result<String, String> {
        match &self.grouping {
            Some(g) => Ok(format!(
                "{}: {} primitives, {} rounds, depth {} (mean {:.2}); recorded in {:.3} s",
                scene.name,
                scene.len(),
                g.rounds,
                g.tree.depth_max(),
                g.tree.depth_mean(),
                self.seconds
            )),
            None => {
                let why = match &self.stopped {
                    Some(s) => self.limits.message(s, scene.len()),
                    None => "grouping stopped".to_string(),
                };
                Err(format!(
                    "incomplete: {}: {why}; wrote what was recorded, marked incomplete",
                    scene.name
                ))
            }
        }
    }

    /// The two files with their sizes in MB, a line each.
    pub fn files(&self) -> String {
        let size = |p: &Path| {
            std::fs::metadata(p)
                .map(|m| m.len() as f64 / 1e6)
                .unwrap_or(0.0)
        };
        format!(
            "  {} ({:.2} MB)\n  {} ({:.2} MB)\n",
            self.rrd.display(),
            size(&self.rrd),
            self.mcap.display(),
            size(&self.mcap)
        )
    }
}
