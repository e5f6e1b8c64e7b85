//! `wraptree snapshot`: headless figures like the paper's Figures 1–4 (PNG and SVG;
//! [`wraptree::render::snapshot`]).

use super::{GroupArgs, SceneArgs};
use anyhow::{Result, bail};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use wraptree::grouping::{Merge, Params, ResolvedParams};
use wraptree::render::View;
use wraptree::render::snapshot::{
    SnapshotOptions, draw, from_recording, parse_angle, parse_size, regroup,
};
use wraptree::scene::Scene;
use wraptree::wrap::WrapperKind;

/// Arguments of `wraptree snapshot`.
#[derive(Args, Debug)]
pub struct SnapshotCmd {
    /// The scene (Wavefront OBJ), or a `.mcap` recording: then its embedded scene is re-grouped
    /// with its recorded parameters (loading and grouping flags do not apply).
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    pub(super) group: GroupArgs,
    /// Tree levels to draw (depths, root = 0), e.g. 3,6,9.
    #[arg(long, value_delimiter = ',', conflicts_with = "nodes")]
    levels: Vec<u32>,
    /// Draw the levels whose node counts are closest to these, e.g. 251,104,8
    /// [default: 90 % and 40 % of the primitives, and 8].
    #[arg(long, value_delimiter = ',')]
    nodes: Vec<usize>,
    /// Wrappers drawn for interior nodes: sphere, hull, box (or aabb), obb; a comma list draws
    /// the levels once per kind.
    #[arg(long, default_value = "sphere", value_delimiter = ',', value_parser = WrapperKind::parse)]
    wrapper: Vec<WrapperKind>,
    /// Output directory, created with its parents if missing.
    #[arg(short, long)]
    output: PathBuf,
    /// View direction: iso, front, side or top (orthographic camera, Z up).
    #[arg(long, default_value = "iso", value_parser = View::parse)]
    view: View,
    /// Eye azimuth in degrees around +Z, from −Y (overrides --view's).
    #[arg(long, allow_negative_numbers = true, value_parser = |s: &str| parse_angle(s, -360.0, 360.0))]
    azimuth: Option<f64>,
    /// Eye elevation in degrees above the XY plane, −90..=90 (overrides --view's).
    #[arg(long, allow_negative_numbers = true, value_parser = |s: &str| parse_angle(s, -90.0, 90.0))]
    elevation: Option<f64>,
    /// Size of one frame's picture in pixels, WxH (the caption band is added below).
    #[arg(long, default_value = "800x600", value_parser = parse_size)]
    size: (u32, u32),
    /// Replace existing images.
    #[arg(long)]
    force: bool,
}

/// The scene and parameters to draw, from a scene file or a recording.
fn load(cmd: &SnapshotCmd) -> Result<(Scene, ResolvedParams, Option<Vec<Merge>>)> {
    let path = &cmd.scene.scene;
    let is_mcap = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"));
    if !is_mcap {
        let loaded = cmd.scene.load()?;
        let params = cmd.group.params()?.resolve(&loaded.scene);
        return Ok((loaded.scene, params, None));
    }
    if cmd.scene.has_load_flags() || cmd.group.params()? != Params::default() {
        bail!(
            "{}: loading and grouping flags do not apply to a recording (it carries its own)",
            path.display()
        );
    }
    from_recording(path, &wraptree::stop::Stop::on_signals())
}

impl SnapshotCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        let stop = wraptree::stop::Stop::on_signals();
        let (scene, params, recorded) = load(&self)?;
        let status = super::progress::Status::new("snapshot", "grouping");
        let (g, differs) = regroup(&scene, &params, recorded.as_deref(), &stop)?;
        if differs {
            status.suspend(|| {
                eprintln!(
                    "warning: re-grouping the recorded scene differs from the recording; drawing the re-run"
                )
            });
        }
        status.set_message("building wrappers and drawing the frames");
        let (az0, el0) = self.view.angles();
        let opts = SnapshotOptions {
            levels: self.levels,
            nodes: self.nodes,
            kinds: self.wrapper,
            azimuth: self.azimuth.unwrap_or(az0),
            elevation: self.elevation.unwrap_or(el0),
            size: self.size,
            force: self.force,
        };
        let s = draw(&scene, &g.tree, &opts, &self.output, &stop)?;
        drop(status);
        print!("{}", s.text(&scene, &g.tree));
        Ok(ExitCode::SUCCESS)
    }
}
