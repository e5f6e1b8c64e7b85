//! The Subset Tree: a flat arena of the N leaves (ids `0..N`, input order) and the N − 1
//! interior nodes (ids `N..2N−1`, merge order) made by the grouping phase.

use crate::geom::{Aabb, area};

/// Marker for "no node" (the root's parent).
pub const NONE: u32 = u32::MAX;

/// A binary Subset Tree with each node's AABB p-set wrapper and diameter.
#[derive(Clone, Debug, PartialEq)]
pub struct SubsetTree {
    n: u32,
    /// Parent of every node (`NONE` for the root).
    pub parent: Vec<u32>,
    /// Children of interior node `N + i` at index `i`.
    pub children: Vec<[u32; 2]>,
    /// Depth of every node (root = 0).
    pub depth: Vec<u32>,
    /// AABB of every node's set.
    pub aabb: Vec<Aabb>,
    /// Diameter of every node's p-set wrapper.
    pub diameter: Vec<f64>,
}

impl SubsetTree {
    /// Builds a tree from the leaves' boxes and diameters and the merges `(a, b, box, diameter)`
    /// in order; merge `i` creates node `N + i`. Fails unless the merges form one binary tree.
    pub fn from_merges(
        leaf_aabb: Vec<Aabb>,
        leaf_diameter: Vec<f64>,
        merges: &[(u32, u32, Aabb, f64)],
    ) -> Result<SubsetTree, String> {
        let (mut aabb, mut diameter) = (leaf_aabb, leaf_diameter);
        aabb.extend(merges.iter().map(|m| m.2));
        diameter.extend(merges.iter().map(|m| m.3));
        let children = merges.iter().map(|&(a, b, _, _)| [a, b]).collect();
        SubsetTree::new(aabb, diameter, children)
    }

    /// Builds a tree from every node's box and diameter (2N − 1 each: leaves, then interior
    /// nodes in merge order) and the children of each interior node. Fails unless the children
    /// form one binary tree whose children precede their parents.
    pub fn new(
        aabb: Vec<Aabb>,
        diameter: Vec<f64>,
        children: Vec<[u32; 2]>,
    ) -> Result<SubsetTree, String> {
        let n = children.len() + 1;
        let total = 2 * n - 1;
        if aabb.len() != total || diameter.len() != total {
            return Err(format!(
                "{} merges need {total} node boxes and diameters, got {} and {}",
                n - 1,
                aabb.len(),
                diameter.len()
            ));
        }
        let mut parent = vec![NONE; total];
        for (i, &[a, b]) in children.iter().enumerate() {
            let new = (n + i) as u32;
            for c in [a, b] {
                if c >= new || parent[c as usize] != NONE || a == b {
                    return Err(format!(
                        "merge {i} ({a}, {b}) reuses or forward-references a body"
                    ));
                }
                parent[c as usize] = new;
            }
        }
        let mut depth = vec![0u32; total];
        for node in (0..total - 1).rev() {
            depth[node] = depth[parent[node] as usize] + 1;
        }
        Ok(SubsetTree {
            n: n as u32,
            parent,
            children,
            depth,
            aabb,
            diameter,
        })
    }

    /// A tree from arrays that already hold one (as [`SubsetTree::new`] would build them:
    /// parents and depths consistent with `children`), without checking or recomputing them.
    pub(crate) fn from_parts(
        parent: Vec<u32>,
        children: Vec<[u32; 2]>,
        depth: Vec<u32>,
        aabb: Vec<Aabb>,
        diameter: Vec<f64>,
    ) -> SubsetTree {
        debug_assert!(parent.len() == 2 * children.len() + 1 && aabb.len() == parent.len());
        SubsetTree {
            n: (children.len() + 1) as u32,
            parent,
            children,
            depth,
            aabb,
            diameter,
        }
    }

    /// Number of leaves N.
    pub fn leaves(&self) -> usize {
        self.n as usize
    }

    /// Number of nodes, 2N − 1.
    pub fn len(&self) -> usize {
        self.parent.len()
    }

    /// Always false: a tree has at least one node.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The root's id (2N − 2).
    pub fn root(&self) -> u32 {
        (self.len() - 1) as u32
    }

    /// Whether `node` is a leaf (an input primitive).
    pub fn is_leaf(&self, node: u32) -> bool {
        node < self.n
    }

    /// The two children of an interior node.
    pub fn children_of(&self, node: u32) -> Option<[u32; 2]> {
        (!self.is_leaf(node)).then(|| self.children[(node - self.n) as usize])
    }

    /// Largest leaf depth (edges from the root); the tree has `depth_max() + 1` levels.
    pub fn depth_max(&self) -> u32 {
        self.depth[..self.leaves()]
            .iter()
            .copied()
            .max()
            .unwrap_or(0)
    }

