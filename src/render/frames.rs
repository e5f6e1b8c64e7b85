//! Writing drawn frames: each as a PNG + SVG pair and all of them on one figure sheet, under
//! one camera, every picture drawn and written before any file is moved into place.

use super::Frame;
use crate::output::{OutDir, Pending, check_absent};
use crate::stop::Stop;
use anyhow::Result;
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
    // Every destination is checked before anything is drawn.
    let dests: Vec<[PathBuf; 2]> = names
        .iter()
        .map(|n| [dir.join(format!("{n}.png")), dir.join(format!("{n}.svg"))])
        .collect();
    check_absent(dests.as_flattened(), look.force)?;
    let out_dir = crate::output::output_dir(Some(dir), "")?;
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
    let mut files = Vec::with_capacity(dests.len());
    for ([png, svg], text) in dests.iter().zip(&svgs) {
        stop.check()?;
        let bytes = super::png::svg_to_png_until(text.clone(), stop)?
            .map_err(|e| anyhow::anyhow!("{}: {e}", png.display()))?;
        files.push((
            Pending::with_bytes(png, &bytes, look.force)?,
            Pending::with_bytes(svg, text.as_bytes(), look.force)?,
        ));
    }
    Ok(Drawn {
        _dir: out_dir,
        files,
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
