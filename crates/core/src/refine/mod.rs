//! Refinement of a finished Subset Tree (the grouping's or any peer's) to a lower SAH
//! ([`crate::grouping::sah`]): treelet restructuring (Karras and Aila 2013, [`treelet`]), then
//! insertion-based optimisation (Bittner, Hapala and Havran 2013) in the parallel form of
//! Meister and Bittner 2018 ([`reinsert`]). See `docs/method.md`, "Refinement after the
//! grouping".
//!
//! A run is `treelet_passes` treelet passes (a pass that rebuilds nothing ends them), then up to
//! `passes` reinsertion passes. Reinsertion pass k searches, in parallel on the frozen tree, new
//! places for the first ⌈batch × (2N − 2) / (2k + 1)⌉ nodes ranked by [`reinsert::candidates`],
//! then applies the moves best first, each re-checked on the current tree. The shrinking batches
//! (1, 1/3, 1/5, …, as obvhs does) spend the later passes on the large nodes near the top; a pass
//! that keeps no move ends the run. A rebuilt treelet or a move is kept only when it lowers the
//! SAH by more than 10⁻¹² of the root's area, and each kept one is a [`Step`] event
//! (`Event::Refine`). What holds for every input is listed at [`refine`].

pub use crate::events::{RefineParams, Step, StepKind};

pub mod reinsert;
pub mod renumber;
pub mod treelet;
pub mod work;

use crate::geom::area;
use crate::grouping::{Event, Observer, SubsetTree};
use crate::grouping::{sah, sah_of_sums};
use crate::par::{POOL_MIN, on_pool};
use work::WorkTree;

/// The fast path's refinement (`--fast`, bench method `fast`) from [`FAST_SMALL`] leaves up,
/// after the partitioned grouping with
/// [`Chunking::FAST`](crate::grouping::partitioned::Chunking::FAST): one pass of small
/// treelets low in the tree, then two reinsertion passes. The split leaves
/// its lowest levels as binned cuts made without regard to their neighbours; treelets of 5
/// leaves at every node of at least 8 rebuild them optimally, which the reinsertion's
/// candidates (children of large, inefficient parents) seldom reach; against reinsertion
/// passes alone it gives trees at or below the best peer's on more meshes for a little more
/// time (`docs/benchmarks.md`). Pass k of the reinsertion searches a fixed share of the
/// nodes, so the work stays proportional to the tree's size. Larger treelets give better
/// trees in more time; smaller ones, or treelets rooted only higher up, worse ones.
pub const FAST: RefineParams = RefineParams {
    passes: 2,
    batch: 0.1,
    treelet: 5,
    treelet_passes: 1,
    treelet_min: 8,
};

/// Trees of at least this many leaves take [`FAST_LARGE_BATCH`] in [`fast_for`] (2^14).
pub const FAST_LARGE: usize = 1 << 14;

/// The first batch of the fast path's refinement on trees of at least [`FAST_LARGE`] leaves:
/// 7 % of the nodes instead of 10 %: on large trees the smaller batch loses no SAH and saves
/// time; on small ones it costs SAH, so they keep 10 %.
pub const FAST_LARGE_BATCH: f64 = 0.07;

/// Trees of fewer leaves than this take [`FAST_SMALL_PARAMS`] in [`fast_for`] (2^10).
pub const FAST_SMALL: usize = 1 << 10;

/// The fast path's refinement below [`FAST_SMALL`] leaves: three reinsertion passes and no
/// treelet pass. So small a tree is built in microseconds, and there the treelet pass costs a
/// large share of the build for little gain.
pub const FAST_SMALL_PARAMS: RefineParams = RefineParams {
    passes: 3,
    treelet_passes: 0,
    ..FAST
};

/// Which parameters a refinement starts from: the default ones, or the fast path's for the
/// tree's size ([`fast_for`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
pub enum Refinement {
    /// [`RefineParams::default`].
    Default,
    /// The fast path's: [`fast_for`] the tree's size.
    Fast,
}

impl Refinement {
    /// The parameters for a tree of `n` leaves.
    pub fn params(self, n: usize) -> RefineParams {
        match self {
            Refinement::Default => RefineParams::default(),
            Refinement::Fast => fast_for(n),
        }
    }
}

