//! The tree levels on the `level` timeline: at d = 0..=depth max, the cut at depth d
//! ([`SubsetTree::level`]) as interior-node wrappers and leaf polygons (`levels/leaves`), like
//! the frames of the paper's Figure 1. Wrappers are drawn for the kinds recorded
//! (`record --wrapper`): spheres (`levels/spheres`), convex hulls (`levels/hulls`),
//! axis-aligned boxes (`levels/boxes`) and oriented boxes (`levels/obbs`).
//!
//! Meshes are logged the way `levels/leaves` is: the vertices once, at d = 0, later levels send
//! only the triangle indices of the shapes in their cut (a partial `Mesh3D` update). The leaves'
//! vertices (positions and normals, see [`PrimMesh`]) are per primitive; the hulls' vertices are
//! input points, shared by a node's hull and its ancestors' hulls, so each distinct point is
//! logged once and without normals (the hulls are drawn translucent and unshaded). Each level
//! costs 12 bytes per drawn triangle, 16 bytes per sphere, 24 per box and 40 per oriented box.

use std::collections::HashMap;

use rerun::RecordingStream;
use rerun::components::FillMode;

use super::mesh::PrimMesh;
use super::{rel, send_at};
use crate::geom::P3;
use crate::grouping::SubsetTree;
use crate::wrap::{Hull, Sphere, Wrappers};

/// Translucent blue of the level spheres.
const SPHERE_BLUE: u32 = 0x1E90FF40;
/// Orange of the leaves drawn at a level.
const LEAF_ORANGE: u32 = 0xE07020FF;
/// Translucent green of the level hulls (`render::Style::HULL`).
const HULL_GREEN: u32 = 0x6EB2844D;
/// Translucent violet of the level boxes (`render::Style::BOX`).
const BOX_VIOLET: u32 = 0xA082C84D;
/// Translucent darker violet of the level oriented boxes, told apart from the boxes.
const OBB_VIOLET: u32 = 0x7850B44D;

/// Every interior node's hull as one indexed mesh over the distinct hull vertices.
struct HullMesh {
    /// Distinct hull vertices relative to the scene origin (one dummy point when none).
    positions: Vec<[f32; 3]>,
    /// Offsets into `tris` per node, length = nodes + 1 (leaves have none).
    start: Vec<u32>,
    /// Triangles as indices into `positions`.
    tris: Vec<[u32; 3]>,
}

impl HullMesh {
    fn new(tree: &SubsetTree, hulls: &[Hull], origin: &P3) -> HullMesh {
        let mut slot: HashMap<[u64; 3], u32> = HashMap::new();
        let mut m = HullMesh {
            positions: Vec::new(),
            start: Vec::with_capacity(hulls.len() + 1),
            tris: Vec::new(),
        };
        m.start.push(0);
        for (x, h) in hulls.iter().enumerate() {
            if !tree.is_leaf(x as u32) {
                for t in &h.triangles {
                    let tri = t.map(|i| {
                        let p = &h.vertices[i as usize];
                        *slot
                            .entry(p.coords.map(f64::to_bits).into())
                            .or_insert_with(|| {
                                m.positions.push(rel(p, origin));
                                m.positions.len() as u32 - 1
                            })
                    });
                    m.tris.push(tri);
                }
            }
            m.start.push(m.tris.len() as u32);
        }
        if m.positions.is_empty() {
            m.positions.push([0.0; 3]);
        }
        m
    }

    fn node_tris(&self, x: u32) -> &[[u32; 3]] {
        &self.tris[self.start[x as usize] as usize..self.start[x as usize + 1] as usize]
    }
}

/// Fails unless `len` wrappers (when present) match the tree's nodes.
fn check_len(what: &str, len: Option<usize>, tree: &SubsetTree) -> anyhow::Result<()> {
    match len {
        Some(l) if l != tree.len() => anyhow::bail!("{l} {what} for {} tree nodes", tree.len()),
        _ => Ok(()),
    }
}

/// An empty index list would make the viewer read the positions as a triangle soup; one
/// degenerate triangle draws nothing.
fn nonempty(mut tris: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
    if tris.is_empty() {
        tris.push([0, 0, 0]);
    }
    tris
}

