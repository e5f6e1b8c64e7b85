//! Hierarchy queries against brute force: point–scene distance, scene–scene distance, overlap
//! and contacts on generated scenes, two tree shapes and AABB and sphere BVs; triangle–triangle
//! and segment–segment distances on hand-computed cases and against dense sampling; the
//! contact test against the distance.

use proptest::prelude::*;
use wraptree::geom::P3;
use wraptree::geom::distance::{segment_segment, segment_triangle, triangle_triangle};
use wraptree::grouping::{Params, SubsetTree, group};
use wraptree::query::prim::prims_touch;
use wraptree::query::{
    Bv, Counts, Hierarchy, Workload, contacts, measure, moved, moved_spheres, overlap,
    point_distance, reference, scene_distance, scene_distance_within,
};
use wraptree::scene::{Scene, generate};
use wraptree::wrap::{SphereMethod, sphere_tree};

fn p(x: f64, y: f64, z: f64) -> P3 {
    P3::new(x, y, z)
}

/// Triangle–triangle distance of corner arrays, checked symmetric in the argument order (to
/// rounding; 0 exactly).
fn tt(t: [P3; 3], u: [P3; 3]) -> f64 {
    let d = triangle_triangle([&t[0], &t[1], &t[2]], [&u[0], &u[1], &u[2]]);
    let e = triangle_triangle([&u[0], &u[1], &u[2]], [&t[0], &t[1], &t[2]]);
    let sym = (d == 0.0) == (e == 0.0) && (d - e).abs() <= 1e-14 * d.max(1.0);
    assert!(
        sym,
        "triangle_triangle is not symmetric for {t:?} {u:?}: {d} vs {e}"
    );
    d
}

fn close(got: f64, want: f64) -> bool {
    if want == 0.0 {
        got.abs() <= 1e-12
    } else {
        (got - want).abs() <= 1e-5 * want.abs()
    }
}

