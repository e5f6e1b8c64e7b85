//! Collision spheres for robots (`wraptree spherize`): per link, in the link's frame,
//! conservative, the fewest for their error, in the formats planners read.
//!
//! For each link with geometry ([`read_links`](crate::scene::urdf::links::read_links)): its
//! polygons cut into pieces of bounded edge ([`pieces`]), one Subset Tree over them with the
//! smallest enclosing sphere and the sampled excess of every node ([`link_tree`]), and a cover —
//! a cut of the tree — per link ([`allocate`]): the fewest spheres within a tolerance, or the
//! least robot-wide largest excess within a budget, allocated exactly across links. Each cover
//! is then [tightened](mod@tighten): its spheres give up the pieces other spheres hold, and the
//! spheres a budget frees are spent again. Every node's sphere holds all of the node's
//! vertices, hence its pieces, and tightening keeps every piece in some sphere, so every cover
//! holds the whole link: the spheres are conservative by construction.
//!
//! [`score`] measures a set the way the independent checker does, [`read_set`] reads existing
//! sets to score them, and [`write`](mod@write) writes URDF, cuRobo YAML, SRDF and `.sph` files.

pub mod allocate;
pub mod link_tree;
pub mod pieces;
pub mod read_set;
pub mod score;
pub mod spend;
pub mod tighten;
pub mod write;

use std::fmt::Write as _;
use std::time::Instant;

use anyhow::{Result, bail};

use crate::geom::Sphere;
use crate::grouping::{self, Params};
use crate::scene::urdf::links::Link;
use crate::stop::{Interrupted, Stop};
use allocate::Allocation;
use link_tree::LinkTree;
use rayon::prelude::*;
use read_set::SphereSet;
use score::Score;
use tighten::Tight;

/// Boundary samples per sphere when measuring a node's excess.
pub const NODE_SAMPLES: usize = 64;
/// Pieces are cut to edges of at most a link's box diagonal over this.
pub const PIECES_PER_DIAGONAL: f64 = 16.0;
/// Levels of every tree measured for the recording (depth ≤ this).
pub const SHOWN_DEPTH: u32 = 6;
/// With a budget, the mean's spending may split every node down to this depth ([`spend`]).
pub const MEAN_DEPTH: u32 = 8;
/// Pieces are never cut below a link's box diagonal over this.
pub const FINEST_PIECES: f64 = 256.0;
/// With a budget, how often the spheres tightening frees are spent again.
pub const RESPEND_ROUNDS: usize = 8;

/// What bounds the spheres.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Limit {
    /// The fewest spheres with every link's excess within this length.
    Tolerance(f64),
    /// The least largest excess with at most this many spheres in all.
    Budget(usize),
}

/// How spheres are chosen and written.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Settings {
    /// Tolerance or budget.
    pub limit: Limit,
    /// Added to every written radius (a planner's safety margin).
    pub margin: f64,
    /// Smallest written radius.
    pub min_radius: f64,
    /// With a budget: the share by which the largest excess may exceed the budget's least one
    /// while its spheres are spent to lower the mean excess ([`spend`]).
    pub slack: f64,
    /// Refine each link's Subset Tree before its spheres are measured ([`LinkTree::build`]).
    pub refine: bool,
}

impl Settings {
    /// `s` as written: radius plus the margin, at least the minimum radius.
    pub fn planner(&self, s: &Sphere) -> Sphere {
        Sphere {
            center: s.center,
            radius: (s.radius + self.margin).max(self.min_radius),
        }
    }
}

/// One link's result.
#[derive(Clone, Debug)]
pub struct LinkResult {
    /// The link and its mesh in its frame.
    pub link: Link,
    /// Longest piece edge its tree was built over.
    pub max_edge: f64,
    /// Its sphere tree.
    pub tree: LinkTree,
    /// The chosen cut, node ids sorted.
    pub cover: Vec<u32>,
    /// The cut's spheres, tightened ([`tighten`](mod@tighten)): as many or fewer.
    pub spheres: Vec<tighten::Tight>,
}

impl LinkResult {
    /// The largest excess of the cover's spheres.
    pub fn cover_excess(&self) -> f64 {
        self.spheres.iter().map(|t| t.excess).fold(0.0, f64::max)
    }
}

