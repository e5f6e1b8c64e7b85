//! A robot's links each in its own frame: the geometry the URDF loader yields (posed by the
//! joints), moved back by the inverse of each link's pose. Whatever mesh
//! formats the loader reads, this reads too.

use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Vector3};

use super::{UrdfOptions, link_poses, read};
use crate::geom::P3;
use crate::scene::faces::build;
use crate::scene::input::{LoadError, LoadErrorKind, LoadOptions, Up, read_file};
use crate::scene::{PrimitiveKind, Scene};
use crate::stop::Stop;

/// One link with geometry: its name, its pose at the given joint values and its mesh in its
/// own frame.
#[derive(Clone, Debug)]
pub struct Link {
    /// The link's name in the URDF.
    pub name: String,
    /// Rotation of the link's frame in the robot's root frame.
    pub rotation: Matrix3<f64>,
    /// Origin of the link's frame in the robot's root frame.
    pub translation: Vector3<f64>,
    /// The link's polygons (its visual or collision geometry), in the link's frame.
    pub mesh: Scene,
}

impl Link {
    /// `p` (in the link's frame) in the robot's root frame.
    pub fn to_root(&self, p: &P3) -> P3 {
        P3::from(self.rotation * p.coords + self.translation)
    }
}

/// A URDF read link by link.
#[derive(Clone, Debug)]
pub struct Links {
    /// The parsed URDF (links, joints, visuals), for writers that keep it.
    pub robot: urdf_rs::Robot,
    /// The links that have geometry, in the URDF's order.
    pub links: Vec<Link>,
    /// The loader's warnings.
    pub warnings: Vec<String>,
}

/// Reads the URDF at `path` with `opts` (collision or visual geometry, joint values, package
/// folders) and gives each link's mesh in the link's frame. Errors are the loader's, one line
/// naming the file; stops with an interrupted error when `stop` is requested.
pub fn read_links(path: &Path, opts: &UrdfOptions, stop: &Stop) -> Result<Links, LoadError> {
    let shown = path.display().to_string();
    let err = |kind, problem: String| LoadError {
        file: shown.clone(),
        kind,
        problem,
    };
    let bytes = read_file(path).map_err(|p| err(LoadErrorKind::Read, p))?;
    let dir = path.parent().map(|d| {
        if d.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            d.to_path_buf()
        }
    });
    let (faces, mut warnings) =
        read(&shown, &bytes, dir.as_deref(), opts).map_err(|e| LoadError {
            file: shown.clone(),
            ..e
        })?;
    let text = std::str::from_utf8(&bytes).expect("read() checked UTF-8");
    let robot = urdf_rs::read_from_string(text).map_err(|e| {
        err(
            LoadErrorKind::Malformed,
            format!("not a valid URDF file ({e})"),
        )
    })?;
    let poses = link_poses(&robot, &opts.joints).map_err(|(k, p)| err(k, p))?;
    let built = build(&shown, faces, &LoadOptions::default(), Up::Z, stop)?;
    warnings.extend(built.warnings);
    let scene = &built.scene;
    let mut links: Vec<Link> = Vec::new();
    // Object ids follow the links' order of first appearance; names are the links' (unique).
    let mut of_object: Vec<Option<usize>> = vec![None; built.names.len()];
    for (o, name) in built.names.iter().enumerate() {
        let Some(l) = robot.links.iter().position(|l| &l.name == name) else {
            continue;
        };
        let pose = &poses[l];
        of_object[o] = Some(links.len());
        links.push(Link {
            name: name.clone(),
            rotation: pose.m,
            translation: pose.t,
            mesh: Scene::new(name.clone()),
        });
    }
    let mut local: Vec<Vec<u32>> = vec![Vec::new(); links.len()];
    for l in &mut local {
        l.resize(scene.points.len(), u32::MAX);
    }
    for i in 0..scene.len() {
        let Some(l) = of_object[scene.object(i) as usize] else {
            continue;
        };
        let link = &mut links[l];
        let map = &mut local[l];
        let inv = link.rotation.transpose();
        let mut id = |v: u32| {
            if map[v as usize] == u32::MAX {
                map[v as usize] = link.mesh.points.len() as u32;
                let p = scene.points[v as usize].coords - link.translation;
                link.mesh.points.push(P3::from(inv * p));
            }
            map[v as usize]
        };
        let verts: Vec<u32> = scene.prim(i).iter().map(|&v| id(v)).collect();
        let tris: Vec<[u32; 3]> = scene.prim_tris(i).iter().map(|t| t.map(&mut id)).collect();
        link.mesh.push(PrimitiveKind::Polygon, &verts, &tris);
    }
    links.retain(|l| !l.mesh.is_empty());
    Ok(Links {
        robot,
        links,
        warnings,
    })
}
