//! `wraptree scene`: write a generated scene as OBJ.

use anyhow::{Result, anyhow};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `wraptree scene`.
#[derive(Args, Debug)]
pub struct SceneCmd {
    /// robot-base (276 polygons), lamp (626), lamps (lamp × --copies, default 5),
    /// robot-bases (robot base × --copies, default 44), soup (-n triangles), or a
    /// pathological kind (-n primitives): spaghetti-parallel, spaghetti-random, slabs,
    /// coincident, duplicates, coplanar, collinear, offset, scales, ngons, two-clusters,
    /// thin-triangles.
    kind: String,
    /// Copies for `lamps` and `robot-bases`.
    #[arg(long)]
    copies: Option<usize>,
    /// Triangle count for `soup`, primitive count for the pathological kinds.
    #[arg(short)]
    n: Option<usize>,
    /// Seed for placement and soups.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output OBJ file.
    #[arg(short, long)]
    output: PathBuf,
    /// Replace an existing file.
    #[arg(long)]
    force: bool,
}

impl SceneCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        let status = super::progress::Status::new("scene", "generating");
        let scene = wraptree::scene::generate::by_name(&self.kind, self.copies, self.n, self.seed)
            .map_err(|e| anyhow!(e))?;
        status.set_message(format!("writing {}", self.output.display()));
        let mut bytes = Vec::new();
        scene.write_obj(&mut bytes)?;
        wraptree::output::write_atomic(&self.output, &bytes, self.force)?;
        drop(status);
        eprintln!(
            "wrote {} ({} primitives)",
            self.output.display(),
            scene.len()
        );
        Ok(ExitCode::SUCCESS)
    }
}
