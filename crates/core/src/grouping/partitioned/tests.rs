//! The brute-force subproblems (`all_pairs`, `partner_table`, through `brute_force`) against the voxel-hash one on the same bodies.

use super::round_limits::RoundLimits;
use super::subproblem::{Body, Counters, Leftover, MergeInfo, MergeSlots, PairList, RunInputs};
use super::{all_pairs, brute_force, voxel_step};
use crate::geom::Aabb;
use crate::grouping::{Budget, Params, Weights};
use crate::scene::generate;

/// Children, Cost bits and round of each merge, and the ids of the bodies left.
type Solved = (Vec<([u32; 2], u64, u32)>, Vec<u32>);

/// Bodies and, when a brute-force subproblem left them, their pairs.
#[derive(Default)]
struct Half {
    bodies: Vec<Body>,
    pairs: PairList,
}

/// A part of bodies without pairs.
fn part(bodies: &[Body]) -> Half {
    Half {
        bodies: bodies.to_vec(),
        pairs: PairList::new(),
    }
}

/// Runs `combine` on `bodies` (ids from 0, new ids from `n`) and returns the merges and the
/// bodies left.
fn solve(ctx: &RunInputs, bodies: &[Body], keep: usize, n: u32, brute: bool) -> Solved {
    solve_parts(
        ctx,
        [part(bodies), Half::default()],
        keep,
        n,
        brute.then_some(false),
    )
    .0
}

/// Runs `combine` on `parts` (brute force with `export`, or the voxel hash for `None`); returns
/// the merges and bodies left, and what the brute force left.
fn solve_parts(
    ctx: &RunInputs,
    parts: [Half; 2],
    keep: usize,
    n: u32,
    export: Option<bool>,
) -> (Solved, Half) {
    let m = parts[0].bodies.len() + parts[1].bodies.len() - keep;
    let mut children = vec![[0u32; 2]; m];
    let mut aabb = vec![Aabb::EMPTY; m];
    let mut diameter = vec![0.0; m];
    let mut info = vec![MergeInfo::default(); m];
    let mut out = MergeSlots {
        first_new: n,
        children: &mut children,
        aabb: &mut aabb,
        diameter: &mut diameter,
        info: Some(&mut info),
        stats: Counters::default(),
    };
    let left = match export {
        Some(e) => {
            let [a, b] = parts;
            let lefts = [
                Leftover {
                    n: a.bodies.len(),
                    pairs: a.pairs,
                },
                Leftover {
                    n: b.bodies.len(),
                    pairs: b.pairs,
                },
            ];
            let mut arena = [a.bodies, b.bodies].concat();
            let left = brute_force::combine(ctx, &mut arena, lefts, keep, &mut out, e);
            Half {
                bodies: arena[..left.n].to_vec(),
                pairs: left.pairs,
            }
        }
        None => {
            let [a, b] = parts;
            let bodies = [a.bodies, b.bodies].concat();
            part(&voxel_step::combine_by_voxels(ctx, bodies, keep, &mut out).unwrap())
        }
    };
    let merges = (0..m)
        .map(|i| (children[i], info[i].cost.to_bits(), info[i].round))
        .collect();
    let mut ids: Vec<u32> = left.bodies.iter().map(|b| b.id).collect();
    ids.sort_unstable();
    ((merges, ids), left)
}

#[test]
fn brute_force_equals_the_voxel_hash_run() {
    let budget = Budget::default();
    // Sizes for both brute-force solvers (`all_pairs` up to 8 bodies, `brute_force` above).
    for (seed, n) in [
        (1u64, 64usize),
        (2, 40),
        (3, 17),
        (4, 64),
        (5, 2),
        (6, 3),
        (7, 5),
        (8, 8),
        (9, 7),
        (10, 12),
    ] {
        let scene = generate::soup(n, seed);
        for weights in [
            Weights {
                a: 1.0,
                b: 1.0,
                c: 0.0,
            },
            Weights {
                a: 2.0,
                b: 0.5,
                c: 1.0,
            },
        ] {
            let params = Params {
                weights,
                seed: (seed % 2 == 0).then_some(seed),
                ..Params::default()
            }
            .resolve(&scene);
            let ctx = RunInputs::new(params, &budget);
            // Ids spread out as in a larger run: body i has id 3i + 1.
            let bodies: Vec<Body> = (0..n)
                .map(|i| {
                    let aabb = scene.prim_aabb(i);
                    Body {
                        id: 3 * i as u32 + 1,
                        first_round: ctx.dl.first(aabb.diameter()),
                        aabb,
                        diameter: aabb.diameter(),
                    }
                })
                .collect();
            for keep in [1, 2, n / 2, n].into_iter().filter(|&k| k >= 1 && k <= n) {
                let next = 3 * n as u32 + 5;
                let a = solve(&ctx, &bodies, keep, next, true);
                let b = solve(&ctx, &bodies, keep, next, false);
                assert_eq!(a, b, "soup {n} seed {seed} keep {keep} {weights:?}");
            }
            // The pairs two halves pass up give the merges of pairs evaluated again.
            if n >= 6 {
                let h = n / 2;
                let half = |r: &[Body], keep, first| {
                    solve_parts(&ctx, [part(r), Half::default()], keep, first, Some(true)).1
                };
                let (l0, l1) = (
                    half(&bodies[..h], h - 1, 1000),
                    half(&bodies[h..], n - h - 1, 2000),
                );
                assert!(!l0.pairs.is_empty() && !l1.pairs.is_empty());
                let bare = [part(&l0.bodies), part(&l1.bodies)];
                let keep = (n - 2) / 2;
                let with = solve_parts(&ctx, [l0, l1], keep, 3000, Some(false)).0;
                let without = solve_parts(&ctx, bare, keep, 3000, Some(false)).0;
                assert_eq!(with, without, "soup {n} seed {seed} {weights:?}");
            }
        }
    }
}

