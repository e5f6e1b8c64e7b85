//! `wraptree sweep`: the A/B/C × size-measure grid of the grouping phase's Cost on one scene, as a table,
//! `sweep.csv`, heat maps, one `.rrd` with every setting's series (`sweep.rrd`) and one with
//! the trees of the best distinct settings side by side (`compare.rrd`).

use anyhow::{Result, anyhow};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use wraptree::grouping::{CostMeasure, PSet, Params};
use wraptree::metrics::report::{SweepRrd, setting_name, sweep_table, write_sweep};
use wraptree::metrics::sweep::{grid, sweep, write_sweep_comparison};
use wraptree::output::output_dir;

/// Arguments of `wraptree sweep`.
#[derive(Args, Debug)]
pub struct SweepCmd {
    /// OBJ file, or a generated scene as KIND[:COUNT] (see `bench`).
    scene: String,
    /// Values of the diameter exponent A (comma list).
    #[arg(long, value_delimiter = ',', default_values_t = [0.0, 1.0, 2.0], allow_negative_numbers = true)]
    a: Vec<f64>,
    /// Values of the Fill weight B (comma list).
    #[arg(long, value_delimiter = ',', default_values_t = [0.0, 1.0], allow_negative_numbers = true)]
    b: Vec<f64>,
    /// Values of the Balance weight C (comma list).
    #[arg(long, value_delimiter = ',', default_values_t = [0.0, 1.0], allow_negative_numbers = true)]
    c: Vec<f64>,
    /// Size measures in the Cost (comma list): diameter (the paper's), area (surface area of
    /// the merged box).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [CostMeasure::Diameter, CostMeasure::Area])]
    cost: Vec<CostMeasure>,
    /// P-set wrapper for every setting.
    #[arg(long, value_enum, default_value_t = PSet::Aabb)]
    pset: PSet,
    /// Output directory, created with its parents if missing [default:
    /// recordings/sweep-<scene>].
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Replace existing result files.
    #[arg(long)]
    force: bool,
    /// Timed repetitions per setting (the best is reported).
    #[arg(long, default_value_t = 3)]
    repeat: u32,
}

impl SweepCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        let scene = super::bench::load_spec(&self.scene)?;
        let settings = grid(&self.a, &self.b, &self.c, &self.cost);
        for s in &settings {
            s.weights.check().map_err(|e| anyhow!("--{e}"))?;
        }
        let default = format!("recordings/sweep-{}", scene.name);
        let dir = output_dir(self.output.as_deref(), &default)?;
        let rrd = SweepRrd::create(&dir.join("sweep.rrd"), &settings, self.force)?;
        let base = Params {
            pset: self.pset,
            ..Params::default()
        };
        let bar = super::progress::bar(settings.len() as u64, &scene.name);
        let stop = wraptree::stop::Stop::on_signals();
        let mut runs = Vec::with_capacity(settings.len());
        let rows = sweep(&scene, &settings, &base, self.repeat, 1, |_, w, merges| {
            stop.check()?;
            bar.set_message(setting_name(w));
            bar.inc(1);
            runs.push(merges.to_vec());
            rrd.setting(w, merges)
        })?;
        bar.finish_and_clear();
        print!("{}", sweep_table(&rows));
        let mut written = write_sweep(&dir, &scene.name, &rows, self.force)?;
        written.push(rrd.finish(&rows)?);
        let names: Vec<String> = settings.iter().map(setting_name).collect();
        let compare = dir.join("compare");
        let pair = write_sweep_comparison(&compare, &scene, &rows, &runs, &names, self.force)?;
        written.extend(pair.into_iter().flatten());
        for p in written {
            eprintln!("wrote {}", p.display());
        }
        Ok(ExitCode::SUCCESS)
    }
}
