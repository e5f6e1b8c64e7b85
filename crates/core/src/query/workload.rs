//! A seeded standard query workload for one scene and its mean cost per query (eq. (1)):
//! 256 points around the scene, 8 near poses and 8 touching poses of a rotated copy
//! ([`Workload::standard`]), run by [`measure`]. `docs/benchmarks.md` ("How it is measured")
//! describes it as the benchmarks use it.

use super::{
    Bv, Counts, Hierarchy, contacts_within, moved, moved_spheres, overlap_within,
    point_distance_within, scene_distance_within,
};
use crate::geom::{P3, V3};
use crate::grouping::SubsetTree;
use crate::scene::Scene;
use crate::scene::generate::random_rotation;
use crate::stop::{Interrupted, Stop};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Cost of one BV test in eq. (1) as [`measure`] reports it.
pub const C_V: f64 = 1.0;
/// Cost of one primitive test in eq. (1) as [`measure`] reports it.
pub const C_P: f64 = 1.0;

/// Tests (BV and primitive) per primitive of the scene after which a query of
/// [`Workload::standard`] stops ([`Counts::capped`]) on larger scenes ([`Workload::cap`]). The
/// cap is at least twice the most any query of the workload makes on the bundled and reference
/// meshes above 2,000 primitives (docs/benchmarks.md), within the [`MIN_MAX_TESTS`] floor, so
/// only exact ties reach it: `k` stacked coincident copies of a part make a scene–copy query
/// test `k²` tied pairs (up to `n²`).
pub const MAX_TESTS_PER_PRIM: u64 = 256;

/// Tests per pair of primitives (`n²`) below which the cap of [`Workload::standard`] does not
/// go, up to [`MIN_MAX_TESTS`]: small scenes make more tests per primitive (0.88·n² = 559·n, a
/// scene–copy distance with Goldsmith–Salmon's tree and merged spheres on a 636-polygon
/// scene), and a query tests at most about `5n²`.
pub const MAX_TESTS_PER_PAIR: u64 = 2;

/// The largest floor of the per-query cap ([`Workload::cap`]): 2^24 ≈ 1.7·10^7 tests.
pub const MIN_MAX_TESTS: u64 = 1 << 24;

/// Query points and poses of a copy of the scene (see [`Workload::standard`]).
#[derive(Clone, Debug)]
pub struct Workload {
    /// Points for point–scene distance queries.
    pub points: Vec<P3>,
    /// Poses (copy vertex `q` ↦ `pose * q`) whose copy is apart from the scene.
    pub poses_near: Vec<Isometry3<f64>>,
    /// Poses whose copy overlaps the scene partially.
    pub poses_touching: Vec<Isometry3<f64>>,
    /// Tests after which one query stops, counted as capped ([`MAX_TESTS_PER_PRIM`]).
    pub max_tests: u64,
}

/// A uniform random unit vector.
fn random_direction(rng: &mut ChaCha8Rng) -> V3 {
    let (u, v): (f64, f64) = (rng.random(), rng.random());
    let z = 2.0 * u - 1.0;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * v;
    V3::new(r * phi.cos(), r * phi.sin(), z)
}

/// The pose `q ↦ to + rot · (q − from)`.
fn pose_about(rot: UnitQuaternion<f64>, from: &P3, to: &P3) -> Isometry3<f64> {
    Isometry3::from_parts(Translation3::from(to.coords - rot * from.coords), rot)
}

impl Workload {
    /// The test cap of a query on a scene of `n` primitives: [`MAX_TESTS_PER_PRIM`]·n, and at
    /// least [`MAX_TESTS_PER_PAIR`]·n² or [`MIN_MAX_TESTS`], whichever is less.
    pub fn cap(n: usize) -> u64 {
        let n = n as u64;
        let floor = MAX_TESTS_PER_PAIR
            .saturating_mul(n.saturating_mul(n))
            .min(MIN_MAX_TESTS);
        MAX_TESTS_PER_PRIM.saturating_mul(n).max(floor)
    }

