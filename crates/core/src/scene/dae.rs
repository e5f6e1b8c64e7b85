//! COLLADA (`.dae`) files: each geometry's triangles read by `mesh-loader`, placed here by the
//! visual scene's nodes, the way trimesh (with pycollada) and ROS tools place them.
//!
//! - **Geometry.** `mesh-loader` reads each `<geometry>`'s `<mesh>`: `<triangles>`,
//!   `<polylist>`, `<polygons>`, `<trifans>` and `<tristrips>`, polygons as fans (in `f32`, as it
//!   parses); lines are not faces.
//! - **Placement.** The nodes of the `<scene>`'s `<instance_visual_scene>` are walked from the
//!   top: a node's `<matrix>`, `<translate>`, `<rotate>` and `<scale>` compose in document order
//!   after its parent's transform. Each `<instance_geometry>` places one copy of its geometry (a
//!   geometry used twice is there twice, one never used is not there), each `<instance_node>` a
//!   copy of the node it names. A `<lookat>` or `<skew>` transform is refused with one error line;
//!   skinned meshes (`<instance_controller>`) are skipped with a warning. A file without a
//!   `<scene>` gives each geometry once, where it is.
//! - **Unit.** `<asset><unit meter="M">` scales the scene by M, so that it is in metres (as RViz
//!   does; trimesh keeps the file's numbers and records the unit beside them).
//! - **Up axis.** `<asset><up_axis>` is returned for the loader to turn a file
//!   loaded alone (absent: Y, the specification's default); a URDF's meshes ignore it, as ROS
//!   tools do. X_UP is not turned (a warning says so).
//!
//! Each placed geometry is one object, named after its node (`name`, else `id`), else after the
//! geometry. Errors are one line: not UTF-8, not XML, not COLLADA, a bad number or reference
//! in the scene, or geometry `mesh-loader` cannot read (a reader panic is caught).

use std::collections::HashMap;

use nalgebra::{Matrix3, Matrix4, Rotation3, Unit, Vector3};
use roxmltree::{Document, Node};

use super::faces::{Affine, Faces};
use super::guard::caught;
use super::input::{LoadError, LoadErrorKind, Up, one_line};

/// A COLLADA file as read.
#[derive(Debug)]
pub(crate) struct Dae {
    /// The placed geometries' triangles, in metres, in the file's axes (not turned).
    pub faces: Faces,
    /// The file's `<up_axis>`: `Some(Y)` or `Some(Z)`; `None` when absent (or X_UP).
    pub up: Option<Up>,
    /// One line per kind of thing skipped, naming the file.
    pub warnings: Vec<String>,
}

/// A problem with its kind.
type Problem = (LoadErrorKind, String);

fn malformed(what: String) -> Problem {
    (LoadErrorKind::Malformed, what)
}

/// How deep nodes may nest (an `<instance_node>` loop ends here).
const MAX_DEPTH: usize = 256;

/// The faces of the COLLADA file `bytes` named `file_name`.
pub(crate) fn read(file_name: &str, bytes: &[u8]) -> Result<Dae, LoadError> {
    let mut dae = read_document(bytes).map_err(|(kind, what)| LoadError {
        file: file_name.to_string(),
        kind,
        problem: if kind == LoadErrorKind::Malformed {
            format!("not a valid COLLADA file ({what})")
        } else {
            what
        },
    })?;
    for w in &mut dae.warnings {
        *w = format!("{file_name}: {w}");
    }
    Ok(dae)
}

fn read_document(bytes: &[u8]) -> Result<Dae, Problem> {
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    let text = super::utf8_text(bytes)
        .map_err(|line| malformed(format!("line {line}: not UTF-8 text")))?;
    let doc = Document::parse(text)
        .map_err(|e| malformed(format!("XML: {}", one_line(&e.to_string(), 200))))?;
    let root = doc.root_element();
    if root.tag_name().name() != "COLLADA" {
        return Err(malformed(format!(
            "the root element is <{}>, not <COLLADA>",
            one_line(root.tag_name().name(), 40)
        )));
    }
    let mut warnings = Vec::new();
    let (unit, up) = asset(root, &mut warnings)?;
    let meshes = geometries(text, root)?;
    let mut walk = Walk {
        ids: root
            .descendants()
            .filter_map(|n| Some((n.attribute("id")?, n)))
            .collect(),
        meshes: &meshes,
        unit,
        faces: Faces::new(),
        controllers: 0,
    };
    match child(root, "scene").and_then(|s| child(s, "instance_visual_scene")) {
        Some(instance) => {
            let scene = walk.target(instance, "visual_scene")?;
            for node in children(scene, "node") {
                walk.node(node, &Matrix4::identity(), 0)?;
            }
        }
        None => {
            let mut names: Vec<&String> = meshes.keys().collect();
            names.sort();
            for name in names {
                walk.place(&meshes[name], name, &Matrix4::identity())?;
            }
        }
    }
    if walk.controllers > 0 {
        warnings.push(format!(
            "skipped {} skinned meshes (<instance_controller>)",
            walk.controllers
        ));
    }
    Ok(Dae {
        faces: walk.faces,
        up,
        warnings,
    })
}

