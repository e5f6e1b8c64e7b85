//! Cutting a link's polygons into triangles of bounded edge length, so that the leaves of its
//! Subset Tree are small enough for a sphere to fit each closely: a triangle's smallest
//! enclosing sphere is centred on the triangle, so no point of that sphere is farther than its
//! radius (at most the longest edge / √3) from the surface. The surface is unchanged; every
//! input vertex stays a vertex.

use crate::geom::P3;
use crate::scene::{PrimitiveKind, Scene};

/// Most pieces one triangle is cut into (halvings stop there).
pub const MAX_PIECES: usize = 4096;

/// `mesh` with every triangle whose longest edge exceeds `max_edge` halved across its longest
/// edge until none does (or [`MAX_PIECES`] pieces); polygons whose vertices are all within
/// `max_edge` of each other are kept whole, the others are cut through their triangles.
pub fn split_long_edges(mesh: &Scene, max_edge: f64) -> Scene {
    let mut out = Scene::new(mesh.name.clone());
    out.points = mesh.points.clone();
    let long = |a: &P3, b: &P3| (a - b).norm() > max_edge;
    for i in 0..mesh.len() {
        let verts = mesh.prim(i);
        let n = verts.len();
        // Every pair of vertices, not only the edges: a disc's many short edges span a wide
        // polygon, whose own sphere would be as wide.
        let within = (0..n).all(|a| {
            (a + 1..n).all(|b| {
                let (a, b) = (verts[a] as usize, verts[b] as usize);
                !long(&mesh.points[a], &mesh.points[b])
            })
        });
        if within || max_edge.is_nan() || max_edge <= 0.0 {
            out.push(PrimitiveKind::Polygon, verts, mesh.prim_tris(i));
            continue;
        }
        for t in mesh.prim_tris(i) {
            let mut stack = vec![(*t, 1usize)];
            while let Some((t, pieces)) = stack.pop() {
                let p = t.map(|v| out.points[v as usize]);
                let edge = |k: usize| (p[(k + 1) % 3] - p[k]).norm();
                let k = (0..3)
                    .max_by(|&a, &b| edge(a).total_cmp(&edge(b)))
                    .expect("three edges");
                if edge(k) <= max_edge || pieces * 2 > MAX_PIECES {
                    out.push(PrimitiveKind::Polygon, &t, &[t]);
                    continue;
                }
                let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                let m = out.points.len() as u32;
                let pa = out.points[a as usize];
                let pb = out.points[b as usize];
                out.points.push(P3::from((pa.coords + pb.coords) / 2.0));
                stack.push(([m, b, c], pieces * 2));
                stack.push(([a, m, c], pieces * 2));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_triangles_are_halved_and_keep_their_area() {
        let mut s = Scene::new("t");
        s.points = vec![
            P3::new(0.0, 0.0, 0.0),
            P3::new(4.0, 0.0, 0.0),
            P3::new(0.0, 1.0, 0.0),
        ];
        s.push(PrimitiveKind::Polygon, &[0, 1, 2], &[[0, 1, 2]]);
        let out = split_long_edges(&s, 1.0);
        let area = |t: &[u32; 3]| {
            let p = t.map(|v| out.points[v as usize]);
            (p[1] - p[0]).cross(&(p[2] - p[0])).norm() / 2.0
        };
        let total: f64 = out.tris.iter().map(area).sum();
        assert!((total - 2.0).abs() < 1e-12, "{total}");
        for t in &out.tris {
            for k in 0..3 {
                let (a, b) = (
                    out.points[t[k] as usize],
                    out.points[t[(k + 1) % 3] as usize],
                );
                assert!((a - b).norm() <= 1.0 + 1e-12);
            }
        }
        assert!(out.len() > 4);
        assert_eq!(split_long_edges(&s, 10.0).len(), 1);
    }

    #[test]
    fn a_disc_of_short_edges_is_cut_to_pieces_of_the_bound() {
        // A 32-gon of radius 1: edges of about 0.2, but 2 across.
        let n = 32u32;
        let mut s = Scene::new("disc");
        s.points = (0..n)
            .map(|k| {
                let t = f64::from(k) * std::f64::consts::TAU / f64::from(n);
                P3::new(t.cos(), t.sin(), 0.0)
            })
            .collect();
        let verts: Vec<u32> = (0..n).collect();
        let fan: Vec<[u32; 3]> = (1..n - 1).map(|k| [0, k, k + 1]).collect();
        s.push(PrimitiveKind::Polygon, &verts, &fan);
        let out = split_long_edges(&s, 0.5);
        assert!(out.len() > 8, "{} pieces", out.len());
        for i in 0..out.len() {
            let p: Vec<P3> = out.prim_vertices(i).copied().collect();
            for a in &p {
                for b in &p {
                    assert!((a - b).norm() <= 0.5 + 1e-12);
                }
            }
        }
        assert_eq!(
            split_long_edges(&s, 2.5).len(),
            1,
            "within the bound: kept whole"
        );
    }
}
