//! Prints the partitioned schedule's table ([`wraptree::metrics::bench::partitioned`]).

use anyhow::Result;
use wraptree::metrics::bench::partitioned::row;
use wraptree::metrics::report::{partitioned_header, partitioned_line, partitioned_notes};
use wraptree::scene::Scene;

/// Measures and prints a row per scene (`repeat` timed builds each, fewer from 10^6
/// primitives).
pub(super) fn print_table(cases: &[Scene], repeat: u32) -> Result<()> {
    print!("{}", partitioned_header());
    for scene in cases {
        print!("{}", partitioned_line(&row(scene, repeat)?));
    }
    print!("{}", partitioned_notes());
    Ok(())
}
