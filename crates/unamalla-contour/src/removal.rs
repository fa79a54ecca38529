//! One-vertex removal with **topology safety**, shared by every vertex-removing method.
//!
//! All rings of a region live in one [`Workspace`]: a doubly linked list per ring plus a
//! dynamic spatial index (a bucket grid) of the live vertices of *all* rings. Removing vertex `b` with
//! live neighbours `a`, `c` replaces the edges `ab`, `bc` by `ac`. The removal is allowed iff
//!
//! 1. the ring keeps at least 3 vertices (and they are not collinear), and
//! 2. no other live vertex of any ring lies in the **closed** triangle `abc` (exact
//!    [`orient2d`]; for collinear `a, b, c` the triangle is the segment `ac`).
//!
//! Why 2 suffices (given the current rings are simple and pairwise disjoint, the invariant):
//! an edge that meets the closed triangle but has no endpoint in it enters and leaves the
//! triangle through two of its sides or corners; it cannot meet `ab` or `bc` (rings are simple
//! and disjoint) nor pass through `a`, `b`, `c` (they are vertices of other edges), and a
//! segment cannot enter and leave a convex set through the single side `ac` without being
//! collinear with it, which again puts it through `a` or `c`. Edges incident to `a` or `c`
//! (other than `ab`, `bc`) have their far endpoint in the triangle whenever they enter it. So
//! the new edge `ac` crosses nothing, no ring (hole or piece of the same ring) can end up on the
//! other side of it, and the ring's orientation is kept: the removal is a continuous sweep of
//! `b` across an empty triangle. The region stays valid after every accepted removal.
//!
//! The live vertices are kept in a sparse bucket grid (cells of about eight mean edge lengths,
//! flat arrays, see `Grid`): removal is O(1) and a query visits the cells under the
//! triangle's bounding box. The point-in-triangle tests use `orient2d` with its floating-point
//! filter inlined (`criteria::orient2d_fast`, bit-identical to the exact predicate).
//!
//! Performance notes (issue #5, 100,000-vertex ring, `docs/benchmarks.md`): the removal loop
//! is memory-bound — each step touches a random place of the ring — so the data structures
//! are flat arrays indexed by vertex id: the priority queue `Queue` (initial keys sorted once +
//! `IndexedHeap` of recomputed keys, no stale entries) and the grid (open-addressing table of
//! occupied cells with a locality-preserving slot layout, vertices stored cell by cell). All
//! of them reproduce the previous decisions exactly (same order of removals, same topology
//! answers), which `tests/baseline.rs` checks against the outputs stored before the change.

use glam::DVec2;
use unamalla_mesh::geometry::{orient2d, point_on_segment};

/// Linked rings plus a dynamic spatial index of their live vertices.
#[derive(Debug, Clone)]
pub(crate) struct Workspace {
    pts: Vec<DVec2>,
    ring_of: Vec<u32>,
    prev: Vec<u32>,
    next: Vec<u32>,
    alive: Vec<bool>,
    /// First global id of each ring (ring `r` owns ids `start[r]..start[r + 1]`).
    start: Vec<usize>,
    /// Live vertex count of each ring.
    len: Vec<usize>,
    /// A live vertex of each ring (to walk it).
    head: Vec<u32>,
    grid: Grid,
}

impl Workspace {
    /// Builds the workspace; rings must form a valid region (simple, disjoint).
    pub(crate) fn new(rings: &[Vec<DVec2>]) -> Self {
        let total: usize = rings.iter().map(Vec::len).sum();
        let mut pts = Vec::with_capacity(total);
        let mut ring_of = Vec::with_capacity(total);
        let mut prev = Vec::with_capacity(total);
        let mut next = Vec::with_capacity(total);
        let mut start = Vec::with_capacity(rings.len() + 1);
        for (r, ring) in rings.iter().enumerate() {
            let s = pts.len();
            start.push(s);
            let n = ring.len();
            for (k, &p) in ring.iter().enumerate() {
                pts.push(p);
                ring_of.push(r as u32);
                prev.push((s + (k + n - 1) % n) as u32);
                next.push((s + (k + 1) % n) as u32);
            }
        }
        start.push(pts.len());
        let edges: usize = rings.iter().map(Vec::len).sum::<usize>().max(1);
        let mean_edge = rings
            .iter()
            .map(|r| {
                let n = r.len();
                (0..n).map(|k| r[k].distance(r[(k + 1) % n])).sum::<f64>()
            })
            .sum::<f64>()
            / edges as f64;
        Self {
            alive: vec![true; pts.len()],
            len: rings.iter().map(Vec::len).collect(),
            head: start[..rings.len()].iter().map(|&s| s as u32).collect(),
            grid: Grid::new(&pts, mean_edge),
            pts,
            ring_of,
            prev,
            next,
            start,
        }
    }