    /// The standard workload for `scene`; the same seed gives the same workload. Panics if the
    /// scene is empty.
    ///
    /// Drawn with a ChaCha8 RNG seeded by `seed`:
    /// - 256 query **points** uniform in the scene's AABB scaled by 1.1 about its centre (each
    ///   half-extent at least 5% of the diagonal, so flat scenes get a slab), so about a quarter
    ///   fall outside the box;
    /// - 8 **near** poses of a copy of the scene: a uniform random rotation about the box centre,
    ///   then a translation along a uniform random direction `u` until a slab of width `gap`
    ///   perpendicular to `u` separates the vertices of the copy from the original's, with `gap`
    ///   uniform in [2%, 30%] of the diagonal. The surfaces lie within their vertices' hull, so
    ///   the scene–copy distance is at least `gap` (> 0), and near it;
    /// - 8 **touching** poses: a uniform random rotation, then the translation that puts the
    ///   centroid of a random triangle of the copy on the centroid of a random triangle of the
    ///   original (a random vertex when the scene has no triangles). The two triangles then
    ///   cross there, so the copy overlaps the original partially.
    ///
    /// Each query stops after [`Workload::cap`] tests.
    pub fn standard(scene: &Scene, seed: u64) -> Workload {
        assert!(!scene.is_empty(), "the workload needs a non-empty scene");
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let bbox = scene.aabb();
        let (c, diag) = (bbox.center(), bbox.diameter());
        let half = (bbox.extents() * 0.55).map(|h| h.max(0.05 * diag));
        let points = (0..256)
            .map(|_| {
                let u: [f64; 3] = rng.random();
                c + V3::from(u.map(|x| 2.0 * x - 1.0)).component_mul(&half)
            })
            .collect();
        let poses_near = (0..8)
            .map(|_| {
                let rot = random_rotation(&mut rng);
                let u = random_direction(&mut rng);
                let gap = diag * rng.random_range(0.02..=0.30);
                let top = scene.points.iter().map(|p| u.dot(&p.coords));
                let top = top.fold(f64::NEG_INFINITY, f64::max);
                let low = scene.points.iter().map(|q| u.dot(&(rot * (q - c))));
                let low = low.fold(f64::INFINITY, f64::min);
                pose_about(rot, &c, &(c + u * (top - u.dot(&c.coords) - low + gap)))
            })
            .collect();
        let anchor = |rng: &mut ChaCha8Rng| -> P3 {
            if scene.tris.is_empty() {
                scene.points[rng.random_range(0..scene.points.len())]
            } else {
                let t = scene.tris[rng.random_range(0..scene.tris.len())];
                let [a, b, d] = t.map(|k| scene.points[k as usize].coords);
                P3::from((a + b + d) / 3.0)
            }
        };
        let poses_touching = (0..8)
            .map(|_| {
                let rot = random_rotation(&mut rng);
                let (to, from) = (anchor(&mut rng), anchor(&mut rng));
                pose_about(rot, &from, &to)
            })
            .collect();
        Workload {
            points,
            poses_near,
            poses_touching,
            max_tests: Workload::cap(scene.len()),
        }
    }
}

/// Mean work per query of one kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct MeanCost {
    /// Number of queries.
    pub queries: usize,
    /// Mean BV tests per query (`N_v`).
    pub bv_tests: f64,
    /// Mean primitive tests per query (`N_p`).
    pub prim_tests: f64,
    /// Eq. (1) per query: `N_v·C_V + N_p·C_P` (with `C_V = C_P = 1`).
    pub cost: f64,
    /// Seconds of the queries of this kind, each timed on its own and summed (they run side by
    /// side on rayon's threads, so on several threads their wall time is less).
    pub seconds: f64,
    /// Queries stopped at [`Workload::max_tests`] (their tests are a lower bound of the
    /// exact query's).
    pub capped: u64,
}

impl MeanCost {
    fn new(total: &Counts, queries: usize, seconds: f64) -> MeanCost {
        let (bv_tests, prim_tests) = total.per_query(queries);
        MeanCost {
            queries,
            bv_tests,
            prim_tests,
            cost: bv_tests * C_V + prim_tests * C_P,
            seconds,
            capped: total.capped,
        }
    }
}

