//! Argument definitions and dispatch for every subcommand.

mod bench;
mod compare;
mod cover;
mod deadline;
mod group;
mod progress;
mod record;
mod replay;
mod scene_cmd;
mod snapshot;
mod spherize;
mod stress;
mod sweep;
mod wrap_cmd;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use wraptree::grouping::partitioned::Chunking;
use wraptree::grouping::{CostMeasure, Mode, PSet, Params, Pregroup, Schedule, Weights};
use wraptree::refine::Refinement;
use wraptree::scene::{LoadOptions, Loaded, Up, UrdfOptions};

/// Build, record and inspect bounding-volume hierarchies with the bottom-up grouping phase of
/// Xavier's "A Generic Algorithm for Constructing Hierarchical Representations of Geometric
/// Objects".
#[derive(Parser, Debug)]
#[command(name = "wraptree", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run the grouping phase on a scene and print the Subset Tree's summary (--max-seconds
    /// bounds it; times: docs/benchmarks.md).
    Group(group::GroupCmd),
    /// Group a scene step by step and record it to PREFIX.rrd (Rerun) and PREFIX.mcap (Foxglove)
    /// (time and file sizes grow with the scene and --detail; sizes: docs/recordings.md).
    Record(record::RecordCmd),
    /// Rebuild a run from its .mcap; --verify re-runs it; --a/--b/--c re-weights it (reading is
    /// one pass over the file; a re-run costs one grouping, a re-weighting one recording).
    Replay(replay::ReplayCmd),
    /// Two or more .mcap recordings of one scene side by side in one .rrd, their first
    /// divergence marked (one pass over each file, linear in the runs' merges).
    Compare(compare::CompareCmd),
    /// Generate a seeded synthetic scene as Wavefront OBJ (linear in its size).
    Scene(scene_cmd::SceneCmd),
    /// Compare hierarchy builders × wrappers on scenes (CSV, charts, .rrd), or print the targets
    /// table against obvhs PLOC and parry Binned. Builds are timed in rounds that build every
    /// method in turn, the fastest build of each kept (--repeat). Every step's work is bounded
    /// by the scene's size (hulls from the children's hull vertices, tightness and queries
    /// sampled or capped); stacked coincident copies take longest, their queries testing every
    /// tied pair up to a cap. Times: docs/benchmarks.md.
    Bench(bench::BenchCmd),
    /// Run the A/B/C grid of the grouping Cost on a scene: table, heat maps, the series of every
    /// setting (sweep.rrd) and the trees of the 6 best distinct settings side by side
    /// (compare.rrd). One grouping per setting of the grid, each bounded by --max-seconds.
    Sweep(sweep::SweepCmd),
    /// Render the input and chosen tree levels as PNG/SVG frames and a figure sheet (one
    /// grouping, then rasterising: linear in the scene and the frames).
    Snapshot(snapshot::SnapshotCmd),
    /// Build Wrapper Trees and print their per-level tightness (error sampled per depth) and
    /// containment check (every node); linear in the scene with the defaults, grouping
    /// included.
    Wrap(wrap_cmd::WrapCmd),
    /// The fewest wrappers that model a scene within --tolerance, or the best --budget of them
    /// (one grouping and one Wrapper Tree per kind, then a pass over the tree).
    Cover(cover::CoverCmd),
    /// Every builder on pathological scenes (spaghetti, slabs, …) under a time budget per case
    /// (the whole run within 226 × (--budget + 1 s)).
    Stress(stress::StressCmd),
    /// Per-link collision spheres for a robot URDF, conservative and fewest for their error,
    /// as URDF, cuRobo YAML, MoveIt SRDF and .sph, with scores and a recording (a
    /// 17k-triangle robot takes seconds on 2 cores).
    Spherize(spherize::SpherizeCmd),
}