    pub(crate) fn num_rings(&self) -> usize {
        self.len.len()
    }
    pub(crate) fn ring(&self, v: usize) -> usize {
        self.ring_of[v] as usize
    }
    /// The triangle `(prev, v, next)` of a live vertex.
    pub(crate) fn triangle(&self, v: usize) -> (DVec2, DVec2, DVec2) {
        (
            self.pts[self.prev[v] as usize],
            self.pts[v],
            self.pts[self.next[v] as usize],
        )
    }
    pub(crate) fn neighbours(&self, v: usize) -> (usize, usize) {
        (self.prev[v] as usize, self.next[v] as usize)
    }

    /// Live global ids of ring `r` in ring order, starting at the lowest live id.
    pub(crate) fn ring_ids(&self, r: usize) -> Vec<usize> {
        let first = (self.start[r]..self.start[r + 1])
            .find(|&v| self.alive[v])
            .unwrap_or(self.head[r] as usize);
        let mut out = Vec::with_capacity(self.len[r]);
        let mut v = first;
        loop {
            out.push(v);
            v = self.next[v] as usize;
            if v == first || out.len() > self.len[r] {
                break;
            }
        }
        out
    }
    /// Live vertices of ring `r` in ring order as indices into the input ring `r` (strictly
    /// increasing: the walk starts at the lowest live id and removals keep the cyclic order).
    pub(crate) fn ring_local_ids(&self, r: usize) -> Vec<usize> {
        let s = self.start[r];
        self.ring_ids(r).into_iter().map(|v| v - s).collect()
    }
    /// Live points of ring `r` in order.
    pub(crate) fn ring_points(&self, r: usize) -> Vec<DVec2> {
        self.ring_ids(r).into_iter().map(|v| self.pts[v]).collect()
    }

    /// `true` if removing live vertex `b` keeps every ring simple and all rings disjoint
    /// (see the module documentation).
    pub(crate) fn can_remove(&self, b: usize) -> bool {
        self.blocker(b).is_ok()
    }

    /// `Ok(())` if live vertex `b` can be removed; otherwise `Err(Some(v))` naming a live
    /// vertex `v` in its closed triangle, or `Err(None)` if the ring is too small.
    pub(crate) fn blocker(&self, b: usize) -> Result<(), Option<usize>> {
        let r = self.ring(b);
        if !self.alive[b] || self.len[r] <= 3 {
            return Err(None);
        }
        let (ia, ic) = self.neighbours(b);
        let (a, pb, c) = (self.pts[ia], self.pts[b], self.pts[ic]);
        if self.len[r] == 4 {
            let d = self.pts[self.next[ic] as usize];
            if orient2d(a, c, d) == 0.0 {
                return Err(None);
            }
        }
        let o = orient_sign(a, pb, c);
        let lo = a.min(pb).min(c);
        let hi = a.max(pb).max(c);
        let contains = |p: DVec2| -> bool {
            if p.cmplt(lo).any() || p.cmpgt(hi).any() {
                return false;
            }
            if o > 0.0 {
                orient_sign(a, pb, p) >= 0.0
                    && orient_sign(pb, c, p) >= 0.0
                    && orient_sign(c, a, p) >= 0.0
            } else if o < 0.0 {
                orient_sign(a, pb, p) <= 0.0
                    && orient_sign(pb, c, p) <= 0.0
                    && orient_sign(c, a, p) <= 0.0
            } else {
                point_on_segment(a, c, p)
                    || point_on_segment(a, pb, p)
                    || point_on_segment(pb, c, p)
            }
        };
        match self.grid.find_in_box(lo, hi, [ia, b, ic], |v, p| {
            (v != ia && v != b && v != ic && contains(p)).then_some(v)
        }) {
            Some(v) => Err(Some(v)),
            None => Ok(()),
        }
    }

