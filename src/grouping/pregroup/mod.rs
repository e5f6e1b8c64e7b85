//! Pre-grouping and instancing: the paper's speed-ups of §1.3 — "(1) component objects are
//! pre-grouped and processed separately first, and (2) repeated component groups are
//! processed separately and then copy-moved" — and the "boundary connectivity analysis to
//! pre-group the input" of the Figure 3 text.
//!
//! 1. Components: [`components::connected`] (primitives sharing welded vertices) or
//!    [`components::objects`] (the file's `o`/`g` objects), numbered by smallest primitive.
//! 2. Parts: components of at least [`MIN_PART`] primitives. Smaller components (a lone
//!    triangle, a six-face box) stay as primitives in the top level, so a soup of tiny pieces
//!    costs what the plain run costs (plus finding the components).
//! 3. With instancing, parts that are rigid copies of an earlier part are found
//!    (`instancing`); they are not grouped.
//! 4. Every other part is grouped by the grouping phase (`cluster::run_boxes`) on its own, in
//!    parallel (rayon). Each part starts its rounds from its own bodies: DLimit0 = the median
//!    diameter of its bodies, GLimit0 = DLimit0 × the run's GLimit0/DLimit0 (1/4 by default),
//!    so a part of small bolts does not wait for the scene's median (the run's own limits in
//!    every part measured within 2 % in instructions on 44 robot bases and 5 lamps). A part's
//!    result depends only on its own primitives, so the whole run is identical for any thread
//!    count.
//! 5. Every copy takes its representative's Subset Tree shape over its own primitives (the
//!    i-th primitive of the copy where the representative has its i-th), with boxes and
//!    diameters recomputed from its own geometry, since an AABB does not rotate with its
//!    contents.
//! 6. The top level groups, as bodies, the primitives of the small components (increasing) and
//!    then the parts' roots (in part order), with the same rule for its limits.
//!
//! **Numbering**: leaves `0..N` in input order; interior nodes part by part in part order
//! (component index order; a copy at its own place), each part's in its merge order, then the
//! top level's. **Events**: each part is announced by [`Event::Part`] (`Component` for a
//! grouped part, `Copy` with the representative's component index and the motion for a copy,
//! `Top` for the top level) followed by its events with global ids; rounds are numbered over
//! the whole run (a part's first round follows the previous part's last), and the run's
//! `rounds` counts them all. A copy has only merges (no rounds of its own: round = the last
//! round started, active flag from the representative's merge, queue length 0). Parts run in
//! parallel buffer their events only when the observer listens ([`Observer::is_silent`]).
//! **Limits**: a [`Budget`]'s `max_pairs` counts the pairs of every part in event order, as if
//! the parts ran one after another: the part that crosses it is re-run alone up to the stop.
//!
//! Only the AABB p-set is pre-grouped: `run` in [`super`] runs the plain §2.2 grouping for the
//! hull p-set (the CLI refuses the combination).

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

/// Components with fewer primitives than this stay as primitives in the top level.
///
/// Measured (callgrind, one thread, whole `wraptree group` process, 12,000 primitives in
/// pieces of k; as parts / loose / plain run): k = 2: 441 / 415 / 380 M instructions; k = 3:
/// 379 / 373 / 344 M; k = 5: 370 / 434 / 410 M; k = 8: 413 / 485 / 460 M.
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
}

