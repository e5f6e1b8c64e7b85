//! Components of a scene: the sets of primitives that pre-grouping (§1.3 of the paper) groups
//! on their own before the top level.
//!
//! - [`connected`]: primitives joined by shared boundary, i.e. sharing a vertex after welding
//!   vertices that lie within [`WELD_TOLERANCE`] × the diagonal of the box of the scene's
//!   points of each other (L∞).
//!   Welding sorts vertices by a grid cell of 64 tolerances: a vertex is compared with the
//!   vertices of its cell and of the neighbouring cells it is within the tolerance of, and
//!   close pairs are joined in a union-find; each primitive then joins its vertices.
//!   O(V log V) (vertices piled up in one cell compare pairwise).
//! - [`objects`]: the scene's own objects ([`Scene::objects`], the OBJ `o`/`g` groups).
//!
//! Both are deterministic: components are numbered in order of their smallest primitive, and
//! each lists its primitives in increasing order.

use super::Scene;
use foldhash::HashMap;

/// Vertices closer than this fraction of the scene's AABB diagonal (L∞) are welded.
///
/// 1e-7 is far above the rounding of coordinates written with ~15 digits and far below any
/// modelled gap (a 1 km scene welds within 0.1 mm).
pub const WELD_TOLERANCE: f64 = 1e-7;

/// A partition of a scene's primitives into components.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Components {
    /// Component of each primitive.
    pub of: Vec<u32>,
    /// Offsets into `prims`, one more than the components.
    pub start: Vec<u32>,
    /// Primitives of every component, concatenated, each component's in increasing order.
    pub prims: Vec<u32>,
}

impl Components {
    /// Number of components.
    pub fn len(&self) -> usize {
        self.start.len() - 1
    }

    /// Whether there are no components (an empty scene).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Primitives of component `c`, in increasing order.
    pub fn get(&self, c: usize) -> &[u32] {
        &self.prims[self.start[c] as usize..self.start[c + 1] as usize]
    }

    /// Numbers the classes of `label` (any per-primitive key) in order of their smallest
    /// primitive.
    fn from_labels(label: &[u32]) -> Components {
        // Labels are point indices or object ids: a dense table when they are small enough.
        let max = label.iter().copied().max().unwrap_or(0) as usize;
        let mut dense = vec![
            u32::MAX;
            if max < 4 * label.len() + 1024 {
                max + 1
            } else {
                0
            }
        ];
        let mut sparse: HashMap<u32, u32> = HashMap::default();
        let mut k = 0u32;
        let of: Vec<u32> = label
            .iter()
            .map(|&l| {
                let slot = match dense.get_mut(l as usize) {
                    Some(slot) => slot,
                    None => sparse.entry(l).or_insert(u32::MAX),
                };
                if *slot == u32::MAX {
                    *slot = k;
                    k += 1;
                }
                *slot
            })
            .collect();
        let k = k as usize;
        let mut start = vec![0u32; k + 1];
        for &c in &of {
            start[c as usize + 1] += 1;
        }
        for c in 0..k {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut prims = vec![0u32; of.len()];
        for (i, &c) in of.iter().enumerate() {
            prims[fill[c as usize] as usize] = i as u32;
            fill[c as usize] += 1;
        }
        Components { of, start, prims }
    }
}

/// A union-find over `0..n` with path halving; the smaller index becomes the root, so the
/// result does not depend on the order of unions.
struct UnionFind(Vec<u32>);

impl UnionFind {
    fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let up = self.0[self.0[x as usize] as usize];
            self.0[x as usize] = up;
            x = up;
        }
        x
    }

    fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.0[hi as usize] = lo;
        }
    }
}

/// The scene's own objects as components ([`Scene::objects`]; one component when it has none).
pub fn objects(scene: &Scene) -> Components {
    let label: Vec<u32> = (0..scene.len()).map(|i| scene.object(i)).collect();
    Components::from_labels(&label)
}

/// Connected components of primitives sharing a vertex after welding (see the module doc).
pub fn connected(scene: &Scene) -> Components {
    let n = scene.len();
    let np = scene.points.len();
    let mut uf = UnionFind((0..np as u32).collect());
    let bounds = crate::geom::Aabb::from_points(&scene.points);
    let tol = WELD_TOLERANCE * bounds.diameter();
    if tol.is_finite() && tol > 0.0 {
        weld(scene, &bounds.min, tol, &mut uf);
    }
    for i in 0..n {
        for w in scene.prim(i).windows(2) {
            uf.union(w[0], w[1]);
        }
    }
    let label: Vec<u32> = (0..n)
        .map(|i| {
            scene
                .prim(i)
                .first()
                .map_or(u32::MAX - i as u32, |&v| uf.find(v))
        })
        .collect();
    Components::from_labels(&label)
}