#[test]
fn two_bodies_merge_as_the_table_of_pairs_merges_them() {
    let budget = Budget::default();
    let cube = |lo: f64, hi: f64| Aabb {
        min: [lo; 3].into(),
        max: [hi; 3].into(),
    };
    // Overlapping, far apart (eligible in a later round) and two points.
    let boxes = [
        (cube(0.0, 1.0), cube(0.5, 2.0)),
        (cube(0.0, 0.1), cube(40.0, 41.0)),
        (cube(3.0, 3.0), cube(3.0, 3.0)),
    ];
    let params = Params::default().resolve(&generate::soup(16, 3));
    let ctx = RunInputs::new(params, &budget);
    let mut rounds = Vec::new();
    for (x, y) in boxes {
        let body = |id, aabb: Aabb| Body {
            id,
            first_round: ctx.dl.first(aabb.diameter()),
            aabb,
            diameter: aabb.diameter(),
        };
        // One half of two bodies (a chunk), or two halves of one.
        for split in [2, 1] {
            let run = |pair: bool| {
                let mut children = [[0u32; 2]; 1];
                let (mut aabb, mut diameter) = ([Aabb::EMPTY; 1], [0.0; 1]);
                let mut info = [MergeInfo::default(); 1];
                let mut out = MergeSlots {
                    first_new: 9,
                    children: &mut children,
                    aabb: &mut aabb,
                    diameter: &mut diameter,
                    info: Some(&mut info),
                    stats: Counters::default(),
                };
                let mut arena = [body(4, x), body(7, y)];
                let parts = [
                    Leftover {
                        n: split,
                        pairs: PairList::new(),
                    },
                    Leftover {
                        n: 2 - split,
                        pairs: PairList::new(),
                    },
                ];
                let (left, stats) = if pair {
                    let mut stats = Counters::default();
                    arena[0] = all_pairs::pair(&ctx, &arena[0], &arena[1], &mut out, &mut stats);
                    let left = Leftover {
                        n: 1,
                        pairs: PairList::new(),
                    };
                    (left, stats)
                } else {
                    let left = all_pairs::combine_few(&ctx, &mut arena, parts, 1, &mut out, true);
                    (left, out.stats)
                };
                let stats = format!("{stats:?}");
                (
                    children,
                    aabb,
                    diameter.map(f64::to_bits),
                    format!("{:?}", info[0]),
                    stats,
                    left.n,
                    left.pairs.len(),
                    arena[0].id,
                )
            };
            let got = run(true);
            assert_eq!(got, run(false), "{x:?} {y:?} split {split}");
            rounds.push(got.3.contains("round: 0,"));
        }
    }
    // Both merges at the first round start and merges that wait for a later one.
    assert!(
        rounds.contains(&true) && rounds.contains(&false),
        "{rounds:?}"
    );
}
#[test]
fn limits_are_the_base_doubled_up_to_the_first_infinity() {
    for base in [
        0.3,
        1.0,
        1.5,
        1e-310,
        5e-324,
        1e300,
        f64::MAX,
        f64::MIN_POSITIVE,
    ] {
        let l = RoundLimits::new(base);
        let mut v = base;
        for r in 0..l.rounds() as u32 {
            assert_eq!(l.at(r).to_bits(), v.to_bits(), "base {base}, round {r}");
            assert_eq!(v.is_infinite(), r + 1 == l.rounds() as u32, "base {base}");
            v *= 2.0;
        }
    }
}

#[test]
fn limits_give_the_first_round_that_admits_a_value() {
    let l = RoundLimits::new(0.3);
    for x in [0.0, 0.3, 0.31, 0.6, 0.6000001, 1e-300, 7.5, 1e300, f64::MAX] {
        let r = l.first(x);
        assert!(x <= l.at(r), "{x} within round {r}");
        assert!(r == 0 || x > l.at(r - 1), "{x}: round {r} is the first");
    }
    assert_eq!(l.first(f64::INFINITY), l.first(f64::INFINITY));
    assert!(l.at(l.first(f64::INFINITY)).is_infinite());
    // Against a linear search, for normal and subnormal bases and values at, just above and
    // just below every limit.
    for base in [0.3, 1.0, 1.5, 1e-310, 5e-324, 1e300] {
        let l = RoundLimits::new(base);
        let naive = |x: f64| (0u32..).find(|&r| x <= l.at(r)).unwrap();
        for r in 0..l.rounds() as u32 {
            let v = l.at(r);
            for x in [
                v,
                f64::from_bits(v.to_bits() + 1),
                f64::from_bits(v.to_bits() - 1),
            ] {
                if x.is_finite() && x > 0.0 {
                    assert_eq!(l.first(x), naive(x), "base {base}, x {x}");
                }
            }
        }
    }
}
