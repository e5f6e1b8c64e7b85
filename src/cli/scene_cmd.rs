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
    /// thin-triangles; or assembly (rigid copies of real parts, --part).
    kind: String,
    /// `assembly`: FILE:COUNT, COUNT rigid copies of the part in FILE (any scene format the
    /// loader reads) at its own scale, randomly rotated and placed apart; repeatable.
    #[arg(long, value_name = "FILE:COUNT")]
    part: Vec<String>,
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
        let (scene, bytes) = if self.kind == "assembly" {
            self.assembly()?
        } else {
            if !self.part.is_empty() {
                anyhow::bail!("--part needs the scene kind assembly, not '{}'", self.kind);
            }
            let scene =
                wraptree::scene::generate::by_name(&self.kind, self.copies, self.n, self.seed)
                    .map_err(|e| anyhow!(e))?;
            let mut bytes = Vec::new();
            scene.write_obj(&mut bytes)?;
            (scene, bytes)
        };
        status.set_message(format!("writing {}", self.output.display()));
        wraptree::output::write_atomic(&self.output, &bytes, self.force)?;
        drop(status);
        eprintln!(
            "wrote {} ({} primitives)",
            self.output.display(),
            scene.len()
        );
        Ok(ExitCode::SUCCESS)
    }

    /// The `assembly` scene of the `--part` specs and its OBJ text.
    fn assembly(&self) -> Result<(wraptree::scene::Scene, Vec<u8>)> {
        use wraptree::scene::assembly::{assemble, load_part};
        if self.part.is_empty() {
            anyhow::bail!("scene kind assembly needs at least one --part FILE:COUNT");
        }
        if self.copies.is_some() || self.n.is_some() {
            anyhow::bail!("scene kind assembly takes its counts from --part FILE:COUNT");
        }
        let parts = self
            .part
            .iter()
            .map(|p| load_part(p))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| anyhow!(e))?;
        let (scene, names) = assemble(&parts, self.seed).map_err(|e| anyhow!(e))?;
        let what = format!("wraptree scene assembly --seed {}", self.seed);
        let bytes = wraptree::scene::export::obj_text(&scene, &names, &what);
        Ok((scene, bytes))
    }
}
