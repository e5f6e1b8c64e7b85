//! `wraptree bench`: every hierarchy builder × wrapper on given scenes (CSV, charts, `.rrd`),
//! the targets table against obvhs PLOC and parry Binned measured in the same run, and (with
//! `--record`) what recording costs ([`wraptree::metrics::bench`]).

use anyhow::{Result, anyhow};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use wraptree::metrics::bench::{record_cost, record_scenes, target_rows, target_scenes};
use wraptree::metrics::compare::{Options, Wrapper, evaluate};
use wraptree::metrics::report::{bench_table, write_bench};
use wraptree::peers::Method;
use wraptree::record::Detail;
use wraptree::record::output::output_dir;
use wraptree::scene::generate;
use wraptree::scene::spec::{as_loaded, scene_spec};

/// Arguments of `wraptree bench`.
#[derive(Args, Debug)]
pub struct BenchCmd {
    /// Scenes to compare every method × wrapper on: OBJ files, or generated scenes as
    /// KIND[:COUNT] (soup:100000, robot-bases:44, lamps:5, robot-base, lamp). Without scenes:
    /// the targets table on the standard scenes and the bundled meshes.
    scenes: Vec<String>,
    /// Output directory for results.csv, charts and bench.rrd (with SCENEs), created with its
    /// parents if missing [default: recordings/bench].
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Replace existing result files.
    #[arg(long)]
    force: bool,
    /// Hierarchy builders to compare (comma list) [default: all].
    #[arg(long, value_delimiter = ',', value_parser = Method::parse)]
    methods: Vec<Method>,
    /// Wrappers to build on each hierarchy (comma list) [default: all].
    #[arg(long, value_delimiter = ',', value_parser = Wrapper::parse)]
    wrappers: Vec<Wrapper>,
    /// Tightness is measured up to this many primitives (it costs more than the builds).
    #[arg(long, default_value_t = 50_000)]
    tightness_max_n: usize,
    /// Largest soup size in the targets table (10^4, 10^5, 10^6 by default; 10000000 adds a
    /// 10^7 soup to the partitioned table).
    #[arg(long, default_value_t = 1_000_000)]
    max_soup: usize,
    /// Threads of the rayon pool the comparison uses (partitioned grouping, the exact run's
    /// scans, obvhs PLOC) [default: all cores]; the partitioned table sets 1 and 2 itself.
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    /// Timed repetitions per case (the best is reported).
    #[arg(long, default_value_t = 3)]
    repeat: u32,
    /// Instead: measure recording (time and file sizes per --detail) on the 3,130- and
    /// 12,144-polygon scenes and a 10^5-triangle soup.
    #[arg(long)]
    record: bool,
}

/// Loads a KIND[:COUNT] or OBJ scene spec, printing loader warnings to stderr.
pub(super) fn load_spec(spec: &str) -> Result<wraptree::scene::Scene> {
    let (scene, warnings) = scene_spec(spec)?;
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    Ok(scene)
}

