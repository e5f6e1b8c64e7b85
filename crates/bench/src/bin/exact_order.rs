//! How far the exact schedule's own tree moves when only the primitives' input order changes
//! (the file's face order, which no user chooses): the exact tree of the scene with its
//! primitives reversed and in two seeded shuffles, each mapped back to the input's ids, and the
//! default partitioned tree of each order; SAH and node tests per query (AABB BVs, the standard
//! workload of the scene as given) over the input order's exact tree. Ties between equal costs
//! break by id, and the voxel hash is walked in id order, so the order is the only thing that
//! changes (a variant study; its table is in the git history of `docs/benchmarks.md`).
//!
//! `cargo run --release -p wraptree-bench --bin exact_order -- FILE...`

use rand::SeedableRng;
use rand::seq::SliceRandom;
use wraptree::grouping::partitioned::{Chunking, group_with};
use wraptree::grouping::{Budget, Params, SubsetTree, group};
use wraptree::metrics::{compare::query_values, sah};
use wraptree::query::{self, Bv, Workload};
use wraptree::scene::Scene;

/// `scene` with its primitives in the order `order` (new position → input id).
fn permuted(scene: &Scene, order: &[u32]) -> Scene {
    let mut out = Scene::new(scene.name.clone());
    out.points = scene.points.clone();
    let kind = scene.kind.expect("a scene with primitives");
    for &i in order {
        out.push(kind, scene.prim(i as usize), scene.prim_tris(i as usize));
    }
    out
}

/// `tree` (over a permuted scene) with its leaves renamed to the input's ids, `order[x]` for
/// leaf `x`; the interior nodes keep their ids and order.
fn mapped_back(tree: &SubsetTree, order: &[u32]) -> anyhow::Result<SubsetTree> {
    let n = tree.leaves();
    let mut boxes = vec![tree.aabb[0]; n];
    let mut diameters = vec![0.0; n];
    for (x, &i) in order.iter().enumerate() {
        boxes[i as usize] = tree.aabb[x];
        diameters[i as usize] = tree.diameter[x];
    }
    let id = |x: u32| {
        if (x as usize) < n {
            order[x as usize]
        } else {
            x
        }
    };
    let merges: Vec<_> = (n..tree.len())
        .map(|x| {
            let [a, b] = tree.children_of(x as u32).expect("an interior node");
            (id(a), id(b), tree.aabb[x], tree.diameter[x])
        })
        .collect();
    SubsetTree::from_merges(boxes, diameters, &merges).map_err(anyhow::Error::msg)
}

fn main() -> anyhow::Result<()> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    println!(
        "| scene | N | exact SAH / tests: reversed | shuffle 1 | shuffle 2 | partitioned: input order | reversed | shuffle 1 | shuffle 2 |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for path in std::env::args().skip(1) {
        let scene = wraptree::scene::load_path(path.as_ref(), &Default::default())?.scene;
        let n = scene.len();
        let workload = Workload::standard(&scene, 1);
        let quality = |t: &SubsetTree| {
            let q = query::measure(t, &scene, Bv::Aabb, &workload);
            (sah(t), query_values(&q)[6])
        };
        let identity: Vec<u32> = (0..n as u32).collect();
        let mut orders = vec![identity.iter().rev().copied().collect::<Vec<u32>>()];
        for seed in 1..=2 {
            let mut o = identity.clone();
            o.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(seed));
            orders.push(o);
        }
        let (se, qe) = quality(&pool.install(|| group(&scene, &Params::default(), ())).tree);
        let mut exact = Vec::new();
        let mut part = Vec::new();
        let partitioned = |s: &Scene| {
            let params = Params::default().resolve(s);
            pool.install(|| {
                group_with(
                    s,
                    &params,
                    &Chunking {
                        delta: Chunking::LARGE_DELTA,
                        ..Chunking::DEFAULT
                    },
                    (),
                    &Budget::default(),
                )
            })
            .map_err(|s| anyhow::anyhow!("stopped: {:?}", s.reason))
            .map(|g| g.tree)
        };
        part.push(quality(&partitioned(&scene)?));
        for o in &orders {
            let s = permuted(&scene, o);
            let e = pool.install(|| group(&s, &Params::default(), ())).tree;
            exact.push(quality(&mapped_back(&e, o)?));
            part.push(quality(&mapped_back(&partitioned(&s)?, o)?));
        }
        print!("| {} | {} |", scene.name, n);
        for (s, q) in exact.iter().chain(&part) {
            print!(" {:.3} / {:.3} |", s / se, q / qe);
        }
        println!();
    }
    Ok(())
}
