//! `wraptree cover`: the fewest wrappers that model a scene within an error, or the best K
//! (see [`wraptree::wrap::cover`]); writes `OUT.json` and `OUT.obj`.

use super::{GroupArgs, SceneArgs};
use anyhow::{Context, Result, bail};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use wraptree::output::{check_new, output_prefix, with_ext, write_atomic};
use wraptree::wrap::WrapperKind;
use wraptree::wrap::cover::export;
use wraptree::wrap::cover::solve::{CoverLimit, Tolerance, cover_scene};

/// Arguments of `wraptree cover`.
#[derive(Args, Debug)]
#[command(group(clap::ArgGroup::new("limit").required(true).args(["tolerance", "budget"])))]
pub struct CoverCmd {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    pub(super) group: GroupArgs,
    /// Largest allowed error per wrapper: a length in scene units, or P% of the scene diagonal.
    #[arg(long, value_parser = Tolerance::parse, allow_negative_numbers = true)]
    tolerance: Option<Tolerance>,
    /// Largest number of wrappers; the cover minimises the largest error.
    #[arg(long)]
    budget: Option<usize>,
    /// Wrapper kinds to choose from, comma-separated: sphere, box (or aabb), obb, hull.
    #[arg(long, default_value = "sphere,box,hull", value_delimiter = ',', value_parser = WrapperKind::parse)]
    kinds: Vec<WrapperKind>,
    /// Output prefix: writes OUT.json and OUT.obj [default: recordings/<scene stem>-cover]; the
    /// prefix's directory must exist.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Replace existing files.
    #[arg(long)]
    force: bool,
    /// Print the summary as one JSON object instead of text.
    #[arg(long)]
    json: bool,
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
        let prefix = output_prefix(self.output.as_deref(), &loaded.source.file_name, "-cover")?;
        let (json_path, obj_path) = (with_ext(&prefix, ".json"), with_ext(&prefix, ".obj"));
        check_new(&[&json_path, &obj_path], &self.scene.scene, self.force)?;
        let Some(limit) = CoverLimit::from_flags(self.tolerance, self.budget) else {
            bail!("give --tolerance or --budget");
        };
        let stop = wraptree::stop::Stop::on_signals();
        let bar = super::progress::spinner("cover");
        let out = cover_scene(scene, &params, limit, &self.kinds, &stop);
        bar.finish_and_clear();
        let out = out?;
        let json = serde_json::to_vec_pretty(&out).context("cover: cannot serialise")?;
        write_atomic(&json_path, &json, self.force)?;
        let obj = export::to_obj(&out.wrappers, &scene.name);
        write_atomic(&obj_path, obj.as_bytes(), self.force)?;
        if self.json {
            println!("{}", out.to_json(&json_path, &obj_path)?);
        } else {
            print!("{}", out.text());
            println!("wrote {} and {}", json_path.display(), obj_path.display());
        }
        Ok(ExitCode::SUCCESS)
    }
}
