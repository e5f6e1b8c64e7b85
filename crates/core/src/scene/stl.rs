//! STL files, binary or ASCII, read with `stl_io`.
//!
//! A file is binary when its size is exactly 84 + 50 × the triangle count in its header (also
//! when its 80-byte header begins with `solid`, as many exporters write), ASCII when it begins
//! with `solid` and is text, and binary otherwise: then a file shorter than its header's count
//! says is an error naming both. An ASCII file may hold several `solid … endsolid` blocks: each is one
//! object, named after its solid. Every triangle is one face (its three vertices as written);
//! the facet normals are not used.

use std::io::Cursor;

use super::faces::Faces;
use super::input::{LoadError, LoadErrorKind, one_line};

/// Bytes of a binary STL's header: 80 free bytes and the triangle count.
const HEADER: usize = 84;
/// Bytes per triangle of a binary STL.
const RECORD: usize = 50;

/// The faces of the STL file `bytes` named `file_name`.
pub(crate) fn read(file_name: &str, bytes: &[u8]) -> Result<Faces, LoadError> {
    let err = |kind, what: String| LoadError {
        file: file_name.to_string(),
        kind,
        problem: format!("not a valid STL file ({what})"),
    };
    let stem = super::faces::stem(file_name);
    let count = (bytes.len() >= HEADER)
        .then(|| u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize);
    let exact_binary = count.is_some_and(|n| {
        n.checked_mul(RECORD)
            .and_then(|b| b.checked_add(HEADER))
            .is_some_and(|size| size == bytes.len())
    });
    // A binary file whose header begins with `solid` but whose size is off (truncated) is
    // not text: binary data is practically never valid UTF-8.
    let ascii = !exact_binary && starts_with_solid(bytes) && std::str::from_utf8(bytes).is_ok();
    let mut faces = Faces::new();
    if ascii {
        read_ascii(bytes, &stem, &mut faces).map_err(|e| err(LoadErrorKind::Malformed, e))?;
        return Ok(faces);
    }
    let Some(n) = count else {
        let why = format!(
            "{} bytes: shorter than the {HEADER}-byte header of a binary STL, and not ASCII STL",
            bytes.len()
        );
        return Err(err(LoadErrorKind::Malformed, why));
    };
    let holds = (bytes.len() - HEADER) / RECORD;
    if holds < n {
        let why = format!(
            "truncated: the header says {n} triangles, the file holds {holds} \
             ({} bytes, {} needed)",
            bytes.len(),
            HEADER as u64 + RECORD as u64 * n as u64
        );
        return Err(err(LoadErrorKind::Malformed, why));
    }
    // stl_io tells ASCII from binary by a leading `solid `: blank it in a binary header.
    let mut data = bytes[..HEADER + RECORD * n].to_vec();
    data[..5].copy_from_slice(b"     ");
    let object = faces.object(&stem);
    triangles(&data, object, &mut faces).map_err(|e| err(LoadErrorKind::Malformed, e))?;
    Ok(faces)
}

/// Whether `bytes` begin (after blanks) with the word `solid`.
fn starts_with_solid(bytes: &[u8]) -> bool {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(bytes.len());
    let rest = &bytes[start..];
    rest.starts_with(b"solid") && rest.get(5).is_none_or(|b| b.is_ascii_whitespace())
}

/// Appends the triangles `stl_io` reads from `data` to `faces` as object `object`.
fn triangles(data: &[u8], object: u32, faces: &mut Faces) -> Result<(), String> {
    let mut cursor = Cursor::new(data);
    let reader =
        stl_io::create_stl_reader(&mut cursor).map_err(|e| one_line(&e.to_string(), 160))?;
    for t in reader {
        let t = t.map_err(|e| one_line(&e.to_string(), 160))?;
        let v = t.vertices.map(|p| faces.vertex(p.0.map(f64::from)));
        faces.face(v, object);
    }
    Ok(())
}

/// Reads every `solid … endsolid` block of the ASCII STL `bytes`, each one object.
fn read_ascii(bytes: &[u8], stem: &str, faces: &mut Faces) -> Result<(), String> {
    let text = super::utf8_text(bytes).map_err(|line| format!("line {line}: not ASCII text"))?;
    let mut lines = text.lines().enumerate();
    let mut solids = 0;
    // Each `solid` line; blank lines between solids are skipped.
    while let Some((at, first)) = lines.find(|(_, l)| !l.trim().is_empty()) {
        let mut words = first.split_whitespace();
        if words.next() != Some("solid") {
            return Err(format!(
                "line {}: expected `solid`, found {:?}",
                at + 1,
                one_line(first, 40)
            ));
        }
        let name: Vec<&str> = words.collect();
        let name = if name.is_empty() {
            stem.to_string()
        } else {
            name.join(" ")
        };
        // The block for stl_io: a `solid` line it accepts, then the lines up to `endsolid`.
        let mut block = String::from("solid x\n");
        let mut ended = false;
        for (_, l) in lines.by_ref() {
            block.push_str(l);
            block.push('\n');
            if l.split_whitespace().next() == Some("endsolid") {
                ended = true;
                break;
            }
        }
        if !ended {
            block.push_str("endsolid\n");
        }
        let object = faces.object(&name);
        triangles(block.as_bytes(), object, faces)
            .map_err(|e| format!("solid {} (line {}): {e}", solids + 1, at + 1))?;
        solids += 1;
    }
    if solids == 0 {
        return Err("no `solid`".to_string());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn binary(tris: &[[[f32; 3]; 3]], header: &[u8]) -> Vec<u8> {
        let mut b = vec![b' '; 80];
        b[..header.len()].copy_from_slice(header);
        b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
        for t in tris {
            b.extend_from_slice(&[0u8; 12]);
            for p in t {
                for x in p {
                    b.extend_from_slice(&x.to_le_bytes());
                }
            }
            b.extend_from_slice(&[0, 0]);
        }
        b
    }

    const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    #[test]
    fn binary_files_load_even_with_a_solid_header() {
        for header in [&b"binary"[..], b"solid made by a CAD tool"] {
            let f = read("part.stl", &binary(&[TRI, TRI], header)).unwrap();
            assert_eq!((f.len(), f.coords.len()), (2, 6));
            assert_eq!(f.names, ["part"]);
        }
    }

    #[test]
    fn a_truncated_binary_file_is_one_error_line() {
        let mut b = binary(&[TRI, TRI, TRI], b"x");
        b.truncate(b.len() - 30);
        let e = read("part.stl", &b).unwrap_err();
        assert_eq!(
            e.to_string(),
            "part.stl: not a valid STL file (truncated: the header says 3 triangles, the file \
             holds 2 (204 bytes, 234 needed))"
        );
        let e = read("tiny.stl", b"abc").unwrap_err();
        assert!(e.problem.contains("shorter than the 84-byte header"), "{e}");
    }

    #[test]
    fn ascii_solids_are_objects() {
        let facet = "facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  \
                     vertex 0 1 0\n endloop\nendfacet\n";
        let text = format!("solid a b\n{facet}{facet}endsolid a b\nsolid\n{facet}endsolid\n");
        let f = read("two.stl", text.as_bytes()).unwrap();
        assert_eq!(f.len(), 3);
        assert_eq!(f.names, ["a b", "two"]);
        let bad = format!("solid a\n{facet}facet normal 0 0\nendsolid\n");
        let e = read("bad.stl", bad.as_bytes()).unwrap_err();
        assert!(
            e.problem
                .starts_with("not a valid STL file (solid 1 (line 1): "),
            "{e}"
        );
        assert!(!e.to_string().contains('\n'));
    }
}
