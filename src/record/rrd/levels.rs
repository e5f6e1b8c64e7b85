//! The tree levels on the `level` timeline: at d = 0..=depth max, the cut at depth d
//! ([`SubsetTree::level`]) as interior-node wrappers of the kinds recorded (`record --wrapper`:
//! `levels/spheres`, `levels/hulls`, `levels/boxes`, `levels/obbs`) and leaf polygons, like the
//! frames of the paper's Figure 1.
//!
//! Geometry is logged once: `levels/leaves/<k>` holds the leaves at depth k (see [`PrimMesh`])
//! at tick k and stays, so tick d shows the cut's leaves; the hulls' vertices (input points,
//! shared by a node's hull and its ancestors') are logged once at d = 0, unshaded, and later
//! levels send only the cut's triangle indices (a partial `Mesh3D` update).
//!
//! One level, the *preview* (the shallowest cut of at least 64 nodes), is also logged at tick 0
//! of `merge` and `round`, so the Levels view shows something on any timeline. A cover is one
//! more level at tick `depth_max + 1` under `cover/*` ([`log_cover`]), its meshes sent whole.

use std::collections::HashMap;

use rerun::RecordingStream;
use rerun::components::FillMode;

use super::mesh::PrimMesh;
use super::{rel, send_at, send_static};
use crate::geom::{Aabb, P3, V3};
use crate::grouping::SubsetTree;
use crate::record::CoverLevel;
use crate::wrap::cover::export::{self, Geometry};
use crate::wrap::{Hull, Obb, Sphere, Wrappers};

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

/// The preview level is the shallowest whose cut has at least this many nodes.
const PREVIEW_NODES: usize = 64;

/// Times of the rows that show the preview level on the `merge` and `round` timelines.
const PREVIEW: [(&str, i64); 2] = [("merge", 0), ("round", 0)];

/// Logs every level of `tree` with the leaves drawn from `mesh`; `spheres` holds one sphere
/// per node, or none (levels without spheres: `levels/spheres` stays empty); the hulls, boxes
/// and oriented boxes of `wrappers` (its spheres are ignored) are logged when present.
///
/// Leaves are logged once each: `levels/leaves/<k>` holds the leaves at depth k at level tick k
/// and is never cleared, so at tick d the view shows the leaves of depth ≤ d, the cut's leaves.
/// The preview level (the shallowest whose cut has at least 64 nodes, else the deepest) is also
/// on the `merge` and `round` timelines at tick 0: its wrappers in one more row per entity, its
/// leaves by giving the rows of depth ≤ preview those times too.
pub(super) fn log_levels(
    rec: &RecordingStream,
    mesh: &PrimMesh,
    tree: &SubsetTree,
    spheres: &[Sphere],
    wrappers: Option<&Wrappers>,
    origin: &P3,
) -> anyhow::Result<()> {
    let none = Wrappers::default();
    let w = wrappers.unwrap_or(&none);
    check_lens(tree, spheres, w)?;
    let hull_mesh = w.hulls.as_deref().map(|h| HullMesh::new(tree, h, origin));
    let leaves_by_depth = leaves_by_depth(tree);
    let mut preview = None;
    for d in 0..=tree.depth_max() {
        let cut = tree.level(d);
        let in_preview = preview.is_none();
        if in_preview && (cut.len() >= PREVIEW_NODES || d == tree.depth_max()) {
            preview = Some(d);
        }
        let level = ("level", d as i64);
        let times: Vec<_> = if in_preview && d == 0 {
            [level].into_iter().chain(PREVIEW).collect()
        } else {
            vec![level]
        };
        let send = |entity: &str, arch: &dyn rerun::AsComponents| -> anyhow::Result<()> {
            send_at(rec, entity, &times, arch)?;
            if preview == Some(d) {
                send_at(rec, entity, &PREVIEW, arch)?;
            }
            Ok(())
        };
        let interior: Vec<u32> = cut.iter().copied().filter(|&x| !tree.is_leaf(x)).collect();
        if !spheres.is_empty() || w.trees().is_empty() {
            send("levels/spheres", &level_spheres(&interior, spheres, origin))?;
        }
        if let Some(hm) = &hull_mesh {
            send("levels/hulls", &level_hulls(hm, &interior, d))?;
        }
        if let Some(b) = &w.boxes {
            send("levels/boxes", &level_boxes(&interior, b, origin))?;
        }
        if let Some(b) = &w.obbs {
            send("levels/obbs", &level_obbs(&interior, b, origin))?;
        }
        let new_leaves = &leaves_by_depth[d as usize];
        if !new_leaves.is_empty() {
            let leaf_times: Vec<_> = if in_preview {
                [level].into_iter().chain(PREVIEW).collect()
            } else {
                vec![level]
            };
            let arch = leaf_mesh(mesh, new_leaves);
            send_at(rec, &format!("levels/leaves/{d}"), &leaf_times, &arch)?;
        }
    }
    Ok(())
}

