//! `wraptree compare`: recordings of one scene side by side in one `.rrd`
//! ([`wraptree::replay::compare`]).

use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use wraptree::replay::{self, Replay};
use wraptree::stop::Stop;

/// Arguments of `wraptree compare`.
#[derive(Args, Debug)]
pub struct CompareCmd {
    /// Two or more `.mcap` recordings of the same scene (`record`, `replay --a/--b/--c`); the
    /// first is the reference the others' divergence is measured from.
    #[arg(required = true, num_args = 2..)]
    files: Vec<PathBuf>,
    /// Output prefix: writes PREFIX.rrd and PREFIX.mcap [default: the first file's path
    /// without `.mcap`, plus `.compare`].
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Replace existing comparison files.
    #[arg(long)]
    force: bool,
}

impl CompareCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        let stop = Stop::on_signals();
        let status = super::progress::Status::new("compare", "reading");
        let replays = self
            .files
            .iter()
            .map(|f| {
                stop.check()?;
                status.set_message(format!("reading {}", f.display()));
                replay::open_until(f, &stop)
            })
            .collect::<Result<Vec<Replay>>>()?;
        let mut labels: Vec<String> = replays
            .iter()
            .map(|r| replay::run_label(&r.rec.params))
            .collect();
        // Runs with the same weights are told apart by their file names.
        for (label, file) in labels.iter_mut().zip(&self.files) {
            let stem = file.file_stem().unwrap_or_default().to_string_lossy();
            *label = format!("{stem}: {label}");
        }
        let prefix = self
            .output
            .clone()
            .unwrap_or_else(|| self.files[0].with_extension("compare"));
        let refs: Vec<&Replay> = replays.iter().collect();
        status.set_message("writing the comparison");
        let c = replay::compare(&refs, &labels, &prefix, self.force, &stop)?;
        drop(status);
        for (i, label) in c.labels.iter().enumerate() {
            println!("run {i}: {label}");
        }
        match c.divergence {
            Some(k) => println!("first divergence of run 1 from run 0: merge {k}"),
            None => println!("runs 0 and 1 make the same merges"),
        }
        for p in &c.paths {
            println!("  {}", p.display());
        }
        Ok(ExitCode::SUCCESS)
    }
}
