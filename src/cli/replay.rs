//! `wraptree replay`: rebuild, verify or re-weight a run from its `.mcap` recording.

use super::group::BudgetArgs;
use super::record::{Logged, Options, exit_code, output_prefix, record_with, report};
use anyhow::{Context, Result, bail};
use clap::Args;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use wraptree::grouping::{
    Event, EventLog, Merge, Observer, ResolvedParams, Stopped, SubsetTree, Weights, group_within,
};
use wraptree::record::Detail;
use wraptree::record::mcap::{Recorded, metadata, read_recording};
use wraptree::scene::{Loaded, load_bytes};
use wraptree::wrap::WrapperKind;

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
    /// Limits on the re-run of --verify and --a/--b/--c.
    #[command(flatten)]
    limits: BudgetArgs,
}

/// The magic bytes that open every Rerun `.rrd` stream, and the 8 bytes before the entry count
/// that close a finished one (`RRF2FOOT`).
const RRD_MAGIC: &[u8; 4] = b"RRF2";
const RRD_FOOTER: &[u8; 8] = b"RRF2FOOT";
/// The magic bytes that open an MCAP file.
const MCAP_MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

/// Why `path` cannot be what `replay` reads, when its first and last bytes say so: a Rerun
/// `.rrd` file (finished, truncated or with a bad magic) or an empty file. `None` for anything
/// else, which the MCAP reader then judges.
pub fn not_an_mcap(path: &Path) -> Option<String> {
    use std::io::{Read, Seek, SeekFrom};
    let mut f = std::fs::File::open(path).ok()?;
    let len = f.metadata().ok()?.len();
    let name = path.display();
    if len == 0 {
        return Some(format!("{name}: empty file (not a recording)"));
    }
    let mut head = [0u8; 8];
    let n = f.read(&mut head).ok()?;
    let head = &head[..n];
    let is_rrd = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("rrd"));
    let mcap = path.with_extension("mcap");
    let hint = if mcap != path && mcap.is_file() {
        format!("replay reads the .mcap beside it ({})", mcap.display())
    } else {
        "replay reads the .mcap that `record` writes beside the .rrd".to_string()
    };
    if head.starts_with(RRD_MAGIC) {
        let mut tail = [0u8; 12];
        let finished = len >= 24
            && f.seek(SeekFrom::End(-12)).is_ok()
            && f.read_exact(&mut tail).is_ok()
            && tail.starts_with(RRD_FOOTER);
        let what = if finished {
            "a Rerun .rrd recording"
        } else {
            "a truncated Rerun .rrd recording (no footer)"
        };
        return Some(format!("{name}: {what}, not an MCAP file; {hint}"));
    }
    if is_rrd && !head.starts_with(MCAP_MAGIC) {
        return Some(format!(
            "{name}: not a Rerun recording (bad magic, expected RRF2) nor an MCAP file"
        ));
    }
    None
}

/// An observer that keeps the event log and sets `stop` once `limit` merges are made, so a
/// re-run of an incomplete recording ends where the recording did.
struct UpTo<'a> {
    log: EventLog,
    limit: Option<usize>,
    stop: &'a AtomicBool,
}

impl Observer for UpTo<'_> {
    fn on_event(&mut self, event: &Event<'_>) {
        self.log.on_event(event);
        if self.limit.is_some_and(|k| self.log.merges.len() >= k) {
            self.stop.store(true, Ordering::Relaxed);
        }
    }
}

/// The Subset Tree rebuilt from the recorded merges alone (leaf boxes from the embedded scene).
fn tree_of(rec: &Recorded, loaded: &Loaded) -> Result<SubsetTree> {
    rec.tree(&loaded.scene).map_err(anyhow::Error::msg)
}

/// Re-runs the grouping within `limits`, up to `merges` merges when given (the length of an
/// incomplete recording). Err: the stop, when a limit of `limits` ended the re-run first.
fn rerun(
    loaded: &Loaded,
    params: &ResolvedParams,
    limits: &BudgetArgs,
    merges: Option<usize>,
) -> Result<EventLog, Stopped> {
    let stop = AtomicBool::new(merges == Some(0));
    let mut obs = UpTo {
        log: EventLog::default(),
        limit: merges,
        stop: &stop,
    };
    let budget = limits.budget(Some(&stop));
    match group_within(&loaded.scene, params, &mut obs, &budget) {
        Ok(_) => Ok(obs.log),
        // Our own flag, set at the recorded length: the re-run went as far as the recording.
        Err(s) if s.reason == wraptree::grouping::StopReason::Interrupted => Ok(obs.log),
        Err(s) => Err(s),
    }
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
        self.limits.check()?;
        if let Some(why) = not_an_mcap(&self.file) {
            bail!("{why}");
        }
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
            let why = metadata::stop_reason(&rec.metadata).unwrap_or("unknown");
            println!(
                "incomplete recording (stopped: {why}): {} of {} merges, {} rounds started; no tree",
                rec.merges.len(),
                n.saturating_sub(1),
                rec.rounds
            );
        }
        if self.verify {
            let upto = (!rec.complete).then_some(rec.merges.len());
            let log = match rerun(&loaded, &rec.params, &self.limits, upto) {
                Ok(log) => log,
                Err(s) => {
                    let msg = self.limits.message(&s, loaded.scene.len());
                    eprintln!("error: {name}: --verify re-run: {msg}");
                    return Ok(BudgetArgs::exit_code(s.reason));
                }
            };
            match first_divergence(&rec.merges, &log.merges) {
                None if !rec.complete => println!(
                    "verified: the {0} recorded merges match the re-run's first {0} (the recording stopped there)",
                    rec.merges.len()
                ),
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
        let kinds = [WrapperKind::Sphere];
        let logged = Logged {
            kinds: &kinds,
            cover: None,
        };
        let written = record_with(
            &loaded.scene,
            &loaded.source,
            &params,
            self.detail,
            &prefix,
            Options {
                force: self.force,
                reproducible: false,
                all_levels: false,
                limits: self.limits,
            },
            logged,
        )?;
        let Some(g) = &written.grouping else {
            report(&written, &loaded.scene);
            return Ok(exit_code(&written));
        };
        // The same run again for its events: it finished within the limits just now.
        let log = rerun(loaded, &params, &BudgetArgs::default(), None)
            .expect("an unlimited re-run is never stopped");
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
