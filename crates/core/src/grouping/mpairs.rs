//! MPairs, the priority queue of eligible pairs by increasing Cost (steps 3–4), and the short
//! partner lists it is fed from.
//!
//! Every active body keeps its first few partners in key order, found when it last searched.
//! The queue holds one entry per active body: the first list entry whose partner was alive. An
//! entry whose owner merged is dropped when popped; one whose partner merged is replaced by the
//! next live list entry, and only a used-up list makes its owner search again.
//!
//! # Why the popped pair is the global minimum
//!
//! Pair Costs are symmetric, so every eligible pair has one key. Let *t(x)* be the time body `x`
//! last searched; its list is a prefix, in key order, of all its partners at *t(x)*. Claim: at
//! any time, for every pair of live active bodies `x`, `y`, the queue holds an entry with key
//! ≤ key(x, y). Take `x` to be the one that searched last; `y` existed then (every body searches
//! when it becomes active, after which `y` was made before `t(x)` or `y` searched after `x`).
//! `x`'s queued entry is its list entry *i*; entries before *i* name dead partners, so `y` is
//! not among them, and either `y` is at or after *i* in the list or beyond its end, both with
//! key ≥ entry *i*'s. Replacing a dead-partner entry by the next live one, or by a fresh search,
//! keeps the claim. Hence the cheapest entry popped with both members live is the cheapest
//! eligible pair overall — exactly the pair the paper's queue of every eligible pair would
//! pop — and the merges (hence the tree) are the same as with that queue.

use std::cmp::Ordering;

/// A queued pair: `owner`'s best live partner `partner` at `cost`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Entry {
    /// Cost of merging the pair, as [`order_bits`] (compare as integers).
    pub cost: u64,
    /// The body whose list the entry comes from.
    pub owner: u32,
    /// Its partner.
    pub partner: u32,
}

impl Entry {
    /// Whether `self` should be popped before `o`; `tags` are the bodies' tie tags.
    #[inline(always)]
    pub fn before(&self, o: &Entry, tags: &[u64]) -> bool {
        match self.cost.cmp(&o.cost) {
            Ordering::Less => true,
            Ordering::Greater => false,
            Ordering::Equal => {
                let pair = |e: &Entry| {
                    let (a, b) = (tags[e.owner as usize], tags[e.partner as usize]);
                    (a.min(b), a.max(b), e.owner)
                };
                pair(self) < pair(o)
            }
        }
    }
}

/// The bits of `cost` as an integer with the order of `f64::total_cmp`.
#[inline(always)]
pub fn order_bits(cost: f64) -> u64 {
    let b = cost.to_bits();
    b ^ ((((b as i64) >> 63) as u64) | (1 << 63))
}

/// The queue: a 4-ary min-heap of [`Entry`], so one step down reads one cache line of children.
///
/// The order is total, (Cost, smaller tie tag, larger tie tag, owner), so runs are deterministic.
/// Entries are 16 bytes; the tie tags are read from the caller's tag array only when two Costs
/// are equal.
#[derive(Debug, Default)]
pub struct MPairs {
    heap: Vec<Entry>,
}

impl MPairs {
    /// Queues an entry.
    #[inline]
    pub fn push(&mut self, e: Entry, tags: &[u64]) {
        self.heap.push(e);
        self.sift_up(self.heap.len() - 1, e, tags);
    }

    /// The cheapest entry.
    #[inline]
    pub fn peek(&self) -> Option<Entry> {
        self.heap.first().copied()
    }

    /// Removes the cheapest entry.
    #[inline]
    pub fn pop(&mut self, tags: &[u64]) -> Option<Entry> {
        let last = self.heap.pop()?;
        if self.heap.is_empty() {
            return Some(last);
        }
        let top = self.heap[0];
        self.sift_down(last, tags);
        Some(top)
    }

    /// Replaces the cheapest entry by `e` (a pop followed by a push).
    #[inline]
    pub fn replace_top(&mut self, e: Entry, tags: &[u64]) {
        self.sift_down(e, tags);
    }

    fn sift_up(&mut self, mut i: usize, e: Entry, tags: &[u64]) {
        while i > 0 {
            let p = (i - 1) / 4;
            if !e.before(&self.heap[p], tags) {
                break;
            }
            self.heap[i] = self.heap[p];
            i = p;
        }
        self.heap[i] = e;
    }

