//! Wavefront OBJ loading (via `tobj`) into a [`Scene`] of convex primitives, with validation.
//!
//! Each file goes through two passes: `scan` validates the text, reporting the first problem
//! with its line, and writes a cleaned copy for `tobj` with the coordinates kept in `f64`; then
//! `tobj::load_obj_buf` parses that copy into groups and faces, materials refused (from 1 MB up
//! the two run at once, `pipe`). In polygon mode (default) every face becomes one
//! `PrimitiveKind::Polygon` by the rules of [`polygon`]; with [`LoadOptions::polyhedra`] every
//! OBJ object/group becomes one `PrimitiveKind::Polyhedron` by the rules of [`polyhedron`].
//! Every primitive records the object id of its group ([`Scene::objects`]; groups of the same
//! name share one id, in order of first appearance). Vertices with bit-identical positions are
//! merged; loading the same bytes twice gives the same scene. With [`LoadOptions::up`] = Y the
//! coordinates are turned so that +Y becomes +Z (OBJ itself says nothing about up: Z is kept by
//! default).

use self::groups::{Group, INDEX_SPLIT, collect_groups};
use self::pipe::Cleaned;
use super::Scene;
use super::faces::{Faces, turn_y_up};
use super::input::{Format, Up};
use super::polygon::{self, PolygonStats};
use super::polyhedron::{self, PolyhedronStats};
use crate::stop::Stop;
// The loading API's types lived here before other formats came; these paths keep working.
pub use super::input::{
    LoadError, LoadErrorKind, LoadOptions, Loaded, MAX_COORDINATE, SceneSource,
};

mod groups;
mod pipe;

/// Loads OBJ `bytes` named `file_name` (the scene is named after its stem).
pub(super) fn load(
    file_name: &str,
    bytes: Vec<u8>,
    opts: &LoadOptions,
    stop: &Stop,
) -> Result<Loaded, LoadError> {
    load_piped_from(file_name, bytes, opts, pipe::PIPELINE_FROM, stop)
}

/// The faces of OBJ `bytes`, one object per group (for a URDF's meshes): the file's
/// coordinates, not turned.
pub(super) fn read_faces(file_name: &str, bytes: Vec<u8>) -> Result<Faces, LoadError> {
    let mut points = Vec::new();
    let never = Stop::new();
    let (groups, scanned) = parse(
        file_name,
        &bytes,
        None,
        &mut points,
        pipe::PIPELINE_FROM,
        &never,
    )?;
    let mut faces = Faces::new();
    faces.coords = points.iter().map(|p| [p.x, p.y, p.z]).collect();
    faces.short = scanned.short_faces;
    for g in &groups {
        let o = faces.object(&g.name);
        for f in g.faces() {
            faces.face(f.iter().copied(), o);
        }
    }
    Ok(faces)
}

/// Checks and parses OBJ `bytes` (pre-pass, then `tobj`): the groups over `points`, which it
/// fills (turned by `up` when that is Y), and the pre-pass's counts. The pre-pass checks `stop`
/// (ending it ends `tobj`'s input too).
fn parse(
    file_name: &str,
    bytes: &[u8],
    up: Option<Up>,
    points: &mut Vec<crate::geom::P3>,
    pipeline_from: usize,
    stop: &Stop,
) -> Result<(Vec<Group>, Scanned), LoadError> {
    let err = |kind, problem: String| LoadError {
        file: file_name.to_string(),
        kind,
        problem,
    };
    let text = super::utf8_text(bytes).map_err(|line| {
        err(
            LoadErrorKind::Malformed,
            format!("not a valid OBJ file (line {line}: not UTF-8 text)"),
        )
    })?;
    let tobj_opts = tobj::LoadOptions {
        single_index: true,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // tobj reads the pre-pass's cleaned text as it is written (a large file) or after it.
    let scan_until = |text: &str, out: &mut dyn Cleaned| scan(text, out, stop);
    let (mut scanned, parsed) = pipe::scan_then(text, pipeline_from, scan_until, |cleaned| {
        tobj::load_obj_buf(cleaned, &tobj_opts, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        })
    })
    .map_err(|(kind, problem)| err(kind, problem))?;
    if scanned.faces == 0 {
        let why = match scanned.short_faces {
            0 => String::new(),
            n => format!(" ({n} faces with fewer than 3 vertices were dropped)"),
        };
        return Err(err(LoadErrorKind::NoFaces, format!("no faces{why}")));
    }
    let (models, _materials) = parsed.map_err(|e| {
        err(
            LoadErrorKind::Malformed,
            format!("not a valid OBJ file ({e})"),
        )
    })?;
    if up == Some(Up::Y) {
        turn_y_up(&mut scanned.coords);
    }
    let groups =
        collect_groups(&models, &scanned.coords, points, stop).map_err(|(kind, p)| err(kind, p))?;
    Ok((groups, scanned))
}

