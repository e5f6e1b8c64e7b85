//! One link's sphere tree: its Subset Tree (the grouping phase on the link's pieces), the
//! smallest enclosing sphere of every node ([`welzl`](crate::wrap::welzl)), and the excess of
//! the spheres a cover looks at, measured on demand ([`LinkTree::measure`]).
//!
//! A sphere's **excess** is the largest distance to the link's surface over sampled points of
//! the sphere's surface that lie outside the link (by the side of the nearest face): a union's
//! boundary inside the link is mostly covered by its other spheres, and a sphere's inner side
//! says nothing about how well it hugs the surface. The distance is to the whole link, not just
//! the node's pieces, so the largest node excess of a cover bounds the cover's outer excess up
//! to sampling.
//!
//! **Tighter spheres.** The smallest enclosing sphere of a patch of surface is centred on the
//! patch, so half of it stands out of the link. When a node's pieces face one way (their
//! area-weighted normals sum to at least [`FACING`] of their area), spheres centred deeper
//! along the inward normal ([`DEPTHS`] × the smallest radius), each just large enough to hold
//! the node's vertices, are measured too; of those within [`MEAN_SLACK`] of the least excess,
//! the one of least mean distance outside is kept: still conservative, and closer to the
//! surface outside.

use rayon::prelude::*;

use crate::geom::{P3, Sphere, V3};
use crate::grouping::{self, Params, SubsetTree};
use crate::scene::Scene;
use crate::stop::{Interrupted, Stop};
use crate::wrap::distance::{point_aabb, point_node, point_prim};
use crate::wrap::{LeafOrder, SphereMethod, sphere_tree};

/// Depths (times the smallest enclosing radius) of the candidate centres along a node's
/// inward normal.
pub const DEPTHS: [f64; 7] = [0.0, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0];
/// A candidate sphere within this share of a node's least excess may be kept for a smaller
/// mean distance outside.
pub const MEAN_SLACK: f64 = 0.1;
/// Share of a node's area its normals must sum to for deeper centres to be tried.
pub const FACING: f64 = 0.2;

/// Nodes measured between two checks of the stop request.
const CHUNK: usize = 256;

/// A link's Subset Tree with a sphere per node and the excess of those measured (index = node
/// id).
#[derive(Clone, Debug)]
pub struct LinkTree {
    /// The link's pieces (its polygons, long ones cut), the tree's leaves.
    pub mesh: Scene,
    /// The Subset Tree over `mesh`.
    pub tree: SubsetTree,
    /// Every node's sphere: the smallest enclosing one, or once measured the best candidate.
    pub spheres: Vec<Sphere>,
    /// Every sphere's excess, NaN until measured.
    pub excess: Vec<f64>,
    /// Every measured sphere's sample points outside the link: the sum of their distances to
    /// the surface and their number (what `spend.rs` lowers the mean of).
    pub outside: Vec<(f64, u32)>,
    /// Each piece's unit normal (zero when degenerate).
    normals: Vec<V3>,
    /// Every node's area-weighted normal sum and area.
    facing: Vec<(V3, f64)>,
    /// Every node's vertices.
    order: LeafOrder,
    /// The sample directions.
    dirs: Vec<V3>,
}

/// `n` directions spread evenly over the unit sphere (a Fibonacci lattice): the deterministic
/// samples of a sphere's surface.
pub fn directions(n: usize) -> Vec<V3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (2 * i + 1) as f64 / n as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let a = golden * i as f64;
            V3::new(r * a.cos(), r * a.sin(), z)
        })
        .collect()
}

/// The distance from `p` to the surface of `mesh` (the leaves of `tree`).
pub fn surface_distance(tree: &SubsetTree, mesh: &Scene, p: &P3, stack: &mut Vec<u32>) -> f64 {
    point_node(tree, mesh, tree.root(), p, stack)
}

