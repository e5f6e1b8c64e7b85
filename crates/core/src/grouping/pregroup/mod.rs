//! Pre-grouping and instancing, the paper's speed-ups of §1.3 (`docs/method.md`, "Pre-grouping
//! and instancing"):
//!
//! 1. Components ([`components::connected`] or [`components::objects`]) of at least
//!    [`MIN_PART`] primitives are parts; smaller ones stay loose primitives of the top level.
//! 2. With instancing, parts that are rigid copies of an earlier part are found (`instancing`).
//! 3. Every other part is grouped on its own, in parallel, from its own DLimit0 (median body
//!    diameter) and GLimit0 in the run's ratio; the result is the same for any thread count.
//! 4. A copy takes its representative's Subset Tree shape, with boxes and diameters from its own
//!    primitives (an AABB does not rotate with its contents).
//! 5. The top level groups the loose primitives (increasing), then the part roots.
//!
//! Interior nodes are numbered part by part, then the top level's. Each part is announced by
//! [`Event::Part`], then its events follow with global ids and rounds; a [`Budget`]'s
//! `max_pairs` counts in that order. Only the AABB p-set is pre-grouped.

mod instancing;
mod remap;

pub use instancing::{COPY_TOLERANCE, kabsch};

use self::instancing::CopyOf;
use self::remap::{Buffer, IdMap, Remap};
use super::cluster::{self, fill_balance};
use super::{Budget, Grouping, Mode, Pregroup, ResolvedParams, Stats, Stopped, SubsetTree};
use crate::events::{Event, Merge, Observer, Part, PartKind};
use crate::geom::Aabb;
use crate::scene::Scene;
use crate::scene::components::{self, Components};
use rayon::prelude::*;

/// Components with fewer primitives than this stay as primitives in the top level: pieces of 2
/// or 3 primitives cost fewer instructions left loose, pieces of 5 or more grouped as parts
/// (`docs/method.md`, "Pre-grouping and instancing").
pub const MIN_PART: usize = 4;

/// What pre-grouping found and did in one run (printed by `wraptree group`, in `--json`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Pregrouping {
    /// The kind of components.
    pub pregroup: Pregroup,
    /// Whether copies were looked for.
    pub instancing: bool,
    /// Components found.
    pub components: u32,
    /// Components of at least [`MIN_PART`] primitives, grouped on their own or copied.
    pub parts: u32,
    /// Primitives of the smaller components, grouped at the top level.
    pub loose: u32,
    /// Instancing: classes of parts with at least one copy.
    pub classes: u32,
    /// Instancing: parts that took a representative's shape instead of being grouped.
    pub copies: u32,
    /// Instancing: primitives of those copies (not grouped).
    pub primitives_saved: u32,
    /// Bodies of the top level (loose primitives + part roots).
    pub top_bodies: u32,
    /// Worker threads available to the parts (rayon's current pool).
    pub threads: u32,
}

/// The parameters of a part over bodies `boxes`: its own DLimit0 (median body diameter, the
/// run's DLimit0 if that is 0) and GLimit0 in the run's ratio; the plain mode.
fn part_params(params: &ResolvedParams, boxes: &[Aabb]) -> ResolvedParams {
    let mut d: Vec<f64> = boxes.iter().map(Aabb::diameter).collect();
    let mid = d.len() / 2;
    let median = *d.select_nth_unstable_by(mid, f64::total_cmp).1;
    let dlimit0 = if median.is_finite() && median > 0.0 {
        median
    } else {
        params.dlimit0
    };
    ResolvedParams {
        dlimit0,
        glimit0: dlimit0 * (params.glimit0 / params.dlimit0),
        mode: Mode::default(),
        ..*params
    }
}

/// Runs one part with a buffer when `listen`.
fn run_part(
    boxes: Vec<Aabb>,
    params: &ResolvedParams,
    listen: bool,
    budget: &Budget<'_>,
) -> (Result<Grouping, Stopped>, Buffer) {
    let p = part_params(params, &boxes);
    let mut buf = Buffer::default();
    let r = if listen {
        cluster::run_boxes(boxes, &p, &mut buf, budget)
    } else {
        cluster::run_boxes(boxes, &p, (), budget)
    };
    (r, buf)
}

/// A part's grouping and its buffered events; `None` for a copy, which is not grouped.
type PartRun = Option<(Result<Grouping, Stopped>, Buffer)>;

