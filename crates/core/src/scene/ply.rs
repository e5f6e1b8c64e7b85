//! PLY files, ASCII or binary (either byte order), read with `ply-rs-bw`.
//!
//! The `vertex` element's `x`, `y`, `z` (any scalar type) are the vertices, and each `face`
//! element's `vertex_indices` (or `vertex_index`) list, of any length and integer type, is one
//! face. A `tristrips` element's lists (as Stanford's scans write them) are triangle strips,
//! each list one or more strips separated by −1: every three consecutive vertices of a strip
//! are a triangle, and those that repeat a vertex (the joins between strips) are dropped. Other
//! elements and properties (normals, colours, texture coordinates, edges) are read past and
//! ignored. The file is one object named after its stem. An element count larger than the
//! payload holds is an error, as is a face index outside the vertex list.

use std::io::BufReader;

use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{Encoding, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType};

use super::faces::Faces;
use super::input::{LoadError, LoadErrorKind, one_line};

/// A vertex: its coordinates, and which of them the file set.
#[derive(Default)]
struct Vertex {
    p: [f64; 3],
}

impl Vertex {
    fn set(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        let k = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return PropertyAccessResult::Ignored,
        };
        self.p[k] = value;
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Vertex::default()
    }
    fn set_char(&mut self, name: &str, v: i8) -> PropertyAccessResult {
        self.set(name, v.into())
    }
    fn set_uchar(&mut self, name: &str, v: u8) -> PropertyAccessResult {
        self.set(name, v.into())
    }
    fn set_short(&mut self, name: &str, v: i16) -> PropertyAccessResult {
        self.set(name, v.into())
    }
    fn set_ushort(&mut self, name: &str, v: u16) -> PropertyAccessResult {
        self.set(name, v.into())
    }
    fn set_int(&mut self, name: &str, v: i32) -> PropertyAccessResult {
        self.set(name, v.into())
    }
    fn set_uint(&mut self, name: &str, v: u32) -> PropertyAccessResult {
        self.set(name, v.into())
    }
    fn set_float(&mut self, name: &str, v: f32) -> PropertyAccessResult {
        self.set(name, v.into())
    }
    fn set_double(&mut self, name: &str, v: f64) -> PropertyAccessResult {
        self.set(name, v)
    }
}

/// A face: its vertex indices as written (negative ones kept to be reported).
#[derive(Default)]
struct Face {
    idx: Vec<i64>,
}

impl Face {
    fn set<T: Copy + Into<i64>>(&mut self, name: &str, v: &[T]) -> PropertyAccessResult {
        if !is_index_list(name) {
            return PropertyAccessResult::Ignored;
        }
        self.idx = v.iter().map(|&x| x.into()).collect();
        PropertyAccessResult::Set
    }
}

/// Whether a `face` or `tristrips` property named `name` holds the vertex indices.
fn is_index_list(name: &str) -> bool {
    matches!(name, "vertex_indices" | "vertex_index")
}

impl PropertyAccess for Face {
    fn new() -> Self {
        Face::default()
    }
    fn set_list_char(&mut self, name: &str, v: Vec<i8>) -> PropertyAccessResult {
        self.set(name, &v)
    }
    fn set_list_uchar(&mut self, name: &str, v: Vec<u8>) -> PropertyAccessResult {
        self.set(name, &v)
    }
    fn set_list_short(&mut self, name: &str, v: Vec<i16>) -> PropertyAccessResult {
        self.set(name, &v)
    }
    fn set_list_ushort(&mut self, name: &str, v: Vec<u16>) -> PropertyAccessResult {
        self.set(name, &v)
    }
    fn set_list_int(&mut self, name: &str, v: Vec<i32>) -> PropertyAccessResult {
        self.set(name, &v)
    }
    fn set_list_uint(&mut self, name: &str, v: Vec<u32>) -> PropertyAccessResult {
        self.set(name, &v)
    }
}

/// An element read past: nothing kept.
struct Skip;

impl PropertyAccess for Skip {
    fn new() -> Self {
        Skip
    }
}

