//! Argument definitions and dispatch for every subcommand.

mod bench;
mod cover;
mod group;
mod record;
mod replay;
mod scene_cmd;
mod snapshot;
mod wrap_cmd;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use wraptree::grouping::{PSet, Params, Weights};
use wraptree::scene::{LoadOptions, Loaded};

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
    /// Run the grouping phase on a scene and print the Subset Tree's summary.
    Group(group::GroupCmd),
    /// Group a scene step by step and record it to PREFIX.rrd (Rerun) and PREFIX.mcap (Foxglove).
    Record(record::RecordCmd),
    /// Rebuild a run from its .mcap; --verify re-runs it; --a/--b/--c re-weights it.
    Replay(replay::ReplayCmd),
    /// Generate a seeded synthetic scene as Wavefront OBJ.
    Scene(scene_cmd::SceneCmd),
    /// Time the grouping phase on the standard scenes (12,144-polygon robot bases, soups).
    Bench(bench::BenchCmd),
    /// Render the input and chosen tree levels as PNG/SVG frames and a figure sheet.
    Snapshot(snapshot::SnapshotCmd),
    /// Build Wrapper Trees and print their per-level tightness and containment check.
    Wrap(wrap_cmd::WrapCmd),
    /// The fewest wrappers that model a scene within --tolerance, or the best --budget of them.
    Cover(cover::CoverCmd),
}

/// How to read a scene file.
#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Wavefront OBJ file.
    pub scene: PathBuf,
    /// Treat each OBJ object/group as one convex polyhedron (default: each face is a polygon).
    #[arg(long)]
    pub polyhedra: bool,
    /// With --polyhedra: a group whose vertices are not in convex position is an error.
    #[arg(long)]
    pub strict: bool,
}

impl SceneArgs {
    /// Loads the scene, printing loader warnings to stderr.
    pub fn load(&self) -> Result<Loaded> {
        let opts = LoadOptions {
            polyhedra: self.polyhedra,
            strict: self.strict,
        };
        let loaded = wraptree::scene::load_path(&self.scene, &opts)?;
        for w in &loaded.warnings {
            eprintln!("warning: {w}");
        }
        Ok(loaded)
    }
}

/// Parameters of the grouping phase (§2.2).
#[derive(Args, Debug, Clone)]
pub struct GroupArgs {
    /// Cost exponent A in Cost = diameter^A × (B·Fill + C·Balance).
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
}

impl GroupArgs {
    /// Checks the values and turns them into [`Params`].
    pub fn params(&self) -> Result<Params> {
        let weights = Weights {
            a: self.a,
            b: self.b,
            c: self.c,
        };
        weights.check().map_err(|e| anyhow::anyhow!("--{e}"))?;
        for (name, v) in [("--dlimit", self.dlimit), ("--glimit", self.glimit)] {
            if let Some(v) = v
                && !(v.is_finite() && v > 0.0)
            {
                anyhow::bail!("{name} must be a finite number > 0, got {v}");
            }
        }
        Ok(Params {
            weights,
            dlimit: self.dlimit,
            glimit: self.glimit,
            pset: self.pset,
            seed: self.seed,
        })
    }
}

/// Runs the parsed command.
pub fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Command::Group(c) => c.run(),
        Command::Record(c) => c.run(),
        Command::Replay(c) => c.run(),
        Command::Scene(c) => c.run(),
        Command::Bench(c) => c.run(),
        Command::Snapshot(c) => c.run(),
        Command::Wrap(c) => c.run(),
        Command::Cover(c) => c.run(),
    }
}

/// Peak resident memory of this process in bytes (Linux `VmHWM`), if known.
pub fn peak_rss_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