/// The components of a run, which of them are parts, and which parts copy an earlier one.
struct Plan {
    comps: Components,
    /// Component indices of the parts (at least [`MIN_PART`] primitives), increasing.
    parts: Vec<u32>,
    /// Per part, with instancing: the earlier part it copies.
    copies: Vec<Option<CopyOf>>,
}

impl Plan {
    /// Finds the components (as `params.mode.pregroup` says), the parts and, with
    /// instancing, the copies.
    fn new(scene: &Scene, params: &ResolvedParams) -> Plan {
        let comps: Components = match params.mode.pregroup {
            Pregroup::Objects => components::objects(scene),
            Pregroup::Connected | Pregroup::None => components::connected(scene),
        };
        let parts: Vec<u32> = (0..comps.len() as u32)
            .filter(|&c| comps.get(c as usize).len() >= MIN_PART)
            .collect();
        let copies: Vec<Option<CopyOf>> = if params.mode.instancing {
            instancing::find(scene, &comps, &parts)
        } else {
            vec![None; parts.len()]
        };
        Plan {
            comps,
            parts,
            copies,
        }
    }

    /// The boxes of component `c`'s primitives, taken from `boxes`.
    fn gather(&self, c: u32, boxes: &[Aabb]) -> Vec<Aabb> {
        self.comps
            .get(c as usize)
            .iter()
            .map(|&i| boxes[i as usize])
            .collect()
    }

    /// Groups every part that is not a copy on its own, in parallel, buffering its events
    /// when `listen`.
    fn run_parts(
        &self,
        boxes: &[Aabb],
        params: &ResolvedParams,
        listen: bool,
        budget: &Budget<'_>,
    ) -> Vec<PartRun> {
        self.parts
            .par_iter()
            .zip(self.copies.par_iter())
            .map(|(&c, copy)| {
                copy.is_none()
                    .then(|| run_part(self.gather(c, boxes), params, listen, budget))
            })
            .collect()
    }

    /// What pre-grouping found; the top level's counts are filled in later.
    fn report(&self, params: &ResolvedParams) -> Pregrouping {
        let mut report = Pregrouping {
            pregroup: params.mode.pregroup,
            instancing: params.mode.instancing,
            components: self.comps.len() as u32,
            parts: self.parts.len() as u32,
            threads: rayon::current_num_threads() as u32,
            ..Pregrouping::default()
        };
        for (&c, _) in self
            .parts
            .iter()
            .zip(&self.copies)
            .filter(|(_, k)| k.is_some())
        {
            report.copies += 1;
            report.primitives_saved += self.comps.get(c as usize).len() as u32;
        }
        let mut reps: Vec<usize> = self.copies.iter().flatten().map(|c| c.of).collect();
        reps.sort_unstable();
        reps.dedup();
        report.classes = reps.len() as u32;
        report
    }

    /// The primitives of the components too small to be parts, increasing.
    fn loose(&self) -> Vec<u32> {
        let mut loose: Vec<u32> = (0..self.comps.len())
            .filter(|&c| self.comps.get(c).len() < MIN_PART)
            .flat_map(|c| self.comps.get(c).iter().copied())
            .collect();
        loose.sort_unstable();
        loose
    }
}

/// Each representative's merges, whose active flags its copies' merge events take (none
/// when nobody listens).
fn rep_merges(runs: &[PartRun], listen: bool) -> Vec<Vec<Merge>> {
    runs.iter()
        .map(|r| match r {
            Some((_, buf)) if listen => buf.merges().collect(),
            _ => Vec::new(),
        })
        .collect()
}

/// The whole run's tree under construction and its counters.
struct Assembly {
    n: usize,
    aabb: Vec<Aabb>,
    diameter: Vec<f64>,
    children: Vec<[u32; 2]>,
    stats: Stats,
    rounds: u32,
    parts: u32,
}

impl Assembly {
    /// The N leaves with boxes `boxes`, room for their N − 1 merges.
    fn new(boxes: Vec<Aabb>) -> Assembly {
        let n = boxes.len();
        let mut asm = Assembly {
            n,
            diameter: boxes.iter().map(Aabb::diameter).collect(),
            aabb: boxes,
            children: Vec::with_capacity(n - 1),
            stats: Stats::default(),
            rounds: 0,
            parts: 0,
        };
        asm.aabb.reserve(n - 1);
        asm.diameter.reserve(n - 1);
        asm
    }