    /// Removes live vertex `b` (callers check [`Workspace::can_remove`] first).
    pub(crate) fn remove(&mut self, b: usize) {
        debug_assert!(self.alive[b]);
        let (ia, ic) = self.neighbours(b);
        self.next[ia] = ic as u32;
        self.prev[ic] = ia as u32;
        self.alive[b] = false;
        let r = self.ring(b);
        self.len[r] -= 1;
        if self.head[r] as usize == b {
            self.head[r] = ia as u32;
        }
        self.grid.remove(b as u32);
    }
}

/// Sign-exact orientation for the topology check: [`crate::criteria::orient2d_fast`], the
/// inlined floating-point filter of `robust::orient2d` with the exact predicate as fallback
/// (bit-identical to `orient2d`, so every decision equals the exact one).
#[inline(always)]
fn orient_sign(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    crate::criteria::orient2d_fast(a, b, c)
}

/// A sparse uniform bucket grid over the live vertices (cells of side ≈ 8 × the mean edge
/// length, so a cell holds a handful of vertices whatever the ring's shape — a dense grid
/// sized by the bounding box would put hundreds of vertices of a long curve into one cell, or
/// need ≈ 6·10⁶ cells for the 100k benchmark ring at this cell size, of which only ≈ 1–2·10⁴ are
/// occupied).
///
/// Flat layout, built once: an open-addressing hash table (linear probing, ≈ 1/4 load) of the
/// occupied cells, each slot holding the cell's packed coordinates and its range
/// `start..start + live` of live vertices in one array (`ids` and their points `pts`, stored
/// cell by cell, CSR-style) — so one probe gives the cell's contents. The home slot keeps the
/// 4 × 4 blocks of cells together (hash of the block, cell position in the low bits), so the
/// cells under one triangle's bounding box share one or two cache lines of the table.
/// Removal swaps the vertex with the last live one of its cell (O(1) via `slot_of[v]` and
/// `pos[v]`, no hashing); a query probes each cell under the triangle's bounding box (the
/// cells of the triangle's own vertices are known without hashing) or, for a huge box, scans
/// the table. Replaces a `HashMap<(i64, i64), Vec<u32>>` (one allocation per cell, SipHash-free
/// but a hash on every removal) and, before it, a dynamic R*-tree (`docs/benchmarks.md`).
#[derive(Debug, Clone)]
struct Grid {
    lo: DVec2,
    inv_cell: f64,
    table: Vec<Slot>,
    mask: usize,
    /// Number of occupied cells.
    cells: usize,
    ids: Vec<u32>,
    pts: Vec<DVec2>,
    /// Per vertex: the table slot of its cell and its position in `ids`.
    slot_of: Vec<u32>,
    pos: Vec<u32>,
}

/// One slot of the grid's hash table.
#[derive(Debug, Clone, Copy)]
struct Slot {
    /// Packed cell coordinates, [`Grid::EMPTY`] for a free slot.
    key: u64,
    start: u32,
    live: u32,
}

impl Grid {
    const EMPTY: u64 = u64::MAX;

