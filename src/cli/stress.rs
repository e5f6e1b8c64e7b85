//! `wraptree stress`: every builder on pathological scenes under a time budget
//! ([`wraptree::metrics::stress`]).

use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;
use wraptree::metrics::report::stress_table;
use wraptree::metrics::stress::{self, Step, StressOptions, check_outputs};
use wraptree::output::output_dir;
use wraptree::stop::Stop;

/// Arguments of `wraptree stress`.
#[derive(Args, Debug)]
pub struct StressCmd {
    /// Output directory for stress.csv, spaghetti{,-n}.{svg,png}, created with its parents if
    /// missing [default: recordings/stress].
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Small scenes (300 primitives, 10 n-gons) and three aspect ratios: seconds, not minutes.
    #[arg(long)]
    quick: bool,
    /// Time budget per case, in seconds: a case over it is stopped (groupings) or given up
    /// within 1 s more, so a run of at most 226 cases (216 with --quick) ends within
    /// 226 × (budget + 1 s).
    #[arg(long, default_value_t = 5.0)]
    budget: f64,
    /// Aspect limit R of the split runs (`--split-aspect R`).
    #[arg(long, default_value_t = 8.0)]
    split: f64,
    /// Replace existing output files.
    #[arg(long)]
    force: bool,
}

impl StressCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        if !(self.budget.is_finite() && self.budget > 0.0) {
            anyhow::bail!("--budget must be a finite number > 0, got {}", self.budget);
        }
        if self.split.is_nan() || self.split < wraptree::scene::split::MIN_ASPECT_LIMIT {
            anyhow::bail!("--split must be a number ≥ 2, got {}", self.split);
        }
        let dir = output_dir(self.output.as_deref(), "recordings/stress")?;
        check_outputs(&dir, self.force)?;
        let opts = StressOptions {
            quick: self.quick,
            budget: Duration::from_secs_f64(self.budget),
            split: self.split,
        };
        let stop = Stop::on_signals();
        let report = stress::run(&opts, &stop, &mut |step| match step {
            Step::Scene(s) => eprintln!("stress: {} ({} primitives)", s.name, s.len()),
            Step::Sweep(s) => eprintln!("stress: sweep {} ({} primitives)", s.name, s.len()),
        })?;
        print!("{}", stress_table(&report.rows));
        report.write(&dir, self.force)?;
        eprintln!(
            "wrote {}/stress.csv, spaghetti.{{svg,png}} and spaghetti-n.{{svg,png}}",
            dir.display()
        );
        Ok(ExitCode::SUCCESS)
    }
}
