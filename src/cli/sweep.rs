//! `wraptree sweep`: the A/B/C × size-measure grid of the grouping phase's Cost on one scene, as a table,
//! `sweep.csv`, heat maps, one `.rrd` with every setting's series (`sweep.rrd`) and one with
//! the trees of the best distinct settings side by side (`compare.rrd`).

use anyhow::{Result, anyhow, bail};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use wraptree::grouping::{CostMeasure, Limits, PSet, Params};
use wraptree::metrics::report::{SweepRrd, setting_name, sweep_table, write_sweep};
use wraptree::metrics::sweep::{Setting, SweepRuns, grid, sweep, write_sweep_comparison};
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
    /// Timed repetitions per setting (the best is reported), repeated only while its runs took
    /// under 0.1 s in all.
    #[arg(long, default_value_t = 3)]
    repeat: u32,
    /// Largest wall time of one grouping run, in seconds: a setting whose run takes longer is
    /// left out and named under the table (the all-ties corner A = 0, B = C = 0 grows faster
    /// than linearly in the scene).
    #[arg(long, value_name = "S", default_value_t = 60.0)]
    max_seconds: f64,
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
        let limits = Limits {
            max_seconds: Some(self.max_seconds),
            max_pairs: None,
        };
        limits.check().map_err(anyhow::Error::msg)?;
        let runs = SweepRuns {
            repeat: self.repeat,
            seed: 1,
            limits,
        };
        let bar = super::progress::bar(settings.len() as u64, &scene.name);
        let stop = wraptree::stop::Stop::on_signals();
        let mut merges = Vec::with_capacity(settings.len());
        let swept = sweep(&scene, &settings, &base, &runs, &stop, |_, w, m| {
            stop.check()?;
            bar.set_message(setting_name(w));
            bar.inc(1);
            merges.push(m.to_vec());
            rrd.setting(w, m)
        })?;
        bar.finish_and_clear();
        let rows = swept.rows;
        print!("{}", sweep_table(&rows));
        for (w, why) in &swept.left_out {
            println!("left out {}: {why}", setting_name(w));
        }
        if rows.is_empty() {
            bail!(
                "every setting was left out (--max-seconds {})",
                self.max_seconds
            );
        }
        let mut written = write_sweep(&dir, &scene.name, &rows, self.force)?;
        written.push(rrd.finish(&rows)?);
        let names: Vec<String> = rows
            .iter()
            .map(|r| {
                setting_name(&Setting {
                    weights: r.weights,
                    cost: r.cost,
                })
            })
            .collect();
        let compare = dir.join("compare");
        let pair =
            write_sweep_comparison(&compare, &scene, &rows, &merges, &names, self.force, &stop)?;
        written.extend(pair.into_iter().flatten());
        for p in written {
            eprintln!("wrote {}", p.display());
        }
        Ok(ExitCode::SUCCESS)
    }
}
