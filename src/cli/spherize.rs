//! `wraptree spherize`: per-link collision spheres for a robot (see [`wraptree::spherize`]);
//! writes the spherized URDF, its one-sphere-per-link `_1` level, cuRobo YAML, MoveIt SRDF,
//! the per-link trees as `.sph`, the scores as JSON, the run as `.rrd` and `.mcap`, and
//! figures of it with `--snapshot`.

use anyhow::{Context, Result, bail};
use clap::Args;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use wraptree::output::{Pending, check_new, output_dir, output_prefix, with_ext};
use wraptree::render::frames::Look;
use wraptree::scene::UrdfOptions;
use wraptree::scene::urdf::links::read_links;
use wraptree::spherize::{self, Limit, Report, Settings, write};

/// A sphere-set format `--format` names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum Format {
    /// Spherized URDF (PREFIX.urdf) and its one-sphere-per-link level (PREFIX_1.urdf).
    Urdf,
    /// cuRobo's collision_spheres YAML (PREFIX.yml).
    Curobo,
    /// MoveIt's SRDF link_sphere_approximation (PREFIX.srdf).
    Srdf,
    /// Each link's sphere tree in sphere-tree's .sph layout (PREFIX.sph/LINK.sph).
    Sph,
}

/// Arguments of `wraptree spherize`.
#[derive(Args, Debug)]
#[command(group(clap::ArgGroup::new("limit").required(true).args(["tolerance", "budget", "score"])))]
pub struct SpherizeCmd {
    /// The robot's URDF.
    robot: PathBuf,
    /// Read each link's collision geometry instead of its visual geometry.
    #[arg(long)]
    urdf_collision: bool,
    /// A joint's value, NAME=VALUE (radians, or metres for a prismatic joint); repeat for more.
    /// Spheres are in link frames either way; the recording shows the robot so posed.
    #[arg(long, value_name = "NAME=VALUE", value_parser = super::parse_joint, allow_hyphen_values = true)]
    joint: Vec<(String, f64)>,
    /// A folder to find package://NAME/… meshes in; repeatable, searched before
    /// ROS_PACKAGE_PATH and the URDF's own folders.
    #[arg(long, value_name = "DIR")]
    package_path: Vec<PathBuf>,
    /// The fewest spheres with every link's excess (distance from its spheres' boundary to its
    /// surface) within this length, in the URDF's units.
    #[arg(long, value_name = "LENGTH")]
    tolerance: Option<f64>,
    /// At most this many spheres in all, allocated across links to minimise the largest excess.
    #[arg(long, value_name = "K")]
    budget: Option<usize>,
    /// With --budget: the share by which the largest excess may exceed the least one the
    /// budget allows while its spheres are spent to lower the mean excess (0: not at all).
    #[arg(long, default_value_t = 0.1, value_name = "SHARE")]
    slack: f64,
    /// Refine each link's Subset Tree before its spheres are measured (the fast path's
    /// refinement): on some robots a lower largest excess, the mean either way.
    #[arg(long)]
    refine: bool,
    /// Score an existing sphere set (a spherized URDF or a cuRobo YAML) against the robot
    /// instead, the same way.
    #[arg(long, value_name = "SPHERES")]
    score: Option<PathBuf>,
    /// Formats to write, comma-separated.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "urdf,curobo,srdf,sph"
    )]
    format: Vec<Format>,
    /// Added to every written radius (a planner's safety margin).
    #[arg(long, default_value_t = 0.0, value_name = "LENGTH")]
    margin: f64,
    /// Smallest written radius.
    #[arg(long, default_value_t = 0.0, value_name = "LENGTH")]
    min_radius: f64,
    /// Output prefix [default: recordings/<robot stem>-spheres]; its directory must exist.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Do not record the run (PREFIX.rrd, PREFIX.mcap).
    #[arg(long)]
    no_record: bool,
    /// Also draw the robot, its links' sphere trees at a few depths and the cover as PNG + SVG
    /// figures into this directory (created if missing; iso view).
    #[arg(long, value_name = "DIR")]
    snapshot: Option<PathBuf>,
    /// Replace existing files.
    #[arg(long)]
    force: bool,
    /// Print the report as JSON instead of text.
    #[arg(long)]
    json: bool,
}

fn length(name: &str, v: f64) -> Result<f64> {
    if !(v.is_finite() && v >= 0.0) {
        bail!("--{name} must be a finite length ≥ 0, not {v}");
    }
    Ok(v)
}