/// Unit normal of every primitive (its first triangle's; zero when degenerate).
fn prim_normals(mesh: &Scene) -> Vec<V3> {
    (0..mesh.len())
        .map(|i| {
            mesh.prim_tris(i)
                .iter()
                .map(|t| {
                    let p = t.map(|v| mesh.points[v as usize]);
                    (p[1] - p[0]).cross(&(p[2] - p[0]))
                })
                .max_by(|a, b| a.norm_squared().total_cmp(&b.norm_squared()))
                .and_then(|n| n.try_normalize(0.0))
                .unwrap_or_else(V3::zeros)
        })
        .collect()
}

impl LinkTree {
    /// Groups `mesh` (default parameters), refines the tree when `refine` (the fast path's
    /// refinement, [`refine_fast`](crate::refine::refine_fast)) and computes every node's sphere;
    /// excess is measured later with `samples` points per sphere. Stops with [`Interrupted`]
    /// when `stop` is requested.
    pub fn build(
        mesh: Scene,
        samples: usize,
        refine: bool,
        stop: &Stop,
    ) -> Result<LinkTree, Interrupted> {
        let params = Params::default().resolve(&mesh);
        let tree = grouping::group_until(&mesh, &params, (), stop.flag())
            .map_err(|_| Interrupted)?
            .tree;
        let tree = if refine {
            crate::refine::refine_fast(tree).tree
        } else {
            tree
        };
        stop.check()?;
        let spheres = sphere_tree(&tree, &mesh, SphereMethod::Minimum);
        let normals = prim_normals(&mesh);
        let n = tree.leaves();
        let mut facing: Vec<(V3, f64)> = (0..tree.len())
            .map(|x| {
                if x >= n {
                    return (V3::zeros(), 0.0);
                }
                let area: f64 = mesh
                    .prim_tris(x)
                    .iter()
                    .map(|t| {
                        let p = t.map(|v| mesh.points[v as usize]);
                        (p[1] - p[0]).cross(&(p[2] - p[0])).norm() / 2.0
                    })
                    .sum();
                (normals[x] * area, area)
            })
            .collect();
        for (i, [a, b]) in tree.children.iter().enumerate() {
            let (fa, fb) = (facing[*a as usize], facing[*b as usize]);
            facing[n + i] = (fa.0 + fb.0, fa.1 + fb.1);
        }
        let order = LeafOrder::new(&tree, &mesh);
        Ok(LinkTree {
            facing,
            order,
            excess: vec![f64::NAN; spheres.len()],
            outside: vec![(0.0, 0); spheres.len()],
            mesh,
            tree,
            spheres,
            normals,
            dirs: directions(samples),
        })
    }

    /// The distance from `p` to the surface and whether `p` is outside (by the side of the
    /// nearest piece; among pieces at the same distance, the one whose plane is farthest).
    pub fn signed(&self, p: &P3, stack: &mut Vec<u32>) -> (f64, bool) {
        let (tree, mesh) = (&self.tree, &self.mesh);
        let mut best = f64::INFINITY;
        let mut plane = 0.0f64;
        stack.clear();
        stack.push(tree.root());
        while let Some(x) = stack.pop() {
            if point_aabb(p, &tree.aabb[x as usize]) > best {
                continue;
            }
            match tree.children_of(x) {
                None => {
                    let i = x as usize;
                    let d = point_prim(mesh, i, p);
                    let v0 = mesh.points[mesh.prim(i)[0] as usize];
                    let h = self.normals[i].dot(&(p - v0));
                    let tie = 1e-12 * (1.0 + best.abs());
                    if d < best - tie {
                        best = d;
                        plane = h;
                    } else if d <= best + tie && h.abs() > plane.abs() {
                        best = best.min(d);
                        plane = h;
                    }
                }
                Some([a, b]) => {
                    let da = point_aabb(p, &tree.aabb[a as usize]);
                    let db = point_aabb(p, &tree.aabb[b as usize]);
                    if da < db {
                        stack.extend([b, a]);
                    } else {
                        stack.extend([a, b]);
                    }
                }
            }
        }
        (best, plane > 0.0)
    }

    /// The excess of sphere `s`: the largest distance to the surface of its sample points
    /// outside the link (0 when none is).
    pub fn sphere_excess(&self, s: &Sphere, stack: &mut Vec<u32>) -> f64 {
        self.excess_stats(s, stack).0
    }

