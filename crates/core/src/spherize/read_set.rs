//! Reading an existing sphere set to score it: a spherized URDF (each `<collision>` with a
//! `<sphere>`, its centre the `<origin>`'s xyz in the link's frame) or a cuRobo-style YAML
//! (`collision_spheres: LINK: - center: [x, y, z] radius: r`, found at any depth).

use std::collections::BTreeMap;
use std::path::Path;

use yaml_rust2::{Yaml, YamlLoader};

use crate::geom::{P3, Sphere};

/// Spheres by link name.
pub type SphereSet = BTreeMap<String, Vec<Sphere>>;

/// Reads the sphere set at `path` by its extension (`.yml`/`.yaml`: YAML, else URDF). Err: one
/// line naming the file and the problem.
pub fn read_set(path: &Path) -> Result<SphereSet, String> {
    let shown = path.display();
    let text = std::fs::read_to_string(path).map_err(|e| format!("{shown}: cannot read: {e}"))?;
    let yaml = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("yml") || e.eq_ignore_ascii_case("yaml"));
    let set = if yaml {
        from_yaml(&text)
    } else {
        from_urdf(&text)
    };
    let set = set.map_err(|p| format!("{shown}: {p}"))?;
    if set.values().all(Vec::is_empty) {
        return Err(format!("{shown}: no spheres"));
    }
    Ok(set)
}

/// The `<sphere>` collisions of a URDF's links.
pub fn from_urdf(text: &str) -> Result<SphereSet, String> {
    let robot = urdf_rs::read_from_string(text).map_err(|e| {
        let e = e.to_string();
        format!("not a valid URDF file ({})", e.lines().next().unwrap_or(""))
    })?;
    let mut set = SphereSet::new();
    for link in &robot.links {
        for c in &link.collision {
            if let urdf_rs::Geometry::Sphere { radius } = c.geometry {
                let [x, y, z] = c.origin.xyz.0;
                set.entry(link.name.clone()).or_default().push(Sphere {
                    center: P3::new(x, y, z),
                    radius,
                });
            }
        }
    }
    Ok(set)
}

/// The first `collision_spheres` mapping of a YAML document, depth first.
fn find(y: &Yaml) -> Option<&Yaml> {
    let h = y.as_hash()?;
    if let Some(v) = h.get(&Yaml::String("collision_spheres".into()))
        && v.as_hash().is_some()
    {
        return Some(v);
    }
    h.values().find_map(find)
}

fn number(y: &Yaml) -> Option<f64> {
    y.as_f64().or_else(|| y.as_i64().map(|i| i as f64))
}

/// The `collision_spheres` of a cuRobo-style YAML.
pub fn from_yaml(text: &str) -> Result<SphereSet, String> {
    let docs = YamlLoader::load_from_str(text).map_err(|e| format!("not valid YAML ({e})"))?;
    let spheres = docs
        .iter()
        .find_map(find)
        .ok_or("no collision_spheres mapping")?;
    let mut set = SphereSet::new();
    for (link, list) in spheres.as_hash().expect("found as a mapping") {
        let name = link
            .as_str()
            .map(str::to_string)
            .or_else(|| number(link).map(|v| v.to_string()))
            .ok_or("a link name that is not a string")?;
        let entries = list.as_vec().map(Vec::as_slice).unwrap_or(&[]);
        let mut out = Vec::new();
        for s in entries {
            let c = s["center"].as_vec().filter(|c| c.len() == 3);
            let c = c.and_then(|c| Some([number(&c[0])?, number(&c[1])?, number(&c[2])?]));
            let (Some([x, y, z]), Some(r)) = (c, number(&s["radius"])) else {
                return Err(format!(
                    "link '{name}': a sphere without center: [x, y, z] and radius: r"
                ));
            };
            out.push(Sphere {
                center: P3::new(x, y, z),
                radius: r,
            });
        }
        set.insert(name, out);
    }
    Ok(set)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yaml_sets_are_found_at_any_depth() {
        let y = "robot_cfg:\n  kinematics:\n    collision_spheres:\n      arm:\n        - center: [0, 0.5, 1]\n          radius: 0.25\n      \"hand\":\n        - {center: [1.0, 2.0, 3.0], radius: 1}\n";
        let s = from_yaml(y).unwrap();
        assert_eq!(s["arm"][0].center, P3::new(0.0, 0.5, 1.0));
        assert_eq!(s["hand"][0].radius, 1.0);
        assert!(from_yaml("a: 1").is_err());
    }
}