/// [`load_bytes`], with the pre-pass and `tobj` at once from `pipeline_from` bytes up, checking
/// `stop`.
fn load_piped_from(
    file_name: &str,
    bytes: Vec<u8>,
    opts: &LoadOptions,
    pipeline_from: usize,
    stop: &Stop,
) -> Result<Loaded, LoadError> {
    let err = |kind, problem: String| LoadError {
        file: file_name.to_string(),
        kind,
        problem,
    };
    let up = opts.up.unwrap_or(Format::Obj.default_up());
    let stem = super::faces::stem(file_name);
    let mut scene = Scene::new(stem);
    let (groups, scanned) = parse(
        file_name,
        &bytes,
        Some(up),
        &mut scene.points,
        pipeline_from,
        stop,
    )?;
    let mut warnings = Vec::new();
    // Object ids by group name, in order of first appearance.
    let mut object_ids = std::collections::HashMap::<&str, u32>::new();
    let group_ids: Vec<u32> = groups
        .iter()
        .map(|g| {
            let next = object_ids.len() as u32;
            *object_ids.entry(g.name.as_str()).or_insert(next)
        })
        .collect();
    if opts.polyhedra {
        let mut stats = PolyhedronStats::default();
        for (g, &id) in groups.iter().zip(&group_ids) {
            stop.check()
                .map_err(|_| LoadError::interrupted(file_name))?;
            let faces: Vec<&[u32]> = g.faces().collect();
            polyhedron::add(&mut scene, &g.name, &faces, opts.strict, &mut stats)
                .map_err(|p| err(LoadErrorKind::NotConvex, p))?;
            scene.objects.resize(scene.len(), id);
        }
        warnings.extend(
            stats
                .warnings()
                .into_iter()
                .map(|w| format!("{file_name}: {w}")),
        );
    } else {
        let mut stats = PolygonStats {
            degenerate: scanned.short_faces,
            ..PolygonStats::default()
        };
        let mut scratch = polygon::Scratch::default();
        for (g, &id) in groups.iter().zip(&group_ids) {
            for (k, face) in g.faces().enumerate() {
                stop.check_every(k)
                    .map_err(|_| LoadError::interrupted(file_name))?;
                polygon::add(&mut scene, face, &mut stats, &mut scratch);
            }
            scene.objects.resize(scene.len(), id);
        }
        warnings.extend(
            stats
                .warnings()
                .into_iter()
                .map(|w| format!("{file_name}: {w}")),
        );
    }
    if scene.is_empty() {
        return Err(err(
            LoadErrorKind::NoFaces,
            format!(
                "no faces (all {} faces are degenerate)",
                scanned.faces + scanned.short_faces
            ),
        ));
    }
    debug_assert!(scene.points.iter().all(|p| p.iter().all(|c| c.is_finite())));
    let source = super::input::source(file_name, bytes, *opts);
    Ok(Loaded {
        scene,
        source,
        warnings,
    })
}

/// Result of [`scan`]: the `f64` vertices and the face counts.
#[derive(Default)]
struct Scanned {
    coords: Vec<[f64; 3]>,
    faces: usize,
    short_faces: usize,
}