#[test]
fn triangle_triangle_hand_cases() {
    let t = [p(0.0, 0.0, 0.0), p(2.0, 0.0, 0.0), p(0.0, 2.0, 0.0)];
    // An edge of u pierces the interior of t; no vertex or edge pair is closer than 0.5.
    let pierce = [p(0.5, 0.5, -1.0), p(0.5, 0.5, 1.0), p(3.0, 3.0, 0.0)];
    assert_eq!(tt(t, pierce), 0.0);
    // The same triangle lifted by 1.5 no longer crosses: nearest is its lower vertex.
    let lifted = pierce.map(|q| q + wraptree::geom::V3::new(0.0, 0.0, 1.5));
    assert!(close(tt(t, lifted), 0.5));
    // A vertex of u on an edge of t (touching), then moved off the edge by 0.25.
    let touch = [p(0.5, 0.0, 0.0), p(0.5, -1.0, 1.0), p(0.5, -1.0, -1.0)];
    assert_eq!(tt(t, touch), 0.0);
    let off = touch.map(|q| q + wraptree::geom::V3::new(0.0, -0.25, 0.0));
    assert!(close(tt(t, off), 0.25));
    // Sharing an edge (touching along it).
    assert_eq!(
        tt(t, [p(0.0, 0.0, 0.0), p(2.0, 0.0, 0.0), p(0.0, 0.0, 1.0)]),
        0.0
    );
    // Coplanar disjoint: parallel hypotenuses sqrt(2)/2 apart... here a unit gap along x.
    let copl = [p(3.0, 0.0, 0.0), p(4.0, 0.0, 0.0), p(3.0, 1.0, 0.0)];
    assert!(close(tt(t, copl), 1.0));
    // Coplanar overlapping, and nested.
    assert_eq!(
        tt(t, [p(1.0, 0.5, 0.0), p(3.0, 0.5, 0.0), p(1.0, 2.5, 0.0)]),
        0.0
    );
    assert_eq!(
        tt(t, [p(0.2, 0.2, 0.0), p(0.4, 0.2, 0.0), p(0.2, 0.4, 0.0)]),
        0.0
    );
    // Parallel planes 0.5 apart, overlapping in projection.
    assert!(close(
        tt(t, [p(0.2, 0.2, 0.5), p(0.4, 0.2, 0.5), p(0.2, 0.4, 0.5)]),
        0.5
    ));
    // Skew edges: the closest points are interior points of one edge of each (distance 1),
    // every vertex–triangle distance is sqrt(2).
    let a = [p(-1.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(0.0, -1.0, 0.0)];
    let b = [p(0.0, 1.0, -1.0), p(0.0, 1.0, 1.0), p(0.0, 2.0, 0.0)];
    assert!(close(tt(a, b), 1.0));
}

#[test]
fn triangle_triangle_degenerate() {
    let t = [p(0.0, 0.0, 0.0), p(2.0, 0.0, 0.0), p(0.0, 2.0, 0.0)];
    // A collinear "triangle" above t, and one piercing it.
    let above = [p(0.2, 0.2, 1.0), p(0.2, 0.2, 2.0), p(0.2, 0.2, 3.0)];
    assert!(close(tt(t, above), 1.0));
    let through = [p(0.2, 0.2, -1.0), p(0.2, 0.2, 0.5), p(0.2, 0.2, 1.0)];
    assert_eq!(tt(t, through), 0.0);
    // A point triangle.
    let point = [p(0.5, 0.5, 2.0); 3];
    assert!(close(tt(t, point), 2.0));
    // Two degenerate triangles: skew segments 1 apart, then crossing segments.
    let s1 = [p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(0.5, 0.0, 0.0)];
    let s2 = [p(0.5, -1.0, 1.0), p(0.5, 1.0, 1.0), p(0.5, 0.0, 1.0)];
    assert!(close(tt(s1, s2), 1.0));
    let s3 = [p(0.5, -1.0, 0.0), p(0.5, 1.0, 0.0), p(0.5, 0.0, 0.0)];
    assert_eq!(tt(s1, s3), 0.0);
    // Two point triangles 5 apart.
    assert!(close(tt([p(0.0, 0.0, 0.0); 3], [p(3.0, 4.0, 0.0); 3]), 5.0));
}

#[test]
fn segment_cases() {
    let (o, x) = (p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0));
    // Parallel, overlapping in x, 0.5 apart; parallel disjoint; zero-length; crossing.
    assert!(close(
        segment_segment(&o, &x, &p(0.5, 0.5, 0.0), &p(3.0, 0.5, 0.0)),
        0.5
    ));
    assert!(close(
        segment_segment(&o, &x, &p(4.0, 0.0, 0.0), &p(5.0, 0.0, 0.0)),
        3.0
    ));
    assert!(close(
        segment_segment(&o, &x, &p(0.5, 2.0, 0.0), &p(0.5, 2.0, 0.0)),
        2.0
    ));
    assert!(close(segment_segment(&x, &x, &o, &o), 1.0));
    assert_eq!(
        segment_segment(&o, &x, &p(0.5, -1.0, 0.0), &p(0.5, 1.0, 0.0)),
        0.0
    );
    let (a, b, c) = (p(0.0, 0.0, 0.0), p(2.0, 0.0, 0.0), p(0.0, 2.0, 0.0));
    assert_eq!(
        segment_triangle(&p(0.5, 0.5, -1.0), &p(0.5, 0.5, 1.0), &a, &b, &c),
        0.0
    );
    assert!(close(
        segment_triangle(&p(3.0, 3.0, -1.0), &p(3.0, 3.0, 1.0), &a, &b, &c),
        8f64.sqrt()
    ));
}

/// Points of a triangle on a barycentric grid with `k` steps per edge.
fn grid(t: &[P3; 3], k: usize) -> Vec<P3> {
    let mut out = Vec::new();
    for i in 0..=k {
        for j in 0..=k - i {
            let (u, v) = (i as f64 / k as f64, j as f64 / k as f64);
            out.push(P3::from(
                t[0].coords * (1.0 - u - v) + t[1].coords * u + t[2].coords * v,
            ));
        }
    }
    out
}

fn coord() -> impl Strategy<Value = f64> {
    prop_oneof![-1.0..1.0f64, (-2i32..=2).prop_map(|i| i as f64 * 0.5)]
}