    fn new(pts: &[DVec2], mean_edge: f64) -> Self {
        let lo = pts
            .iter()
            .fold(DVec2::splat(f64::INFINITY), |lo, &p| lo.min(p));
        let hi = pts
            .iter()
            .fold(DVec2::splat(f64::NEG_INFINITY), |hi, &p| hi.max(p));
        let ext = (hi - lo).max_element();
        // ≈ 8 mean edges per cell (on the 100k ring: fewer cells under a triangle's box than
        // with 4, more points per cell, but a cell's points are contiguous; 8 measured ≈ 15 %
        // faster than 4, 12 and 16 no better), never more than ~2^20 cells per axis
        let mut cell = (8.0 * mean_edge).max(ext / 1_048_576.0);
        if !(cell > 0.0 && cell.is_finite()) {
            cell = 1.0;
        }
        let mut g = Self {
            lo,
            inv_cell: 1.0 / cell,
            table: Vec::new(),
            mask: 0,
            cells: 0,
            ids: vec![0; pts.len()],
            pts: vec![DVec2::ZERO; pts.len()],
            slot_of: vec![0; pts.len()],
            pos: vec![0; pts.len()],
        };
        // insert the occupied cells, growing the table to keep its load ≤ 1/4 (slots move
        // when it grows, so they are read afterwards), then count each cell's vertices
        g.resize((pts.len() / 4).next_power_of_two().max(16));
        for &p in pts {
            let (x, y) = g.coord(p);
            g.insert(Self::pack(x, y));
            if 4 * g.cells > g.table.len() {
                let old = std::mem::take(&mut g.table);
                g.resize(2 * old.len());
                for s in old.iter().filter(|s| s.key != Self::EMPTY) {
                    g.insert(s.key);
                }
            }
        }
        for (i, &p) in pts.iter().enumerate() {
            let (x, y) = g.coord(p);
            let h = g.insert(Self::pack(x, y));
            g.slot_of[i] = h as u32;
            g.table[h].live += 1;
        }
        // ranges (prefix sums in table order), then place the vertices
        let mut acc = 0u32;
        for s in g.table.iter_mut().filter(|s| s.key != Self::EMPTY) {
            s.start = acc;
            acc += s.live;
            s.live = 0;
        }
        for (i, &p) in pts.iter().enumerate() {
            let s = &mut g.table[g.slot_of[i] as usize];
            let k = (s.start + s.live) as usize;
            s.live += 1;
            g.ids[k] = i as u32;
            g.pts[k] = p;
            g.pos[i] = k as u32;
        }
        g
    }
    /// Empties the table and gives it `cap` (a power of two) slots.
    fn resize(&mut self, cap: usize) {
        self.table = vec![
            Slot {
                key: Self::EMPTY,
                start: 0,
                live: 0
            };
            cap
        ];
        self.mask = cap - 1;
        self.cells = 0;
    }
    #[inline]
    fn coord(&self, p: DVec2) -> (i64, i64) {
        let q = ((p - self.lo) * self.inv_cell).floor();
        (q.x as i64, q.y as i64)
    }
    #[inline]
    fn pack(x: i64, y: i64) -> u64 {
        ((x as u64 & 0xffff_ffff) << 32) | (y as u64 & 0xffff_ffff)
    }
    #[inline]
    fn unpack(key: u64) -> (i64, i64) {
        ((key >> 32) as u32 as i32 as i64, key as u32 as i32 as i64)
    }
    /// Home slot of a packed cell key: the 4 × 4 block of cells is hashed (multiplicative
    /// hash) and the cell's position inside it is the low 4 bits, so neighbouring cells — the
    /// cells under one triangle's bounding box — share one or two cache lines of the table.
    #[inline]
    fn home(&self, key: u64) -> usize {
        let (x, y) = Self::unpack(key);
        let block = Self::pack(x >> 2, y >> 2);
        let h = (block.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 32) as usize;
        ((h << 4) | ((x & 3) << 2 | (y & 3)) as usize) & self.mask
    }
    /// The slot of `key`, inserted if absent.
    fn insert(&mut self, key: u64) -> usize {
        let mut h = self.home(key);
        loop {
            let k = self.table[h].key;
            if k == key {
                return h;
            }
            if k == Self::EMPTY {
                self.table[h].key = key;
                self.cells += 1;
                return h;
            }
            h = (h + 1) & self.mask;
        }
    }
    /// The slot of cell `(x, y)` if it is occupied.
    #[inline]
    fn find(&self, x: i64, y: i64) -> Option<usize> {
        let key = Self::pack(x, y);
        let mut h = self.home(key);
        loop {
            let k = self.table[h].key;
            if k == key {
                return Some(h);
            }
            if k == Self::EMPTY {
                return None;
            }
            h = (h + 1) & self.mask;
        }
    }
    /// Removes vertex `id` (must be live).
    #[inline]
    fn remove(&mut self, id: u32) {
        let s = &mut self.table[self.slot_of[id as usize] as usize];
        let k = self.pos[id as usize] as usize;
        s.live -= 1;
        let last = (s.start + s.live) as usize;
        if k != last {
            let moved = self.ids[last];
            self.ids[k] = moved;
            self.pts[k] = self.pts[last];
            self.pos[moved as usize] = k as u32;
        }
    }
    /// Calls `f(id, point)` on every live vertex in the cells meeting the box `[lo, hi]`
    /// until it returns `Some`. `near` are live vertices whose cells need no hashing.
    #[inline]
    fn find_in_box<T>(
        &self,
        lo: DVec2,
        hi: DVec2,
        near: [usize; 3],
        mut f: impl FnMut(usize, DVec2) -> Option<T>,
    ) -> Option<T> {
        let (x0, y0) = self.coord(lo);
        let (x1, y1) = self.coord(hi);
        let mut scan = |s: &Slot| -> Option<T> {
            let a = s.start as usize;
            for k in a..a + s.live as usize {
                if let Some(t) = f(self.ids[k] as usize, self.pts[k]) {
                    return Some(t);
                }
            }
            None
        };
        let span = (x1 - x0 + 1) as f64 * (y1 - y0 + 1) as f64;
        if span > 2.0 * self.cells as f64 {
            for s in self.table.iter().filter(|s| s.key != Self::EMPTY) {
                let (x, y) = Self::unpack(s.key);
                if x >= x0 && x <= x1 && y >= y0 && y <= y1 {
                    if let Some(t) = scan(s) {
                        return Some(t);
                    }
                }
            }
            return None;
        }
        let known = near.map(|v| self.slot_of[v] as usize);
        let known_keys = known.map(|h| self.table[h].key);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let key = Self::pack(x, y);
                let h = match known_keys.iter().position(|&k| k == key) {
                    Some(i) => Some(known[i]),
                    None => self.find(x, y),
                };
                if let Some(h) = h {
                    if let Some(t) = scan(&self.table[h]) {
                        return Some(t);
                    }
                }
            }
        }
        None
    }
}