/// Checks that every wrapper given has one entry per node of `tree` (no spheres: none drawn).
fn check_lens(tree: &SubsetTree, spheres: &[Sphere], w: &Wrappers) -> anyhow::Result<()> {
    if !spheres.is_empty() {
        check_len("spheres", Some(spheres.len()), tree)?;
    }
    check_len("hulls", w.hulls.as_ref().map(Vec::len), tree)?;
    check_len("boxes", w.boxes.as_ref().map(Vec::len), tree)?;
    check_len("oriented boxes", w.obbs.as_ref().map(Vec::len), tree)
}

/// The leaves of `tree` by depth, each list increasing.
fn leaves_by_depth(tree: &SubsetTree) -> Vec<Vec<u32>> {
    let mut by_depth = vec![Vec::new(); tree.depth_max() as usize + 1];
    for x in 0..tree.leaves() as u32 {
        by_depth[tree.depth[x as usize] as usize].push(x);
    }
    by_depth
}

/// The cut's `interior` nodes as translucent spheres (none when `spheres` is empty).
pub(super) fn level_spheres(
    interior: &[u32],
    spheres: &[Sphere],
    origin: &P3,
) -> rerun::Ellipsoids3D {
    let (centers, radii): (Vec<_>, Vec<_>) = interior
        .iter()
        .filter(|_| !spheres.is_empty())
        .map(|&x| {
            let s = &spheres[x as usize];
            (rel(&s.center, origin), s.radius as f32)
        })
        .unzip();
    rerun::Ellipsoids3D::from_centers_and_radii(centers, radii)
        .with_colors([SPHERE_BLUE])
        .with_fill_mode(FillMode::TransparentFillMajorWireframe)
}

/// The hulls of the cut's `interior` nodes: every hull vertex with the triangles at depth 0,
/// then only the triangle indices (a partial update).
fn level_hulls(hm: &HullMesh, interior: &[u32], d: u32) -> rerun::Mesh3D {
    let tris = interior.iter().flat_map(|&x| hm.node_tris(x)).copied();
    if d == 0 {
        rerun::Mesh3D::new(hm.positions.iter().copied()).with_albedo_factor(HULL_GREEN)
    } else {
        rerun::Mesh3D::update_fields()
    }
    .with_triangle_indices(nonempty(tris.collect()))
}

/// The axis-aligned boxes of the cut's `interior` nodes.
fn level_boxes(interior: &[u32], boxes: &[Aabb], origin: &P3) -> rerun::Boxes3D {
    let (centers, halves): (Vec<_>, Vec<_>) = interior
        .iter()
        .map(|&x| {
            let b = &boxes[x as usize];
            let h = b.extents() / 2.0;
            (
                rel(&b.center(), origin),
                [h.x as f32, h.y as f32, h.z as f32],
            )
        })
        .unzip();
    rerun::Boxes3D::from_centers_and_half_sizes(centers, halves)
        .with_colors([BOX_VIOLET])
        .with_fill_mode(FillMode::TransparentFillMajorWireframe)
}