fn triangle() -> impl Strategy<Value = [P3; 3]> {
    prop::array::uniform3(prop::array::uniform3(coord()).prop_map(|c| p(c[0], c[1], c[2])))
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 192,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// The exact distance never exceeds any sampled pair's distance and the densest sampled
    /// pair is within the grid spacing of it.
    #[test]
    fn triangle_triangle_vs_sampling(
        t in triangle(),
        u in triangle(),
        shift in prop::array::uniform3(-1.5..1.5f64),
    ) {
        let u = u.map(|q| q + wraptree::geom::V3::from(shift));
        let exact = tt(t, u);
        let k = 24;
        let (gt, gu) = (grid(&t, k), grid(&u, k));
        let sampled = gt.iter()
            .flat_map(|a| gu.iter().map(move |b| (a - b).norm()))
            .fold(f64::INFINITY, f64::min);
        let longest = |s: &[P3; 3]| {
            (0..3).map(|i| (s[i] - s[(i + 1) % 3]).norm()).fold(0.0, f64::max)
        };
        prop_assert!(sampled >= exact - 1e-12, "sampled {sampled} < exact {exact}");
        let spacing = (longest(&t) + longest(&u)) / k as f64;
        prop_assert!(sampled <= exact + spacing + 1e-12, "sampled {sampled} ≫ exact {exact}");
    }

    /// A triangle built through an interior point of another, in a random plane, is at
    /// distance 0 from it.
    #[test]
    fn crossing_triangles_touch(t in prop::array::uniform3(prop::array::uniform3(-1.0..1.0f64)),
        bary in (0.1..0.8f64, 0.1..0.8f64),
        dirs in prop::array::uniform2(prop::array::uniform3(-1.0..1.0f64))) {
        let t = t.map(|c| p(c[0], c[1], c[2]));
        let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
        let n = e1.cross(&e2);
        prop_assume!(n.norm() > 0.05 * e1.norm() * e2.norm());
        let (u, v) = (bary.0, bary.1 * (1.0 - bary.0));
        let x = t[0] + e1 * u + e2 * v;
        let (d1, d2) = (wraptree::geom::V3::from(dirs[0]), wraptree::geom::V3::from(dirs[1]));
        let s = d1.cross(&d2);
        prop_assume!(s.norm() > 0.1 && s.normalize().cross(&n.normalize()).norm() > 0.2);
        // x is the centroid of u's corners x + d1, x + d2, x − d1 − d2.
        let u_tri = [x + d1, x + d2, x - d1 - d2];
        prop_assert_eq!(tt(t, u_tri), 0.0);
    }

    /// The contact test (planes that clearly separate skipped first) answers as the distance
    /// does: on random pairs, shifted apart or not, with corners on a half-unit grid where
    /// pairs touch at a corner, an edge or in a plane.
    #[test]
    fn prims_touch_agrees_with_the_distance(
        t in triangle(),
        u in triangle(),
        shift in prop::array::uniform3((-2i32..=2).prop_map(|i| i as f64 * 0.5)),
    ) {
        let u = u.map(|q| q + wraptree::geom::V3::from(shift));
        let one = |c: [P3; 3]| {
            let mut s = Scene::new("one");
            s.points.extend(c);
            s.push(wraptree::scene::PrimitiveKind::Polygon, &[0, 1, 2], &[[0, 1, 2]]);
            s
        };
        let (a, b) = (one(t), one(u));
        prop_assert_eq!(prims_touch(&a, 0, &b, 0), tt(t, u) == 0.0);
    }
}

/// A balanced tree pairing leaves in index order, level by level (an odd one is carried up).
fn pairing_tree(scene: &Scene) -> SubsetTree {
    let boxes: Vec<_> = (0..scene.len()).map(|i| scene.prim_aabb(i)).collect();
    let mut merges = Vec::new();
    let mut all = boxes.clone();
    let mut level: Vec<u32> = (0..scene.len() as u32).collect();
    while level.len() > 1 {
        let mut next = Vec::new();
        for pair in level.chunks(2) {
            if let [a, b] = *pair {
                let m = all[a as usize].merge(&all[b as usize]);
                next.push(all.len() as u32);
                all.push(m);
                merges.push((a, b, m, m.diameter()));
            } else {
                next.push(pair[0]);
            }
        }
        level = next;
    }
    let diam = boxes.iter().map(|b| b.diameter()).collect();
    SubsetTree::from_merges(boxes, diam, &merges).expect("pairing is a binary tree")
}

