//! The bundled scenes in `scenes/`: every `.obj` there (and every URDF robot in a folder of its
//! own, `scenes/NAME/NAME.urdf`) is listed in a table of `scenes/README.md` and loads with the
//! primitive count that table states; the composed assemblies hold their parts as separate
//! objects, placed where their URDF puts them; the monastery stands upright with `--up y`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use wraptree::scene::{LoadOptions, PrimitiveKind, Up, load_path};

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// One row of a README table: loaded with `--polyhedra`, and its primitive count.
#[derive(Debug, PartialEq)]
struct Stated {
    polyhedra: bool,
    primitives: usize,
}

fn cells(line: &str) -> Vec<String> {
    let t = line.trim().trim_start_matches('|').trim_end_matches('|');
    t.split('|').map(|c| c.trim().to_string()).collect()
}

/// Every row of every table in `text` whose header has a `File` and a `Primitives` column:
/// the file name in backticks, the `Mode` column (if any) naming `--polyhedra`, and the
/// leading number of the `Primitives` cell (thousands separated by commas).
fn stated_counts(text: &str) -> BTreeMap<String, Stated> {
    let mut out = BTreeMap::new();
    let mut header: Option<Vec<String>> = None;
    for line in text.lines() {
        if !line.trim_start().starts_with('|') {
            header = None;
            continue;
        }
        let row = cells(line);
        let Some(h) = &header else {
            header = Some(row);
            continue;
        };
        if row
            .iter()
            .all(|c| c.chars().all(|ch| ch == '-' || ch == ':'))
        {
            continue;
        }
        let col = |name: &str| h.iter().position(|c| c == name);
        let (Some(file), Some(prims)) = (col("File"), col("Primitives")) else {
            continue;
        };
        let name = row[file].trim_matches('`').to_string();
        let digits: String = row[prims]
            .chars()
            .take_while(|c| c.is_ascii_digit() || *c == ',')
            .filter(|c| *c != ',')
            .collect();
        let primitives = digits
            .parse()
            .unwrap_or_else(|_| panic!("{name}: no count in {:?}", row[prims]));
        let polyhedra = col("Mode").is_some_and(|m| row[m].contains("--polyhedra"));
        let dup = out.insert(
            name.clone(),
            Stated {
                polyhedra,
                primitives,
            },
        );
        assert!(dup.is_none(), "{name} is listed twice in scenes/README.md");
    }
    out
}

#[test]
fn the_readme_parser_reads_file_mode_and_count() {
    let text = "| File | Mode | Primitives |\n|---|---|---|\n\
                | `a.obj` | polygons | 12,345 (see below) |\n| `b.obj` | `--polyhedra` | 5 |\n\n\
                | File | Command |\n|---|---|\n| `c.obj` | x |\n";
    let got = stated_counts(text);
    assert_eq!(got.len(), 2);
    assert_eq!(
        got["a.obj"],
        Stated {
            polyhedra: false,
            primitives: 12345
        }
    );
    assert_eq!(
        got["b.obj"],
        Stated {
            polyhedra: true,
            primitives: 5
        }
    );
}

#[test]
fn every_bundled_scene_loads_with_the_count_its_readme_states() {
    let readme = std::fs::read_to_string(repo("scenes/README.md")).unwrap();
    let stated = stated_counts(&readme);
    let mut on_disk: Vec<String> = Vec::new();
    for e in std::fs::read_dir(repo("scenes")).unwrap() {
        let e = e.unwrap();
        let n = e.file_name().to_string_lossy().into_owned();
        if n.ends_with(".obj") {
            on_disk.push(n);
        } else if e.path().is_dir() {
            // A robot in a folder of its own: its URDFs.
            for f in std::fs::read_dir(e.path()).unwrap() {
                let f = f.unwrap().file_name().to_string_lossy().into_owned();
                if f.ends_with(".urdf") {
                    on_disk.push(format!("{n}/{f}"));
                }
            }
        }
    }
    on_disk.sort();
    let listed: Vec<String> = stated.keys().cloned().collect();
    assert_eq!(
        on_disk, listed,
        "scenes/*.obj and the tables of scenes/README.md differ"
    );
    for (name, s) in &stated {
        let opts = LoadOptions {
            polyhedra: s.polyhedra,
            strict: s.polyhedra,
            up: None,
        };
        let l =
            load_path(&repo(&format!("scenes/{name}")), &opts).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(l.scene.len(), s.primitives, "{name}");
        let kind = [PrimitiveKind::Polygon, PrimitiveKind::Polyhedron][s.polyhedra as usize];
        assert_eq!(l.scene.kind, Some(kind), "{name}");
        assert!(
            l.scene
                .points
                .iter()
                .all(|p| p.iter().all(|c| c.is_finite())),
            "{name}"
        );
        let stem = Path::new(name).file_stem().unwrap().to_string_lossy();
        // A URDF is embedded in recordings as the OBJ of its scene.
        assert_eq!(l.source.file_name.trim_end_matches(".obj"), stem, "{name}");
        assert_eq!(l.scene.name, stem);
        if s.polyhedra {
            assert_eq!(l.scene.labels.len(), s.primitives, "{name}");
        }
    }
}

/// The `o` objects of an OBJ file in order, each with its vertices.
fn objects(path: &Path) -> Vec<(String, Vec<[f64; 3]>)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut out: Vec<(String, Vec<[f64; 3]>)> = Vec::new();
    for line in text.lines() {
        let mut t = line.split_whitespace();
        match t.next() {
            Some("o") => out.push((t.next().unwrap().to_string(), Vec::new())),
            Some("v") => {
                let v: Vec<f64> = t.map(|x| x.parse().unwrap()).collect();
                out.last_mut().unwrap().1.push([v[0], v[1], v[2]]);
            }
            _ => {}
        }
    }
    out
}