/// A problem found by [`scan`], before its line number is attached.
struct Problem(LoadErrorKind, String);

impl Problem {
    fn malformed(what: String) -> Problem {
        Problem(LoadErrorKind::Malformed, what)
    }

    /// The message with its line, e.g. `not a valid OBJ file (line 5: bad number "x")`.
    fn at(self, line: usize) -> (LoadErrorKind, String) {
        let msg = match self.0 {
            LoadErrorKind::Malformed => format!("not a valid OBJ file (line {line}: {})", self.1),
            _ => format!("{} (line {line})", self.1),
        };
        (self.0, msg)
    }
}

/// Quotes a token for an error message, shortened to 32 characters.
fn shown(tok: &str) -> String {
    let t: String = tok.chars().take(32).collect();
    let more = if t.len() < tok.len() { "…" } else { "" };
    format!("{t:?}{more}")
}

/// Validates `text` line by line and writes to `out` the cleaned copy handed to `tobj`.
///
/// Reports the first problem with its line: not UTF-8, malformed `v`/`f` statements,
/// non-finite or out-of-range coordinates, face indices out of range (including relative ones
/// reaching before the first vertex). Coordinates are parsed in `f64`, and each `v` line of the
/// copy holds its vertex index instead (`tobj` parses `f32` unless its `use_f64` feature is on,
/// and `f32` would lose detail; small integers it holds exactly), so the vertex indices in
/// `tobj`'s positions lead back to the `f64` coordinates. Faces with fewer than 3 vertices and
/// every statement we ignore (`vt`, `vn`, `l`, `p`, `mtllib`, `usemtl`, `s`, …) are blanked;
/// `f`, `o` and `g` lines are kept verbatim. A line ending in `\\` continues on the next (the
/// OBJ specification's long lines): the statement is checked and copied whole on its last line,
/// its errors naming its first.
fn scan(
    text: &str,
    out: &mut dyn Cleaned,
    stop: &Stop,
) -> Result<Scanned, (LoadErrorKind, String)> {
    let mut s = Scanned::default();
    // A vertex's rewritten line, written out whole.
    let mut vline = String::with_capacity(32);
    let mut face_no = 0;
    // Positive indices may point forward: the largest (with its face and line) is checked
    // once all vertices are known.
    let mut forward: Option<(i64, usize, usize)> = None;
    // A statement continued over lines ending in `\`: its text so far and its first line.
    let mut joined = String::new();
    let mut joined_from = 0;
    let mut pieces = text.split('\n').enumerate().peekable();
    while let Some((i, piece)) = pieces.next() {
        stop.check_every(i)
            .map_err(|e| (LoadErrorKind::Interrupted, e.to_string()))?;
        let piece = piece.strip_suffix('\r').unwrap_or(piece);
        if let Some(head) = piece.trim_end_matches([' ', '\t']).strip_suffix('\\')
            && pieces.peek().is_some()
        {
            if joined.is_empty() {
                joined_from = i + 1;
            }
            joined.push_str(head);
            joined.push(' ');
            // The copy keeps one line per line of the file.
            out.push_str("\n");
            continue;
        }
        let (line, raw) = if joined.is_empty() {
            (i + 1, std::borrow::Cow::Borrowed(piece))
        } else {
            joined.push_str(piece);
            (
                joined_from,
                std::borrow::Cow::Owned(std::mem::take(&mut joined)),
            )
        };
        let raw: &str = &raw;
        let mut words = raw.split_whitespace();
        match words.next() {
            Some("v") => {
                // Up to 7 tokens kept: more is an error either way.
                let mut toks = [""; 7];
                let mut n = 0;
                for (slot, t) in toks.iter_mut().zip(words) {
                    *slot = t;
                    n += 1;
                }
                let c = parse_vertex(&toks[..n], s.coords.len() + 1).map_err(|p| p.at(line))?;
                let k = s.coords.len() as u64;
                s.coords.push(c);
                let mut digits = itoa::Buffer::new();
                vline.clear();
                vline.push_str("v ");
                vline.push_str(digits.format(k % INDEX_SPLIT));
                vline.push(' ');
                vline.push_str(digits.format(k / INDEX_SPLIT));
                vline.push_str(" 0\n");
                out.push_str(&vline);
                continue;
            }
            Some("f") => {
                face_no += 1;
                let mut n = 0;
                for tok in words {
                    n += 1;
                    let idx =
                        parse_face_vertex(tok, face_no, s.coords.len()).map_err(|p| p.at(line))?;
                    if idx > forward.map_or(s.coords.len() as i64, |f| f.0) {
                        forward = Some((idx, face_no, line));
                    }
                }
                if n >= 3 {
                    s.faces += 1;
                    out.push_str(raw);
                } else {
                    s.short_faces += 1;
                }
            }
            Some("o" | "g") => out.push_str(raw),
            _ => {}
        }
        out.push_str("\n");
    }
    if let Some((idx, face, line)) = forward.filter(|f| f.0 > s.coords.len() as i64) {
        let n = s.coords.len();
        let why = format!("face {face} refers to vertex {idx} but the file has {n} vertices");
        return Err(Problem(LoadErrorKind::BadIndex, why).at(line));
    }
    Ok(s)
}