/// The fast path's refinement for a tree of `n` leaves: [`FAST`], with a first batch of
/// [`FAST_LARGE_BATCH`] from [`FAST_LARGE`] leaves up, or [`FAST_SMALL_PARAMS`] below
/// [`FAST_SMALL`] ([`refine_fast`]).
pub fn fast_for(n: usize) -> RefineParams {
    if n < FAST_SMALL {
        FAST_SMALL_PARAMS
    } else if n >= FAST_LARGE {
        RefineParams {
            batch: FAST_LARGE_BATCH,
            ..FAST
        }
    } else {
        FAST
    }
}

/// Knobs of a refinement run that recordings do not name (so `record --refine` and
/// `replay --verify` always use [`Tuning::default`]); for measuring variants
/// (`wraptree-bench`'s `refine_cost`) through [`refine_tuned`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tuning {
    /// Treelets are rooted only at nodes whose subtree has at least this many leaves (Karras
    /// and Aila's γ), over [`RefineParams::treelet_min`]; 3 = every node that has more than one
    /// shape; 0 (the default) = the parameters' γ ([`Tuning::gamma`]).
    pub treelet_min: u32,
    /// Treelets are rooted only at every `treelet_every`-th height from the bottom (heights 2,
    /// 2 + e, 2 + 2e, …; 1 = every height).
    pub treelet_every: u32,
    /// The treelet passes run after the reinsertion passes instead of before.
    pub treelet_after: bool,
}

impl Default for Tuning {
    /// γ by the tree's size, treelets on every height, before the reinsertion passes (measured
    /// against the other variants with `wraptree-bench`'s `refine_cost`).
    fn default() -> Self {
        Tuning {
            treelet_min: 0,
            treelet_every: 1,
            treelet_after: false,
        }
    }
}

impl Tuning {
    /// γ for a tree of `n` leaves under `params`: `treelet_min` here if set, else the
    /// parameters' ([`RefineParams::treelet_min`]) if set, else the size rule: 64 up to 65,536
    /// leaves (about 1/32 of the interior nodes, since treelets at every node cost several PLOC
    /// builds), above that `n` rounded up to a power of two, over 1,024 (128 at 10^5, 1,024 at
    /// 10^6), where the larger γ gives the same SAH in less time (`docs/benchmarks.md`).
    pub fn gamma(&self, params: &RefineParams, n: usize) -> u32 {
        if self.treelet_min > 0 {
            return self.treelet_min;
        }
        if params.treelet_min > 0 {
            return params.treelet_min;
        }
        (n.checked_next_power_of_two().unwrap_or(1 << 40) / 1024).clamp(64, 1 << 30) as u32
    }
}

/// The outcome of a refinement run.
#[derive(Clone, Debug)]
pub struct Refined {
    /// The refined tree (the input itself when no move was kept).
    pub tree: SubsetTree,
    /// SAH of the input.
    pub sah_before: f64,
    /// SAH of the result.
    pub sah_after: f64,
    /// Steps kept (rebuilt treelets and moves).
    pub steps: u32,
    /// Passes run.
    pub passes: u32,
}

/// Refines `tree` (see the module doc), reporting the start ([`Event::RefineStart`]) and each
/// kept step ([`Event::Refine`]) to `observer`.
///
/// What holds for every input:
/// - the result is a Subset Tree: leaves `0..N` in input order, interior nodes renumbered so
///   that children precede parents, keeping the input's order where it still holds
///   ([`renumber`]); a tree no step improves is returned unchanged (every id kept);
/// - SAH never above the input's: every kept step lowers it (and a final check against
///   [`crate::grouping::sah`] guards rounding);
/// - deterministic: the same tree and parameters give the same steps, the same events and the
///   same result for any number of rayon threads (searches are pure functions of the frozen
///   tree, collected in candidate order; moves apply sequentially, ties broken by node id);
/// - interior nodes whose leaf set changed take their box diagonal as diameter (the AABB
///   p-set's measure); the others keep the input's;
/// - a tree whose root box has no area (all primitives in one point, or on one line) has
///   nothing to gain and is returned unchanged;
/// - called from a thread outside the rayon pool with an observer that ignores every event, a
///   run with parallel searches goes in one piece to one of the pool's threads.
pub fn refine<O: Observer>(tree: &SubsetTree, params: &RefineParams, observer: O) -> Refined {
    refine_tuned(tree, params, &Tuning::default(), observer)
}

