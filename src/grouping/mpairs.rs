//! MPairs, the priority queue of eligible pairs ordered by increasing Cost (step 3–4).
//!
//! Each entry is one body's cheapest eligible partner. An entry whose owner has merged is
//! dropped when popped; one whose partner has merged is re-searched by the caller. Ordering is
//! total: (Cost, smaller tie tag, larger tie tag, owner), so runs are deterministic.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// A queued pair: `owner`'s best partner `partner` at `cost`.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    /// Cost of merging the pair.
    pub cost: f64,
    /// Smaller tie tag of the two bodies.
    pub lo: u64,
    /// Larger tie tag of the two bodies.
    pub hi: u64,
    /// The body that searched.
    pub owner: u32,
    /// Its chosen partner.
    pub partner: u32,
}

impl Entry {
    /// Whether `self` should be popped before `o`.
    #[inline]
    pub fn before(&self, o: &Entry) -> bool {
        self.cmp_key(o) == Ordering::Less
    }

    #[inline]
    fn cmp_key(&self, o: &Entry) -> Ordering {
        self.cost
            .total_cmp(&o.cost)
            .then(self.lo.cmp(&o.lo))
            .then(self.hi.cmp(&o.hi))
            .then(self.owner.cmp(&o.owner))
    }
}

impl PartialEq for Entry {
    fn eq(&self, o: &Self) -> bool {
        self.cmp_key(o) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Entry {
    /// Reversed so that `BinaryHeap` (a max-heap) pops the cheapest entry first.
    fn cmp(&self, o: &Self) -> Ordering {
        o.cmp_key(self)
    }
}

/// The queue.
#[derive(Debug, Default)]
pub struct MPairs {
    heap: BinaryHeap<Entry>,
}

impl MPairs {
    /// Queues an entry.
    #[inline]
    pub fn push(&mut self, e: Entry) {
        self.heap.push(e);
    }

    /// Pops the cheapest entry.
    #[inline]
    pub fn pop(&mut self) -> Option<Entry> {
        self.heap.pop()
    }

    /// Number of queued entries.
    pub fn len(&self) -> usize {
        self.heap.len()
    }

    /// Whether the queue is empty.
    pub fn is_empty(&self) -> bool {
        self.heap.is_empty()
    }
}