    /// The id map of the next part, over global bodies `leaves`: its interior nodes and
    /// rounds follow those so far.
    fn next_map<'a>(&self, leaves: &'a [u32]) -> IdMap<'a> {
        IdMap {
            leaves,
            base: (self.n + self.children.len()) as u32,
            n: self.n as u32,
            round0: self.rounds,
        }
    }

    /// Appends the interior nodes of a part's tree, mapped to global ids; returns the part's
    /// global root.
    fn append(&mut self, g: &Grouping, map: IdMap<'_>) -> u32 {
        let k = g.tree.leaves();
        for (s, &[a, b]) in g.tree.children.iter().enumerate() {
            self.children.push([map.get(a), map.get(b)]);
            self.aabb.push(g.tree.aabb[k + s]);
            self.diameter.push(g.tree.diameter[k + s]);
        }
        self.rounds += g.rounds;
        let s = &g.stats;
        self.stats.eligible_pairs += s.eligible_pairs;
        self.stats.candidates += s.candidates;
        self.stats.pops += s.pops;
        self.stats.stale_pops += s.stale_pops;
        self.stats.peak_queue = self.stats.peak_queue.max(s.peak_queue);
        map.get(g.tree.root())
    }

    /// The [`Stopped`] of the whole run when part run `s` stopped.
    fn stopped(&self, s: Stopped) -> Stopped {
        Stopped {
            merges: self.children.len() as u32 + s.merges,
            rounds: self.rounds + s.rounds,
            eligible_pairs: self.stats.eligible_pairs + s.eligible_pairs,
            ..s
        }
    }

    /// Announces a part of `bodies` bodies.
    fn announce<O: Observer>(&mut self, observer: &mut O, kind: PartKind, bodies: usize) {
        observer.on_event(&Event::Part(Part {
            id: self.parts,
            kind,
            bodies: bodies as u32,
            first_step: self.children.len() as u32,
        }));
        self.parts += 1;
    }

    /// Gives copy `map` the shape of `rep`, with boxes from its own leaves; emits its merges
    /// (active flags from `rep_merges`, round = the last round started) unless the observer
    /// is silent.
    fn copy<O: Observer>(
        &mut self,
        rep: &Grouping,
        rep_merges: &[Merge],
        map: IdMap<'_>,
        params: &ResolvedParams,
        observer: &mut O,
    ) -> u32 {
        let silent = observer.is_silent();
        for (s, &[a, b]) in rep.tree.children.iter().enumerate() {
            let (ga, gb) = (map.get(a), map.get(b));
            let new = (self.n + self.children.len()) as u32;
            let merged = self.aabb[ga as usize].merge(&self.aabb[gb as usize]);
            let d = merged.diameter();
            self.children.push([ga, gb]);
            self.aabb.push(merged);
            self.diameter.push(d);
            if !silent {
                let (da, db) = (self.diameter[ga as usize], self.diameter[gb as usize]);
                let (fill, balance) = fill_balance(d, da, db);
                let from = rep_merges.get(s);
                observer.on_event(&Event::Merge(Merge {
                    step: new - self.n as u32,
                    round: self.rounds.saturating_sub(1),
                    a: ga,
                    b: gb,
                    new,
                    aabb: merged,
                    diameter: d,
                    fill,
                    balance,
                    cost: params.weights.cost(d, fill, balance),
                    queue_len: 0,
                    active: from.is_none_or(|m| m.active),
                }));
            }
        }
        map.get(rep.tree.root())
    }

    /// Appends every part in part order, announced: a grouped part by [`Assembly::add_part`], a
    /// copy by [`Assembly::copy`] with its representative's shape. Returns their global roots.
    fn add_parts<O: Observer>(
        &mut self,
        plan: &Plan,
        runs: &[PartRun],
        rep_merges: &[Vec<Merge>],
        params: &ResolvedParams,
        observer: &mut O,
        budget: &Budget<'_>,
    ) -> Result<Vec<u32>, Stopped> {
        let mut roots = Vec::with_capacity(plan.parts.len());
        for (j, &c) in plan.parts.iter().enumerate() {
            let root = match &plan.copies[j] {
                Some(copy) => {
                    let map = self.next_map(plan.comps.get(c as usize));
                    let (rep_result, _) = runs[copy.of].as_ref().expect("representatives are run");
                    // A representative that stopped has stopped the run before its copies.
                    let rep = rep_result
                        .as_ref()
                        .expect("copies follow a finished representative");
                    let kind = PartKind::Copy {
                        of: plan.parts[copy.of],
                        rotation: instancing::row_major(&copy.rotation),
                        translation: copy.translation.into(),
                    };
                    self.announce(observer, kind, map.leaves.len());
                    self.copy(rep, &rep_merges[copy.of], map, params, observer)
                }
                None => self.add_part(plan, c, &runs[j], params, observer, budget)?,
            };
            roots.push(root);
        }
        Ok(roots)
    }

    /// Announces part `c` and appends its grouping `run`, its buffered events replayed with
    /// global ids; a part that crosses the run's `max_pairs` is re-run alone with what is left,
    /// up to the stop. Returns the part's global root.
    fn add_part<O: Observer>(
        &mut self,
        plan: &Plan,
        c: u32,
        run: &PartRun,
        params: &ResolvedParams,
        observer: &mut O,
        budget: &Budget<'_>,
    ) -> Result<u32, Stopped> {
        let map = self.next_map(plan.comps.get(c as usize));
        self.announce(observer, PartKind::Component { index: c }, map.leaves.len());
        let (result, buf) = run.as_ref().expect("parts that are not copies are run");
        let max_pairs = budget.max_pairs.unwrap_or(u64::MAX);
        let room = max_pairs.saturating_sub(self.stats.eligible_pairs);
        let pairs = match result {
            Ok(g) => g.stats.eligible_pairs,
            Err(s) => s.eligible_pairs,
        };
        let rerun;
        let result = if pairs > room {
            let b = Budget {
                max_pairs: Some(room),
                ..*budget
            };
            let own = plan.gather(c, &self.aabb[..self.n]);
            let p = part_params(params, &own);
            rerun = cluster::run_boxes(own, &p, Remap::new(observer, map), &b);
            &rerun
        } else {
            buf.replay(&mut Remap::new(observer, map));
            result
        };
        match result {
            Ok(g) => Ok(self.append(g, map)),
            Err(s) => Err(self.stopped(*s)),
        }
    }

    /// Announces the top level and groups its bodies `top` (loose primitives, then part roots)
    /// within what is left of the run's `max_pairs`.
    fn group_top<O: Observer>(
        &mut self,
        top: &[u32],
        params: &ResolvedParams,
        observer: &mut O,
        budget: &Budget<'_>,
    ) -> Result<(), Stopped> {
        let top_boxes: Vec<Aabb> = top.iter().map(|&x| self.aabb[x as usize]).collect();
        self.announce(observer, PartKind::Top, top.len());
        let map = self.next_map(top);
        let b = Budget {
            max_pairs: budget
                .max_pairs
                .map(|m| m.saturating_sub(self.stats.eligible_pairs)),
            ..*budget
        };
        let p = part_params(params, &top_boxes);
        match cluster::run_boxes(top_boxes, &p, Remap::new(observer, map), &b) {
            Ok(g) => {
                self.append(&g, map);
                Ok(())
            }
            Err(s) => Err(self.stopped(s)),
        }
    }

    /// The finished run's tree of N − 1 merges, announced by `Finish`.
    fn finish<O: Observer>(
        self,
        params: &ResolvedParams,
        report: Pregrouping,
        observer: &mut O,
    ) -> Grouping {
        let merges = self.children.len() as u32;
        let tree = SubsetTree::new(self.aabb, self.diameter, self.children)
            .expect("parts and the top level make N - 1 valid merges");
        observer.on_event(&Event::Finish {
            root: tree.root(),
            rounds: self.rounds,
            merges,
        });
        Grouping {
            tree,
            rounds: self.rounds,
            params: *params,
            stats: self.stats,
            pregrouping: Some(report),
        }
    }
}

/// Runs the grouping phase with pre-grouping (and instancing) as `params.mode` says; see the
/// module doc. `params.pset` must be the AABB p-set.
pub(super) fn group_components<O: Observer>(
    scene: &Scene,
    params: &ResolvedParams,
    mut observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    assert!(!scene.is_empty(), "grouping needs at least one primitive");
    let plan = Plan::new(scene, params);
    let boxes: Vec<Aabb> = (0..scene.len()).map(|i| scene.prim_aabb(i)).collect();
    let listen = !observer.is_silent();
    let runs = plan.run_parts(&boxes, params, listen, budget);
    let mut report = plan.report(params);
    let mut asm = Assembly::new(boxes);
    let rep_merges = rep_merges(&runs, listen);
    let roots = asm.add_parts(&plan, &runs, &rep_merges, params, &mut observer, budget)?;
    // The top level: loose primitives (increasing), then the part roots (in part order).
    let mut top = plan.loose();
    report.loose = top.len() as u32;
    top.extend(&roots);
    report.top_bodies = top.len() as u32;
    asm.group_top(&top, params, &mut observer, budget)?;
    Ok(asm.finish(params, report, &mut observer))
}
