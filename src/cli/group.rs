//! `wraptree group`: run the grouping phase and summarise the Subset Tree.

use super::{GroupArgs, SceneArgs};
use anyhow::Result;
use clap::Args;
use std::process::ExitCode;
use std::time::Instant;
use wraptree::grouping::{self, Event, Limits, Observer, StopReason};
use wraptree::metrics::report::{group_json, group_text};
use wraptree::stop::Stop;

/// Exit code of a run stopped by `--max-seconds` or `--max-pairs`.
pub const EXIT_BUDGET: u8 = 3;
pub use super::progress::EXIT_INTERRUPTED;

/// Limits on the grouping phase, for runs that could run away (huge `--glimit`, dense soups).
#[derive(Args, Debug, Clone, Copy, Default)]
pub struct BudgetArgs {
    /// Stop the grouping after S seconds of wall time (loading not counted); exit code 3.
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub max_seconds: Option<f64>,
    /// Stop the grouping once the round-start scans (step 3) have found more than P eligible
    /// pairs, summed over rounds; exit code 3.
    #[arg(long, value_name = "P")]
    pub max_pairs: Option<u64>,
}

impl BudgetArgs {
    /// Checks the values and turns them into [`Limits`].
    pub fn limits(&self) -> Result<Limits> {
        let limits = Limits {
            max_seconds: self.max_seconds,
            max_pairs: self.max_pairs,
        };
        limits.check().map_err(anyhow::Error::msg)?;
        Ok(limits)
    }

    /// The exit code of a run stopped for `reason`.
    pub fn exit_code(reason: StopReason) -> ExitCode {
        match reason {
            StopReason::Interrupted => ExitCode::from(EXIT_INTERRUPTED),
            StopReason::MaxSeconds | StopReason::MaxPairs => ExitCode::from(EXIT_BUDGET),
        }
    }
}

/// Arguments of `wraptree group`.
#[derive(Args, Debug)]
pub struct GroupCmd {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    pub(super) group: GroupArgs,
    #[command(flatten)]
    limits: BudgetArgs,
    /// Print one JSON object (with the parent array) instead of text.
    #[arg(long)]
    json: bool,
}

/// A progress bar over merges on stderr, shown only when stderr is a terminal.
pub struct Progress(indicatif::ProgressBar);

impl Progress {
    /// A bar for `merges` merges, or `None` when stderr is not a terminal or the run is short.
    pub fn for_merges(merges: u64) -> Option<Progress> {
        use std::io::IsTerminal;
        if !std::io::stderr().is_terminal() || merges < 100_000 {
            return None;
        }
        let bar = indicatif::ProgressBar::new(merges);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} grouping {bar:40} {pos}/{len} merges {msg} ({eta})",
            )
            .expect("the template is valid"),
        );
        Some(Progress(bar))
    }
}

impl Observer for Progress {
    fn on_event(&mut self, event: &Event<'_>) {
        match event {
            Event::Merge(m) if m.step % 1024 == 0 => self.0.set_position(m.step as u64),
            Event::RoundStart { round, .. } => self.0.set_message(format!("round {round}")),
            Event::Finish { .. } => self.0.finish_and_clear(),
            _ => {}
        }
    }
}

impl GroupCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        let loaded = self.scene.load()?;
        let params = self.group.params()?;
        let threads = self.group.threads()?;
        let limits = self.limits.limits()?;
        let scene = &loaded.scene;
        let start = Instant::now();
        let resolved = params.resolve(scene);
        let progress = Progress::for_merges(scene.len() as u64);
        let stop = Stop::on_signals();
        let budget = limits.budget(Some(stop.flag()));
        let g = match grouping::group_within(scene, &resolved, progress, &budget) {
            Ok(g) => g,
            Err(s) => {
                let file = self.scene.scene.display();
                eprintln!("error: {file}: {}", limits.message(&s, scene.len()));
                return Ok(BudgetArgs::exit_code(s.reason));
            }
        };
        let seconds = start.elapsed().as_secs_f64();
        if self.json {
            println!("{}", group_json(scene, &g, threads, seconds));
        } else {
            print!("{}", group_text(scene, &g, threads, seconds));
        }
        Ok(ExitCode::SUCCESS)
    }
}
