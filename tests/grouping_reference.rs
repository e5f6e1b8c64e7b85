//! The exact schedule makes the merges of the paper's literal §2.2 run — every eligible pair of
//! the active bodies considered at every step, the cheapest merged — on a scene whose voxels are
//! crowded (hundreds of tiny triangles in one voxel beside a grid of larger ones), on 1 and 2
//! threads, with the same eligible-pair count at each round start.

mod common;

use wraptree::geom::Aabb;
use wraptree::grouping::{Params, ResolvedParams};
use wraptree::scene::{PrimitiveKind, Scene};

/// The literal run: per round, the parent-less bodies within DLimit are active; the cheapest
/// eligible pair (Cost, then the smaller and the larger id) is merged until none is left, and
/// the new body joins the active ones if it is within DLimit. Returns the merges and each
/// round's eligible pairs at its start.
fn literal(boxes: &[Aabb], p: &ResolvedParams) -> (Vec<[u32; 2]>, Vec<u64>) {
    let n = boxes.len();
    let mut aabb = boxes.to_vec();
    let mut diameter: Vec<f64> = boxes.iter().map(Aabb::diameter).collect();
    let mut parentless: Vec<u32> = (0..n as u32).collect();
    let (mut dlimit, mut glimit) = (p.dlimit0, p.glimit0);
    let (mut merges, mut pairs) = (Vec::new(), Vec::new());
    let cost = |a: &Aabb, da: f64, b: &Aabb, db: f64| {
        let d = a.merge(b).diameter();
        let sum = da + db;
        let fill = if sum > 0.0 { d / sum } else { 1.0 };
        p.weights.cost(d, fill, 1.0)
    };
    while parentless.len() > 1 {
        let mut active: Vec<u32> = parentless
            .iter()
            .copied()
            .filter(|&x| diameter[x as usize] <= dlimit)
            .collect();
        let eligible =
            |x: u32, y: u32, aabb: &[Aabb]| aabb[x as usize].gap_linf(&aabb[y as usize]) <= glimit;
        let mut count = 0u64;
        for (i, &x) in active.iter().enumerate() {
            count += active[i + 1..]
                .iter()
                .filter(|&&y| eligible(x, y, &aabb))
                .count() as u64;
        }
        pairs.push(count);
        loop {
            let mut best: Option<(f64, u32, u32)> = None;
            for (i, &x) in active.iter().enumerate() {
                for &y in &active[i + 1..] {
                    if !eligible(x, y, &aabb) {
                        continue;
                    }
                    let (lo, hi) = (x.min(y), x.max(y));
                    let (ax, ay) = (&aabb[x as usize], &aabb[y as usize]);
                    let c = cost(ax, diameter[x as usize], ay, diameter[y as usize]);
                    let first = best.is_none_or(|(bc, bl, bh)| {
                        c.total_cmp(&bc).then((lo, hi).cmp(&(bl, bh))).is_lt()
                    });
                    if first {
                        best = Some((c, lo, hi));
                    }
                }
            }
            let Some((_, a, b)) = best else { break };
            let new = (n + merges.len()) as u32;
            let merged = aabb[a as usize].merge(&aabb[b as usize]);
            aabb.push(merged);
            diameter.push(merged.diameter());
            merges.push([a, b]);
            active.retain(|&x| x != a && x != b);
            parentless.retain(|&x| x != a && x != b);
            parentless.push(new);
            if merged.diameter() <= dlimit {
                active.push(new);
            }
        }
        dlimit *= 2.0;
        glimit *= 2.0;
    }
    (merges, pairs)
}

