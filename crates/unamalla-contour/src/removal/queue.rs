//! The removal order: keys as totally ordered bits, the indexed heap of recomputed keys and
//! the queue that merges it with the sorted initial keys.

use super::{touch, Workspace};

/// The key's position in the IEEE total order (`f64::total_cmp`) as an unsigned integer:
/// flip every bit of a negative value, only the sign bit of a non-negative one. Comparing
/// these integers is exactly `total_cmp`, so (key, vertex) pairs order the same way as before
/// and the removal sequence is unchanged.
#[inline]
pub(super) fn order_bits(k: f64) -> u64 {
    let b = k.to_bits();
    if b >> 63 == 1 {
        !b
    } else {
        b | (1 << 63)
    }
}

/// An indexed 4-ary min-heap of `(key bits, vertex)` pairs with a position table, so a
/// vertex's key can be changed or removed in place: the heap never holds stale entries and
/// its size is at most the number of queued vertices. Four children per node halve the depth
/// of a binary heap; the four keys of a node's children are contiguous.
///
/// **Lazy increase-key.** The true key of a queued vertex is `want[v]`; the key stored in the
/// heap may be smaller (a lower bound). A decrease is applied at once (sift up); an increase
/// only updates `want` — most updated vertices are updated again (another neighbour removed)
/// before they come near the top. [`IndexedHeap::peek`] repairs the root until its stored key
/// is its true key: then it is the true minimum, since every stored key is at most the true
/// key of its vertex and the root's is the smallest stored one (ties by vertex id as well).
pub(super) struct IndexedHeap {
    pub(super) items: Vec<(u64, u32)>,
    /// `pos[v]`: index of `v` in `items`, or [`IndexedHeap::NONE`].
    pos: Vec<u32>,
    /// `want[v]`: the true key of a queued vertex (`≥` its stored key).
    want: Vec<u64>,
}

impl IndexedHeap {
    const NONE: u32 = u32::MAX;
    const D: usize = 4;

    pub(super) fn new(n: usize) -> Self {
        Self {
            items: Vec::new(),
            pos: vec![Self::NONE; n],
            want: vec![0; n],
        }
    }
    /// The queued vertex of smallest true key (ties: lowest id), repairing lazily increased
    /// keys at the root first.
    #[inline]
    pub(super) fn peek(&mut self) -> Option<(u64, u32)> {
        loop {
            let top = *self.items.first()?;
            let w = self.want[top.1 as usize];
            if w == top.0 {
                return Some(top);
            }
            self.items[0].0 = w;
            self.sift_down(0);
        }
    }
    /// Starts loading `v`'s entries of `pos` and `want` (see [`touch`]).
    #[inline(always)]
    pub(super) fn warm(&self, v: usize) {
        if let (Some(p), Some(w)) = (self.pos.get(v), self.want.get(v)) {
            touch(p);
            touch(w);
        }
    }
    /// Inserts `v` with `key`, or changes its key (an increase lazily, see the type docs).
    pub(super) fn set(&mut self, v: usize, key: u64) {
        self.want[v] = key;
        let item = (key, v as u32);
        let p = self.pos[v];
        if p == Self::NONE {
            self.items.push(item);
            let i = self.items.len() - 1;
            self.pos[v] = i as u32;
            self.sift_up(i);
        } else {
            let i = p as usize;
            if item < self.items[i] {
                self.items[i] = item;
                self.sift_up(i);
            }
        }
    }
    /// Removes `v` if queued.
    pub(super) fn remove(&mut self, v: usize) {
        let p = self.pos[v];
        if p == Self::NONE {
            return;
        }
        let i = p as usize;
        self.pos[v] = Self::NONE;
        let last = self.items.len() - 1;
        if i == last {
            self.items.pop();
            return;
        }
        let old = self.items[i];
        let moved = self.items[last];
        self.items.pop();
        self.items[i] = moved;
        self.pos[moved.1 as usize] = i as u32;
        if moved < old {
            self.sift_up(i);
        } else {
            self.sift_down(i);
        }
    }
    pub(super) fn pop(&mut self) -> Option<(u64, u32)> {
        let top = self.peek()?;
        self.remove(top.1 as usize);
        Some(top)
    }
    pub(super) fn clear(&mut self) {
        for &(_, v) in &self.items {
            self.pos[v as usize] = Self::NONE;
        }
        self.items.clear();
    }
    fn sift_up(&mut self, mut i: usize) {
        let item = self.items[i];
        while i > 0 {
            let parent = (i - 1) / Self::D;
            let pi = self.items[parent];
            if pi <= item {
                break;
            }
            self.items[i] = pi;
            self.pos[pi.1 as usize] = i as u32;
            i = parent;
        }
        self.items[i] = item;
        self.pos[item.1 as usize] = i as u32;
    }
    fn sift_down(&mut self, mut i: usize) {
        let n = self.items.len();
        let item = self.items[i];
        loop {
            let first = Self::D * i + 1;
            if first >= n {
                break;
            }
            let end = (first + Self::D).min(n);
            let mut best = first;
            for c in first + 1..end {
                if self.items[c] < self.items[best] {
                    best = c;
                }
            }
            let bi = self.items[best];
            if bi >= item {
                break;
            }
            self.items[i] = bi;
            self.pos[bi.1 as usize] = i as u32;
            i = best;
        }
        self.items[i] = item;
        self.pos[item.1 as usize] = i as u32;
    }
}

