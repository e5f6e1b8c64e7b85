//! Recordings of a `wraptree spherize` run, `.rrd` and `.mcap`: each link's mesh and its
//! spheres at the chosen cover, posed as the robot stands, every sphere coloured by its excess
//! (green none, red the largest the cover may have or more, grey unmeasured), each link's tree cut at
//! depth d on the `level` timeline, and the budget's binary search probe by probe.

use std::path::Path;

use anyhow::Result;

use crate::geom::{P3, Sphere};
use crate::output::Pending;
use crate::scene::Scene;
use crate::spherize::{SHOWN_DEPTH, Spherized};

/// One link as drawn.
#[derive(Clone, Debug)]
pub struct LinkView {
    /// Link name, made safe for entity paths.
    pub name: String,
    /// Its mesh, posed.
    pub mesh: Scene,
    /// Its cover's spheres, posed, with their colours.
    pub cover: Vec<(Sphere, [f64; 4])>,
    /// Its tree cut at each depth 0..=[`SHOWN_DEPTH`], posed, with colours.
    pub levels: Vec<Vec<(Sphere, [f64; 4])>>,
}

/// A spherize run as drawn.
#[derive(Clone, Debug)]
pub struct View {
    /// Every link.
    pub links: Vec<LinkView>,
    /// The budget's probes: threshold and total spheres (`None`: over the budget).
    pub probes: Vec<(f64, Option<usize>)>,
    /// The summary line.
    pub summary: String,
}

/// The colour of a sphere of excess `e` against the largest allowed `t`.
pub fn excess_color(e: f64, t: f64) -> [f64; 4] {
    if e.is_nan() {
        return [0.6, 0.6, 0.6, 0.25];
    }
    let r = if t > 0.0 {
        (e / t).clamp(0.0, 1.0)
    } else {
        1.0
    };
    [r, 1.0 - 0.7 * r, 0.2, 0.35]
}

/// `s` as drawn: posed by `pose`.
fn posed(pose: impl Fn(&P3) -> P3, s: &Sphere) -> Sphere {
    Sphere {
        center: pose(&s.center),
        radius: s.radius,
    }
}

impl View {
    /// The drawing of `s`.
    pub fn new(s: &Spherized) -> View {
        // Colours run to the largest excess the cover may have (the budget's, with its slack).
        let t = s
            .allocation
            .spent
            .map_or(s.allocation.threshold, |x| x.limit);
        let links = s
            .links
            .iter()
            .map(|l| {
                let pose = |p: &P3| l.link.to_root(p);
                let mut mesh = l.link.mesh.clone();
                mesh.points = mesh.points.iter().map(pose).collect();
                let tree = &l.tree;
                let drawn_sphere = |sphere: &Sphere, excess: f64| {
                    let sphere = s.settings.planner(sphere);
                    (posed(pose, &sphere), excess_color(excess, t))
                };
                let drawn =
                    |x: u32| drawn_sphere(&tree.spheres[x as usize], tree.excess[x as usize]);
                let levels = (0..=SHOWN_DEPTH.min(tree.tree.depth_max()))
                    .map(|d| tree.tree.level(d).into_iter().map(drawn).collect())
                    .collect();
                LinkView {
                    name: l
                        .link
                        .name
                        .chars()
                        .map(|c| {
                            if c.is_ascii_alphanumeric() || c == '_' {
                                c
                            } else {
                                '_'
                            }
                        })
                        .collect(),
                    mesh,
                    cover: l
                        .spheres
                        .iter()
                        .map(|c| drawn_sphere(&c.sphere, c.excess))
                        .collect(),
                    levels,
                }
            })
            .collect();
        let n: usize = s.links.iter().map(|l| l.spheres.len()).sum();
        View {
            links,
            probes: s
                .allocation
                .probes
                .iter()
                .map(|p| (p.threshold, p.spheres))
                .collect(),
            summary: format!(
                "{} links, {n} spheres, largest node excess at most {:.4}",
                s.links.len(),
                t
            ),
        }
    }
}

/// Writes the run `s` to `rrd` and `mcap` (each if given), whole, but not yet moved into place:
/// the caller commits them ([`Pending::commit`]) once every output of the run is ready.
pub fn record_spherized(
    s: &Spherized,
    rrd: Option<&Path>,
    mcap: Option<&Path>,
    force: bool,
) -> Result<Vec<Pending>> {
    let view = View::new(s);
    let mut out = Vec::new();
    if let Some(p) = rrd {
        out.push(super::rrd::spherize::write(&view, p, force)?);
    }
    if let Some(p) = mcap {
        let file = Pending::create(p, force)?;
        super::mcap::spherize::write(&view, &file)?;
        out.push(file);
    }
    Ok(out)
}
