//! `wraptree snapshot`: headless figures like the paper's Figures 1–4 (PNG and SVG).

use super::{GroupArgs, SceneArgs};
use anyhow::{Context, Result, bail};
use clap::Args;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use wraptree::grouping::{self, EventLog, Params, ResolvedParams, SubsetTree};
use wraptree::record::mcap::read_recording;
use wraptree::record::output::Pending;
use wraptree::render::{self, Frame, View};
use wraptree::scene::{Scene, load_bytes};
use wraptree::wrap::{SphereMethod, WrapperKind, Wrappers};

/// What a kind is called in titles and captions.
fn kind_title(k: WrapperKind) -> &'static str {
    match k {
        WrapperKind::Sphere => "bounding-sphere",
        WrapperKind::Hull => "convex-hull",
        WrapperKind::Box => "box",
        WrapperKind::Obb => "oriented-box",
    }
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("invalid size '{s}' (want WxH with each 64..=8192, e.g. 800x600)");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if !(64..=8192).contains(&w) || !(64..=8192).contains(&h) {
        return Err(bad());
    }
    Ok((w, h))
}

fn parse_angle(s: &str, lo: f64, hi: f64) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| (lo..=hi).contains(v))
        .ok_or_else(|| format!("want degrees in {lo}..={hi}, got '{s}'"))
}

