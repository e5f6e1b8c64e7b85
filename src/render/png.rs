//! SVG → PNG with `resvg`, captions set in the bundled DejaVu Sans (no system fonts are read,
//! so the same SVG gives the same PNG bytes on every machine).

use resvg::{tiny_skia, usvg};
use std::sync::mpsc;
use std::sync::{Arc, OnceLock};
use std::time::Duration;

use crate::stop::{Interrupted, Stop};

/// DejaVu Sans 2.37 (see `assets/fonts/README.md` for its origin and licence).
pub const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

fn fontdb() -> Arc<usvg::fontdb::Database> {
    static DB: OnceLock<Arc<usvg::fontdb::Database>> = OnceLock::new();
    DB.get_or_init(|| {
        let mut db = usvg::fontdb::Database::new();
        db.load_font_data(FONT.to_vec());
        db.set_sans_serif_family(super::svg::FONT_FAMILY);
        Arc::new(db)
    })
    .clone()
}

/// Parsing options that resolve every font to the bundled one.
pub fn options() -> usvg::Options<'static> {
    let mut opt = usvg::Options {
        font_family: super::svg::FONT_FAMILY.into(),
        ..usvg::Options::default()
    };
    opt.fontdb = fontdb();
    opt
}

/// [`svg_to_png`] on a thread of its own, waited for while `stop` is not requested: a large
/// drawing renders in one call that cannot look at `stop`, so on a stop this returns
/// [`Interrupted`] at once and leaves the thread to end with the process.
pub fn svg_to_png_until(svg: String, stop: &Stop) -> Result<Result<Vec<u8>, String>, Interrupted> {
    let (tx, rx) = mpsc::channel();
    let spawned = std::thread::Builder::new()
        .name("svg-to-png".into())
        .spawn(move || {
            let _ = tx.send(svg_to_png(&svg));
        });
    if let Err(e) = spawned {
        return Ok(Err(format!("cannot start the rendering thread: {e}")));
    }
    loop {
        stop.check()?;
        match rx.recv_timeout(Duration::from_millis(20)) {
            Ok(png) => return Ok(png),
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Ok(Err("the rendering thread failed".into()));
            }
        }
    }
}

/// Renders an SVG document to PNG bytes at its own size (1 SVG unit = 1 pixel).
pub fn svg_to_png(svg: &str) -> Result<Vec<u8>, String> {
    let tree = usvg::Tree::from_str(svg, &options()).map_err(|e| format!("bad SVG: {e}"))?;
    let size = tree.size().to_int_size();
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height())
        .ok_or_else(|| format!("cannot allocate a {size:?} image"))?;
    resvg::render(
        &tree,
        tiny_skia::Transform::identity(),
        &mut pixmap.as_mut(),
    );
    pixmap
        .encode_png()
        .map_err(|e| format!("PNG encoding: {e}"))
}
