//! What this program prints: the partitioned schedule's table ([`crate::measure`]) with its
//! header and notes.

use crate::measure::{Case, Row};
use wraptree::metrics::bench::RecordCost;

/// The partitioned table's header line (after a blank line).
pub fn partitioned_header() -> String {
    format!(
        "\n{:<18} {:>8} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>6} {:>6} {:>7} {:>7} {:>7} {:>7} {:>7}\n",
        "scene",
        "N",
        "exact 1t",
        "exact 2t",
        "part 1t",
        "part 2t",
        "PLOC 1t",
        "PLOC 2t",
        "p/P 1t",
        "p/P 2t",
        "SAH p/e",
        "qry p/e",
        "ns/prim",
        "MB ex",
        "MB part"
    )
}

/// One scene's line of the partitioned table; `-` where the exact run was left out.
pub fn partitioned_line(r: &Row) -> String {
    let ms = |c: Option<Case>| c.map_or("-".to_string(), |c| format!("{:.2}", c.seconds * 1e3));
    let ratio = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{x:.3}"));
    let mb = |b: u64| b as f64 / 1e6;
    let [p1, p2] = r.partitioned;
    format!(
        "{:<18} {:>8} {:>9} {:>9} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>6.2} {:>6.2} {:>7} {:>7} {:>7.0} {:>7} {:>7.0}\n",
        r.scene,
        r.n,
        ms(r.exact[0]),
        ms(r.exact[1]),
        p1.seconds * 1e3,
        p2.seconds * 1e3,
        r.ploc[0].seconds * 1e3,
        r.ploc[1].seconds * 1e3,
        r.per_ploc(0),
        r.per_ploc(1),
        ratio(r.sah_ratio()),
        ratio(r.query_ratio()),
        r.ns_per_primitive(),
        r.exact[0].map_or("-".to_string(), |e| format!("{:.0}", mb(e.peak_bytes))),
        mb(p1.peak_bytes),
    )
}

/// The partitioned table's notes: what each column means and the goals.
pub fn partitioned_notes() -> String {
    "exact/part/PLOC = best build ms of the exact grouping, the partitioned grouping and obvhs\n\
     PLOC (its `parallel` build) in a rayon pool of 1 or 2 threads (1t, 2t); p/P = part / PLOC.\n\
     SAH p/e, qry p/e = SAH and node tests per query (AABB BVs) of the partitioned tree / the\n\
     exact tree's. ns/prim = part 1t per primitive. MB = peak RSS during the 1-thread builds\n\
     (peak reset before each; exact left out above 10^6). Goals: p/P 1t <= 1.5, p/P 2t <= 1,\n\
     SAH and qry p/e <= 1.02.\n"
        .to_string()
}

/// The line under the partitioned table: recording `scene` (`n` primitives) with the
/// partitioned schedule at `--detail merges` on one thread, against its grouping alone.
pub fn partitioned_record_line(scene: &str, n: usize, c: &RecordCost) -> String {
    format!(
        "record {scene} ({n}, partitioned, --detail merges, 1t): group {:.0} ms, record {:.0} ms, \
         ratio {:.2} (median {:.2}; goal <= 3); .rrd {:.1} MB, .mcap {:.1} MB\n",
        c.group_seconds * 1e3,
        c.record_seconds * 1e3,
        c.record_seconds / c.group_seconds,
        c.median_ratio,
        c.rrd_bytes as f64 / 1e6,
        c.mcap_bytes as f64 / 1e6,
    )
}
