//! glTF 2.0 files, `.gltf` (JSON) or `.glb` (binary), read with the `gltf` crate.
//!
//! The document is parsed and validated by `gltf`; the buffers are read here: a GLB's `BIN`
//! chunk, `data:` URIs (base64), and files next to the `.gltf` (`Box0.bin`; such a file is then
//! embedded in recordings as the OBJ of the scene, `export.rs`). Every mesh primitive of
//! the default scene (the first scene when none is named default, every root node when there
//! is no scene) is read in the node's world transform (matrix or TRS, composed in `f64`):
//! triangle lists, strips and fans become triangles; points and lines are skipped with one
//! warning. Each node with a mesh is one object, named after the node (or its mesh).
//!
//! Accessors are read by our own bounds-checked code (any byte stride, sparse substitution,
//! `u8`/`u16`/`u32` indices, `f32` positions): a view or accessor reaching past its buffer, an
//! index past the positions, a required extension (Draco or meshopt compression) or quantized
//! positions give one error line. glTF is Y-up: [`super::Up::Y`] is its default.

use std::path::Path;

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::buffer::Source;
use ::gltf::mesh::{Mode, Semantic};
use ::gltf::scene::Transform;
use base64::Engine;
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use super::faces::{Affine, Faces};
use super::input::{LoadError, LoadErrorKind, one_line, read_file};

/// What [`read`] found.
#[derive(Debug)]
pub(crate) struct Read {
    /// The faces in world coordinates (not turned to Z-up).
    pub faces: Faces,
    /// Whether a buffer is a separate file (the source must then be converted to embed it).
    pub external: bool,
    /// One line per kind of thing skipped, naming the file.
    pub warnings: Vec<String>,
}

/// A problem with its kind.
type Problem = (LoadErrorKind, String);

fn malformed(what: impl Into<String>) -> Problem {
    (LoadErrorKind::Malformed, what.into())
}

/// The faces of the glTF or GLB file `bytes` named `file_name`, whose external buffers are in
/// `dir` (`None`: it may have none).
pub(crate) fn read(file_name: &str, bytes: &[u8], dir: Option<&Path>) -> Result<Read, LoadError> {
    read_doc(file_name, bytes, dir).map_err(|(kind, problem)| LoadError {
        file: file_name.to_string(),
        kind,
        problem,
    })
}

