//! URDF robots, read with `urdf-rs`: each link's visual geometry (or its collision geometry,
//! [`UrdfOptions::collision`]) placed where the joints put it.
//!
//! **Pose.** The links form one tree (one root; each link the child of at most one joint; no
//! loop). A link's pose is its parent's, then the joint's `<origin>` (xyz, then roll–pitch–yaw
//! about fixed axes), then the joint's motion at its value: zero, or what
//! [`UrdfOptions::joints`] gives (`--joint NAME=VALUE`): a revolute or continuous joint turns
//! by VALUE radians about its axis, a prismatic joint slides VALUE metres along it. A `<mimic>`
//! joint follows its joint (multiplier × value + offset) unless given a value itself.
//!
//! **Geometry.** Each `<visual>` (or `<collision>`) is placed by the link's pose and its own
//! `<origin>`. A `<mesh>` (STL, OBJ, PLY, OFF, glTF/GLB, COLLADA) is scaled by its `scale` first;
//! its path is resolved as [`resolve`] says. A mesh is taken in its file's own coordinates, as
//! ROS tools (RViz, MoveIt's `geometric_shapes`) take it: a COLLADA file's node transforms and
//! `<unit meter>` apply, its `<up_axis>` does not, nor does glTF's Y-up. Shapes are
//! meshed ([`shapes`]): a box as 6 rectangles, a cylinder as [`shapes::SIDES`] rectangles and
//! two [`shapes::SIDES`]-gons, a sphere as [`shapes::SLICES`] × [`shapes::STACKS`] polygons
//! (triangles at the poles, quadrilaterals between), a capsule as a cylinder's side between two
//! half-spheres. Each link is one object named after it, so `--pregroup objects` and instancing
//! see links. A mesh file used several times is read once.
//!
//! **Errors**, one line naming the URDF: not a URDF, two links of one name, a joint naming a
//! missing link, a link with two parents, a loop, no or several roots, a `--joint` naming no
//! joint or a fixed one, a mesh that cannot be found or read (naming the link and the mesh).

pub mod links;
pub mod shapes;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use urdf_rs::{Geometry, JointType, Pose, Robot};

use super::faces::{Affine, Faces};
use super::input::{Format, LoadError, LoadErrorKind, one_line, read_file};
use super::mesh;

/// How a URDF is posed and where its meshes are found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct UrdfOptions {
    /// Read the `<collision>` geometry instead of the `<visual>` geometry.
    pub collision: bool,
    /// Joint values by joint name (radians for revolute and continuous joints, metres for
    /// prismatic ones); every other joint is at 0.
    pub joints: Vec<(String, f64)>,
    /// Folders to find `package://NAME/…` meshes in: `DIR/NAME/…`, or `DIR/…` when `DIR` is
    /// itself named NAME. Searched in order, before the URDF's own folders.
    pub package_path: Vec<PathBuf>,
}

impl UrdfOptions {
    /// The folders of the `ROS_PACKAGE_PATH` environment variable (colon-separated), if set.
    pub fn ros_package_path() -> Vec<PathBuf> {
        std::env::var_os("ROS_PACKAGE_PATH")
            .map(|v| {
                std::env::split_paths(&v)
                    .filter(|p| !p.as_os_str().is_empty())
                    .collect()
            })
            .unwrap_or_default()
    }
}

/// Parses `NAME=VALUE` (a `--joint` argument).
///
/// ```
/// let (name, value) = wraptree_core::scene::urdf::parse_joint("elbow=-0.5").unwrap();
/// assert_eq!((name.as_str(), value), ("elbow", -0.5));
/// ```
pub fn parse_joint(s: &str) -> Result<(String, f64), String> {
    let (name, value) = s
        .split_once('=')
        .ok_or_else(|| format!("{s:?}: expected NAME=VALUE"))?;
    let v: f64 = value
        .trim()
        .parse()
        .map_err(|_| format!("{s:?}: {value:?} is not a number"))?;
    if !v.is_finite() || name.trim().is_empty() {
        return Err(format!("{s:?}: expected NAME=VALUE with a finite VALUE"));
    }
    Ok((name.trim().to_string(), v))
}

