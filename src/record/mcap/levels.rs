//! The `/levels/<d>` snapshots and the `/cover` level, written after the run.

use super::{LEVEL_LEAF_SHARE, MS, McapRecorder, add_topic, emit, scene_msgs};
use crate::grouping::SubsetTree;
use crate::record::Outcome;
use crate::wrap::{Sphere, Wrappers};
use anyhow::{Context, Result, bail};
use foxglove::messages::SceneEntity;
use scene_msgs::SceneMesh;
use std::io::{Seek, Write};

impl<W: Write + Seek> McapRecorder<'_, W> {
    /// Writes one `/levels/<d>` snapshot per depth of the finished tree, from the root down to
    /// the last cut of less than [`LEVEL_LEAF_SHARE`] leaves (to the deepest with `all_levels`),
    /// then the cover if any; returns the number of levels written.
    pub(super) fn write_levels(&mut self, outcome: &Outcome<'_>) -> Result<u32> {
        let (Some(grouping), Some(spheres)) = (outcome.grouping, outcome.spheres) else {
            return Ok(0);
        };
        let tree = &grouping.tree;
        let none = Wrappers::default();
        let extra = outcome.wrappers.unwrap_or(&none);
        check_lens(tree, spheres, extra)?;
        // The cut at depth d holds the leaves of depth <= d: each level adds one depth's leaves.
        let mut leaves_by_depth = vec![Vec::new(); tree.depth_max() as usize + 1];
        for x in 0..tree.leaves() {
            leaves_by_depth[tree.depth[x] as usize].push(x);
        }
        let mut leaf_mesh = SceneMesh::new(self.info.scene);
        let mut written = 0;
        for d in 0..=tree.depth_max() {
            let cut = tree.level(d);
            let interior: Vec<usize> = cut
                .iter()
                .filter(|&&x| !tree.is_leaf(x))
                .map(|&x| x as usize)
                .collect();
            let leaves = cut.len() - interior.len();
            if d > 0 && !self.all_levels && leaves as f64 >= LEVEL_LEAF_SHARE * cut.len() as f64 {
                break;
            }
            written = d + 1;
            let t = (self.events + 1 + u64::from(d)) * MS;
            let mut topic =
                add_topic(&mut self.writer, self.scene_update, &format!("/levels/{d}"))?;
            let mut entities = wrapper_entities(&interior, spheres, extra, t);
            let mut leaves = scene_msgs::entity("leaves", t);
            leaf_mesh.add(leaves_by_depth[d as usize].iter().copied());
            leaves
                .triangles
                .push(leaf_mesh.primitive(scene_msgs::LEAF_COLOR));
            entities.push(leaves);
            let msg = scene_msgs::update(entities);
            emit(&mut self.writer, &mut self.buf, &mut topic, t, &msg)
                .with_context(|| format!("writing level {d}"))?;
        }
        if let Some(cover) = &outcome.cover {
            let t = (self.events + 2 + u64::from(tree.depth_max())) * MS;
            let mut topic = add_topic(&mut self.writer, self.scene_update, "/cover")?;
            let msg = scene_msgs::cover_update(cover.wrappers, t);
            emit(&mut self.writer, &mut self.buf, &mut topic, t, &msg)
                .context("writing the cover")?;
        }
        Ok(written)
    }
}

/// Checks that every wrapper given has one entry per node of `tree` (no spheres: none drawn).
fn check_lens(tree: &SubsetTree, spheres: &[Sphere], extra: &Wrappers) -> Result<()> {
    if !spheres.is_empty() && spheres.len() != tree.len() {
        bail!("{} spheres for {} tree nodes", spheres.len(), tree.len());
    }
    for (what, len) in [
        ("hulls", extra.hulls.as_ref().map(Vec::len)),
        ("boxes", extra.boxes.as_ref().map(Vec::len)),
        ("oriented boxes", extra.obbs.as_ref().map(Vec::len)),
    ] {
        if let Some(len) = len.filter(|&l| l != tree.len()) {
            bail!("{len} {what} for {} tree nodes", tree.len());
        }
    }
    Ok(())
}

/// The wrappers of a cut's `interior` nodes at `t`, one entity per kind recorded: `spheres`
/// (unless there are none), `hulls`, `boxes`, `obbs`.
fn wrapper_entities(
    interior: &[usize],
    spheres: &[Sphere],
    extra: &Wrappers,
    t: u64,
) -> Vec<SceneEntity> {
    let mut entities = Vec::with_capacity(5);
    if !spheres.is_empty() {
        let mut e = scene_msgs::entity("spheres", t);
        e.spheres = interior
            .iter()
            .map(|&x| scene_msgs::sphere(&spheres[x], scene_msgs::SPHERE_COLOR))
            .collect();
        entities.push(e);
    }
    if let Some(h) = &extra.hulls {
        let mut e = scene_msgs::entity("hulls", t);
        e.triangles = interior
            .iter()
            .map(|&x| scene_msgs::hull_triangles(&h[x], scene_msgs::HULL_COLOR))
            .collect();
        entities.push(e);
    }
    if let Some(b) = &extra.boxes {
        let mut e = scene_msgs::entity("boxes", t);
        e.cubes = interior
            .iter()
            .map(|&x| scene_msgs::cube(&b[x], scene_msgs::BOX_COLOR))
            .collect();
        entities.push(e);
    }
    if let Some(b) = &extra.obbs {
        let mut e = scene_msgs::entity("obbs", t);
        e.cubes = interior
            .iter()
            .map(|&x| scene_msgs::obb_cube(&b[x], scene_msgs::OBB_COLOR))
            .collect();
        entities.push(e);
    }
    entities
}
