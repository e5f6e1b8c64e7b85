//! Input formats besides OBJ (STL, PLY, glTF/GLB, COLLADA, URDF), the up axis, OBJ files of
//! other parsers' test suites, and recordings of multi-file inputs.
//!
//! The real files are in `tests/data/formats/` (from trimesh's and tobj's test models, MIT;
//! see its README) and `scenes/r2d2/` (pybullet's R2-D2). Counts and placements are compared
//! with independent readers: trimesh (meshes; COLLADA through pycollada) and urdf_parser_py with
//! numpy forward kinematics (URDF), run by `tests/formats_reader.py` in the tests' Python
//! environment.

mod common;

use std::path::{Path, PathBuf};

use wraptree::geom::Aabb;
use wraptree::scene::{
    LoadOptions, Loaded, Up, UrdfOptions, load_bytes, load_path, load_path_with,
};

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

fn formats(name: &str) -> PathBuf {
    repo("tests/data/formats").join(name)
}

/// `tests/formats_reader.py ARGS` run by the tests' Python; its JSON output.
fn reader(args: &[&str]) -> serde_json::Value {
    let out = common::python()
        .arg(repo("tests/formats_reader.py"))
        .args(args)
        .output()
        .expect("python runs");
    assert!(
        out.status.success(),
        "formats_reader.py {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("JSON")
}

fn xyz(v: &serde_json::Value) -> [f64; 3] {
    [0, 1, 2].map(|k| v[k].as_f64().unwrap())
}

/// Asserts that `aabb` has the corners `min`, `max` within `tol` × its diagonal.
fn assert_box(what: &str, aabb: &Aabb, min: [f64; 3], max: [f64; 3], tol: f64) {
    let d = aabb.diameter().max(1e-12);
    for k in 0..3 {
        assert!(
            (aabb.min[k] - min[k]).abs() <= tol * d && (aabb.max[k] - max[k]).abs() <= tol * d,
            "{what}: ours {aabb:?}, independent {min:?}..{max:?}"
        );
    }
}

const Z_UP: LoadOptions = LoadOptions {
    polyhedra: false,
    strict: false,
    up: Some(Up::Z),
};

#[test]
fn real_mesh_files_load_with_the_triangles_trimesh_reads() {
    // (file, trimesh's triangles are our primitives: every face a triangle)
    let files = [
        ("idler_riser.STL", true),      // binary, its header begins with "solid"
        ("multibody.stl", true),        // ASCII, two solids
        ("mirror.ply", true),           // binary little-endian
        ("sphere.ply", true),           // ASCII
        ("cube_blender_uv.ply", false), // ASCII quads with normals and uv
        ("nested.glb", true),           // node hierarchy
        ("no_indices_3storybuilding.glb", true), // no index accessors
        ("rgb_cube_with_primitives.gltf", true), // data: URIs
        ("TestScene.gltf", true),       // an external .bin buffer
        ("obj-suites/trimesh/wallhole.obj", false), // `\` line continuations, n-gons
    ];
    let paths: Vec<String> = files
        .iter()
        .map(|(f, _)| formats(f).display().to_string())
        .collect();
    let mut args = vec!["mesh"];
    args.extend(paths.iter().map(String::as_str));
    let theirs = reader(&args);
    eprintln!(
        "{:<34} {:>9} {:>11} {:>10}",
        "file", "trimesh", "our tris", "our prims"
    );
    for ((file, all_triangles), t) in files.iter().zip(theirs.as_array().unwrap()) {
        // glTF is Y-up: load without turning, to compare in the file's frame.
        let l = load_path(&formats(file), &Z_UP).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            l.warnings.iter().all(|w| !w.contains("dropped")),
            "{file}: {:?}",
            l.warnings
        );
        let n = t["triangles"].as_u64().unwrap() as usize;
        eprintln!(
            "{file:<34} {n:>9} {:>11} {:>10}",
            l.scene.tris.len(),
            l.scene.len()
        );
        assert_eq!(
            l.scene.tris.len(),
            n,
            "{file}: fan triangles against trimesh"
        );
        if *all_triangles {
            assert_eq!(l.scene.len(), n, "{file}: primitives against trimesh");
        }
        assert_box(file, &l.scene.aabb(), xyz(&t["min"]), xyz(&t["max"]), 1e-6);
    }
}

