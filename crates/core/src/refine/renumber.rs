//! Back to the Subset Tree's numbering after moves: leaves keep `0..N`; interior slots get ids
//! `N..2N−1` in a topological order (children before parents) that keeps the input's order
//! wherever it still holds — among the slots whose children are all numbered, the smallest
//! input id comes next. An unmoved tree keeps every id.

use super::work::{PARALLEL_COPY, WorkTree, tabulate};
use crate::grouping::SubsetTree;
use rayon::prelude::*;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// The interior slots of `w` in their new order (slot `order[k]` becomes node `N + k`; see the
/// module doc). Fails unless every slot is reachable from the root.
pub fn order(w: &WorkTree) -> Result<Vec<u32>, String> {
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
    Ok(order)
}

/// The sum of the interior areas of the Subset Tree that [`subset_tree`] makes of `w` in
/// `order`, from the areas `w` keeps, in that tree's id order: the sum
/// [`crate::grouping::sah`] takes of it, bit for bit.
pub fn interior_area(w: &WorkTree, order: &[u32]) -> f64 {
    let n = w.n as usize;
    order.iter().map(|&i| w.area[n + i as usize]).sum()
}

/// The Subset Tree of `w` with its interior slots renumbered in `order` ([`order`]): boxes as
/// refitted, and `diameter` (the input's, by input id) for every node whose leaf set is
/// unchanged, the box diagonal for the others. The boxes and diameters are permuted in the
/// arrays they came in, from the first slot that moved on.
pub fn subset_tree(w: WorkTree, order: &[u32], diameter: Vec<f64>) -> Result<SubsetTree, String> {
    let n = w.n as usize;
    let slots = order.len();
    let mut new_id = vec![0u32; slots];
    for (k, &i) in order.iter().enumerate() {
        new_id[i as usize] = (n + k) as u32;
    }
    let id = |c: u32| {
        if w.is_leaf(c) {
            c
        } else {
            new_id[(c as usize) - n]
        }
    };
    let children = tabulate(slots, |k| w.children[order[k] as usize].map(id));
    // Slots before the first that moved keep their place (`order` is a permutation whose
    // prefix is the identity).
    let first = order
        .iter()
        .enumerate()
        .position(|(k, &i)| k != i as usize)
        .unwrap_or(slots);
    let (mut aabb, mut diam) = (w.aabb, diameter);
    permute(&mut aabb[n..], order, first);
    permute(&mut diam[n..], order, first);
    let changed = &w.changed;
    let fix = |(k, d): (usize, &mut f64)| {
        if changed[order[k] as usize] {
            *d = aabb[n + k].diameter();
        }
    };
    if slots >= PARALLEL_COPY {
        diam[n..].par_iter_mut().enumerate().for_each(fix);
    } else {
        diam[n..].iter_mut().enumerate().for_each(fix);
    }
    SubsetTree::new(aabb, diam, children)
}

/// `v[k] = v_before[order[k]]` for every `k` from `first` on (`order[..first]` is the
/// identity, so only the rest is copied aside); on rayon's threads for large arrays.
fn permute<T: Copy + Send + Sync>(v: &mut [T], order: &[u32], first: usize) {
    if first == order.len() {
        return;
    }
    let old = v[first..].to_vec();
    let put = |(x, &i): (&mut T, &u32)| *x = old[i as usize - first];
    if order.len() - first >= PARALLEL_COPY {
        v[first..].par_iter_mut().zip(&order[first..]).for_each(put);
    } else {
        v[first..].iter_mut().zip(&order[first..]).for_each(put);
    }
}
