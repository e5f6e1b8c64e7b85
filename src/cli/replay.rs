//! `wraptree replay`: rebuild, verify or re-weight a run from its `.mcap` recording
//! ([`wraptree::replay`]).

use super::group::{BudgetArgs, Progress};
use super::record::{exit_code, report, stop_flag};
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use wraptree::grouping::{Merge, Part};
use wraptree::record::mcap::metadata;
use wraptree::record::output::output_prefix;
use wraptree::record::{Detail, RecordOptions};
use wraptree::replay::{self, RefineVerified, Replay, Verified, balance_stats};

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
    /// the prefix's directory must exist.
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
}

/// A table row: field name and how to print it from a merge.
type Row<'a> = (&'a str, &'a dyn Fn(&Merge) -> String);

fn side_by_side(i: usize, left: (&str, Option<&Merge>), right: (&str, Option<&Merge>)) {
    println!("first divergence at merge step {i}:");
    println!("  {:<10} {:>24} {:>24}", "field", left.0, right.0);
    let f =
        |m: Option<&Merge>, g: &dyn Fn(&Merge) -> String| m.map(g).unwrap_or_else(|| "-".into());
    let rows: [Row; 10] = [
        ("round", &|m| m.round.to_string()),
        ("a", &|m| m.a.to_string()),
        ("b", &|m| m.b.to_string()),
        ("new", &|m| m.new.to_string()),
        ("diameter", &|m| format!("{:.9e}", m.diameter)),
        ("fill", &|m| format!("{:.9}", m.fill)),
        ("balance", &|m| format!("{:.9}", m.balance)),
        ("cost", &|m| format!("{:.9e}", m.cost)),
        ("queue_len", &|m| m.queue_len.to_string()),
        ("active", &|m| m.active.to_string()),
    ];
    for (name, g) in rows {
        println!("  {:<10} {:>24} {:>24}", name, f(left.1, g), f(right.1, g));
    }
}