/// The offset that moves `a` onto `b` vertex by vertex, if one translation does (within 1e-6).
fn translation(a: &[[f64; 3]], b: &[[f64; 3]]) -> Option<[f64; 3]> {
    if a.len() != b.len() || a.is_empty() {
        return None;
    }
    let d = [0, 1, 2].map(|k| b[0][k] - a[0][k]);
    let fits = a
        .iter()
        .zip(b)
        .all(|(p, q)| (0..3).all(|k| (q[k] - p[k] - d[k]).abs() < 1e-6));
    fits.then_some(d)
}

#[test]
fn husky_wheels_and_bumpers_are_placed_copies() {
    let objs = objects(&repo("scenes/husky.obj"));
    let names: Vec<&str> = objs.iter().map(|o| o.0.as_str()).collect();
    assert_eq!(
        names,
        [
            "base_link",
            "front_left_wheel_link",
            "front_right_wheel_link",
            "rear_left_wheel_link",
            "rear_right_wheel_link",
            "top_plate_link",
            "user_rail_link",
            "front_bumper_link",
            "rear_bumper_link"
        ]
    );
    // husky.urdf: wheels at x = ±0.256, y = ±0.2854, same orientation.
    let fl = &objs[1].1;
    for (i, want) in [
        (2, [0.0, -0.5708, 0.0]),
        (3, [-0.512, 0.0, 0.0]),
        (4, [-0.512, -0.5708, 0.0]),
    ] {
        let d = translation(fl, &objs[i].1).unwrap_or_else(|| panic!("{} is no copy", objs[i].0));
        assert!(
            (0..3).all(|k| (d[k] - want[k]).abs() < 1e-9),
            "{}: {d:?}",
            objs[i].0
        );
    }
    // The rear bumper is the front one turned half a turn about z (rpy 0 0 3.14159):
    // (x, y, z) -> (-x, -y, z) up to the 2.65e-6 rad the URDF leaves out of pi.
    let (front, rear) = (&objs[7].1, &objs[8].1);
    assert_eq!(front.len(), rear.len());
    for (p, q) in front.iter().zip(rear) {
        assert!(
            (q[0] + p[0]).abs() < 1e-5 && (q[1] + p[1]).abs() < 1e-5,
            "{p:?} {q:?}"
        );
        assert!((q[2] - p[2]).abs() < 1e-9);
    }
    assert!(translation(front, rear).is_none());
}

#[test]
fn kuka_iiwa_links_are_stacked_along_the_arm() {
    let objs = objects(&repo("scenes/kuka-iiwa.obj"));
    assert_eq!(objs.len(), 8);
    let mut prev_top = f64::NEG_INFINITY;
    for (i, (name, v)) in objs.iter().enumerate() {
        assert_eq!(name, &format!("lbr_iiwa_link_{i}"));
        let top = v.iter().map(|p| p[2]).fold(f64::NEG_INFINITY, f64::max);
        assert!(
            top > prev_top,
            "{name} ends at z = {top}, below the link before it"
        );
        prev_top = top;
    }
    // Zero configuration: the arm stands upright, 1.306 m tall (base 0, flange 1.306).
    assert!((prev_top - 1.306).abs() < 1e-3, "{prev_top}");
}

#[test]
fn r2d2_links_are_objects_and_its_wheels_are_placed_copies() {
    let l = load_path(&repo("scenes/r2d2/r2d2.urdf"), &LoadOptions::default()).unwrap();
    let text = String::from_utf8(l.source.bytes.clone()).unwrap();
    let names: Vec<&str> = text.lines().filter_map(|s| s.strip_prefix("o ")).collect();
    assert_eq!(names.len(), 16);
    assert_eq!(names[0], "base_link");
    // Each wheel's vertices in order of first use.
    let points = |name: &str| -> Vec<[f64; 3]> {
        let id = names.iter().position(|n| *n == name).unwrap() as u32;
        let mut seen = std::collections::BTreeSet::new();
        let mut out = Vec::new();
        for i in (0..l.scene.len()).filter(|&i| l.scene.object(i) == id) {
            for &v in l.scene.prim(i) {
                if seen.insert(v) {
                    let p = l.scene.points[v as usize];
                    out.push([p.x, p.y, p.z]);
                }
            }
        }
        out
    };
    let rf = points("right_front_wheel");
    for (other, want) in [
        ("right_back_wheel", [0.0, -0.266666666666, 0.0]),
        ("left_front_wheel", [-0.44, 0.0, 0.0]),
        ("left_back_wheel", [-0.44, -0.266666666666, 0.0]),
    ] {
        let d = translation(&rf, &points(other)).unwrap_or_else(|| panic!("{other} is no copy"));
        assert!(
            (0..3).all(|k| (d[k] - want[k]).abs() < 1e-9),
            "{other}: {d:?}"
        );
    }
}

#[test]
fn the_monastery_stands_upright_with_up_y() {
    let path = repo("scenes/samurai-monastery.obj");
    let y_up = LoadOptions {
        up: Some(Up::Y),
        ..LoadOptions::default()
    };
    let a = load_path(&path, &y_up).unwrap().scene.aabb();
    let e = a.max - a.min;
    // A compound of about 124 × 121 m, 30 m tall, standing on z = 0.
    assert!(e.z < 0.3 * e.x.min(e.y), "{e:?}");
    assert!(a.min.z.abs() < 0.1, "{a:?}");
}
