//! OFF files (Object File Format: Geomview's, as CGAL, the Princeton Shape Benchmark and
//! ModelNet write them), ASCII.
//!
//! The first word is `OFF`, optionally with the prefixes that add per-vertex data (`ST`, `C`,
//! `N`: texture coordinates, colours, normals; `STCNOFF` at most), and may be followed on its
//! line by the counts; otherwise the counts (vertices, faces, edges) are the next line. Then
//! one vertex a line (its first three numbers; what follows is the prefixes' data, ignored)
//! and one face a line (its vertex count k, then k vertex indices from 0; what follows, a
//! colour, is ignored). `#` starts a comment to the end of its line; blank lines are skipped.
//! The file is one object named after its stem. 4-D and n-D files (`4OFF`, `nOFF`) and binary
//! ones (`OFF BINARY`) are not read. Fewer lines than the counts say, a word that is not a
//! number and a face index outside the vertices are errors naming the line.

use super::faces::Faces;
use super::input::{LoadError, LoadErrorKind};

/// The faces of the OFF file `bytes` named `file_name`.
pub(crate) fn read(file_name: &str, bytes: &[u8]) -> Result<Faces, LoadError> {
    let err = |kind, what: String| LoadError {
        file: file_name.to_string(),
        kind,
        problem: format!("not a valid OFF file ({what})"),
    };
    let malformed = |what: String| err(LoadErrorKind::Malformed, what);
    let text = std::str::from_utf8(bytes)
        .map_err(|_| malformed("not text: binary OFF files are not read".into()))?;
    // (line number from 1, its words), comments and blank lines left out.
    let mut lines = text.lines().enumerate().filter_map(|(i, l)| {
        let l = l.split('#').next().unwrap_or_default();
        let words: Vec<&str> = l.split_whitespace().collect();
        (!words.is_empty()).then_some((i + 1, words))
    });
    let Some((at, head)) = lines.next() else {
        return Err(malformed("empty".into()));
    };
    let keyword = head[0];
    let Some(prefix) = keyword.strip_suffix("OFF") else {
        return Err(malformed(format!(
            "line {at}: it begins with {keyword:?}, not OFF"
        )));
    };
    if prefix.contains('4') || prefix.contains('n') {
        return Err(err(
            LoadErrorKind::Unsupported,
            format!("line {at}: {keyword} is not 3-D; only 3-D OFF files are read"),
        ));
    }
    if !is_prefix(prefix) {
        return Err(malformed(format!("line {at}: unknown keyword {keyword:?}")));
    }
    if head.get(1) == Some(&"BINARY") {
        return Err(err(
            LoadErrorKind::Unsupported,
            "binary OFF files are not read".into(),
        ));
    }
    let (at, counts) = if head.len() > 1 {
        (at, head[1..].to_vec())
    } else {
        lines
            .next()
            .ok_or_else(|| malformed("no counts after the keyword".into()))?
    };
    let count = |k: usize, what: &str| -> Result<usize, LoadError> {
        let w = counts
            .get(k)
            .ok_or_else(|| malformed(format!("line {at}: no {what} count")))?;
        w.parse()
            .map_err(|_| malformed(format!("line {at}: the {what} count {w:?} is not a count")))
    };
    let (nv, nf) = (count(0, "vertex")?, count(1, "face")?);
    let stem = super::faces::stem(file_name);
    let mut faces = Faces::new();
    let object = faces.object(&stem);
    let truncated = |what: &str, got: usize| {
        malformed(format!(
            "truncated: the counts say {nv} vertices and {nf} faces, the file ends after \
             {got} {what}"
        ))
    };
    let number = |at: usize, w: &str| -> Result<f64, LoadError> {
        w.parse()
            .map_err(|_| malformed(format!("line {at}: {w:?} is not a number")))
    };
    for v in 0..nv {
        let (at, words) = lines.next().ok_or_else(|| truncated("vertices", v))?;
        if words.len() < 3 {
            return Err(malformed(format!(
                "line {at}: a vertex needs three coordinates, it has {}",
                words.len()
            )));
        }
        faces.vertex([
            number(at, words[0])?,
            number(at, words[1])?,
            number(at, words[2])?,
        ]);
    }
    let mut verts = Vec::new();
    for f in 0..nf {
        let (at, words) = lines.next().ok_or_else(|| truncated("faces", f))?;
        let k: usize = words[0].parse().map_err(|_| {
            malformed(format!(
                "line {at}: a face begins with its vertex count, not {:?}",
                words[0]
            ))
        })?;
        // `words` holds the count itself, so `len() - 1` cannot underflow, where `1 + k` could
        // overflow.
        if words.len() - 1 < k {
            return Err(malformed(format!(
                "line {at}: a face of {k} vertices lists {}",
                words.len() - 1
            )));
        }
        verts.clear();
        for w in &words[1..=k] {
            let i: usize = w.parse().map_err(|_| {
                malformed(format!("line {at}: the vertex index {w:?} is not an index"))
            })?;
            if i >= nv {
                return Err(err(
                    LoadErrorKind::BadIndex,
                    format!("line {at}: vertex {i} of a face, of {nv} vertices"),
                ));
            }
            verts.push(i as u32);
        }
        faces.face(verts.iter().copied(), object);
    }
    Ok(faces)
}

