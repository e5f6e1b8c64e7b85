//! `wraptree cover`: the fewest wrappers that model a scene within an error, or the best K
//! (see [`wraptree::wrap::cover`]); writes `OUT.json` and `OUT.obj`.

use super::{GroupArgs, SceneArgs};
use anyhow::{Context, Result, bail};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use wraptree::grouping;
use wraptree::record::output::write_atomic;
use wraptree::wrap::cover::{self, Fits, LevelRow, export};
use wraptree::wrap::{DEFAULT_SAMPLES, SphereMethod, WrapperKind, Wrappers};

/// A tolerance: a length in scene units, or `P%` of the scene diagonal.
#[derive(Clone, Copy, Debug)]
pub enum Tolerance {
    /// A length in scene units.
    Abs(f64),
    /// A fraction of the scene diagonal.
    Rel(f64),
}

impl Tolerance {
    /// The length for a scene of diagonal `diagonal`.
    pub fn length(self, diagonal: f64) -> f64 {
        match self {
            Tolerance::Abs(t) => t,
            Tolerance::Rel(r) => r * diagonal,
        }
    }
}

/// Parses `--tolerance`: a length ≥ 0, or `P%` of the scene diagonal.
pub(super) fn parse_tolerance(s: &str) -> Result<Tolerance, String> {
    let bad = || format!("invalid tolerance '{s}' (want a length ≥ 0, or P% of the diagonal)");
    let t = s.trim();
    let (num, rel) = match t.strip_suffix('%') {
        Some(n) => (n, true),
        None => (t, false),
    };
    let v: f64 = num.trim().parse().map_err(|_| bad())?;
    if !(v.is_finite() && v >= 0.0) {
        return Err(bad());
    }
    Ok(if rel {
        Tolerance::Rel(v / 100.0)
    } else {
        Tolerance::Abs(v)
    })
}

/// Arguments of `wraptree cover`.
#[derive(Args, Debug)]
#[command(group(clap::ArgGroup::new("limit").required(true).args(["tolerance", "budget"])))]
pub struct CoverCmd {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    group: GroupArgs,
    /// Largest allowed error per wrapper: a length in scene units, or P% of the scene diagonal.
    #[arg(long, value_parser = parse_tolerance, allow_negative_numbers = true)]
    tolerance: Option<Tolerance>,
    /// Largest number of wrappers; the cover minimises the largest error.
    #[arg(long)]
    budget: Option<usize>,
    /// Wrapper kinds to choose from, comma-separated: sphere, box (or aabb), obb, hull.
    #[arg(long, default_value = "sphere,box,hull", value_delimiter = ',', value_parser = WrapperKind::parse)]
    kinds: Vec<WrapperKind>,
    /// Output prefix: writes OUT.json and OUT.obj [default: recordings/<scene stem>-cover].
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Replace existing files.
    #[arg(long)]
    force: bool,
    /// Print the summary as one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

/// The JSON file: the run, the cover and its wrappers, and the level comparison.
#[derive(serde::Serialize)]
struct Output<'a> {
    scene: &'a str,
    primitives: usize,
    diagonal: f64,
    kinds: Vec<&'static str>,
    sphere_method: SphereMethod,
    samples: usize,
    query_costs: &'static str,
    tolerance: f64,
    budget: Option<usize>,
    size: usize,
    max_error: f64,
    total_cost: f64,
    seconds: f64,
    levels: &'a [LevelRow],
    wrappers: Vec<export::WrapperRecord>,
}

