//! The working form of a tree under refinement: the Subset Tree's arrays made mutable, with a
//! movable root, cached box areas and the running sum of interior areas (the SAH numerator).
//!
//! Ids are the input tree's: leaves `0..N` never change, and an interior id names a *slot*
//! that a move may hang elsewhere ([`WorkTree::reinsert`]). The renumbering (`renumber.rs`)
//! turns the slots back into a Subset Tree's merge order at the end.

use crate::geom::Aabb;
use crate::geom::area;
use crate::grouping::{NONE, SubsetTree};
use rayon::prelude::*;

/// What [`WorkTree::reinsert`] changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Moved {
    /// The moved node's old sibling, now in its parent's old place.
    pub sibling: u32,
    /// The parent's old parent (`NONE` if the parent was the root).
    pub old_grandparent: u32,
    /// The parent slot, now the parent of the node and its target.
    pub parent: u32,
}

/// What undoes one kept step ([`WorkTree::undo`]), logged so that a run can give back the tree
/// it was handed when its final check fails.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Undo {
    /// A move: `node` goes back next to its old sibling ([`WorkTree::reinsert`] undoes itself).
    Move {
        /// The moved node.
        node: u32,
        /// Its sibling before the move.
        sibling: u32,
    },
    /// An interior slot as it was before a treelet was rebuilt.
    Slot {
        /// The slot.
        x: u32,
        /// Its children.
        kids: [u32; 2],
        /// Its box.
        aabb: Aabb,
        /// Its box's area.
        area: f64,
    },
}

/// Trees of at least this many nodes have their arrays built on rayon's threads.
pub const PARALLEL_COPY: usize = 1 << 16;

/// `f(0), f(1), …, f(len − 1)`: on rayon's threads from [`PARALLEL_COPY`] items, where the
/// fresh pages and the copies cost more than handing out the work.
pub fn tabulate<U: Send>(len: usize, f: impl Fn(usize) -> U + Sync + Send) -> Vec<U> {
    if len >= PARALLEL_COPY {
        (0..len).into_par_iter().map(f).collect()
    } else {
        (0..len).map(f).collect()
    }
}

/// A tree under refinement.
#[derive(Clone, Debug)]
pub struct WorkTree {
    /// Number of leaves N.
    pub n: u32,
    /// Parent of every node (`NONE` for the root).
    pub parent: Vec<u32>,
    /// Children of interior slot `N + i` at index `i`.
    pub children: Vec<[u32; 2]>,
    /// Box of every node.
    pub aabb: Vec<Aabb>,
    /// Surface area of every node's box.
    pub area: Vec<f64>,
    /// The root.
    pub root: u32,
    /// Σ area of the interior nodes.
    pub interior: f64,
    /// Whether an interior slot's leaf set changed (its diameter is then recomputed).
    pub changed: Vec<bool>,
    /// Whether every interior slot's interior children still have smaller ids (true until the
    /// first move or rebuilt treelet, as in the Subset Tree it was made from).
    pub topological: bool,
    /// Scratch marks for [`WorkTree::reinsert`] (all false between calls).
    mark: Vec<bool>,
}

impl WorkTree {
    /// The working form of `tree` (a copy: see [`WorkTree::from_tree`]).
    pub fn of(tree: &SubsetTree) -> WorkTree {
        WorkTree::from_tree(tree.clone()).0
    }

    /// The working form of `tree`, made of its own arrays (parents, children, boxes: moved,
    /// not copied), with the depths and diameters it does not use given back for
    /// [`WorkTree::into_tree`] and the renumbering.
    ///
    /// Only the areas are new: on rayon's threads for large trees ([`tabulate`]), the interior
    /// sum taken in id order, so it is the same for any number of threads.
    pub fn from_tree(tree: SubsetTree) -> (WorkTree, Vec<u32>, Vec<f64>) {
        let (n, root) = (tree.leaves(), tree.root());
        let SubsetTree {
            parent,
            children,
            depth,
            aabb,
            diameter,
            ..
        } = tree;
        let area: Vec<f64> = tabulate(aabb.len(), |i| area(&aabb[i]));
        let slots = children.len();
        let w = WorkTree {
            n: n as u32,
            mark: vec![false; parent.len()],
            parent,
            children,
            aabb,
            interior: area[n..].iter().sum(),
            area,
            root,
            changed: vec![false; slots],
            topological: true,
        };
        (w, depth, diameter)
    }

    /// The Subset Tree this working tree was made from, with its `depth` and `diameter`: for a
    /// tree no step changed (moves undone leave every array as it was, boxes being the unions
    /// of their children's).
    pub fn into_tree(self, depth: Vec<u32>, diameter: Vec<f64>) -> SubsetTree {
        SubsetTree::from_parts(self.parent, self.children, depth, self.aabb, diameter)
    }

