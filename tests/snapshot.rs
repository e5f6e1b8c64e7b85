//! `wraptree snapshot` end to end on a tiny scene, and the renderer's ordering and framing.

mod common;

use common::wraptree;

use resvg::{tiny_skia::Pixmap, usvg};
use std::path::{Path, PathBuf};
use std::process::Output;
use wraptree::geom::{Aabb, P3};
use wraptree::render::{self, Camera, Frame, Shape, Style};

/// Four triangles in two far-apart pairs: the tree is ((t0, t1), (t2, t3)), depth 2.
fn tiny_scene(dir: &Path) -> PathBuf {
    let mut obj = String::new();
    for (k, x) in [0.0, 0.3, 10.0, 10.3].iter().enumerate() {
        obj += &format!("v {x} 0 0\nv {} 0 0\nv {x} 0.2 0.5\n", x + 0.2);
        obj += &format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
    }
    let p = dir.join("tiny.obj");
    std::fs::write(&p, obj).unwrap();
    p
}

const NAMES: [&str; 4] = [
    "frame-00-input",
    "frame-01-level-0",
    "frame-02-level-1",
    "figure",
];

fn snapshot(dir: &Path, input: &Path, out: &str) -> Output {
    let args = [
        "snapshot",
        input.to_str().unwrap(),
        "--levels",
        "0,1",
        "--size",
        "200x150",
        "-o",
        out,
    ];
    wraptree(&args, dir)
}

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn read(dir: &Path, name: &str) -> Vec<u8> {
    std::fs::read(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn count(svg: &[u8], tag: &str) -> usize {
    String::from_utf8_lossy(svg).matches(tag).count()
}

#[test]
fn frames_and_sheet_are_written_and_deterministic() {
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_scene(dir.path());
    ok(&snapshot(dir.path(), &scene, "a"));
    ok(&snapshot(dir.path(), &scene, "b"));
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    for name in NAMES {
        for ext in ["png", "svg"] {
            let f = format!("{name}.{ext}");
            assert_eq!(read(&a, &f), read(&b, &f), "{f} differs between runs");
        }
        let svg = read(&a, &format!("{name}.svg"));
        usvg::Tree::from_data(&svg, &render::png::options()).expect("the SVG parses");
        let png = Pixmap::decode_png(&read(&a, &format!("{name}.png"))).expect("PNG decodes");
        if name != "figure" {
            // 200x150 picture + an 18-pixel caption band.
            assert_eq!((png.width(), png.height()), (200, 168), "{name}");
        } else {
            assert!(
                png.width() > 400 && png.height() > 168,
                "sheet holds the tiles"
            );
        }
    }
    let svg = |n: &str| read(&a, &format!("{n}.svg"));
    assert_eq!(count(&svg(NAMES[0]), "<path"), 4, "input: four polygons");
    assert_eq!(count(&svg(NAMES[0]), "<circle"), 0);
    assert_eq!(
        count(&svg(NAMES[1]), "<circle"),
        1,
        "level 0: the root sphere"
    );
    assert_eq!(count(&svg(NAMES[1]), "<path"), 0);
    assert_eq!(count(&svg(NAMES[2]), "<circle"), 2, "level 1: two spheres");
    assert_eq!(
        count(&svg(NAMES[3]), "<circle"),
        3,
        "sheet: 0 + 1 + 2 spheres"
    );
    assert_eq!(count(&svg(NAMES[3]), "<path"), 4);
    assert!(String::from_utf8_lossy(&svg(NAMES[2])).contains("level 1 · 2 nodes"));
    assert_ne!(
        read(&a, "frame-01-level-0.png"),
        read(&a, "frame-02-level-1.png"),
        "levels draw differently"
    );
}

#[test]
fn a_recording_gives_the_same_images_as_its_scene() {
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_scene(dir.path());
    let rec = wraptree(
        &[
            "record",
            scene.to_str().unwrap(),
            "-o",
            "rec",
            "--reproducible",
        ],
        dir.path(),
    );
    ok(&rec);
    ok(&snapshot(dir.path(), &scene, "from-scene"));
    ok(&snapshot(
        dir.path(),
        &dir.path().join("rec.mcap"),
        "from-mcap",
    ));
    for name in NAMES {
        for ext in ["png", "svg"] {
            let f = format!("{name}.{ext}");
            assert_eq!(
                read(&dir.path().join("from-scene"), &f),
                read(&dir.path().join("from-mcap"), &f),
                "{f}"
            );
        }
    }
    let mcap = dir.path().join("rec.mcap");
    let out = wraptree(
        &["snapshot", mcap.to_str().unwrap(), "--a", "2", "-o", "x"],
        dir.path(),
    );
    common::assert_one_line_error(&out, "do not apply to a recording");
}

#[test]
fn bad_values_give_one_error_line_and_nothing_is_clobbered() {
    let dir = tempfile::tempdir().unwrap();
    let scene = tiny_scene(dir.path());
    let s = scene.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["snapshot", s, "-o", "out"];
        args.extend_from_slice(extra);
        wraptree(&args, dir.path())
    };
    common::assert_one_line_error(&run(&["--wrapper", "cone"]), "valid: sphere, hull, box");
    common::assert_one_line_error(&run(&["--view", "diag"]), "valid: iso, front, side, top");
    common::assert_one_line_error(&run(&["--levels", "9"]), "max depth 2");
    common::assert_one_line_error(&run(&["--size", "10x10"]), "WxH");
    common::assert_one_line_error(&run(&["--elevation", "95"]), "--elevation");
    ok(&run(&["--levels", "1"]));
    let before = read(&dir.path().join("out"), "figure.png");
    common::assert_one_line_error(&run(&["--levels", "2"]), "already exists");
    assert_eq!(read(&dir.path().join("out"), "figure.png"), before);
    assert!(!dir.path().join("out/frame-01-level-2.png").exists());
    ok(&run(&[
        "--levels",
        "2",
        "--force",
        "--wrapper",
        "hull,box,obb",
    ]));
    assert!(dir.path().join("out/frame-03-level-2-obb.svg").exists());
}

fn poly(z: f64, opacity: f64) -> Shape {
    Shape::Polygon {
        points: vec![
            P3::new(0.0, 0.0, z),
            P3::new(1.0, 0.0, z),
            P3::new(0.0, 1.0, z),
        ],
        style: Style {
            opacity,
            stroke_width: 0.0,
            ..Style::INPUT
        },
    }
}

#[test]
fn painter_order_is_far_to_near_and_the_camera_frames_everything() {
    // Seen from the top, z = 1 is nearer than z = 0, whatever the input order.
    let frame = Frame {
        shapes: vec![poly(1.0, 0.91), poly(0.0, 0.37)],
        caption: "t".into(),
    };
    let cam = render::fit_camera(std::slice::from_ref(&frame), 0.0, 90.0, (100, 80));
    let svg = render::frame_svg(&frame, &cam);
    let near = svg.find("fill-opacity=\"0.91\"").unwrap();
    let far = svg.find("fill-opacity=\"0.37\"").unwrap();
    assert!(far < near, "the far polygon is drawn first:\n{svg}");
    let b = Aabb::from_points(&[P3::new(-3.0, 2.0, 1.0), P3::new(5.0, 4.0, 7.0)]);
    let frame = Frame {
        shapes: vec![Shape::aabb(&b, Style::BOX)],
        caption: String::new(),
    };
    for (az, el) in [(0.0, 0.0), (45.0, 35.0), (200.0, -60.0), (10.0, 90.0)] {
        let cam: Camera = render::fit_camera(std::slice::from_ref(&frame), az, el, (300, 200));
        for f in frame.shapes.iter().flat_map(Shape::extent) {
            let (x, y, _) = cam.project(&f.0);
            assert!(
                (0.0..=300.0).contains(&x) && (0.0..=200.0).contains(&y),
                "{az} {el}"
            );
        }
    }
}

#[test]
fn node_targets_pick_the_closest_level() {
    let counts = [1, 2, 8, 30, 104, 251, 276];
    assert_eq!(render::level_for_nodes(&counts, 251), 5);
    assert_eq!(render::level_for_nodes(&counts, 100), 4);
    assert_eq!(
        render::level_for_nodes(&counts, 5),
        1,
        "tie goes to the shallower level"
    );
    assert_eq!(render::level_for_nodes(&counts, 10_000), 6);
}
