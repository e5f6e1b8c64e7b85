//! `wraptree bench`: hierarchy builders × wrappers on given scenes (CSV, charts, `.rrd`),
//! the targets table against obvhs PLOC and parry Binned measured in the same run, and (with
//! `--record`) what recording costs ([`wraptree::metrics::bench`]).

use super::{ChunkArgs, progress};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use wraptree::grouping::Schedule;
use wraptree::grouping::partitioned::Chunking;
use wraptree::metrics::bench::{record_costs, target_rows, target_scenes};
use wraptree::metrics::compare::{Options, Step, Wrapper, evaluate};
use wraptree::metrics::report::{
    bench_outputs, bench_table, record_cost_header, record_cost_line, record_cost_notes,
    refine_table, speedup_table, target_line, targets_header, targets_notes, write_bench,
};
use wraptree::metrics::timing::ROUNDS;
use wraptree::output::{check_absent, output_dir};
use wraptree::peers::Method;
use wraptree::scene::spec::scene_spec;
use wraptree::stop::Stop;

/// Arguments of `wraptree bench`.
#[derive(Args, Debug)]
pub struct BenchCmd {
    /// Scenes to compare the methods × wrappers on: OBJ files, or generated scenes as
    /// KIND[:COUNT] (soup:100000, robot-bases:44, lamps:5, robot-base, lamp). Without scenes:
    /// the targets table on the standard scenes and the bundled meshes.
    scenes: Vec<String>,
    /// Output directory for results.csv, charts and bench.rrd (with SCENEs), created with its
    /// parents if missing [default: recordings/bench].
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Replace existing result files (without it, a run refuses them before it measures
    /// anything).
    #[arg(long)]
    force: bool,
    /// Hierarchy builders to compare (comma list, or `all`) [default:
    /// grouping,fast,grouping+refine,grouping-partitioned,parry-binned,obvhs-ploc,obvhs-ploc-reinsert].
    /// The --chunk-* flags set grouping-partitioned's chunks (`fast` keeps its own).
    #[arg(long, value_delimiter = ',', value_parser = method_choice)]
    methods: Vec<Choice<Method>>,
    /// Wrappers to build on each hierarchy (comma list, or `all`) [default:
    /// box,sphere-min,obb,hull].
    #[arg(long, value_delimiter = ',', value_parser = wrapper_choice)]
    wrappers: Vec<Choice<Wrapper>>,
    /// Tightness is measured up to this many primitives.
    #[arg(long, default_value_t = 1_000_000)]
    tightness_max_n: usize,
    /// Interior nodes per tree depth whose tightness is measured, drawn by a seeded hash (0:
    /// every node, exact queries: slow on large scenes).
    #[arg(long, value_name = "N", default_value_t = wraptree::wrap::NODES_PER_DEPTH)]
    tightness_nodes: usize,
    /// Largest soup size in the targets table (10^4, 10^5, 10^6 by default).
    #[arg(long, default_value_t = 1_000_000)]
    max_soup: usize,
    /// Threads of the rayon pool the comparison uses (partitioned grouping, the exact run's
    /// scans, obvhs PLOC) [default: all cores].
    #[arg(long, value_name = "N")]
    pub(super) threads: Option<usize>,
    /// Timed runs. With SCENEs the builds run in this many rounds, each building every method
    /// once, in --methods' order, and each method's fastest build is reported (with
    /// obvhs-ploc among them, in the table's `/ PLOC` column too): the protocol of the build
    /// times in docs/benchmarks.md (add `--threads 1` for its one-thread tables). Each wrapper
    /// is built up to this many times, the best kept, and repeated only while its runs took
    /// under 0.1 s in all (with 2 or more, at least until they took 20 ms, at most 200 runs).
    /// Without SCENEs: the same rounds per scene of the targets table (at most 2 from 10^6
    /// primitives). [default: 9 with SCENEs, else 3]
    #[arg(long, value_name = "N")]
    repeat: Option<u32>,
    /// Instead: measure recording (time and file sizes per --detail) on the 3,130- and
    /// 12,144-polygon scenes and a 10^5-triangle soup.
    #[arg(long)]
    record: bool,
    /// The chunks of grouping-partitioned and grouping-partitioned+refine.
    #[command(flatten)]
    chunks: ChunkArgs,
}

/// A `--methods` or `--wrappers` item: one name, or `all`.
#[derive(Clone, Copy, Debug)]
enum Choice<T> {
    All,
    One(T),
}

/// Parses a `--methods` or `--wrappers` item with `parse`, or `all`.
fn choice<T>(s: &str, parse: fn(&str) -> Result<T, String>) -> Result<Choice<T>, String> {
    match s.trim() {
        "all" => Ok(Choice::All),
        _ => parse(s)
            .map(Choice::One)
            .map_err(|e| format!("{e}, or all")),
    }
}

/// Parses a `--methods` item.
fn method_choice(s: &str) -> Result<Choice<Method>, String> {
    choice(s, Method::parse)
}

/// Parses a `--wrappers` item.
fn wrapper_choice(s: &str) -> Result<Choice<Wrapper>, String> {
    choice(s, Wrapper::parse)
}

/// The items chosen, in the order given (`all`: every one of `all`, in its order), each once.
fn chosen<T: Copy + PartialEq>(items: &[Choice<T>], all: &[T]) -> Vec<T> {
    let mut out: Vec<T> = Vec::new();
    for c in items {
        let more = match c {
            Choice::All => all.to_vec(),
            Choice::One(x) => vec![*x],
        };
        for x in more {
            if !out.contains(&x) {
                out.push(x);
            }
        }
    }
    out
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
    /// `--repeat` of the tables without SCENEs.
    fn repeat_else(&self) -> u32 {
        self.repeat.unwrap_or(3)
    }

    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        let threads = super::build_pool(self.threads)?;
        eprintln!("threads: {threads} (rayon pool)");
        if let Some(flag) = self.chunks.first_set()
            && (self.record || self.scenes.is_empty())
        {
            anyhow::bail!(
                "{flag} needs SCENEs (it sets grouping-partitioned's chunks in their table)"
            );
        }
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
        let mut opts = Options {
            repeat: self.repeat.unwrap_or(ROUNDS),
            tightness_max_n: self.tightness_max_n,
            tightness_nodes: self.tightness_nodes,
            ..Options::default()
        };
        if !self.methods.is_empty() {
            opts.methods = chosen(&self.methods, &Method::ALL);
        }
        if !self.wrappers.is_empty() {
            opts.wrappers = chosen(&self.wrappers, &Wrapper::ALL);
        }
        if let Some(flag) = self.chunks.first_set() {
            if !opts
                .methods
                .iter()
                .any(|m| m.base() == Method::GROUPING_PARTITIONED)
            {
                anyhow::bail!(
                    "{flag} sets grouping-partitioned's chunks: name grouping-partitioned \
                     or grouping-partitioned+refine in --methods"
                );
            }
            // Read by grouping-partitioned only (`Method::schedule`).
            let c = self.chunks.apply(Chunking::DEFAULT);
            opts.params.mode.schedule = Schedule::Partitioned(c);
            opts.params.check().map_err(anyhow::Error::msg)?;
            let delta = match c.delta {
                0 => "by the scene's size".to_string(),
                d => d.to_string(),
            };
            eprintln!(
                "grouping-partitioned: chunks of δ = {delta}, ε = {}, root share {}, SAH cuts up to {}",
                c.epsilon, c.top, c.sah_below
            );
        }
        let output = output_dir(self.output.as_deref(), "recordings/bench")?;
        let names: Vec<&str> = scenes.iter().map(|s| s.name.as_str()).collect();
        check_absent(&bench_outputs(&output, &names), self.force)?;
        let stop = Stop::on_signals();
        let mut rows = Vec::new();
        for scene in &scenes {
            // A step per build of each round, then one per method measured.
            let methods = opts.methods.len() as u64;
            let bar = progress::bar((u64::from(opts.repeat.max(1)) + 1) * methods, &scene.name);
            let (mut done, mut measuring) = (0, None);
            let r = evaluate(scene, &opts, &stop, &mut |step| {
                let next = match step {
                    Step::Build(_) => true,
                    Step::Wrapper(m, _) | Step::Tightness(m, _) | Step::Query(m, _) => {
                        measuring.replace(m) != Some(m)
                    }
                };
                if next {
                    bar.set_position(done);
                    done += 1;
                }
                bar.set_message(step.to_string());
            });
            bar.finish_and_clear();
            let r = r?;
            print!("{}", bench_table(&r.iter().collect::<Vec<_>>()));
            rows.extend(r);
        }
        stop.check()?;
        for p in write_bench(&output, &rows, self.force)? {
            eprintln!("wrote {}", p.display());
        }
        Ok(ExitCode::SUCCESS)
    }