#[test]
fn urdf_links_are_placed_as_an_independent_reader_places_them() {
    let urdf = repo("scenes/r2d2/r2d2.urdf");
    let urdf_s = urdf.display().to_string();
    for joints in [
        vec![],
        vec![
            ("head_swivel", 0.5),
            ("gripper_extension", -0.2),
            ("left_gripper_joint", 0.4),
            ("right_front_wheel_joint", 1.0),
        ],
    ] {
        let given: Vec<String> = joints.iter().map(|(n, v)| format!("{n}={v}")).collect();
        let mut args = vec!["urdf", urdf_s.as_str()];
        args.extend(given.iter().map(String::as_str));
        let theirs = reader(&args);
        let opts = UrdfOptions {
            joints: joints.iter().map(|(n, v)| (n.to_string(), *v)).collect(),
            ..UrdfOptions::default()
        };
        let l = load_path_with(&urdf, &LoadOptions::default(), &opts).unwrap();
        let links = theirs.as_array().unwrap();
        let objects = 1 + *l.scene.objects.iter().max().unwrap() as usize;
        assert_eq!(objects, links.len());
        let mut meshes = 0;
        for (id, link) in links.iter().enumerate() {
            let name = link["name"].as_str().unwrap();
            let prims: Vec<usize> = (0..l.scene.len())
                .filter(|&i| l.scene.object(i) as usize == id)
                .collect();
            let shapes: usize = link["shapes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| match s.as_str().unwrap() {
                    "box" => 6,
                    "cylinder" => wraptree::scene::urdf::shapes::SIDES + 2,
                    "sphere" => {
                        wraptree::scene::urdf::shapes::SLICES
                            * wraptree::scene::urdf::shapes::STACKS
                    }
                    other => panic!("{other}"),
                })
                .sum();
            let tris = link["mesh_triangles"].as_u64().unwrap() as usize;
            meshes += tris;
            assert_eq!(prims.len(), tris + shapes, "link {name}");
            if let Some(min) = link.get("min") {
                let aabb = prims
                    .iter()
                    .fold(Aabb::EMPTY, |b, &i| b.merge(&l.scene.prim_aabb(i)));
                assert_box(name, &aabb, xyz(min), xyz(&link["max"]), 1e-9);
            }
        }
        eprintln!(
            "r2d2 {given:?}: {} links, {meshes} mesh triangles (urdf_parser_py + trimesh), {} \
             primitives (ours)",
            links.len(),
            l.scene.len()
        );
    }
}