/// Runs the grouping phase with pre-grouping (and instancing) as `params.mode` says; see the
/// module doc. `params.pset` must be the AABB p-set.
pub(super) fn run<O: Observer>(
    scene: &Scene,
    params: &ResolvedParams,
    mut observer: O,
    budget: &Budget<'_>,
) -> Result<Grouping, Stopped> {
    assert!(!scene.is_empty(), "grouping needs at least one primitive");
    let n = scene.len();
    let comps: Components = match params.mode.pregroup {
        Pregroup::Objects => components::objects(scene),
        Pregroup::Connected | Pregroup::None => components::connected(scene),
    };
    let boxes: Vec<Aabb> = (0..n).map(|i| scene.prim_aabb(i)).collect();
    let parts: Vec<u32> = (0..comps.len() as u32)
        .filter(|&c| comps.get(c as usize).len() >= MIN_PART)
        .collect();
    let copies: Vec<Option<CopyOf>> = if params.mode.instancing {
        instancing::find(scene, &comps, &parts)
    } else {
        vec![None; parts.len()]
    };
    let listen = !observer.is_silent();
    let gather = |c: u32, boxes: &[Aabb]| -> Vec<Aabb> {
        comps
            .get(c as usize)
            .iter()
            .map(|&i| boxes[i as usize])
            .collect()
    };
    let runs: Vec<Option<(Result<Grouping, Stopped>, Buffer)>> = parts
        .par_iter()
        .zip(copies.par_iter())
        .map(|(&c, copy)| {
            copy.is_none()
                .then(|| run_part(gather(c, &boxes), params, listen, budget))
        })
        .collect();
    let rep_merges: Vec<Vec<Merge>> = runs
        .iter()
        .map(|r| match r {
            Some((_, buf)) if listen => buf.merges().collect(),
            _ => Vec::new(),
        })
        .collect();

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
    let max_pairs = budget.max_pairs.unwrap_or(u64::MAX);
    let mut roots = Vec::with_capacity(parts.len());
    let mut report = Pregrouping {
        pregroup: params.mode.pregroup,
        instancing: params.mode.instancing,
        components: comps.len() as u32,
        parts: parts.len() as u32,
        threads: rayon::current_num_threads() as u32,
        ..Pregrouping::default()
    };
    for (j, &c) in parts.iter().enumerate() {
        let prims = comps.get(c as usize);
        let map = IdMap {
            leaves: prims,
            base: (n + asm.children.len()) as u32,
            n: n as u32,
            round0: asm.rounds,
        };
        if let Some(copy) = &copies[j] {
            let (rep_result, _) = runs[copy.of].as_ref().expect("representatives are run");
            // A representative that stopped has stopped the run before its copies.
            let rep = rep_result
                .as_ref()
                .expect("copies follow a finished representative");
            let kind = PartKind::Copy {
                of: parts[copy.of],
                rotation: instancing::row_major(&copy.rotation),
                translation: copy.translation.into(),
            };
            asm.announce(&mut observer, kind, prims.len());
            roots.push(asm.copy(rep, &rep_merges[copy.of], map, params, &mut observer));
            report.copies += 1;
            report.primitives_saved += prims.len() as u32;
            continue;
        }
        asm.announce(&mut observer, PartKind::Component { index: c }, prims.len());
        let (result, buf) = runs[j].as_ref().expect("parts that are not copies are run");
        let room = max_pairs.saturating_sub(asm.stats.eligible_pairs);
        let pairs = match result {
            Ok(g) => g.stats.eligible_pairs,
            Err(s) => s.eligible_pairs,
        };
        let rerun;
        let result = if pairs > room {
            // This part crosses the run's max_pairs: re-run it alone with what is left.
            let b = Budget {
                max_pairs: Some(room),
                ..*budget
            };
            let own = gather(c, &asm.aabb[..n]);
            let p = part_params(params, &own);
            rerun = cluster::run_boxes(own, &p, Remap::new(&mut observer, map), &b);
            &rerun
        } else {
            buf.replay(&mut Remap::new(&mut observer, map));
            result
        };
        match result {
            Ok(g) => roots.push(asm.append(g, map)),
            Err(s) => return Err(asm.stopped(*s)),
        }
    }
    report.classes = {
        let mut reps: Vec<usize> = copies.iter().flatten().map(|c| c.of).collect();
        reps.sort_unstable();
        reps.dedup();
        reps.len() as u32
    };

    // The top level: loose primitives (increasing), then the part roots (in part order).
    let mut top: Vec<u32> = (0..comps.len())
        .filter(|&c| comps.get(c).len() < MIN_PART)
        .flat_map(|c| comps.get(c).iter().copied())
        .collect();
    top.sort_unstable();
    report.loose = top.len() as u32;
    top.extend(&roots);
    report.top_bodies = top.len() as u32;
    let top_boxes: Vec<Aabb> = top.iter().map(|&x| asm.aabb[x as usize]).collect();
    asm.announce(&mut observer, PartKind::Top, top.len());
    let map = IdMap {
        leaves: &top,
        base: (n + asm.children.len()) as u32,
        n: n as u32,
        round0: asm.rounds,
    };
    let b = Budget {
        max_pairs: budget
            .max_pairs
            .map(|m| m.saturating_sub(asm.stats.eligible_pairs)),
        ..*budget
    };
    let p = part_params(params, &top_boxes);
    match cluster::run_boxes(top_boxes, &p, Remap::new(&mut observer, map), &b) {
        Ok(g) => {
            asm.append(&g, map);
        }
        Err(s) => return Err(asm.stopped(s)),
    }
    let merges = asm.children.len() as u32;
    let tree = SubsetTree::new(asm.aabb, asm.diameter, asm.children)
        .expect("parts and the top level make N - 1 valid merges");
    observer.on_event(&Event::Finish {
        root: tree.root(),
        rounds: asm.rounds,
        merges,
    });
    Ok(Grouping {
        tree,
        rounds: asm.rounds,
        params: *params,
        stats: asm.stats,
        pregrouping: Some(report),
    })
}