impl CoverCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        if self.budget == Some(0) {
            bail!("--budget must be ≥ 1 (a cover needs at least one wrapper)");
        }
        let loaded = self.scene.load()?;
        let scene = &loaded.scene;
        let params = self.group.params()?;
        let prefix = super::record::output_prefix(
            self.output.as_deref(),
            &loaded.source.file_name,
            "-cover",
        )?;
        let json_path = super::record::with_ext(&prefix, ".json");
        let obj_path = super::record::with_ext(&prefix, ".obj");
        let input = std::fs::canonicalize(&self.scene.scene).ok();
        for p in [&json_path, &obj_path] {
            if input.is_some() && std::fs::canonicalize(p).ok() == input {
                bail!("{}: is the input scene; choose another -o", p.display());
            }
            if p.exists() && !self.force {
                bail!(
                    "{}: already exists (use --force to replace it)",
                    p.display()
                );
            }
        }
        let start = Instant::now();
        let g = grouping::group(scene, &params, ());
        let tree = &g.tree;
        let method = SphereMethod::Minimum;
        let mut build = self.kinds.clone();
        if !build.contains(&WrapperKind::Hull) {
            build.push(WrapperKind::Hull);
        }
        let mut wrappers = Wrappers::build(tree, scene, &build, method);
        let hulls = if self.kinds.contains(&WrapperKind::Hull) {
            None
        } else {
            wrappers.hulls.take()
        };
        let fits = Fits::measure(tree, scene, &wrappers, hulls.as_deref(), DEFAULT_SAMPLES);
        let diagonal = scene.aabb().diameter();
        let c = match (self.tolerance, self.budget) {
            (Some(t), _) => fits.cover_tolerance(tree, t.length(diagonal)),
            (None, Some(k)) => fits.cover_budget(tree, k).map_err(anyhow::Error::msg)?,
            (None, None) => bail!("give --tolerance or --budget"),
        };
        let levels = cover::compare_levels(tree, &fits.best);
        let seconds = start.elapsed().as_secs_f64();
        let records = export::records(&c, tree, scene, &wrappers);
        let obj = export::to_obj(&records, &scene.name);
        let out = Output {
            scene: &scene.name,
            primitives: scene.len(),
            diagonal,
            kinds: self.kinds.iter().map(|k| k.name()).collect(),
            sphere_method: method,
            samples: DEFAULT_SAMPLES,
            query_costs: "sphere 1, box 2, obb 3, hull/primitive 4 + vertices/16",
            tolerance: c.tolerance,
            budget: self.budget,
            size: c.nodes.len(),
            max_error: c.max_error(),
            total_cost: c.cost(),
            seconds,
            levels: &levels,
            wrappers: records,
        };
        let json = serde_json::to_vec_pretty(&out).context("cover: cannot serialise")?;
        write_atomic(&json_path, &json, self.force)?;
        write_atomic(&obj_path, obj.as_bytes(), self.force)?;
        if self.json {
            let mut v = serde_json::to_value(&out).context("cover: cannot serialise")?;
            if let Some(m) = v.as_object_mut() {
                m.remove("wrappers");
                m.insert("json".into(), json_path.display().to_string().into());
                m.insert("obj".into(), obj_path.display().to_string().into());
            }
            println!("{v}");
        } else {
            print_text(&out, &levels);
            println!("wrote {} and {}", json_path.display(), obj_path.display());
        }
        Ok(ExitCode::SUCCESS)
    }
}

fn print_text(o: &Output<'_>, levels: &[LevelRow]) {
    let mut count = std::collections::BTreeMap::new();
    for w in &o.wrappers {
        *count.entry(w.node.choice.kind.name()).or_insert(0usize) += 1;
    }
    let kinds: Vec<String> = count.iter().map(|(k, n)| format!("{n} {k}")).collect();
    println!(
        "{}: {} primitives, diagonal {:.4e}; kinds {}",
        o.scene,
        o.primitives,
        o.diagonal,
        o.kinds.join(",")
    );
    match o.budget {
        Some(k) => println!(
            "budget {k}: smallest achievable max error {:.4e}",
            o.tolerance
        ),
        None => println!("tolerance {:.4e}", o.tolerance),
    }
    println!(
        "cover       {} wrappers ({}), max error {:.4e}, query cost {:.1}",
        o.size,
        kinds.join(", "),
        o.max_error,
        o.total_cost
    );
    println!("depth  level nodes  level max error  cover nodes  ratio");
    for r in levels {
        println!(
            "{:>5}  {:>11}  {:>15.4e}  {:>11}  {:>5.1}",
            r.depth,
            r.level_nodes,
            r.level_max_error,
            r.cover_nodes,
            r.level_nodes as f64 / r.cover_nodes.max(1) as f64
        );
    }
}