/// The first child element of `node` named `name`.
fn child<'a, 'i>(node: Node<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
    children(node, name).next()
}

/// The child elements of `node` named `name`.
fn children<'a, 'i>(node: Node<'a, 'i>, name: &str) -> impl Iterator<Item = Node<'a, 'i>> {
    node.children()
        .filter(move |c| c.is_element() && c.tag_name().name() == name)
}

/// The `<asset>`'s unit (metres per file unit) and up axis.
fn asset(root: Node, warnings: &mut Vec<String>) -> Result<(f64, Option<Up>), Problem> {
    let Some(asset) = child(root, "asset") else {
        return Ok((1.0, None));
    };
    let unit = match child(asset, "unit").and_then(|u| u.attribute("meter")) {
        None => 1.0,
        Some(m) => match m.trim().parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => v,
            _ => {
                return Err(malformed(format!(
                    "<unit meter=\"{}\"> is not a positive number",
                    one_line(m, 40)
                )));
            }
        },
    };
    let up = match child(asset, "up_axis").map(|a| a.text().unwrap_or("").trim()) {
        None => None,
        Some("Y_UP") => Some(Up::Y),
        Some("Z_UP") => Some(Up::Z),
        Some("X_UP") => {
            warnings.push("<up_axis> X_UP is not turned (read as Z-up; --up y|z chooses)".into());
            Some(Up::Z)
        }
        Some(other) => {
            return Err(malformed(format!(
                "<up_axis> {:?} is not X_UP, Y_UP or Z_UP",
                one_line(other, 40)
            )));
        }
    };
    Ok((unit, up))
}

/// Every geometry `mesh-loader` reads from `text`, by id, where the file defines it: the scene
/// graph (`<library_visual_scenes>`, `<library_nodes>`, `<scene>`) is cut out first, so that
/// `mesh-loader` places nothing.
fn geometries(text: &str, root: Node) -> Result<HashMap<String, mesh_loader::Mesh>, Problem> {
    counts_fit(text.len(), root)?;
    let mut cut = String::with_capacity(text.len());
    let mut from = 0;
    for c in root.children().filter(|c| {
        c.is_element()
            && matches!(
                c.tag_name().name(),
                "library_visual_scenes" | "library_nodes" | "scene"
            )
    }) {
        cut.push_str(&text[from..c.range().start]);
        from = c.range().end;
    }
    cut.push_str(&text[from..]);
    let scene = caught(|| mesh_loader::collada::from_str(&cut))
        .ok_or_else(|| malformed("its geometry's sources and indices disagree".into()))?
        .map_err(|e| malformed(format!("geometry: {}", one_line(&e.to_string(), 200))))?;
    Ok(scene
        .meshes
        .into_iter()
        .map(|m| (m.name.clone(), m))
        .collect())
}

/// Checks that no `count`, `stride` or `offset` of the document claims more values than its
/// `len` bytes can hold (each value takes two bytes or more), before `mesh-loader` reserves
/// room for them: a claim of 4·10⁹ values must be an error, not an allocation that aborts.
fn counts_fit(len: usize, root: Node) -> Result<(), Problem> {
    let number = |e: Node, name: &str| -> u64 {
        e.attribute(name)
            .and_then(|v| v.trim().parse().ok())
            .unwrap_or(0)
    };
    let len = len as u64;
    for e in root.descendants().filter(Node::is_element) {
        let count = number(e, "count");
        let per = match e.tag_name().name() {
            "triangles" | "polylist" | "polygons" | "lines" | "linestrips" | "trifans"
            | "tristrips" => {
                let inputs = children(e, "input").map(|i| number(i, "offset"));
                3 * (1 + inputs.max().unwrap_or(0))
            }
            "accessor" => number(e, "stride").max(1),
            _ => 1,
        };
        let claimed = count.saturating_mul(per);
        let offset = number(e, "offset");
        if claimed.saturating_mul(2) > len || offset > len {
            return Err(malformed(format!(
                "<{}> claims {} values, more than the file holds",
                e.tag_name().name(),
                claimed.max(offset)
            )));
        }
    }
    Ok(())
}

/// The scene graph walk: where each geometry instance goes.
struct Walk<'a, 'i> {
    /// Every element with an `id`, by it.
    ids: HashMap<&'a str, Node<'a, 'i>>,
    /// The geometries, by id.
    meshes: &'a HashMap<String, mesh_loader::Mesh>,
    /// Metres per file unit.
    unit: f64,
    /// The placed faces.
    faces: Faces,
    /// Skinned mesh instances skipped.
    controllers: usize,
}