/// `grid` right triangles with legs 0.05 on a 0.2 grid (so DLimit0, their median diameter, makes
/// voxels of about 0.088) and `tiny` with legs 0.0005 at seeded places in a 0.01 cube inside one
/// voxel.
fn crowded(grid: usize, tiny: usize) -> Scene {
    let mut corners: Vec<([f64; 3], f64)> = Vec::new();
    for i in 0..grid {
        corners.push(([(i % 20) as f64 * 0.2, (i / 20) as f64 * 0.2, 0.0], 0.05));
    }
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..tiny {
        let c = [0.1 + 0.01 * next(), 0.1 + 0.01 * next(), 0.01 * next()];
        corners.push((c, 0.0005));
    }
    let mut s = Scene::new("crowded");
    for (c, size) in corners {
        let base = s.points.len() as u32;
        s.points.push(wraptree::geom::P3::new(c[0], c[1], c[2]));
        s.points
            .push(wraptree::geom::P3::new(c[0] + size, c[1], c[2]));
        s.points
            .push(wraptree::geom::P3::new(c[0], c[1] + size, c[2] + size));
        s.push(
            PrimitiveKind::Polygon,
            &[base, base + 1, base + 2],
            &[[base, base + 1, base + 2]],
        );
    }
    s
}

/// Whether round 0's voxels (edge DLimit0 + GLimit0 from the active boxes' lowest corner) are
/// crowded: more than 64 voxel-mates per active body on average.
fn crowded_round(boxes: &[Aabb], resolved: &ResolvedParams) -> bool {
    let csize = resolved.dlimit0 + resolved.glimit0;
    let active: Vec<&Aabb> = boxes
        .iter()
        .filter(|b| b.diameter() <= resolved.dlimit0)
        .collect();
    let origin = active.iter().fold(Aabb::EMPTY, |u, b| u.merge(b)).min;
    let mut voxels = std::collections::HashMap::new();
    for b in &active {
        let c = b.center();
        let v = [0, 1, 2].map(|k| ((c[k] - origin[k]) / csize).floor() as i64);
        *voxels.entry(v).or_insert(0usize) += 1;
    }
    let mates: usize = voxels.values().map(|n| n * n).sum();
    mates > 64 * active.len()
}

/// The merges and each round's eligible pairs of `scene` are the literal run's on 1 and 2 threads.
fn check_literal(scene: &Scene) {
    let params = Params::default();
    let resolved = params.resolve(scene);
    let boxes: Vec<Aabb> = (0..scene.len()).map(|i| scene.prim_aabb(i)).collect();
    let (want, pairs) = literal(&boxes, &resolved);
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let (g, log) = pool.install(|| common::run(scene, &params));
        common::check_tree(scene, &g, &log);
        let got: Vec<[u32; 2]> = log.merges.iter().map(|m| [m.a, m.b]).collect();
        assert_eq!(got.len(), want.len());
        for (i, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g, w, "merge {i} on {threads} threads");
        }
        let got_pairs: Vec<u64> = log.rounds.iter().map(|r| r.5).collect();
        assert_eq!(
            got_pairs, pairs,
            "eligible pairs per round on {threads} threads"
        );
    }
}

#[test]
fn crowded_voxels_give_the_literal_merges_on_1_and_2_threads() {
    // 300 active bodies in crowded round 0: on 2 threads its start runs in parallel (from 256).
    let scene = crowded(300, 250);
    let params = Params::default();
    let boxes: Vec<Aabb> = (0..scene.len()).map(|i| scene.prim_aabb(i)).collect();
    assert!(crowded_round(&boxes, &params.resolve(&scene)));
    check_literal(&scene);
}

#[test]
fn one_crowded_voxel_in_a_sparse_round_gives_the_literal_merges() {
    // 90 tiny triangles in one voxel: its records are cut into blocks (searched block by block
    // and scanned run by run at the round start), in a round that is not crowded overall.
    let scene = crowded(400, 90);
    let params = Params::default();
    let boxes: Vec<Aabb> = (0..scene.len()).map(|i| scene.prim_aabb(i)).collect();
    assert!(!crowded_round(&boxes, &params.resolve(&scene)));
    check_literal(&scene);
}
