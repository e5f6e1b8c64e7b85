//! `wraptree wrap`: group a scene, build the chosen Wrapper Trees and report how tightly each
//! fits, level by level, and whether it contains every vertex below each node
//! ([`wraptree::wrap::report`]).

use super::{GroupArgs, SceneArgs};
use anyhow::Result;
use clap::{Args, ValueEnum};
use std::process::ExitCode;
use std::time::Instant;
use wraptree::grouping;
use wraptree::wrap::report::{KindReport, report};
use wraptree::wrap::{DEFAULT_SAMPLES, SphereMethod, WrapperKind};

/// Arguments of `wraptree wrap`.
#[derive(Args, Debug)]
pub struct WrapCmd {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    group: GroupArgs,
    /// Wrapper Trees to build, comma-separated: sphere, hull, box (or aabb), obb.
    #[arg(long, default_value = "sphere,hull,box,obb", value_delimiter = ',', value_parser = WrapperKind::parse)]
    wrapper: Vec<WrapperKind>,
    /// How spheres are computed.
    #[arg(long, value_enum, default_value_t = SphereMethod::AabbCenter)]
    sphere_method: SphereMethod,
    /// Surface samples per wrapper for the error measure.
    #[arg(long, default_value_t = DEFAULT_SAMPLES as u32, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    samples: u32,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

/// The command-line name of `m`, e.g. `aabb-center`.
fn method_name(m: SphereMethod) -> String {
    m.to_possible_value()
        .map_or_else(|| format!("{m:?}"), |v| v.get_name().to_string())
}

/// Prints one kind's report as text.
fn print_kind(r: &KindReport, method: SphereMethod) {
    let name = match r.kind {
        WrapperKind::Sphere => format!("sphere ({})", method_name(method)),
        k => k.name().to_string(),
    };
    let c = &r.containment;
    println!(
        "\n{name}: built in {:.3} s; containment {}: max excess {:.3e} (worst node {:.3e} vs tolerance {:.3e}, {})",
        r.build_seconds,
        if c.holds { "holds" } else { "FAILS" },
        c.max_excess,
        c.excess_at_worst,
        c.tolerance_at_worst,
        c.tolerance_rule
    );
    println!(
        "{:>5} {:>7} {:>8} {:>12} {:>8} {:>11} {:>11}",
        "depth", "nodes", "interior", "volume", "ratio", "error max", "error mean"
    );
    for l in &r.levels {
        let ratio = l
            .volume_ratio
            .map_or_else(|| "-".to_string(), |v| format!("{v:.3}"));
        println!(
            "{:>5} {:>7} {:>8} {:>12.4e} {:>8} {:>11.4e} {:>11.4e}",
            l.depth, l.nodes, l.interior, l.volume, ratio, l.error_max, l.error_mean
        );
    }
}

impl WrapCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        let loaded = self.scene.load()?;
        let params = self.group.params()?;
        let scene = &loaded.scene;
        let start = Instant::now();
        let g = grouping::group(scene, &params, ());
        let group_seconds = start.elapsed().as_secs_f64();
        let tree = &g.tree;
        let samples = self.samples as usize;
        let reports = report(tree, scene, &self.wrapper, self.sphere_method, samples);
        if self.json {
            let out = serde_json::json!({
                "scene": scene.name,
                "primitives": scene.len(),
                "depth_max": tree.depth_max(),
                "grouping_seconds": group_seconds,
                "sphere_method": method_name(self.sphere_method),
                "samples": samples,
                "wrappers": reports,
            });
            println!("{out}");
        } else {
            println!(
                "{}: {} primitives, depth {}, grouped in {:.3} s; error from {samples} surface samples per wrapper",
                scene.name,
                scene.len(),
                tree.depth_max(),
                group_seconds
            );
            for r in &reports {
                print_kind(r, self.sphere_method);
            }
        }
        let failed: Vec<&str> = reports
            .iter()
            .filter(|r| !r.containment.holds)
            .map(|r| r.kind.name())
            .collect();
        if !failed.is_empty() {
            anyhow::bail!(
                "{}: containment fails for {} (a vertex lies outside its node's wrapper beyond the tolerance)",
                self.scene.scene.display(),
                failed.join(", ")
            );
        }
        Ok(ExitCode::SUCCESS)
    }
}