/// How to read a scene file.
#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Scene file: Wavefront OBJ, STL, PLY, OFF, glTF/GLB, COLLADA or URDF (by its extension).
    pub scene: PathBuf,
    /// Treat each object (OBJ o/g, STL solid, glTF or COLLADA node, URDF link) as one convex
    /// polyhedron (default: each face is a polygon).
    #[arg(long)]
    pub polyhedra: bool,
    /// With --polyhedra: an object whose vertices are not in convex position is an error.
    #[arg(long)]
    pub strict: bool,
    /// The file's up axis, turned to +Z when loading: y or z [default: y for glTF, a COLLADA
    /// file's <up_axis> (y if none), z for the other formats].
    #[arg(long, value_enum)]
    pub up: Option<Up>,
    /// URDF: read each link's collision geometry instead of its visual geometry.
    #[arg(long)]
    pub urdf_collision: bool,
    /// URDF: a joint's value, NAME=VALUE (radians, or metres for a prismatic joint); repeat
    /// for more joints. Other joints are at 0.
    #[arg(long, value_name = "NAME=VALUE", value_parser = parse_joint, allow_hyphen_values = true)]
    pub joint: Vec<(String, f64)>,
    /// URDF: a folder to find package://NAME/… meshes in (DIR/NAME/… or DIR/… for a DIR named
    /// NAME); repeatable, searched before ROS_PACKAGE_PATH and the URDF's own folders.
    #[arg(long, value_name = "DIR")]
    pub package_path: Vec<PathBuf>,
    /// Before grouping, cut polygons whose aspect (principal : secondary extent) exceeds R
    /// into slabs of aspect ≤ R (§4); the split scene is what is grouped and recorded.
    #[arg(long, value_name = "R")]
    pub split_aspect: Option<f64>,
}

impl SceneArgs {
    /// Loads the scene, printing loader warnings to stderr.
    pub fn load(&self) -> Result<Loaded> {
        let opts = LoadOptions {
            polyhedra: self.polyhedra,
            strict: self.strict,
            up: self.up,
        };
        let mut package_path = self.package_path.clone();
        package_path.extend(UrdfOptions::ros_package_path());
        let urdf = UrdfOptions {
            collision: self.urdf_collision,
            joints: self.joint.clone(),
            package_path,
        };
        let stop = wraptree::stop::Stop::on_signals();
        let mut loaded = wraptree::scene::load_path_until(&self.scene, &opts, &urdf, &stop)?;
        if let Some(r) = self.split_aspect {
            let (split, line) = wraptree::scene::split::split_flag(loaded, r)?;
            eprintln!("{line}");
            loaded = split;
        }
        for w in &loaded.warnings {
            eprintln!("warning: {w}");
        }
        Ok(loaded)
    }

    /// Whether any flag about reading the scene file is given (they do not apply to a
    /// recording, which carries its own).
    pub fn has_load_flags(&self) -> bool {
        self.polyhedra
            || self.strict
            || self.up.is_some()
            || self.urdf_collision
            || !self.joint.is_empty()
            || !self.package_path.is_empty()
    }
}

/// Parses a `--joint NAME=VALUE`.
fn parse_joint(s: &str) -> Result<(String, f64), String> {
    wraptree::scene::urdf::parse_joint(s)
}

/// Parameters of the grouping phase (§2.2).
#[derive(Args, Debug, Clone)]
pub struct GroupArgs {
    /// Cost exponent A in Cost = diameter^A × (B·Fill + C·Balance) (with B = C = 0 the
    /// bracket is 1). A = B = C = 0 makes every Cost 1, so pairs merge in id order, far from
    /// each other's best: many times slower (in group, record and cover --max-seconds bounds
    /// it).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub a: f64,
    /// Fill weight B.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub b: f64,
    /// Balance weight C.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub c: f64,
    /// Initial DLimit [default: median primitive diameter].
    #[arg(long, allow_negative_numbers = true)]
    pub dlimit: Option<f64>,
    /// Initial GLimit [default: DLimit / 4].
    #[arg(long, allow_negative_numbers = true)]
    pub glimit: Option<f64>,
    /// P-set wrapper: aabb (boxes, L∞ gaps) or hull (convex hulls, L2 gaps).
    #[arg(long, value_enum, default_value_t = PSet::Aabb)]
    pub pset: PSet,
    /// Break cost ties by seeded random tags instead of by id.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Schedule: exact (the literal §2.2 run) or partitioned (the same step inside the chunks
    /// of a Morton split, bottom-up, in parallel).
    #[arg(long, default_value = "exact", value_parser = ["exact", "partitioned"])]
    pub schedule: String,
    /// The fast path: the partitioned schedule whose split is the tree below a root share of
    /// 16 (chunks of δ = 2; the --chunk-* flags still apply), after merging neighbours with
    /// identical boxes; with `record`, `--refine` adds its refinement (the bench method
    /// `fast`'s, for the scene's size).
    #[arg(long, conflicts_with = "schedule")]
    pub fast: bool,
    /// Components grouped on their own first: none, objects (the file's o/g), connected
    /// (primitives sharing welded vertices).
    #[arg(long, value_enum, default_value_t = Pregroup::None)]
    pub pregroup: Pregroup,
    /// Rigid copies of a component reuse its Subset Tree shape (with --pregroup).
    #[arg(long)]
    pub instancing: bool,
    /// Size measure in the Cost: diameter (the paper's) or area (surface area of the box).
    #[arg(long, value_enum, default_value_t = CostMeasure::Diameter)]
    pub cost: CostMeasure,
    /// The partitioned schedule's chunking.
    #[command(flatten)]
    pub chunks: ChunkArgs,
    /// Threads for the parallel steps (partitioned chunks, the exact run's round-start scans);
    /// the tree is the same for any count [default: all cores].
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
}

