//! Tightening a link's cover once it is chosen.
//!
//! A cut's spheres overlap: a piece is often held by two or three of them, yet each node's
//! sphere holds all of its own pieces. [`tighten`] lets each sphere in turn (largest first)
//! give up the pieces another sphere already holds: it is rebuilt around the pieces only it
//! holds ([`LinkTree::best_for`]: their smallest enclosing sphere, or a deeper centre), and the
//! new sphere is kept when its excess is no larger and fewer of its samples stand out, by less.
//! A sphere that holds no piece alone is dropped. Every piece stays inside some sphere after
//! every step, so the cover stays conservative; the rounds repeat while a sphere changes, up
//! to [`ROUNDS`].

use super::link_tree::LinkTree;
use crate::geom::{P3, Sphere, V3};
use crate::stop::{Interrupted, Stop};
use crate::wrap::distance::point_aabb;
use crate::wrap::welzl::min_sphere;

/// Most rounds over the cover's spheres.
pub const ROUNDS: usize = 4;

/// A cover sphere after tightening: the sphere, its excess, and the sum and number of its
/// samples outside the link.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tight {
    /// The sphere.
    pub sphere: Sphere,
    /// Its excess ([`LinkTree::sphere_excess`]).
    pub excess: f64,
    /// Sum and number of its samples outside the link.
    pub outside: (f64, u32),
}

/// Whether `s` holds every vertex of piece `p` (up to rounding: its radius is their largest
/// distance).
fn holds(l: &LinkTree, s: &Sphere, p: usize) -> bool {
    let tol = 1e-12 * s.radius + 1e-15;
    l.mesh.prim_vertices(p).all(|v| s.contains(v, tol))
}

/// The pieces `s` holds, found through the link's tree.
fn held_by(l: &LinkTree, s: &Sphere, stack: &mut Vec<u32>) -> Vec<u32> {
    let mut out = Vec::new();
    stack.clear();
    stack.push(l.tree.root());
    while let Some(x) = stack.pop() {
        if point_aabb(&s.center, &l.tree.aabb[x as usize]) > s.radius {
            continue;
        }
        match l.tree.children_of(x) {
            Some([a, b]) => stack.extend([a, b]),
            None => {
                if holds(l, s, x as usize) {
                    out.push(x);
                }
            }
        }
    }
    out.sort_unstable();
    out
}

/// The cover `nodes` of `l` tightened (see the module): its spheres, as many or fewer. Stops
/// with [`Interrupted`] when `stop` is requested.
pub fn tighten(l: &LinkTree, nodes: &[u32], stop: &Stop) -> Result<Vec<Tight>, Interrupted> {
    let mut stack = Vec::new();
    let mut spheres: Vec<Option<Tight>> = nodes
        .iter()
        .map(|&x| {
            let x = x as usize;
            Some(Tight {
                sphere: l.spheres[x],
                excess: l.excess[x],
                outside: l.outside[x],
            })
        })
        .collect();
    for t in spheres.iter_mut().flatten() {
        if t.excess.is_nan() {
            let (e, o) = l.stats(&t.sphere, &mut stack);
            (t.excess, t.outside) = (e, o);
        }
    }
    // The pieces each sphere holds, and how many spheres hold each piece.
    let mut count = vec![0u32; l.mesh.len()];
    let mut held: Vec<Vec<u32>> = spheres
        .iter()
        .map(|t| held_by(l, &t.expect("all kept").sphere, &mut stack))
        .collect();
    for &p in held.iter().flatten() {
        count[p as usize] += 1;
    }
    let mut order: Vec<usize> = (0..spheres.len()).collect();
    order.sort_by(|&a, &b| {
        let r = |i: usize| spheres[i].map_or(0.0, |t| t.sphere.radius);
        r(b).total_cmp(&r(a)).then(a.cmp(&b))
    });
    for _ in 0..ROUNDS {
        stop.check()?;
        let mut changed = false;
        for &i in &order {
            let Some(cur) = spheres[i] else { continue };
            let alone: Vec<u32> = held[i]
                .iter()
                .copied()
                .filter(|&p| count[p as usize] == 1)
                .collect();
            let next = if alone.is_empty() {
                None
            } else {
                let points: Vec<P3> = alone
                    .iter()
                    .flat_map(|&p| l.mesh.prim_vertices(p as usize).copied())
                    .collect();
                let facing = alone.iter().fold((V3::zeros(), 0.0), |(n, a), &p| {
                    let (pn, pa) = l.piece_facing(p);
                    (n + pn, a + pa)
                });
                let (s, e, o) = l.best_for(min_sphere(&points), &points, facing, &mut stack);
                let mean = |(sum, n): (f64, u32)| if n > 0 { sum / n as f64 } else { 0.0 };
                let better = e <= cur.excess * (1.0 + 1e-9)
                    && o.0 < cur.outside.0 * (1.0 - 1e-9)
                    && mean(o) <= mean(cur.outside) * (1.0 + 1e-9);
                if !better {
                    continue;
                }
                Some(Tight {
                    sphere: s,
                    excess: e,
                    outside: o,
                })
            };
            changed = true;
            spheres[i] = next;
            for &p in &held[i] {
                count[p as usize] -= 1;
            }
            held[i] = next.map_or_else(Vec::new, |t| held_by(l, &t.sphere, &mut stack));
            for &p in &held[i] {
                count[p as usize] += 1;
            }
            debug_assert!(count.iter().all(|&c| c > 0));
        }
        if !changed {
            break;
        }
    }
    Ok(spheres.into_iter().flatten().collect())
}