/// Parses the numbers after `v` (`x y z`, `x y z w` or `x y z r g b`) of vertex `number`.
fn parse_vertex(toks: &[&str], number: usize) -> Result<[f64; 3], Problem> {
    use LoadErrorKind::NonFinite;
    if !matches!(toks.len(), 3 | 4 | 6) {
        return Err(Problem::malformed(format!(
            "vertex {number} needs 3 coordinates"
        )));
    }
    let num = |tok: &str| {
        tok.parse::<f64>()
            .map_err(|_| Problem::malformed(format!("bad number {}", shown(tok))))
    };
    let mut c = [0.0; 3];
    for (x, tok) in c.iter_mut().zip(toks) {
        *x = num(tok)?;
        if !x.is_finite() {
            let tok = shown(tok);
            let why = format!(
                "vertex {number} has a non-finite coordinate ({})",
                tok.trim_matches('"')
            );
            return Err(Problem(NonFinite, why));
        }
    }
    if toks.len() == 4 {
        let w = num(toks[3])?;
        if w == 0.0 || !w.is_finite() {
            return Err(Problem(
                NonFinite,
                format!("vertex {number} has weight w = {w}"),
            ));
        }
        c = c.map(|x| x / w);
    }
    if c.iter().any(|x| !x.is_finite() || x.abs() > MAX_COORDINATE) {
        let why = format!("vertex {number} has a coordinate beyond ±{MAX_COORDINATE:e}");
        return Err(Problem(NonFinite, why));
    }
    Ok(c)
}

/// Parses one `v`, `v/vt`, `v//vn` or `v/vt/vn` token of face `face` when `defined` vertices
/// precede it; returns the vertex index as written (relative ones checked here, positive ones
/// by the caller).
fn parse_face_vertex(tok: &str, face: usize, defined: usize) -> Result<i64, Problem> {
    let bad = || Problem::malformed(format!("bad face vertex {}", shown(tok)));
    let mut parts = tok.split('/');
    let idx = parts
        .next()
        .unwrap_or("")
        .parse::<isize>()
        .map_err(|_| bad())? as i64;
    for (k, p) in parts.enumerate() {
        if k >= 2 || (!p.is_empty() && p.parse::<isize>().is_err()) {
            return Err(bad());
        }
    }
    if idx == 0 {
        let why = format!("face {face} uses vertex index 0 (OBJ indices start at 1)");
        return Err(Problem(LoadErrorKind::BadIndex, why));
    }
    if idx < 0 && idx.unsigned_abs() > defined as u64 {
        let why = format!(
            "face {face} uses relative vertex index {idx}, which reaches before the first \
             vertex ({defined} defined so far)"
        );
        return Err(Problem(LoadErrorKind::BadIndex, why));
    }
    Ok(idx)
}
