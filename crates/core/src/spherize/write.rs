//! Writers of sphere sets in the formats planners read, each spheres in the links' frames:
//!
//! - [`urdf`]: the input robot (links, joints, visuals kept) with each `<collision>` one
//!   `<sphere>` at an `<origin xyz>` (VAMP's and foam's spherized URDFs);
//! - [`curobo_yaml`]: cuRobo's `collision_spheres: LINK: - center: [x, y, z] radius: r`;
//! - [`srdf`]: MoveIt's `<link_sphere_approximation link="…"><sphere center="x y z"
//!   radius="r"/>`;
//! - [`sph`]: one link's sphere tree in sphere-tree's `.sph` layout (first line `LEVELS 2`,
//!   then one `x y z r 1` line per node, breadth first in the complete binary layout, children
//!   of slot i at 2i + 1 and 2i + 2; an empty slot is `0 0 0 -1 0`).
//!
//! Numbers are written in Rust's shortest round-trip form, so they read back exactly.

use crate::geom::Sphere;
use crate::grouping::SubsetTree;

/// Spheres per link, in the robot's link order.
pub type Spheres = [(String, Vec<Sphere>)];

/// Levels of a `.sph` file at most (2^LEVELS − 1 slots).
pub const SPH_LEVELS: u32 = 10;

/// The robot `robot` with the collisions of every link in `set` replaced by its spheres.
pub fn urdf(robot: &urdf_rs::Robot, set: &Spheres) -> Result<String, String> {
    let mut out = robot.clone();
    for link in &mut out.links {
        if let Some((_, spheres)) = set.iter().find(|(n, _)| *n == link.name) {
            link.collision = spheres
                .iter()
                .map(|s| urdf_rs::Collision {
                    name: None,
                    origin: urdf_rs::Pose {
                        xyz: urdf_rs::Vec3([s.center.x, s.center.y, s.center.z]),
                        rpy: urdf_rs::Vec3([0.0; 3]),
                    },
                    geometry: urdf_rs::Geometry::Sphere { radius: s.radius },
                })
                .collect();
        }
    }
    let text =
        urdf_rs::write_to_string(&out).map_err(|e| format!("cannot write the URDF ({e})"))?;
    Ok(format!("<?xml version=\"1.0\"?>\n{text}\n"))
}

/// A double-quoted string, escaped as JSON (a valid YAML scalar).
fn quoted(s: &str) -> String {
    serde_json::to_string(s).expect("a string serialises")
}

/// cuRobo's sphere YAML.
pub fn curobo_yaml(set: &Spheres) -> String {
    let mut out = String::from("collision_spheres:\n");
    for (link, spheres) in set {
        out.push_str(&format!("  {}:\n", quoted(link)));
        for s in spheres {
            out.push_str(&format!(
                "    - center: [{}, {}, {}]\n      radius: {}\n",
                s.center.x, s.center.y, s.center.z, s.radius
            ));
        }
    }
    out
}

/// `s` escaped for an XML attribute.
fn attr(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// MoveIt's SRDF sphere approximation of robot `name`.
pub fn srdf(name: &str, set: &Spheres) -> String {
    let mut out = format!("<?xml version=\"1.0\"?>\n<robot name=\"{}\">\n", attr(name));
    for (link, spheres) in set {
        out.push_str(&format!(
            "  <link_sphere_approximation link=\"{}\">\n",
            attr(link)
        ));
        for s in spheres {
            out.push_str(&format!(
                "    <sphere center=\"{} {} {}\" radius=\"{}\"/>\n",
                s.center.x, s.center.y, s.center.z, s.radius
            ));
        }
        out.push_str("  </link_sphere_approximation>\n");
    }
    out.push_str("</robot>\n");
    out
}

/// The top `min(depth + 1, SPH_LEVELS)` levels of a link's sphere tree (`spheres[node]`,
/// each `planner`-adjusted by the caller) in the `.sph` layout.
pub fn sph(tree: &SubsetTree, spheres: &[Sphere]) -> String {
    let levels = (tree.depth_max() + 1).min(SPH_LEVELS);
    let slots = (1usize << levels) - 1;
    let mut node = vec![None; slots];
    node[0] = Some(tree.root());
    for i in 0..slots {
        let Some(x) = node[i] else { continue };
        if let Some([a, b]) = tree.children_of(x) {
            for (k, c) in [a, b].into_iter().enumerate() {
                if let Some(slot) = node.get_mut(2 * i + 1 + k) {
                    *slot = Some(c);
                }
            }
        }
    }
    let mut out = format!("{levels} 2\n");
    for slot in node {
        match slot {
            Some(x) => {
                let s = &spheres[x as usize];
                out.push_str(&format!(
                    "{} {} {} {} 1\n",
                    s.center.x, s.center.y, s.center.z, s.radius
                ));
            }
            None => out.push_str("0 0 0 -1 0\n"),
        }
    }
    out
}
