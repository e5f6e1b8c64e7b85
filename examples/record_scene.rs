//! Load an OBJ from `scenes/`, group it and record the run to `.rrd` (Rerun) and `.mcap`
//! (Foxglove).
//!
//! `cargo run --release --example record_scene [SCENE.obj] [OUT_PREFIX]` — defaults: the bundled
//! lamp, written into a temporary directory that is removed at exit.

use wraptree::grouping::Params;
use wraptree::record::{RecordOptions, record};
use wraptree::scene::{LoadOptions, load_path};

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args_os().skip(1);
    let scene = args
        .next()
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/lamp.obj").into());
    let tmp = tempfile::tempdir()?;
    let prefix = args
        .next()
        .map_or_else(|| tmp.path().join("lamp"), Into::into);

    let loaded = load_path(&scene, &LoadOptions::default())?;
    let params = Params::default().resolve(&loaded.scene);
    let written = record(&loaded, &params, &prefix, &RecordOptions::default(), ())?;

    let tree = &written
        .grouping
        .as_ref()
        .expect("no limits: it finishes")
        .tree;
    println!(
        "{}: {} primitives, depth {}",
        loaded.scene.name,
        loaded.scene.len(),
        tree.depth_max()
    );
    println!("{}", written.rrd.display());
    println!("{}", written.mcap.display());
    Ok(())
}
