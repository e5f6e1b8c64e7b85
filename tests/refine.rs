//! The refinement pass (`wraptree::refine`): valid Subset Trees on bundled and
//! property-generated scenes, SAH never above the input's, determinism (also across thread
//! counts), no-op on trees already optimal, `replay --verify` of a refined recording, and the
//! surface-area Cost.

mod common;

use proptest::prelude::*;
use wraptree::geom::P3;
use wraptree::grouping::{CostMeasure, EventLog, Params, SubsetTree, group};
use wraptree::metrics::sah;
use wraptree::peers::{self, Method};
use wraptree::refine::{RefineParams, Refined, StepKind, Tuning, refine, refine_tuned};
use wraptree::scene::{LoadOptions, PrimitiveKind, Scene, generate, load_path};

/// Every leaf once under the root, children before parents and inside them, boxes exact
/// unions, leaves' boxes those of the scene's primitives.
fn check_valid(scene: &Scene, t: &SubsetTree) {
    let n = scene.len();
    assert_eq!(t.leaves(), n);
    assert_eq!(t.len(), 2 * n - 1);
    let mut seen = vec![0u32; t.len()];
    for (i, &[a, b]) in t.children.iter().enumerate() {
        let x = n + i;
        assert!(
            (a as usize) < x && (b as usize) < x,
            "children precede parent"
        );
        seen[a as usize] += 1;
        seen[b as usize] += 1;
        let u = t.aabb[a as usize].merge(&t.aabb[b as usize]);
        assert_eq!(t.aabb[x], u, "node {x} box is its children's union");
    }
    for (x, c) in seen.iter().enumerate() {
        assert_eq!(
            *c,
            u32::from(x != 2 * n - 2),
            "node {x} is a child {c} times"
        );
    }
    let rebuilt = SubsetTree::new(t.aabb.clone(), t.diameter.clone(), t.children.clone());
    assert_eq!(
        rebuilt.as_ref(),
        Ok(t),
        "parents and depths follow the children"
    );
    let mut leaves = t.leaves_under(t.root());
    leaves.sort();
    assert_eq!(leaves, (0..n as u32).collect::<Vec<_>>());
    for leaf in 0..n {
        assert_eq!(
            t.aabb[leaf],
            scene.prim_aabb(leaf),
            "leaf {leaf} in input order"
        );
    }
}

/// Parameters and tuning of a refinement run.
type Setup = (RefineParams, Tuning);

fn refined(tree: &SubsetTree) -> (Refined, EventLog) {
    let mut log = EventLog::default();
    let r = refine(tree, &RefineParams::default(), &mut log);
    (r, log)
}

fn refined_with(tree: &SubsetTree, (params, tuning): &Setup) -> (Refined, EventLog) {
    let mut log = EventLog::default();
    let r = refine_tuned(tree, params, tuning, &mut log);
    (r, log)
}

/// Treelet restructuring alone: `passes` treelet passes of `k` leaves rooted at every node
/// with more than one shape, no reinsertion.
fn treelets(k: u32, passes: u32) -> Setup {
    let params = RefineParams {
        passes: 0,
        treelet: k,
        treelet_passes: passes,
        ..RefineParams::default()
    };
    let tuning = Tuning {
        treelet_min: 3,
        treelet_every: 1,
        treelet_after: false,
    };
    (params, tuning)
}

/// Checks a refinement of `tree` over `scene`: valid, SAH not above, events consistent.
fn check_refinement(scene: &Scene, tree: &SubsetTree) -> Refined {
    check_refinement_with(scene, tree, &(RefineParams::default(), Tuning::default()))
}

