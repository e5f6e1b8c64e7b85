//! Aspect-limited splitting, the mitigation the paper proposes in §4 for long thin primitives:
//! "preprocess the input to obtain polygons or polyhedra with limited aspect
//! (primary-axis:secondary-axis) ratios" (`--split-aspect`, `docs/stability.md`).
//!
//! [`aspect`] measures a primitive's aspect from its principal axes; [`split_aspect`] cuts each
//! polygon of aspect above R into convex slabs across its long axis that tile it exactly. Never
//! a panic: a zero-area primitive and every polyhedron are kept unchanged; R below 2 is taken as
//! 2 and R = ∞ or NaN keeps the scene as it is.

use super::{LoadError, LoadOptions, Loaded, PrimitiveKind, Scene, load_bytes};
use crate::geom::pca::Frame;
use crate::geom::{P3, V3};

/// Relative second extent below which a primitive counts as degenerate and is not split: like
/// the loader's [`AREA_EPS`](super::polygon::AREA_EPS), relative to the primitive's own size
/// (its first extent), never the scene's.
pub const DEGENERATE_REL: f64 = 1e-12;

/// Smallest aspect limit used; lower values are raised to it.
pub const MIN_ASPECT_LIMIT: f64 = 2.0;

/// What [`split_aspect`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SplitStats {
    /// Primitives cut into pieces.
    pub split: usize,
    /// Pieces those primitives became.
    pub pieces: usize,
    /// Primitives above the limit kept whole because they are degenerate or polyhedra.
    pub kept: usize,
}

/// The aspect of a point set and the frame it was measured in: (principal extent / second
/// extent, frame, min and max local coordinates). `f64::INFINITY` when the second extent is
/// zero or negligible (≤ [`DEGENERATE_REL`] × the first), 1 for fewer than two distinct points.
fn measure(points: &[P3]) -> (f64, Frame, V3, V3) {
    let frame = Frame::principal(points);
    let (lo, hi) = frame.bounds(points);
    let e = hi - lo;
    let a = if e.x.is_nan() || e.x <= 0.0 {
        1.0
    } else if e.y <= DEGENERATE_REL * e.x {
        f64::INFINITY
    } else {
        e.x / e.y
    };
    (a, frame, lo, hi)
}

/// The aspect of `points`: principal extent over second principal extent; ∞ for collinear
/// points, 1 for a single point.
///
/// The extents are those along the principal axis (largest variance, [`Frame::principal`]) and
/// the second principal axis. For a planar polygon the third extent (its 3D thickness) is zero,
/// so the second axis is the in-plane width; extents are max − min of vertex coordinates, which
/// no interior vertex can perturb, and the principal axis of a long shape is its long axis
/// whatever its vertex count.
pub fn aspect(points: &[P3]) -> f64 {
    measure(points).0
}

/// Splits every polygon of `scene` whose [`aspect`] exceeds `r` into convex pieces of aspect at
/// most `r` (up to the sharp-corner limit below), returning the new scene and, for each of its
/// primitives, the id of the original primitive it came from.
///
/// Primitives below the limit, degenerate primitives (second extent ≤ [`DEGENERATE_REL`] × the
/// first) and polyhedra are copied unchanged; the order is kept (pieces of primitive i follow
/// each other where i was). `r` below 2 is taken as 2 (for 1 ≤ R < 2 slabs of a rectangle could
/// come out too wide for their length); `r` = ∞ (or NaN) returns a copy of the scene with the
/// identity map.
///
/// A polygon of aspect A > R is cut by k − 1 planes perpendicular to its long axis,
/// k = ⌈A / R⌉ (up to 1e-12 relative), into k slabs of equal length (Sutherland–Hodgman against
/// one plane at a time). Each cut point is computed once and shared by the two pieces, so the
/// pieces are convex, lie in the polygon's plane (up to rounding of the interpolation), and tile
/// it exactly: their areas sum to the original's. A piece whose width is the polygon's full
/// width (rectangles, the middle of any blunt shape) has aspect ≤ R for R ≥ 2. A piece
/// containing a corner sharper than about 1 / R keeps that corner's sliver shape: any convex
/// piece containing a corner of angle θ has aspect ≥ ~1 / θ, so no partition could do better;
/// such pieces are still at most R × the original width long.
pub fn split_aspect(scene: &Scene, r: f64) -> (Scene, Vec<u32>) {
    let (s, map, _) = split_aspect_stats(scene, r);
    (s, map)
}