/// Logs every level of `tree` with the leaves drawn from `mesh`; `spheres` holds one sphere
/// per node, or none (levels without spheres: `levels/spheres` stays empty); the hulls, boxes
/// and oriented boxes of `wrappers` (its spheres are ignored) are logged when present.
pub(super) fn log_levels(
    rec: &RecordingStream,
    mesh: &PrimMesh,
    tree: &SubsetTree,
    spheres: &[Sphere],
    wrappers: Option<&Wrappers>,
    origin: &P3,
) -> anyhow::Result<()> {
    if !spheres.is_empty() {
        check_len("spheres", Some(spheres.len()), tree)?;
    }
    let none = Wrappers::default();
    let w = wrappers.unwrap_or(&none);
    check_len("hulls", w.hulls.as_ref().map(Vec::len), tree)?;
    check_len("boxes", w.boxes.as_ref().map(Vec::len), tree)?;
    check_len("oriented boxes", w.obbs.as_ref().map(Vec::len), tree)?;
    let hull_mesh = w.hulls.as_deref().map(|h| HullMesh::new(tree, h, origin));
    for d in 0..=tree.depth_max() {
        let times = [("level", d as i64)];
        let cut = tree.level(d);
        let interior: Vec<u32> = cut.iter().copied().filter(|&x| !tree.is_leaf(x)).collect();
        if !spheres.is_empty() || w.trees().is_empty() {
            let (centers, radii): (Vec<_>, Vec<_>) = interior
                .iter()
                .filter(|_| !spheres.is_empty())
                .map(|&x| {
                    let s = &spheres[x as usize];
                    (rel(&s.center, origin), s.radius as f32)
                })
                .unzip();
            let arch = rerun::Ellipsoids3D::from_centers_and_radii(centers, radii)
                .with_colors([SPHERE_BLUE])
                .with_fill_mode(FillMode::TransparentFillMajorWireframe);
            send_at(rec, "levels/spheres", &times, &arch)?;
        }
        if let Some(hm) = &hull_mesh {
            let tris = interior.iter().flat_map(|&x| hm.node_tris(x)).copied();
            let arch = if d == 0 {
                rerun::Mesh3D::new(hm.positions.iter().copied()).with_albedo_factor(HULL_GREEN)
            } else {
                rerun::Mesh3D::update_fields()
            }
            .with_triangle_indices(nonempty(tris.collect()));
            send_at(rec, "levels/hulls", &times, &arch)?;
        }
        if let Some(b) = &w.boxes {
            let (centers, halves): (Vec<_>, Vec<_>) = interior
                .iter()
                .map(|&x| {
                    let b = &b[x as usize];
                    let h = b.extents() / 2.0;
                    (
                        rel(&b.center(), origin),
                        [h.x as f32, h.y as f32, h.z as f32],
                    )
                })
                .unzip();
            let arch = rerun::Boxes3D::from_centers_and_half_sizes(centers, halves)
                .with_colors([BOX_VIOLET])
                .with_fill_mode(FillMode::TransparentFillMajorWireframe);
            send_at(rec, "levels/boxes", &times, &arch)?;
        }
        if let Some(b) = &w.obbs {
            let mut centers = Vec::with_capacity(interior.len());
            let mut halves = Vec::with_capacity(interior.len());
            let mut rotations = Vec::with_capacity(interior.len());
            for &x in &interior {
                let b = &b[x as usize];
                centers.push(rel(&b.center, origin));
                halves.push(b.half.map(|h| h as f32));
                let q = b.rotation().coords.map(|c| c as f32);
                rotations.push(rerun::datatypes::Quaternion::from_xyzw([
                    q.x, q.y, q.z, q.w,
                ]));
            }
            let arch = rerun::Boxes3D::from_centers_and_half_sizes(
                centers,
                halves.iter().map(|h| [h.x, h.y, h.z]),
            )
            .with_quaternions(rotations)
            .with_colors([OBB_VIOLET])
            .with_fill_mode(FillMode::TransparentFillMajorWireframe);
            send_at(rec, "levels/obbs", &times, &arch)?;
        }
        let tris = cut.iter().filter(|&&x| tree.is_leaf(x));
        let tris = tris.flat_map(|&x| mesh.prim_tris(x)).copied().collect();
        let leaves = if d == 0 {
            rerun::Mesh3D::new(mesh.positions.iter().copied())
                .with_vertex_normals(mesh.normals.iter().copied())
                .with_albedo_factor(LEAF_ORANGE)
        } else {
            rerun::Mesh3D::update_fields()
        }
        .with_triangle_indices(nonempty(tris));
        send_at(rec, "levels/leaves", &times, &leaves)?;
    }
    Ok(())
}