    /// Puts `e` at the root and moves it down to its place.
    fn sift_down(&mut self, e: Entry, tags: &[u64]) {
        let n = self.heap.len();
        let mut i = 0;
        loop {
            let c = 4 * i + 1;
            if c >= n {
                break;
            }
            let mut m = c;
            for j in c + 1..(c + 4).min(n) {
                // The least child without a branch on the Costs' order (a coin flip); equal
                // Costs, rare, go to the tie tags.
                let (a, b) = (&self.heap[j], &self.heap[m]);
                let take = (a.cost < b.cost) | ((a.cost == b.cost) && a.before(b, tags));
                m = if take { j } else { m };
            }
            if !self.heap[m].before(&e, tags) {
                break;
            }
            self.heap[i] = self.heap[m];
            i = m;
        }
        self.heap[i] = e;
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

/// The longest partner list.
pub const K_MAX: usize = 4;

/// One candidate partner in a list.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cand {
    /// Cost of the pair.
    pub cost: f64,
    /// The partner.
    pub partner: u32,
}

/// A list of at most `C` partners, cheapest first.
#[derive(Clone, Copy, Debug)]
pub struct Top<const C: usize> {
    e: [Cand; C],
    len: u8,
    next: u8,
}

/// A body's partner list.
pub type List = Top<K_MAX>;

impl<const C: usize> Top<C> {
    /// An empty list.
    pub const EMPTY: Top<C> = Top {
        e: [Cand {
            cost: 0.0,
            partner: u32::MAX,
        }; C],
        len: 0,
        next: 0,
    };

    /// The first `k` (at most `D`) entries whose partner is not `x`, in order.
    #[inline]
    pub fn without<const D: usize>(&self, x: u32, k: usize) -> Top<D> {
        let mut out = Top::<D>::EMPTY;
        for c in &self.e[..self.len as usize] {
            if (out.len as usize) < k.min(D) && c.partner != x {
                out.e[out.len as usize] = *c;
                out.len += 1;
            }
        }
        out
    }

    /// The Cost above which a candidate cannot enter a list of capacity `k`.
    #[inline]
    pub fn bar(&self, k: usize) -> f64 {
        if (self.len as usize) < k {
            f64::INFINITY
        } else {
            self.e[k - 1].cost
        }
    }

    /// Offers `partner` at `cost` to a list of capacity `k`; the key of a pair with a fixed
    /// owner is (Cost, the partner's tie tag).
    #[inline(always)]
    pub fn offer(&mut self, k: usize, cost: f64, partner: u32, tags: &[u64]) {
        let len = self.len as usize;
        if len == k && cost > self.e[k - 1].cost {
            return;
        }
        // Tie tags are read only for equal Costs (rare), sparing a random memory access.
        let goes_before = |c: &Cand| match cost.total_cmp(&c.cost) {
            Ordering::Less => true,
            Ordering::Greater => false,
            Ordering::Equal => tags[partner as usize] < tags[c.partner as usize],
        };
        let mut i = len;
        if i == k {
            if !goes_before(&self.e[k - 1]) {
                return;
            }
            i -= 1;
        } else {
            self.len += 1;
        }
        while i > 0 && goes_before(&self.e[i - 1]) {
            self.e[i] = self.e[i - 1];
            i -= 1;
        }
        self.e[i] = Cand { cost, partner };
    }

    /// The current entry (the first not yet skipped), if any.
    #[inline]
    pub fn current(&self) -> Option<Cand> {
        (self.next < self.len).then(|| self.e[self.next as usize])
    }

    /// Skips the current entry and every following one whose partner is not `live`; returns
    /// the new current entry, if any.
    #[inline]
    pub fn advance(&mut self, live: impl Fn(u32) -> bool) -> Option<Cand> {
        self.next += 1;
        while self.next < self.len {
            let c = self.e[self.next as usize];
            if live(c.partner) {
                return Some(c);
            }
            self.next += 1;
        }
        None
    }
}

/// Partner lists of the active bodies, in reusable slots.
#[derive(Debug, Default)]
pub struct Partners {
    lists: Vec<List>,
    slot: Vec<u32>,
    free: Vec<u32>,
}

impl Partners {
    /// Forgets every list; `ids` is the number of body ids.
    pub fn reset(&mut self, ids: usize) {
        self.lists.clear();
        self.free.clear();
        self.slot.resize(ids, u32::MAX);
    }

    /// Gives body `x` an empty list.
    #[inline]
    pub fn open(&mut self, x: u32) {
        if self.slot.len() <= x as usize {
            self.slot.resize(x as usize + 1, u32::MAX);
        }
        let s = match self.free.pop() {
            Some(s) => {
                self.lists[s as usize] = List::EMPTY;
                s
            }
            None => {
                self.lists.push(List::EMPTY);
                (self.lists.len() - 1) as u32
            }
        };
        self.slot[x as usize] = s;
    }

    /// Frees body `x`'s list.
    #[inline]
    pub fn close(&mut self, x: u32) {
        self.free.push(self.slot[x as usize]);
    }

    /// Body `x`'s list.
    #[inline]
    pub fn get(&mut self, x: u32) -> &mut List {
        &mut self.lists[self.slot[x as usize] as usize]
    }

    /// The list slot of body `x` (for callers that update two lists at once).
    #[inline]
    pub fn slot(&self, x: u32) -> usize {
        self.slot[x as usize] as usize
    }

    /// The list slot of every body id (`u32::MAX` for ids never given a list).
    #[inline]
    pub fn slots(&self) -> &[u32] {
        &self.slot
    }

    /// All list slots.
    #[inline]
    pub fn lists_mut(&mut self) -> &mut [List] {
        &mut self.lists
    }
}