/// Joins in `uf` the vertices (used by primitives) within `tol` (L∞) of each other.
///
/// Cells have edge [`CELL_TOLERANCES`] × `tol`; vertices are sorted by their packed cell key
/// (21 bits per axis; keys that wrap around only bring far vertices together, which the
/// distance test rejects). A vertex is compared with the later vertices of its own cell and,
/// only when it lies within `tol` of a cell face, with the vertices of the cells beyond that
/// face (found by binary search): about 1.1 cell visits per vertex instead of 27, and no hash
/// table.
fn weld(scene: &Scene, min: &crate::geom::P3, tol: f64, uf: &mut UnionFind) {
    const MASK: u64 = (1 << 21) - 1;
    let np = scene.points.len();
    let h = CELL_TOLERANCES * tol;
    let inv = 1.0 / h;
    let mut used = vec![false; np];
    for &v in &scene.prim_points {
        used[v as usize] = true;
    }
    // Offsets from the lower corner are ≥ 0, so truncation is the floor.
    let cell = |p: &crate::geom::P3| [0, 1, 2].map(|a| ((p[a] - min[a]) * inv) as i64);
    let pack = |k: [i64; 3]| {
        (k[0] as u64 & MASK) | ((k[1] as u64 & MASK) << 21) | ((k[2] as u64 & MASK) << 42)
    };
    let mut order: Vec<(u64, u32)> = (0..np)
        .filter(|&v| used[v])
        .map(|v| (pack(cell(&scene.points[v])), v as u32))
        .collect();
    order.sort_unstable();
    let close =
        |v: u32, w: u32| (scene.points[w as usize] - scene.points[v as usize]).amax() <= tol;
    for (i, &(key, v)) in order.iter().enumerate() {
        for &(_, w) in order[i + 1..].iter().take_while(|e| e.0 == key) {
            if close(v, w) {
                uf.union(v, w);
            }
        }
        let p = &scene.points[v as usize];
        let k = cell(p);
        // The neighbouring cells this vertex can reach within `tol`, per axis.
        let mut axis = [[0i64; 3]; 3];
        let mut len = [1usize; 3];
        for a in 0..3 {
            let lo = min[a] + k[a] as f64 * h;
            if p[a] - lo <= tol {
                axis[a][len[a]] = -1;
                len[a] += 1;
            }
            if lo + h - p[a] <= tol {
                axis[a][len[a]] = 1;
                len[a] += 1;
            }
        }
        if len == [1; 3] {
            continue;
        }
        for &dx in &axis[0][..len[0]] {
            for &dy in &axis[1][..len[1]] {
                for &dz in &axis[2][..len[2]] {
                    let nk = pack([k[0] + dx, k[1] + dy, k[2] + dz]);
                    if nk == key {
                        continue;
                    }
                    let from = order.partition_point(|e| e.0 < nk);
                    for &(_, w) in order[from..].iter().take_while(|e| e.0 == nk) {
                        // Each close pair across a face is found from both ends; join it once.
                        if w > v && close(v, w) {
                            uf.union(v, w);
                        }
                    }
                }
            }
        }
    }
}

/// Cell edge of the welding grid, in weld tolerances (see [`weld`]).
const CELL_TOLERANCES: f64 = 64.0;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::generate;

    #[test]
    fn robot_base_has_ten_parts() {
        // Cylinder, washer, boss, six bolt heads and the connector box are separate pieces.
        let c = connected(&generate::robot_base());
        assert_eq!(c.len(), 10);
        assert_eq!(c.get(0).len(), 42);
        let sizes: Vec<usize> = (0..c.len()).map(|k| c.get(k).len()).collect();
        assert_eq!(sizes.iter().sum::<usize>(), 276);
    }

    #[test]
    fn replicas_are_objects() {
        let s = generate::replicate(&generate::lamp(), 3, 1);
        let o = objects(&s);
        assert_eq!(o.len(), 3);
        assert_eq!(o.get(1), (626..1252).collect::<Vec<u32>>().as_slice());
    }
}
