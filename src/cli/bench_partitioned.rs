//! Prints the partitioned schedule's table ([`wraptree::metrics::bench::partitioned`]).

use anyhow::Result;
use wraptree::metrics::bench::partitioned::{RECORD_N, record_row, row};
use wraptree::metrics::report::{
    partitioned_header, partitioned_line, partitioned_notes, partitioned_record_line,
};
use wraptree::scene::Scene;

/// Measures and prints a row per scene (`repeat` timed builds each, fewer from 10^6
/// primitives), then what recording the scene of [`RECORD_N`] primitives costs, if there is
/// one.
pub(super) fn print_table(cases: &[Scene], repeat: u32) -> Result<()> {
    print!("{}", partitioned_header());
    for scene in cases {
        print!("{}", partitioned_line(&row(scene, repeat)?));
    }
    print!("{}", partitioned_notes());
    if let Some(scene) = cases.iter().find(|s| s.len() == RECORD_N) {
        let cost = record_row(scene, repeat)?;
        print!(
            "{}",
            partitioned_record_line(&scene.name, scene.len(), &cost)
        );
    }
    Ok(())
}
