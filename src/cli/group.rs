//! `wraptree group`: run the grouping phase and summarise the Subset Tree.

use super::{GroupArgs, SceneArgs};
use anyhow::Result;
use clap::Args;
use std::process::ExitCode;
use std::time::Instant;
use wraptree::grouping::{self, Event, Limits, Observer, StopReason};

/// Exit code of a run stopped by `--max-seconds` or `--max-pairs`.
pub const EXIT_BUDGET: u8 = 3;
/// Exit code of a run stopped by Ctrl-C or SIGTERM (128 + SIGINT, as shells report it).
pub const EXIT_INTERRUPTED: u8 = 130;

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
    group: GroupArgs,
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
        let g = if limits.is_none() {
            match Progress::for_merges(scene.len() as u64) {
                Some(p) => grouping::group(scene, &params, p),
                None => grouping::group(scene, &params, ()),
            }
        } else {
            let resolved = params.resolve(scene);
            let budget = limits.budget(None);
            let run = match Progress::for_merges(scene.len() as u64) {
                Some(p) => grouping::group_within(scene, &resolved, p, &budget),
                None => grouping::group_within(scene, &resolved, (), &budget),
            };
            match run {
                Ok(g) => g,
                Err(s) => {
                    let file = self.scene.scene.display();
                    eprintln!("error: {file}: {}", limits.message(&s, scene.len()));
                    return Ok(BudgetArgs::exit_code(s.reason));
                }
            }
        };
        let seconds = start.elapsed().as_secs_f64();
        let t = &g.tree;
        if self.json {
            let out = serde_json::json!({
                "scene": scene.name,
                "primitives": scene.len(),
                "rounds": g.rounds,
                "depth_max": t.depth_max(),
                "depth_mean": t.depth_mean(),
                "seconds": seconds,
                "threads": threads,
                "params": g.params,
                "stats": g.stats,
                "pregrouping": g.pregrouping,
                "peak_rss_bytes": wraptree::metrics::peak_rss_bytes(),
                "parent": t.parent_i64(),
            });
            println!("{out}");
        } else {
            println!("scene       {} ({} primitives)", scene.name, scene.len());
            println!(
                "params      A={} B={} C={} DLimit0={:.6e} GLimit0={:.6e} pset={:?}",
                g.params.weights.a,
                g.params.weights.b,
                g.params.weights.c,
                g.params.dlimit0,
                g.params.glimit0,
                g.params.pset
            );
            println!(
                "schedule    {:?} on {threads} thread{}",
                g.params.mode.schedule,
                if threads == 1 { "" } else { "s" }
            );
            if let Some(p) = &g.pregrouping {
                println!("{}", pregrouping_lines(p));
            }
            println!("rounds      {}", g.rounds);
            println!(
                "depth       max {} ({} levels), mean {:.2}, 2·log2 N = {:.1}",
                t.depth_max(),
                t.depth_max() + 1,
                t.depth_mean(),
                2.0 * (scene.len() as f64).log2()
            );
            println!("time        {:.3} ms", seconds * 1e3);
        }
        Ok(ExitCode::SUCCESS)
    }
}

/// What pre-grouping found, as the lines `wraptree group` prints.
fn pregrouping_lines(p: &grouping::Pregrouping) -> String {
    let kind = match p.pregroup {
        grouping::Pregroup::None => "none",
        grouping::Pregroup::Objects => "objects",
        grouping::Pregroup::Connected => "connected",
    };
    let mut out = format!(
        "pregroup    {kind}: {} components, {} grouped on their own (>= {} primitives), {} \
         primitives of smaller ones and {} part roots at the top level ({} bodies), {} threads",
        p.components,
        p.parts - p.copies,
        grouping::pregroup::MIN_PART,
        p.loose,
        p.parts,
        p.top_bodies,
        p.threads
    );
    if p.instancing {
        out.push_str(&format!(
            "\ninstancing  {} classes with copies, {} copies, {} primitives not grouped",
            p.classes, p.copies, p.primitives_saved
        ));
    }
    out
}