/// The oriented boxes of the cut's `interior` nodes, rotations as quaternions.
fn level_obbs(interior: &[u32], obbs: &[Obb], origin: &P3) -> rerun::Boxes3D {
    let mut centers = Vec::with_capacity(interior.len());
    let mut halves = Vec::with_capacity(interior.len());
    let mut rotations = Vec::with_capacity(interior.len());
    for &x in interior {
        let b = &obbs[x as usize];
        centers.push(rel(&b.center, origin));
        halves.push(b.half.map(|h| h as f32));
        let q = b.rotation().coords.map(|c| c as f32);
        rotations.push(rerun::datatypes::Quaternion::from_xyzw([
            q.x, q.y, q.z, q.w,
        ]));
    }
    rerun::Boxes3D::from_centers_and_half_sizes(centers, halves.iter().map(|h| [h.x, h.y, h.z]))
        .with_quaternions(rotations)
        .with_colors([OBB_VIOLET])
        .with_fill_mode(FillMode::TransparentFillMajorWireframe)
}

/// The polygons of `leaves` as one shaded mesh.
fn leaf_mesh(mesh: &PrimMesh, leaves: &[u32]) -> rerun::Mesh3D {
    mesh.subset(leaves)
        .to_mesh3d()
        .with_albedo_factor(LEAF_ORANGE)
}

/// Logs `cover` as one more level, at tick `depth_max + 1` of the `level` timeline: its spheres
/// (`cover/spheres`), boxes (`cover/boxes`, axis-aligned and oriented together, with rotations
/// when any is oriented), hulls (`cover/hulls`, one mesh) and leaves drawn as themselves
/// (`cover/leaves`, one mesh), only the entities used; a recursive `Clear` of `levels` at the
/// same tick so the cover is seen alone; and a static `TextLog` `cover/summary` with the
/// tolerance, size and largest error.
pub(super) fn log_cover(
    rec: &RecordingStream,
    tree: &SubsetTree,
    cover: &CoverLevel<'_>,
    origin: &P3,
) -> anyhow::Result<()> {
    let times = [("level", i64::from(tree.depth_max()) + 1)];
    send_static(
        rec,
        "cover",
        &rerun::Transform3D::from_translation([origin.x as f32, origin.y as f32, origin.z as f32]),
    )?;
    send_at(rec, "levels", &times, &rerun::Clear::recursive())?;
    let mut geometry = CoverGeometry::default();
    for w in cover.wrappers {
        geometry.add(&w.geometry, origin);
    }
    geometry.send(rec, &times)?;
    let c = cover.cover;
    let limit = match cover.budget {
        Some(k) => format!("budget {k}, tolerance {:.4e}", c.tolerance),
        None => format!("tolerance {:.4e}", c.tolerance),
    };
    let line = format!(
        "cover at level tick {}: {limit}, {} wrappers, max error {:.4e}",
        times[0].1,
        c.nodes.len(),
        c.max_error()
    );
    send_static(rec, "cover/summary", &rerun::TextLog::new(line))?;
    Ok(())
}

/// A cover's wrappers gathered by entity, relative to the scene origin.
#[derive(Default)]
struct CoverGeometry {
    centers: Vec<[f32; 3]>,
    radii: Vec<f32>,
    /// Axis-aligned and oriented boxes: centre, half size, rotation (x, y, z, w).
    boxes: Vec<([f32; 3], [f32; 3], [f32; 4])>,
    /// Whether any box is oriented (the boxes then carry their rotations).
    oriented: bool,
    /// Hulls and leaves drawn as themselves, each as one mesh: positions and triangles.
    hulls: (Vec<[f32; 3]>, Vec<[u32; 3]>),
    leaves: (Vec<[f32; 3]>, Vec<[u32; 3]>),
}

