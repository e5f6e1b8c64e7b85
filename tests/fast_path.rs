//! The fast path (`--fast`, bench method `fast`): a valid tree over every primitive, the same
//! tree on 1 and 2 threads, a refinement that never raises the SAH of its grouping, and the
//! flag's parsing.

mod common;

use common::wraptree;
use wraptree::grouping::partitioned::Chunking;
use wraptree::grouping::{Params, SubsetTree, sah};
use wraptree::peers::{Method, build};
use wraptree::scene::{LoadOptions, Scene, generate, load_path};

/// `method`'s tree of `scene` in a rayon pool of `threads` threads.
fn tree_on(threads: usize, method: Method, scene: &Scene) -> SubsetTree {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| build(method, scene, &Params::default()).unwrap().tree)
}

/// Every primitive a leaf once, every interior box covering its children's, one root.
fn check_cover(tree: &SubsetTree, scene: &Scene) {
    let n = scene.len();
    assert_eq!(tree.leaves(), n);
    assert_eq!(tree.children.len(), n - 1);
    let mut seen = vec![0u32; tree.len()];
    for (i, &[a, b]) in tree.children.iter().enumerate() {
        seen[a as usize] += 1;
        seen[b as usize] += 1;
        let x = n + i;
        assert!(tree.aabb[x].contains_aabb(&tree.aabb[a as usize], 0.0));
        assert!(tree.aabb[x].contains_aabb(&tree.aabb[b as usize], 0.0));
    }
    for (i, b) in tree.aabb[..n].iter().enumerate() {
        assert!(b.contains_aabb(&scene.prim_aabb(i), 0.0), "leaf {i}");
    }
    let roots: Vec<usize> = (0..tree.len()).filter(|&x| seen[x] == 0).collect();
    assert_eq!(roots, vec![tree.root() as usize]);
    assert!(seen.iter().all(|&s| s <= 1));
}

fn scenes() -> Vec<Scene> {
    let bunny = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/stanford-bunny.obj");
    vec![
        generate::soup(5_000, 3),
        generate::replicate(&generate::robot_base(), 6, 2),
        load_path(&bunny, &LoadOptions::default()).unwrap().scene,
    ]
}

#[test]
fn the_fast_path_is_a_valid_tree_and_the_same_on_1_and_2_threads() {
    for scene in scenes() {
        // Split into many subproblems (not grouped whole).
        assert!(!Chunking::FAST.whole(scene.len()), "{}", scene.name);
        for m in [Method::GROUPING_FAST, Method::FAST] {
            let one = tree_on(1, m, &scene);
            let two = tree_on(2, m, &scene);
            check_cover(&one, &scene);
            assert_eq!(one.children, two.children, "{} {}", scene.name, m.name());
            assert_eq!(one.aabb, two.aabb, "{} {}", scene.name, m.name());
        }
        let grouped = tree_on(2, Method::GROUPING_FAST, &scene);
        let fast = tree_on(2, Method::FAST, &scene);
        assert!(sah(&fast) <= sah(&grouped), "{}", scene.name);
    }
}

#[test]
fn the_fast_flag_groups_partitioned_with_the_fast_split_and_parses_like_the_others() {
    let dir = common::soup_dir(2_000, 6);
    let out = wraptree(&["group", "s.obj", "--fast", "--threads", "1"], dir.path());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("Partitioned on 1 thread"), "{text}");
    assert!(text.contains("root share 16,"), "{text}");
    assert!(text.contains("chunks of δ = 2,"), "{text}");
    // The --chunk-* flags apply on the fast path.
    let out = wraptree(
        &["group", "s.obj", "--fast", "--chunk-top", "512"],
        dir.path(),
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("root share 512"),
        "{text}"
    );
    let out = wraptree(
        &["group", "s.obj", "--fast", "--schedule", "exact"],
        dir.path(),
    );
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--fast") && err.contains("--schedule"),
        "{err}"
    );
    // The bench method by name.
    assert_eq!(Method::parse("fast"), Ok(Method::FAST));
    assert_eq!(Method::parse("grouping-fast"), Ok(Method::GROUPING_FAST));
}

