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
use wraptree::wrap::report::{report, report_json, report_text};
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
        let samples = self.samples as usize;
        bar.set_message("wrappers and their tightness");
        let reports = report(tree, scene, &self.wrapper, self.sphere_method, samples);
        bar.finish_and_clear();
        stop.check()?;
        let (m, t) = (self.sphere_method, group_seconds);
        if self.json {
            println!("{}", report_json(scene, tree, t, m, samples, &reports));
        } else {
            print!("{}", report_text(scene, tree, t, m, samples, &reports));
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
