//! Scores of a sphere set against a robot's link meshes, link by link in link frames, with the
//! definitions of the independent checker the sets are compared with (`sphere_check.py`):
//!
//! - **uncovered**: the share of points — every mesh vertex and [`SURFACE_SAMPLES`] surface
//!   samples per link — outside every sphere of their link by more than [`SLACK`], and the
//!   deepest point outside (the largest distance outside the nearest sphere's surface; ≤ 0 when
//!   every point is inside);
//! - **excess**: distances from points on the boundary of each link's sphere union
//!   ([`SPHERE_SAMPLES`] per sphere, those strictly inside another sphere left out) to the
//!   link's mesh surface: the largest and the mean over all such points;
//! - **volume ratio**: the volume of the link's sphere union (on a [`GRID`]³ grid over the
//!   spheres' box) over the mesh's enclosed volume.
//!
//! The sampling is deterministic (a seeded generator for the surface, a Fibonacci lattice on
//! the spheres); distances to the surface are exact point–triangle distances.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::link_tree::{directions, surface_distance};
use crate::geom::{P3, Sphere};
use crate::grouping::SubsetTree;
use crate::scene::Scene;

/// Surface samples per link.
pub const SURFACE_SAMPLES: usize = 4000;
/// Boundary samples per sphere.
pub const SPHERE_SAMPLES: usize = 400;
/// A point farther than this outside every sphere is uncovered (0.1 mm in metres).
pub const SLACK: f64 = 1e-4;
/// Grid cells per axis for the union's volume.
pub const GRID: usize = 48;

/// One link's score.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LinkScore {
    /// Link name.
    pub link: String,
    /// Spheres of the link.
    pub spheres: usize,
    /// Points checked for cover (vertices and surface samples).
    pub points: usize,
    /// Share of the points outside every sphere.
    pub uncovered: f64,
    /// Deepest point outside (≤ 0: all inside).
    pub outside_max: f64,
    /// Largest excess.
    pub excess_max: f64,
    /// Mean excess.
    pub excess_mean: f64,
    /// Boundary points the excess is measured at.
    pub excess_points: usize,
    /// Volume of the sphere union.
    pub sphere_volume: f64,
    /// Volume the mesh encloses.
    pub mesh_volume: f64,
    /// Sphere union volume over mesh volume.
    pub volume_ratio: f64,
}

/// A robot's score: the links' and their totals.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Score {
    /// Spheres in all.
    pub spheres: usize,
    /// Links with geometry.
    pub links: usize,
    /// Links with geometry and no sphere.
    pub links_without_spheres: Vec<String>,
    /// Links of the set without geometry in the robot (their spheres count in `spheres`, and
    /// are scored against nothing).
    pub links_not_in_robot: Vec<String>,
    /// Share of all points outside every sphere of their link.
    pub uncovered: f64,
    /// Deepest point outside over all links.
    pub outside_max: f64,
    /// Largest excess over all links.
    pub excess_max: f64,
    /// Mean excess over all boundary points.
    pub excess_mean: f64,
    /// The links' sphere union volumes over their mesh volumes, both summed.
    pub volume_ratio: f64,
    /// Every link's score, in the links' order.
    pub per_link: Vec<LinkScore>,
}

/// Surface samples of `mesh`: area-weighted, from a generator seeded with 0.
pub fn surface_samples(mesh: &Scene, n: usize) -> Vec<P3> {
    let area = |t: &[u32; 3]| {
        let p = t.map(|v| mesh.points[v as usize]);
        (p[1] - p[0]).cross(&(p[2] - p[0])).norm() / 2.0
    };
    let mut cum = Vec::with_capacity(mesh.tris.len());
    let mut sum = 0.0;
    for t in &mesh.tris {
        sum += area(t);
        cum.push(sum);
    }
    if sum.is_nan() || sum <= 0.0 {
        return Vec::new();
    }
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    (0..n)
        .map(|_| {
            let u: f64 = rng.random::<f64>() * sum;
            let i = cum.partition_point(|&c| c < u).min(cum.len() - 1);
            let p = mesh.tris[i].map(|v| mesh.points[v as usize]);
            let (r1, r2): (f64, f64) = (rng.random::<f64>().sqrt(), rng.random());
            P3::from(
                p[0].coords * (1.0 - r1)
                    + p[1].coords * (r1 * (1.0 - r2))
                    + p[2].coords * (r1 * r2),
            )
        })
        .collect()
}

/// The enclosed volume of `mesh` (|Σ signed tetrahedra|; meaningful for closed meshes).
pub fn mesh_volume(mesh: &Scene) -> f64 {
    mesh.tris
        .iter()
        .map(|t| {
            let p = t.map(|v| mesh.points[v as usize].coords);
            p[0].dot(&p[1].cross(&p[2])) / 6.0
        })
        .sum::<f64>()
        .abs()
}