/// The cost of a [`Workload`] on one hierarchy.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct QueryCost {
    /// Point–scene distance queries (one per workload point).
    pub point: MeanCost,
    /// Scene–copy distance queries (one per near pose).
    pub distance: MeanCost,
    /// Scene–copy overlap queries (one per near and per touching pose).
    pub overlap: MeanCost,
    /// How many overlap queries answered true.
    pub overlapping: usize,
    /// Scene–copy contact queries (one per touching pose: every touching primitive pair).
    ///
    /// Kept apart from the other kinds: an overlap query stops at the first touching pair, so
    /// its tests on a touching pose depend on how soon the traversal happens upon one (on one
    /// tree they range over three orders of magnitude between poses, and a few poses decide
    /// the mean), while a contact query visits every overlapping pair of BVs, so its tests
    /// depend on the two trees alone.
    ///
    /// Run with box BVs only (with sphere BVs no query, `queries` 0): with spheres they make
    /// many times the tests, about equal for every builder (the spheres' looseness, not the
    /// tree), and on an assembly of rigid copies some reach
    /// the test cap, which is meant for exact ties.
    pub contact: MeanCost,
    /// Touching primitive pairs the contact queries found, summed over the poses.
    pub contacts: u64,
    /// Seconds of all queries, summed as [`MeanCost::seconds`] (moving the copies excluded).
    pub seconds: f64,
}

impl QueryCost {
    /// Queries of every kind stopped at [`Workload::max_tests`].
    pub fn capped(&self) -> u64 {
        self.point.capped + self.distance.capped + self.overlap.capped + self.contact.capped
    }
}

/// Runs the whole workload on `tree` over `scene` with `bv` (sphere BVs are moved with each
/// copy by [`moved_spheres`]): all 256 point queries, a scene–copy distance query per near pose,
/// an overlap query per near and per touching pose (8 answers false, 8 true) and, with box
/// BVs, a contact query per touching pose ([`contacts_within`]), each stopping after
/// [`Workload::max_tests`] tests; moving the copies is not timed.
///
/// Once a query stops at the cap, the rest of its set (the points, the distances, the overlaps
/// of near poses, those of touching poses, the contacts) is not run and is counted as capped
/// with no tests (its mean is then a lower bound, and an overlap not run is not counted as
/// overlapping): only exact ties reach the cap, and on them every query of the set would run
/// to it.
///
/// The queries run side by side on rayon's threads, and their counts are summed in workload
/// order with the rule above, so the result is that of running them one by one, for any number
/// of threads: a query is not started once one before it in its set was capped, and one that
/// ran after such a query (started before that query ended) is dropped.
pub fn measure(tree: &SubsetTree, scene: &Scene, bv: Bv, workload: &Workload) -> QueryCost {
    match measure_until(tree, scene, bv, workload, &Stop::new()) {
        Ok(cost) => cost,
        Err(Interrupted) => unreachable!("nobody holds the new stop token"),
    }
}

/// The lowest index of a capped query in a set run side by side (`usize::MAX`: none yet).
struct FirstCapped(AtomicUsize);

impl FirstCapped {
    fn new() -> FirstCapped {
        FirstCapped(AtomicUsize::new(usize::MAX))
    }

    /// Whether query `i` is still to run: no query before it was capped so far.
    fn open(&self, i: usize) -> bool {
        self.0.load(Ordering::Relaxed) >= i
    }

    /// Runs query `i` of the set into fresh counts, timed, noting whether it was capped.
    fn run<T>(&self, i: usize, query: impl FnOnce(&mut Counts) -> T) -> (Counts, f64, T) {
        let (mut c, start) = (Counts::default(), Instant::now());
        let answer = query(&mut c);
        if c.capped > 0 {
            self.0.fetch_min(i, Ordering::Relaxed);
        }
        (c, start.elapsed().as_secs_f64(), answer)
    }
}

/// What one pose of the workload measured: its distance and overlap queries (`None`: not run),
/// each with its tests, seconds and (overlap) answer.
struct PoseResult {
    distance: Option<(Counts, f64, ())>,
    overlap: Option<(Counts, f64, bool)>,
    contact: Option<(Counts, f64, u64)>,
}

/// A set's queries summed in workload order, as the one-by-one run counts them: after its first
/// capped query, each counts as capped, with no tests.
#[derive(Default)]
struct InOrder {
    counts: Counts,
    seconds: f64,
}

impl InOrder {
    /// Adds the next query of the set (`None`: not run); returns its answer if it counts.
    fn push<T>(&mut self, r: Option<(Counts, f64, T)>) -> Option<T> {
        if self.counts.capped > 0 {
            self.counts.capped += 1;
            return None;
        }
        let (c, secs, answer) = r.expect("every query before a set's first capped one ran");
        self.counts.add(&c);
        self.seconds += secs;
        Some(answer)
    }
}

