//! Builders for the `foxglove.SceneUpdate` messages: the input scene, boxes of bodies, the
//! level snapshots and the cover. Many shapes share one primitive list (one entity, one `TriangleListPrimitive`
//! with indexed vertices) to keep messages small.

use crate::geom::{Aabb, P3, V3};
use crate::scene::Scene;
use crate::wrap::cover::export::{self, Geometry, WrapperRecord};
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

/// `x` rounded to `f32`, the precision viewers draw in (kept as it is beyond `f32`'s range). The
/// low mantissa bits are then zero, so the chunk compression shrinks drawn geometry that would
/// not shrink otherwise. Only drawn geometry is rounded: `replay` and `snapshot` read the
/// attached scene, and merge boxes keep their exact values.
pub fn shown(x: f64) -> f64 {
    let r = f64::from(x as f32);
    if r.is_finite() { r } else { x }
}

/// A scene or wrapper vertex as drawn (see [`shown`]).
fn point(p: &P3) -> Point3 {
    Point3 {
        x: shown(p.x),
        y: shown(p.y),
        z: shown(p.z),
    }
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

/// The `/scene` message: every primitive of `scene` in one light grey entity `scene` at 0.
pub fn scene_update(scene: &Scene) -> SceneUpdate {
    let mut entity = entity("scene", 0);
    let mut mesh = SceneMesh::new(scene);
    mesh.add(0..scene.len());
    entity.triangles.push(mesh.into_primitive(SCENE_COLOR));
    update(vec![entity])
}

/// One merge at `t_ns` as entity `merge`: the merged pair's boxes `a`, `b` and the new body's.
pub fn merge_boxes(a: &Aabb, b: &Aabb, new: &Aabb, t_ns: u64) -> SceneUpdate {
    let mut e = entity("merge", t_ns);
    e.cubes = vec![
        cube(a, PAIR_COLOR),
        cube(b, PAIR_COLOR),
        cube(new, NEW_COLOR),
    ];
    update(vec![e])
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

/// One indexed triangle list drawing the hull `h`, its vertices once ([`shown`]). A segment
/// hull is one degenerate triangle `[a, b, b]` and a point hull `[a, a, a]` (they draw nothing
/// but keep their geometry), so readers get exactly one primitive per hull.
pub fn hull_triangles(h: &Hull, rgba: [f64; 4]) -> TriangleListPrimitive {
    let points = h.vertices.iter().map(point).collect();
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

/// A sphere primitive: pose at the centre, size = the diameter along every axis (both
/// [`shown`]).
pub fn sphere(s: &Sphere, rgba: [f64; 4]) -> SpherePrimitive {
    let d = shown(2.0 * s.radius);
    let c = s.center.map(shown);
    SpherePrimitive {
        pose: pose_at(&c),
        size: vector(d, d, d),
        color: color(rgba),
    }
}

/// An indexed triangle list of scene primitives, built up by [`SceneMesh::add`]: each scene
/// vertex the primitives use appears once in `points` ([`shown`]), and the triangles index it
/// (unless the index is the identity). Adding keeps what is there, so nested sets (the leaves
/// of successive levels) are built once.
#[derive(Debug)]
pub struct SceneMesh<'s> {
    scene: &'s Scene,
    /// Index in `points` of each scene vertex, `u32::MAX` while unused.
    slot: Vec<u32>,
    points: Vec<Point3>,
    indices: Vec<u32>,
}

impl<'s> SceneMesh<'s> {
    /// An empty mesh over `scene`'s vertices.
    pub fn new(scene: &'s Scene) -> SceneMesh<'s> {
        SceneMesh {
            scene,
            slot: vec![u32::MAX; scene.points.len()],
            points: Vec::new(),
            indices: Vec::new(),
        }
    }

    /// Appends the triangles of primitives `prims`.
    pub fn add(&mut self, prims: impl IntoIterator<Item = usize>) {
        let scene = self.scene;
        for i in prims {
            for t in scene.prim_tris(i) {
                for &v in t {
                    let slot = &mut self.slot[v as usize];
                    if *slot == u32::MAX {
                        *slot = self.points.len() as u32;
                        self.points.push(point(&scene.points[v as usize]));
                    }
                    self.indices.push(*slot);
                }
            }
        }
    }

    /// The mesh so far as one primitive in colour `rgba` (see [`SceneMesh::into_primitive`]).
    pub fn primitive(&self, rgba: [f64; 4]) -> TriangleListPrimitive {
        Self::list(self.points.clone(), self.index_list(), rgba)
    }

    /// The mesh as one primitive in colour `rgba`, its points moved rather than copied. The
    /// indices are left out when they would be 0, 1, 2, … (no vertex shared, as in a triangle
    /// soup), which readers take as the default.
    pub fn into_primitive(self, rgba: [f64; 4]) -> TriangleListPrimitive {
        let indices = self.index_list();
        Self::list(self.points, indices, rgba)
    }

    fn index_list(&self) -> Vec<u32> {
        let identity = self.indices.len() == self.points.len()
            && self.indices.iter().enumerate().all(|(i, &v)| v == i as u32);
        if identity {
            Vec::new()
        } else {
            self.indices.clone()
        }
    }

    fn list(points: Vec<Point3>, indices: Vec<u32>, rgba: [f64; 4]) -> TriangleListPrimitive {
        TriangleListPrimitive {
            pose: pose_at(&P3::origin()),
            points,
            color: color(rgba),
            colors: Vec::new(),
            indices,
        }
    }
}

/// An indexed triangle list of one cover mesh ([`export::mesh`]).
fn mesh_triangles(g: &Geometry, rgba: [f64; 4]) -> TriangleListPrimitive {
    let (v, t) = export::mesh(g);
    TriangleListPrimitive {
        pose: pose_at(&P3::origin()),
        points: v.iter().map(point).collect(),
        color: color(rgba),
        colors: Vec::new(),
        indices: t.iter().flatten().copied().collect(),
    }
}

/// The `/cover` update at `t_ns`: entities `spheres` (`SpherePrimitive`s), `boxes`
/// (`CubePrimitive`s, oriented ones with their rotation), `hulls` (one indexed
/// `TriangleListPrimitive` per hull, degenerate hulls as in [`export::mesh`]) and `leaves`
/// (one `TriangleListPrimitive` per leaf drawn as itself), each only when used.
pub fn cover_update(wrappers: &[WrapperRecord], t_ns: u64) -> SceneUpdate {
    let mut spheres = entity("spheres", t_ns);
    let mut boxes = entity("boxes", t_ns);
    let mut hulls = entity("hulls", t_ns);
    let mut leaves = entity("leaves", t_ns);
    let f = |a: &[f64; 3]| P3::new(a[0], a[1], a[2]);
    for w in wrappers {
        match &w.geometry {
            Geometry::Sphere { center, radius } => spheres.spheres.push(sphere(
                &Sphere {
                    center: f(center),
                    radius: *radius,
                },
                SPHERE_COLOR,
            )),
            Geometry::Box { min, max } => boxes.cubes.push(cube(
                &Aabb {
                    min: f(min),
                    max: f(max),
                },
                BOX_COLOR,
            )),
            Geometry::Obb {
                center,
                axes,
                half_extents,
            } => {
                let col = |k: usize| V3::new(axes[k][0], axes[k][1], axes[k][2]);
                let b = Obb {
                    center: f(center),
                    axes: nalgebra::Matrix3::from_columns(&[col(0), col(1), col(2)]),
                    half: V3::new(half_extents[0], half_extents[1], half_extents[2]),
                };
                boxes.cubes.push(obb_cube(&b, OBB_COLOR));
            }
            Geometry::Hull { .. } => hulls
                .triangles
                .push(mesh_triangles(&w.geometry, HULL_COLOR)),
            Geometry::Primitive { .. } => leaves
                .triangles
                .push(mesh_triangles(&w.geometry, LEAF_COLOR)),
        }
    }
    let used =
        |e: &SceneEntity| !(e.spheres.is_empty() && e.cubes.is_empty() && e.triangles.is_empty());
    update(
        [spheres, boxes, hulls, leaves]
            .into_iter()
            .filter(used)
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::generate;

    #[test]
    fn a_soup_is_drawn_without_indices_and_a_shared_mesh_with_them() {
        let soup = generate::soup(50, 1);
        let mut mesh = SceneMesh::new(&soup);
        mesh.add(0..soup.len());
        let list = mesh.into_primitive(SCENE_COLOR);
        assert_eq!(list.points.len(), 150);
        assert!(list.indices.is_empty());
        // The lamp's primitives share vertices: three indices per triangle, fewer points.
        let lamp = generate::lamp();
        let mut mesh = SceneMesh::new(&lamp);
        mesh.add(0..lamp.len());
        let kept = mesh.primitive(SCENE_COLOR);
        let moved = mesh.into_primitive(SCENE_COLOR);
        assert_eq!(kept, moved);
        assert_eq!(moved.indices.len(), 3 * lamp.tris.len());
        assert!(moved.points.len() < moved.indices.len());
    }

    #[test]
    fn drawn_vertices_are_the_scene_rounded_to_f32() {
        let soup = generate::soup(50, 1);
        let mut mesh = SceneMesh::new(&soup);
        mesh.add(0..soup.len());
        let list = mesh.into_primitive(SCENE_COLOR);
        let mut rounded = 0;
        for (q, p) in list.points.iter().zip(&soup.points) {
            for (drawn, exact) in [(q.x, p.x), (q.y, p.y), (q.z, p.z)] {
                assert_eq!(drawn, f64::from(exact as f32));
                rounded += usize::from(drawn != exact);
            }
        }
        assert!(
            rounded > 0,
            "the soup's coordinates are not all f32 already"
        );
        // Beyond f32's range a coordinate is kept rather than drawn at infinity.
        assert_eq!(shown(1e300), 1e300);
        assert_eq!(shown(-1e300), -1e300);
    }
}