/// A spherized robot.
#[derive(Clone, Debug)]
pub struct Spherized {
    /// The settings.
    pub settings: Settings,
    /// Every link with geometry, in the URDF's order.
    pub links: Vec<LinkResult>,
    /// Spheres per link and the excess they keep to.
    pub allocation: Allocation,
    /// Wall time of [`spherize`].
    pub seconds: f64,
}

/// Spheres per link name, in link order.
pub type LinkSpheres = Vec<(String, Vec<Sphere>)>;

impl Spherized {
    /// The cover's spheres as written (margin, minimum radius).
    pub fn cover_spheres(&self) -> LinkSpheres {
        self.links
            .iter()
            .map(|l| {
                let v = l
                    .spheres
                    .iter()
                    .map(|t| self.settings.planner(&t.sphere))
                    .collect();
                (l.link.name.clone(), v)
            })
            .collect()
    }

    /// One sphere per link, each tree's root (the hierarchy's top level), as written.
    pub fn top_spheres(&self) -> LinkSpheres {
        self.links
            .iter()
            .map(|l| {
                let root = l.tree.tree.root() as usize;
                (
                    l.link.name.clone(),
                    vec![self.settings.planner(&l.tree.spheres[root])],
                )
            })
            .collect()
    }

    /// Scores `set` against the links (their meshes, distances through their trees).
    pub fn score(&self, set: &LinkSpheres) -> Score {
        score::total(
            self.links
                .iter()
                .map(|l| {
                    let spheres = set
                        .iter()
                        .find(|(n, _)| *n == l.link.name)
                        .map(|(_, s)| s.as_slice())
                        .unwrap_or(&[]);
                    score::score_link(
                        &l.link.name,
                        &l.link.mesh,
                        &l.tree.tree,
                        &l.tree.mesh,
                        spheres,
                    )
                })
                .collect(),
        )
    }
}

