//! What `bench` prints: the targets table against obvhs PLOC and parry Binned, grouping +
//! refinement against the best peer, the §1.3 speed-ups, and (`bench --record`) what recording
//! costs. Each table comes as text with its header and notes; rows that are printed as they are
//! measured have their own line function.

use crate::metrics::bench::{RecordCostRow, RefineRow, SpeedupRow, TargetRow};
use std::fmt::Write as _;

/// The targets table's header line.
pub fn targets_header() -> String {
    format!(
        "{:<18} {:>8} {:>9} {:>9} {:>7} {:>9} {:>7} {:>8} {:>8} {:>8} {:>6} {:>8}\n",
        "scene",
        "N",
        "group ms",
        "PLOC ms",
        "t/PLOC",
        "binned ms",
        "t/bin",
        "SAH/bin",
        "qry/bin",
        "con/bin",
        "depth",
        "peak MB"
    )
}

/// One scene's line of the targets table.
pub fn target_line(r: &TargetRow) -> String {
    let (t, tp, tb) = (r.group_seconds, r.ploc_seconds, r.binned_seconds);
    format!(
        "{:<18} {:>8} {:>9.2} {:>9.2} {:>7.2} {:>9.2} {:>7.2} {:>8.3} {:>8.3} {:>8.3} {:>6} {:>8.0}\n",
        r.scene,
        r.n,
        t * 1e3,
        tp * 1e3,
        t / tp,
        tb * 1e3,
        t / tb,
        r.sah_ratio,
        r.query_ratio,
        r.contact_ratio,
        r.depth,
        r.peak_rss_bytes.unwrap_or(0) as f64 / 1e6
    )
}

/// The notes under the targets table, and a blank line.
pub fn targets_notes() -> String {
    "t/PLOC = grouping time / obvhs PLOC build time; t/bin = / parry3d Bvh Binned.\n\
     SAH/bin, qry/bin = SAH cost and node tests per query (AABB BVs, standard\n\
     workload) of the grouping tree / parry Binned's. Goal: t/PLOC <= 1 and qry/bin <= 1.\n\
     con/bin = the same for node tests per contact query (every touching pair of the\n\
     touching poses: these depend on the trees alone, not on how soon a traversal finds one).\n\
     peak MB = process peak RSS after the case (cases run in increasing size).\n\n"
        .to_string()
}

/// Grouping + refinement against the best peer, with its notes and a blank line.
pub fn refine_table(rows: &[RefineRow]) -> String {
    let mut s = format!(
        "{:<18} {:>9} {:>9} {:>10} {:>9} {:>9} {:>9} | {:>9} {:>10} {:>9} {:>9} {:>9}\n",
        "scene",
        "ref ms",
        "total ms",
        "ref/PLOC",
        "SAH/best",
        "qry/best",
        "con/best",
        "p tot ms",
        "p ref/PLOC",
        "p SAH/bst",
        "p qry/bst",
        "p con/bst"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{:<18} {:>9.2} {:>9.2} {:>10.2} {:>9.3} {:>9.3} {:>9.3} | {:>9.2} {:>10.2} {:>9.3} {:>9.3} {:>9.3}",
            r.scene,
            r.refine_seconds * 1e3,
            r.total_seconds * 1e3,
            r.refine_per_ploc,
            r.sah_per_best,
            r.query_per_best,
            r.contact_per_best,
            r.part_total_seconds * 1e3,
            r.part_refine_per_ploc,
            r.part_sah_per_best,
            r.part_query_per_best,
            r.part_contact_per_best
        );
    }
    s.push_str(
        "grouping+refine: ref ms = refinement alone, total ms = grouping + refinement;\n\
         ref/PLOC = refinement time alone / obvhs PLOC build time;\n\
         SAH/best, qry/best, con/best = its SAH, node tests per query and per contact query /\n\
         the best of parry Binned and obvhs PLOC + reinsertion. Goal: all <= 1.\n\
         p ... = the same for the partitioned grouping + refinement (grouping-partitioned+refine).\n\n",
    );
    s
}

/// The §1.3 speed-ups, with their notes, a blank line and the thread count of the targets
/// table's grouping times (`threads`).
pub fn speedup_table(rows: &[SpeedupRow], threads: usize) -> String {
    let mut s = format!(
        "{:<18} {:<19} {:>3} {:>9} {:>7} {:>7} {:>8} {:>8} {:>6} {:>8} {:>8}\n",
        "scene",
        "method",
        "thr",
        "ms",
        "t/PLOC",
        "t/grp",
        "SAH/grp",
        "qry/grp",
        "depth",
        "box8/grp",
        "hull8/grp"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "{:<18} {:<19} {:>3} {:>9.2} {:>7.2} {:>7.2} {:>8.3} {:>8.3} {:>6} {:>8.3} {:>8.3}",
            r.scene,
            r.method.name(),
            r.threads,
            r.seconds * 1e3,
            r.per_ploc,
            r.per_grouping,
            r.sah_ratio,
            r.query_ratio,
            r.depth,
            r.box8_ratio,
            r.hull8_ratio
        );
    }
    s.push_str(
        "The paper's §1.3 speed-ups (pregroup: connected components grouped first;\n\
         instanced: and rigid copies copy-moved; objects: the scene's objects as\n\
         components, copies copy-moved) on thr threads, against obvhs PLOC and the plain\n\
         grouping above: t/grp time, SAH, node tests per query, and the volume of the\n\
         depth-3 cut (Figure 3's 8-node level) as AABBs and convex hulls (N <= 50,000).\n\n",
    );
    let _ = writeln!(
        s,
        "group ms on {threads} threads (the exact run's round-start scans are parallel)."
    );
    s
}

/// The header line of `bench --record`'s table.
pub fn record_cost_header() -> String {
    format!(
        "{:<16} {:>7} {:>8} {:>9} {:>10} {:>7} {:>7} {:>8} {:>8} {:>8}\n",
        "scene",
        "N",
        "detail",
        "group ms",
        "record ms",
        "ratio",
        "median",
        "no-fixed",
        "rrd MB",
        "mcap MB"
    )
}

/// One scene and detail's line of `bench --record`'s table.
pub fn record_cost_line(r: &RecordCostRow) -> String {
    let c = &r.cost;
    let (t_group, t_rec) = (c.group_seconds, c.record_seconds);
    format!(
        "{:<16} {:>7} {:>8} {:>9.1} {:>10.1} {:>7.2} {:>7.2} {:>8.2} {:>8.2} {:>8.2}\n",
        r.scene,
        r.n,
        format!("{:?}", r.detail).to_lowercase(),
        t_group * 1e3,
        t_rec * 1e3,
        t_rec / t_group,
        c.median_ratio,
        (t_rec - r.fixed_seconds).max(0.0) / t_group,
        c.rrd_bytes as f64 / 1e6,
        c.mcap_bytes as f64 / 1e6
    )
}

/// The notes under `bench --record`'s table, with the fixed costs (s) of a 2-triangle
/// recording per detail (levels, merges, full).
pub fn record_cost_notes(fixed: &[f64; 3]) -> String {
    let ms = fixed.map(|f| format!("{:.1}", f * 1e3));
    format!(
        "record ms = grouping with both recorders listening + sphere tree + writing both files.\n\
         ratio = best record ms / best group ms; median = median over the runs of record / group\n\
         in the same pair (recording overhead is ratio - 1). Goal: merges <= 3.\n\
         no-fixed = (record ms - fixed cost) / group ms, the fixed cost being a 2-triangle \
         recording: {} ms (levels / merges / full).\n",
        ms.join(" / ")
    )
}
