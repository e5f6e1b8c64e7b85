//! `wraptree replay`: rebuild, verify or re-weight a run from its `.mcap` recording
//! ([`wraptree::replay`]).

use super::group::{BudgetArgs, Progress};
use super::progress::Status;
use super::record::{LiveArgs, after_run, exit_code, print_written, stop_flag};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use wraptree::output::output_prefix;
use wraptree::record::{Detail, RecordOptions};
use wraptree::replay::{self, Replay, report};
use wraptree::stop::Stop;

/// Arguments of `wraptree replay`.
#[derive(Args, Debug)]
pub struct ReplayCmd {
    /// A `.mcap` recording written by `wraptree record`.
    file: PathBuf,
    /// Re-run the grouping from the embedded scene and parameters and compare merge by merge.
    #[arg(long)]
    verify: bool,
    /// Re-run with this Cost exponent A (other parameters as recorded).
    #[arg(long)]
    a: Option<f64>,
    /// Re-run with this Fill weight B.
    #[arg(long)]
    b: Option<f64>,
    /// Re-run with this Balance weight C.
    #[arg(long)]
    c: Option<f64>,
    /// Output prefix for the re-weighted recordings [default: recordings/<stem>-a<A>-b<B>-c<C>];
    /// the prefix's directory must exist. Besides PREFIX.rrd and PREFIX.mcap, a finished run
    /// writes PREFIX.compare.rrd and PREFIX.compare.mcap: the recorded and the re-weighted run
    /// side by side.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// What the re-weighted recordings hold.
    #[arg(long, value_enum, default_value_t = Detail::Full)]
    detail: Detail,
    /// Replace existing recordings.
    #[arg(long)]
    force: bool,
    /// Limits on the re-run of --verify and --a/--b/--c.
    #[command(flatten)]
    limits: BudgetArgs,
    /// Live viewing of the re-weighted run (with --a/--b/--c).
    #[command(flatten)]
    live: LiveArgs,
}

impl ReplayCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        let limits = self.limits.limits()?;
        let reweights = self.a.is_some() || self.b.is_some() || self.c.is_some();
        if self.live.any() && !reweights {
            anyhow::bail!(
                "--connect, --serve, --spawn and --foxglove-ws stream a re-weighted run: give --a, \
                 --b or --c"
            );
        }
        let stop = Stop::on_signals();
        let status = Status::new("replay", "reading the recording");
        let replay = replay::open_until(&self.file, &stop)?;
        drop(status);
        let (rec, loaded) = (&replay.rec, &replay.loaded);
        let name = self.file.display().to_string();
        print!("{}", report::header(rec, &name));
        print!("{}", report::state(&replay, &name)?);
        if self.verify {
            let status = Status::new("replay --verify", "re-running the grouping");
            let v = report::verification(&replay, &limits, &stop)?;
            drop(status);
            let v = match v {
                Ok(v) => v,
                Err(s) => {
                    let msg = limits.message(&s, loaded.scene.len());
                    eprintln!("error: {name}: --verify re-run: {msg}");
                    return Ok(BudgetArgs::exit_code(s.reason));
                }
            };
            print!("{}", v.text);
            if let Some(e) = &v.error {
                eprintln!("error: {name}: --verify: {e}");
            }
            if !v.passed {
                return Ok(ExitCode::FAILURE);
            }
        }
        if reweights {
            return self.reweight(&replay, limits);
        }
        Ok(ExitCode::SUCCESS)
    }

    fn reweight(&self, replay: &Replay, limits: wraptree::grouping::Limits) -> Result<ExitCode> {
        let (rec, loaded) = (&replay.rec, &replay.loaded);
        let weights = replay::weights(rec, self.a, self.b, self.c)?;
        let suffix = format!("-a{}-b{}-c{}", weights.a, weights.b, weights.c);
        let prefix = output_prefix(self.output.as_deref(), &rec.scene_file_name, &suffix)?;
        let stop = stop_flag();
        let live = self.live.start(&stop)?;
        let opts = RecordOptions {
            detail: self.detail,
            force: self.force,
            limits,
            stop: Some(stop.clone()),
            refine: rec.refine.map(|r| r.params),
            live: live.clone(),
            ..RecordOptions::default()
        };
        let progress = Progress::for_merges(loaded.scene.len() as u64);
        let r = replay::reweight(replay, weights, &prefix, &opts, progress)?;
        let (Some(g), Some(log)) = (&r.written.grouping, &r.log) else {
            print_written(&r.written, &loaded.scene);
            after_run(&live, &stop);
            return Ok(exit_code(&r.written));
        };
        print!("{}", report::pairs_compared(&rec.merges, &log.merges));
        let old = replay.tree()?;
        print!("{}", report::reweight_table(rec, &old, g, &log.merges));
        print_written(&r.written, &loaded.scene);
        for path in r.comparison.iter().flatten() {
            println!("  {} (both runs side by side)", path.display());
        }
        after_run(&live, &stop);
        Ok(exit_code(&r.written))
    }
}