/// A problem with its kind.
type Problem = (LoadErrorKind, String);

fn malformed(what: String) -> Problem {
    (LoadErrorKind::Malformed, what)
}

/// The faces of the URDF `bytes` named `file_name` in folder `dir`, and the warnings of its
/// meshes.
pub(crate) fn read(
    file_name: &str,
    bytes: &[u8],
    dir: Option<&Path>,
    opts: &UrdfOptions,
) -> Result<(Faces, Vec<String>), LoadError> {
    read_robot(bytes, dir, opts).map_err(|(kind, problem)| LoadError {
        file: file_name.to_string(),
        kind,
        problem,
    })
}

fn read_robot(
    bytes: &[u8],
    dir: Option<&Path>,
    opts: &UrdfOptions,
) -> Result<(Faces, Vec<String>), Problem> {
    let text = std::str::from_utf8(bytes)
        .map_err(|_| malformed("not a valid URDF file (not UTF-8 text)".into()))?;
    let robot = urdf_rs::read_from_string(text).map_err(|e| {
        malformed(format!(
            "not a valid URDF file ({})",
            one_line(&e.to_string(), 200)
        ))
    })?;
    let poses = link_poses(&robot, &opts.joints)?;
    let mut faces = Faces::new();
    let mut warnings = Vec::new();
    let mut meshes: HashMap<PathBuf, Faces> = HashMap::new();
    let ancestors: Vec<PathBuf> = dir
        .map(|d| d.ancestors().map(Path::to_path_buf).collect())
        .unwrap_or_default();
    for (link, pose) in robot.links.iter().zip(&poses) {
        let elements: Vec<(&Pose, &Geometry)> = if opts.collision {
            link.collision
                .iter()
                .map(|c| (&c.origin, &c.geometry))
                .collect()
        } else {
            link.visual
                .iter()
                .map(|v| (&v.origin, &v.geometry))
                .collect()
        };
        if elements.is_empty() {
            continue;
        }
        let object = faces.object(&link.name);
        for (origin, geometry) in elements {
            let at = pose.then_apply(&origin_affine(origin)?);
            let shape = match geometry {
                Geometry::Box { size } => shapes::cuboid(size.0),
                Geometry::Cylinder { radius, length } => shapes::cylinder(*radius, *length),
                Geometry::Sphere { radius } => shapes::sphere(*radius),
                Geometry::Capsule { radius, length } => shapes::capsule(*radius, *length),
                Geometry::Mesh { filename, scale } => {
                    let ctx =
                        |what: String| format!("link '{}': mesh {filename:?}: {what}", link.name);
                    let path = resolve(filename, dir, &ancestors, &opts.package_path)
                        .map_err(|(k, p)| (k, ctx(p)))?;
                    if !meshes.contains_key(&path) {
                        let name = path
                            .file_name()
                            .map(|n| n.to_string_lossy().into_owned())
                            .unwrap_or_default();
                        // A refused format (xacro) is named before the file is looked for.
                        let format =
                            Format::of(&name).map_err(|p| (LoadErrorKind::Unsupported, ctx(p)))?;
                        let bytes = read_file(&path).map_err(|e| {
                            (
                                LoadErrorKind::Read,
                                ctx(format!("{e} ({})", path.display())),
                            )
                        })?;
                        let mesh = mesh::read(&name, format, &bytes, path.parent())
                            .map_err(|e| (e.kind, ctx(e.problem)))?;
                        warnings.extend(mesh.warnings);
                        meshes.insert(path.clone(), mesh.faces);
                    }
                    let s = scale.map_or([1.0; 3], |s| s.0);
                    let scaled = Affine {
                        m: Matrix3::from_diagonal(&Vector3::from(s)),
                        t: Vector3::zeros(),
                    };
                    let m = at.then_apply(&scaled);
                    if !m.is_finite() {
                        return Err((
                            LoadErrorKind::NonFinite,
                            format!("link '{}': a non-finite pose or scale", link.name),
                        ));
                    }
                    faces.append(&meshes[&path], &m, object);
                    continue;
                }
            };
            let shape = shape.map_err(|e| malformed(format!("link '{}': {e}", link.name)))?;
            faces.append(&shape, &at, object);
        }
    }
    if faces.is_empty() && faces.short == 0 {
        let what = if opts.collision {
            "collision"
        } else {
            "visual"
        };
        let hint = if opts.collision {
            ""
        } else {
            "; try --urdf-collision"
        };
        return Err((
            LoadErrorKind::NoFaces,
            format!("no faces (no link has {what} geometry{hint})"),
        ));
    }
    Ok((faces, warnings))
}