/// [`check_refinement`] with `setup`.
fn check_refinement_with(scene: &Scene, tree: &SubsetTree, setup: &Setup) -> Refined {
    let (r, log) = refined_with(tree, setup);
    let (params, tuning) = setup;
    // Treelet passes come first, or after every reinsertion pass (`after`).
    let reinsert_passes = log
        .refine
        .iter()
        .filter(|s| s.kind == StepKind::Move)
        .map(|s| s.pass);
    let first_treelet_pass = if tuning.treelet_after {
        reinsert_passes.max().map_or(0, |p| p + 1)
    } else {
        0
    };
    check_valid(scene, &r.tree);
    assert!(
        r.sah_after <= r.sah_before,
        "{} > {}",
        r.sah_after,
        r.sah_before
    );
    assert_eq!(r.sah_before, sah(tree));
    assert_eq!(r.sah_after, sah(&r.tree));
    assert_eq!(log.refine.len(), r.steps as usize);
    assert_eq!(log.refine_start.map(|s| s.1), Some(r.sah_before));
    for (i, s) in log.refine.iter().enumerate() {
        assert_eq!(s.step as usize, i);
        assert!(s.sah < s.sah_before, "every kept step lowers the SAH");
        match s.kind {
            StepKind::Move if tuning.treelet_after => assert!(s.pass < first_treelet_pass),
            StepKind::Move => assert!(s.pass >= params.treelet_passes),
            StepKind::Treelet { leaves } => {
                assert!(s.pass >= first_treelet_pass);
                assert!(tuning.treelet_after || s.pass < params.treelet_passes);
                assert!((3..=params.treelet).contains(&leaves), "{s:?}");
                assert_eq!(
                    s.aabb, s.parent_aabb,
                    "a rebuilt treelet keeps its root box"
                );
            }
        }
    }
    if let Some(last) = log.refine.last() {
        assert!((last.sah - r.sah_after).abs() <= 1e-9 * r.sah_after);
    } else {
        assert_eq!(&r.tree, tree, "no move: the input unchanged");
    }
    r
}

const LAMP: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/lamp.obj");

fn bundled() -> Vec<Scene> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| load_path(p, &LoadOptions::default()).unwrap().scene)
        .collect()
}

#[test]
fn refined_trees_are_valid_and_no_worse_on_every_bundled_scene() {
    for scene in bundled() {
        for m in [Method::GROUPING, Method::PARRY_BINNED, Method::OBVHS_PLOC] {
            let b = peers::build(m, &scene, &Params::default()).unwrap();
            let r = check_refinement(&scene, &b.tree);
            if m == Method::GROUPING && scene.len() > 100 {
                assert!(
                    r.sah_after < r.sah_before,
                    "{}: the grouping's tree improves",
                    scene.name
                );
            }
        }
    }
}

#[test]
fn refinement_is_deterministic_and_thread_count_independent() {
    // Large enough that the first passes search in parallel (`reinsert::PARALLEL_MIN`) and
    // that the tree's arrays are built in parallel (`work::PARALLEL_COPY` nodes).
    let scene = generate::soup(33_000, 7);
    assert!(2 * scene.len() > wraptree::refine::work::PARALLEL_COPY);
    let g = group(&scene, &Params::default(), ());
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| refined(&g.tree))
    };
    let (r1, log1) = run(1);
    let (r2, log2) = run(2);
    let (r3, log3) = run(2);
    assert!(r1.steps > 0);
    assert_eq!(log1, log2);
    assert_eq!(log2, log3);
    assert_eq!(r1.tree, r2.tree);
    assert_eq!(r2.tree, r3.tree);
}

#[test]
fn treelet_pass_is_no_worse_and_thread_count_independent() {
    // Wide enough that the low heights are solved in parallel (`treelet::PARALLEL_MIN`).
    let scene = generate::soup(20_000, 5);
    let g = group(&scene, &Params::default(), ());
    let params = treelets(7, 2);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| refined_with(&g.tree, &params))
    };
    let (r1, log1) = run(1);
    let (r2, log2) = run(2);
    assert!(r1.steps > 1000, "{} treelets rebuilt", r1.steps);
    assert!(r1.sah_after < r1.sah_before);
    assert_eq!(log1, log2);
    assert_eq!(r1.tree, r2.tree);
    check_refinement_with(&scene, &g.tree, &params);
    // A second pass finds less to do than the first.
    let first = log1.refine.iter().filter(|s| s.pass == 0).count();
    assert!(log1.refine.len() - first < first);
}

#[test]
fn a_badly_paired_treelet_is_rebuilt_in_its_optimal_shape() {
    // Four triangles in a row at 0, 1, 10, 11, paired (0, 10) and (1, 11): the optimal tree
    // pairs the neighbours, which one rebuilt treelet of 4 leaves finds.
    let s = tri_scene(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [10.0, 0.0, 0.0],
        [11.0, 0.0, 0.0],
    ]);
    let b: Vec<_> = (0..4).map(|i| s.prim_aabb(i)).collect();
    let (a, c) = (b[0].merge(&b[2]), b[1].merge(&b[3]));
    let mut aabb = b.clone();
    aabb.extend([a, c, a.merge(&c)]);
    let diameter = aabb.iter().map(|x| x.diameter()).collect();
    let bad = SubsetTree::new(aabb, diameter, vec![[0, 2], [1, 3], [4, 5]]).unwrap();
    let r = check_refinement_with(&s, &bad, &treelets(4, 1));
    assert_eq!(r.steps, 1);
    let mut pairs: Vec<Vec<u32>> = [4, 5]
        .iter()
        .map(|&x| {
            let mut l = r.tree.leaves_under(x);
            l.sort();
            l
        })
        .collect();
    pairs.sort();
    assert_eq!(pairs, vec![vec![0, 1], vec![2, 3]]);
    // Already optimal: a second run keeps every id.
    let (again, log) = refined_with(&r.tree, &treelets(7, 3));
    assert_eq!(again.tree, r.tree);
    assert!(log.refine.is_empty());
}

