//! What `wraptree replay` prints: the recording's run, the outcome of [`verify`]
//! and [`verify_refinement`], and a re-weighted run beside the
//! recorded one.

use super::{
    RefineVerified, Replay, Verified, balance_stats, final_tree, verify, verify_refinement,
};
use crate::grouping::{Grouping, Limits, Merge, Part, Stopped, SubsetTree};
use crate::record::mcap::{Recorded, metadata};
use anyhow::{Context, Result};
use std::fmt::Write as _;

/// The first line: the recording `name`, its scene and parameters.
pub fn header(rec: &Recorded, name: &str) -> String {
    let p = &rec.params;
    format!(
        "{name}: scene {} ({} primitives), A={} B={} C={} DLimit0={:.6e} GLimit0={:.6e} pset={:?}\n",
        rec.scene_name,
        rec.primitives,
        p.weights.a,
        p.weights.b,
        p.weights.c,
        p.dlimit0,
        p.glimit0,
        p.pset
    )
}

/// What the recording holds: the refinement and the replayed tree of a complete recording
/// (rebuilt with [`final_tree`]), or why an incomplete one stopped. Err: merges that do not
/// form a tree.
pub fn state(replay: &Replay, name: &str) -> Result<String> {
    let rec = &replay.rec;
    let mut s = String::new();
    if !rec.complete {
        let why = metadata::stop_reason(&rec.metadata).unwrap_or("unknown");
        let _ = writeln!(
            s,
            "incomplete recording (stopped: {why}): {} of {} merges, {} rounds started; no tree",
            rec.merges.len(),
            rec.primitives.saturating_sub(1),
            rec.rounds
        );
        return Ok(s);
    }
    let t = final_tree(replay)
        .with_context(|| format!("{name}: the merge events do not form a tree"))?;
    if let Some(r) = &rec.refine {
        let _ = writeln!(
            s,
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
    let _ = writeln!(
        s,
        "replayed {} merges in {} rounds: root {}, depth max {} ({} levels), mean {:.2}",
        rec.merges.len(),
        rec.rounds,
        t.root(),
        t.depth_max(),
        t.depth_max() + 1,
        t.depth_mean()
    );
    Ok(s)
}

/// A table row: field name and how to print it from a merge.
type Row<'a> = (&'a str, &'a dyn Fn(&Merge) -> String);

/// Two runs' merges at step `i` side by side, each column headed by its label (`-` where a
/// run has no merge `i`).
pub fn divergence_table(
    i: usize,
    left: (&str, Option<&Merge>),
    right: (&str, Option<&Merge>),
) -> String {
    let mut s = format!("first divergence at merge step {i}:\n");
    let _ = writeln!(s, "  {:<10} {:>24} {:>24}", "field", left.0, right.0);
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
        let _ = writeln!(
            s,
            "  {:<10} {:>24} {:>24}",
            name,
            f(left.1, g),
            f(right.1, g)
        );
    }
    s
}

/// What [`verify`] found, as `replay --verify` reports it: for
/// [`Verified::PartDiffers`] one line without its end (an error message), for
/// [`Verified::Diverged`] the [`divergence_table`] against the recording `rec`, else the
/// lines printed on success.
pub fn verified_text(v: &Verified, rec: &Recorded) -> String {
    match v {
        Verified::Prefix { merges } => format!(
            "verified: the {merges} recorded merges match the re-run's first {merges} (the recording stopped there)\n"
        ),
        Verified::Identical {
            merges,
            queue_lengths_differ,
        } => {
            let mut s = format!("verified: the merge sequence is identical ({merges} merges)\n");
            if *queue_lengths_differ {
                s.push_str(
                    "note: MPairs queue lengths differ (the queue's storage changed between versions)\n",
                );
            }
            s
        }
        Verified::PartDiffers {
            index,
            recorded,
            rerun,
        } => {
            let show = |p: &Option<Part>| p.map_or("none".to_string(), |p| p.to_string());
            format!(
                "part {index} differs: recorded {}, re-run {}",
                show(recorded),
                show(rerun)
            )
        }
        Verified::Diverged { step, rerun } => divergence_table(
            *step,
            ("recorded", rec.merges.get(*step)),
            ("re-run", rerun.merges.get(*step)),
        ),
    }
}

/// What [`verify_refinement`] found, as `replay --verify` prints it.
pub fn refine_verified_text(v: &RefineVerified) -> String {
    match v {
        RefineVerified::Identical { moves } => {
            format!("verified: the refinement's moves are identical ({moves} moves)\n")
        }
        RefineVerified::Diverged {
            step,
            recorded,
            rerun,
        } => format!(
            "first refinement divergence at step {step}:\n  recorded: {recorded:?}\n  re-run:   {rerun:?}\n"
        ),
    }
}

/// What `replay --verify` found, worded as it prints it.
#[derive(Clone, Debug, PartialEq)]
pub struct Verification {
    /// Lines for standard output.
    pub text: String,
    /// The one line, without its end, saying which part differs, when that failed the
    /// verification (for standard error).
    pub error: Option<String>,
    /// Whether the merges and, for a refined recording, the refinement's moves match.
    pub passed: bool,
}

/// Runs [`verify`] within `limits` and, when the merges match, [`verify_refinement`], and
/// words what they found ([`verified_text`], [`refine_verified_text`]). Inner Err: the stop,
/// when a limit or `stop` ended the re-run first.
pub fn verification(
    replay: &Replay,
    limits: &Limits,
    stop: &crate::stop::Stop,
) -> Result<Result<Verification, Stopped>> {
    let v = match verify(replay, limits, stop) {
        Ok(v) => v,
        Err(s) => return Ok(Err(s)),
    };
    let text = verified_text(&v, &replay.rec);
    let out = match v {
        Verified::PartDiffers { .. } => Verification {
            text: String::new(),
            error: Some(text),
            passed: false,
        },
        Verified::Diverged { .. } => Verification {
            text,
            error: None,
            passed: false,
        },
        _ => {
            let refined = verify_refinement(replay)?;
            Verification {
                text: text + &refined.as_ref().map_or(String::new(), refine_verified_text),
                error: None,
                passed: !matches!(refined, Some(RefineVerified::Diverged { .. })),
            }
        }
    };
    Ok(Ok(out))
}

/// Whether a re-weighted run's merges pair the same bodies in the same order as the recorded
/// ones, else the [`divergence_table`] at the first pair that differs.
pub fn pairs_compared(recorded: &[Merge], reweighted: &[Merge]) -> String {
    let pairs = |m: &[Merge]| m.iter().map(|x| (x.a, x.b)).collect::<Vec<_>>();
    let (old_pairs, new_pairs) = (pairs(recorded), pairs(reweighted));
    match (0..old_pairs.len().max(new_pairs.len())).find(|&i| old_pairs.get(i) != new_pairs.get(i))
    {
        None => format!(
            "the same pairs merge in the same order ({} merges); only costs differ\n",
            reweighted.len()
        ),
        Some(i) => divergence_table(
            i,
            ("recorded", recorded.get(i)),
            ("re-weighted", reweighted.get(i)),
        ),
    }
}

/// The recorded run (`rec`, its tree `old`) beside the re-weighted one (`new`, its merges
/// `merges`): depth, Balance and rounds.
pub fn reweight_table(
    rec: &Recorded,
    old: &SubsetTree,
    new: &Grouping,
    merges: &[Merge],
) -> String {
    let (ob, obmax) = balance_stats(&rec.merges);
    let (nb, nbmax) = balance_stats(merges);
    let mut s = format!("  {:<22} {:>12} {:>12}\n", "", "recorded", "re-weighted");
    let _ = writeln!(
        s,
        "  {:<22} {:>12} {:>12}",
        "depth max",
        old.depth_max(),
        new.tree.depth_max()
    );
    let _ = writeln!(
        s,
        "  {:<22} {:>12.3} {:>12.3}",
        "depth mean",
        old.depth_mean(),
        new.tree.depth_mean()
    );
    let _ = writeln!(s, "  {:<22} {:>12.3} {:>12.3}", "Balance mean", ob, nb);
    let _ = writeln!(s, "  {:<22} {:>12.3} {:>12.3}", "Balance max", obmax, nbmax);
    let _ = writeln!(
        s,
        "  {:<22} {:>12} {:>12}",
        "rounds", rec.rounds, new.rounds
    );
    s
}
