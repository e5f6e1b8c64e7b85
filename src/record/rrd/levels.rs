//! The tree levels on the `level` timeline: at d = 0..=depth max, the cut at depth d
//! ([`SubsetTree::level`]) as interior-node spheres (`levels/spheres`) and leaf polygons
//! (`levels/leaves`), like the frames of the paper's Figure 1.
//!
//! The leaves' vertices (positions and normals, see [`PrimMesh`]) are logged once, at d = 0;
//! later levels send only the triangle indices of the leaves in their cut (a partial `Mesh3D`
//! update), so each level costs 12 bytes per drawn triangle and 16 bytes per sphere.

use rerun::RecordingStream;
use rerun::components::FillMode;

use super::mesh::PrimMesh;
use super::{rel, send_at};
use crate::geom::P3;
use crate::grouping::SubsetTree;
use crate::wrap::Sphere;

/// Translucent blue of the level spheres.
const SPHERE_BLUE: u32 = 0x1E90FF40;
/// Orange of the leaves drawn at a level.
const LEAF_ORANGE: u32 = 0xE07020FF;

/// Logs every level of `tree` with the leaves drawn from `mesh`; `spheres` holds one sphere
/// per node, or none (levels without spheres: `levels/spheres` stays empty).
pub(super) fn log_levels(
    rec: &RecordingStream,
    mesh: &PrimMesh,
    tree: &SubsetTree,
    spheres: &[Sphere],
    origin: &P3,
) -> anyhow::Result<()> {
    if !spheres.is_empty() && spheres.len() != tree.len() {
        anyhow::bail!("{} spheres for {} tree nodes", spheres.len(), tree.len());
    }
    for d in 0..=tree.depth_max() {
        let mut centers = Vec::new();
        let mut radii = Vec::new();
        let mut tris = Vec::new();
        for node in tree.level(d) {
            if tree.is_leaf(node) {
                tris.extend_from_slice(mesh.prim_tris(node));
            } else if !spheres.is_empty() {
                let s = &spheres[node as usize];
                centers.push(rel(&s.center, origin));
                radii.push(s.radius as f32);
            }
        }
        if tris.is_empty() {
            // An empty index list would make the viewer read the positions as a triangle
            // soup; one degenerate triangle draws nothing.
            tris.push([0, 0, 0]);
        }
        let times = [("level", d as i64)];
        let spheres = rerun::Ellipsoids3D::from_centers_and_radii(centers, radii)
            .with_colors([SPHERE_BLUE])
            .with_fill_mode(FillMode::TransparentFillMajorWireframe);
        send_at(rec, "levels/spheres", &times, &spheres)?;
        let leaves = if d == 0 {
            rerun::Mesh3D::new(mesh.positions.iter().copied())
                .with_vertex_normals(mesh.normals.iter().copied())
                .with_albedo_factor(LEAF_ORANGE)
        } else {
            rerun::Mesh3D::update_fields()
        }
        .with_triangle_indices(tris);
        send_at(rec, "levels/leaves", &times, &leaves)?;
    }
    Ok(())
}
