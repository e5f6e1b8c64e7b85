//! Snapshots (`wraptree snapshot`): the input and chosen tree levels of a grouping drawn as
//! PNG + SVG frames and one figure sheet, like the paper's Figures 1–4.
//!
//! ```no_run
//! use wraptree::grouping::Params;
//! use wraptree::render::snapshot::{SnapshotOptions, draw, regroup};
//! use wraptree::stop::Stop;
//! let loaded = wraptree::scene::load_path("scenes/lamp.obj".as_ref(), &Default::default())?;
//! let params = Params::default().resolve(&loaded.scene);
//! let stop = Stop::new();
//! let (g, _) = regroup(&loaded.scene, &params, None, &stop)?;
//! let s = draw(&loaded.scene, &g.tree, &SnapshotOptions::default(), "/tmp/lamp-figures".as_ref(), &stop)?;
//! println!("{}", s.captions.join(" | "));
//! # Ok::<(), anyhow::Error>(())
//! ```

use super::frames::{Look, write_frames};
use super::{Frame, View};
use crate::grouping::{self, EventLog, Grouping, Merge, ResolvedParams, SubsetTree};
use crate::replay;
use crate::scene::Scene;
use crate::stop::{Interrupted, Stop};
use crate::wrap::{SphereMethod, WrapperKind, Wrappers};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};

/// What a kind is called in titles and captions.
fn kind_title(k: WrapperKind) -> &'static str {
    match k {
        WrapperKind::Sphere => "bounding-sphere",
        WrapperKind::Hull => "convex-hull",
        WrapperKind::Box => "box",
        WrapperKind::Obb => "oriented-box",
    }
}

/// What to draw and how.
#[derive(Clone, Debug, PartialEq)]
pub struct SnapshotOptions {
    /// Tree levels to draw (depths, root = 0); when empty, the levels whose node counts are
    /// closest to `nodes`.
    pub levels: Vec<u32>,
    /// Node counts to pick levels by; when empty too, 90 % and 40 % of the primitives, and 8.
    pub nodes: Vec<usize>,
    /// Wrappers drawn for interior nodes; several draw the levels once per kind.
    pub kinds: Vec<WrapperKind>,
    /// Eye azimuth in degrees around +Z, from −Y.
    pub azimuth: f64,
    /// Eye elevation in degrees above the XY plane.
    pub elevation: f64,
    /// Size of one frame's picture in pixels (the caption band is added below).
    pub size: (u32, u32),
    /// Replace existing images.
    pub force: bool,
}

impl Default for SnapshotOptions {
    /// Default levels, spheres, the iso view, 800 × 600.
    fn default() -> Self {
        let (azimuth, elevation) = View::Iso.angles();
        SnapshotOptions {
            levels: Vec::new(),
            nodes: Vec::new(),
            kinds: vec![WrapperKind::Sphere],
            azimuth,
            elevation,
            size: (800, 600),
            force: false,
        }
    }
}

/// The embedded scene and parameters of the `.mcap` recording at `path` (read through
/// [`replay::open_until`], obeying `stop`), and its merges when it is complete and holds them.
pub fn from_recording(
    path: &Path,
    stop: &Stop,
) -> Result<(Scene, ResolvedParams, Option<Vec<Merge>>)> {
    let replay::Replay { rec, loaded } = replay::open_until(path, stop)?;
    let merges = (rec.complete && rec.detail.merges()).then_some(rec.merges);
    Ok((loaded.scene, rec.params, merges))
}

/// Groups `scene` with `params`; also says whether its merges make another decision than
/// `recorded`, when given ([`replay::first_divergence`]: the MPairs length is not compared).
/// Fails with [`Interrupted`] when `stop` is requested during the grouping.
pub fn regroup(
    scene: &Scene,
    params: &ResolvedParams,
    recorded: Option<&[Merge]>,
    stop: &Stop,
) -> Result<(Grouping, bool)> {
    let Some(recorded) = recorded else {
        let g = grouping::group_until(scene, params, (), stop.flag()).map_err(|_| Interrupted)?;
        return Ok((g, false));
    };
    let mut log = EventLog::default();
    let g = grouping::group_until(scene, params, &mut log, stop.flag()).map_err(|_| Interrupted)?;
    let differs = replay::first_divergence(recorded, &log.merges).is_some();
    Ok((g, differs))
}