/// Whether `p` is a valid prefix of `OFF` in a 3-D file: `ST`, `C` and `N`, each at most once,
/// in that order.
fn is_prefix(p: &str) -> bool {
    let p = p.strip_prefix("ST").unwrap_or(p);
    let p = p.strip_prefix('C').unwrap_or(p);
    let p = p.strip_prefix('N').unwrap_or(p);
    p.is_empty()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube: 8 vertices, 6 quads.
    const CUBE: &str = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n\
                        4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 3 0 4 7\n";

    fn problem(bytes: &[u8]) -> (LoadErrorKind, String) {
        let e = read("x.off", bytes).map(|_| ()).unwrap_err();
        assert_eq!(e.file, "x.off");
        assert_eq!(e.problem.lines().count(), 1, "{}", e.problem);
        (e.kind, e.problem)
    }

    #[test]
    fn headers_comments_and_per_vertex_data_are_read() {
        for text in [
            format!("OFF\n8 6 12\n{CUBE}"),
            format!("# a cube\nOFF 8 6 0 # counts here\n\n{CUBE}"),
            // Colours after the coordinates and after the faces are ignored.
            format!(
                "COFF\n8 6 12\n{}",
                CUBE.lines()
                    .map(|l| format!("{l} 0.5 0.5 0.5 1\n"))
                    .collect::<String>()
            ),
            format!("STCNOFF\n8 6 12\n{CUBE}"),
            format!("OFF\r\n8 6 12\r\n{}", CUBE.replace('\n', "\r\n")),
        ] {
            let faces = read("cube.off", text.as_bytes()).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(faces.len(), 6, "{text}");
            let all: Vec<(&[u32], u32)> = faces.faces().collect();
            assert_eq!(all[0].0, &[0, 3, 2, 1]);
            assert!(all.iter().all(|(v, o)| v.len() == 4 && *o == 0));
        }
    }

    #[test]
    fn bad_files_are_one_error_naming_the_line() {
        let cases = [
            (
                "PLY\n1 0 0\n",
                LoadErrorKind::Malformed,
                "line 1: it begins with \"PLY\", not OFF",
            ),
            (
                "XOFF\n",
                LoadErrorKind::Malformed,
                "unknown keyword \"XOFF\"",
            ),
            (
                "4OFF\n1 0 0\n",
                LoadErrorKind::Unsupported,
                "4OFF is not 3-D",
            ),
            ("nOFF\n4\n", LoadErrorKind::Unsupported, "nOFF is not 3-D"),
            (
                "OFF BINARY\n",
                LoadErrorKind::Unsupported,
                "binary OFF files are not read",
            ),
            ("", LoadErrorKind::Malformed, "empty"),
            (
                "OFF\n",
                LoadErrorKind::Malformed,
                "no counts after the keyword",
            ),
            (
                "OFF\n8\n",
                LoadErrorKind::Malformed,
                "line 2: no face count",
            ),
            (
                "OFF\n8 x\n",
                LoadErrorKind::Malformed,
                "the face count \"x\" is not a count",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n",
                LoadErrorKind::Malformed,
                "truncated: the counts say 3 vertices and 1 faces, the file ends after 2 vertices",
            ),
            (
                "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                LoadErrorKind::Malformed,
                "the file ends after 1 faces",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n",
                LoadErrorKind::Malformed,
                "line 4: \"zero\" is not a number",
            ),
            (
                "OFF\n3 1 0\n0 0\n",
                LoadErrorKind::Malformed,
                "line 3: a vertex needs three coordinates, it has 2",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
                LoadErrorKind::BadIndex,
                "line 6: vertex 3 of a face, of 3 vertices",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n",
                LoadErrorKind::Malformed,
                "a face of 4 vertices lists 3",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n18446744073709551615 0 1 2\n",
                LoadErrorKind::Malformed,
                "a face of 18446744073709551615 vertices lists 3",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n",
                LoadErrorKind::Malformed,
                "the vertex index \"-1\" is not an index",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\nthree 0 1 2\n",
                LoadErrorKind::Malformed,
                "a face begins with its vertex count",
            ),
        ];
        for (text, kind, want) in cases {
            let (k, p) = problem(text.as_bytes());
            assert_eq!(k, kind, "{text:?}: {p}");
            assert!(p.contains(want), "{text:?}: {p:?} lacks {want:?}");
        }
        let (k, p) = problem(b"OFF\n\xff\xfe\n");
        assert_eq!(k, LoadErrorKind::Malformed);
        assert!(p.contains("not text"), "{p}");
        // A count far beyond the file allocates nothing ahead: the file ends first.
        let (_, p) = problem(b"OFF\n4000000000 1 0\n0 0 0\n");
        assert!(p.contains("ends after 1 vertices"), "{p}");
    }
}