/// The same polygons with no triangles: each primitive is its closed vertex polygon.
fn edges_only(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    s.tris.clear();
    s.tri_start = vec![0; scene.len() + 1];
    s
}

/// Every query on `scene` (both tree shapes, AABB, sphere and mixed BVs) equals brute force.
/// `copy` is the scene the moved copies are made of (the scene itself or a variant with the
/// same vertices). The touching poses are checked to touch when both have triangles (the
/// workload crosses two triangles there). Returns the counts of the AABB grouping-tree
/// scene–scene queries.
fn check_scene(scene: &Scene, copy: &Scene, seed: u64) -> Counts {
    let expect_touch = !scene.tris.is_empty() && !copy.tris.is_empty();
    let w = Workload::standard(scene, seed);
    let trees = [
        group(scene, &Params::default(), ()).tree,
        pairing_tree(scene),
    ];
    let points: Vec<f64> = w
        .points
        .iter()
        .map(|q| reference::point_distance(scene, q))
        .collect();
    let poses: Vec<_> = w.poses_near.iter().chain(&w.poses_touching).collect();
    let copies: Vec<Scene> = poses
        .iter()
        .map(|pose| moved(&trees[0], copy, pose).1)
        .collect();
    let want: Vec<f64> = copies
        .iter()
        .map(|c| reference::scene_distance(scene, c))
        .collect();
    let touching: Vec<u64> = copies
        .iter()
        .map(|c| reference::contacts(scene, c))
        .collect();
    for (k, d) in want.iter().enumerate() {
        assert_eq!(touching[k] > 0, *d == 0.0, "pose {k}");
        if k < w.poses_near.len() {
            assert!(*d > 0.0, "near pose {k} touches the scene");
        } else if expect_touch {
            assert_eq!(*d, 0.0, "touching pose {k} does not touch");
        }
    }
    let mut summary = Counts::default();
    for (ti, tree) in trees.iter().enumerate() {
        let spheres = sphere_tree(tree, scene, SphereMethod::AabbCenter);
        for (bi, bv) in [Bv::Aabb, Bv::Sphere(&spheres)].into_iter().enumerate() {
            let h = Hierarchy { tree, scene, bv };
            let mut c = Counts::default();
            for (q, want) in w.points.iter().zip(&points) {
                let got = point_distance(&h, q, &mut c);
                assert!(
                    close(got, *want),
                    "tree {ti} bv {bi}: point {q} got {got}, want {want}"
                );
            }
            assert!(c.bv_tests > 0 && c.prim_tests > 0);
            assert!(c.prim_tests < (w.points.len() * scene.len()) as u64);
            let mut c = Counts::default();
            for (k, pose) in poses.iter().enumerate() {
                let (t2, s2) = moved(tree, copy, pose);
                let sp2 = moved_spheres(&spheres, pose);
                for bv2 in [Bv::Aabb, Bv::Sphere(&sp2)] {
                    let h2 = Hierarchy {
                        tree: &t2,
                        scene: &s2,
                        bv: bv2,
                    };
                    let got = scene_distance(&h, &h2, &mut c);
                    assert!(
                        close(got, want[k]),
                        "tree {ti} bv {bi}: pose {k} got {got}, want {}",
                        want[k]
                    );
                    assert_eq!(
                        overlap(&h, &h2, &mut c),
                        want[k] == 0.0,
                        "tree {ti} bv {bi}: pose {k}"
                    );
                    assert_eq!(
                        contacts(&h, &h2, &mut Counts::default()),
                        touching[k],
                        "tree {ti} bv {bi}: pose {k}"
                    );
                }
            }
            assert!(c.bv_tests > 0 && c.prim_tests > 0);
            let brute = (2 * poses.len() * scene.len() * copy.len()) as u64;
            assert!(
                c.prim_tests < brute / 4,
                "{} primitive tests vs {brute} brute force",
                c.prim_tests
            );
            if ti == 0 && bi == 0 {
                summary = c;
            }
        }
    }
    summary
}

#[test]
fn robot_base_queries_match_brute_force() {
    let s = generate::robot_base();
    check_scene(&s, &s, 1);
}