    /// Over the sample points of `s` outside the link: their largest distance to the surface
    /// (0 when none is), the sum of those distances and their number.
    fn excess_stats(&self, s: &Sphere, stack: &mut Vec<u32>) -> (f64, f64, u32) {
        let (mut max, mut sum, mut n) = (0.0f64, 0.0, 0u32);
        for d in &self.dirs {
            let (dist, out) = self.signed(&(s.center + d * s.radius), stack);
            if out {
                max = max.max(dist);
                sum += dist;
                n += 1;
            }
        }
        (max, sum, n)
    }

    /// The sphere for node `x` among the candidates (see the module) and its excess: of those
    /// within [`MEAN_SLACK`] of the least excess, the one of least mean distance outside.
    pub fn best_sphere(&self, x: u32, stack: &mut Vec<u32>) -> (Sphere, f64, (f64, u32)) {
        self.best_for(
            self.spheres[x as usize],
            self.order.node_points(x),
            self.facing[x as usize],
            stack,
        )
    }

    /// The best sphere holding `points` (see the module), from their smallest enclosing sphere
    /// `base` and their area-weighted normal sum and area, with its excess and the sum and
    /// number of its samples outside.
    pub fn best_for(
        &self,
        base: Sphere,
        points: &[P3],
        (sum, area): (V3, f64),
        stack: &mut Vec<u32>,
    ) -> (Sphere, f64, (f64, u32)) {
        let mut found = vec![(base, self.excess_stats(&base, stack))];
        if sum.norm() >= FACING * area && area > 0.0 && base.radius > 0.0 {
            let inward = -sum.normalize();
            for &k in &DEPTHS[1..] {
                let center = base.center + inward * (k * base.radius);
                let radius = points
                    .iter()
                    .map(|p| (p - center).norm())
                    .fold(0.0, f64::max);
                let s = Sphere { center, radius };
                found.push((s, self.excess_stats(&s, stack)));
            }
        }
        let least = found.iter().map(|f| f.1.0).fold(f64::INFINITY, f64::min);
        let (s, (max, sum, n)) = found
            .into_iter()
            .filter(|f| f.1.0 <= least * (1.0 + MEAN_SLACK))
            .min_by(|a, b| a.1.1.total_cmp(&b.1.1))
            .expect("the least is among them");
        (s, max, (sum, n))
    }

    /// The excess of `s`, and the sum and number of its samples outside the link.
    pub fn stats(&self, s: &Sphere, stack: &mut Vec<u32>) -> (f64, (f64, u32)) {
        let (max, sum, n) = self.excess_stats(s, stack);
        (max, (sum, n))
    }

    /// Leaf `p`'s area-weighted normal and area.
    pub fn piece_facing(&self, p: u32) -> (V3, f64) {
        self.facing[p as usize]
    }

    /// Measures the excess of every node of `nodes` not measured yet, in parallel, keeping
    /// each one's best sphere.
    pub fn measure(&mut self, nodes: &[u32], stop: &Stop) -> Result<(), Interrupted> {
        let todo: Vec<u32> = nodes
            .iter()
            .copied()
            .filter(|&x| self.excess[x as usize].is_nan())
            .collect();
        for chunk in todo.chunks(CHUNK) {
            stop.check()?;
            let this = &*self;
            let values: Vec<(Sphere, f64, (f64, u32))> = chunk
                .par_iter()
                .map_init(Vec::new, |stack, &x| this.best_sphere(x, stack))
                .collect();
            for (&x, (s, e, o)) in chunk.iter().zip(values) {
                self.spheres[x as usize] = s;
                self.excess[x as usize] = e;
                self.outside[x as usize] = o;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_are_unit_and_balanced() {
        let d = directions(400);
        assert!(d.iter().all(|v| (v.norm() - 1.0).abs() < 1e-12));
        let mean: V3 = d.iter().sum::<V3>() / 400.0;
        assert!(mean.norm() < 1e-2, "{mean}");
    }
}
