//! The `.mcap` of a spherize run ([`crate::record::spherize`]): `/robot` (the links' meshes),
//! `/spheres` (the cover), `/levels` (each link's tree cut at depth d at d + 1 ms) as
//! `foxglove.SceneUpdate`, and `/allocation` (the budget's probes) as `foxglove.Log`.

use std::io::BufWriter;

use anyhow::{Context, Result};
use foxglove::messages::{Log, SceneUpdate, Timestamp};

use super::scene_msgs::{self, SceneMesh};
use super::{Out, ZSTD_LEVEL, add_schema, add_topic, emit, write_options};
use crate::output::Pending;
use crate::record::spherize::View;

/// Writes `view` into `file`.
pub fn write(view: &View, file: &Pending) -> Result<()> {
    let name = file.dest().display().to_string();
    write_file(view, file).with_context(|| format!("{name}: cannot write the MCAP recording"))
}

fn write_file(view: &View, file: &Pending) -> Result<()> {
    let options = write_options(Some(mcap::Compression::Zstd), ZSTD_LEVEL);
    let mut w = Out {
        mcap: options.create(BufWriter::new(file.file()?))?,
        live: None,
    };
    let buf = &mut Vec::new();
    let scene_update = add_schema::<SceneUpdate, _>(&mut w)?;
    let log_schema = add_schema::<Log, _>(&mut w)?;
    let mut robot = add_topic(&mut w, scene_update, "/robot")?;
    let mut cover = add_topic(&mut w, scene_update, "/spheres")?;
    let mut levels = add_topic(&mut w, scene_update, "/levels")?;
    let mut allocation = add_topic(&mut w, log_schema, "/allocation")?;
    let mut meshes = Vec::new();
    let mut spheres = Vec::new();
    for l in &view.links {
        let mut e = scene_msgs::entity(&format!("{}/mesh", l.name), 0);
        let mut m = SceneMesh::new(&l.mesh);
        m.add(0..l.mesh.len());
        e.triangles.push(m.into_primitive(scene_msgs::SCENE_COLOR));
        meshes.push(e);
        let mut e = scene_msgs::entity(&format!("{}/spheres", l.name), 0);
        e.spheres = l
            .cover
            .iter()
            .map(|(s, c)| scene_msgs::sphere(s, *c))
            .collect();
        spheres.push(e);
    }
    emit(&mut w, buf, &mut robot, 0, &scene_msgs::update(meshes))?;
    emit(&mut w, buf, &mut cover, 0, &scene_msgs::update(spheres))?;
    let depth = view.links.iter().map(|l| l.levels.len()).max().unwrap_or(0);
    for d in 0..depth {
        let t = (d as u64 + 1) * 1_000_000;
        let entities = view
            .links
            .iter()
            .map(|l| {
                let mut e = scene_msgs::entity(&format!("{}/level", l.name), t);
                let level = l.levels.get(d).or(l.levels.last());
                e.spheres = level
                    .into_iter()
                    .flatten()
                    .map(|(s, c)| scene_msgs::sphere(s, *c))
                    .collect();
                e
            })
            .collect();
        emit(&mut w, buf, &mut levels, t, &scene_msgs::update(entities))?;
    }
    for (k, (thr, n)) in view.probes.iter().enumerate() {
        let t = (k as u64 + 1) * 1_000_000;
        let message = match n {
            Some(n) => {
                format!("probe {k}: largest excess {thr:.6}: {n} spheres, within the budget")
            }
            None => format!("probe {k}: largest excess {thr:.6}: over the budget"),
        };
        let log = Log {
            timestamp: Some(Timestamp::new(0, t as u32)),
            level: foxglove::messages::log::Level::Info as i32,
            message,
            name: "wraptree spherize".into(),
            file: String::new(),
            line: 0,
        };
        emit(&mut w, buf, &mut allocation, t, &log)?;
    }
    w.finish_file()
}