impl CoverGeometry {
    /// Adds one wrapper of the cover.
    fn add(&mut self, g: &Geometry, origin: &P3) {
        let f = |a: &[f64; 3]| P3::new(a[0], a[1], a[2]);
        match g {
            Geometry::Sphere { center, radius } => {
                self.centers.push(rel(&f(center), origin));
                self.radii.push(*radius as f32);
            }
            Geometry::Box { min, max } => {
                let (lo, hi) = (f(min), f(max));
                let h = (hi - lo) / 2.0;
                let c = rel(&nalgebra::center(&lo, &hi), origin);
                self.boxes.push((
                    c,
                    [h.x as f32, h.y as f32, h.z as f32],
                    [0.0, 0.0, 0.0, 1.0],
                ));
            }
            Geometry::Obb {
                center,
                axes,
                half_extents,
            } => {
                self.oriented = true;
                let col = |k: usize| V3::new(axes[k][0], axes[k][1], axes[k][2]);
                let m = nalgebra::Matrix3::from_columns(&[col(0), col(1), col(2)]);
                let q = nalgebra::UnitQuaternion::from_matrix(&m)
                    .coords
                    .map(|c| c as f32);
                self.boxes.push((
                    rel(&f(center), origin),
                    half_extents.map(|h| h as f32),
                    [q.x, q.y, q.z, q.w],
                ));
            }
            Geometry::Hull { .. } => append_mesh(&mut self.hulls, g, origin),
            Geometry::Primitive { .. } => append_mesh(&mut self.leaves, g, origin),
        }
    }

    /// Sends the entities used (`cover/spheres`, `cover/boxes`, `cover/hulls`, `cover/leaves`)
    /// at `times`.
    fn send(self, rec: &RecordingStream, times: &[(&'static str, i64)]) -> anyhow::Result<()> {
        if !self.centers.is_empty() {
            let arch = rerun::Ellipsoids3D::from_centers_and_radii(self.centers, self.radii)
                .with_colors([SPHERE_BLUE])
                .with_fill_mode(FillMode::TransparentFillMajorWireframe);
            send_at(rec, "cover/spheres", times, &arch)?;
        }
        let boxes = &self.boxes;
        if !boxes.is_empty() {
            let mut arch = rerun::Boxes3D::from_centers_and_half_sizes(
                boxes.iter().map(|b| b.0),
                boxes.iter().map(|b| b.1),
            );
            if self.oriented {
                arch = arch.with_quaternions(
                    boxes
                        .iter()
                        .map(|b| rerun::datatypes::Quaternion::from_xyzw(b.2)),
                );
            }
            let arch = arch
                .with_colors([BOX_VIOLET])
                .with_fill_mode(FillMode::TransparentFillMajorWireframe);
            send_at(rec, "cover/boxes", times, &arch)?;
        }
        for (path, (positions, tris), rgba) in [
            ("cover/hulls", self.hulls, HULL_GREEN),
            ("cover/leaves", self.leaves, LEAF_ORANGE),
        ] {
            if !positions.is_empty() {
                let arch = rerun::Mesh3D::new(positions)
                    .with_triangle_indices(nonempty(tris))
                    .with_albedo_factor(rgba);
                send_at(rec, path, times, &arch)?;
            }
        }
        Ok(())
    }
}

/// Appends the mesh of `g` ([`export::mesh`]) to (positions, triangles), relative to `origin`.
fn append_mesh((positions, tris): &mut (Vec<[f32; 3]>, Vec<[u32; 3]>), g: &Geometry, origin: &P3) {
    let (v, t) = export::mesh(g);
    let base = positions.len() as u32;
    positions.extend(v.iter().map(|p| rel(p, origin)));
    tris.extend(t.iter().map(|t| t.map(|i| i + base)));
}