#[test]
fn soup_queries_match_brute_force() {
    let s = generate::soup(300, 7);
    check_scene(&s, &s, 2);
    check_scene(&s, &edges_only(&s), 3);
}

#[test]
fn replicated_soup_queries_match_brute_force() {
    let s = generate::replicate(&generate::soup(60, 3), 4, 5);
    check_scene(&edges_only(&s), &s, 4);
}

#[test]
fn lamp_point_queries_match_brute_force() {
    let s = generate::lamp();
    let tree = group(&s, &Params::default(), ()).tree;
    let spheres = sphere_tree(&tree, &s, SphereMethod::Minimum);
    let w = Workload::standard(&s, 9);
    for bv in [Bv::Aabb, Bv::Sphere(&spheres)] {
        let h = Hierarchy {
            tree: &tree,
            scene: &s,
            bv,
        };
        let mut c = Counts::default();
        for q in &w.points {
            let (got, want) = (
                point_distance(&h, q, &mut c),
                reference::point_distance(&s, q),
            );
            assert!(close(got, want), "point {q}: got {got}, want {want}");
        }
        assert!(c.prim_tests < (w.points.len() * s.len() / 4) as u64);
    }
}

#[test]
fn moved_copies_hold_their_vertices() {
    let s = generate::robot_base();
    let tree = group(&s, &Params::default(), ()).tree;
    let spheres = sphere_tree(&tree, &s, SphereMethod::Ritter);
    let pose = Workload::standard(&s, 11).poses_near[0];
    let (t2, s2) = moved(&tree, &s, &pose);
    let sp2 = moved_spheres(&spheres, &pose);
    assert_eq!(t2.children, tree.children);
    for x in 0..t2.len() as u32 {
        for leaf in t2.leaves_under(x) {
            for q in s2.prim_vertices(leaf as usize) {
                assert!(t2.aabb[x as usize].contains_point(q, 0.0));
                assert!(sp2[x as usize].contains(q, 1e-12));
            }
        }
    }
    assert_ne!(s2.points[0], s.points[0]);
}

#[test]
fn workload_is_seeded_and_measured() {
    let s = generate::soup(200, 1);
    let (a, b) = (Workload::standard(&s, 5), Workload::standard(&s, 5));
    assert_eq!(a.points, b.points);
    assert_eq!(a.poses_near, b.poses_near);
    assert_eq!(a.poses_touching, b.poses_touching);
    assert_ne!(a.points, Workload::standard(&s, 6).points);
    let tree = group(&s, &Params::default(), ()).tree;
    let cost = measure(&tree, &s, Bv::Aabb, &a);
    assert_eq!(
        (
            cost.point.queries,
            cost.distance.queries,
            cost.overlap.queries
        ),
        (256, 8, 16)
    );
    assert_eq!(cost.overlapping, 8);
    assert_eq!(cost.capped(), 0);
    for m in [cost.point, cost.distance, cost.overlap] {
        assert!(m.bv_tests > 0.0 && m.prim_tests > 0.0);
        assert_eq!(m.cost, m.bv_tests + m.prim_tests);
    }
}

/// A scene of 300 coincident copies of one triangle against itself: every primitive pair
/// touches, and the search ends at the first one instead of testing all 90,000.
#[test]
fn scene_distance_ends_at_the_first_touching_pair() {
    let s = wraptree::scene::pathological::coincident(300);
    let tree = pairing_tree(&s);
    let h = Hierarchy {
        tree: &tree,
        scene: &s,
        bv: Bv::Aabb,
    };
    let mut c = Counts::default();
    assert_eq!(scene_distance(&h, &h, &mut c), 0.0);
    assert!(c.prim_tests <= 2 && c.bv_tests <= 64, "{c:?}");
}