#[test]
fn the_bench_method_refines_with_a_smaller_first_batch_from_2_14_primitives_up() {
    // `fast` is the fast grouping, then `refine::fast_for` the scene's size: a tenth of the
    // nodes first below `FAST_LARGE` primitives, 7 % from it up, which gives another tree there.
    use wraptree::refine::{self, FAST, FAST_LARGE, fast_for};
    for n in [5_000, FAST_LARGE + 1_000] {
        let scene = generate::soup(n, 11);
        let bench = tree_on(1, Method::FAST, &scene);
        let grouped = tree_on(1, Method::GROUPING_FAST, &scene);
        let ours = refine::refine(&grouped, &fast_for(n), ()).tree;
        assert_eq!(bench, ours, "{n} primitives");
        let tenth = refine::refine(&grouped, &FAST, ()).tree;
        assert_eq!(bench == tenth, n < FAST_LARGE, "{n} primitives");
        assert!(sah(&bench) <= sah(&grouped));
    }
    assert_eq!(fast_for(FAST_LARGE - 1), FAST);
    assert_eq!(fast_for(FAST_LARGE).batch, refine::FAST_LARGE_BATCH);
}

#[test]
fn below_2_10_primitives_the_bench_method_refines_without_its_treelet_pass() {
    // Three reinsertion passes below `FAST_SMALL`, where the treelet pass would cost a large
    // share of PLOC's build; from it up the treelets of `FAST` change the tree.
    use wraptree::refine::{self, FAST, FAST_SMALL, FAST_SMALL_PARAMS, fast_for};
    let n = 700;
    let scene = generate::soup(n, 5);
    let bench = tree_on(1, Method::FAST, &scene);
    let grouped = tree_on(1, Method::GROUPING_FAST, &scene);
    assert_eq!(bench, refine::refine(&grouped, &FAST_SMALL_PARAMS, ()).tree);
    assert_ne!(bench, refine::refine(&grouped, &FAST, ()).tree);
    assert_eq!(fast_for(FAST_SMALL - 1), FAST_SMALL_PARAMS);
    assert_eq!(fast_for(FAST_SMALL), FAST);
    assert_eq!(FAST_SMALL_PARAMS.treelet_passes, 0);
    assert_eq!((FAST.treelet_passes, FAST.treelet_min), (1, 8));
}

#[test]
fn record_fast_refine_gives_the_bench_tree_and_replays() {
    use wraptree::refine::{fast_for, refine};
    let dir = tempfile::tempdir().unwrap();
    let bunny = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/stanford-bunny.obj");
    let prefix = dir.path().join("bunny");
    let p = prefix.to_str().unwrap();
    let args = [
        "record",
        bunny.to_str().unwrap(),
        "--fast",
        "--refine",
        "--detail",
        "levels",
        "--reproducible",
        "-o",
        p,
    ];
    common::printed(&args, dir.path());
    let mcap = format!("{p}.mcap");
    let rec = wraptree::record::mcap::read_recording(std::path::Path::new(&mcap)).unwrap();
    let r = rec.refine.expect("the metadata names the refinement");
    let scene = load_path(&bunny, &LoadOptions::default()).unwrap().scene;
    assert_eq!(r.params, fast_for(scene.len()), "the recorded parameters");
    let bench = tree_on(1, Method::FAST, &scene);
    assert_eq!(
        refine(&rec.tree(&scene).unwrap(), &r.params, ()).tree,
        bench
    );
    let out = wraptree(&["replay", &mcap, "--verify"], dir.path());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && stdout.contains("the refinement's moves are identical"),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // A flag given wins over the fast path's value...
    let other = dir.path().join("three");
    let mut three = args.to_vec();
    three.truncate(args.len() - 1);
    three.extend([other.to_str().unwrap(), "--refine-passes", "3"]);
    common::printed(&three, dir.path());
    let path = format!("{}.mcap", other.display());
    let rec = wraptree::record::mcap::read_recording(std::path::Path::new(&path)).unwrap();
    let r = rec.refine.expect("refined");
    assert_eq!((r.params.passes, r.params.treelet_min), (3, 8));
    // ...and a treelet root below 3 leaves is refused in one line, before any work.
    let mut bad = args.to_vec();
    bad.extend(["--refine-treelet-min", "2"]);
    let out = wraptree(&bad, dir.path());
    common::assert_one_line_error(&out, "--refine-treelet-min");
}