/// [`measure`] that checks `stop` before each query (Err: [`Interrupted`]).
pub fn measure_until(
    tree: &SubsetTree,
    scene: &Scene,
    bv: Bv,
    workload: &Workload,
    stop: &Stop,
) -> Result<QueryCost, Interrupted> {
    let h = Hierarchy { tree, scene, bv };
    let first = FirstCapped::new();
    let each: Vec<Option<(Counts, f64, ())>> = workload
        .points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            if !first.open(i) || stop.is_requested() {
                return None;
            }
            Some(first.run(i, |c| {
                point_distance_within(&h, p, workload.max_tests, c);
            }))
        })
        .collect();
    stop.check()?;
    let mut points = InOrder::default();
    for r in each {
        points.push(r);
    }
    let point = MeanCost::new(&points.counts, workload.points.len(), points.seconds);
    let near = workload.poses_near.iter().map(|p| (p, true));
    let poses: Vec<_> = near
        .chain(workload.poses_touching.iter().map(|p| (p, false)))
        .collect();
    // The distances, the overlaps of near and of touching poses, and the contacts stop at the
    // cap apart.
    let (first_dist, first_over) = (FirstCapped::new(), [FirstCapped::new(), FirstCapped::new()]);
    let first_contact = FirstCapped::new();
    // Contact queries with box BVs only (see [`QueryCost::contact`]).
    let boxes = matches!(bv, Bv::Aabb);
    let each: Vec<PoseResult> = poses
        .par_iter()
        .enumerate()
        .map(|(i, &(pose, is_near))| {
            let over_set = &first_over[usize::from(is_near)];
            let run_dist = is_near && first_dist.open(i);
            let run_over = over_set.open(i);
            let run_contact = boxes && !is_near && first_contact.open(i);
            if (!run_dist && !run_over && !run_contact) || stop.is_requested() {
                return PoseResult {
                    distance: None,
                    overlap: None,
                    contact: None,
                };
            }
            let (t, s) = moved(tree, scene, pose);
            let spheres = match bv {
                Bv::Aabb => Vec::new(),
                Bv::Sphere(sp) => moved_spheres(sp, pose),
            };
            let bv2 = match bv {
                Bv::Aabb => Bv::Aabb,
                Bv::Sphere(_) => Bv::Sphere(&spheres),
            };
            let copy = Hierarchy {
                tree: &t,
                scene: &s,
                bv: bv2,
            };
            let distance = run_dist.then(|| {
                first_dist.run(i, |c| {
                    scene_distance_within(&h, &copy, workload.max_tests, c);
                })
            });
            let overlap = run_over
                .then(|| over_set.run(i, |c| overlap_within(&h, &copy, workload.max_tests, c)));
            let contact = run_contact.then(|| {
                first_contact.run(i, |c| contacts_within(&h, &copy, workload.max_tests, c))
            });
            PoseResult {
                distance,
                overlap,
                contact,
            }
        })
        .collect();
    stop.check()?;
    // The distances, the overlaps of near and of touching poses, and the contacts, each set in
    // its order.
    let (mut dist, mut over) = (InOrder::default(), [InOrder::default(), InOrder::default()]);
    let (mut contact, mut contacts) = (InOrder::default(), 0u64);
    let mut overlapping = 0;
    for (&(_, is_near), r) in poses.iter().zip(each) {
        if is_near {
            dist.push(r.distance);
        } else if boxes {
            contacts += contact.push(r.contact).unwrap_or(0);
        }
        let hit = over[usize::from(is_near)].push(r.overlap);
        overlapping += usize::from(hit == Some(true));
    }
    let mut over_counts = over[0].counts;
    over_counts.add(&over[1].counts);
    let over_s = over[0].seconds + over[1].seconds;
    let n_pose = workload.poses_near.len() + workload.poses_touching.len();
    Ok(QueryCost {
        point,
        distance: MeanCost::new(&dist.counts, workload.poses_near.len(), dist.seconds),
        overlap: MeanCost::new(&over_counts, n_pose, over_s),
        overlapping,
        contact: MeanCost::new(
            &contact.counts,
            if boxes {
                workload.poses_touching.len()
            } else {
                0
            },
            contact.seconds,
        ),
        contacts,
        seconds: point.seconds + dist.seconds + over_s + contact.seconds,
    })
}