fn tri_scene(corners: &[[f64; 3]]) -> Scene {
    common::triangles(corners, 0.1)
}

#[test]
fn optimal_trees_of_two_and_three_primitives_are_unchanged() {
    // Two primitives: one tree.
    let two = tri_scene(&[[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]]);
    let g = group(&two, &Params::default(), ());
    let (r, log) = refined(&g.tree);
    assert_eq!(r.tree, g.tree);
    assert!(log.refine.is_empty());
    // Three in a row, the two close ones paired first: the SAH-optimal tree.
    let three = tri_scene(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [9.0, 0.0, 0.0]]);
    let g = group(&three, &Params::default(), ());
    assert_eq!(g.tree.children[0], [0, 1]);
    let (r, log) = refined(&g.tree);
    assert_eq!(r.tree, g.tree);
    assert!(log.refine.is_empty());
    // The same three paired badly ((0, 2), 1) is fixed by one move.
    let boxes: Vec<_> = (0..3).map(|i| three.prim_aabb(i)).collect();
    let b02 = boxes[0].merge(&boxes[2]);
    let root = b02.merge(&boxes[1]);
    let mut aabb = boxes.clone();
    aabb.extend([b02, root]);
    let diameter = aabb.iter().map(|b| b.diameter()).collect();
    let bad = SubsetTree::new(aabb, diameter, vec![[0, 2], [1, 3]]).unwrap();
    let r = check_refinement(&three, &bad);
    assert_eq!(r.steps, 1);
    assert_eq!(r.tree.leaves_under(3).len(), 2);
    let mut pair = r.tree.leaves_under(3);
    pair.sort();
    assert_eq!(pair, vec![0, 1]);
}

#[test]
fn degenerate_scenes_are_returned_unchanged() {
    // Every primitive in one point: the root box has no area.
    let mut s = Scene::new("points");
    for _ in 0..5 {
        let b = s.points.len() as u32;
        s.points.extend([P3::new(1.0, 2.0, 3.0); 3]);
        s.push(
            PrimitiveKind::Polygon,
            &[b, b + 1, b + 2],
            &[[b, b + 1, b + 2]],
        );
    }
    let g = group(&s, &Params::default(), ());
    let (r, log) = refined(&g.tree);
    assert_eq!(r.tree, g.tree);
    assert!(log.refine.is_empty());
}