impl BenchCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        if self.threads == Some(0) {
            anyhow::bail!("--threads must be at least 1, got 0");
        }
        let mut pool = rayon::ThreadPoolBuilder::new();
        if let Some(n) = self.threads {
            pool = pool.num_threads(n);
        }
        // Fails only when a pool exists already: that pool is then the one used.
        let _ = pool.build_global();
        eprintln!("threads: {} (rayon pool)", rayon::current_num_threads());
        if self.record {
            return self.run_record();
        }
        if self.scenes.is_empty() {
            return self.run_targets();
        }
        let scenes = self
            .scenes
            .iter()
            .map(|s| load_spec(s))
            .collect::<Result<Vec<_>>>()?;
        let opts = Options {
            methods: if self.methods.is_empty() {
                Method::ALL.to_vec()
            } else {
                self.methods.clone()
            },
            wrappers: if self.wrappers.is_empty() {
                Wrapper::ALL.to_vec()
            } else {
                self.wrappers.clone()
            },
            repeat: self.repeat,
            tightness_max_n: self.tightness_max_n,
            ..Options::default()
        };
        let output = output_dir(self.output.as_deref(), "recordings/bench")?;
        let mut rows = Vec::new();
        for scene in &scenes {
            let bar = method_bar(opts.methods.len(), &scene.name);
            let r = evaluate(scene, &opts, |m| {
                bar.set_message(m.name());
                bar.inc(1);
            })
            .map_err(|e| anyhow!(e))?;
            bar.finish_and_clear();
            print!("{}", bench_table(&r.iter().collect::<Vec<_>>()));
            rows.extend(r);
        }
        for p in write_bench(&output, &rows, self.force)? {
            eprintln!("wrote {}", p.display());
        }
        Ok(ExitCode::SUCCESS)
    }

    /// The targets: grouping time against obvhs PLOC, SAH and query cost against parry Binned.
    fn run_targets(&self) -> Result<ExitCode> {
        let mut cases = target_scenes(self.max_soup)?;
        println!(
            "{:<18} {:>8} {:>9} {:>9} {:>7} {:>9} {:>7} {:>8} {:>8} {:>6} {:>8}",
            "scene",
            "N",
            "group ms",
            "PLOC ms",
            "t/PLOC",
            "binned ms",
            "t/bin",
            "SAH/bin",
            "qry/bin",
            "depth",
            "peak MB"
        );
        let mut refined = Vec::new();
        let mut sped_up = Vec::new();
        for scene in &cases {
            let (r, refine, speedups) = target_rows(scene, self.repeat)?;
            let (t, tp, tb) = (r.group_seconds, r.ploc_seconds, r.binned_seconds);
            refined.push(refine);
            sped_up.extend(speedups);
            println!(
                "{:<18} {:>8} {:>9.2} {:>9.2} {:>7.2} {:>9.2} {:>7.2} {:>8.3} {:>8.3} {:>6} {:>8.0}",
                r.scene,
                r.n,
                t * 1e3,
                tp * 1e3,
                t / tp,
                tb * 1e3,
                t / tb,
                r.sah_ratio,
                r.query_ratio,
                r.depth,
                r.peak_rss_bytes.unwrap_or(0) as f64 / 1e6
            );
        }
        println!("t/PLOC = grouping time / obvhs PLOC build time; t/bin = / parry3d Bvh Binned.");
        println!("SAH/bin, qry/bin = SAH cost and node tests per query (AABB BVs, standard");
        println!(
            "workload) of the grouping tree / parry Binned's. Goal: t/PLOC <= 1 and qry/bin <= 1."
        );
        println!("peak MB = process peak RSS after the case (cases run in increasing size).");
        println!();
        println!(
            "{:<18} {:>9} {:>9} {:>10} {:>9} {:>9}",
            "scene", "ref ms", "total ms", "ref/PLOC", "SAH/best", "qry/best"
        );
        for r in &refined {
            println!(
                "{:<18} {:>9.2} {:>9.2} {:>10.2} {:>9.3} {:>9.3}",
                r.scene,
                r.refine_seconds * 1e3,
                r.total_seconds * 1e3,
                r.refine_per_ploc,
                r.sah_per_best,
                r.query_per_best
            );
        }
        println!("grouping+refine: ref ms = refinement alone, total ms = grouping + refinement;");
        println!("ref/PLOC = refinement time alone / obvhs PLOC build time;");
        println!(
            "SAH/best, qry/best = its SAH and node tests per query / the best of parry Binned"
        );
        println!("and obvhs PLOC + reinsertion. Goal: all three <= 1.");
        println!();
        println!(
            "{:<18} {:<19} {:>3} {:>9} {:>7} {:>7} {:>8} {:>8} {:>6} {:>8} {:>8}",
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
        for r in &sped_up {
            println!(
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
        println!("The paper's §1.3 speed-ups (pregroup: connected components grouped first;");
        println!("instanced: and rigid copies copy-moved; objects: the scene's objects as");
        println!("components, copies copy-moved) on thr threads, against obvhs PLOC and the plain");
        println!("grouping above: t/grp time, SAH, node tests per query, and the volume of the");
        println!("depth-3 cut (Figure 3's 8-node level) as AABBs and convex hulls (N <= 50,000).");
        println!();
        println!(
            "group ms on {} threads (the exact run's round-start scans are parallel).",
            rayon::current_num_threads()
        );
        if self.max_soup >= 10_000_000 {
            cases.push(generate::soup(10_000_000, 1));
        }
        super::bench_partitioned::print_table(&cases, self.repeat)?;
        Ok(ExitCode::SUCCESS)
    }

    fn run_record(&self) -> Result<ExitCode> {
        let details = [Detail::Levels, Detail::Merges, Detail::Full];
        let dir = tempfile::tempdir()?;
        // The fixed cost of a recording: two triangles, one merge.
        let tiny = as_loaded(&generate::soup(2, 1))?;
        let mut fixed = [0.0; 3];
        for (f, &detail) in fixed.iter_mut().zip(&details) {
            let prefix = dir.path().join(format!("fixed-{detail:?}"));
            *f = record_cost(&tiny, detail, &prefix, self.repeat)?.record_seconds;
        }
        println!(
            "{:<16} {:>7} {:>8} {:>9} {:>10} {:>7} {:>7} {:>8} {:>8} {:>8}",
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
        );
        for scene in &record_scenes() {
            let loaded = as_loaded(scene)?;
            for (&detail, &fixed) in details.iter().zip(&fixed) {
                let prefix = dir.path().join(format!("{}-{detail:?}", scene.name));
                let c = record_cost(&loaded, detail, &prefix, self.repeat)?;
                let (t_group, t_rec) = (c.group_seconds, c.record_seconds);
                println!(
                    "{:<16} {:>7} {:>8} {:>9.1} {:>10.1} {:>7.2} {:>7.2} {:>8.2} {:>8.2} {:>8.2}",
                    scene.name,
                    scene.len(),
                    format!("{detail:?}").to_lowercase(),
                    t_group * 1e3,
                    t_rec * 1e3,
                    t_rec / t_group,
                    c.median_ratio,
                    (t_rec - fixed).max(0.0) / t_group,
                    c.rrd_bytes as f64 / 1e6,
                    c.mcap_bytes as f64 / 1e6
                );
            }
        }
        let ms = fixed.map(|f| format!("{:.1}", f * 1e3));
        println!(
            "record ms = grouping with both recorders listening + sphere tree + writing both files."
        );
        println!(
            "ratio = best record ms / best group ms; median = median over the runs of record / group"
        );
        println!("in the same pair (recording overhead is ratio - 1). Goal: merges <= 3.");
        println!(
            "no-fixed = (record ms - fixed cost) / group ms, the fixed cost being a 2-triangle \
             recording: {} ms (levels / merges / full).",
            ms.join(" / ")
        );
        Ok(ExitCode::SUCCESS)
    }
}

/// A bar over methods on stderr, hidden when stderr is not a terminal.
pub(super) fn method_bar(len: usize, scene: &str) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len as u64);
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} {msg} {elapsed}")
    {
        bar.set_style(style);
    }
    bar.set_prefix(scene.to_string());
    bar
}
