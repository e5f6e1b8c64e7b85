//! Any binary tree over a scene's primitives, as a [`SubsetTree`].
//!
//! Peers number their nodes their own way (parry: wide node pairs in depth-first order; obvhs:
//! sibling pairs in one array; top-down builders: creation order). [`subset_tree`] takes such a
//! tree as a flat list of [`Node`]s, renumbers its interior nodes in post-order (children before
//! parents, as the Subset Tree requires) and recomputes every node's box in `f64` from the
//! primitives, so only the topology comes from the peer and all hierarchies are measured alike.

use crate::geom::Aabb;
use crate::grouping::SubsetTree;
use crate::scene::Scene;

/// One node of a peer's binary tree; children are indices into the same list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Node {
    /// A leaf holding primitive `id` (input order).
    Leaf(u32),
    /// An interior node with two children.
    Inner(u32, u32),
}

/// Converts the tree rooted at `nodes[root]` to a Subset Tree over `scene`. Fails unless every
/// primitive is a leaf exactly once and every node is reached once.
pub fn subset_tree(scene: &Scene, nodes: &[Node], root: u32) -> Result<SubsetTree, String> {
    let n = scene.len();
    if n == 0 {
        return Err("empty scene".into());
    }
    let mut id = vec![u32::MAX; nodes.len()];
    let mut seen_prim = vec![false; n];
    let mut children: Vec<[u32; 2]> = Vec::with_capacity(n - 1);
    let mut visited = vec![false; nodes.len()];
    // Iterative post-order: (node, children done).
    let mut stack = vec![(root, false)];
    while let Some((x, done)) = stack.pop() {
        let node = *nodes
            .get(x as usize)
            .ok_or_else(|| format!("node {x} out of range"))?;
        match node {
            Node::Leaf(p) => {
                if visited[x as usize] {
                    return Err(format!("node {x} reached twice"));
                }
                visited[x as usize] = true;
                let slot = seen_prim
                    .get_mut(p as usize)
                    .ok_or_else(|| format!("leaf primitive {p} out of range"))?;
                if std::mem::replace(slot, true) {
                    return Err(format!("primitive {p} is in two leaves"));
                }
                id[x as usize] = p;
            }
            Node::Inner(a, b) if !done => {
                if std::mem::replace(&mut visited[x as usize], true) {
                    return Err(format!("node {x} reached twice"));
                }
                stack.push((x, true));
                stack.push((b, false));
                stack.push((a, false));
            }
            Node::Inner(a, b) => {
                let (ia, ib) = (id[a as usize], id[b as usize]);
                id[x as usize] = (n + children.len()) as u32;
                children.push([ia, ib]);
            }
        }
    }
    if let Some(p) = seen_prim.iter().position(|s| !s) {
        return Err(format!("primitive {p} is in no leaf"));
    }
    let mut aabb: Vec<Aabb> = (0..n).map(|i| scene.prim_aabb(i)).collect();
    aabb.resize(2 * n - 1, Aabb::EMPTY);
    for (i, &[a, b]) in children.iter().enumerate() {
        aabb[n + i] = aabb[a as usize].merge(&aabb[b as usize]);
    }
    let diameter = aabb.iter().map(Aabb::diameter).collect();
    SubsetTree::new(aabb, diameter, children)
}

/// The scene's primitive boxes in `f32`, relative to the scene box's centre (what the `f32`
/// peers are given; see [`crate::geom::to_glam_local`]).
pub fn local_boxes(scene: &Scene) -> Vec<([f32; 3], [f32; 3])> {
    let origin = scene.aabb().center();
    (0..scene.len())
        .map(|i| {
            let b = scene.prim_aabb(i);
            let lo = b.min - origin;
            let hi = b.max - origin;
            (
                [lo.x as f32, lo.y as f32, lo.z as f32],
                [hi.x as f32, hi.y as f32, hi.z as f32],
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::generate;

    #[test]
    fn renumbers_in_post_order_and_checks_leaves() {
        let scene = generate::soup(3, 1);
        // ((2, 0), 1) with the root first, as a top-down builder would list it.
        let nodes = [
            Node::Inner(1, 4),
            Node::Inner(2, 3),
            Node::Leaf(2),
            Node::Leaf(0),
            Node::Leaf(1),
        ];
        let t = subset_tree(&scene, &nodes, 0).unwrap();
        assert_eq!(t.children, vec![[2, 0], [3, 1]]);
        assert_eq!(t.depth[..3], [2, 1, 2]);
        let twice = [Node::Inner(1, 2), Node::Leaf(0), Node::Leaf(0)];
        assert!(
            subset_tree(&scene, &twice, 0)
                .unwrap_err()
                .contains("two leaves")
        );
        let short = [Node::Inner(1, 2), Node::Leaf(0), Node::Leaf(1)];
        assert!(
            subset_tree(&scene, &short, 0)
                .unwrap_err()
                .contains("no leaf")
        );
    }
}