fn arb_scene() -> impl Strategy<Value = Scene> {
    let coord = -50.0f64..50.0;
    let edge = prop_oneof![Just(0.0f64), -3.0f64..3.0];
    let tri = (
        [coord.clone(), coord.clone(), coord],
        [edge.clone(), edge.clone(), edge],
    );
    prop::collection::vec(tri, 1..120).prop_map(|tris| {
        let mut s = Scene::new("prop");
        for (c, u) in tris {
            let b = s.points.len() as u32;
            let c = P3::new(c[0], c[1], c[2]);
            s.points.extend([
                c,
                c + nalgebra::Vector3::from(u),
                c + nalgebra::Vector3::new(u[1], u[2], u[0]),
            ]);
            s.push(
                PrimitiveKind::Polygon,
                &[b, b + 1, b + 2],
                &[[b, b + 1, b + 2]],
            );
        }
        s
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn refinement_of_any_builder_is_valid(scene in arb_scene(), which in 0usize..3, area in any::<bool>()) {
        let params = Params {
            mode: wraptree::grouping::Mode {
                cost: if area { CostMeasure::Area } else { CostMeasure::Diameter },
                ..Default::default()
            },
            ..Params::default()
        };
        let m = [Method::GROUPING, Method::PARRY_BINNED, Method::MEDIAN_SPLIT][which];
        let b = peers::build(m, &scene, &params).unwrap();
        check_valid(&scene, &b.tree);
        check_refinement(&scene, &b.tree);
    }

    #[test]
    fn treelet_restructuring_of_any_builder_is_valid(scene in arb_scene(), which in 0usize..3, k in 3u32..=7) {
        let m = [Method::GROUPING, Method::PARRY_BINNED, Method::MEDIAN_SPLIT][which];
        let b = peers::build(m, &scene, &Params::default()).unwrap();
        check_refinement_with(&scene, &b.tree, &treelets(k, 2));
    }

    #[test]
    fn any_tuning_gives_valid_trees(
        scene in arb_scene(),
        min in 3u32..=40,
        every in 1u32..=3,
        after in any::<bool>(),
    ) {
        let b = peers::build(Method::GROUPING, &scene, &Params::default()).unwrap();
        let tuning = Tuning { treelet_min: min, treelet_every: every, treelet_after: after };
        check_refinement_with(&scene, &b.tree, &(RefineParams::default(), tuning));
    }
}

#[test]
fn area_cost_gives_valid_trees_that_differ_from_the_diameter_cost() {
    let area = Params {
        mode: wraptree::grouping::Mode {
            cost: CostMeasure::Area,
            ..Default::default()
        },
        ..Params::default()
    };
    let mut differed = 0;
    for scene in [
        generate::soup(2000, 3),
        generate::robot_base(),
        generate::lamp(),
    ] {
        let (ga, log) = common::run(&scene, &area);
        common::check_tree(&scene, &ga, &log);
        let gd = group(&scene, &Params::default(), ());
        differed += usize::from(ga.tree.children != gd.tree.children);
        // Fill is the merged box's area over the children's, as the events say.
        for m in &log.merges[..50] {
            let t = &ga.tree;
            let s = |x: u32| wraptree::geom::area(&t.aabb[x as usize]);
            let fill = s(m.new) / (s(m.a) + s(m.b));
            assert!(
                (m.fill - fill).abs() <= 1e-12 * fill,
                "{} vs {fill}",
                m.fill
            );
            assert_eq!(
                m.diameter, t.diameter[m.new as usize],
                "DLimit stays a length"
            );
        }
    }
    assert!(differed >= 2, "the area Cost changes the merge order");
}

#[test]
fn replay_verifies_a_refined_recording() {
    let dir = tempfile::tempdir().unwrap();
    let prefix = dir.path().join("lamp");
    let p = prefix.to_str().unwrap();
    common::printed(
        &[
            "record",
            LAMP,
            "--refine",
            "--detail",
            "levels",
            "--reproducible",
            "-o",
            p,
        ],
        dir.path(),
    );
    let mcap = format!("{p}.mcap");
    let rec = wraptree::record::mcap::read_recording(std::path::Path::new(&mcap)).unwrap();
    let r = rec.refine.expect("the metadata names the refinement");
    assert_eq!(r.params, RefineParams::default());
    assert!(r.steps > 0 && r.sah_after < r.sah_before);
    assert_eq!(rec.refine_steps.len(), r.steps as usize);
    // Both kinds of step are recorded: rebuilt treelets first, then moves.
    let treelet = |s: &&wraptree::refine::Step| matches!(s.kind, StepKind::Treelet { .. });
    let rebuilt = rec.refine_steps.iter().take_while(treelet).count();
    assert!(rebuilt > 0 && rebuilt < rec.refine_steps.len());
    assert!(!rec.refine_steps[rebuilt..].iter().any(|s| treelet(&s)));
    // The levels are the refined tree's: its depth is recorded.
    let loaded = wraptree::scene::load_bytes(
        &rec.scene_file_name,
        rec.scene_bytes.clone(),
        &rec.load_options,
    )
    .unwrap();
    let t = refine(&rec.tree(&loaded.scene).unwrap(), &r.params, ()).tree;
    assert_eq!(rec.metadata["depth_max"], t.depth_max().to_string());
    let out = common::wraptree(&["replay", &mcap, "--verify"], dir.path());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("the refinement's moves are identical"),
        "{stdout}"
    );
    common::assert_rrd_verifies(std::path::Path::new(&format!("{p}.rrd")));
}

#[test]
fn bad_refine_batch_is_one_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = common::wraptree(
        &["record", LAMP, "--refine", "--refine-batch", "0", "-o", "x"],
        dir.path(),
    );
    common::assert_one_line_error(&out, "--refine-batch");
    assert!(!dir.path().join("x.rrd").exists());
    let out = common::wraptree(
        &[
            "record",
            LAMP,
            "--refine",
            "--refine-treelet",
            "8",
            "-o",
            "x",
        ],
        dir.path(),
    );
    common::assert_one_line_error(&out, "--refine-treelet");
    assert!(!dir.path().join("x.rrd").exists());
}