/// Arguments of `wraptree snapshot`.
#[derive(Args, Debug)]
pub struct SnapshotCmd {
    /// The scene (Wavefront OBJ), or a `.mcap` recording: then its embedded scene is re-grouped
    /// with its recorded parameters (loading and grouping flags do not apply).
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    group: GroupArgs,
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
    /// Output directory (created if missing).
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
fn load(cmd: &SnapshotCmd) -> Result<(Scene, ResolvedParams, Option<Vec<grouping::Merge>>)> {
    let path = &cmd.scene.scene;
    let is_mcap = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"));
    if !is_mcap {
        let loaded = cmd.scene.load()?;
        let params = cmd.group.params()?.resolve(&loaded.scene);
        return Ok((loaded.scene, params, None));
    }
    if cmd.scene.polyhedra || cmd.scene.strict || cmd.group.params()? != Params::default() {
        bail!(
            "{}: loading and grouping flags do not apply to a recording (it carries its own)",
            path.display()
        );
    }
    let rec = read_recording(path)?;
    let loaded = load_bytes(
        &rec.scene_file_name,
        rec.scene_bytes.clone(),
        &rec.load_options,
    )
    .map_err(|e| anyhow::anyhow!("{}: embedded scene: {e}", path.display()))?;
    let merges = (rec.complete && rec.detail.merges()).then_some(rec.merges);
    Ok((loaded.scene, rec.params, merges))
}

/// Levels to draw, validated against the tree; repeats dropped, order kept.
fn choose_levels(cmd: &SnapshotCmd, tree: &SubsetTree) -> Result<Vec<u32>> {
    let dmax = tree.depth_max();
    let counts = render::level_counts(tree);
    let mut levels = cmd.levels.clone();
    if levels.is_empty() {
        let n = tree.leaves() as f64;
        let targets = if cmd.nodes.is_empty() {
            vec![(0.9 * n).round() as usize, (0.4 * n).round() as usize, 8]
        } else {
            cmd.nodes.clone()
        };
        levels = targets
            .iter()
            .map(|&k| render::level_for_nodes(&counts, k))
            .collect();
    }
    if let Some(bad) = levels.iter().find(|&&d| d > dmax) {
        bail!("level {bad} is beyond the tree's depth (max depth {dmax}: valid levels 0..={dmax})");
    }
    let mut seen = Vec::new();
    levels.retain(|d| {
        let new = !seen.contains(d);
        seen.push(*d);
        new
    });
    Ok(levels)
}

/// The destinations of `names` in `dir`, each as a `.png`/`.svg` pair, all checked before any
/// is written so an existing file without `--force` stops the run before it writes anything.
fn pendings(dir: &Path, names: &[String], force: bool) -> Result<Vec<(Pending, Pending)>> {
    names
        .iter()
        .map(|n| {
            Ok((
                Pending::create(&dir.join(format!("{n}.png")), force)?,
                Pending::create(&dir.join(format!("{n}.svg")), force)?,
            ))
        })
        .collect()
}

fn write(p: Pending, bytes: &[u8]) -> Result<PathBuf> {
    use std::io::Write;
    let dest = p.dest().to_path_buf();
    p.file()?
        .write_all(bytes)
        .with_context(|| format!("{}: write failed", dest.display()))?;
    p.commit()
}

impl SnapshotCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        let (scene, params, recorded) = load(&self)?;
        let mut log = EventLog::default();
        let never = AtomicBool::new(false);
        let g = grouping::group_until(&scene, &params, &mut log, &never)
            .map_err(|_| anyhow::anyhow!("grouping stopped unexpectedly"))?;
        if let Some(m) = recorded
            && m != log.merges
        {
            eprintln!(
                "warning: re-grouping the recorded scene differs from the recording; drawing the re-run"
            );
        }
        let tree = &g.tree;
        let levels = choose_levels(&self, tree)?;
        let mut kinds: Vec<WrapperKind> = Vec::new();
        for k in &self.wrapper {
            if !kinds.contains(k) {
                kinds.push(*k);
            }
        }
        let built = Wrappers::build(tree, &scene, &kinds, SphereMethod::AabbCenter);
        let mut frames: Vec<Frame> = vec![render::input_frame(&scene)];
        let mut names = vec!["frame-00-input".to_string()];
        for &kind in &kinds {
            let w = built
                .get(kind)
                .with_context(|| format!("no {} Wrapper Tree was built", kind.name()))?;
            for &d in &levels {
                let mut f = render::level_frame(&scene, tree, d, &|x| render::wrapper_shape(w, x));
                let mut name = format!("frame-{:02}-level-{d}", frames.len());
                if kinds.len() > 1 || kind != WrapperKind::Sphere {
                    f.caption.push_str(&format!(" · {}s", kind.name()));
                    name.push_str(&format!("-{}", kind.name()));
                }
                frames.push(f);
                names.push(name);
            }
        }
        names.push("figure".into());
        let (az0, el0) = self.view.angles();
        let (az, el) = (self.azimuth.unwrap_or(az0), self.elevation.unwrap_or(el0));
        let cam = render::fit_camera(&frames, az, el, self.size);
        std::fs::create_dir_all(&self.output)
            .with_context(|| format!("{}: cannot create the directory", self.output.display()))?;
        let outs = pendings(&self.output, &names, self.force)?;
        let kind = kinds
            .iter()
            .map(|&k| kind_title(k))
            .collect::<Vec<_>>()
            .join(" / ");
        let title = format!(
            "{} · {kind} Wrapper Tree · depth {}",
            scene.name,
            tree.depth_max()
        );
        let mut svgs: Vec<String> = frames.iter().map(|f| render::frame_svg(f, &cam)).collect();
        svgs.push(render::sheet_svg(
            &frames,
            &cam,
            render::sheet_columns(frames.len()),
            &title,
        ));
        for ((png, svg), text) in outs.into_iter().zip(&svgs) {
            let dest = png.dest().display().to_string();
            let bytes = render::svg_to_png(text).map_err(|e| anyhow::anyhow!("{dest}: {e}"))?;
            let p = write(png, &bytes)?;
            let s = write(svg, text.as_bytes())?;
            println!("  {} + {}", p.display(), s.display());
        }
        let captions: Vec<&str> = frames.iter().map(|f| f.caption.as_str()).collect();
        println!(
            "{}: {} primitives, depth {}; frames: {}",
            scene.name,
            scene.len(),
            tree.depth_max(),
            captions.join(" | ")
        );
        Ok(ExitCode::SUCCESS)
    }
}