impl ReplayCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        let limits = self.limits.limits()?;
        let replay = replay::open(&self.file)?;
        let (rec, loaded) = (&replay.rec, &replay.loaded);
        let name = self.file.display().to_string();
        let n = rec.primitives;
        let p = &rec.params;
        println!(
            "{name}: scene {} ({n} primitives), A={} B={} C={} DLimit0={:.6e} GLimit0={:.6e} pset={:?}",
            rec.scene_name, p.weights.a, p.weights.b, p.weights.c, p.dlimit0, p.glimit0, p.pset
        );
        if rec.complete {
            let t = replay::final_tree(&replay)
                .with_context(|| format!("{name}: the merge events do not form a tree"))?;
            if let Some(r) = &rec.refine {
                println!(
                    "refined ({} treelet passes of {} leaves, {} reinsertion passes at most, first batch {}): {} steps, SAH {:.6} -> {:.6}",
                    r.params.treelet_passes,
                    r.params.treelet,
                    r.params.passes,
                    r.params.batch,
                    r.steps,
                    r.sah_before,
                    r.sah_after
                );
            }
            println!(
                "replayed {} merges in {} rounds: root {}, depth max {} ({} levels), mean {:.2}",
                rec.merges.len(),
                rec.rounds,
                t.root(),
                t.depth_max(),
                t.depth_max() + 1,
                t.depth_mean()
            );
        } else {
            let why = metadata::stop_reason(&rec.metadata).unwrap_or("unknown");
            println!(
                "incomplete recording (stopped: {why}): {} of {} merges, {} rounds started; no tree",
                rec.merges.len(),
                n.saturating_sub(1),
                rec.rounds
            );
        }
        if self.verify {
            match replay::verify(&replay, &limits) {
                Err(s) => {
                    let msg = limits.message(&s, loaded.scene.len());
                    eprintln!("error: {name}: --verify re-run: {msg}");
                    return Ok(BudgetArgs::exit_code(s.reason));
                }
                Ok(Verified::Prefix { merges }) => println!(
                    "verified: the {merges} recorded merges match the re-run's first {merges} (the recording stopped there)"
                ),
                Ok(Verified::Identical {
                    merges,
                    queue_lengths_differ,
                }) => {
                    println!("verified: the merge sequence is identical ({merges} merges)");
                    if queue_lengths_differ {
                        println!(
                            "note: MPairs queue lengths differ (the queue's storage changed between versions)"
                        );
                    }
                }
                Ok(Verified::PartDiffers {
                    index,
                    recorded,
                    rerun,
                }) => {
                    let show = |p: Option<Part>| p.map_or("none".to_string(), |p| p.to_string());
                    eprintln!(
                        "error: {name}: --verify: part {index} differs: recorded {}, re-run {}",
                        show(recorded),
                        show(rerun)
                    );
                    return Ok(ExitCode::FAILURE);
                }
                Ok(Verified::Diverged { step, rerun }) => {
                    side_by_side(
                        step,
                        ("recorded", rec.merges.get(step)),
                        ("re-run", rerun.merges.get(step)),
                    );
                    return Ok(ExitCode::FAILURE);
                }
            }
            match replay::verify_refinement(&replay)? {
                None => {}
                Some(RefineVerified::Identical { moves }) => {
                    println!("verified: the refinement's moves are identical ({moves} moves)")
                }
                Some(RefineVerified::Diverged {
                    step,
                    recorded,
                    rerun,
                }) => {
                    println!("first refinement divergence at step {step}:");
                    println!("  recorded: {recorded:?}");
                    println!("  re-run:   {rerun:?}");
                    return Ok(ExitCode::FAILURE);
                }
            }
        }
        if self.a.is_some() || self.b.is_some() || self.c.is_some() {
            return self.reweight(&replay, limits);
        }
        Ok(ExitCode::SUCCESS)
    }

    fn reweight(&self, replay: &Replay, limits: wraptree::grouping::Limits) -> Result<ExitCode> {
        let (rec, loaded) = (&replay.rec, &replay.loaded);
        let weights = replay::weights(rec, self.a, self.b, self.c)?;
        let suffix = format!("-a{}-b{}-c{}", weights.a, weights.b, weights.c);
        let prefix = output_prefix(self.output.as_deref(), &rec.scene_file_name, &suffix)?;
        let opts = RecordOptions {
            detail: self.detail,
            force: self.force,
            limits,
            stop: Some(stop_flag()),
            refine: rec.refine.map(|r| r.params),
            ..RecordOptions::default()
        };
        let progress = Progress::for_merges(loaded.scene.len() as u64);
        let r = replay::reweight(replay, weights, &prefix, &opts, progress)?;
        let (Some(g), Some(log)) = (&r.written.grouping, &r.log) else {
            report(&r.written, &loaded.scene);
            return Ok(exit_code(&r.written));
        };
        let pairs = |m: &[Merge]| m.iter().map(|x| (x.a, x.b)).collect::<Vec<_>>();
        let (old_pairs, new_pairs) = (pairs(&rec.merges), pairs(&log.merges));
        match (0..old_pairs.len().max(new_pairs.len()))
            .find(|&i| old_pairs.get(i) != new_pairs.get(i))
        {
            None => println!(
                "the same pairs merge in the same order ({} merges); only costs differ",
                log.merges.len()
            ),
            Some(i) => side_by_side(
                i,
                ("recorded", rec.merges.get(i)),
                ("re-weighted", log.merges.get(i)),
            ),
        }
        let old = replay.tree()?;
        let (ob, obmax) = balance_stats(&rec.merges);
        let (nb, nbmax) = balance_stats(&log.merges);
        println!("  {:<22} {:>12} {:>12}", "", "recorded", "re-weighted");
        println!(
            "  {:<22} {:>12} {:>12}",
            "depth max",
            old.depth_max(),
            g.tree.depth_max()
        );
        println!(
            "  {:<22} {:>12.3} {:>12.3}",
            "depth mean",
            old.depth_mean(),
            g.tree.depth_mean()
        );
        println!("  {:<22} {:>12.3} {:>12.3}", "Balance mean", ob, nb);
        println!("  {:<22} {:>12.3} {:>12.3}", "Balance max", obmax, nbmax);
        println!("  {:<22} {:>12} {:>12}", "rounds", rec.rounds, g.rounds);
        report(&r.written, &loaded.scene);
        Ok(exit_code(&r.written))
    }
}