/// Where the mesh `uri` of a URDF in folder `dir` (whose folders up to the root are
/// `ancestors`) is:
/// - `package://NAME/REST`: `DIR/NAME/REST` or, for a `DIR` named NAME, `DIR/REST`, for each
///   `DIR` of `package_path` (`--package-path`, then `ROS_PACKAGE_PATH`), then for each folder
///   above the URDF (a URDF in `NAME/urdf/` finds `NAME/meshes/`);
/// - `file://PATH`: PATH;
/// - anything else: a path relative to the URDF's folder (or absolute).
pub fn resolve(
    uri: &str,
    dir: Option<&Path>,
    ancestors: &[PathBuf],
    package_path: &[PathBuf],
) -> Result<PathBuf, (LoadErrorKind, String)> {
    if let Some(rest) = uri.strip_prefix("package://") {
        let (pkg, rel) = rest.split_once('/').unwrap_or((rest, ""));
        let mut tried = Vec::new();
        for base in package_path.iter().chain(ancestors.iter().skip(1)) {
            let mut candidates = vec![base.join(pkg).join(rel)];
            if base.file_name().is_some_and(|n| n == pkg) {
                candidates.push(base.join(rel));
            }
            for c in candidates {
                if c.is_file() {
                    return Ok(c);
                }
                tried.push(c);
            }
        }
        let hint = "give --package-path DIR or set ROS_PACKAGE_PATH";
        return Err((
            LoadErrorKind::Read,
            format!(
                "package '{pkg}' not found ({} places tried; {hint})",
                tried.len()
            ),
        ));
    }
    if let Some(path) = uri.strip_prefix("file://") {
        return Ok(PathBuf::from(path));
    }
    if uri.contains("://") {
        return Err((
            LoadErrorKind::Unsupported,
            "a remote mesh is not read".into(),
        ));
    }
    let path = Path::new(uri);
    if path.is_absolute() {
        return Ok(path.to_path_buf());
    }
    match dir {
        Some(d) => Ok(d.join(path)),
        None => Err((
            LoadErrorKind::Read,
            "a file beside the URDF: load the URDF from its folder".into(),
        )),
    }
}

/// The rigid motion of an `<origin>`: rotation R = Rz(yaw) Ry(pitch) Rx(roll), then xyz.
fn origin_affine(p: &Pose) -> Result<Affine, Problem> {
    let [r, pi, y] = p.rpy.0;
    let a = Affine {
        m: Rotation3::from_euler_angles(r, pi, y).into_inner(),
        t: Vector3::from(p.xyz.0),
    };
    if a.is_finite() {
        Ok(a)
    } else {
        Err((LoadErrorKind::NonFinite, "an <origin> is not finite".into()))
    }
}