/// Levels to draw (see [`SnapshotOptions::levels`]), validated against the tree; repeats
/// dropped, order kept.
pub fn choose_levels(tree: &SubsetTree, levels: &[u32], nodes: &[usize]) -> Result<Vec<u32>> {
    let dmax = tree.depth_max();
    let counts = super::level_counts(tree);
    let mut levels = levels.to_vec();
    if levels.is_empty() {
        let n = tree.leaves() as f64;
        let targets = if nodes.is_empty() {
            vec![(0.9 * n).round() as usize, (0.4 * n).round() as usize, 8]
        } else {
            nodes.to_vec()
        };
        levels = targets
            .iter()
            .map(|&k| super::level_for_nodes(&counts, k))
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

/// What [`draw`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    /// The (PNG, SVG) pair of every frame, then of the figure sheet.
    pub written: Vec<(PathBuf, PathBuf)>,
    /// Every frame's caption.
    pub captions: Vec<String>,
}

impl Snapshot {
    /// What `wraptree snapshot` prints: each frame's files, a line each, then `scene` and
    /// `tree` in one line with the frames' captions.
    pub fn text(&self, scene: &Scene, tree: &SubsetTree) -> String {
        let mut s = String::new();
        for (p, v) in &self.written {
            s.push_str(&format!("  {} + {}\n", p.display(), v.display()));
        }
        s.push_str(&format!(
            "{}: {} primitives, depth {}; frames: {}\n",
            scene.name,
            scene.len(),
            tree.depth_max(),
            self.captions.join(" | ")
        ));
        s
    }
}

/// Parses a frame size `WxH` (`--size`), each side in 64..=8192.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
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

/// Parses an angle in degrees within `lo..=hi` (`--azimuth`, `--elevation`).
pub fn parse_angle(s: &str, lo: f64, hi: f64) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| (lo..=hi).contains(v))
        .ok_or_else(|| format!("want degrees in {lo}..={hi}, got '{s}'"))
}

/// Draws the input and the chosen levels of `tree` over `scene` into `dir` (created with its
/// parents if missing): `frame-NN-….{png,svg}` per frame and `figure.{png,svg}`, the sheet of
/// them all. Every picture is drawn before any file is moved into place, and `stop` is obeyed
/// while the wrappers are built and between the pictures ([`Interrupted`], nothing written).
pub fn draw(
    scene: &Scene,
    tree: &SubsetTree,
    opts: &SnapshotOptions,
    dir: &Path,
    stop: &Stop,
) -> Result<Snapshot> {
    let levels = choose_levels(tree, &opts.levels, &opts.nodes)?;
    let mut kinds: Vec<WrapperKind> = Vec::new();
    for k in &opts.kinds {
        if !kinds.contains(k) {
            kinds.push(*k);
        }
    }
    let built = Wrappers::build_until(tree, scene, &kinds, SphereMethod::AabbCenter, stop)?;
    let mut frames: Vec<Frame> = vec![super::input_frame(scene)];
    let mut names = vec!["frame-00-input".to_string()];
    for &kind in &kinds {
        let w = built
            .get(kind)
            .with_context(|| format!("no {} Wrapper Tree was built", kind.name()))?;
        for &d in &levels {
            stop.check()?;
            let mut f = super::level_frame(scene, tree, d, &|x| super::wrapper_shape(w, x));
            let mut name = format!("frame-{:02}-level-{d}", frames.len());
            if kinds.len() > 1 || kind != WrapperKind::Sphere {
                f.caption.push_str(&format!(" · {}s", kind.name()));
                name.push_str(&format!("-{}", kind.name()));
            }
            frames.push(f);
            names.push(name);
        }
    }
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
    let look = Look {
        azimuth: opts.azimuth,
        elevation: opts.elevation,
        size: opts.size,
        force: opts.force,
    };
    let captions = frames.iter().map(|f| f.caption.clone()).collect();
    let written = write_frames(frames, names, &title, &look, dir, stop)?;
    Ok(Snapshot { written, captions })
}