impl SpherizeCmd {
    /// Runs the command.
    pub fn run(self) -> Result<ExitCode> {
        let margin = length("margin", self.margin)?;
        if !(self.slack.is_finite() && self.slack >= 0.0) {
            bail!("--slack must be a finite share ≥ 0, not {}", self.slack);
        }
        let min_radius = length("min-radius", self.min_radius)?;
        let limit = match (self.tolerance, self.budget) {
            (Some(t), _) => Some(Limit::Tolerance(length("tolerance", t)?)),
            (_, Some(0)) => bail!("--budget must be ≥ 1"),
            (_, Some(k)) => Some(Limit::Budget(k)),
            _ => None,
        };
        let mut package_path = self.package_path.clone();
        package_path.extend(UrdfOptions::ros_package_path());
        let opts = UrdfOptions {
            collision: self.urdf_collision,
            joints: self.joint.clone(),
            package_path,
        };
        let stop = wraptree::stop::Stop::on_signals();
        let links = read_links(&self.robot, &opts, &stop)?;
        for w in &links.warnings {
            eprintln!("warning: {w}");
        }
        let file_name = self
            .robot
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        if let Some(set_path) = &self.score {
            let set = spherize::read_set::read_set(set_path).map_err(anyhow::Error::msg)?;
            let score = spherize::score_set(&links.links, &set, &stop)?;
            if self.json {
                println!("{}", serde_json::to_string_pretty(&score)?);
            } else {
                let name = set_path.file_name().unwrap_or_default().to_string_lossy();
                print!("{}", spherize::score_text(&name, &score));
            }
            return Ok(ExitCode::SUCCESS);
        }
        let limit = limit.expect("clap requires one of the three");
        let prefix = output_prefix(self.output.as_deref(), &file_name, "-spheres")?;
        let mut paths: Vec<PathBuf> = vec![with_ext(&prefix, ".json")];
        for f in &self.format {
            match f {
                Format::Urdf => {
                    paths.push(with_ext(&prefix, ".urdf"));
                    paths.push(with_ext(&prefix, "_1.urdf"));
                }
                Format::Curobo => paths.push(with_ext(&prefix, ".yml")),
                Format::Srdf => paths.push(with_ext(&prefix, ".srdf")),
                Format::Sph => {}
            }
        }
        if !self.no_record {
            paths.push(with_ext(&prefix, ".rrd"));
            paths.push(with_ext(&prefix, ".mcap"));
        }
        if let Some(dir) = &self.snapshot {
            paths.push(dir.join("figure.png"));
        }
        let refs: Vec<&Path> = paths.iter().map(PathBuf::as_path).collect();
        check_new(&refs, &self.robot, self.force)?;
        let settings = Settings {
            limit,
            margin,
            min_radius,
            slack: self.slack,
            refine: self.refine,
        };
        let bar = super::progress::spinner("spherize");
        let done = spherize::spherize(links.links, settings, &stop);
        bar.finish_and_clear();
        // A setting the robot cannot meet (a budget below its links) names the robot.
        let done = done.map_err(|e| {
            if e.is::<wraptree::stop::Interrupted>() {
                e
            } else {
                anyhow::anyhow!("{}: {e}", self.robot.display())
            }
        })?;
        let report = Report::new(&links.robot.name, &done);
        let cover = done.cover_spheres();
        // Every output is written whole first and moved into place only once all are ready,
        // so a stop request before then leaves nothing.
        // Directories made for outputs go when empty, so they are dropped after the files.
        let mut dirs = Vec::new();
        let mut ready: Vec<Pending> = Vec::new();
        let mut put = |path: PathBuf, bytes: &[u8]| -> Result<()> {
            ready.push(Pending::with_bytes(&path, bytes, self.force)?);
            Ok(())
        };
        put(
            with_ext(&prefix, ".json"),
            &serde_json::to_vec_pretty(&report).context("spherize: cannot serialise")?,
        )?;
        for f in &self.format {
            match f {
                Format::Urdf => {
                    let text = write::urdf(&links.robot, &cover).map_err(anyhow::Error::msg)?;
                    put(with_ext(&prefix, ".urdf"), text.as_bytes())?;
                    let text = write::urdf(&links.robot, &done.top_spheres())
                        .map_err(anyhow::Error::msg)?;
                    put(with_ext(&prefix, "_1.urdf"), text.as_bytes())?;
                }
                Format::Curobo => {
                    put(
                        with_ext(&prefix, ".yml"),
                        write::curobo_yaml(&cover).as_bytes(),
                    )?;
                }
                Format::Srdf => {
                    let text = write::srdf(&links.robot.name, &cover);
                    put(with_ext(&prefix, ".srdf"), text.as_bytes())?;
                }
                Format::Sph => {
                    let dir = with_ext(&prefix, ".sph");
                    dirs.push(output_dir(Some(&dir), "")?);
                    for l in &done.links {
                        let spheres: Vec<_> =
                            l.tree.spheres.iter().map(|s| settings.planner(s)).collect();
                        let name: String = l
                            .link
                            .name
                            .chars()
                            .map(|c| {
                                if c.is_alphanumeric() || "-_.".contains(c) {
                                    c
                                } else {
                                    '_'
                                }
                            })
                            .collect();
                        let text = write::sph(&l.tree.tree, &spheres);
                        put(dir.join(format!("{name}.sph")), text.as_bytes())?;
                    }
                }
            }
        }
        stop.check()?;
        if !self.no_record {
            let (rrd, mcap) = (with_ext(&prefix, ".rrd"), with_ext(&prefix, ".mcap"));
            ready.extend(wraptree::record::spherize::record_spherized(
                &done,
                Some(&rrd),
                Some(&mcap),
                self.force,
            )?);
        }
        let figures = match &self.snapshot {
            Some(dir) => {
                let (az, el) = wraptree::render::View::Iso.angles();
                let look = Look {
                    azimuth: az,
                    elevation: el,
                    size: (800, 600),
                    force: self.force,
                };
                let view = wraptree::record::spherize::View::new(&done);
                Some(
                    wraptree::render::spheres::draw(&links.robot.name, &view, &look, dir, &stop)?.0,
                )
            }
            None => None,
        };
        stop.check()?;
        let mut written = Vec::with_capacity(ready.len());
        for p in ready {
            written.push(p.commit()?);
        }
        if let Some(f) = figures {
            written.extend(f.commit()?.into_iter().map(|(png, _)| png));
        }
        drop(dirs);
        if self.json {
            println!("{}", serde_json::to_string_pretty(&report)?);
        } else {
            print!("{}", report.text());
            println!("spherized in {:.2} s", done.seconds);
            let shown: Vec<String> = written
                .iter()
                .filter(|p| p.extension().is_none_or(|e| e != "sph"))
                .map(|p| p.display().to_string())
                .collect();
            println!("wrote {}", shown.join(", "));
        }
        Ok(ExitCode::SUCCESS)
    }
}
