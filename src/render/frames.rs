//! Writing drawn frames: each as a PNG + SVG pair and all of them on one figure sheet, under
//! one camera, every picture drawn and written before any file is moved into place.

use super::Frame;
use crate::output::{OutDir, Pending};
use crate::stop::Stop;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// How the frames are looked at and written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Look {
    /// Eye azimuth in degrees around +Z, from −Y.
    pub azimuth: f64,
    /// Eye elevation in degrees above the XY plane.
    pub elevation: f64,
    /// Size of one frame's picture in pixels (the caption band is added below).
    pub size: (u32, u32),
    /// Replace existing images.
    pub force: bool,
}

/// The destinations of `names` in `dir`, each as a `.png`/`.svg` pair, all checked before any
/// is written so an existing file without `force` stops the run before it writes anything.
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

fn write(p: &Pending, bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    p.file()?
        .write_all(bytes)
        .with_context(|| format!("{}: write failed", p.dest().display()))
}

/// Frames drawn and written to temporary files beside their destinations, not yet in place;
/// dropped, they leave nothing behind (nor the directories made for them).
pub struct Drawn {
    _dir: OutDir,
    files: Vec<(Pending, Pending)>,
}

impl Drawn {
    /// Moves every picture into place; returns the (PNG, SVG) pairs, the sheet's last.
    pub fn commit(self) -> Result<Vec<(PathBuf, PathBuf)>> {
        let Drawn { _dir, files } = self;
        files
            .into_iter()
            .map(|(png, svg)| Ok((png.commit()?, svg.commit()?)))
            .collect()
    }
}

/// Draws `frames` for `dir` (created with its parents if missing) as `NAME.{png,svg}`, one per
/// frame with `names` in order, and `figure.{png,svg}`, the sheet of them all under `title`,
/// ready to [commit](Drawn::commit). `stop` is obeyed between the pictures and while each is
/// rasterised ([`Interrupted`](crate::stop::Interrupted), nothing written).
pub fn draw_frames(
    frames: Vec<Frame>,
    mut names: Vec<String>,
    title: &str,
    look: &Look,
    dir: &Path,
    stop: &Stop,
) -> Result<Drawn> {
    names.push("figure".into());
    let cam = super::fit_camera(&frames, look.azimuth, look.elevation, look.size);
    let out_dir = crate::output::output_dir(Some(dir), "")?;
    let outs = pendings(dir, &names, look.force)?;
    let mut svgs = Vec::with_capacity(frames.len() + 1);
    for f in &frames {
        stop.check()?;
        svgs.push(super::frame_svg(f, &cam));
    }
    stop.check()?;
    svgs.push(super::sheet_svg(
        &frames,
        &cam,
        super::sheet_columns(frames.len()),
        title,
    ));
    for ((png, svg), text) in outs.iter().zip(&svgs) {
        stop.check()?;
        let dest = png.dest().display().to_string();
        let bytes = super::png::svg_to_png_until(text.clone(), stop)?
            .map_err(|e| anyhow::anyhow!("{dest}: {e}"))?;
        write(png, &bytes)?;
        write(svg, text.as_bytes())?;
    }
    Ok(Drawn {
        _dir: out_dir,
        files: outs,
    })
}

/// [`draw_frames`], then every picture moved into place; returns the (PNG, SVG) pairs
/// written, the sheet's last.
pub fn write_frames(
    frames: Vec<Frame>,
    names: Vec<String>,
    title: &str,
    look: &Look,
    dir: &Path,
    stop: &Stop,
) -> Result<Vec<(PathBuf, PathBuf)>> {
    draw_frames(frames, names, title, look, dir, stop)?.commit()
}
