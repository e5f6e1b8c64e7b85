//! `wraptree wrap`: group a scene, build the chosen Wrapper Trees and report how tightly each
//! fits, level by level, and whether it contains every vertex below each node
//! ([`wraptree::wrap::report`]).

use super::{GroupArgs, SceneArgs};
use anyhow::Result;
use clap::Args;
use std::process::ExitCode;
use std::time::Instant;
use wraptree::grouping;
use wraptree::stop::{Interrupted, Stop};
use wraptree::wrap::report::{Measured, report, report_json, report_text};
use wraptree::wrap::{DEFAULT_SAMPLES, NODES_PER_DEPTH, SphereMethod, WrapperKind};

/// Arguments of `wraptree wrap`.
#[derive(Args, Debug)]
pub struct WrapCmd {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    pub(super) group: GroupArgs,
    /// Wrapper Trees to build, comma-separated: sphere, hull, box (or aabb), obb.
    #[arg(long, default_value = "sphere,hull,box,obb", value_delimiter = ',', value_parser = WrapperKind::parse)]
    wrapper: Vec<WrapperKind>,
    /// How spheres are computed.
    #[arg(long, value_enum, default_value_t = SphereMethod::AabbCenter)]
    sphere_method: SphereMethod,
    /// Surface samples per wrapper for the error measure.
    #[arg(long, default_value_t = DEFAULT_SAMPLES as u32, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    samples: u32,
    /// Interior nodes per tree depth whose error is measured, drawn by a seeded hash, besides
    /// every leaf: a level's error mean is then an estimate, its max the largest measured;
    /// volumes and containment cover every node (0: every node's error, exact queries,
    /// longer).
    #[arg(long, value_name = "N", default_value_t = NODES_PER_DEPTH)]
    tightness_nodes: usize,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

impl WrapCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        let loaded = self.scene.load()?;
        let params = self.group.params()?;
        let scene = &loaded.scene;
        let start = Instant::now();
        let stop = Stop::on_signals();
        let resolved = params.resolve(scene);
        let bar = super::progress::spinner("wrap");
        bar.set_message("grouping");
        let g =
            grouping::group_until(scene, &resolved, (), stop.flag()).map_err(|_| Interrupted)?;
        let group_seconds = start.elapsed().as_secs_f64();
        let tree = &g.tree;
        let how = Measured {
            method: self.sphere_method,
            samples: self.samples as usize,
            per_depth: self.tightness_nodes,
        };
        bar.set_message("wrappers and their tightness");
        let reports = report(tree, scene, &self.wrapper, how, &stop);
        bar.finish_and_clear();
        let reports = reports?;
        let t = group_seconds;
        if self.json {
            println!("{}", report_json(scene, tree, t, how, &reports));
        } else {
            print!("{}", report_text(scene, tree, t, how, &reports));
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