impl GroupArgs {
    /// Builds the global rayon pool with `--threads` threads (once per process; later calls
    /// keep the first pool) and returns the number of threads it has.
    pub fn threads(&self) -> Result<usize> {
        build_pool(self.threads)
    }

    /// The refinement `record --refine` starts from: the fast path's with `--fast` (its
    /// preset's other half, next to [`GroupArgs::params`]' schedule), else the default.
    pub fn refinement(&self) -> Refinement {
        if self.fast {
            Refinement::Fast
        } else {
            Refinement::Default
        }
    }

    /// Checks the values (building the thread pool, see [`GroupArgs::threads`]) and turns them
    /// into [`Params`]. `--fast` is resolved here, once: the partitioned schedule with
    /// [`Chunking::FAST`] (the `--chunk-*` flags still apply to it).
    pub fn params(&self) -> Result<Params> {
        self.threads()?;
        let schedule = if self.fast || self.schedule == "partitioned" {
            let preset = if self.fast {
                Chunking::FAST
            } else {
                Chunking::DEFAULT
            };
            Schedule::Partitioned(self.chunks.apply(preset))
        } else {
            if let Some(flag) = self.chunks.first_set() {
                anyhow::bail!("{flag} needs --schedule partitioned or --fast");
            }
            Schedule::Exact
        };
        let params = Params {
            weights: Weights {
                a: self.a,
                b: self.b,
                c: self.c,
            },
            dlimit: self.dlimit,
            glimit: self.glimit,
            pset: self.pset,
            seed: self.seed,
            mode: Mode {
                schedule,
                pregroup: self.pregroup,
                instancing: self.instancing,
                cost: self.cost,
            },
        };
        if schedule.is_partitioned() && params.pset == PSet::Hull {
            // The library groups hulls with the exact schedule whatever the mode says; a run
            // that reported a partitioned schedule (and its chunks) would not be the run made.
            // Refused here, not in `Mode::check`, which recordings' metadata also passes:
            // recordings made with this pair still replay (as the exact run they were).
            let flag = if self.fast {
                "--fast"
            } else {
                "--schedule partitioned"
            };
            anyhow::bail!(
                "{flag} needs --pset aabb (the hull p-set has no partitioned form: \
                 drop it to group hulls with the exact schedule)"
            );
        }
        params.check().map_err(anyhow::Error::msg)?;
        Ok(params)
    }
}