/// Every link's pose (in `robot.links` order) at the joint values `given`.
fn link_poses(robot: &Robot, given: &[(String, f64)]) -> Result<Vec<Affine>, Problem> {
    let mut link_of = HashMap::new();
    for (i, l) in robot.links.iter().enumerate() {
        if link_of.insert(l.name.as_str(), i).is_some() {
            return Err(malformed(format!("two links are named '{}'", l.name)));
        }
    }
    let mut joint_of = HashMap::new();
    for (j, joint) in robot.joints.iter().enumerate() {
        if joint_of.insert(joint.name.as_str(), j).is_some() {
            return Err(malformed(format!("two joints are named '{}'", joint.name)));
        }
    }
    // The parent joint of each link.
    let mut parent: Vec<Option<usize>> = vec![None; robot.links.len()];
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
    for (j, joint) in robot.joints.iter().enumerate() {
        let find = |name: &str| {
            link_of.get(name).copied().ok_or_else(|| {
                malformed(format!(
                    "joint '{}' names the missing link '{name}'",
                    joint.name
                ))
            })
        };
        let (p, c) = (find(&joint.parent.link)?, find(&joint.child.link)?);
        if let Some(other) = parent[c] {
            return Err(malformed(format!(
                "link '{}' has two parents (joints '{}' and '{}')",
                robot.links[c].name, robot.joints[other].name, joint.name
            )));
        }
        parent[c] = Some(j);
        children[p].push(j);
    }
    let roots: Vec<usize> = (0..robot.links.len())
        .filter(|&l| parent[l].is_none())
        .collect();
    match roots.len() {
        0 if robot.links.is_empty() => {
            return Err(malformed("not a valid URDF file (no links)".into()));
        }
        0 => {
            return Err(malformed(format!(
                "the joints form a loop (every link has a parent, '{}' too)",
                robot.links[0].name
            )));
        }
        1 => {}
        _ => {
            let names: Vec<String> = roots
                .iter()
                .take(4)
                .map(|&l| format!("'{}'", robot.links[l].name))
                .collect();
            return Err(malformed(format!(
                "{} links have no parent ({}): a URDF is one tree",
                roots.len(),
                names.join(", ")
            )));
        }
    }
    let values = joint_values(robot, &joint_of, given)?;
    let mut pose: Vec<Option<Affine>> = vec![None; robot.links.len()];
    pose[roots[0]] = Some(Affine::IDENTITY);
    let mut stack = vec![roots[0]];
    while let Some(l) = stack.pop() {
        let here = pose[l].expect("set before pushed");
        for &j in &children[l] {
            let joint = &robot.joints[j];
            let c = link_of[joint.child.link.as_str()];
            let motion = joint_motion(joint, values[j])?;
            pose[c] = Some(
                here.then_apply(&origin_affine(&joint.origin)?)
                    .then_apply(&motion),
            );
            stack.push(c);
        }
    }
    if let Some(l) = pose.iter().position(Option::is_none) {
        return Err(malformed(format!(
            "the joints form a loop through link '{}'",
            robot.links[l].name
        )));
    }
    Ok(pose.into_iter().map(|p| p.expect("checked")).collect())
}

