//! A cover's wrappers as data ([`Geometry`], serialised in the JSON output) and as meshes
//! ([`to_obj`]: one `o node<id>-<kind>` group per wrapper).
//!
//! Meshes: spheres as circumscribed icospheres (subdivision 2: 162 vertices, 320 triangles,
//! scaled so every face lies on or outside the sphere, so the mesh still contains it), boxes
//! and oriented boxes as 12 triangles, hulls as their triangles, a leaf drawn as itself as its
//! primitive's triangles. Hulls of collinear or coincident points (no triangles) are written as
//! one degenerate triangle so every group has a face.

use super::{Cover, CoverKind, CoverNode};
use crate::geom::{P3, V3};
use crate::grouping::SubsetTree;
use crate::scene::Scene;
use crate::scene::obj_writer::ObjWriter;
use crate::wrap::hull::BOX_TRIANGLES;
use crate::wrap::kind::Wrappers;
use crate::wrap::obb::Obb;

/// The shape of one cover wrapper, in scene coordinates.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum Geometry {
    /// A leaf's own primitive.
    Primitive {
        /// Primitive index (= leaf id).
        primitive: u32,
        /// Its vertices.
        vertices: Vec<[f64; 3]>,
        /// Triangles indexing `vertices`.
        triangles: Vec<[u32; 3]>,
    },
    /// A sphere.
    Sphere {
        /// Centre.
        center: [f64; 3],
        /// Radius.
        radius: f64,
    },
    /// An axis-aligned box.
    Box {
        /// Lower corner.
        min: [f64; 3],
        /// Upper corner.
        max: [f64; 3],
    },
    /// An oriented box.
    Obb {
        /// Centre.
        center: [f64; 3],
        /// Unit axes (the rotation's columns).
        axes: [[f64; 3]; 3],
        /// Half extents along the axes.
        half_extents: [f64; 3],
    },
    /// A convex hull.
    Hull {
        /// Vertices.
        vertices: Vec<[f64; 3]>,
        /// Triangles indexing `vertices` (empty for a segment or a point).
        triangles: Vec<[u32; 3]>,
    },
}

/// One wrapper of a cover with its geometry (an element of the JSON `wrappers` array).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct WrapperRecord {
    /// Node id, kind, error and cost.
    #[serde(flatten)]
    pub node: CoverNode,
    /// Leaves under the node.
    pub leaves: usize,
    /// The shape.
    pub geometry: Geometry,
}

fn arr(p: &P3) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// The geometry of cover node `n`. Panics if `wrappers` lacks the chosen kind (the cover was
/// measured on other wrappers).
pub fn geometry(n: &CoverNode, scene: &Scene, wrappers: &Wrappers) -> Geometry {
    let x = n.node as usize;
    let missing = "cover measured on these wrappers";
    match n.choice.kind {
        CoverKind::Primitive => {
            let (vertices, triangles) = primitive_mesh(scene, x);
            Geometry::Primitive {
                primitive: n.node,
                vertices: vertices.iter().map(arr).collect(),
                triangles,
            }
        }
        CoverKind::Sphere => {
            let s = &wrappers.spheres.as_ref().expect(missing)[x];
            Geometry::Sphere {
                center: arr(&s.center),
                radius: s.radius,
            }
        }
        CoverKind::Box => {
            let b = &wrappers.boxes.as_ref().expect(missing)[x];
            Geometry::Box {
                min: arr(&b.min),
                max: arr(&b.max),
            }
        }
        CoverKind::Obb => {
            let b = &wrappers.obbs.as_ref().expect(missing)[x];
            let c = |k: usize| [b.axes[(0, k)], b.axes[(1, k)], b.axes[(2, k)]];
            Geometry::Obb {
                center: arr(&b.center),
                axes: [c(0), c(1), c(2)],
                half_extents: [b.half.x, b.half.y, b.half.z],
            }
        }
        CoverKind::Hull => {
            let h = &wrappers.hulls.as_ref().expect(missing)[x];
            Geometry::Hull {
                vertices: h.vertices.iter().map(arr).collect(),
                triangles: h.triangles.clone(),
            }
        }
    }
}

/// Every wrapper of `cover` with its leaf count and geometry.
pub fn records(
    cover: &Cover,
    tree: &SubsetTree,
    scene: &Scene,
    wrappers: &Wrappers,
) -> Vec<WrapperRecord> {
    cover
        .nodes
        .iter()
        .map(|n| WrapperRecord {
            node: *n,
            leaves: tree.leaves_under(n.node).len(),
            geometry: geometry(n, scene, wrappers),
        })
        .collect()
}

