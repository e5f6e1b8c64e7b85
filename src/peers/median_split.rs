//! Top-down median split: the primitives of a node are ordered by their box centres along the
//! longest axis of the centres' bounds and split into equal halves (ties by primitive id), the
//! classic O(N log N) baseline (Kay and Kajiya, 1986; Glassner, "An Introduction to Ray
//! Tracing", 1989). Depth is ⌈log2 N⌉ by construction.

use super::topology::Node;
use crate::geom::P3;

/// Builds the tree over primitive box centres `centres`; returns the nodes and the root index.
pub fn build(centres: &[P3]) -> (Vec<Node>, u32) {
    let n = centres.len();
    let mut ids: Vec<u32> = (0..n as u32).collect();
    let mut nodes = Vec::with_capacity(2 * n);
    nodes.push(Node::Leaf(0));
    // (node slot, range of `ids`).
    let mut stack = vec![(0usize, 0usize, n)];
    while let Some((slot, lo, hi)) = stack.pop() {
        if hi - lo == 1 {
            nodes[slot] = Node::Leaf(ids[lo]);
            continue;
        }
        let part = &mut ids[lo..hi];
        let (mut min, mut max) = (
            P3::from([f64::INFINITY; 3]),
            P3::from([f64::NEG_INFINITY; 3]),
        );
        for &i in part.iter() {
            min = min.inf(&centres[i as usize]);
            max = max.sup(&centres[i as usize]);
        }
        let axis = (max - min).imax();
        let mid = part.len() / 2;
        part.select_nth_unstable_by(mid, |&a, &b| {
            centres[a as usize][axis]
                .total_cmp(&centres[b as usize][axis])
                .then(a.cmp(&b))
        });
        let (left, right) = (nodes.len(), nodes.len() + 1);
        nodes.extend([Node::Leaf(0), Node::Leaf(0)]);
        nodes[slot] = Node::Inner(left as u32, right as u32);
        stack.push((right, lo + mid, hi));
        stack.push((left, lo, lo + mid));
    }
    (nodes, 0)
}
