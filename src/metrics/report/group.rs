//! What `group` prints: a finished run's summary as text or as one JSON object.

use crate::grouping::{self, Grouping, Pregroup, Pregrouping};
use crate::scene::Scene;
use std::fmt::Write as _;

/// The summary of `g`, the grouping of `scene` on `threads` threads in `seconds`, as the lines
/// `wraptree group` prints.
pub fn group_text(scene: &Scene, g: &Grouping, threads: usize, seconds: f64) -> String {
    let (t, p) = (&g.tree, &g.params);
    let mut s = format!("scene       {} ({} primitives)\n", scene.name, scene.len());
    let _ = writeln!(
        s,
        "params      A={} B={} C={} DLimit0={:.6e} GLimit0={:.6e} pset={:?}",
        p.weights.a, p.weights.b, p.weights.c, p.dlimit0, p.glimit0, p.pset
    );
    let (name, chunking) = match &p.mode.schedule {
        grouping::Schedule::Partitioned(c) => {
            // Without pre-grouping, a scene of at most 1.5 × the root share is one subproblem.
            let whole = p.mode.pregroup == Pregroup::None && c.whole(scene.len());
            let text = format!(
                " (chunks of δ = {}, ε = {}, root share {}, {}{})",
                c.delta,
                c.epsilon,
                c.top,
                match c.sah_below {
                    0 => "Morton cuts only".to_string(),
                    n => format!("SAH cuts up to {n} primitives"),
                },
                if whole {
                    "; grouped whole, the exact schedule's tree: at most 1.5 × the root share"
                } else {
                    ""
                }
            );
            ("Partitioned", text)
        }
        grouping::Schedule::Exact => ("Exact", String::new()),
    };
    let _ = writeln!(
        s,
        "schedule    {name} on {threads} thread{}{chunking}",
        if threads == 1 { "" } else { "s" }
    );
    if let Some(p) = &g.pregrouping {
        let _ = writeln!(s, "{}", pregrouping_lines(p));
    }
    if g.stats.identical > 0 {
        let _ = writeln!(
            s,
            "identical   {} merges of neighbours with identical boxes before the split",
            g.stats.identical
        );
    }
    let _ = writeln!(s, "rounds      {}", g.rounds);
    let _ = writeln!(
        s,
        "depth       max {} ({} levels), mean {:.2}, 2·log2 N = {:.1}",
        t.depth_max(),
        t.depth_max() + 1,
        t.depth_mean(),
        2.0 * (scene.len() as f64).log2()
    );
    let _ = writeln!(s, "time        {:.3} ms", seconds * 1e3);
    s
}

/// The same summary as one JSON object, with the stats, the process's peak RSS and the tree
/// as its parent array (`group --json`).
pub fn group_json(scene: &Scene, g: &Grouping, threads: usize, seconds: f64) -> serde_json::Value {
    let t = &g.tree;
    serde_json::json!({
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
        "peak_rss_bytes": crate::metrics::peak_rss_bytes(),
        "parent": t.parent_i64(),
    })
}

/// What pre-grouping found, as the lines `wraptree group` prints.
pub fn pregrouping_lines(p: &Pregrouping) -> String {
    let kind = match p.pregroup {
        Pregroup::None => "none",
        Pregroup::Objects => "objects",
        Pregroup::Connected => "connected",
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