impl<'a, 'i> Walk<'a, 'i> {
    /// The element `instance`'s `url` names (`#id`), which must be a `<kind>`.
    fn target(&self, instance: Node<'a, 'i>, kind: &str) -> Result<Node<'a, 'i>, Problem> {
        let what = instance.tag_name().name();
        let url = instance
            .attribute("url")
            .ok_or_else(|| malformed(format!("<{what}> has no url")))?;
        let found = url
            .strip_prefix('#')
            .and_then(|id| self.ids.get(id))
            .filter(|n| n.tag_name().name() == kind);
        found.copied().ok_or_else(|| {
            malformed(format!(
                "<{what} url=\"{}\"> names no <{kind}> of this file",
                one_line(url, 80)
            ))
        })
    }

    /// Places the node `node` under the transform `parent`, `depth` nodes deep.
    fn node(
        &mut self,
        node: Node<'a, 'i>,
        parent: &Matrix4<f64>,
        depth: usize,
    ) -> Result<(), Problem> {
        if depth > MAX_DEPTH {
            return Err(malformed(format!(
                "nodes nest deeper than {MAX_DEPTH} (an <instance_node> loop?)"
            )));
        }
        let name = node
            .attribute("name")
            .or_else(|| node.attribute("id"))
            .unwrap_or("");
        let mut at = *parent;
        for c in node.children().filter(Node::is_element) {
            at *= match c.tag_name().name() {
                "matrix" => Matrix4::from_row_slice(&numbers::<16>(c, name)?),
                "translate" => Matrix4::new_translation(&Vector3::from(numbers::<3>(c, name)?)),
                "scale" => Matrix4::new_nonuniform_scaling(&Vector3::from(numbers::<3>(c, name)?)),
                "rotate" => {
                    let [x, y, z, degrees] = numbers::<4>(c, name)?;
                    let axis = Unit::try_new(Vector3::new(x, y, z), 0.0).ok_or_else(|| {
                        malformed(format!("node '{name}': a <rotate> about no axis"))
                    })?;
                    Rotation3::from_axis_angle(&axis, degrees.to_radians()).to_homogeneous()
                }
                t @ ("lookat" | "skew") => {
                    return Err((
                        LoadErrorKind::Unsupported,
                        format!("node '{name}': a <{t}> transform is not read"),
                    ));
                }
                _ => continue,
            };
        }
        for c in node.children().filter(Node::is_element) {
            match c.tag_name().name() {
                "node" => self.node(c, &at, depth + 1)?,
                "instance_node" => {
                    let target = self.target(c, "node")?;
                    self.node(target, &at, depth + 1)?;
                }
                "instance_geometry" => {
                    let geometry = self.target(c, "geometry")?;
                    let id = geometry.attribute("id").unwrap_or("");
                    // A geometry mesh-loader does not read (a spline, a convex mesh) has none.
                    if let Some(mesh) = self.meshes.get(id) {
                        let label = if name.is_empty() { id } else { name };
                        self.place(mesh, label, &at)?;
                    }
                }
                "instance_controller" => self.controllers += 1,
                _ => {}
            }
        }
        Ok(())
    }

    /// Appends `mesh` placed by `at` (then scaled by the unit) as the object `name`.
    fn place(
        &mut self,
        mesh: &mesh_loader::Mesh,
        name: &str,
        at: &Matrix4<f64>,
    ) -> Result<(), Problem> {
        let m = Affine {
            m: Matrix3::from(at.fixed_view::<3, 3>(0, 0)) * self.unit,
            t: Vector3::from(at.fixed_view::<3, 1>(0, 3)) * self.unit,
        };
        if !m.is_finite() {
            return Err((
                LoadErrorKind::NonFinite,
                format!("node '{name}': a non-finite transform"),
            ));
        }
        if mesh.faces.is_empty() {
            return Ok(());
        }
        let object = self.faces.object(name);
        let base = self.faces.coords.len();
        for v in &mesh.vertices {
            self.faces.vertex(m.apply(v.map(f64::from)));
        }
        let n = mesh.vertices.len();
        for f in &mesh.faces {
            if f.iter().any(|&i| i as usize >= n) {
                return Err(malformed(format!(
                    "geometry '{}': a face refers to a missing vertex",
                    one_line(&mesh.name, 80)
                )));
            }
            self.faces
                .face(f.map(|i| (base + i as usize) as u32), object);
        }
        Ok(())
    }
}

/// The `N` numbers of the transform element `e` of node `node`.
fn numbers<const N: usize>(e: Node, node: &str) -> Result<[f64; N], Problem> {
    let bad = || {
        malformed(format!(
            "node '{node}': <{}> needs {N} numbers",
            e.tag_name().name()
        ))
    };
    let mut out = [0.0; N];
    let mut words = e.text().unwrap_or("").split_whitespace();
    for slot in &mut out {
        *slot = words.next().ok_or_else(bad)?.parse().map_err(|_| bad())?;
    }
    if words.next().is_some() {
        return Err(bad());
    }
    Ok(out)
}