    /// Mean leaf depth.
    pub fn depth_mean(&self) -> f64 {
        let s: u64 = self.depth[..self.leaves()].iter().map(|&d| d as u64).sum();
        s as f64 / self.leaves() as f64
    }

    /// Leaves under `node`, in left-to-right order.
    pub fn leaves_under(&self, node: u32) -> Vec<u32> {
        let mut out = Vec::new();
        let mut stack = vec![node];
        while let Some(x) = stack.pop() {
            match self.children_of(x) {
                Some([a, b]) => {
                    stack.push(b);
                    stack.push(a);
                }
                None => out.push(x),
            }
        }
        out
    }

    /// The cut at depth `d`: nodes at depth `d` plus leaves shallower than `d`, sorted by id.
    /// This is the set the paper's figures draw for one level.
    pub fn level(&self, d: u32) -> Vec<u32> {
        (0..self.len() as u32)
            .filter(|&x| {
                self.depth[x as usize] == d || (self.is_leaf(x) && self.depth[x as usize] < d)
            })
            .collect()
    }

    /// Checks the tree over `scene`, the one validator of Subset Trees: 2N − 1 nodes, each
    /// leaf exactly once under the root, each leaf's box holding its primitive's vertices,
    /// each interior node with two children whose boxes it holds, whose parent it is and one
    /// level above them, and a diameter at least theirs (within 1e-12, relative). Err: the
    /// first violation.
    pub fn validate(&self, scene: &crate::scene::Scene) -> Result<(), String> {
        let n = scene.len();
        if self.len() != 2 * n - 1 || self.leaves() != n {
            return Err(format!("{} nodes for {n} leaves", self.len()));
        }
        let mut leaves = self.leaves_under(self.root());
        leaves.sort_unstable();
        if leaves.len() != n || leaves.iter().enumerate().any(|(i, &l)| l as usize != i) {
            return Err("not every leaf exactly once under the root".into());
        }
        for leaf in 0..n {
            if !scene
                .prim_vertices(leaf)
                .all(|p| self.aabb[leaf].contains_point(p, 0.0))
            {
                return Err(format!("leaf {leaf}'s box misses a vertex"));
            }
        }
        for x in n as u32..self.len() as u32 {
            let [a, b] = self
                .children_of(x)
                .ok_or(format!("node {x} has no children"))?;
            for c in [a, b] {
                let (xi, ci) = (x as usize, c as usize);
                if !self.aabb[xi].contains_aabb(&self.aabb[ci], 0.0) {
                    return Err(format!("node {c}'s box is not inside its parent {x}'s"));
                }
                if self.depth[ci] != self.depth[xi] + 1 || self.parent[ci] != x {
                    return Err(format!("node {c}: parent or depth inconsistent"));
                }
                if self.diameter[xi] < self.diameter[ci] * (1.0 - 1e-12) - 1e-12 {
                    return Err(format!("node {x}'s diameter is below its child {c}'s"));
                }
            }
        }
        Ok(())
    }

    /// Parents as `i64` with −1 for the root (the `--json` form).
    pub fn parent_i64(&self) -> Vec<i64> {
        self.parent
            .iter()
            .map(|&p| if p == NONE { -1 } else { p as i64 })
            .collect()
    }
}

/// SAH cost of visiting an interior node.
pub const C_TRAV: f64 = 1.0;
/// SAH cost of testing a primitive.
pub const C_PRIM: f64 = 1.0;

/// SAH cost of `tree` (MacDonald and Booth, 1990): traversal cost [`C_TRAV`] per interior node
/// and intersection cost [`C_PRIM`] per primitive, each weighted by the probability
/// `area(node) / area(root)` that a random ray through the root box hits the node box,
/// `SAH = (C_TRAV · Σ_interior A(n) + C_PRIM · Σ_leaves A(l)) / A(root)`. The leaf term is the
/// same for every hierarchy over a scene. A tree whose root box has no area (all primitives in
/// one point) gets SAH = number of nodes.
pub fn sah(tree: &SubsetTree) -> f64 {
    let n = tree.leaves();
    let root = area(&tree.aabb[tree.root() as usize]);
    if root.is_nan() || root <= 0.0 {
        return tree.len() as f64;
    }
    let leaves: f64 = tree.aabb[..n].iter().map(area).sum();
    let interior: f64 = tree.aabb[n..].iter().map(area).sum();
    sah_of_sums(interior, leaves, root)
}

/// The SAH of [`sah`] from its sums: the interior nodes' areas, the leaves' and the root's.
pub fn sah_of_sums(interior: f64, leaves: f64, root: f64) -> f64 {
    (C_TRAV * interior + C_PRIM * leaves) / root
}