/// Builds every link's sphere tree and chooses the covers within `settings.limit`. Err: a
/// budget below the number of links, or [`Interrupted`] when `stop` is requested.
pub fn spherize(links: Vec<Link>, settings: Settings, stop: &Stop) -> Result<Spherized> {
    let start = Instant::now();
    if links.is_empty() {
        bail!("no link has geometry");
    }
    let mut out = Vec::with_capacity(links.len());
    let mut trees: Vec<LinkTree> = Vec::with_capacity(links.len());
    for link in links {
        stop.check()?;
        let diagonal = link.mesh.aabb().diameter();
        let mut max_edge = diagonal / PIECES_PER_DIAGONAL;
        if let Limit::Tolerance(t) = settings.limit {
            max_edge = max_edge.min(3f64.sqrt() * t);
        }
        let max_edge = max_edge.max(diagonal / FINEST_PIECES);
        let pieces = pieces::split_long_edges(&link.mesh, max_edge);
        trees.push(LinkTree::build(
            pieces,
            NODE_SAMPLES,
            settings.refine,
            stop,
        )?);
        out.push((link, max_edge));
    }
    let (covers, tight, allocation) = match settings.limit {
        Limit::Tolerance(t) => {
            let (covers, allocation) = allocate::by_tolerance(&mut trees, t, stop)?;
            let tight = tighten_all(&trees, &covers, stop)?;
            (covers, tight, allocation)
        }
        Limit::Budget(k) => {
            let (covers, mut allocation) =
                allocate::by_budget(&mut trees, k, stop)?.map_err(anyhow::Error::msg)?;
            for tree in trees.iter_mut() {
                let upper: Vec<u32> = (0..tree.tree.len() as u32)
                    .filter(|&x| tree.tree.depth[x as usize] <= MEAN_DEPTH)
                    .collect();
                tree.measure(&upper, stop)?;
            }
            let limit = allocation.threshold * (1.0 + settings.slack);
            // Tightening drops spheres; the budget they free is spent again, while it fits.
            let mut best: Option<Chosen> = None;
            let mut spend_k = k;
            for _ in 0..RESPEND_ROUNDS {
                let (covers, spent) = spend::by_mean(&trees, spend_k, limit, covers.clone(), stop)?;
                if best.as_ref().is_some_and(|b| b.covers == covers) {
                    break;
                }
                let tight = tighten_all(&trees, &covers, stop)?;
                let n: usize = tight.iter().map(Vec::len).sum();
                if n > k {
                    break;
                }
                best = Some(Chosen {
                    covers,
                    tight,
                    spent,
                });
                if n == k {
                    break;
                }
                spend_k += k - n;
            }
            let Chosen {
                covers,
                tight,
                spent,
            } = best.expect("the first spending fits the budget");
            allocation.per_link = tight.iter().map(Vec::len).collect();
            allocation.spent = Some(spent);
            (covers, tight, allocation)
        }
    };
    let mut links = Vec::with_capacity(out.len());
    for ((((link, max_edge), mut tree), cover), spheres) in
        out.into_iter().zip(trees).zip(covers).zip(tight)
    {
        let shown: Vec<u32> = (0..tree.tree.len() as u32)
            .filter(|&x| tree.tree.depth[x as usize] <= SHOWN_DEPTH)
            .collect();
        tree.measure(&shown, stop)?;
        links.push(LinkResult {
            link,
            max_edge,
            tree,
            cover,
            spheres,
        });
    }
    let out = links;
    Ok(Spherized {
        settings,
        links: out,
        allocation,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Covers chosen within a budget: the cuts, tightened, and what their spending reached.
struct Chosen {
    covers: Vec<Vec<u32>>,
    tight: Vec<Vec<Tight>>,
    spent: spend::Spent,
}

/// Every link's cover tightened, in parallel.
fn tighten_all(
    trees: &[LinkTree],
    covers: &[Vec<u32>],
    stop: &Stop,
) -> Result<Vec<Vec<Tight>>, Interrupted> {
    trees
        .par_iter()
        .zip(covers)
        .map(|(t, c)| tighten::tighten(t, c, stop))
        .collect()
}

/// Scores an existing `set` against `links` (each link's mesh grouped for its distances);
/// stops with [`Interrupted`] when `stop` is requested.
pub fn score_set(links: &[Link], set: &SphereSet, stop: &Stop) -> Result<Score> {
    let mut per = Vec::with_capacity(links.len());
    for l in links {
        stop.check()?;
        let params = Params::default().resolve(&l.mesh);
        let tree = grouping::group_until(&l.mesh, &params, (), stop.flag())
            .map_err(|_| Interrupted)?
            .tree;
        let spheres = set.get(&l.name).map(Vec::as_slice).unwrap_or(&[]);
        per.push(score::score_link(&l.name, &l.mesh, &tree, &l.mesh, spheres));
    }
    let mut s = score::total(per);
    for (name, spheres) in set {
        if !links.iter().any(|l| l.name == *name) && !spheres.is_empty() {
            s.spheres += spheres.len();
            s.links_not_in_robot.push(name.clone());
        }
    }
    Ok(s)
}

/// What `wraptree spherize` writes as JSON: the settings, the allocation, each link's tree
/// and cover, and the scores of the cover and of the one-sphere-per-link level.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Report {
    /// The robot's name.
    pub robot: String,
    /// The settings.
    pub settings: Settings,
    /// Boundary samples per sphere for the node excess.
    pub node_samples: usize,
    /// The allocation (and the budget's probes).
    pub allocation: Allocation,
    /// Per link: triangles, pieces, tree size and depth, spheres and largest node excess.
    pub links: Vec<LinkInfo>,
    /// Score of the cover's spheres as written.
    pub score: Score,
    /// Score of one sphere per link (the `_1` level).
    pub top_score: Score,
}

/// One link in a [`Report`].
#[derive(Clone, Debug, serde::Serialize)]
pub struct LinkInfo {
    /// Link name.
    pub link: String,
    /// Triangles of its mesh.
    pub triangles: usize,
    /// Pieces its tree is built over.
    pub pieces: usize,
    /// Longest piece edge.
    pub max_edge: f64,
    /// Depth of its tree.
    pub depth: u32,
    /// Spheres in its cover.
    pub spheres: usize,
    /// Largest node excess of its cover.
    pub cover_excess: f64,
}

impl Report {
    /// The report of `s` for robot `robot`.
    pub fn new(robot: &str, s: &Spherized) -> Report {
        Report {
            robot: robot.to_string(),
            settings: s.settings,
            node_samples: NODE_SAMPLES,
            allocation: s.allocation.clone(),
            links: s
                .links
                .iter()
                .map(|l| LinkInfo {
                    link: l.link.name.clone(),
                    triangles: l.link.mesh.tris.len(),
                    pieces: l.tree.mesh.len(),
                    max_edge: l.max_edge,
                    depth: l.tree.tree.depth_max(),
                    spheres: l.spheres.len(),
                    cover_excess: l.cover_excess(),
                })
                .collect(),
            score: s.score(&s.cover_spheres()),
            top_score: s.score(&s.top_spheres()),
        }
    }

    /// The printed summary: one line per link, the totals, and the `_1` level's totals.
    pub fn text(&self) -> String {
        let mut out = String::new();
        let limit = match self.settings.limit {
            Limit::Tolerance(t) => format!("tolerance {t}"),
            Limit::Budget(k) => format!("budget {k}"),
        };
        let _ = writeln!(
            out,
            "{}: {} links, {limit}: {} spheres, largest node excess {:.4}{}",
            self.robot,
            self.links.len(),
            self.score.spheres,
            self.allocation.threshold,
            match self.allocation.spent {
                Some(x) if x.limit > self.allocation.threshold => format!(
                    " (the least; spent on the mean within {:.4}, sampled mean {:.4})",
                    x.limit, x.mean
                ),
                Some(x) => format!(" (sampled mean {:.4})", x.mean),
                None => String::new(),
            }
        );
        let _ = writeln!(
            out,
            "{:<28} {:>7} {:>9} {:>9} {:>10} {:>10} {:>7}",
            "link", "spheres", "uncovered", "outside", "excess max", "mean", "volume"
        );
        let mm = |x: f64| format!("{:.1} mm", x * 1000.0);
        // A flat link (a disc, a plate) has no volume to compare with.
        let ratio = |x: f64| {
            if x.is_finite() {
                format!("{x:.2}×")
            } else {
                "—".into()
            }
        };
        let outside = |x: f64| {
            if x > score::SLACK {
                mm(x)
            } else {
                "—".into()
            }
        };
        for l in self.score.per_link.iter() {
            let _ = writeln!(
                out,
                "{:<28} {:>7} {:>8.2}% {:>9} {:>10} {:>10} {:>7}",
                l.link,
                l.spheres,
                l.uncovered * 100.0,
                outside(l.outside_max),
                mm(l.excess_max),
                mm(l.excess_mean),
                ratio(l.volume_ratio)
            );
        }
        for (name, s) in [("all", &self.score), ("one per link (_1)", &self.top_score)] {
            let _ = writeln!(
                out,
                "{:<28} {:>7} {:>8.2}% {:>9} {:>10} {:>10} {:>7}",
                name,
                s.spheres,
                s.uncovered * 100.0,
                outside(s.outside_max),
                mm(s.excess_max),
                mm(s.excess_mean),
                ratio(s.volume_ratio)
            );
        }
        out
    }
}

/// The printed summary of a score (`wraptree spherize --score`).
pub fn score_text(name: &str, s: &Score) -> String {
    let extra = if s.links_not_in_robot.is_empty() {
        String::new()
    } else {
        format!(
            " (and on {} links without geometry: {})",
            s.links_not_in_robot.len(),
            s.links_not_in_robot.join(", ")
        )
    };
    let outside = if s.outside_max > score::SLACK {
        format!("{:.1} mm", s.outside_max * 1000.0)
    } else {
        "—".into()
    };
    format!(
        "{name}: {} spheres on {}/{} links{extra}, uncovered {:.2} % (deepest {outside} outside), excess \
         max {:.1} mm mean {:.1} mm, volume {:.2}× the mesh's\n",
        s.spheres,
        s.links - s.links_without_spheres.len(),
        s.links,
        s.uncovered * 100.0,
        s.excess_max * 1000.0,
        s.excess_mean * 1000.0,
        s.volume_ratio
    )
}
