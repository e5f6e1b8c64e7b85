//! Build a Subset Tree over a scene and ask it for the distance from a point to the scene,
//! counting the work the branch and bound did.
//!
//! `cargo run --release --example query_tree [X Y Z]` — default point (2, 0, 0), against 44
//! generated robot bases (12,144 polygons).

use wraptree::geom::P3;
use wraptree::grouping::{Params, group};
use wraptree::query::{Bv, Counts, Hierarchy, point_distance};
use wraptree::scene::generate;

fn main() -> anyhow::Result<()> {
    let xyz: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let p = match xyz[..] {
        [x, y, z] => P3::new(x, y, z),
        [] => P3::new(2.0, 0.0, 0.0),
        _ => anyhow::bail!("give a point as X Y Z"),
    };

    let scene = generate::replicate(&generate::robot_base(), 44, 1);
    let tree = group(&scene, &Params::default(), ()).tree;
    let h = Hierarchy {
        tree: &tree,
        scene: &scene,
        bv: Bv::Aabb,
    };
    let mut counts = Counts::default();
    let d = point_distance(&h, &p, &mut counts);

    println!(
        "scene {} ({} primitives), depth {}",
        scene.name,
        scene.len(),
        tree.depth_max()
    );
    println!("distance from {p} = {d:.9}");
    println!(
        "{} box tests, {} primitive tests",
        counts.bv_tests, counts.prim_tests
    );
    Ok(())
}
