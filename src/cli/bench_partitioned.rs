//! Prints the partitioned schedule's table ([`wraptree::metrics::bench::partitioned`]).

use anyhow::Result;
use wraptree::metrics::bench::partitioned::{Case, row};
use wraptree::scene::Scene;

/// Measures and prints a row per scene (`repeat` timed builds each, fewer from 10^6
/// primitives).
pub(super) fn print_table(cases: &[Scene], repeat: u32) -> Result<()> {
    println!();
    println!(
        "{:<18} {:>8} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>6} {:>6} {:>7} {:>7} {:>7} {:>7} {:>7}",
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
    );
    for scene in cases {
        let r = row(scene, repeat)?;
        let ms = |c: Option<Case>| c.map_or("-".to_string(), |c| format!("{:.2}", c.seconds * 1e3));
        let ratio = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{x:.3}"));
        let mb = |b: u64| b as f64 / 1e6;
        let [p1, p2] = r.partitioned;
        println!(
            "{:<18} {:>8} {:>9} {:>9} {:>9.2} {:>9.2} {:>9.2} {:>9.2} {:>6.2} {:>6.2} {:>7} {:>7} {:>7.0} {:>7} {:>7.0}",
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
        );
    }
    println!(
        "exact/part/PLOC = best build ms of the exact grouping, the partitioned grouping and obvhs"
    );
    println!(
        "PLOC (its `parallel` build) in a rayon pool of 1 or 2 threads (1t, 2t); p/P = part / PLOC."
    );
    println!(
        "SAH p/e, qry p/e = SAH and node tests per query (AABB BVs) of the partitioned tree / the"
    );
    println!(
        "exact tree's. ns/prim = part 1t per primitive. MB = peak RSS during the 1-thread builds"
    );
    println!(
        "(peak reset before each; exact left out above 10^6). Goals: p/P 1t <= 1.5, p/P 2t <= 1,"
    );
    println!("SAH and qry p/e <= 1.02.");
    Ok(())
}