fn read_doc(file_name: &str, bytes: &[u8], dir: Option<&Path>) -> Result<Read, Problem> {
    let not_gltf = |e: &dyn std::fmt::Display| {
        malformed(format!(
            "not a valid glTF file ({})",
            one_line(&e.to_string(), 200)
        ))
    };
    if bytes.starts_with(b"glTF") {
        // The declared length must cover at least the 12-byte header (`gltf` subtracts it).
        let declared = bytes
            .get(8..12)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
        if declared.is_none_or(|n| n < 12) {
            return Err(not_gltf(&"GLB header too short"));
        }
    }
    let raw = ::gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| not_gltf(&e))?;
    // gltf-json's validation indexes the accessors by each POSITION before checking the index
    // (and panics on a bad one): check those first.
    let json = raw.document.into_json();
    let accessors = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (k, p) in mesh.primitives.iter().enumerate() {
            let pos = p.attributes.get(&::gltf::json::validation::Checked::Valid(
                Semantic::Positions,
            ));
            if let Some(i) = pos.filter(|i| i.value() >= accessors) {
                return Err(malformed(format!(
                    "mesh {m} primitive {k}: POSITION is accessor {}, which does not exist",
                    i.value()
                )));
            }
        }
    }
    let doc = ::gltf::Gltf {
        document: ::gltf::Document::from_json(json).map_err(|e| not_gltf(&e))?,
        blob: raw.blob,
    };
    if let Some(ext) = doc.extensions_required().next() {
        return Err((
            LoadErrorKind::Unsupported,
            format!("requires the glTF extension {ext}, which wraptree does not read"),
        ));
    }
    let mut external = false;
    let mut buffers = Vec::new();
    for b in doc.buffers() {
        let data = match b.source() {
            Source::Bin => doc.blob.clone().ok_or_else(|| {
                malformed(format!(
                    "buffer {} is the GLB's BIN chunk, which is missing",
                    b.index()
                ))
            })?,
            Source::Uri(uri) => {
                if let Some(data) = uri.strip_prefix("data:") {
                    let (_, payload) = data.split_once(";base64,").ok_or_else(|| {
                        malformed(format!(
                            "buffer {}: a data URI that is not base64",
                            b.index()
                        ))
                    })?;
                    base64::engine::general_purpose::STANDARD
                        .decode(payload)
                        .map_err(|e| malformed(format!("buffer {}: bad base64 ({e})", b.index())))?
                } else {
                    external = true;
                    let Some(dir) = dir else {
                        return Err((
                            LoadErrorKind::Read,
                            format!(
                                "buffer {} is the separate file {uri:?}: load the .gltf from its \
                                 folder",
                                b.index()
                            ),
                        ));
                    };
                    if uri.contains("://") {
                        return Err((
                            LoadErrorKind::Unsupported,
                            format!("buffer {} is the remote {uri:?}: not read", b.index()),
                        ));
                    }
                    let path = dir.join(percent_decoded(uri));
                    read_file(&path).map_err(|e| {
                        (
                            LoadErrorKind::Read,
                            format!("buffer {} ({}): {e}", b.index(), path.display()),
                        )
                    })?
                }
            }
        };
        if data.len() < b.length() {
            return Err(malformed(format!(
                "buffer {} has {} bytes, the glTF says {}",
                b.index(),
                data.len(),
                b.length()
            )));
        }
        buffers.push(data);
    }
    let mut faces = Faces::new();
    let mut skipped = 0usize;
    // The roots: the default scene's, the first scene's, or every node no node has as a child.
    let roots: Vec<::gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        None => {
            let mut child = vec![false; doc.nodes().len()];
            for n in doc.nodes() {
                for c in n.children() {
                    child[c.index()] = true;
                }
            }
            doc.nodes().filter(|n| !child[n.index()]).collect()
        }
    };
    let mut seen = vec![false; doc.nodes().len()];
    let mut stack: Vec<(::gltf::Node, Affine)> = roots
        .into_iter()
        .rev()
        .map(|n| (n, Affine::IDENTITY))
        .collect();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut seen[node.index()], true) {
            return Err(malformed(format!(
                "node {} is reached twice from the scene (two parents or a loop)",
                node.index()
            )));
        }
        let world = parent.then_apply(&local(&node.transform()));
        if !world.is_finite() {
            return Err((
                LoadErrorKind::NonFinite,
                format!("node {} has a non-finite transform", node.index()),
            ));
        }
        if let Some(mesh) = node.mesh() {
            let name = node
                .name()
                .or(mesh.name())
                .map(str::to_string)
                .unwrap_or_else(|| format!("node{}", node.index()));
            let object = faces.object(&name);
            for (k, prim) in mesh.primitives().enumerate() {
                let at = || format!("mesh {} primitive {k}", mesh.index());
                if matches!(
                    prim.mode(),
                    Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip
                ) {
                    skipped += 1;
                    continue;
                }
                let Some(pos) = prim.get(&Semantic::Positions) else {
                    return Err(malformed(format!("{} has no POSITION", at())));
                };
                if pos.dimensions() != Dimensions::Vec3 || pos.data_type() != DataType::F32 {
                    return Err((
                        LoadErrorKind::Unsupported,
                        format!("{}: positions are not 3 × f32 (quantized?)", at()),
                    ));
                }
                let raw = read_accessor(&pos, &buffers)
                    .map_err(|e| malformed(format!("{}: {e}", at())))?;
                let base = faces.coords.len() as u32;
                for c in raw.chunks_exact(3) {
                    faces.vertex(world.apply([c[0], c[1], c[2]]));
                }
                let n = pos.count();
                let indices: Vec<u32> = match prim.indices() {
                    Some(acc) => {
                        if acc.dimensions() != Dimensions::Scalar
                            || !matches!(
                                acc.data_type(),
                                DataType::U8 | DataType::U16 | DataType::U32
                            )
                        {
                            return Err(malformed(format!("{}: indices are not u8/u16/u32", at())));
                        }
                        let idx = read_accessor(&acc, &buffers)
                            .map_err(|e| malformed(format!("{}: {e}", at())))?;
                        let mut out = Vec::with_capacity(idx.len());
                        for i in idx {
                            if i >= n as f64 {
                                return Err((
                                    LoadErrorKind::BadIndex,
                                    format!("{}: index {i} but {n} positions", at()),
                                ));
                            }
                            out.push(i as u32);
                        }
                        out
                    }
                    None => (0..n as u32).collect(),
                };
                for t in triangles(prim.mode(), &indices) {
                    faces.face(t.map(|i| base + i), object);
                }
            }
        }
        for c in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((c, world));
        }
    }
    let mut warnings = Vec::new();
    if skipped > 0 {
        warnings.push(format!(
            "{file_name}: skipped {skipped} mesh primitives of points or lines"
        ));
    }
    Ok(Read {
        faces,
        external,
        warnings,
    })
}

