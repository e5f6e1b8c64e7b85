//! The primitives as one shaded triangle mesh, shared by `scene/primitives` and
//! `levels/leaves/<k>` (a subset per leaf depth).
//!
//! Every primitive gets its own copies of its vertices, each with the normalised sum of the
//! area-weighted normals of the primitive's triangles at that vertex: a planar polygon is shaded
//! flat and a convex polyhedron smoothly, and neighbouring primitives do not blur into each
//! other. Degenerate triangles contribute no normal; a vertex with none gets +z.

use crate::geom::{P3, V3};
use crate::scene::Scene;

/// Vertices, normals and per-primitive triangles of the scene's drawing.
pub(super) struct PrimMesh {
    /// Vertex positions relative to the scene origin.
    pub(super) positions: Vec<[f32; 3]>,
    /// Unit vertex normals.
    pub(super) normals: Vec<[f32; 3]>,
    /// Offsets into `positions` and `normals` per primitive, length N + 1.
    vert_start: Vec<u32>,
    /// Offsets into `tris`, length N + 1.
    tri_start: Vec<u32>,
    /// Triangles as indices into `positions`.
    tris: Vec<[u32; 3]>,
}

impl PrimMesh {
    /// Builds the mesh of `scene` with positions relative to `origin`.
    pub(super) fn new(scene: &Scene, origin: &P3) -> PrimMesh {
        let mut m = PrimMesh {
            positions: Vec::with_capacity(scene.vertex_refs()),
            normals: Vec::with_capacity(scene.vertex_refs()),
            vert_start: Vec::with_capacity(scene.len() + 1),
            tri_start: Vec::with_capacity(scene.len() + 1),
            tris: Vec::with_capacity(scene.tris.len()),
        };
        m.vert_start.push(0);
        m.tri_start.push(0);
        let mut local: Vec<(u32, V3)> = Vec::new();
        for i in 0..scene.len() {
            let base = m.positions.len() as u32;
            local.clear();
            local.extend(scene.prim(i).iter().map(|&v| (v, V3::zeros())));
            let slot = |local: &[(u32, V3)], v: u32| local.iter().position(|&(w, _)| w == v);
            for t in scene.prim_tris(i) {
                let [a, b, c] = t.map(|v| scene.points[v as usize]);
                let n = (b - a).cross(&(c - a));
                let mut idx = [0u32; 3];
                for (k, &v) in t.iter().enumerate() {
                    let s = slot(&local, v).unwrap_or_else(|| {
                        local.push((v, V3::zeros()));
                        local.len() - 1
                    });
                    if n.iter().all(|x| x.is_finite()) {
                        local[s].1 += n;
                    }
                    idx[k] = base + s as u32;
                }
                m.tris.push(idx);
            }
            for &(v, n) in &local {
                m.positions
                    .push(super::rel(&scene.points[v as usize], origin));
                let len = n.norm();
                let n = if len > 0.0 { n / len } else { V3::z() };
                m.normals.push([n.x as f32, n.y as f32, n.z as f32]);
            }
            m.vert_start.push(m.positions.len() as u32);
            m.tri_start.push(m.tris.len() as u32);
        }
        m
    }

    /// The mesh of the primitives `prims` alone: their vertices, normals and triangles, the
    /// triangles indexing the returned vertices.
    pub(super) fn subset(&self, prims: &[u32]) -> PrimMesh {
        let mut m = PrimMesh {
            positions: Vec::new(),
            normals: Vec::new(),
            vert_start: vec![0],
            tri_start: vec![0],
            tris: Vec::new(),
        };
        for &i in prims {
            let (i, base) = (i as usize, m.positions.len() as u32);
            let verts = self.vert_start[i] as usize..self.vert_start[i + 1] as usize;
            let shift = base.wrapping_sub(self.vert_start[i]);
            m.positions
                .extend_from_slice(&self.positions[verts.clone()]);
            m.normals.extend_from_slice(&self.normals[verts]);
            let tris = self.prim_tris(i as u32).iter();
            m.tris
                .extend(tris.map(|t| t.map(|v| v.wrapping_add(shift))));
            m.vert_start.push(m.positions.len() as u32);
            m.tri_start.push(m.tris.len() as u32);
        }
        m
    }

    /// One colour per vertex: primitive `i` in the colour of its component `component[i]`,
    /// hues spread by the golden angle so neighbouring indices differ.
    pub(super) fn component_colors(&self, component: &[u32]) -> Vec<[u8; 4]> {
        let mut out = Vec::with_capacity(self.positions.len());
        for (i, w) in self.vert_start.windows(2).enumerate() {
            let c = hue_color(component.get(i).copied().unwrap_or(0));
            out.extend(std::iter::repeat_n(c, (w[1] - w[0]) as usize));
        }
        out
    }

    /// Every triangle.
    pub(super) fn all_tris(&self) -> &[[u32; 3]] {
        &self.tris
    }

    /// Whether the triangles are 0 1 2, 3 4 5, … (every vertex in one triangle, in order, as in
    /// a triangle soup): the default a `Mesh3D` without indices stands for.
    pub(super) fn sequential(&self) -> bool {
        self.tris.len() * 3 == self.positions.len()
            && (0u32..)
                .step_by(3)
                .zip(&self.tris)
                .all(|(i, t)| *t == [i, i + 1, i + 2])
    }

    /// Triangles of primitive `i`.
    /// The whole mesh as one shaded `Mesh3D` (positions, normals, and the triangles unless
    /// they are the positions in order), without colour.
    pub(super) fn to_mesh3d(&self) -> rerun::Mesh3D {
        let mesh = rerun::Mesh3D::new(self.positions.iter().copied())
            .with_vertex_normals(self.normals.iter().copied());
        // Without indices the viewer reads each three positions as a triangle.
        if self.sequential() {
            mesh
        } else {
            mesh.with_triangle_indices(self.all_tris().iter().copied())
        }
    }

    pub(super) fn prim_tris(&self, i: u32) -> &[[u32; 3]] {
        &self.tris[self.tri_start[i as usize] as usize..self.tri_start[i as usize + 1] as usize]
    }
}

/// A light, saturated colour for index `k` (hue = k × the golden angle).
fn hue_color(k: u32) -> [u8; 4] {
    let h = (k as f64 * 0.618_033_988_749_895).fract() * 6.0;
    let x = 1.0 - ((h % 2.0) - 1.0).abs();
    let (r, g, b) = match h as u32 {
        0 => (1.0, x, 0.0),
        1 => (x, 1.0, 0.0),
        2 => (0.0, 1.0, x),
        3 => (0.0, x, 1.0),
        4 => (x, 0.0, 1.0),
        _ => (1.0, 0.0, x),
    };
    let v = |c: f64| (90.0 + 150.0 * c) as u8;
    [v(r), v(g), v(b), 255]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::generate;

    #[test]
    fn only_a_soup_has_sequential_triangles() {
        let soup = generate::soup(40, 2);
        let m = PrimMesh::new(&soup, &P3::origin());
        assert!(m.sequential());
        assert_eq!(m.positions.len(), 120);
        // A polygon of more than three vertices shares them between its triangles.
        let lamp = generate::lamp();
        let m = PrimMesh::new(&lamp, &P3::origin());
        assert!(!m.sequential());
        assert!(m.positions.len() < 3 * m.all_tris().len());
    }
}