/// Stacked coincident copies tie every scene–copy pair: the workload's queries stop at their
/// test cap, are counted as capped (a set's queries after the first capped one are not run),
/// and a capped distance is never below the true one.
#[test]
fn workload_queries_stop_at_the_cap_on_coincident_copies() {
    let s = wraptree::scene::pathological::coincident(400);
    let tree = pairing_tree(&s);
    let mut w = Workload::standard(&s, 1);
    // 256·400 < 2·400² < 2^24.
    assert_eq!(w.max_tests, 2 * 400 * 400);
    assert_eq!(Workload::cap(10), 2560);
    assert_eq!(Workload::cap(10_000), 1 << 24);
    assert_eq!(Workload::cap(100_000), 25_600_000);
    w.max_tests = 20_000;
    let cost = measure(&tree, &s, Bv::Aabb, &w);
    // 400² = 160,000 tied pairs per near pose.
    assert_eq!(cost.distance.capped, 8);
    assert!(cost.capped() >= 8);
    for m in [cost.point, cost.distance, cost.overlap] {
        assert!(m.bv_tests + m.prim_tests <= 20_002.0, "{m:?}");
    }
    // Once one distance query reaches the cap, the other seven are not run.
    let d = cost.distance;
    assert!((d.bv_tests + d.prim_tests) * 8.0 <= 20_002.0, "{d:?}");
    let h = Hierarchy {
        tree: &tree,
        scene: &s,
        bv: Bv::Aabb,
    };
    let (t2, s2) = moved(&tree, &s, &w.poses_near[0]);
    let copy = Hierarchy {
        tree: &t2,
        scene: &s2,
        bv: Bv::Aabb,
    };
    let mut c = Counts::default();
    let got = scene_distance_within(&h, &copy, 1_000, &mut c);
    let want = reference::scene_distance(&s, &s2);
    assert!(c.capped == 1 && c.bv_tests + c.prim_tests <= 1_002, "{c:?}");
    assert!(
        got.is_finite() && got >= want * (1.0 - 1e-12),
        "{got} < {want}"
    );
}

/// One query kind's queries, BV and primitive tests per query, and capped queries.
type KindCounts = (usize, f64, f64, u64);

/// A workload cost's counts: [`KindCounts`] for points, distances and overlaps, the number of
/// overlapping poses, [`KindCounts`] for contacts and the number of contacts.
type Kinds = (KindCounts, KindCounts, KindCounts, usize, KindCounts, u64);

/// A workload cost's counts, for comparing runs ([`Kinds`]).
fn counts(c: &wraptree::query::QueryCost) -> Kinds {
    let m = |m: &wraptree::query::MeanCost| (m.queries, m.bv_tests, m.prim_tests, m.capped);
    (
        m(&c.point),
        m(&c.distance),
        m(&c.overlap),
        c.overlapping,
        m(&c.contact),
        c.contacts,
    )
}

/// The workload's queries run side by side on rayon's threads: every count (tests, capped
/// queries, overlaps) is the same for any number of threads, with sphere BVs, and where the
/// sets stop at their cap (the capped queries land in different places of each pool's run).
#[test]
fn workload_counts_are_the_same_for_any_thread_count() {
    let soup = generate::soup(600, 3);
    let soup_tree = group(&soup, &Params::default(), ()).tree;
    let spheres = sphere_tree(&soup_tree, &soup, SphereMethod::Ritter);
    let stack = wraptree::scene::pathological::coincident(300);
    let stack_tree = pairing_tree(&stack);
    let mut capped = Workload::standard(&stack, 2);
    capped.max_tests = 5_000;
    let cases = [
        (&soup_tree, &soup, Bv::Aabb, Workload::standard(&soup, 4)),
        (
            &soup_tree,
            &soup,
            Bv::Sphere(&spheres),
            Workload::standard(&soup, 4),
        ),
        (&stack_tree, &stack, Bv::Aabb, capped),
    ];
    for (k, (tree, scene, bv, w)) in cases.iter().enumerate() {
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            counts(&pool.install(|| measure(tree, scene, *bv, w)))
        };
        let one = on(1);
        assert_eq!(one, on(2), "case {k}");
        assert_eq!(one, on(5), "case {k}");
        if k == 2 {
            assert_eq!(one.1.3, 8, "every distance query of the stack is capped");
        }
    }
}