/// Bytes of one value of a binary PLY.
fn scalar_size(t: &ScalarType) -> usize {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// The faces of the PLY file `bytes` named `file_name`.
pub(crate) fn read(file_name: &str, bytes: &[u8]) -> Result<Faces, LoadError> {
    let err = |kind, what: String| LoadError {
        file: file_name.to_string(),
        kind,
        problem: format!("not a valid PLY file ({what})"),
    };
    let malformed = |e: ply_rs_bw::parser::ParseError| {
        err(LoadErrorKind::Malformed, one_line(&e.to_string(), 200))
    };
    let mut reader = Reader::new(BufReader::new(bytes));
    let header = Parser::<Skip>::new()
        .read_header(&mut reader)
        .map_err(malformed)?;
    let Some(vdef) = header.elements.get("vertex") else {
        return Err(err(LoadErrorKind::Malformed, "no `vertex` element".into()));
    };
    for axis in ["x", "y", "z"] {
        match vdef.properties.get(axis).map(|p| &p.data_type) {
            Some(PropertyType::Scalar(_)) => {}
            _ => {
                let why = format!("the `vertex` element has no scalar property `{axis}`");
                return Err(err(LoadErrorKind::Malformed, why));
            }
        }
    }
    // Each element's smallest size against what is left: a count too large for the file is
    // reported before any of it is read.
    let payload = bytes.len().saturating_sub(header_len(bytes));
    let mut least = 0u128;
    for e in header.elements.values() {
        let each: usize = match header.encoding {
            // An ASCII element is a line of at least one value and a line break.
            Encoding::Ascii => 2,
            _ => e
                .properties
                .values()
                .map(|p| match &p.data_type {
                    PropertyType::Scalar(t) => scalar_size(t),
                    PropertyType::List(n, _) => scalar_size(n),
                })
                .sum(),
        };
        least += e.count as u128 * each as u128;
        if least > payload as u128 {
            let why = format!(
                "the header says {} `{}` elements, more than the {} bytes after it can hold",
                e.count, e.name, payload
            );
            return Err(err(LoadErrorKind::Malformed, why));
        }
    }
    let mut coords: Vec<[f64; 3]> = Vec::new();
    let mut lists: Vec<Vec<i64>> = Vec::new();
    let mut has_faces = false;
    let mut strips: Vec<Vec<i64>> = Vec::new();
    for (name, e) in &header.elements {
        match name.as_str() {
            "vertex" => {
                let vs = Parser::<Vertex>::new()
                    .read_payload_for_element(&mut reader, e, &header)
                    .map_err(malformed)?;
                coords = vs.into_iter().map(|v| v.p).collect();
            }
            "face" | "tristrips" if e.properties.keys().any(|k| is_index_list(k)) => {
                has_faces = true;
                let fs = Parser::<Face>::new()
                    .read_payload_for_element(&mut reader, e, &header)
                    .map_err(malformed)?;
                let idx = fs.into_iter().map(|f| f.idx).collect();
                if name == "face" {
                    lists = idx;
                } else {
                    strips = idx;
                }
            }
            _ => {
                Parser::<Skip>::new()
                    .read_payload_for_element(&mut reader, e, &header)
                    .map_err(malformed)?;
            }
        }
    }
    let mut faces = Faces::new();
    if !has_faces {
        return Ok(faces);
    }
    let stem = super::faces::stem(file_name);
    let object = faces.object(&stem);
    faces.coords = coords;
    let n = faces.coords.len();
    for (k, list) in lists.iter().enumerate() {
        if let Some(&bad) = list.iter().find(|&&i| i < 0 || i as u64 >= n as u64) {
            return Err(bad_index(file_name, &format!("face {}", k + 1), bad, n));
        }
        faces.face(list.iter().map(|&i| i as u32), object);
    }
    for (k, list) in strips.iter().enumerate() {
        if let Some(&bad) = list
            .iter()
            .find(|&&i| i < -1 || (i >= 0 && i as u64 >= n as u64))
        {
            let what = format!("triangle strip list {}", k + 1);
            return Err(bad_index(file_name, &what, bad, n));
        }
        for strip in list.split(|&i| i == -1) {
            for (t, w) in strip.windows(3).enumerate() {
                if w[0] == w[1] || w[1] == w[2] || w[0] == w[2] {
                    continue;
                }
                // Every other triangle of a strip turns the other way: swap two to keep the
                // winding.
                let tri = if t % 2 == 0 {
                    [w[0], w[1], w[2]]
                } else {
                    [w[1], w[0], w[2]]
                };
                faces.face(tri.iter().map(|&i| i as u32), object);
            }
        }
    }
    Ok(faces)
}

/// The error of `what` (a face, a strip list) naming vertex `bad` of a file with `n`.
fn bad_index(file_name: &str, what: &str, bad: i64, n: usize) -> LoadError {
    LoadError {
        file: file_name.to_string(),
        kind: LoadErrorKind::BadIndex,
        problem: format!("{what} refers to vertex {bad} but the file has {n} vertices"),
    }
}

/// Bytes of the header: up to and including the line break after `end_header` (the whole file
/// when there is none, which the parser then reports).
fn header_len(bytes: &[u8]) -> usize {
    let key = b"end_header";
    let Some(at) = bytes.windows(key.len()).position(|w| w == key) else {
        return bytes.len();
    };
    let rest = &bytes[at + key.len()..];
    let nl = rest
        .iter()
        .position(|&b| b == b'\n')
        .map_or(rest.len(), |p| p + 1);
    at + key.len() + nl
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment x\nelement vertex 5\nproperty float x\n\
                         property float y\nproperty double z\nproperty uchar red\n\
                         element face 2\nproperty list uchar int vertex_indices\nend_header\n\
                         0 0 0 1\n1 0 0 1\n1 1 0 1\n0 1 0 1\n0 0 1 1\n4 0 1 2 3\n3 0 1 4\n";

    #[test]
    fn ascii_faces_of_any_size() {
        let f = read("q.ply", ASCII.as_bytes()).unwrap();
        assert_eq!((f.coords.len(), f.len()), (5, 2));
        let sizes: Vec<usize> = f.faces().map(|(v, _)| v.len()).collect();
        assert_eq!(sizes, [4, 3]);
    }

    #[test]
    fn binary_big_and_little_endian() {
        for (fmt, be) in [("binary_little_endian", false), ("binary_big_endian", true)] {
            let mut b = format!(
                "ply\nformat {fmt} 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                 property float z\nelement face 1\nproperty list uchar uint vertex_index\n\
                 end_header\n"
            )
            .into_bytes();
            for p in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0]] {
                for x in p {
                    b.extend(if be { x.to_be_bytes() } else { x.to_le_bytes() });
                }
            }
            b.push(3);
            for i in [0u32, 1, 2] {
                b.extend(if be { i.to_be_bytes() } else { i.to_le_bytes() });
            }
            let f = read("t.ply", &b).unwrap();
            assert_eq!(f.coords[2], [0.0, 2.0, 0.0], "{fmt}");
            assert_eq!(f.len(), 1);
        }
    }

    #[test]
    fn wrong_counts_and_indices_are_one_line_errors() {
        let more = ASCII.replace("element face 2", "element face 20");
        let e = read("q.ply", more.as_bytes()).unwrap_err();
        assert!(e.problem.starts_with("not a valid PLY file ("), "{e}");
        assert!(!e.to_string().contains('\n'));
        let huge = ASCII.replace("element vertex 5", "element vertex 4000000000");
        let e = read("q.ply", huge.as_bytes()).unwrap_err();
        assert!(e.problem.contains("4000000000 `vertex` elements"), "{e}");
        let bad = ASCII.replace("3 0 1 4\n", "3 0 1 7\n");
        let e = read("q.ply", bad.as_bytes()).unwrap_err();
        assert_eq!(
            e.problem,
            "face 2 refers to vertex 7 but the file has 5 vertices"
        );
        let e = read("q.ply", b"ply\nformat ascii 1.0\n").unwrap_err();
        assert!(e.problem.starts_with("not a valid PLY file ("), "{e}");
    }

    const STRIPS: &str = "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\n\
                          property float y\nproperty float z\nelement tristrips 1\n\
                          property list int int vertex_indices\nend_header\n\
                          0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 2 0\n1 2 0\n\
                          9 0 1 2 3 3 4 -1 4 5\n";

    #[test]
    fn triangle_strips_split_at_minus_one_and_drop_joins() {
        let f = read("s.ply", STRIPS.as_bytes()).unwrap();
        let tris: Vec<Vec<u32>> = f.faces().map(|(v, _)| v.to_vec()).collect();
        // 0 1 2 3 3 4: (0 1 2), (2 1 3) turned back, then (2 3 3) and (3 3 4) repeat a vertex;
        // -1 ends the strip, and 4 5 alone is no triangle.
        assert_eq!(tris, [vec![0, 1, 2], vec![2, 1, 3]]);
        let bad = STRIPS.replace("-1 4 5", "-1 4 6");
        let e = read("s.ply", bad.as_bytes()).unwrap_err();
        assert_eq!(
            e.problem,
            "triangle strip list 1 refers to vertex 6 but the file has 6 vertices"
        );
        let neg = STRIPS.replace("-1 4 5", "-2 4 5");
        let e = read("s.ply", neg.as_bytes()).unwrap_err();
        assert!(e.problem.contains("vertex -2"), "{e}");
    }
}