/// Each joint's value: given, following its mimic joint, or 0.
fn joint_values(
    robot: &Robot,
    joint_of: &HashMap<&str, usize>,
    given: &[(String, f64)],
) -> Result<Vec<f64>, Problem> {
    let mut value: Vec<Option<f64>> = vec![None; robot.joints.len()];
    for (name, v) in given {
        let &j = joint_of.get(name.as_str()).ok_or_else(|| {
            (
                LoadErrorKind::Malformed,
                format!("--joint {name}: the robot has no joint of that name"),
            )
        })?;
        let kind = match robot.joints[j].joint_type {
            JointType::Revolute | JointType::Continuous | JointType::Prismatic => None,
            JointType::Fixed => Some("fixed"),
            JointType::Floating => Some("floating"),
            JointType::Planar => Some("planar"),
            JointType::Spherical => Some("spherical"),
        };
        if let Some(kind) = kind {
            return Err((
                LoadErrorKind::Malformed,
                format!(
                    "--joint {name}: a {kind} joint takes no value (revolute, continuous and \
                     prismatic ones do)"
                ),
            ));
        }
        value[j] = Some(*v);
    }
    let mut out = vec![0.0; robot.joints.len()];
    for (j, slot) in out.iter_mut().enumerate() {
        // Follow mimic links to a joint with a value (or none): at most one step per joint.
        let (mut k, mut mul, mut add) = (j, 1.0, 0.0);
        let mut steps = 0;
        while value[k].is_none() {
            let Some(m) = &robot.joints[k].mimic else {
                break;
            };
            let Some(&next) = joint_of.get(m.joint.as_str()) else {
                return Err(malformed(format!(
                    "joint '{}' mimics the missing joint '{}'",
                    robot.joints[k].name, m.joint
                )));
            };
            let (a, b) = (m.multiplier.unwrap_or(1.0), m.offset.unwrap_or(0.0));
            (mul, add) = (mul * a, mul * b + add);
            k = next;
            steps += 1;
            if steps > robot.joints.len() {
                return Err(malformed(format!(
                    "the mimic joints form a loop through joint '{}'",
                    robot.joints[j].name
                )));
            }
        }
        *slot = mul * value[k].unwrap_or(0.0) + add;
    }
    Ok(out)
}