/// [`split_aspect`] with counts of what was split.
pub fn split_aspect_stats(scene: &Scene, r: f64) -> (Scene, Vec<u32>, SplitStats) {
    let identity = || {
        (
            scene.clone(),
            (0..scene.len() as u32).collect(),
            SplitStats::default(),
        )
    };
    if r.is_nan() || r == f64::INFINITY {
        return identity();
    }
    let r = r.max(MIN_ASPECT_LIMIT);
    let mut out = Scene::new(scene.name.clone());
    out.kind = scene.kind;
    out.points = scene.points.clone();
    let mut map = Vec::with_capacity(scene.len());
    let mut stats = SplitStats::default();
    let poly = scene.kind == Some(PrimitiveKind::Polygon);
    let mut pts: Vec<P3> = Vec::new();
    for i in 0..scene.len() {
        pts.clear();
        pts.extend(scene.prim_vertices(i).copied());
        let (a, frame, lo, hi) = measure(&pts);
        if a <= r {
            copy_primitive(scene, i, &mut out);
            map.push(i as u32);
            continue;
        }
        if !poly || !a.is_finite() {
            stats.kept += 1;
            copy_primitive(scene, i, &mut out);
            map.push(i as u32);
            continue;
        }
        let u: V3 = frame.axes.column(0).into();
        // A relative slack of 1e-12 keeps an aspect of m·R (up to rounding) at m pieces.
        let k = ((a / r * (1.0 - 1e-12)).ceil() as usize).max(2);
        let pieces = cut_slabs(&mut out, scene.prim(i), &u, &frame.origin, lo.x, hi.x, k);
        stats.split += 1;
        stats.pieces += pieces;
        map.extend(std::iter::repeat_n(i as u32, pieces));
    }
    if let Some(labels) = (!scene.labels.is_empty()).then_some(&scene.labels) {
        out.labels = map
            .iter()
            .map(|&i| labels.get(i as usize).cloned().unwrap_or_default())
            .collect();
    }
    if !scene.objects.is_empty() {
        out.objects = map.iter().map(|&i| scene.object(i as usize)).collect();
    }
    (out, map, stats)
}

/// A loaded scene with its polygons split at aspect `r` ([`split_aspect`]), as if loaded from
/// the split scene's OBJ: the source bytes are the split scene written by [`Scene::write_obj`]
/// and loaded back with the same options less the up axis (file `{stem}-split{r}.obj`, already
/// upright), so a recording of it
/// embeds exactly the scene that was grouped and `replay --verify` reproduces it. When nothing
/// is split, `loaded` is returned unchanged.
pub fn split_loaded(loaded: Loaded, r: f64) -> Result<(Loaded, SplitStats), LoadError> {
    let (scene, _, stats) = split_aspect_stats(&loaded.scene, r);
    if stats.split == 0 {
        return Ok((loaded, stats));
    }
    let mut bytes = Vec::new();
    scene
        .write_obj(&mut bytes)
        .expect("writing to a Vec cannot fail");
    let name = format!("{}-split{r}.obj", loaded.scene.name);
    // The split scene is written already turned upright: loaded without turning it again.
    let opts = LoadOptions {
        up: None,
        ..loaded.source.options
    };
    let mut out = load_bytes(&name, bytes, &opts)?;
    out.warnings.splice(0..0, loaded.warnings);
    Ok((out, stats))
}

/// `--split-aspect R`: [`split_loaded`] after checking `r`, with what was split in one line
/// (`split-aspect R: split S of N primitives into P pieces (N → M primitives)`). Err: `r` NaN
/// or below [`MIN_ASPECT_LIMIT`] (named as the flag), or a split scene that does not load.
pub fn split_flag(loaded: Loaded, r: f64) -> anyhow::Result<(Loaded, String)> {
    if r.is_nan() || r < MIN_ASPECT_LIMIT {
        anyhow::bail!("--split-aspect must be a number ≥ 2, got {r}");
    }
    let n = loaded.scene.len();
    let (split, st) = split_loaded(loaded, r)?;
    let line = format!(
        "split-aspect {r}: split {} of {n} primitives into {} pieces ({n} → {} primitives)",
        st.split,
        st.pieces,
        split.scene.len()
    );
    Ok((split, line))
}

/// Appends primitive `i` of `scene` to `out` (which shares `scene`'s points) unchanged.
fn copy_primitive(scene: &Scene, i: usize, out: &mut Scene) {
    let kind = scene.kind.unwrap_or(PrimitiveKind::Polygon);
    out.push(kind, scene.prim(i), scene.prim_tris(i));
}

/// Cuts the convex polygon `verts` (indices into `out.points`) into `k` slabs of equal length
/// along `u` between local coordinates `lo` and `hi` (measured from `origin`), appends them to
/// `out` and returns how many pieces were appended.
fn cut_slabs(
    out: &mut Scene,
    verts: &[u32],
    u: &V3,
    origin: &P3,
    lo: f64,
    hi: f64,
    k: usize,
) -> usize {
    let mut rest: Vec<u32> = verts.to_vec();
    let mut pieces = 0;
    for j in 1..k {
        let t = lo + (hi - lo) * j as f64 / k as f64;
        let (below, above) = cut(out, &rest, u, origin, t);
        if below.len() >= 3 {
            push_fan(out, &below);
            pieces += 1;
        }
        rest = above;
    }
    if rest.len() >= 3 {
        push_fan(out, &rest);
        pieces += 1;
    }
    pieces
}