/// The partitioned schedule's chunking flags (`--chunk-*`); unset ones keep the schedule's own
/// setting (the default partitioned one, or the fast path's).
#[derive(Args, Debug, Clone, Default)]
pub struct ChunkArgs {
    /// Partitioned schedule: about how many bodies its root step (the exact schedule's) starts
    /// from; scenes of at most 1.5× this are grouped whole. Smaller is faster on mid-sized
    /// scenes and further from the exact tree; 0 = AAC's reduction alone
    /// [default: 8192].
    #[arg(long, value_name = "N")]
    pub chunk_top: Option<u32>,
    /// Partitioned schedule: δ, the largest range of primitives grouped as one chunk (by the
    /// exact step, down to δ/2 bodies at ε = 0.5), at least 2; 0 = by the scene's size
    /// [default: 0, 2 with --fast]. By size: 4096 up to 2^18 primitives (close to the exact
    /// tree, the exact schedule's work spread over the threads), 4 above (faster). For speed
    /// on smaller scenes use --fast. Measurements: docs/benchmarks.md.
    #[arg(long, value_name = "N")]
    pub chunk_delta: Option<u32>,
    /// Partitioned schedule: ε of AAC's reduction f(n) = ⌈c·n^(1/2 − ε)⌉, c = δ^(1/2 + ε)/2,
    /// the bodies a node of n primitives leaves below the root share: 0.5 leaves δ/2 per node
    /// (1 with --fast), AAC's fast setting 0.2 more (slower)
    /// [default: 0.5].
    #[arg(long, value_name = "E")]
    pub chunk_epsilon: Option<f64>,
    /// Partitioned schedule: ranges of at most N primitives are cut where binned SAH on the
    /// best axis of their centres puts the cut, not at a Morton bit (which runs through
    /// clusters); 0 = Morton cuts throughout [default: 256].
    #[arg(long, value_name = "N")]
    pub chunk_sah: Option<u32>,
}

impl ChunkArgs {
    /// `chunking` with the flags that are set in its place: the one conversion from the
    /// `--chunk-*` flags.
    pub fn apply(&self, chunking: Chunking) -> Chunking {
        Chunking {
            top: self.chunk_top.unwrap_or(chunking.top),
            delta: self.chunk_delta.unwrap_or(chunking.delta),
            epsilon: self.chunk_epsilon.unwrap_or(chunking.epsilon),
            sah_below: self.chunk_sah.unwrap_or(chunking.sah_below),
            ..chunking
        }
    }

    /// The first flag that is set, if any (for errors naming it).
    pub fn first_set(&self) -> Option<&'static str> {
        [
            (self.chunk_top.is_some(), "--chunk-top"),
            (self.chunk_delta.is_some(), "--chunk-delta"),
            (self.chunk_epsilon.is_some(), "--chunk-epsilon"),
            (self.chunk_sah.is_some(), "--chunk-sah"),
        ]
        .into_iter()
        .find_map(|(set, flag)| set.then_some(flag))
    }
}

/// Builds the global rayon pool with `threads` threads (`--threads`; once per process, later
/// calls keep the first pool) and returns the number of threads it has.
pub fn build_pool(threads: Option<usize>) -> Result<usize> {
    if threads == Some(0) {
        anyhow::bail!("--threads must be at least 1, got 0");
    }
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        pool = pool.num_threads(n);
    }
    // Fails only when a pool exists already: that pool is then the one used.
    let _ = pool.build_global();
    Ok(rayon::current_num_threads())
}

impl Command {
    /// The `--threads` the command asks for, if it takes the option and was given it.
    fn threads(&self) -> Option<usize> {
        match self {
            Command::Group(c) => c.group.threads,
            Command::Record(c) => c.group.threads,
            Command::Snapshot(c) => c.group.threads,
            Command::Wrap(c) => c.group.threads,
            Command::Cover(c) => c.group.threads,
            Command::Bench(c) => c.threads,
            _ => None,
        }
    }
}

/// Runs the parsed command, its `--threads` pool built first, so that loading and every other
/// step before the grouping run on it too.
pub fn run(cli: Cli) -> Result<ExitCode> {
    // Installed before any work, so that a stop during loading is obeyed too.
    deadline::arm(wraptree::stop::Stop::on_signals());
    let threads = cli.command.threads();
    if threads.is_some() {
        build_pool(threads)?;
    }
    match cli.command {
        Command::Group(c) => progress::or_stopped("group", c.run()),
        Command::Record(c) => progress::or_stopped("record", c.run()),
        Command::Replay(c) => progress::or_stopped("replay", c.run()),
        Command::Compare(c) => progress::or_stopped("compare", c.run()),
        Command::Scene(c) => c.run(),
        Command::Bench(c) => progress::or_stopped("bench", c.run()),
        Command::Sweep(c) => progress::or_stopped("sweep", c.run()),
        Command::Snapshot(c) => progress::or_stopped("snapshot", c.run()),
        Command::Wrap(c) => progress::or_stopped("wrap", c.run()),
        Command::Cover(c) => progress::or_stopped("cover", c.run()),
        Command::Stress(c) => progress::or_stopped("stress", c.run()),
        Command::Spherize(c) => progress::or_stopped("spherize", c.run()),
    }
}