/// Overlap queries search the deeper-overlapping child pair first, so the workload's counts do
/// not depend on which child a node stores first: the same tree with every node's children
/// swapped gives the same counts, with box and with sphere BVs (a soup: no two boxes alike).
#[test]
fn workload_counts_do_not_depend_on_child_order() {
    let soup = generate::soup(800, 9);
    let tree = group(&soup, &Params::default(), ()).tree;
    let mut mirrored = tree.clone();
    mirrored.children.iter_mut().for_each(|k| k.swap(0, 1));
    let w = Workload::standard(&soup, 2);
    let boxes = counts(&measure(&tree, &soup, Bv::Aabb, &w));
    assert_eq!(boxes.3, 8, "every touching pose overlaps");
    assert_eq!(boxes, counts(&measure(&mirrored, &soup, Bv::Aabb, &w)));
    assert_eq!(boxes.4.0, 8, "a contact query per touching pose");
    // The same sphere for each node (its children's order does not change its primitives).
    let spheres = sphere_tree(&tree, &soup, SphereMethod::Ritter);
    let balls = counts(&measure(&tree, &soup, Bv::Sphere(&spheres), &w));
    assert_eq!(
        balls,
        counts(&measure(&mirrored, &soup, Bv::Sphere(&spheres), &w))
    );
    assert_eq!(
        (balls.4.0, balls.5),
        (0, 0),
        "no contact queries with spheres"
    );
}

/// Contact queries visit every overlapping BV pair: their counts do not depend on the child
/// order even between exactly tied boxes (stacked coincident copies), nor on the number of
/// threads, and they find every touching pair.
#[test]
fn contact_counts_depend_on_the_trees_alone() {
    let stack = wraptree::scene::pathological::coincident(30);
    let tree = pairing_tree(&stack);
    let mut mirrored = tree.clone();
    mirrored.children.iter_mut().for_each(|k| k.swap(0, 1));
    let w = Workload::standard(&stack, 3);
    let on = |tree: &SubsetTree, threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let q = pool.install(|| measure(tree, &stack, Bv::Aabb, &w));
        (
            q.contact.queries,
            q.contact.bv_tests,
            q.contact.prim_tests,
            q.contact.capped,
            q.contacts,
        )
    };
    let one = on(&tree, 1);
    // Each of the 30 copies of a touching pose's crossing triangle meets all 30 stacked ones.
    assert_eq!((one.0, one.3, one.4), (8, 0, 8 * 30 * 30));
    assert_eq!(one, on(&tree, 3));
    assert_eq!(one, on(&mirrored, 1));
}

/// Prints the workload cost on the 12,144-polygon scene and one brute-force scene–scene
/// query's time on the lamp (626 polygons). Not asserted: run with `--ignored --nocapture`.
#[test]
#[ignore]
fn report_query_cost() {
    let s = generate::replicate(&generate::robot_base(), 44, 1);
    let tree = group(&s, &Params::default(), ()).tree;
    let w = Workload::standard(&s, 1);
    let spheres = sphere_tree(&tree, &s, SphereMethod::AabbCenter);
    let minimum = sphere_tree(&tree, &s, SphereMethod::Minimum);
    let bvs = [
        ("aabb", Bv::Aabb),
        ("sphere aabb-center", Bv::Sphere(&spheres)),
        ("sphere minimum", Bv::Sphere(&minimum)),
    ];
    for (name, bv) in bvs {
        let c = measure(&tree, &s, bv, &w);
        println!("{} {name}: {}", s.len(), serde_json::to_string(&c).unwrap());
    }
    let lamp = generate::lamp();
    let lt = group(&lamp, &Params::default(), ()).tree;
    let lw = Workload::standard(&lamp, 1);
    let (_, copy) = moved(&lt, &lamp, &lw.poses_near[0]);
    let start = std::time::Instant::now();
    let d = reference::scene_distance(&lamp, &copy);
    println!(
        "brute force lamp ({} polygons, {} triangles): distance {d} in {:.3} s",
        lamp.len(),
        lamp.tris.len(),
        start.elapsed().as_secs_f64()
    );
    let h = Hierarchy {
        tree: &lt,
        scene: &lamp,
        bv: Bv::Aabb,
    };
    let (t2, s2) = moved(&lt, &lamp, &lw.poses_near[0]);
    let mut c = Counts::default();
    let start = std::time::Instant::now();
    let got = scene_distance(
        &h,
        &Hierarchy {
            tree: &t2,
            scene: &s2,
            bv: Bv::Aabb,
        },
        &mut c,
    );
    println!(
        "hierarchy: distance {got} in {:.6} s, {c:?}",
        start.elapsed().as_secs_f64()
    );
}
