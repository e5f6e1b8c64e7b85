//! The pathological scenes (`scene::pathological`): every generator groups into a valid Subset
//! Tree with both p-sets, every Wrapper Tree holds its leaves, diameters and gaps survive a 1e7
//! offset; `scene::split` cuts long thin polygons into convex planar pieces that tile them; the
//! `stress` command and `--split-aspect` end to end.

mod common;

use common::wraptree;

use wraptree::geom::{P3, V3};
use wraptree::grouping::{PSet, Params};
use wraptree::scene::pathological::{self as path, Layout};
use wraptree::scene::split::{aspect, split_aspect};
use wraptree::scene::{PrimitiveKind, Scene, generate};
use wraptree::wrap::{
    HULL_TOL_REL, SphereMethod, WrapperTree, containment_excess, hull_tree, obb_tree, sphere_tree,
};

/// Every generator at a size that keeps the hull p-set fast (1,024-vertex polygons are slow to
/// hull: few of them).
fn scenes() -> Vec<Scene> {
    let mut v: Vec<Scene> = path::KINDS
        .iter()
        .filter(|k| **k != "ngons")
        .map(|k| path::by_name(k, Some(120), 7).unwrap())
        .collect();
    v.push(path::ngons(5, 1024, 7));
    v.push(path::spaghetti(150, 1024.0, Layout::Parallel, 2));
    v
}

fn hull_pset() -> Params {
    Params {
        pset: PSet::Hull,
        ..Params::default()
    }
}

#[test]
fn every_generator_groups_into_a_valid_tree_with_both_psets() {
    for s in scenes() {
        for params in [Params::default(), hull_pset()] {
            let (g, log) = common::run(&s, &params);
            common::check_tree(&s, &g, &log);
            assert!(
                g.tree.diameter.iter().all(|d| d.is_finite()),
                "{} {:?}",
                s.name,
                params.pset
            );
        }
    }
}