/// The key's position in the IEEE total order (`f64::total_cmp`) as an unsigned integer:
/// flip every bit of a negative value, only the sign bit of a non-negative one. Comparing
/// these integers is exactly `total_cmp`, so (key, vertex) pairs order the same way as before
/// and the removal sequence is unchanged.
#[inline]
fn order_bits(k: f64) -> u64 {
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
struct IndexedHeap {
    items: Vec<(u64, u32)>,
    /// `pos[v]`: index of `v` in `items`, or [`IndexedHeap::NONE`].
    pos: Vec<u32>,
    /// `want[v]`: the true key of a queued vertex (`≥` its stored key).
    want: Vec<u64>,
}

impl IndexedHeap {
    const NONE: u32 = u32::MAX;
    const D: usize = 4;

    fn new(n: usize) -> Self {
        Self {
            items: Vec::new(),
            pos: vec![Self::NONE; n],
            want: vec![0; n],
        }
    }
    /// The queued vertex of smallest true key (ties: lowest id), repairing lazily increased
    /// keys at the root first.
    #[inline]
    fn peek(&mut self) -> Option<(u64, u32)> {
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
    /// Inserts `v` with `key`, or changes its key (an increase lazily, see the type docs).
    fn set(&mut self, v: usize, key: u64) {
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
    fn remove(&mut self, v: usize) {
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
    fn pop(&mut self) -> Option<(u64, u32)> {
        let top = self.peek()?;
        self.remove(top.1 as usize);
        Some(top)
    }
    fn clear(&mut self) {
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

/// When the sequential removal stops.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Stop {
    /// Remove while the smallest key is below this fixed value (scaled Visvalingam, modified
    /// criteria (3.6), (3.8): `ε ·` the mean triangle area of the input ring).
    Below(f64),
}

/// Rounds of retrying vertices whose removal was blocked by the topology check.
const RETRY_ROUNDS: usize = 4;

/// The priority queue of [`sequential`]: the minimum over (key, vertex id) of the queued
/// vertices, kept in two parts:
///
/// * `sorted`: the **initial** keys, sorted once (`sort_unstable` on `(u64, u32)` pairs,
///   cache-friendly) and consumed front to back. An entry is stale iff its vertex was updated
///   since (`updated[v]`) or removed — one array read, no heap work. Most vertices of a dense
///   ring are removed with their initial key, so most pops cost O(1).
/// * `heap`: an [`IndexedHeap`] of the keys **recomputed** after a neighbour's removal
///   (changed in place, no stale entries), much smaller than the ring.
///
/// The next candidate is the smaller of the two fronts in the same total order as a single
/// heap of all entries, so the removal sequence is exactly that of one binary heap (the
/// previous implementation, a lazy `BinaryHeap` whose `pop` on ≈ 260 k entries took ≈ 28 % of
/// the 100k benchmark).
struct Queue {
    sorted: Vec<(u64, u32)>,
    pos: usize,
    heap: IndexedHeap,
    /// The vertex's key was recomputed after the initial evaluation (its `sorted` entry is
    /// stale).
    updated: Vec<bool>,
}

impl Queue {
    /// Pops the smallest queued vertex.
    #[inline]
    fn pop(&mut self, alive: &[bool]) -> Option<usize> {
        // A removed vertex was popped first: from `sorted` (its entry is behind `pos`) or from
        // the heap (then it had been updated, so its `sorted` entry is stale). So an entry of
        // a vertex that was never updated is live: one flag decides.
        while let Some(&(_, v)) = self.sorted.get(self.pos) {
            if !self.updated[v as usize] {
                debug_assert!(alive[v as usize]);
                break;
            }
            self.pos += 1;
        }
        match (self.sorted.get(self.pos).copied(), self.heap.peek()) {
            (Some(s), Some(h)) if h < s => self.heap.pop().map(|e| e.1 as usize),
            (Some((_, v)), _) => {
                self.pos += 1;
                Some(v as usize)
            }
            (None, Some(_)) => self.heap.pop().map(|e| e.1 as usize),
            (None, None) => None,
        }
    }
}

/// Sequential (one vertex at a time) removal on ring `r` with a priority queue: repeatedly
/// take the live vertex of smallest `key` (ties: lowest vertex id), stop when it is not below
/// the threshold, skip it if its removal is topologically unsafe, otherwise remove it and
/// update only its two neighbours' keys. O(n log n) ([`Queue`]). A skipped vertex comes
/// back when a neighbour changes; the vertices still skipped when the queue runs out are
/// retried in up to [`RETRY_ROUNDS`] further rounds (other removals may have emptied their
/// triangles). Returns the number removed.
pub(crate) fn sequential<K>(ws: &mut Workspace, r: usize, key: K, stop: Stop) -> usize
where
    K: Fn(DVec2, DVec2, DVec2) -> f64,
{
    let Stop::Below(threshold) = stop;
    let ids = ws.ring_ids(r);
    let n = ws.pts.len();
    // `stamp[v]` counts the key updates of `v`: a skipped vertex is re-queued in a retry round
    // only if no neighbour change re-queued it since
    let mut stamp = vec![0u32; n];
    let mut sorted = Vec::with_capacity(ids.len());
    for &v in &ids {
        let (a, b, c) = ws.triangle(v);
        let k = key(a, b, c);
        if k < threshold {
            sorted.push((order_bits(k), v as u32));
        }
    }
    sorted.sort_unstable();
    let mut q = Queue {
        sorted,
        pos: 0,
        heap: IndexedHeap::new(n),
        updated: vec![false; n],
    };
    let mut removed = 0;
    let mut skipped: Vec<(u32, u32)> = Vec::new();
    for _ in 0..=RETRY_ROUNDS {
        let mut removed_round = 0;
        while let Some(v) = q.pop(&ws.alive) {
            // every queued key is below the threshold (only those are queued)
            if ws.len[r] <= 3 {
                break;
            }
            if !ws.can_remove(v) {
                skipped.push((v as u32, stamp[v]));
                continue;
            }
            let (ia, ic) = ws.neighbours(v);
            ws.remove(v);
            removed += 1;
            removed_round += 1;
            for w in [ia, ic] {
                let (a, b, c) = ws.triangle(w);
                let k = key(a, b, c);
                stamp[w] = stamp[w].wrapping_add(1);
                q.updated[w] = true;
                if k < threshold {
                    q.heap.set(w, order_bits(k));
                } else {
                    q.heap.remove(w);
                }
            }
        }
        if removed_round == 0 || skipped.is_empty() || ws.len[r] <= 3 {
            break;
        }
        q.heap.clear();
        q.pos = q.sorted.len();
        for (v, st) in skipped.drain(..) {
            let v = v as usize;
            // still live and not re-queued since (a neighbour change would have done that)
            if ws.alive[v] && stamp[v] == st {
                // its neighbours are those of its last key evaluation (unchanged stamp), so
                // this recomputes exactly that key
                let (a, b, c) = ws.triangle(v);
                q.heap.set(v, order_bits(key(a, b, c)));
            }
        }
    }
    removed
}

/// Batch ("non-sequential") removal on ring `r` (§3.3.1–§3.3.2, Obs 3.3): each pass evaluates
/// `remove(a, b, c, mean_area)` for every live vertex of the current ring (`mean_area` is the
/// current mean triangle area), then deletes all vertices that satisfied it (each deletion
/// topology-checked against the ring as it is at that moment); passes repeat until one deletes
/// nothing. Returns the number removed.
pub(crate) fn batch<F>(ws: &mut Workspace, r: usize, remove: F) -> usize
where
    F: Fn(DVec2, DVec2, DVec2, f64) -> bool,
{
    let mut removed = 0;
    loop {
        let ids = ws.ring_ids(r);
        let tris: Vec<(DVec2, DVec2, DVec2)> = ids.iter().map(|&v| ws.triangle(v)).collect();
        let mean = tris
            .iter()
            .map(|&(a, b, c)| crate::criteria::triangle_area(a, b, c))
            .sum::<f64>()
            / ids.len() as f64;
        let cands: Vec<usize> = ids
            .iter()
            .zip(&tris)
            .filter(|(_, &(a, b, c))| remove(a, b, c, mean))
            .map(|(&v, _)| v)
            .collect();
        let mut pass = 0;
        for v in cands {
            if ws.len[r] <= 3 {
                break;
            }
            if ws.can_remove(v) {
                ws.remove(v);
                pass += 1;
            }
        }
        removed += pass;
        if pass == 0 {
            break;
        }
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn removal_blocked_by_a_vertex_of_another_ring() {
        // outer square with a midpoint bump at the top; a hole sits just under the bump's chord
        let outer = vec![v(0., 0.), v(10., 0.), v(10., 10.), v(5., 10.5), v(0., 10.)];
        let hole = vec![v(4.9, 9.9), v(5.1, 9.9), v(5.0, 10.1)];
        let ws = Workspace::new(&[outer.clone(), hole]);
        // vertex 3 (the bump) cannot go: the hole's apex (5, 10.1) is inside its triangle
        assert!(!ws.can_remove(3));
        let ws = Workspace::new(&[outer]);
        assert!(ws.can_remove(3));
    }

    #[test]
    fn reflex_pocket_blocks_ear_removal() {
        // ring a, b, c, d with d inside triangle abc: removing b would flip the ring
        let ring = vec![v(0., 0.), v(5., 10.), v(10., 0.), v(5., 3.)];
        let ws = Workspace::new(&[ring]);
        assert!(!ws.can_remove(1));
        assert!(ws.can_remove(3));
    }

    use proptest::prelude::*;
    use std::collections::BTreeSet;

    /// Brute-force reference of the topology check: no other live vertex in the closed
    /// triangle, tested against every live vertex with the exact predicate (no grid, no filter).
    fn brute_can_remove(ws: &Workspace, b: usize) -> bool {
        let r = ws.ring(b);
        if !ws.alive[b] || ws.len[r] <= 3 {
            return false;
        }
        let (ia, ic) = ws.neighbours(b);
        let (a, pb, c) = (ws.pts[ia], ws.pts[b], ws.pts[ic]);
        if ws.len[r] == 4 && orient2d(a, c, ws.pts[ws.next[ic] as usize]) == 0.0 {
            return false;
        }
        let o = orient2d(a, pb, c);
        (0..ws.pts.len())
            .filter(|&v| ws.alive[v] && v != ia && v != b && v != ic)
            .all(|v| {
                let p = ws.pts[v];
                let inside = if o != 0.0 {
                    let s = [orient2d(a, pb, p), orient2d(pb, c, p), orient2d(c, a, p)];
                    s.iter().all(|&x| x * o >= 0.0)
                } else {
                    point_on_segment(a, c, p)
                        || point_on_segment(a, pb, p)
                        || point_on_segment(pb, c, p)
                };
                !inside
            })
    }

    /// A star ring whose vertices sit on a coarse lattice (many exactly collinear triples and
    /// vertices on triangle sides, so the exact fallback of the filter is exercised).
    fn lattice_star(n: usize, radii: &[u8]) -> Vec<DVec2> {
        (0..n)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / n as f64;
                let r = 4.0 + radii[k % radii.len()] as f64 % 6.0;
                v((r * t.cos()).round() * 0.5, (r * t.sin()).round() * 0.5)
            })
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, .. ProptestConfig::default() })]

        /// The grid query with the filtered orientation agrees with the brute-force exact test
        /// for every vertex, before and after a sequence of accepted removals.
        #[test]
        fn topology_check_matches_brute_force(
            n in 8usize..60,
            radii in prop::collection::vec(any::<u8>(), 1..60),
            order in prop::collection::vec(any::<u16>(), 0..80),
            lattice in any::<bool>(),
        ) {
            let mut ring = if lattice {
                lattice_star(n, &radii)
            } else {
                (0..n)
                    .map(|k| {
                        let t = std::f64::consts::TAU * k as f64 / n as f64;
                        let r = 40.0 + radii[k % radii.len()] as f64 * 0.2;
                        v(r * t.cos(), r * t.sin())
                    })
                    .collect()
            };
            ring.dedup();
            prop_assume!(unamalla_mesh::Region::new(ring.clone(), vec![]).is_ok());
            let hole: Vec<DVec2> = vec![v(-1.0, -1.0), v(1.5, -1.0), v(0.0, 1.5)];
            let mut ws = Workspace::new(&[ring, hole]);
            for step in order {
                for b in 0..ws.pts.len() {
                    if ws.alive[b] {
                        prop_assert_eq!(ws.can_remove(b), brute_can_remove(&ws, b), "vertex {}", b);
                    }
                }
                let b = step as usize % ws.pts.len();
                if ws.alive[b] && ws.can_remove(b) {
                    ws.remove(b);
                }
            }
        }

        /// The filtered orientation has the sign of the exact predicate, also for exactly and
        /// nearly collinear points.
        #[test]
        fn filtered_orientation_has_the_exact_sign(
            ax in -1e3f64..1e3, ay in -1e3f64..1e3, bx in -1e3f64..1e3, by in -1e3f64..1e3,
            t in -2.0f64..3.0, ulps in -3i64..4,
        ) {
            let (a, b) = (v(ax, ay), v(bx, by));
            let p = a + t * (b - a);
            let p = v(f64::from_bits((p.x.to_bits() as i64 + ulps) as u64), p.y);
            for (x, y, z) in [(a, b, p), (b, p, a), (p, a, b), (a, a, p)] {
                prop_assert_eq!(orient_sign(x, y, z).partial_cmp(&0.0), orient2d(x, y, z).partial_cmp(&0.0));
            }
        }

        /// The indexed heap pops in (key, vertex) order under random set/remove operations
        /// (model: a `BTreeSet` of (key, vertex)).
        #[test]
        fn indexed_heap_matches_an_ordered_set(
            ops in prop::collection::vec((0usize..40, 0u64..20, 0u8..4), 1..300),
        ) {
            let mut h = IndexedHeap::new(40);
            let mut model: BTreeSet<(u64, u32)> = BTreeSet::new();
            let mut key_of = [None::<u64>; 40];
            for (v, k, op) in ops {
                match op {
                    0 | 1 => {
                        if let Some(old) = key_of[v] {
                            model.remove(&(old, v as u32));
                        }
                        h.set(v, k);
                        model.insert((k, v as u32));
                        key_of[v] = Some(k);
                    }
                    2 => {
                        if let Some(old) = key_of[v].take() {
                            model.remove(&(old, v as u32));
                        }
                        h.remove(v);
                    }
                    _ => {
                        let got = h.pop();
                        let want = model.iter().next().copied();
                        if let Some(w) = want {
                            model.remove(&w);
                            key_of[w.1 as usize] = None;
                        }
                        prop_assert_eq!(got, want);
                    }
                }
                prop_assert_eq!(h.peek(), model.iter().next().copied());
                prop_assert_eq!(h.items.len(), model.len());
            }
        }
    }

    #[test]
    fn order_bits_is_total_cmp() {
        // the mapping must be monotone in f64::total_cmp, including signed zeros
        let xs = [
            f64::NEG_INFINITY,
            -2.0,
            -1e-300,
            -0.0,
            0.0,
            1e-300,
            1.0,
            3.5,
            f64::INFINITY,
        ];
        for w in xs.windows(2) {
            assert!(order_bits(w[0]) < order_bits(w[1]), "{} < {}", w[0], w[1]);
            assert_eq!(
                w[0].total_cmp(&w[1]),
                order_bits(w[0]).cmp(&order_bits(w[1]))
            );
        }
    }
}