    /// The targets: grouping time against obvhs PLOC, SAH and query cost against parry Binned.
    fn run_targets(&self) -> Result<ExitCode> {
        let cases = target_scenes(self.max_soup)?;
        print!("{}", targets_header());
        let stop = Stop::on_signals();
        let mut refined = Vec::new();
        let mut sped_up = Vec::new();
        for scene in &cases {
            stop.check()?;
            let bar = progress::spinner(&format!("targets: {}", scene.name));
            let rows = target_rows(scene, self.repeat_else());
            bar.finish_and_clear();
            let (r, refine, speedups) = rows?;
            refined.push(refine);
            sped_up.extend(speedups);
            print!("{}", target_line(&r));
        }
        print!("{}", targets_notes());
        print!("{}", refine_table(&refined));
        print!("{}", speedup_table(&sped_up, rayon::current_num_threads()));
        Ok(ExitCode::SUCCESS)
    }

    /// `--record`: what recording costs, a line per scene and detail as it is measured.
    fn run_record(&self) -> Result<ExitCode> {
        print!("{}", record_cost_header());
        let fixed = record_costs(self.repeat_else(), |r| print!("{}", record_cost_line(r)))?;
        print!("{}", record_cost_notes(&fixed));
        Ok(ExitCode::SUCCESS)
    }
}
