//! `wraptree record`: group a scene step by step and write `PREFIX.rrd` and `PREFIX.mcap`
//! ([`wraptree::record::record`]).

use super::group::{BudgetArgs, EXIT_INTERRUPTED, Progress};
use super::{GroupArgs, SceneArgs};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use wraptree::output::output_prefix;
use wraptree::record::mcap::Compression;
use wraptree::record::{Detail, RecordOptions, Written, record};
use wraptree::refine::RefineParams;
use wraptree::scene::Scene;
use wraptree::wrap::WrapperKind;
use wraptree::wrap::cover::solve::{CoverLimit, Tolerance};

/// Arguments of `wraptree record`.
#[derive(Args, Debug)]
pub struct RecordCmd {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    group: GroupArgs,
    #[command(flatten)]
    limits: BudgetArgs,
    /// Output prefix: writes PREFIX.rrd and PREFIX.mcap [default: recordings/<scene stem>];
    /// the prefix's directory must exist.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// What to write: levels, merges, or full.
    #[arg(long, value_enum, default_value_t = Detail::Full)]
    detail: Detail,
    /// Replace existing recordings.
    #[arg(long)]
    force: bool,
    /// Leave wall-clock timing out of the .mcap so identical runs give identical bytes.
    #[arg(long)]
    reproducible: bool,
    /// Wrapper Trees logged with the levels, comma-separated: sphere, hull, box (aabb), obb.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "sphere")]
    wrapper: Vec<WrapperKind>,
    /// Also log the cover within this error (as `cover --tolerance`: a length, or P% of the
    /// scene diagonal) as one more level.
    #[arg(long, value_parser = Tolerance::parse, allow_negative_numbers = true, conflicts_with = "cover_budget")]
    cover_tolerance: Option<Tolerance>,
    /// Also log the best cover with at most K wrappers as one more level.
    #[arg(long, value_name = "K")]
    cover_budget: Option<usize>,
    /// Wrapper kinds the cover chooses from, comma-separated: sphere, box (or aabb), obb, hull.
    #[arg(long, default_value = "sphere,box,hull", value_delimiter = ',', value_parser = WrapperKind::parse)]
    cover_kinds: Vec<WrapperKind>,
    /// Compress the .mcap's chunks: auto (lz4 below 500,000 primitives, none from there on),
    /// none (fastest to write and read), lz4, or zstd (smallest).
    #[arg(long, value_enum, default_value_t = Compression::Auto)]
    mcap_compression: Compression,
    /// Write every level to the .mcap (default: from the root down to the last level whose cut
    /// is less than half leaves; the .rrd always has every level).
    #[arg(long)]
    all_levels: bool,
    /// Refine the finished tree (treelet restructuring, then reinsertion, see docs/method.md)
    /// and record each step on the `refine` timeline / `/refine/step` topic; the levels are then
    /// the refined tree's.
    #[arg(long)]
    refine: bool,
    /// Most refinement passes (with --refine).
    #[arg(long, default_value_t = RefineParams::default().passes, requires = "refine")]
    refine_passes: u32,
    /// Fraction of the nodes searched in the first refinement pass, in (0, 1] (with --refine).
    #[arg(long, default_value_t = RefineParams::default().batch, requires = "refine")]
    refine_batch: f64,
    /// Most leaves of a restructured treelet, 3 to 7 (with --refine).
    #[arg(long, default_value_t = RefineParams::default().treelet, requires = "refine")]
    refine_treelet: u32,
    /// Treelet restructuring passes before the reinsertion passes (with --refine; 0 = none).
    #[arg(long, default_value_t = RefineParams::default().treelet_passes, requires = "refine")]
    refine_treelet_passes: u32,
}

/// Success for a finished grouping, else the stop's exit code (3 for a limit, 130 for
/// Ctrl-C/SIGTERM).
pub fn exit_code(w: &Written) -> ExitCode {
    match (&w.grouping, &w.stopped) {
        (Some(_), _) => ExitCode::SUCCESS,
        (None, Some(s)) => BudgetArgs::exit_code(s.reason),
        (None, None) => ExitCode::from(EXIT_INTERRUPTED),
    }
}

/// A flag set by the first Ctrl-C or SIGTERM (installed once per process).
pub fn stop_flag() -> Arc<AtomicBool> {
    static FLAG: std::sync::OnceLock<Arc<AtomicBool>> = std::sync::OnceLock::new();
    FLAG.get_or_init(|| {
        let f = Arc::new(AtomicBool::new(false));
        let g = f.clone();
        let _ = ctrlc::set_handler(move || g.store(true, Ordering::Relaxed));
        f
    })
    .clone()
}

/// Prints what was written: the run (or why it stopped, on stderr) and the files.
pub fn print_written(w: &Written, scene: &Scene) {
    match w.summary(scene) {
        Ok(line) => println!("{line}"),
        Err(why) => eprintln!("{why}"),
    }
    print!("{}", w.files());
}

impl RecordCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        // Installed before loading so an early Ctrl-C still ends in readable, incomplete files.
        let stop = stop_flag();
        let limits = self.limits.limits()?;
        let limit = CoverLimit::from_flags(self.cover_tolerance, self.cover_budget);
        let opts = RecordOptions {
            detail: self.detail,
            force: self.force,
            reproducible: self.reproducible,
            limits,
            stop: Some(stop),
            wrappers: self.wrapper,
            cover: limit.map(|l| (l, self.cover_kinds)),
            all_levels: self.all_levels,
            mcap_compression: self.mcap_compression,
            refine: self.refine.then_some(RefineParams {
                passes: self.refine_passes,
                batch: self.refine_batch,
                treelet: self.refine_treelet,
                treelet_passes: self.refine_treelet_passes,
            }),
        };
        opts.check()?;
        let loaded = self.scene.load()?;
        let params = self.group.params()?.resolve(&loaded.scene);
        let prefix = output_prefix(self.output.as_deref(), &loaded.source.file_name, "")?;
        let progress = Progress::for_merges(loaded.scene.len() as u64);
        let w = record(&loaded, &params, &prefix, &opts, progress)?;
        print_written(&w, &loaded.scene);
        Ok(exit_code(&w))
    }
}