    /// Whether `x` is a leaf.
    #[inline(always)]
    pub fn is_leaf(&self, x: u32) -> bool {
        x < self.n
    }

    /// Children of interior node `x`.
    #[inline(always)]
    pub fn kids(&self, x: u32) -> [u32; 2] {
        self.children[(x - self.n) as usize]
    }

    /// The other child of `x`'s parent (`x` must not be the root).
    #[inline(always)]
    pub fn sibling(&self, x: u32) -> u32 {
        let [a, b] = self.kids(self.parent[x as usize]);
        if a == x { b } else { a }
    }

    /// Whether `x` lies in the subtree of `top` (itself included).
    pub fn is_under(&self, mut x: u32, top: u32) -> bool {
        while x != NONE {
            if x == top {
                return true;
            }
            x = self.parent[x as usize];
        }
        false
    }

    /// Replaces child `old` of `p` (`NONE` = the root position) by `new`.
    fn replace_child(&mut self, p: u32, old: u32, new: u32) {
        if p == NONE {
            self.root = new;
        } else {
            let k = &mut self.children[(p - self.n) as usize];
            let i = usize::from(k[0] != old);
            k[i] = new;
        }
        self.parent[new as usize] = p;
    }

    /// Recomputes the boxes from `x` up to the root, stopping above `x` where a box is
    /// unchanged, and keeps [`WorkTree::interior`] in step. `x` itself never stops the walk:
    /// after a move its parent may be new, and that parent's stored box did not cover it.
    fn refit(&mut self, mut x: u32) {
        let mut first = true;
        while x != NONE {
            let [a, b] = self.kids(x);
            let bx = self.aabb[a as usize].merge(&self.aabb[b as usize]);
            if bx == self.aabb[x as usize] && !first {
                return;
            }
            first = false;
            let ar = area(&bx);
            self.interior += ar - self.area[x as usize];
            self.aabb[x as usize] = bx;
            self.area[x as usize] = ar;
            x = self.parent[x as usize];
        }
    }

    /// Moves the subtree `node` next to `target`: `node`'s parent slot `p` leaves its place
    /// (its other child `s` takes it) and becomes the parent of `node` and `target` where
    /// `target` was; `node` keeps its child index in `p`. The caller checks that
    /// `node` is not the root, and `target` is neither `node`'s parent or sibling nor under
    /// `node`. Moving `node` back next to `s` undoes it exactly.
    pub fn reinsert(&mut self, node: u32, target: u32) -> Moved {
        self.topological = false;
        let p = self.parent[node as usize];
        let s = self.sibling(node);
        let g = self.parent[p as usize];
        self.replace_child(g, p, s);
        let t = self.parent[target as usize];
        self.replace_child(t, target, p);
        let k = &mut self.children[(p - self.n) as usize];
        let i = usize::from(k[0] != node);
        k[1 - i] = target;
        self.parent[target as usize] = p;
        if g != NONE {
            self.refit(g);
        }
        self.refit(p);
        Moved {
            sibling: s,
            old_grandparent: g,
            parent: p,
        }
    }

    /// Marks the slots whose leaf set the move `m` changed (their diameters are recomputed):
    /// the moved parent slot, its new ancestors and the old grandparent and its ancestors, each
    /// up to (not including) the lowest node holding both the old and the new position.
    pub fn mark_changed(&mut self, m: &Moved) {
        let (g, p) = (m.old_grandparent, m.parent);
        self.changed[(p - self.n) as usize] = true;
        let mut x = p;
        while x != NONE {
            self.mark[x as usize] = true;
            x = self.parent[x as usize];
        }
        let mut y = g;
        while y != NONE && !self.mark[y as usize] {
            self.changed[(y - self.n) as usize] = true;
            y = self.parent[y as usize];
        }
        let (lca, mut above) = (y, false);
        let mut x = p;
        while x != NONE {
            self.mark[x as usize] = false;
            above |= x == lca;
            if !above {
                self.changed[(x - self.n) as usize] = true;
            }
            x = self.parent[x as usize];
        }
    }

    /// Undoes `u`; undoing a log's entries newest first gives back the tree before them.
    pub fn undo(&mut self, u: &Undo) {
        match *u {
            Undo::Move { node, sibling } => {
                self.reinsert(node, sibling);
            }
            Undo::Slot {
                x,
                kids,
                aabb,
                area,
            } => {
                self.children[(x - self.n) as usize] = kids;
                for c in kids {
                    self.parent[c as usize] = x;
                }
                self.interior += area - self.area[x as usize];
                self.aabb[x as usize] = aabb;
                self.area[x as usize] = area;
            }
        }
    }

    /// SAH of the current tree from the running interior sum (see [`crate::grouping::sah`]).
    pub fn sah(&self, leaves: f64, root_area: f64) -> f64 {
        crate::grouping::sah_of_sums(self.interior, leaves, root_area)
    }
}