/// [`refine`] taking the tree by value: its parents, children and boxes become the working
/// tree's and then the result's arrays, where [`refine`] copies the tree first (on a
/// 124,705-triangle scene the copies in and out of the working form were about a third of the
/// fast path's refinement time). The same steps, events and result.
pub fn refine_owned<O: Observer>(tree: SubsetTree, params: &RefineParams, observer: O) -> Refined {
    refine_tuned_owned(tree, params, &Tuning::default(), observer)
}

/// The fast path's refinement of `tree` ([`fast_for`] its size), taking it by value as
/// [`refine_owned`] does; nothing is reported.
pub fn refine_fast(tree: SubsetTree) -> Refined {
    let params = fast_for(tree.leaves());
    refine_owned(tree, &params, ())
}

/// [`refine`] with other [`Tuning`] than the default.
pub fn refine_tuned<O: Observer>(
    tree: &SubsetTree,
    params: &RefineParams,
    tuning: &Tuning,
    observer: O,
) -> Refined {
    refine_tuned_owned(tree.clone(), params, tuning, observer)
}

/// [`refine_owned`] with other [`Tuning`] than the default.
pub fn refine_tuned_owned<O: Observer>(
    tree: SubsetTree,
    params: &RefineParams,
    tuning: &Tuning,
    observer: O,
) -> Refined {
    if observer.is_silent() {
        // Nothing to tell: a run with parallel steps goes to the pool in one piece
        // (`crate::par`). Those are the searches of a first reinsertion batch of at least
        // `reinsert::PARALLEL_MIN` candidates, and the treelets of a tree large enough for
        // some height to have `treelet::PARALLEL_MIN` of them.
        let nodes = 2 * tree.leaves().max(1) - 1;
        let first = (nodes as f64 * params.batch).ceil() as usize;
        let worth = first >= reinsert::PARALLEL_MIN
            || (params.treelet_passes > 0 && tree.leaves() >= POOL_MIN);
        return on_pool(worth, move || refine_here(tree, params, tuning, ()));
    }
    refine_here(tree, params, tuning, observer)
}

/// [`refine_tuned_owned`] on the caller's thread.
fn refine_here<O: Observer>(
    tree: SubsetTree,
    params: &RefineParams,
    tuning: &Tuning,
    mut observer: O,
) -> Refined {
    let root_area = area(&tree.aabb[tree.root() as usize]);
    if tree.leaves() < 3 || !(root_area.is_finite() && root_area > 0.0) {
        let sah_before = sah(&tree);
        observer.on_event(&Event::RefineStart {
            params: *params,
            sah: sah_before,
        });
        return Refined {
            tree,
            sah_before,
            sah_after: sah_before,
            steps: 0,
            passes: 0,
        };
    }
    let n = tree.leaves();
    let (w, depth, diameter) = WorkTree::from_tree(tree);
    // The areas and the interior sum of `sah(tree)`, in its order: the same value, one pass
    // over the boxes fewer.
    let leaves: f64 = w.area[..n].iter().sum();
    let sah_before = w.sah(leaves, root_area);
    observer.on_event(&Event::RefineStart {
        params: *params,
        sah: sah_before,
    });
    let mut run = Run {
        w,
        leaves,
        root_area,
        min_gain: root_area * 1e-12,
        steps: 0,
        undo: Vec::new(),
        observer: &mut observer,
    };
    let mut passes = 0u32;
    let treelets = |run: &mut Run<'_, O>, passes: &mut u32| {
        for _ in 0..params.treelet_passes {
            *passes += 1;
            if run.treelet_pass(*passes - 1, params, tuning) == 0 {
                break;
            }
        }
    };
    if !tuning.treelet_after {
        treelets(&mut run, &mut passes);
    }
    let nodes = run.w.parent.len() - 1;
    for k in 0..params.passes {
        let count = ((nodes as f64 * params.batch) / (2 * k + 1) as f64).ceil() as usize;
        let kept = run.reinsert_pass(passes, count.max(1));
        passes += 1;
        if kept == 0 {
            break;
        }
    }
    if tuning.treelet_after {
        treelets(&mut run, &mut passes);
    }
    let (mut w, steps, undo) = (run.w, run.steps, run.undo);
    let unchanged = |tree, passes| Refined {
        tree,
        sah_before,
        sah_after: sah_before,
        steps: 0,
        passes,
    };
    if steps == 0 {
        return unchanged(w.into_tree(depth, diameter), passes);
    }
    let order = renumber::order(&w).expect("moves keep one binary tree");
    // What `sah` gives the renumbered tree, from the areas at hand.
    let sah_after = sah_of_sums(renumber::interior_area(&w, &order), leaves, root_area);
    if sah_after > sah_before {
        for u in undo.iter().rev() {
            w.undo(u);
        }
        return unchanged(w.into_tree(depth, diameter), passes);
    }
    Refined {
        tree: renumber::subset_tree(w, &order, diameter).expect("moves keep one binary tree"),
        sah_before,
        sah_after,
        steps,
        passes,
    }
}