/// The motion of `joint` at `value`: a turn about or a slide along its axis.
fn joint_motion(joint: &urdf_rs::Joint, value: f64) -> Result<Affine, Problem> {
    if value == 0.0 {
        return Ok(Affine::IDENTITY);
    }
    let axis = Vector3::from(joint.axis.xyz.0);
    let Some(unit) = Unit::try_new(axis, 1e-12).filter(|u| u.iter().all(|x| x.is_finite())) else {
        return Err(malformed(format!(
            "joint '{}' has no axis to move along",
            joint.name
        )));
    };
    Ok(match joint.joint_type {
        JointType::Revolute | JointType::Continuous => Affine {
            m: Rotation3::from_axis_angle(&unit, value).into_inner(),
            t: Vector3::zeros(),
        },
        JointType::Prismatic => Affine {
            m: Matrix3::identity(),
            t: unit.into_inner() * value,
        },
        _ => Affine::IDENTITY,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn robot(joints: &str) -> String {
        format!(
            r#"<robot name="r">
              <link name="base"><visual><geometry><box size="1 1 1"/></geometry></visual></link>
              <link name="arm"><visual><origin xyz="0 0 0.5"/><geometry><cylinder radius="0.1" length="1"/></geometry></visual></link>
              <link name="tip"><visual><geometry><sphere radius="0.1"/></geometry></visual></link>
              {joints}
            </robot>"#
        )
    }

    const CHAIN: &str = r#"<joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
          <origin xyz="0 0 0.5"/><axis xyz="1 0 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
          <joint name="slide" type="prismatic"><parent link="arm"/><child link="tip"/>
          <origin xyz="0 0 1"/><axis xyz="0 0 1"/><limit lower="0" upper="1" effort="1" velocity="1"/></joint>"#;

    #[test]
    fn links_are_posed_by_their_joints() {
        let opts = UrdfOptions::default();
        let (f, _) = read("r.urdf", robot(CHAIN).as_bytes(), None, &opts).unwrap();
        assert_eq!(f.names, ["base", "arm", "tip"]);
        let top = f.coords.iter().map(|p| p[2]).fold(f64::MIN, f64::max);
        assert!((top - 1.6).abs() < 1e-12, "{top}");
        // Turned a quarter about x and slid by 0.5: the tip reaches y = -(1 + 0.5 + 0.1).
        let opts = UrdfOptions {
            joints: vec![
                ("shoulder".into(), std::f64::consts::FRAC_PI_2),
                ("slide".into(), 0.5),
            ],
            ..UrdfOptions::default()
        };
        let (f, _) = read("r.urdf", robot(CHAIN).as_bytes(), None, &opts).unwrap();
        let low = f.coords.iter().map(|p| p[1]).fold(f64::MAX, f64::min);
        assert!((low + 1.6).abs() < 1e-9, "{low}");
    }

    #[test]
    fn bad_trees_and_joint_values_are_one_line_errors() {
        let opts = UrdfOptions::default();
        let two_parents = format!(
            "{CHAIN}<joint name=\"again\" type=\"fixed\"><parent link=\"base\"/><child link=\"tip\"/></joint>"
        );
        let e = read("r.urdf", robot(&two_parents).as_bytes(), None, &opts).unwrap_err();
        assert_eq!(
            e.problem,
            "link 'tip' has two parents (joints 'slide' and 'again')"
        );
        let looped = "<joint name=\"a\" type=\"fixed\"><parent link=\"base\"/><child link=\"arm\"/></joint>\
                      <joint name=\"b\" type=\"fixed\"><parent link=\"arm\"/><child link=\"base\"/></joint>\
                      <joint name=\"c\" type=\"fixed\"><parent link=\"arm\"/><child link=\"tip\"/></joint>";
        let e = read("r.urdf", robot(looped).as_bytes(), None, &opts).unwrap_err();
        assert!(e.problem.starts_with("the joints form a loop"), "{e}");
        let missing = "<joint name=\"a\" type=\"fixed\"><parent link=\"base\"/><child link=\"nope\"/></joint>";
        let e = read("r.urdf", robot(missing).as_bytes(), None, &opts).unwrap_err();
        assert_eq!(e.problem, "joint 'a' names the missing link 'nope'");
        let opts = UrdfOptions {
            joints: vec![("elbow".into(), 1.0)],
            ..UrdfOptions::default()
        };
        let e = read("r.urdf", robot(CHAIN).as_bytes(), None, &opts).unwrap_err();
        assert_eq!(
            e.problem,
            "--joint elbow: the robot has no joint of that name"
        );
        let e = read(
            "r.urdf",
            b"<robot name=\"x\"><link",
            None,
            &UrdfOptions::default(),
        )
        .unwrap_err();
        assert!(e.problem.starts_with("not a valid URDF file ("), "{e}");
        assert!(!e.to_string().contains('\n'));
    }

    #[test]
    fn package_uris_are_found_in_package_paths_and_above_the_urdf() {
        let tmp = tempfile::tempdir().unwrap();
        let pkg = tmp.path().join("share/my_robot");
        std::fs::create_dir_all(pkg.join("meshes")).unwrap();
        std::fs::create_dir_all(pkg.join("urdf")).unwrap();
        std::fs::write(pkg.join("meshes/a.stl"), b"solid a\nendsolid a\n").unwrap();
        let urdf_dir = pkg.join("urdf");
        let ancestors: Vec<PathBuf> = urdf_dir.ancestors().map(Path::to_path_buf).collect();
        let uri = "package://my_robot/meshes/a.stl";
        let found = resolve(uri, Some(&urdf_dir), &ancestors, &[]).unwrap();
        assert_eq!(found, pkg.join("meshes/a.stl"));
        let found = resolve(uri, None, &[], &[tmp.path().join("share")]).unwrap();
        assert_eq!(found, pkg.join("meshes/a.stl"));
        let e = resolve("package://other/a.stl", Some(&urdf_dir), &ancestors, &[]).unwrap_err();
        assert!(e.1.starts_with("package 'other' not found"), "{}", e.1);
        assert_eq!(
            resolve("meshes/b.stl", Some(&urdf_dir), &[], &[]).unwrap(),
            urdf_dir.join("meshes/b.stl")
        );
    }

    #[test]
    fn joint_arguments_parse() {
        assert_eq!(parse_joint("a=1.5").unwrap(), ("a".to_string(), 1.5));
        assert!(parse_joint("a").is_err());
        assert!(parse_joint("a=x").is_err());
        assert!(parse_joint("a=inf").is_err());
    }
}