/// The triangles of a primitive of `mode` with `indices` (a list's leftover indices dropped).
fn triangles(mode: Mode, indices: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        Mode::TriangleStrip => (2..indices.len())
            .map(|k| {
                let (a, b, c) = (indices[k - 2], indices[k - 1], indices[k]);
                if k % 2 == 0 { [a, b, c] } else { [b, a, c] }
            })
            .collect(),
        Mode::TriangleFan => (2..indices.len())
            .map(|k| [indices[0], indices[k - 1], indices[k]])
            .collect(),
        _ => indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
    }
}

/// A node's local transform in `f64`.
fn local(t: &Transform) -> Affine {
    match t {
        Transform::Matrix { matrix: m } => {
            // Column-major: m[column][row].
            let c = |col: usize, row: usize| f64::from(m[col][row]);
            Affine {
                m: Matrix3::new(
                    c(0, 0),
                    c(1, 0),
                    c(2, 0),
                    c(0, 1),
                    c(1, 1),
                    c(2, 1),
                    c(0, 2),
                    c(1, 2),
                    c(2, 2),
                ),
                t: Vector3::new(c(3, 0), c(3, 1), c(3, 2)),
            }
        }
        Transform::Decomposed {
            translation: tr,
            rotation: r,
            scale: s,
        } => {
            let q = Quaternion::new(
                f64::from(r[3]),
                f64::from(r[0]),
                f64::from(r[1]),
                f64::from(r[2]),
            );
            let rot = if q.norm() > 0.0 {
                UnitQuaternion::from_quaternion(q)
                    .to_rotation_matrix()
                    .into_inner()
            } else {
                Matrix3::identity()
            };
            let scale = Matrix3::from_diagonal(&Vector3::new(
                f64::from(s[0]),
                f64::from(s[1]),
                f64::from(s[2]),
            ));
            Affine {
                m: rot * scale,
                t: Vector3::new(f64::from(tr[0]), f64::from(tr[1]), f64::from(tr[2])),
            }
        }
    }
}