/// How far the worst vertex lies outside its wrapper, minus the tolerance (1e-9 × diagonal and
/// 16 ulps of the largest coordinate; hulls add `HULL_TOL_REL` × the node's box diameter).
fn worst(s: &Scene, tree: &wraptree::grouping::SubsetTree, w: WrapperTree<'_>) -> f64 {
    let far = s.points.iter().flat_map(|p| p.iter().map(|c| c.abs()));
    let base = 1e-9 * s.aabb().diameter() + 16.0 * f64::EPSILON * far.fold(0.0, f64::max);
    let hull = matches!(w, WrapperTree::Hulls(_));
    containment_excess(tree, s, w)
        .iter()
        .enumerate()
        .map(|(x, e)| {
            e - base
                - if hull {
                    HULL_TOL_REL * tree.aabb[x].diameter()
                } else {
                    0.0
                }
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

#[test]
fn every_wrapper_tree_contains_its_leaves() {
    for s in scenes() {
        let g = wraptree::grouping::group(&s, &Params::default(), ());
        let t = &g.tree;
        for m in [
            SphereMethod::Merged,
            SphereMethod::AabbCenter,
            SphereMethod::Ritter,
            SphereMethod::Minimum,
        ] {
            let sp = sphere_tree(t, &s, m);
            let e = worst(&s, t, WrapperTree::Spheres(&sp));
            assert!(e <= 0.0, "{} {m:?}: a vertex {e:e} outside", s.name);
        }
        let h = hull_tree(t, &s);
        let e = worst(&s, t, WrapperTree::Hulls(&h));
        assert!(e <= 0.0, "{} hulls: a vertex {e:e} outside", s.name);
        let o = obb_tree(t, &s, None);
        let e = worst(&s, t, WrapperTree::Obbs(&o));
        assert!(e <= 0.0, "{} OBBs: a vertex {e:e} outside", s.name);
    }
}

#[test]
fn diameters_and_gaps_survive_a_1e7_offset() {
    let near = generate::soup(200, 5);
    let far = path::offset(200, 5);
    let ulp = 1e7f64.next_up() - 1e7;
    let shift = V3::new(1e7, -1e7, 1e7);
    for (a, b) in near.points.iter().zip(&far.points) {
        assert!(
            (a + shift - b).amax() <= ulp,
            "the offset scene is the soup moved"
        );
    }
    for params in [Params::default(), hull_pset()] {
        let gn = wraptree::grouping::group(&near, &params, ());
        let gf = wraptree::grouping::group(&far, &params, ());
        for leaf in 0..near.len() {
            let (dn, df) = (gn.tree.diameter[leaf], gf.tree.diameter[leaf]);
            assert!(
                (dn - df).abs() <= 8.0 * ulp,
                "{:?} leaf {leaf}: {dn} vs {df}",
                params.pset
            );
        }
        let (rn, rf) = (gn.tree.root() as usize, gf.tree.root() as usize);
        let (dn, df) = (gn.tree.diameter[rn], gf.tree.diameter[rf]);
        assert!((dn - df).abs() <= 8.0 * ulp, "root: {dn} vs {df}");
    }
    for i in 0..40 {
        for j in 0..40 {
            let gn = near.prim_aabb(i).gap_linf(&near.prim_aabb(j));
            let gf = far.prim_aabb(i).gap_linf(&far.prim_aabb(j));
            assert!((gn - gf).abs() <= 4.0 * ulp, "gap {i}-{j}: {gn} vs {gf}");
        }
    }
}

/// Area and unit normal (Newell) of primitive `i`.
fn area_normal(s: &Scene, i: usize) -> (f64, V3) {
    let p: Vec<P3> = s.prim_vertices(i).copied().collect();
    let n: V3 = (0..p.len())
        .map(|k| (p[k] - p[0]).cross(&(p[(k + 1) % p.len()] - p[0])))
        .sum();
    (n.norm() / 2.0, n.normalize())
}

/// Asserts the pieces of `out` (from `map`) tile `s`: areas sum to the original's (1e-9 rel),
/// each piece convex and in its original's plane, and each piece of aspect ≤ `r` where `blunt`.
fn check_split(s: &Scene, r: f64, blunt: bool) {
    let (out, map) = split_aspect(s, r);
    assert_eq!(out.len(), map.len());
    assert!(
        map.windows(2).all(|w| w[0] <= w[1]),
        "pieces keep the order"
    );
    // Cut points are rounded to the coordinates' grid: allow 8 ulps of the largest coordinate.
    let far = s.points.iter().flat_map(|p| p.iter().map(|c| c.abs()));
    let grid = 8.0 * f64::EPSILON * far.fold(0.0, f64::max);
    let mut area = vec![0.0; s.len()];
    for (i, &o) in map.iter().enumerate() {
        let o = o as usize;
        let (a, n) = area_normal(&out, i);
        let (_, n0) = area_normal(s, o);
        area[o] += a;
        assert!(n.dot(&n0) > 1.0 - 1e-9, "piece {i} faces like its original");
        let p: Vec<P3> = out.prim_vertices(i).copied().collect();
        let diam = out.prim_aabb(i).diameter();
        let q0 = s.prim_vertices(o).next().unwrap();
        for (k, q) in p.iter().enumerate() {
            let off = (q - q0).dot(&n0).abs();
            assert!(
                off <= 1e-9 * diam + grid,
                "piece {i} of {o}: {off:e} off the plane"
            );
            let (b, c) = (p[(k + 1) % p.len()], p[(k + 2) % p.len()]);
            let turn = (b - q).cross(&(c - b)).dot(&n0);
            assert!(
                turn >= -1e-9 * (b - q).norm() * (c - b).norm(),
                "piece {i} convex"
            );
        }
        let a_i = aspect(&p);
        if blunt {
            assert!(
                a_i <= r * (1.0 + 1e-9),
                "piece {i} of {o}: aspect {a_i} > {r}"
            );
        }
    }
    for (o, a) in area.iter().enumerate() {
        let (a0, _) = area_normal(s, o);
        let perimeter = 4.0 * s.prim_aabb(o).diameter();
        let tol = 1e-9 * a0 + grid * perimeter;
        assert!((a - a0).abs() <= tol, "primitive {o}: pieces {a} vs {a0}");
    }
}

/// Random rectangles and stadium-like octagons (blunt ends) of aspect 1..1000, anywhere.
fn blunt_shapes(seed: u64) -> Scene {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut s = Scene::new("blunt");
    for i in 0..60 {
        let len = 10f64.powf(3.0 * rng.random::<f64>());
        let c = P3::from(V3::from(rng.random::<[f64; 3]>()) * 1e3);
        let d = V3::from(rng.random::<[f64; 3]>().map(|x| x - 0.5)).normalize();
        let e = d.cross(&V3::new(0.3, 0.9, 0.1)).normalize();
        let (h, w) = (d * (len / 2.0), e * 0.5);
        let pts: Vec<P3> = if i % 2 == 0 {
            vec![c - h - w, c + h - w, c + h + w, c - h + w]
        } else {
            let t = d * 0.2;
            let w2 = w * 0.6;
            vec![
                c - h - w2,
                c - h + t - w,
                c + h - t - w,
                c + h - w2,
                c + h + w2,
                c + h - t + w,
                c - h + t + w,
                c - h + w2,
            ]
        };
        let base = s.points.len() as u32;
        s.points.extend(pts.iter().copied());
        let v: Vec<u32> = (base..base + pts.len() as u32).collect();
        let tris: Vec<[u32; 3]> = (1..v.len() - 1).map(|k| [v[0], v[k], v[k + 1]]).collect();
        s.push(PrimitiveKind::Polygon, &v, &tris);
    }
    s
}

#[test]
fn split_pieces_tile_the_original_and_obey_the_limit() {
    for (seed, r) in [(1, 2.0), (2, 8.0), (3, 37.5)] {
        check_split(&blunt_shapes(seed), r, true);
    }
    let spaghetti = path::spaghetti(100, 300.0, Layout::Random, 4);
    check_split(&spaghetti, 8.0, false);
    check_split(&path::offset(100, 4), 2.0, false);
    check_split(&path::ngons(3, 1024, 4), 2.0, true);
}

#[test]
fn split_bounds_the_length_of_thin_triangle_pieces() {
    let s = path::thin_triangles(50, 500.0, 9);
    let (out, map) = split_aspect(&s, 8.0);
    assert_eq!(out.len(), 50 * 63, "⌈500 / 8⌉ = 63 slabs per triangle");
    // Strands have length 1 and width 1/500: a slab is 1/63 long and at most 1/500 wide.
    let most = (1.0f64 / 63.0).hypot(1.0 / 500.0) * (1.0 + 1e-9);
    for (i, o) in map.iter().enumerate() {
        let p: Vec<P3> = out.prim_vertices(i).copied().collect();
        let diam = p
            .iter()
            .flat_map(|a| p.iter().map(move |b| (a - b).norm()))
            .fold(0.0, f64::max);
        assert!(diam <= most, "piece {i} of {o}: diameter {diam}");
    }
}

#[test]
fn split_at_infinity_is_the_identity_and_degenerates_are_kept() {
    let s = path::spaghetti(40, 100.0, Layout::Parallel, 1);
    let (out, map) = split_aspect(&s, f64::INFINITY);
    assert_eq!(out.points, s.points);
    assert_eq!(out.prim_points, s.prim_points);
    assert_eq!(map, (0..40).collect::<Vec<u32>>());
    let c = path::collinear(30, 1);
    let (out, map) = split_aspect(&c, 2.0);
    assert_eq!(
        (out.len(), map.len()),
        (30, 30),
        "zero-area primitives stay whole"
    );
}

#[test]
fn split_aspect_flag_multiplies_n_and_replays_identically() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("spag.obj");
    let obj = obj.to_str().unwrap();
    let out = wraptree(
        &["scene", "spaghetti-parallel", "-n", "40", "-o", obj],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let n_of = |extra: &[&str]| {
        let mut args = vec!["group", obj, "--json"];
        args.extend_from_slice(extra);
        let out = wraptree(&args, dir.path());
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (
            v["primitives"].as_u64().unwrap(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    assert_eq!(n_of(&[]).0, 40);
    let (n8, err) = n_of(&["--split-aspect", "8"]);
    assert_eq!(n8, 40 * 8, "aspect 64 at R = 8: 8 slabs per strand");
    assert!(
        err.contains("split 40 of 40 primitives into 320 pieces"),
        "{err}"
    );
    assert_eq!(
        n_of(&["--split-aspect", "100"]).0,
        40,
        "below the limit: unchanged"
    );
    let bad = wraptree(&["group", obj, "--split-aspect", "1"], dir.path());
    common::assert_one_line_error(&bad, "--split-aspect");

    let prefix = dir.path().join("rec");
    let prefix = prefix.to_str().unwrap();
    let rec = wraptree(
        &[
            "record",
            obj,
            "--split-aspect",
            "8",
            "--detail",
            "levels",
            "-o",
            prefix,
        ],
        dir.path(),
    );
    assert!(
        rec.status.success(),
        "{}",
        String::from_utf8_lossy(&rec.stderr)
    );
    let mcap = format!("{prefix}.mcap");
    let rep = wraptree(&["replay", &mcap, "--verify"], dir.path());
    let text = String::from_utf8_lossy(&rep.stdout);
    assert!(rep.status.success() && text.contains("identical"), "{text}");
    assert!(
        text.contains("320"),
        "the recording holds the split scene: {text}"
    );
}

#[test]
fn stress_quick_writes_the_csv_and_the_chart() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let out = wraptree(&["stress", "--quick", "--budget", "2", "-o", d], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.path().join("stress.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert!(csv.starts_with("scene,n,method,split_r,finished,valid,"));
    for kind in path::KINDS {
        let n = if kind == "ngons" { 10 } else { 300 };
        let name = path::by_name(kind, Some(n), 1).unwrap().name;
        let aabb: Vec<_> = rows
            .iter()
            .filter(|r| r[0] == name && r[1] == n.to_string() && r[2] == "group-aabb")
            .filter(|r| r[3].is_empty())
            .collect();
        assert_eq!(aabb.len(), 1, "{kind}: one unsplit AABB grouping row");
        assert_eq!(
            (aabb[0][4], aabb[0][5]),
            ("true", "true"),
            "{kind}: {:?}",
            aabb[0]
        );
        for m in ["group-hull", "wrap-sphere-minimum", "wrap-obb"] {
            assert!(rows.iter().any(|r| r[0] == name && r[2] == m), "{name} {m}");
        }
    }
    for a in ["a1", "a16", "a256"] {
        let name = format!("spaghetti-parallel-{a}");
        let n = rows
            .iter()
            .filter(|r| r[0] == name && r[2] == "group-aabb")
            .count();
        assert_eq!(n, 2, "{name}: without and with the split");
    }
    for m in [100, 200, 400] {
        let n = rows
            .iter()
            .filter(|r| r[0] == "spaghetti-parallel-a64" && r[2] == "group-aabb")
            .filter(|r| r[3].is_empty() && r[1] == m.to_string())
            .count();
        assert_eq!(n, 1, "N sweep at {m} strands");
    }
    for chart in ["spaghetti", "spaghetti-n"] {
        let png = std::fs::read(dir.path().join(format!("{chart}.png"))).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        let svg = std::fs::read_to_string(dir.path().join(format!("{chart}.svg"))).unwrap();
        assert!(svg.contains("split R = 8"), "{chart}");
    }
    let again = wraptree(&["stress", "--quick", "-o", d], dir.path());
    common::assert_one_line_error(&again, "already exists");
}

/// Sizes spanning 12 decades: node 862 here mixes points 1e-2 apart with a 6e5 extent, which
/// collapse in `f32`, where a hull once folded and left a vertex 1.2e4 outside.
#[test]
fn hull_wrappers_hold_their_vertices_across_12_decades() {
    let s = path::scales(500, 1);
    let g = wraptree::grouping::group(&s, &Params::default(), ());
    let h = hull_tree(&g.tree, &s);
    let e = worst(&s, &g.tree, WrapperTree::Hulls(&h));
    assert!(e <= 0.0, "a vertex {e:e} outside its hull beyond tolerance");
}

/// N coincident triangles: every Cost ties, so the literal queue of every eligible pair merges
/// the two live bodies of smallest tie tag (the id, unseeded) each time. The partner searches
/// must keep that order with O(N²) candidate examinations: bodies of identical geometry that
/// re-search between two merges share one scan, where one scan each would make it O(N³).
/// The same holds for the hull p-set, whose bodies are their vertex sets.
#[test]
fn coincident_bodies_merge_smallest_ids_first_in_quadratic_work() {
    for (n, params) in [(600, Params::default()), (300, hull_pset())] {
        let s = path::coincident(n);
        let (g, log) = common::run(&s, &params);
        common::check_tree(&s, &g, &log);
        let mut live: std::collections::BTreeSet<u32> = (0..n as u32).collect();
        for (i, m) in log.merges.iter().enumerate() {
            let (a, b) = (live.pop_first().unwrap(), live.pop_first().unwrap());
            assert_eq!((m.a, m.b), (a, b), "{:?} merge {i}", params.pset);
            live.insert(m.new);
        }
        let c = g.stats.candidates;
        assert!(
            c < 8 * (n * n) as u64,
            "{:?}: {c} candidates for {n} bodies",
            params.pset
        );
    }
}

/// The shape of the hull runaway: rigid, randomly rotated copies of a small robot link
/// (0.2 units) beside copies of a mug 30 units wide, the link far below the `f32` resolution of
/// the nodes that join them. Every solid hull of both p-sets' trees is closed and convex, holds its
/// children's vertices, and is made of scene vertices only (no fallback box), and the hull
/// p-set's bodies keep only their hulls' vertices.
#[test]
fn mixed_scale_assembly_gets_exact_hulls_from_both_psets() {
    use wraptree::geom::hull::is_convex_cover;
    use wraptree::scene::assembly::{Part, assemble};
    let scaled = |file: &str, size: f64| {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes")
            .join(file);
        let mut s = wraptree::scene::load_path(&path, &Default::default())
            .unwrap()
            .scene;
        let (c, d) = (s.aabb().center(), s.aabb().diameter());
        for p in &mut s.points {
            *p = c + (*p - c) * (size / d);
        }
        s
    };
    let parts = [
        Part {
            scene: scaled("kuka-link0.obj", 0.2),
            copies: 6,
        },
        Part {
            scene: scaled("mug.obj", 30.0),
            copies: 4,
        },
    ];
    let (s, _) = assemble(&parts, 11).unwrap();
    let vertices: std::collections::HashSet<[u64; 3]> = s
        .points
        .iter()
        .map(|p| p.coords.map(f64::to_bits).into())
        .collect();
    for params in [Params::default(), hull_pset()] {
        let g = wraptree::grouping::group(&s, &params, ());
        let hulls = hull_tree(&g.tree, &s);
        for (x, [a, b]) in g.tree.children.iter().enumerate() {
            let x = g.tree.leaves() + x;
            let h = &hulls[x];
            let below: Vec<P3> = [a, b]
                .iter()
                .flat_map(|&&c| hulls[c as usize].vertices.clone())
                .collect();
            // Flat nodes (coplanar faces of one copy) are polygons, checked elsewhere.
            assert!(h.dim < 3 || is_convex_cover(h, &below, 0.0), "node {x}");
            assert!(
                h.vertices
                    .iter()
                    .all(|v| vertices.contains(&<[u64; 3]>::from(v.coords.map(f64::to_bits)))),
                "node {x} has a vertex that is not the scene's"
            );
        }
    }
}