/// A package `my_robot` in `root` with a URDF in `urdf/` whose links use every mesh format
/// through `package://` and relative paths; returns the URDF's path.
fn mixed_robot(root: &Path, extra: &str) -> PathBuf {
    let pkg = root.join("my_robot");
    std::fs::create_dir_all(pkg.join("meshes")).unwrap();
    std::fs::create_dir_all(pkg.join("urdf")).unwrap();
    for f in [
        "idler_riser.STL",
        "mirror.ply",
        "nested.glb",
        "TestScene.gltf",
        "TestScene.bin",
    ] {
        std::fs::copy(formats(f), pkg.join("meshes").join(f)).unwrap();
    }
    std::fs::copy(
        formats("obj-suites/trimesh/wallhole.obj"),
        pkg.join("urdf/wallhole.obj"),
    )
    .unwrap();
    let link = |name: &str, mesh: &str, scale: &str| {
        format!(
            "<link name=\"{name}\"><visual><origin xyz=\"0 0 1\" rpy=\"0 0 1.5\"/><geometry>\
             <mesh filename=\"{mesh}\" scale=\"{scale}\"/></geometry></visual></link>"
        )
    };
    let fixed = |name: &str, child: &str| {
        format!(
            "<joint name=\"{name}\" type=\"fixed\"><parent link=\"stl\"/><child link=\"{child}\"/>\
             <origin xyz=\"1 2 3\"/></joint>"
        )
    };
    let text = format!(
        "<robot name=\"mixed\">{}{}{}{}{}{}{}{}{}{extra}</robot>",
        link("stl", "package://my_robot/meshes/idler_riser.STL", "1 1 1"),
        link("ply", "package://my_robot/meshes/mirror.ply", "2 2 2"),
        link("glb", "../meshes/nested.glb", "1 1 1"),
        link(
            "gltf",
            "package://my_robot/meshes/TestScene.gltf",
            "0.1 0.1 0.1"
        ),
        link("obj", "wallhole.obj", "1 1 1"),
        fixed("j1", "ply"),
        fixed("j2", "glb"),
        fixed("j3", "gltf"),
        fixed("j4", "obj"),
    );
    let path = pkg.join("urdf/robot.urdf");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_urdf_can_use_every_mesh_format_through_package_and_relative_paths() {
    let tmp = tempfile::tempdir().unwrap();
    let urdf = mixed_robot(tmp.path(), "");
    let l = load_path(&urdf, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    // Each link has the primitives of its mesh file loaded alone (placing keeps faces whole).
    let alone = |f: &str| load_path(&formats(f), &Z_UP).unwrap().scene.len();
    let want = [
        alone("idler_riser.STL"),
        alone("mirror.ply"),
        alone("nested.glb"),
        alone("TestScene.gltf"),
        alone("obj-suites/trimesh/wallhole.obj"),
    ];
    let mut got = [0usize; 5];
    for i in 0..l.scene.len() {
        got[l.scene.object(i) as usize] += 1;
    }
    assert_eq!(got, want);
    // A URDF is embedded as the OBJ of its scene, with one `o` per link.
    assert_eq!(l.source.file_name, "robot.obj");
    let text = String::from_utf8(l.source.bytes.clone()).unwrap();
    let objects: Vec<&str> = text.lines().filter_map(|s| s.strip_prefix("o ")).collect();
    assert_eq!(objects, ["stl", "ply", "glb", "gltf", "obj"]);
    // ROS_PACKAGE_PATH-style search: the package found from a package path alone.
    let elsewhere = tmp.path().join("elsewhere.urdf");
    std::fs::write(
        &elsewhere,
        "<robot name=\"r\"><link name=\"a\"><visual><geometry>\
         <mesh filename=\"package://my_robot/meshes/mirror.ply\"/></geometry></visual></link></robot>",
    )
    .unwrap();
    assert!(load_path(&elsewhere, &LoadOptions::default()).is_err());
    let opts = UrdfOptions {
        package_path: vec![tmp.path().to_path_buf()],
        ..UrdfOptions::default()
    };
    let l = load_path_with(&elsewhere, &LoadOptions::default(), &opts).unwrap();
    assert_eq!(l.scene.len(), alone("mirror.ply"));
}

#[test]
fn the_up_axis_turns_y_up_files_and_gltf_is_y_up_by_default() {
    let glb = formats("nested.glb");
    let z = load_path(&glb, &Z_UP).unwrap().scene;
    let default = load_path(&glb, &LoadOptions::default()).unwrap().scene;
    let y = LoadOptions {
        up: Some(Up::Y),
        ..LoadOptions::default()
    };
    let explicit = load_path(&glb, &y).unwrap().scene;
    assert_eq!(default.points, explicit.points);
    assert_eq!(z.len(), default.len());
    for (p, q) in z.points.iter().zip(&default.points) {
        assert_eq!(
            [q.x, q.y, q.z],
            [p.x, -p.z + 0.0, p.y],
            "(x, y, z) -> (x, -z, y)"
        );
    }
    // OBJ keeps Z unless told; --up y turns it the same way.
    let obj = formats("obj-suites/trimesh/two_objects.obj");
    let kept = load_path(&obj, &LoadOptions::default()).unwrap().scene;
    let turned = load_path(&obj, &y).unwrap().scene;
    assert_eq!(kept.len(), turned.len());
    let (a, b) = (kept.aabb(), turned.aabb());
    assert_eq!(
        [b.min.y, b.max.y, b.min.z, b.max.z],
        [-a.max.z, -a.min.z, a.min.y, a.max.y]
    );
}

/// Every OBJ file of tobj's and trimesh's test suites loads, or fails with one error line; the
/// expected failures are the files without faces and tobj's `invalid_index.obj`.
#[test]
fn obj_test_suites_of_other_parsers_load_or_fail_with_one_line() {
    let mut loaded = 0;
    let mut failed = Vec::new();
    for suite in ["tobj", "trimesh"] {
        let dir = formats(&format!("obj-suites/{suite}"));
        let mut names: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj")))
            .collect();
        names.sort();
        for path in names {
            match load_path(&path, &LoadOptions::default()) {
                Ok(l) => {
                    assert!(!l.scene.is_empty());
                    loaded += 1;
                }
                Err(e) => {
                    let msg = e.to_string();
                    assert!(!msg.contains('\n'), "{msg}");
                    assert!(msg.starts_with(&path.display().to_string()), "{msg}");
                    failed.push(path.file_name().unwrap().to_string_lossy().into_owned());
                }
            }
        }
    }
    failed.sort();
    assert_eq!(
        failed,
        [
            "empty.obj",
            "face_in_group_name.obj",
            "invalid_index.obj",
            "lines.obj",
            "obj_empty.obj",
            "obj_points.obj",
            "obj_wireframe.obj"
        ]
    );
    assert_eq!(loaded, 24);
}

#[test]
fn line_continuations_join_statements() {
    let obj = "v 0 0 0\nv 1 0 0\\\n\nv 0 1 0\nv 1 1 \\\n 0\nf 1 2 \\\n  4 \\\r\n 3\nf 1 2 x\n";
    let e = load_bytes("c.obj", obj.as_bytes().to_vec(), &LoadOptions::default()).unwrap_err();
    // The bad statement is on line 10; the statements continued before it were read whole.
    assert_eq!(
        e.problem,
        "not a valid OBJ file (line 10: bad face vertex \"x\")"
    );
    let ok = obj.replace("f 1 2 x\n", "");
    let l = load_bytes("c.obj", ok.into_bytes(), &LoadOptions::default()).unwrap();
    assert_eq!(l.scene.len(), 1);
    assert_eq!(l.scene.prim(0).len(), 4);
}

/// Runs `wraptree ARGS` in `dir`; its exit code and stderr.
#[test]
fn an_off_file_loads_as_the_same_mesh_as_its_obj() {
    // The bundled lamp (quads and polygons) written as OFF: its vertices, then each face's
    // vertex count and indices from 0.
    let obj = std::fs::read_to_string(repo("scenes/lamp.obj")).unwrap();
    let (mut verts, mut faces) = (Vec::new(), Vec::new());
    for line in obj.lines() {
        let mut w = line.split_whitespace();
        match w.next() {
            Some("v") => verts.push(w.take(3).collect::<Vec<_>>().join(" ")),
            Some("f") => {
                let idx: Vec<String> = w
                    .map(|t| {
                        let i: usize = t.split('/').next().unwrap().parse().unwrap();
                        (i - 1).to_string()
                    })
                    .collect();
                faces.push(format!("{} {}", idx.len(), idx.join(" ")));
            }
            _ => {}
        }
    }
    let off = format!(
        "OFF\n# the lamp\n{} {} 0\n{}\n{}\n",
        verts.len(),
        faces.len(),
        verts.join("\n"),
        faces.join("\n")
    );
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("lamp.off"), &off).unwrap();
    let a = load_path(&repo("scenes/lamp.obj"), &Z_UP).unwrap();
    let b = load_path(&tmp.path().join("lamp.off"), &Z_UP).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(b.scene.len(), a.scene.len());
    assert_eq!(b.scene.tris.len(), a.scene.tris.len());
    let (ba, bb) = (a.scene.aabb(), b.scene.aabb());
    assert_box("lamp.off", &bb, ba.min.into(), ba.max.into(), 0.0);
    // The command line reads it by its extension, and a truncated one is one error line.
    let (code, err) = run(&["group", "lamp.off"], tmp.path());
    assert_eq!(code, 0, "{err}");
    std::fs::write(tmp.path().join("cut.off"), &off[..off.len() / 2]).unwrap();
    let (code, err) = run(&["group", "cut.off"], tmp.path());
    assert_eq!(code, 1, "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("error: cut.off: not a valid OFF file ("),
        "{err}"
    );
}

fn run(args: &[&str], dir: &Path) -> (i32, String) {
    let out = common::wraptree(args, dir);
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn bad_input_in_every_format_is_one_error_line_and_exit_code_1() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let stl = std::fs::read(formats("idler_riser.STL")).unwrap();
    std::fs::write(d.join("truncated.stl"), &stl[..stl.len() - 120]).unwrap();
    let ply = std::fs::read_to_string(formats("sphere.ply")).unwrap();
    std::fs::write(
        d.join("counts.ply"),
        ply.replace("element face 1280", "element face 1290"),
    )
    .unwrap();
    let gltf = std::fs::read_to_string(formats("TestScene.gltf")).unwrap();
    std::fs::write(d.join("nobin.gltf"), &gltf).unwrap();
    let dae = std::fs::read_to_string(formats("two_parts.dae")).unwrap();
    std::fs::write(d.join("truncated.dae"), &dae[..dae.len() / 2]).unwrap();
    std::fs::write(
        d.join("badref.dae"),
        dae.replace("\"#box-mesh\"", "\"#nope\""),
    )
    .unwrap();
    std::fs::write(
        d.join("skew.dae"),
        dae.replace("<scale>2 1 1</scale>", "<skew>45 0 1 0 1 0 0</skew>"),
    )
    .unwrap();
    let mesh = |name: &str, file: &str| {
        format!(
            "<link name=\"{name}\"><visual><geometry><mesh filename=\"{file}\"/></geometry>\
             </visual></link>"
        )
    };
    let joint = |name: &str, p: &str, c: &str| {
        format!(
            "<joint name=\"{name}\" type=\"fixed\"><parent link=\"{p}\"/><child link=\"{c}\"/></joint>"
        )
    };
    std::fs::copy(formats("mirror.ply"), d.join("m.ply")).unwrap();
    let robot = |body: String| format!("<robot name=\"r\">{body}</robot>");
    let cases: Vec<(&str, String, &str)> = vec![
        (
            "missing-mesh.urdf",
            robot(mesh("a", "gone.stl")),
            "link 'a': mesh \"gone.stl\": cannot read",
        ),
        (
            "two-parents.urdf",
            robot(
                mesh("a", "m.ply")
                    + &mesh("b", "m.ply")
                    + &mesh("c", "m.ply")
                    + &joint("j1", "a", "c")
                    + &joint("j2", "b", "c"),
            ),
            "link 'c' has two parents (joints 'j1' and 'j2')",
        ),
        (
            "loop.urdf",
            robot(
                mesh("a", "m.ply")
                    + &mesh("b", "m.ply")
                    + &joint("j1", "a", "b")
                    + &joint("j2", "b", "a"),
            ),
            "the joints form a loop",
        ),
        (
            "dae.urdf",
            robot(mesh("a", "truncated.dae")),
            "link 'a': mesh \"truncated.dae\": not a valid COLLADA file (XML: ",
        ),
    ];
    for (name, text, _) in &cases {
        std::fs::write(d.join(name), text).unwrap();
    }
    std::fs::write(d.join("robot.xacro"), "<robot/>").unwrap();
    let mut expect: Vec<(&str, String)> =
        vec![
        (
            "truncated.stl",
            "not a valid STL file (truncated: the header says 1572 triangles, the file holds 1569"
                .into(),
        ),
        ("counts.ply", "not a valid PLY file (".into()),
        ("nobin.gltf", "buffer 0 (".into()),
        ("truncated.dae", "not a valid COLLADA file (XML: ".into()),
        (
            "badref.dae",
            "not a valid COLLADA file (<instance_geometry url=\"#nope\"> names no <geometry> of \
             this file)"
                .into(),
        ),
        ("skew.dae", "node 'arm': a <skew> transform is not read".into()),
        (
            "robot.xacro",
            "a xacro macro file: expand it to a URDF first".into(),
        ),
    ];
    expect.extend(cases.iter().map(|(n, _, p)| (*n, p.to_string())));
    for (file, problem) in expect {
        let (code, err) = run(&["group", file], d);
        assert_eq!(code, 1, "{file}: {err}");
        assert_eq!(err.lines().count(), 1, "{file}: {err}");
        let want = format!("error: {file}: {problem}");
        assert!(
            err.starts_with(&want),
            "{file}: {err:?} does not start with {want:?}"
        );
        assert!(!err.contains("panicked"));
    }
    let (code, err) = run(&["group", "loop.urdf", "--joint", "nope=1"], d);
    assert_eq!(code, 1, "{err}");
    let (code, err) = run(&["group", "m.ply", "--joint", "nonsense"], d);
    assert_eq!(code, 2, "a malformed --joint is a usage error: {err}");
}

#[test]
fn recordings_of_multi_file_inputs_replay_after_the_files_are_gone() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let src = d.join("src");
    std::fs::create_dir_all(&src).unwrap();
    for f in ["r2d2.urdf", "l_finger.stl", "l_finger_tip.stl"] {
        std::fs::copy(repo("scenes/r2d2").join(f), src.join(f)).unwrap();
    }
    for f in ["TestScene.gltf", "TestScene.bin", "idler_riser.STL"] {
        std::fs::copy(formats(f), src.join(f)).unwrap();
    }
    let record = |args: &[&str]| {
        let (code, err) = run(args, d);
        assert_eq!(code, 0, "{args:?}: {err}");
    };
    record(&[
        "record",
        "src/r2d2.urdf",
        "-o",
        "r2d2",
        "--detail",
        "merges",
        "--joint",
        "head_swivel=0.7",
        "--joint",
        "gripper_extension=-0.1",
        "--pregroup",
        "objects",
        "--instancing",
    ]);
    record(&[
        "record",
        "src/TestScene.gltf",
        "-o",
        "gltf",
        "--detail",
        "merges",
        "--up",
        "z",
    ]);
    record(&[
        "record",
        "src/idler_riser.STL",
        "-o",
        "stl",
        "--detail",
        "merges",
        "--up",
        "y",
    ]);
    // What was recorded, before the sources go.
    let loaded_now = |p: &str, opts: &LoadOptions, urdf: &UrdfOptions| -> Loaded {
        load_path_with(&d.join(p), opts, urdf).unwrap()
    };
    let urdf_opts = UrdfOptions {
        joints: vec![
            ("head_swivel".into(), 0.7),
            ("gripper_extension".into(), -0.1),
        ],
        ..UrdfOptions::default()
    };
    let r2d2 = loaded_now("src/r2d2.urdf", &LoadOptions::default(), &urdf_opts);
    let stl_up = LoadOptions {
        up: Some(Up::Y),
        ..LoadOptions::default()
    };
    let stl = loaded_now("src/idler_riser.STL", &stl_up, &UrdfOptions::default());
    std::fs::remove_dir_all(&src).unwrap();
    for prefix in ["r2d2", "gltf", "stl"] {
        let (code, err) = run(&["replay", &format!("{prefix}.mcap"), "--verify"], d);
        assert_eq!(code, 0, "{prefix}: {err}");
    }
    let r = wraptree::replay::open(&d.join("r2d2.mcap")).unwrap();
    assert_eq!(r.rec.scene_file_name, "r2d2.obj");
    assert_eq!(r.loaded.scene.points, r2d2.scene.points);
    assert_eq!(r.loaded.scene.objects, r2d2.scene.objects);
    // A single file is embedded byte for byte, with the up axis it was loaded with.
    let s = wraptree::replay::open(&d.join("stl.mcap")).unwrap();
    assert_eq!(s.rec.scene_file_name, "idler_riser.STL");
    assert_eq!(
        s.rec.scene_bytes,
        std::fs::read(formats("idler_riser.STL")).unwrap()
    );
    assert_eq!(s.rec.load_options.up, Some(Up::Y));
    assert_eq!(s.loaded.scene.points, stl.scene.points);
}

#[test]
fn a_split_scene_keeps_the_up_axis_it_was_loaded_with() {
    let y_up = LoadOptions {
        up: Some(Up::Y),
        ..LoadOptions::default()
    };
    let loaded = load_path(&formats("obj-suites/trimesh/tube.obj"), &y_up).unwrap();
    let before = loaded.scene.aabb();
    let (split, stats) = wraptree::scene::split::split_loaded(loaded, 2.0).unwrap();
    assert!(stats.split > 0);
    assert_eq!(
        split.source.options.up, None,
        "the split OBJ is already upright"
    );
    let after = split.scene.aabb();
    assert_box("split", &after, before.min.into(), before.max.into(), 1e-12);
}

/// `sphere.ply` (a closed icosphere of radius 1) with its vertices times `k`, as ASCII PLY;
/// and its number of triangles.
fn shrunk_sphere_ply(k: f64) -> (String, usize) {
    let text = std::fs::read_to_string(formats("sphere.ply")).unwrap();
    let (head, body) = text.split_once("end_header\n").unwrap();
    let count = |what: &str| -> usize {
        let line = head.lines().find_map(|l| l.strip_prefix(what)).unwrap();
        line.trim().parse().unwrap()
    };
    let (vertices, faces) = (count("element vertex "), count("element face "));
    let mut out = format!("{head}end_header\n");
    for (i, line) in body.lines().enumerate() {
        if i < vertices {
            let v: Vec<String> = line
                .split_whitespace()
                .map(|x| (x.parse::<f64>().unwrap() * k).to_string())
                .collect();
            out += &v.join(" ");
        } else {
            out += line;
        }
        out.push('\n');
    }
    (out, faces)
}

/// A URDF's sensor link a few micrometres across (its mesh in the file's millimetres, scaled by
/// 0.001), 60 units from the origin, beside a link of ordinary size: every face is kept, since
/// a face is judged by its own shape and never by the scene's size; the robot records and the
/// recording verifies. A needle in a link's mesh is still dropped, in a warning naming the URDF.
#[test]
fn a_micrometre_link_far_from_the_origin_keeps_every_face_and_records() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    std::fs::copy(formats("idler_riser.STL"), d.join("base.stl")).unwrap();
    let (ply, sensor_faces) = shrunk_sphere_ply(0.004);
    std::fs::write(d.join("sensor.ply"), ply).unwrap();
    let robot = |sensor_mesh: &str| {
        format!(
            "<robot name=\"arm\">\
             <link name=\"base\"><visual><geometry><mesh filename=\"base.stl\"/></geometry>\
             </visual></link>\
             <link name=\"sensor\"><visual><geometry><mesh filename=\"{sensor_mesh}\" \
             scale=\"0.001 0.001 0.001\"/></geometry></visual></link>\
             <joint name=\"mount\" type=\"fixed\"><parent link=\"base\"/><child link=\"sensor\"/>\
             <origin xyz=\"40 44 -5\" rpy=\"0.3 -0.2 1.1\"/></joint></robot>"
        )
    };
    std::fs::write(d.join("arm.urdf"), robot("sensor.ply")).unwrap();
    let l =
        load_path(&d.join("arm.urdf"), &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    let base_faces = load_path(&formats("idler_riser.STL"), &Z_UP)
        .unwrap()
        .scene
        .len();
    let mut per_link = [0usize; 2];
    for i in 0..l.scene.len() {
        per_link[l.scene.object(i) as usize] += 1;
    }
    assert_eq!(per_link, [base_faces, sensor_faces]);
    // The sensor is where the joint puts it, and as small as its file says (radius 4e-6).
    let sensor = Aabb::from_points(
        (0..l.scene.len())
            .filter(|&i| l.scene.object(i) == 1)
            .flat_map(|i| l.scene.prim_vertices(i)),
    );
    assert!(
        (sensor.center().coords.norm() - 59.674).abs() < 1e-3,
        "{sensor:?}"
    );
    assert!(
        sensor.diameter() > 1e-5 && sensor.diameter() < 1.4e-5,
        "{sensor:?}"
    );
    for args in [
        &[
            "record",
            "arm.urdf",
            "-o",
            "arm",
            "--wrapper",
            "sphere,hull,box,obb",
        ][..],
        &["replay", "arm.mcap", "--verify"],
    ] {
        let (code, err) = run(args, d);
        assert_eq!(code, 0, "{args:?}: {err}");
        assert!(!err.contains("dropped"), "{args:?}: {err}");
    }
    // The same link with one face a needle (its three corners on a line): that face alone goes.
    let mut obj = String::new();
    for i in 0..3 {
        obj += &format!("v {} 0 0\n", i as f64 * 1e-3);
    }
    obj += "v 0 1e-3 0\nf 1 2 4\nf 1 2 3\n";
    std::fs::write(d.join("needle.obj"), obj).unwrap();
    std::fs::write(d.join("needle.urdf"), robot("needle.obj")).unwrap();
    let l = load_path(&d.join("needle.urdf"), &LoadOptions::default()).unwrap();
    assert_eq!(l.scene.len(), base_faces + 1);
    assert_eq!(
        l.warnings,
        ["needle.urdf: dropped 1 degenerate faces (fewer than 3 distinct vertices or zero area)"]
    );
}

/// Asserts that the points `ours` and `theirs` are the same set, each within `tol` of one of
/// the other's.
fn assert_same_points(what: &str, ours: &[[f64; 3]], theirs: &[[f64; 3]], tol: f64) {
    let near = |p: &[f64; 3], set: &[[f64; 3]]| {
        set.iter()
            .any(|q| (0..3).all(|k| (p[k] - q[k]).abs() <= tol))
    };
    for p in theirs {
        assert!(near(p, ours), "{what}: their point {p:?} is not ours");
    }
    for p in ours {
        assert!(near(p, theirs), "{what}: our point {p:?} is not theirs");
    }
}

/// A COLLADA file (two geometries, one used twice, one through `<instance_node>`, placed by
/// nested translate/rotate/matrix/scale nodes, in centimetres) loads with the triangles and
/// the points trimesh with pycollada reads, those times the file's unit: in metres.
#[test]
fn collada_loads_as_trimesh_with_pycollada_places_it_in_metres() {
    let file = formats("two_parts.dae");
    let theirs = reader(&["mesh", &file.display().to_string()]);
    let t = &theirs[0];
    let unit = t["unit"].as_f64().unwrap();
    assert_eq!(unit, 0.01);
    let n = t["triangles"].as_u64().unwrap() as usize;
    assert_eq!((n, t["geometries"].as_u64()), (20, Some(3)));
    let l = load_path(&file, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    assert_eq!((l.scene.len(), l.scene.tris.len()), (n, n));
    let objects: std::collections::BTreeSet<u32> = l.scene.objects.iter().copied().collect();
    assert_eq!(objects.len(), 3, "one object per placed geometry");
    let ours: Vec<[f64; 3]> = l.scene.points.iter().map(|p| [p.x, p.y, p.z]).collect();
    let theirs: Vec<[f64; 3]> = t["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| xyz(p).map(|c| c * unit))
        .collect();
    let size = l.scene.aabb().diameter();
    assert_same_points("two_parts.dae", &ours, &theirs, 1e-6 * size);
    let (min, max) = (xyz(&t["min"]), xyz(&t["max"]));
    let scaled = |v: [f64; 3]| v.map(|c| c * unit);
    assert_box(
        "two_parts.dae",
        &l.scene.aabb(),
        scaled(min),
        scaled(max),
        1e-6,
    );
    // A single file: embedded byte for byte.
    assert_eq!(l.source.file_name, "two_parts.dae");
}

/// A COLLADA file alone is turned by its `<up_axis>` (Y when it names none, the
/// specification's default; `--up` overrides); as a URDF's mesh it is not, as in ROS.
#[test]
fn a_collada_up_axis_turns_the_file_alone_but_not_as_a_urdf_mesh() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let text = std::fs::read_to_string(formats("two_parts.dae")).unwrap();
    let variants = [
        ("z.dae", text.clone()),
        ("y.dae", text.replace("Z_UP", "Y_UP")),
        ("none.dae", text.replace("<up_axis>Z_UP</up_axis>", "")),
    ];
    for (name, t) in &variants {
        std::fs::write(d.join(name), t).unwrap();
    }
    let load = |name: &str, opts: &LoadOptions| load_path(&d.join(name), opts).unwrap().scene;
    let z = load("z.dae", &LoadOptions::default());
    for (name, opts) in [
        ("y.dae", LoadOptions::default()),
        ("none.dae", LoadOptions::default()),
    ] {
        let turned = load(name, &opts);
        assert_eq!(turned.len(), z.len());
        for (p, q) in z.points.iter().zip(&turned.points) {
            assert_eq!(
                [q.x, q.y, q.z],
                [p.x, -p.z + 0.0, p.y],
                "{name}: (x, y, z) -> (x, -z, y)"
            );
        }
    }
    assert_eq!(
        load("y.dae", &Z_UP).points,
        z.points,
        "--up z keeps a Y_UP file"
    );
    // In a URDF, visual and collision: the same points whatever the file's up axis.
    let robot = |mesh: &str| {
        format!(
            "<robot name=\"r\"><link name=\"a\"><visual><geometry><mesh filename=\"{mesh}\"/>\
             </geometry></visual><collision><origin xyz=\"0 0 1\"/><geometry>\
             <mesh filename=\"{mesh}\" scale=\"2 2 2\"/></geometry></collision></link></robot>"
        )
    };
    let mut seen = Vec::new();
    for (name, _) in &variants {
        let urdf = d.join(format!("{name}.urdf"));
        std::fs::write(&urdf, robot(name)).unwrap();
        let visual = load_path(&urdf, &LoadOptions::default()).unwrap().scene;
        let collision = UrdfOptions {
            collision: true,
            ..UrdfOptions::default()
        };
        let coll = load_path_with(&urdf, &LoadOptions::default(), &collision)
            .unwrap()
            .scene;
        assert_eq!((visual.len(), coll.len()), (z.len(), z.len()), "{name}");
        assert_eq!(visual.points, z.points, "{name}: the file's own axes");
        let (a, b) = (visual.aabb(), coll.aabb());
        assert!(
            (b.max.z - (2.0 * a.max.z + 1.0)).abs() < 1e-12,
            "{name}: {a:?} {b:?}"
        );
        seen.push(coll.points);
    }
    assert!(seen.windows(2).all(|w| w[0] == w[1]));
}
