//! `wraptree bench`: time the grouping phase on the standard scenes beside parry3d's binned
//! BVH build measured in the same run, and (with `--record`) what recording costs.

use anyhow::Result;
use clap::Args;
use std::process::ExitCode;
use std::time::Instant;
use wraptree::grouping::{self, Params};
use wraptree::record::Detail;
use wraptree::scene::{LoadOptions, Loaded, Scene, generate, load_bytes};

/// Arguments of `wraptree bench`.
#[derive(Args, Debug)]
pub struct BenchCmd {
    /// Largest soup size to include (10^4, 10^5, 10^6 by default).
    #[arg(long, default_value_t = 1_000_000)]
    max_soup: usize,
    /// Timed repetitions per case (the best is reported).
    #[arg(long, default_value_t = 3)]
    repeat: u32,
    /// Instead: measure recording (time and file sizes per --detail) on the 3,130- and
    /// 12,144-polygon scenes and a 10^5-triangle soup.
    #[arg(long)]
    record: bool,
}

fn best_of(repeat: u32, mut f: impl FnMut()) -> f64 {
    (0..repeat.max(1))
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn parry_binned(scene: &Scene) {
    use parry3d::bounding_volume::Aabb;
    let origin = scene.aabb().center();
    let leaves: Vec<Aabb> = (0..scene.len())
        .map(|i| {
            let b = scene.prim_aabb(i);
            Aabb::new(
                wraptree::geom::to_glam_local(&b.min, &origin),
                wraptree::geom::to_glam_local(&b.max, &origin),
            )
        })
        .collect();
    let bvh = parry3d::partitioning::Bvh::from_leaves(
        parry3d::partitioning::BvhBuildStrategy::Binned,
        &leaves,
    );
    std::hint::black_box(bvh);
}

/// A generated scene as if loaded from its OBJ (so recordings can embed it).
fn as_loaded(scene: &Scene) -> Result<Loaded> {
    let mut bytes = Vec::new();
    scene.write_obj(&mut bytes)?;
    Ok(load_bytes(
        &format!("{}.obj", scene.name),
        bytes,
        &LoadOptions::default(),
    )?)
}

impl BenchCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        if self.record {
            return self.run_record();
        }
        let mut cases: Vec<Scene> = vec![generate::soup(10_000, 1)];
        cases.push(generate::replicate(&generate::robot_base(), 44, 1));
        for n in [100_000, 1_000_000] {
            if n <= self.max_soup {
                cases.push(generate::soup(n, 1));
            }
        }
        println!(
            "{:<18} {:>9} {:>10} {:>9} {:>11} {:>10} {:>8} {:>6} {:>9}",
            "scene",
            "N",
            "group ms",
            "ns/prim",
            "ns/NlogN",
            "parry ms",
            "ratio",
            "depth",
            "peak MB"
        );
        let params = Params::default();
        for scene in &cases {
            let n = scene.len();
            let repeat = if n >= 1_000_000 {
                self.repeat.min(2)
            } else {
                self.repeat
            };
            let mut depth = 0;
            let t = best_of(repeat, || {
                let g = grouping::group(scene, &params, ());
                depth = g.tree.depth_max();
            });
            let tp = best_of(repeat, || parry_binned(scene));
            let nlogn = n as f64 * (n as f64).log2();
            println!(
                "{:<18} {:>9} {:>10.2} {:>9.0} {:>11.2} {:>10.2} {:>8.2} {:>6} {:>9.0}",
                scene.name,
                n,
                t * 1e3,
                t * 1e9 / n as f64,
                t * 1e9 / nlogn,
                tp * 1e3,
                t / tp,
                depth,
                super::peak_rss_bytes().unwrap_or(0) as f64 / 1e6
            );
        }
        println!(
            "ratio = grouping time / parry3d Bvh (Binned) build time on the same AABBs, same run."
        );
        println!("peak MB = process peak RSS after the case (cases run in increasing size).");
        Ok(ExitCode::SUCCESS)
    }

    fn run_record(&self) -> Result<ExitCode> {
        let lamp = generate::lamp();
        let cases = [
            generate::replicate(&lamp, 5, 1),
            generate::replicate(&generate::robot_base(), 44, 1),
            generate::soup(100_000, 1),
        ];
        let dir = tempfile::tempdir()?;
        println!(
            "{:<16} {:>7} {:>8} {:>9} {:>10} {:>7} {:>9} {:>9}",
            "scene", "N", "detail", "group ms", "record ms", "ratio", "rrd MB", "mcap MB"
        );
        for scene in &cases {
            let loaded = as_loaded(scene)?;
            let params = Params::default().resolve(&loaded.scene);
            let t_group = best_of(self.repeat, || {
                std::hint::black_box(grouping::group(&loaded.scene, &Params::default(), ()));
            });
            for detail in [Detail::Levels, Detail::Merges, Detail::Full] {
                let prefix = dir.path().join(format!("{}-{detail:?}", scene.name));
                let mut written = None;
                let t_rec = best_of(self.repeat, || {
                    written = Some(super::record::record(
                        &loaded.scene,
                        &loaded.source,
                        &params,
                        detail,
                        &prefix,
                        true,
                        true,
                    ));
                });
                let w = written.expect("ran at least once")?;
                let mb = |p: &std::path::Path| {
                    std::fs::metadata(p)
                        .map(|m| m.len() as f64 / 1e6)
                        .unwrap_or(0.0)
                };
                println!(
                    "{:<16} {:>7} {:>8} {:>9.1} {:>10.1} {:>7.2} {:>9.2} {:>9.2}",
                    scene.name,
                    scene.len(),
                    format!("{detail:?}").to_lowercase(),
                    t_group * 1e3,
                    t_rec * 1e3,
                    t_rec / t_group,
                    mb(&w.rrd),
                    mb(&w.mcap)
                );
            }
        }
        println!(
            "record ms = grouping with both recorders listening + sphere tree + writing both files."
        );
        println!("ratio = record ms / group ms (recording overhead is ratio - 1).");
        Ok(ExitCode::SUCCESS)
    }
}
