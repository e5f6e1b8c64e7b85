//! `wraptree bench`: every hierarchy builder × wrapper on given scenes (CSV, charts, `.rrd`),
//! the targets table against obvhs PLOC and parry Binned measured in the same run, and (with
//! `--record`) what recording costs.

use anyhow::{Context, Result, anyhow};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use wraptree::grouping::{self, Params};
use wraptree::metrics::{
    self,
    compare::{Options, Row, Wrapper, evaluate},
    report::write_bench,
};
use wraptree::peers::{self, Method};
use wraptree::query::{self, Bv, Workload};
use wraptree::record::Detail;
use wraptree::scene::{LoadOptions, Loaded, Scene, generate, load_bytes, load_path};

/// Arguments of `wraptree bench`.
#[derive(Args, Debug)]
pub struct BenchCmd {
    /// Scenes to compare every method × wrapper on: OBJ files, or generated scenes as
    /// KIND[:COUNT] (soup:100000, robot-bases:44, lamps:5, robot-base, lamp). Without scenes:
    /// the targets table on the standard scenes and the bundled meshes.
    scenes: Vec<String>,
    /// Output directory for results.csv, charts and bench.rrd (with SCENEs) [default:
    /// recordings/bench, created if missing; a given directory must exist].
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

fn best_of(repeat: u32, mut f: impl FnMut()) -> f64 {
    (0..repeat.max(1))
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The output directory: `given`, which must exist, or `default`, created if missing.
pub(super) fn output_dir(given: Option<&std::path::Path>, default: &str) -> Result<PathBuf> {
    match given {
        Some(d) if d.is_dir() => Ok(d.to_path_buf()),
        Some(d) => anyhow::bail!("{}: output directory does not exist", d.display()),
        None => {
            let d = PathBuf::from(default);
            std::fs::create_dir_all(&d)
                .with_context(|| format!("{}: cannot create the output directory", d.display()))?;
            Ok(d)
        }
    }
}

/// A generated scene as if loaded from its OBJ (so recordings can embed it).
fn as_loaded(scene: &Scene) -> Result<Loaded> {
    let mut bytes = Vec::new();
    scene.write_obj(&mut bytes)?;
    Ok(load_bytes(
        &format!("{}.obj", scene.name),
        bytes,
        &LoadOptions::default(),
    )?)
}

/// Loads an OBJ path, or generates KIND[:COUNT] (COUNT = triangles for soup, copies for
/// lamps/robot-bases).
pub(super) fn scene_spec(spec: &str) -> Result<Scene> {
    let path = std::path::Path::new(spec);
    if path.exists() || spec.ends_with(".obj") {
        let loaded = load_path(path, &LoadOptions::default())?;
        for w in &loaded.warnings {
            eprintln!("warning: {w}");
        }
        return Ok(loaded.scene);
    }
    let (kind, count) = match spec.split_once(':') {
        Some((k, c)) => {
            let c: usize = c
                .parse()
                .map_err(|_| anyhow!("{spec}: COUNT must be a whole number"))?;
            (k, Some(c))
        }
        None => (spec, None),
    };
    let (copies, n) = if kind == "soup" {
        (None, count)
    } else {
        (count, None)
    };
    let mut scene = generate::by_name(kind, copies, n, 1)
        .map_err(|e| anyhow!("{spec}: not a file, and {e}"))?;
    scene.name = spec.replace(':', "-");
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
            .map(|s| scene_spec(s))
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
            print_rows(&r);
            rows.extend(r);
        }
        for p in write_bench(&output, &rows, self.force)? {
            eprintln!("wrote {}", p.display());
        }
        Ok(ExitCode::SUCCESS)
    }

