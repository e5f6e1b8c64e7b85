//! Builders for the `foxglove.SceneUpdate` messages: the input scene, boxes of bodies and the
//! level snapshots. Many shapes share one primitive list (one entity, one `TriangleListPrimitive`
//! with indexed vertices) to keep messages small.

use crate::geom::{Aabb, P3};
use crate::scene::Scene;
use crate::wrap::{Hull, Obb, Sphere};
use foxglove::messages::{
    Color, CubePrimitive, Point3, Pose, Quaternion, SceneEntity, SceneUpdate, SpherePrimitive,
    Timestamp, TriangleListPrimitive, Vector3,
};

/// Frame every entity is expressed in.
pub const FRAME: &str = "world";
/// Input primitives on `/scene`: light grey.
pub const SCENE_COLOR: [f64; 4] = [0.8, 0.8, 0.8, 1.0];
/// Active bodies on `/grouping/active`: translucent green.
pub const ACTIVE_COLOR: [f64; 4] = [0.2, 0.8, 0.3, 0.25];
/// The merged pair on `/grouping/bodies`: translucent red.
pub const PAIR_COLOR: [f64; 4] = [0.95, 0.25, 0.2, 0.45];
/// The new body on `/grouping/bodies`: translucent yellow.
pub const NEW_COLOR: [f64; 4] = [1.0, 0.85, 0.1, 0.25];
/// Interior nodes' spheres on `/levels/<d>`: translucent blue.
pub const SPHERE_COLOR: [f64; 4] = [0.25, 0.55, 1.0, 0.3];
/// Interior nodes' convex hulls on `/levels/<d>`: translucent green.
pub const HULL_COLOR: [f64; 4] = [0.3, 0.8, 0.45, 0.3];
/// Interior nodes' axis-aligned boxes on `/levels/<d>`: translucent purple.
pub const BOX_COLOR: [f64; 4] = [0.6, 0.4, 0.9, 0.25];
/// Interior nodes' oriented boxes on `/levels/<d>`: translucent teal.
pub const OBB_COLOR: [f64; 4] = [0.1, 0.7, 0.75, 0.25];
/// Leaves drawn on `/levels/<d>`: orange.
pub const LEAF_COLOR: [f64; 4] = [1.0, 0.55, 0.15, 1.0];

fn color([r, g, b, a]: [f64; 4]) -> Option<Color> {
    Some(Color { r, g, b, a })
}

fn vector(x: f64, y: f64, z: f64) -> Option<Vector3> {
    Some(Vector3 { x, y, z })
}

fn pose_at(p: &P3) -> Option<Pose> {
    Some(Pose {
        position: vector(p.x, p.y, p.z),
        orientation: Some(Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }),
    })
}

/// One entity `id` at log time `t_ns`; the caller fills in its primitives.
pub fn entity(id: &str, t_ns: u64) -> SceneEntity {
    SceneEntity {
        timestamp: Some(Timestamp::new(
            (t_ns / 1_000_000_000) as u32,
            (t_ns % 1_000_000_000) as u32,
        )),
        frame_id: FRAME.to_string(),
        id: id.to_string(),
        ..SceneEntity::default()
    }
}

/// A scene update replacing the given entities.
pub fn update(entities: Vec<SceneEntity>) -> SceneUpdate {
    SceneUpdate {
        deletions: Vec::new(),
        entities,
    }
}

/// A box per AABB: pose at its centre, size = its extents.
pub fn cube(b: &Aabb, rgba: [f64; 4]) -> CubePrimitive {
    let e = b.extents();
    CubePrimitive {
        pose: pose_at(&b.center()),
        size: vector(e.x, e.y, e.z),
        color: color(rgba),
    }
}

/// An oriented box: pose at its centre rotated to its axes, size = twice its half extents.
pub fn obb_cube(b: &Obb, rgba: [f64; 4]) -> CubePrimitive {
    let q = b.rotation();
    let h = b.half * 2.0;
    CubePrimitive {
        pose: Some(Pose {
            position: vector(b.center.x, b.center.y, b.center.z),
            orientation: Some(Quaternion {
                x: q.i,
                y: q.j,
                z: q.k,
                w: q.w,
            }),
        }),
        size: vector(h.x, h.y, h.z),
        color: color(rgba),
    }
}

/// One indexed triangle list drawing the hull `h`, its vertices once. A segment hull is one
/// degenerate triangle `[a, b, b]` and a point hull `[a, a, a]` (they draw nothing but keep
/// their geometry), so readers get exactly one primitive per hull.
pub fn hull_triangles(h: &Hull, rgba: [f64; 4]) -> TriangleListPrimitive {
    let points = h
        .vertices
        .iter()
        .map(|p| Point3 {
            x: p.x,
            y: p.y,
            z: p.z,
        })
        .collect();
    let indices = match (h.triangles.is_empty(), h.vertices.len()) {
        (false, _) => h.triangles.iter().flatten().copied().collect(),
        (true, 0) => Vec::new(),
        (true, 1) => vec![0, 0, 0],
        (true, _) => vec![0, 1, 1],
    };
    TriangleListPrimitive {
        pose: pose_at(&P3::origin()),
        points,
        color: color(rgba),
        colors: Vec::new(),
        indices,
    }
}

/// A sphere primitive: pose at the centre, size = the diameter along every axis.
pub fn sphere(s: &Sphere, rgba: [f64; 4]) -> SpherePrimitive {
    let d = 2.0 * s.radius;
    SpherePrimitive {
        pose: pose_at(&s.center),
        size: vector(d, d, d),
        color: color(rgba),
    }
}

/// Reusable vertex renumbering for [`triangles`]; one per recorder.
#[derive(Debug, Default)]
pub struct Remap {
    slot: Vec<u32>,
    used: Vec<u32>,
}

/// One indexed triangle list drawing the primitives `prims` of `scene`: each scene vertex they
/// use appears once in `points`, the triangles index it.
pub fn triangles(
    scene: &Scene,
    prims: impl IntoIterator<Item = usize>,
    rgba: [f64; 4],
    remap: &mut Remap,
) -> TriangleListPrimitive {
    remap.slot.resize(scene.points.len(), u32::MAX);
    let mut points = Vec::new();
    let mut indices = Vec::new();
    for i in prims {
        for t in scene.prim_tris(i) {
            for &v in t {
                let slot = &mut remap.slot[v as usize];
                if *slot == u32::MAX {
                    *slot = points.len() as u32;
                    remap.used.push(v);
                    let p = &scene.points[v as usize];
                    points.push(Point3 {
                        x: p.x,
                        y: p.y,
                        z: p.z,
                    });
                }
                indices.push(*slot);
            }
        }
    }
    for v in remap.used.drain(..) {
        remap.slot[v as usize] = u32::MAX;
    }
    TriangleListPrimitive {
        pose: pose_at(&P3::origin()),
        points,
        color: color(rgba),
        colors: Vec::new(),
        indices,
    }
}