/// The volume of the union of `spheres`, counted on a [`GRID`]³ grid of cell centres.
pub fn union_volume(spheres: &[Sphere]) -> f64 {
    if spheres.is_empty() {
        return 0.0;
    }
    let lo = spheres
        .iter()
        .map(|s| s.center.coords.add_scalar(-s.radius))
        .reduce(|a, b| a.inf(&b))
        .expect("not empty");
    let hi = spheres
        .iter()
        .map(|s| s.center.coords.add_scalar(s.radius))
        .reduce(|a, b| a.sup(&b))
        .expect("not empty");
    let step = (hi - lo) / GRID as f64;
    let mut inside = 0usize;
    for i in 0..GRID {
        for j in 0..GRID {
            for k in 0..GRID {
                let p = lo
                    + step.component_mul(&nalgebra::Vector3::new(
                        i as f64 + 0.5,
                        j as f64 + 0.5,
                        k as f64 + 0.5,
                    ));
                if spheres
                    .iter()
                    .any(|s| (p - s.center.coords).norm_squared() <= s.radius * s.radius)
                {
                    inside += 1;
                }
            }
        }
    }
    inside as f64 * step.x * step.y * step.z
}

/// Scores `spheres` of link `name` against its `mesh` (vertices, samples, volume), measuring
/// distances to the surface with `tree` over `pieces` (the same surface, maybe cut finer).
pub fn score_link(
    name: &str,
    mesh: &Scene,
    tree: &SubsetTree,
    pieces: &Scene,
    spheres: &[Sphere],
) -> LinkScore {
    let mut points: Vec<P3> = mesh.points.clone();
    points.extend(surface_samples(mesh, SURFACE_SAMPLES));
    let outside = |p: &P3| {
        spheres
            .iter()
            .map(|s| (p - s.center).norm() - s.radius)
            .fold(f64::INFINITY, f64::min)
    };
    let depth: Vec<f64> = points.iter().map(outside).collect();
    let uncovered = depth.iter().filter(|&&d| d.is_nan() || d > SLACK).count();
    let dirs = directions(SPHERE_SAMPLES);
    let mut stack = Vec::new();
    let (mut max, mut sum, mut count) = (0.0f64, 0.0, 0usize);
    for (i, s) in spheres.iter().enumerate() {
        for d in &dirs {
            let b = s.center + d * s.radius;
            let covered = spheres
                .iter()
                .enumerate()
                .any(|(j, o)| j != i && (b - o.center).norm() - o.radius < -1e-9);
            if covered {
                continue;
            }
            let e = surface_distance(tree, pieces, &b, &mut stack);
            max = max.max(e);
            sum += e;
            count += 1;
        }
    }
    let volume = mesh_volume(mesh);
    let union = union_volume(spheres);
    LinkScore {
        link: name.to_string(),
        spheres: spheres.len(),
        points: points.len(),
        uncovered: uncovered as f64 / points.len().max(1) as f64,
        outside_max: depth.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        excess_max: max,
        excess_mean: if count > 0 { sum / count as f64 } else { 0.0 },
        excess_points: count,
        sphere_volume: union,
        mesh_volume: volume,
        volume_ratio: if volume > 0.0 {
            union / volume
        } else {
            f64::NAN
        },
    }
}

/// The totals of the links' scores.
pub fn total(per_link: Vec<LinkScore>) -> Score {
    let points: usize = per_link.iter().map(|l| l.points).sum();
    let unc: f64 = per_link.iter().map(|l| l.uncovered * l.points as f64).sum();
    let count: usize = per_link.iter().map(|l| l.excess_points).sum();
    let sum: f64 = per_link
        .iter()
        .map(|l| l.excess_mean * l.excess_points as f64)
        .sum();
    Score {
        spheres: per_link.iter().map(|l| l.spheres).sum(),
        links: per_link.len(),
        links_without_spheres: per_link
            .iter()
            .filter(|l| l.spheres == 0)
            .map(|l| l.link.clone())
            .collect(),
        links_not_in_robot: Vec::new(),
        uncovered: unc / points.max(1) as f64,
        outside_max: per_link
            .iter()
            .map(|l| l.outside_max)
            .fold(f64::NEG_INFINITY, f64::max),
        excess_max: per_link.iter().map(|l| l.excess_max).fold(0.0, f64::max),
        excess_mean: if count > 0 { sum / count as f64 } else { 0.0 },
        volume_ratio: per_link.iter().map(|l| l.sphere_volume).sum::<f64>()
            / per_link.iter().map(|l| l.mesh_volume).sum::<f64>(),
        per_link,
    }
}