    /// The targets: grouping time against obvhs PLOC, SAH and query cost against parry Binned.
    fn run_targets(&self) -> Result<ExitCode> {
        let mut cases: Vec<Scene> = vec![generate::soup(10_000, 1)];
        cases.push(generate::replicate(&generate::robot_base(), 44, 1));
        for n in [100_000, 1_000_000] {
            if n <= self.max_soup {
                cases.push(generate::soup(n, 1));
            }
        }
        let bundled = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        let mut meshes: Vec<_> = std::fs::read_dir(&bundled)
            .map(|d| d.filter_map(|e| Some(e.ok()?.path())).collect())
            .unwrap_or_default();
        meshes.retain(|p: &PathBuf| p.extension().is_some_and(|e| e == "obj"));
        meshes.sort();
        for m in meshes {
            let mut s = load_path(&m, &LoadOptions::default())?.scene;
            s.name = m.file_stem().unwrap_or_default().to_string_lossy().into();
            cases.push(s);
        }
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
        let params = Params::default();
        let mut refined = Vec::new();
        let mut sped_up = Vec::new();
        for scene in &cases {
            let n = scene.len();
            let repeat = if n >= 1_000_000 {
                self.repeat.min(2)
            } else {
                self.repeat
            };
            let workload = Workload::standard(scene, 1);
            let run = |m: Method| -> Result<(f64, f64, f64, u32, peers::Built)> {
                let mut best: Option<peers::Built> = None;
                for _ in 0..repeat.max(1) {
                    let b = peers::build(m, scene, &params).map_err(|e| anyhow!(e))?;
                    if best.as_ref().is_none_or(|x| b.seconds < x.seconds) {
                        best = Some(b);
                    }
                }
                let b = best.expect("ran at least once");
                let q = query::measure(&b.tree, scene, Bv::Aabb, &workload);
                let tests = wraptree::metrics::compare::query_values(&q)[6];
                let (sah, depth) = (metrics::sah(&b.tree), b.tree.depth_max());
                Ok((b.seconds, sah, tests, depth, b))
            };
            let (t, sah, qc, depth, plain) = run(Method::Grouping)?;
            let (tp, ..) = run(Method::ObvhsPloc)?;
            let (tb, sah_b, qc_b, _, _) = run(Method::ParryBinned)?;
            let (_, sah_r, qc_r, _, built_r) = run(Method::GroupingRefine)?;
            let (_, sah_o, qc_o, ..) = run(Method::ObvhsPlocReinsert)?;
            refined.push((
                scene.name.clone(),
                built_r.refine_seconds / tp,
                sah_r / sah_b.min(sah_o),
                qc_r / qc_b.min(qc_o),
            ));
            // The §1.3 speed-ups with 1 and 2 threads, against the plain grouping.
            let volumes = n <= 50_000;
            let vol = |b: &peers::Built| metrics::level_volume(&b.tree, scene, 3);
            let (box8, hull8) = if volumes { vol(&plain) } else { (1.0, 1.0) };
            for m in [
                Method::GroupingPregroup,
                Method::GroupingInstanced,
                Method::GroupingObjects,
            ] {
                for threads in [1, 2] {
                    let pool = rayon::ThreadPoolBuilder::new()
                        .num_threads(threads)
                        .build()?;
                    let (tm, sah_m, qc_m, depth_m, built) = pool.install(|| run(m))?;
                    let (bm, hm) = if volumes {
                        vol(&built)
                    } else {
                        (f64::NAN, f64::NAN)
                    };
                    sped_up.push(format!(
                        "{:<18} {:<19} {:>3} {:>9.2} {:>7.2} {:>7.2} {:>8.3} {:>8.3} {:>6} {:>8.3} {:>8.3}",
                        scene.name,
                        m.name(),
                        threads,
                        tm * 1e3,
                        tm / tp,
                        tm / t,
                        sah_m / sah,
                        qc_m / qc,
                        depth_m,
                        bm / box8,
                        hm / hull8
                    ));
                }
            }
            println!(
                "{:<18} {:>8} {:>9.2} {:>9.2} {:>7.2} {:>9.2} {:>7.2} {:>8.3} {:>8.3} {:>6} {:>8.0}",
                scene.name,
                n,
                t * 1e3,
                tp * 1e3,
                t / tp,
                tb * 1e3,
                t / tb,
                sah / sah_b,
                qc / qc_b,
                depth,
                super::peak_rss_bytes().unwrap_or(0) as f64 / 1e6
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
            "{:<18} {:>10} {:>9} {:>9}",
            "scene", "ref/PLOC", "SAH/best", "qry/best"
        );
        for (name, t, s, q) in &refined {
            println!("{name:<18} {t:>10.2} {s:>9.3} {q:>9.3}");
        }
        println!("grouping+refine: ref/PLOC = refinement time alone / obvhs PLOC build time;");
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
        for line in &sped_up {
            println!("{line}");
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
        let lamp = generate::lamp();
        let cases = [
            generate::replicate(&lamp, 5, 1),
            generate::replicate(&generate::robot_base(), 44, 1),
            generate::soup(100_000, 1),
        ];
        let details = [Detail::Levels, Detail::Merges, Detail::Full];
        let dir = tempfile::tempdir()?;
        // The fixed cost of a recording: two triangles, one merge.
        let tiny = as_loaded(&generate::soup(2, 1))?;
        let mut fixed = [0.0; 3];
        for (f, &detail) in fixed.iter_mut().zip(&details) {
            let prefix = dir.path().join(format!("fixed-{detail:?}"));
            let (pairs, _) = self.record_pairs(&tiny, detail, &prefix)?;
            *f = pairs.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
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
        for scene in &cases {
            let loaded = as_loaded(scene)?;
            for (&detail, &fixed) in details.iter().zip(&fixed) {
                let prefix = dir.path().join(format!("{}-{detail:?}", scene.name));
                let (pairs, w) = self.record_pairs(&loaded, detail, &prefix)?;
                let t_group = pairs.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
                let t_rec = pairs.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
                let mut ratios: Vec<f64> = pairs.iter().map(|(g, r)| r / g).collect();
                ratios.sort_by(f64::total_cmp);
                let median = ratios[ratios.len() / 2];
                let mb = |p: &std::path::Path| {
                    std::fs::metadata(p)
                        .map(|m| m.len() as f64 / 1e6)
                        .unwrap_or(0.0)
                };
                println!(
                    "{:<16} {:>7} {:>8} {:>9.1} {:>10.1} {:>7.2} {:>7.2} {:>8.2} {:>8.2} {:>8.2}",
                    scene.name,
                    scene.len(),
                    format!("{detail:?}").to_lowercase(),
                    t_group * 1e3,
                    t_rec * 1e3,
                    t_rec / t_group,
                    median,
                    (t_rec - fixed).max(0.0) / t_group,
                    mb(&w.rrd),
                    mb(&w.mcap)
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

    /// `repeat` pairs of (grouping alone, grouping recorded) wall times for `loaded`, each
    /// recorded run just after its grouping-only run so that a slow spell of the machine weighs
    /// on both sides of a pair; and where the last recording went.
    fn record_pairs(
        &self,
        loaded: &Loaded,
        detail: Detail,
        prefix: &std::path::Path,
    ) -> Result<(Vec<(f64, f64)>, super::record::Written)> {
        let params = Params::default().resolve(&loaded.scene);
        let mut written = None;
        let pairs = (0..self.repeat.max(1))
            .map(|_| {
                let t_group = best_of(1, || {
                    std::hint::black_box(grouping::group(&loaded.scene, &Params::default(), ()));
                });
                let t_rec = best_of(1, || {
                    written = Some(super::record::record(
                        &loaded.scene,
                        &loaded.source,
                        &params,
                        detail,
                        prefix,
                        true,
                        true,
                    ));
                });
                (t_group, t_rec)
            })
            .collect();
        Ok((pairs, written.expect("ran at least once")?))
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

/// Prints one scene's comparison rows as a markdown table.
fn print_rows(rows: &[Row]) {
    let rows: Vec<&Row> = rows.iter().collect();
    print!("{}", wraptree::metrics::report::bench_table(&rows));
}
