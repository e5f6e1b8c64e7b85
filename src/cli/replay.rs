//! `wraptree replay`: rebuild, verify or re-weight a run from its `.mcap` recording.

use super::record::{output_prefix, record, report};
use anyhow::{Context, Result, bail};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use wraptree::geom::Aabb;
use wraptree::grouping::{EventLog, Merge, ResolvedParams, SubsetTree, Weights, group_until};
use wraptree::record::Detail;
use wraptree::record::mcap::{Recorded, read_recording};
use wraptree::scene::{Loaded, load_bytes};

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
    /// Output prefix for the re-weighted recordings [default: recordings/<stem>-a<A>-b<B>-c<C>].
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// What the re-weighted recordings hold.
    #[arg(long, value_enum, default_value_t = Detail::Full)]
    detail: Detail,
    /// Replace existing recordings.
    #[arg(long)]
    force: bool,
}

/// The Subset Tree rebuilt from the recorded merges alone (leaf boxes from the embedded scene).
fn tree_of(rec: &Recorded, loaded: &Loaded) -> Result<SubsetTree> {
    let s = &loaded.scene;
    let boxes: Vec<Aabb> = (0..s.len()).map(|i| s.prim_aabb(i)).collect();
    let diam = boxes.iter().map(Aabb::diameter).collect();
    let merges: Vec<_> = rec
        .merges
        .iter()
        .map(|m| (m.a, m.b, m.aabb, m.diameter))
        .collect();
    SubsetTree::from_merges(boxes, diam, &merges).map_err(anyhow::Error::msg)
}

fn rerun(loaded: &Loaded, params: &ResolvedParams) -> EventLog {
    let mut log = EventLog::default();
    let never = AtomicBool::new(false);
    group_until(&loaded.scene, params, &mut log, &never).expect("the stop flag is never set");
    log
}

/// A merge without `queue_len`, which depends on how MPairs stores pairs (it changed between
/// versions), not on which pair merges.
fn decision(m: &Merge) -> Merge {
    Merge { queue_len: 0, ..*m }
}

/// Index of the first merge where two timelines make a different decision, if any.
fn first_divergence(a: &[Merge], b: &[Merge]) -> Option<usize> {
    (0..a.len().max(b.len())).find(|&i| a.get(i).map(decision) != b.get(i).map(decision))
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

/// Mean and largest Balance over a run's merges.
fn balance_stats(m: &[Merge]) -> (f64, f64) {
    let mean = m.iter().map(|x| x.balance).sum::<f64>() / m.len().max(1) as f64;
    (mean, m.iter().map(|x| x.balance).fold(1.0, f64::max))
}

impl ReplayCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        let rec = read_recording(&self.file)?;
        let name = self.file.display().to_string();
        let loaded = load_bytes(
            &rec.scene_file_name,
            rec.scene_bytes.clone(),
            &rec.load_options,
        )
        .with_context(|| format!("{name}: the embedded scene does not load"))?;
        if loaded.scene.len() as u32 != rec.primitives {
            bail!(
                "{name}: the embedded scene has {} primitives, the metadata says {}",
                loaded.scene.len(),
                rec.primitives
            );
        }
        let n = rec.primitives;
        let p = &rec.params;
        println!(
            "{name}: scene {} ({n} primitives), A={} B={} C={} DLimit0={:.6e} GLimit0={:.6e} pset={:?}",
            rec.scene_name, p.weights.a, p.weights.b, p.weights.c, p.dlimit0, p.glimit0, p.pset
        );
        if rec.complete {
            let t = tree_of(&rec, &loaded)
                .with_context(|| format!("{name}: the merge events do not form a tree"))?;
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
            println!(
                "incomplete recording: {} of {} merges, {} rounds started",
                rec.merges.len(),
                n.saturating_sub(1),
                rec.rounds
            );
        }
        if self.verify {
            let log = rerun(&loaded, &rec.params);
            match first_divergence(&rec.merges, &log.merges) {
                None => {
                    println!(
                        "verified: the merge sequence is identical ({} merges)",
                        log.merges.len()
                    );
                    if rec
                        .merges
                        .iter()
                        .zip(&log.merges)
                        .any(|(r, l)| r.queue_len != l.queue_len)
                    {
                        println!(
                            "note: MPairs queue lengths differ (the queue's storage changed between versions)"
                        );
                    }
                }
                Some(i) if !rec.complete && i == rec.merges.len() => println!(
                    "verified: the {} recorded merges match the re-run's first {} (the recording stopped there)",
                    i, i
                ),
                Some(i) => {
                    side_by_side(
                        i,
                        ("recorded", rec.merges.get(i)),
                        ("re-run", log.merges.get(i)),
                    );
                    return Ok(ExitCode::FAILURE);
                }
            }
        }
        if self.a.is_some() || self.b.is_some() || self.c.is_some() {
            return self.reweight(&rec, &loaded);
        }
        Ok(ExitCode::SUCCESS)
    }

    fn reweight(&self, rec: &Recorded, loaded: &Loaded) -> Result<ExitCode> {
        let w = rec.params.weights;
        let weights = Weights {
            a: self.a.unwrap_or(w.a),
            b: self.b.unwrap_or(w.b),
            c: self.c.unwrap_or(w.c),
        };
        weights.check().map_err(|e| anyhow::anyhow!("--{e}"))?;
        let params = ResolvedParams {
            weights,
            ..rec.params
        };
        let suffix = format!("-a{}-b{}-c{}", weights.a, weights.b, weights.c);
        let prefix = output_prefix(self.output.as_deref(), &rec.scene_file_name, &suffix)?;
        let written = record(
            &loaded.scene,
            &loaded.source,
            &params,
            self.detail,
            &prefix,
            self.force,
            false,
        )?;
        let Some(g) = &written.grouping else {
            report(&written, &loaded.scene);
            return Ok(ExitCode::from(130));
        };
        let log = rerun(loaded, &params);
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
        let old = tree_of(rec, loaded)?;
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
        report(&written, &loaded.scene);
        Ok(ExitCode::SUCCESS)
    }
}