/// The priority queue of [`sequential`](super::sequential): the minimum over (key, vertex id) of the queued
/// vertices, kept in two parts:
///
/// * `sorted`: the **initial** keys, sorted once (`sort_unstable` on `(key, vertex, stamp)`
///   triples, ordered by `(key, vertex)` as the vertex is unique; cache-friendly) and consumed
///   front to back. An entry is stale iff its vertex's [`Node::stamp`](super::Node::stamp) changed since (a
///   neighbour was removed, so the key was recomputed) or the vertex was removed — one read of
///   the vertex's node, which the topology check reads next anyway; no heap work. Most
///   vertices of a dense ring are removed with their initial key, so most pops cost O(1).
/// * `heap`: an [`IndexedHeap`] of the keys **recomputed** after a neighbour's removal
///   (changed in place, no stale entries), much smaller than the ring.
///
/// The next candidate is the smaller of the two fronts in the same total order as a single
/// heap of all entries, so the removal sequence is exactly that of one binary heap (the
/// previous implementation, a lazy `BinaryHeap` whose `pop` on ≈ 260 k entries took ≈ 28 % of
/// the 100k benchmark).
pub(super) struct Queue {
    pub(super) sorted: Vec<(u64, u32, u32)>,
    pub(super) pos: usize,
    pub(super) heap: IndexedHeap,
}

impl Queue {
    /// Pops the smallest queued vertex.
    #[inline]
    pub(super) fn pop(&mut self, ws: &Workspace) -> Option<usize> {
        // A removed vertex was popped first: from `sorted` (its entry is behind `pos`) or from
        // the heap (then it had been updated, so its `sorted` entry is stale). So an entry of
        // a vertex whose stamp is unchanged is live: one comparison decides.
        while let Some(&(_, v, st)) = self.sorted.get(self.pos) {
            if ws.stamp(v as usize) == st {
                debug_assert!(ws.alive(v as usize));
                break;
            }
            self.pos += 1;
        }
        let v = match (self.sorted.get(self.pos).copied(), self.heap.peek()) {
            (Some((sk, sv, _)), Some(h)) if h < (sk, sv) => self.heap.pop().map(|e| e.1 as usize),
            (Some((_, v, _)), _) => {
                self.pos += 1;
                Some(v as usize)
            }
            (None, Some(_)) => self.heap.pop().map(|e| e.1 as usize),
            (None, None) => None,
        };
        // prefetch the likely next candidates (no effect on the result): the next sorted
        // entries (two stages: node, then what the topology check reads after it) and the
        // heap's new root
        if let Some(&(_, u, _)) = self.sorted.get(self.pos + 1) {
            ws.warm(u as usize);
        }
        if let Some(&(_, u, _)) = self.sorted.get(self.pos) {
            ws.warm_around(u as usize);
        }
        if let Some(&(_, u)) = self.heap.items.first() {
            ws.warm(u as usize);
        }
        v
    }
}