/// Splits the convex polygon `poly` at the plane `(p − origin)·u = t` into the parts below and
/// above it. Vertices on the plane go to both; each crossing edge gets one new point, computed
/// from the endpoint with the smaller coordinate so that the result does not depend on the
/// edge's direction.
fn cut(out: &mut Scene, poly: &[u32], u: &V3, origin: &P3, t: f64) -> (Vec<u32>, Vec<u32>) {
    let s = |out: &Scene, v: u32| (out.points[v as usize] - origin).dot(u) - t;
    let (mut below, mut above) = (Vec::new(), Vec::new());
    let n = poly.len();
    for e in 0..n {
        let (a, b) = (poly[e], poly[(e + 1) % n]);
        let (sa, sb) = (s(out, a), s(out, b));
        if sa <= 0.0 {
            below.push(a);
        }
        if sa >= 0.0 {
            above.push(a);
        }
        if (sa < 0.0 && sb > 0.0) || (sa > 0.0 && sb < 0.0) {
            let ((p, sp), (q, sq)) = if sa < sb {
                ((a, sa), (b, sb))
            } else {
                ((b, sb), (a, sa))
            };
            let (pp, pq) = (out.points[p as usize], out.points[q as usize]);
            let lambda = (-sp / (sq - sp)).clamp(0.0, 1.0);
            out.points.push(pp + (pq - pp) * lambda);
            let c = (out.points.len() - 1) as u32;
            below.push(c);
            above.push(c);
        }
    }
    (below, above)
}

/// Appends the convex polygon `v` drawn as a fan.
fn push_fan(out: &mut Scene, v: &[u32]) {
    let tris: Vec<[u32; 3]> = (1..v.len() - 1).map(|k| [v[0], v[k], v[k + 1]]).collect();
    out.push(PrimitiveKind::Polygon, v, &tris);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(len: f64, w: f64) -> Scene {
        let mut s = Scene::new("rect");
        s.points = vec![
            P3::new(0.0, 0.0, 0.0),
            P3::new(len, 0.0, 0.0),
            P3::new(len, w, 0.0),
            P3::new(0.0, w, 0.0),
        ];
        push_fan(&mut s, &[0, 1, 2, 3]);
        s
    }

    #[test]
    fn a_rectangle_of_aspect_100_becomes_13_slabs_at_r_8() {
        let s = rect(100.0, 1.0);
        assert!((aspect(&s.points) - 100.0).abs() < 1e-9);
        let (out, map, st) = split_aspect_stats(&s, 8.0);
        assert_eq!(out.len(), 13);
        assert_eq!(map, vec![0; 13]);
        assert_eq!(
            st,
            SplitStats {
                split: 1,
                pieces: 13,
                kept: 0
            }
        );
        for i in 0..out.len() {
            let p: Vec<P3> = out.prim_vertices(i).copied().collect();
            assert!(
                aspect(&p) <= 8.0 * (1.0 + 1e-9),
                "piece {i}: {}",
                aspect(&p)
            );
        }
    }

    /// A 3.6 µm sliver (aspect 18) 60 units from the origin, beside a unit triangle: it is split like any
    /// other, and every piece survives loading the split scene back.
    #[test]
    fn a_tiny_polygon_far_from_the_origin_is_split_and_its_pieces_load() {
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\n\
                   v 40 44 -5\nv 40.000004 44 -5\nv 40.000004 44.0000002 -5\nv 40 44.0000002 -5\n\
                   f 1 2 3\nf 4 5 6 7\n";
        let loaded = load_bytes("far.obj", obj.into(), &LoadOptions::default()).unwrap();
        assert_eq!(loaded.scene.len(), 2);
        let (split, st) = split_loaded(loaded, 4.0).unwrap();
        assert_eq!((st.split, st.pieces), (1, 5));
        assert_eq!(split.scene.len(), 6);
        assert!(split.warnings.is_empty(), "{:?}", split.warnings);
    }

    #[test]
    fn degenerate_and_low_aspect_primitives_are_kept() {
        let mut s = rect(2.0, 1.0);
        s.points.extend([
            P3::new(0.0, 0.0, 1.0),
            P3::new(5.0, 0.0, 1.0),
            P3::new(9.0, 0.0, 1.0),
        ]);
        push_fan(&mut s, &[4, 5, 6]);
        let (out, map, st) = split_aspect_stats(&s, 2.0);
        assert_eq!(map, vec![0, 1]);
        assert_eq!(st.kept, 1);
        assert_eq!(out.prim(1), s.prim(1));
    }
}
