//! Back to the Subset Tree's numbering after moves: leaves keep `0..N`; interior slots get ids
//! `N..2N−1` in a topological order (children before parents) that keeps the input's order
//! wherever it still holds — among the slots whose children are all numbered, the smallest
//! input id comes next. An unmoved tree keeps every id.

use super::work::{WorkTree, tabulate};
use crate::grouping::SubsetTree;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// The Subset Tree of `w`: interior slots renumbered (see the module doc), boxes as refitted,
/// and the diameter of `input` for every node whose leaf set is unchanged, the box diagonal for
/// the others.
pub fn subset_tree(w: &WorkTree, input: &SubsetTree) -> Result<SubsetTree, String> {
    let n = w.n as usize;
    let slots = w.children.len();
    // Children of a slot not yet numbered: 0, 1 or 2. The smallest ready slot comes next: a
    // scan in id order finds the slots that are ready when it reaches them; the others, ready
    // only after the scan passed them, wait in a heap (few where the input's order holds).
    let mut waiting: Vec<u8> = w
        .children
        .iter()
        .map(|k| k.iter().filter(|&&c| !w.is_leaf(c)).count() as u8)
        .collect();
    let mut late = BinaryHeap::new();
    let mut scan = 0u32;
    let mut new_id = vec![0u32; slots];
    let mut order = Vec::with_capacity(slots);
    loop {
        while (scan as usize) < slots && waiting[scan as usize] != 0 {
            scan += 1;
        }
        let i = match late.peek() {
            Some(&Reverse(j)) if j < scan || scan as usize == slots => {
                late.pop();
                j
            }
            _ if (scan as usize) < slots => {
                scan += 1;
                scan - 1
            }
            _ => break,
        };
        new_id[i as usize] = (n + order.len()) as u32;
        order.push(i);
        let p = w.parent[n + i as usize];
        if p != crate::grouping::NONE {
            let j = p - n as u32;
            waiting[j as usize] -= 1;
            if waiting[j as usize] == 0 && j < scan {
                late.push(Reverse(j));
            }
        }
    }
    if order.len() != slots {
        return Err(format!(
            "refined tree is not one tree: {} of {slots} interior nodes reachable",
            order.len()
        ));
    }
    let id = |c: u32| {
        if w.is_leaf(c) {
            c
        } else {
            new_id[(c as usize) - n]
        }
    };
    // The arrays in the new order (on rayon's threads for large trees).
    let node = |k: usize| if k < n { k } else { n + order[k - n] as usize };
    let aabb = tabulate(n + slots, |k| w.aabb[node(k)]);
    let diameter = tabulate(n + slots, |k| {
        let x = node(k);
        if x >= n && w.changed[x - n] {
            w.aabb[x].diameter()
        } else {
            input.diameter[x]
        }
    });
    let children = tabulate(slots, |k| w.children[order[k] as usize].map(id));
    SubsetTree::new(aabb, diameter, children)
}