/// Primitive `i`'s own vertices and triangles (a fan when it has none).
fn primitive_mesh(scene: &Scene, i: usize) -> (Vec<P3>, Vec<[u32; 3]>) {
    let ids = scene.prim(i);
    let local = |v: u32| ids.iter().position(|&w| w == v).unwrap_or(0) as u32;
    let vertices = ids.iter().map(|&v| scene.points[v as usize]).collect();
    let mut triangles: Vec<[u32; 3]> = scene.prim_tris(i).iter().map(|t| t.map(local)).collect();
    if triangles.is_empty() {
        triangles = (1..ids.len().saturating_sub(1) as u32)
            .map(|k| [0, k, k + 1])
            .collect();
    }
    (vertices, triangles)
}

/// The mesh of one geometry (see the [module docs](self)).
pub fn mesh(g: &Geometry) -> (Vec<P3>, Vec<[u32; 3]>) {
    let p = |a: &[f64; 3]| P3::new(a[0], a[1], a[2]);
    let boxed = |b: Obb| {
        (
            (0..8).map(|k| b.corner(k)).collect(),
            BOX_TRIANGLES.to_vec(),
        )
    };
    match g {
        Geometry::Primitive {
            vertices,
            triangles,
            ..
        }
        | Geometry::Hull {
            vertices,
            triangles,
        } => {
            let mut t = triangles.clone();
            if t.is_empty() && !vertices.is_empty() {
                t.push([0, (vertices.len() - 1) as u32, (vertices.len() - 1) as u32]);
            }
            (vertices.iter().map(p).collect(), t)
        }
        Geometry::Sphere { center, radius } => {
            let (unit, tris) = icosphere();
            let c = p(center);
            (unit.iter().map(|u| c + u * *radius).collect(), tris)
        }
        Geometry::Box { min, max } => boxed(Obb::from_aabb(&crate::geom::Aabb {
            min: p(min),
            max: p(max),
        })),
        Geometry::Obb {
            center,
            axes,
            half_extents,
        } => {
            let col = |k: usize| V3::new(axes[k][0], axes[k][1], axes[k][2]);
            boxed(Obb {
                center: p(center),
                axes: nalgebra::Matrix3::from_columns(&[col(0), col(1), col(2)]),
                half: V3::new(half_extents[0], half_extents[1], half_extents[2]),
            })
        }
    }
}

/// Wavefront OBJ of the wrappers, one `o node<id>-<kind>` group each.
pub fn to_obj(records: &[WrapperRecord], title: &str) -> String {
    let comment = format!("wraptree cover of '{title}': {} wrappers", records.len());
    // Writing to a Vec cannot fail.
    let mut w = ObjWriter::new(Vec::new(), &comment).expect("writing to memory");
    for r in records {
        let (v, t) = mesh(&r.geometry);
        let base = w.vertices();
        w.object(&format!(
            "node{}-{}",
            r.node.node,
            r.node.choice.kind.name()
        ))
        .expect("writing to memory");
        for q in &v {
            w.vertex(q).expect("writing to memory");
        }
        for f in &t {
            w.face(f.map(|i| i as usize + base))
                .expect("writing to memory");
        }
    }
    String::from_utf8(w.into_inner()).expect("OBJ text is UTF-8")
}

/// Unit icosphere, subdivision 2, circumscribed (every face at distance ≥ 1 from the centre).
fn icosphere() -> (Vec<V3>, Vec<[u32; 3]>) {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<V3> = [
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ]
    .iter()
    .map(|a| V3::new(a[0], a[1], a[2]).normalize())
    .collect();
    let mut t: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..2 {
        let mut mid = std::collections::HashMap::new();
        let mut next = Vec::with_capacity(t.len() * 4);
        for [a, b, c] in t {
            let mut m = |i: u32, j: u32| {
                *mid.entry((i.min(j), i.max(j))).or_insert_with(|| {
                    v.push((v[i as usize] + v[j as usize]).normalize());
                    (v.len() - 1) as u32
                })
            };
            let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        t = next;
    }
    let inner = t
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|i| v[i as usize]);
            (b - a).cross(&(c - a)).normalize().dot(&a).abs()
        })
        .fold(f64::INFINITY, f64::min);
    (v.into_iter().map(|u| u / inner).collect(), t)
}