/// `%XX` escapes of a URI decoded (invalid ones kept as written).
fn percent_decoded(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%'
            && let (Some(h), Some(l)) = (
                b.get(i + 1).and_then(|&c| hex(c)),
                b.get(i + 2).and_then(|&c| hex(c)),
            )
        {
            out.push((h * 16 + l) as u8);
            i += 3;
            continue;
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Bytes of one component.
fn component_size(t: DataType) -> usize {
    match t {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

/// One component at the start of `b`, as `f64`.
fn component(t: DataType, b: &[u8]) -> f64 {
    match t {
        DataType::I8 => f64::from(b[0] as i8),
        DataType::U8 => f64::from(b[0]),
        DataType::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
        DataType::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
        DataType::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        DataType::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
    }
}

/// The bytes of a buffer view, checked against its buffer.
fn view_bytes<'b>(view: &::gltf::buffer::View, buffers: &'b [Vec<u8>]) -> Result<&'b [u8], String> {
    let buf = &buffers[view.buffer().index()];
    view.offset()
        .checked_add(view.length())
        .and_then(|end| buf.get(view.offset()..end))
        .ok_or_else(|| {
            format!(
                "buffer view {} reaches past its buffer ({} bytes)",
                view.index(),
                buf.len()
            )
        })
}

/// Every component of `count` elements of `comps` components of type `t`, read from `data`
/// at `offset` with `stride` (0: tightly packed). Err: past the end of `data`.
fn elements(
    data: &[u8],
    offset: usize,
    stride: usize,
    count: usize,
    comps: usize,
    t: DataType,
) -> Result<Vec<f64>, String> {
    let size = component_size(t);
    let elem = size * comps;
    let stride = if stride == 0 { elem } else { stride };
    if stride < elem {
        return Err(format!(
            "byte stride {stride} is less than the element's {elem} bytes"
        ));
    }
    if count == 0 {
        return Ok(Vec::new());
    }
    let end = (count - 1)
        .checked_mul(stride)
        .and_then(|x| x.checked_add(offset))
        .and_then(|x| x.checked_add(elem));
    if end.is_none_or(|e| e > data.len()) {
        return Err(format!(
            "{count} elements of {elem} bytes from byte {offset} reach past the {} bytes of their \
             view",
            data.len()
        ));
    }
    let mut out = Vec::with_capacity(count * comps);
    for k in 0..count {
        let at = offset + k * stride;
        for c in 0..comps {
            out.push(component(t, &data[at + c * size..]));
        }
    }
    Ok(out)
}

/// Every component of an accessor (sparse values substituted), as `f64`.
fn read_accessor(acc: &::gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<f64>, String> {
    let t = acc.data_type();
    let comps = acc.dimensions().multiplicity();
    let count = acc.count();
    let mut out = match acc.view() {
        Some(view) => elements(
            view_bytes(&view, buffers)?,
            acc.offset(),
            view.stride().unwrap_or(0),
            count,
            comps,
            t,
        )
        .map_err(|e| format!("accessor {}: {e}", acc.index()))?,
        None => {
            if count.saturating_mul(comps) > buffers.iter().map(Vec::len).sum::<usize>() * 8 + 1024
            {
                return Err(format!(
                    "accessor {} has no data for its {count} elements",
                    acc.index()
                ));
            }
            vec![0.0; count * comps]
        }
    };
    if let Some(sparse) = acc.sparse() {
        let n = sparse.count();
        let idx = sparse.indices();
        let it = match idx.index_type() {
            ::gltf::accessor::sparse::IndexType::U8 => DataType::U8,
            ::gltf::accessor::sparse::IndexType::U16 => DataType::U16,
            ::gltf::accessor::sparse::IndexType::U32 => DataType::U32,
        };
        let at = elements(view_bytes(&idx.view(), buffers)?, idx.offset(), 0, n, 1, it)
            .map_err(|e| format!("accessor {} sparse indices: {e}", acc.index()))?;
        let vals = sparse.values();
        let vs = elements(
            view_bytes(&vals.view(), buffers)?,
            vals.offset(),
            0,
            n,
            comps,
            t,
        )
        .map_err(|e| format!("accessor {} sparse values: {e}", acc.index()))?;
        for (k, &i) in at.iter().enumerate() {
            let i = i as usize;
            if i >= count {
                return Err(format!(
                    "accessor {}: sparse index {i} past its {count} elements",
                    acc.index()
                ));
            }
            out[i * comps..(i + 1) * comps].copy_from_slice(&vs[k * comps..(k + 1) * comps]);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `.gltf` with one triangle mesh in a data URI, under a node moved by `translation`.
    pub(crate) fn triangle_gltf(translation: [f32; 3]) -> String {
        let mut bin = Vec::new();
        for x in [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
            bin.extend(x.to_le_bytes());
        }
        for i in [0u16, 1, 2, 0] {
            bin.extend(i.to_le_bytes());
        }
        let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
            "nodes":[{{"name":"root","translation":[{},{},{}],"children":[1]}},{{"mesh":0,"scale":[2,2,2]}}],
            "meshes":[{{"name":"tri","primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
            "buffers":[{{"byteLength":44,"uri":"data:application/octet-stream;base64,{b64}"}}],
            "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                         {{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}]}}"#,
            translation[0], translation[1], translation[2]
        )
    }

    #[test]
    fn node_transforms_are_composed() {
        let r = read("t.gltf", triangle_gltf([5.0, 0.0, 0.0]).as_bytes(), None).unwrap();
        assert!(!r.external);
        assert_eq!(r.faces.len(), 1);
        assert_eq!(r.faces.names, ["tri"]);
        assert_eq!(
            r.faces.coords,
            [[5.0, 0.0, 0.0], [7.0, 0.0, 0.0], [5.0, 2.0, 0.0]]
        );
    }

    #[test]
    fn bad_views_and_missing_buffers_are_one_line_errors() {
        let text = triangle_gltf([0.0; 3]).replace(
            "\"count\":3,\"type\":\"VEC3\"",
            "\"count\":4,\"type\":\"VEC3\"",
        );
        let e = read("t.gltf", text.as_bytes(), None).unwrap_err();
        assert!(e.problem.contains("reach past"), "{e}");
        let text = triangle_gltf([0.0; 3])
            .replace("data:application/octet-stream;base64,", "")
            .replace("\"uri\":\"", "\"uri\":\"missing.bin?");
        let dir = std::env::temp_dir();
        let e = read("t.gltf", text.as_bytes(), Some(&dir)).unwrap_err();
        assert_eq!(e.kind, LoadErrorKind::Read, "{e}");
        assert!(e.problem.starts_with("buffer 0 ("), "{e}");
        let e = read("t.glb", b"glTF\x02\0\0\0\x05\0\0\0", None).unwrap_err();
        assert!(e.problem.starts_with("not a valid glTF file"), "{e}");
    }

    #[test]
    fn strips_and_fans_become_triangles() {
        assert_eq!(
            triangles(Mode::TriangleStrip, &[0, 1, 2, 3]),
            [[0, 1, 2], [2, 1, 3]]
        );
        assert_eq!(
            triangles(Mode::TriangleFan, &[0, 1, 2, 3]),
            [[0, 1, 2], [0, 2, 3]]
        );
        assert_eq!(triangles(Mode::Triangles, &[0, 1, 2, 3]), [[0, 1, 2]]);
    }
}