/// The state of a refinement run between passes.
struct Run<'a, O: Observer> {
    w: WorkTree,
    /// Σ leaf area (constant).
    leaves: f64,
    root_area: f64,
    min_gain: f64,
    steps: u32,
    /// What undoes the kept steps, oldest first.
    undo: Vec<work::Undo>,
    observer: &'a mut O,
}

impl<O: Observer> Run<'_, O> {
    fn sah(&self) -> f64 {
        self.w.sah(self.leaves, self.root_area)
    }

    /// One treelet pass ([`treelet`]): every height's treelets solved on the frozen tree, then
    /// applied in root order. Returns the treelets rebuilt.
    fn treelet_pass(&mut self, pass: u32, params: &RefineParams, tuning: &Tuning) -> u32 {
        let mut kept = 0;
        let k = params.treelet as usize;
        let every = tuning.treelet_every.max(1) as usize;
        let levels = treelet::by_height(&self.w, tuning.gamma(params, self.w.n as usize));
        for roots in levels.into_iter().step_by(every) {
            for plan in treelet::solve_all(&self.w, &roots, k, self.min_gain) {
                let sah_before = self.sah();
                self.w.restructure(&plan, &mut self.undo);
                let bx = self.w.aabb[plan.root as usize];
                self.emit(Step {
                    step: self.steps,
                    pass,
                    kind: StepKind::Treelet {
                        leaves: plan.leaves,
                    },
                    node: plan.root,
                    parent: crate::grouping::NONE,
                    sibling: crate::grouping::NONE,
                    target: crate::grouping::NONE,
                    aabb: bx,
                    parent_aabb: bx,
                    sah_before,
                    sah: self.sah(),
                });
                kept += 1;
            }
        }
        kept
    }

    /// One reinsertion pass ([`reinsert`]) over the `count` best-ranked candidates. Returns
    /// the moves kept.
    fn reinsert_pass(&mut self, pass: u32, count: usize) -> u32 {
        let candidates = reinsert::candidates(&self.w, count);
        let mut moves = reinsert::find_all(&self.w, &candidates, self.min_gain);
        reinsert::sort_best_first(&mut moves);
        let mut kept = 0;
        for m in &moves {
            if !reinsert::still_valid(&self.w, m) {
                continue;
            }
            let before = self.w.interior;
            let sah_before = self.sah();
            let moved = self.w.reinsert(m.node, m.target);
            if before - self.w.interior <= self.min_gain {
                self.w.reinsert(m.node, moved.sibling);
                self.w.interior = before;
                continue;
            }
            self.w.mark_changed(&moved);
            self.undo.push(work::Undo::Move {
                node: m.node,
                sibling: moved.sibling,
            });
            self.emit(Step {
                step: self.steps,
                pass,
                kind: StepKind::Move,
                node: m.node,
                parent: moved.parent,
                sibling: moved.sibling,
                target: m.target,
                aabb: self.w.aabb[m.node as usize],
                parent_aabb: self.w.aabb[moved.parent as usize],
                sah_before,
                sah: self.sah(),
            });
            kept += 1;
        }
        kept
    }

    fn emit(&mut self, step: Step) {
        self.observer.on_event(&Event::Refine(step));
        self.steps += 1;
    }
}
