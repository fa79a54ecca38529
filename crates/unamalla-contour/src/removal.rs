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
//! Performance notes (target: < 100 ms on the 100,000-vertex ring of `benches/simplify.rs`;
//! figures in `docs/benchmarks.md`): the removal loop
//! is memory-bound — each step touches a random place of the ring — so the data structures
//! are flat arrays indexed by vertex id: the priority queue `Queue` (initial keys sorted once +
//! `IndexedHeap` of recomputed keys, no stale entries) and the grid (open-addressing table of
//! occupied cells with a locality-preserving slot layout, vertices stored cell by cell). All
//! of them reproduce the previous decisions exactly (same order of removals, same topology
//! answers), which `tests/baseline.rs` checks against the outputs stored before the change.
//!
//! Second round (measured with `perf record`: the loop's time was mostly cache
//! misses, one per separate per-vertex array): everything the loop reads about a vertex —
//! point, links, grid slot, liveness and a *stamp* counting its neighbour changes — is one
//! 32-byte `Node`; the stamp also replaces the queue's "updated" flags and the retry
//! bookkeeping (an initial key is current iff the stamp is unchanged), so the staleness check
//! reads the node the topology check needs next anyway; the grid stores only points and
//! removes by searching the (just scanned) cell, so no per-vertex position array is kept up
//! to date; and the data of the next queue candidates and of the neighbours whose keys a
//! removal updates are prefetched an iteration ahead (`touch`). Tried and not kept (no
//! measurable gain): grid cells of vertex ids instead of points, cache-line-aligned sibling
//! groups in the heap, a branch-free child selection, recomputing lazily increased keys from
//! the triangle instead of storing them.

use glam::DVec2;
use unamalla_mesh::geometry::{orient2d, point_on_segment};

/// Marks a removed vertex in [`Node::slot`].
const DEAD: u32 = u32::MAX;

/// Everything the removal loop reads about one vertex, in one 32-byte record (two per cache
/// line): the loop visits vertices in key order, i.e. at random places of the ring, so one
/// record per vertex costs one cache miss where separate arrays (points, links, liveness, ring,
/// grid cell) cost one each (these misses were most of the topology check's time).
#[derive(Debug, Clone, Copy)]
#[repr(C)]
struct Node {
    p: DVec2,
    prev: u32,
    next: u32,
    /// The grid table slot of the vertex's cell; [`DEAD`] once removed.
    slot: u32,
    /// How many times a neighbour of the vertex was removed (its triangle changed): a key
    /// computed when the stamp was `s` is current iff the stamp is still `s`.
    stamp: u32,
}

/// Linked rings plus a dynamic spatial index of their live vertices.
#[derive(Debug, Clone)]
pub(crate) struct Workspace {
    nodes: Vec<Node>,
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
        let mut nodes = Vec::with_capacity(total);
        let mut start = Vec::with_capacity(rings.len() + 1);
        let mut perimeter = 0.0;
        for ring in rings {
            let s = nodes.len();
            start.push(s);
            let n = ring.len();
            for (k, &p) in ring.iter().enumerate() {
                nodes.push(Node {
                    p,
                    prev: (s + (k + n - 1) % n) as u32,
                    next: (s + (k + 1) % n) as u32,
                    slot: 0,
                    stamp: 0,
                });
            }
            perimeter += (0..n)
                .map(|k| ring[k].distance(ring[(k + 1) % n]))
                .sum::<f64>();
        }
        start.push(nodes.len());
        let mean_edge = perimeter / total.max(1) as f64;
        let grid = Grid::new(&mut nodes, mean_edge);
        Self {
            len: rings.iter().map(Vec::len).collect(),
            head: start[..rings.len()].iter().map(|&s| s as u32).collect(),
            grid,
            nodes,
            start,
        }
    }

    pub(crate) fn num_rings(&self) -> usize {
        self.len.len()
    }
    /// Total number of vertices (live or removed) over all rings.
    pub(crate) fn num_vertices(&self) -> usize {
        self.nodes.len()
    }
    /// Live vertex count of ring `r`.
    pub(crate) fn ring_len(&self, r: usize) -> usize {
        self.len[r]
    }
    #[inline]
    pub(crate) fn alive(&self, v: usize) -> bool {
        self.nodes[v].slot != DEAD
    }
    #[cfg(test)]
    pub(crate) fn point(&self, v: usize) -> DVec2 {
        self.nodes[v].p
    }
    /// The ring of vertex `v`.
    #[inline]
    pub(crate) fn ring(&self, v: usize) -> usize {
        // `start` is increasing with start[0] = 0 ≤ v, so the index is ≥ 1
        self.start.partition_point(|&s| s <= v) - 1
    }
    /// The stamp of vertex `v` (see [`Node::stamp`]).
    #[inline]
    pub(crate) fn stamp(&self, v: usize) -> u32 {
        self.nodes[v].stamp
    }
    /// The triangle `(prev, v, next)` of a live vertex.
    #[inline]
    pub(crate) fn triangle(&self, v: usize) -> (DVec2, DVec2, DVec2) {
        let n = &self.nodes[v];
        (
            self.nodes[n.prev as usize].p,
            n.p,
            self.nodes[n.next as usize].p,
        )
    }
    #[inline]
    pub(crate) fn neighbours(&self, v: usize) -> (usize, usize) {
        let n = &self.nodes[v];
        (n.prev as usize, n.next as usize)
    }

    /// Live global ids of ring `r` in ring order, starting at the lowest live id.
    pub(crate) fn ring_ids(&self, r: usize) -> Vec<usize> {
        let first = (self.start[r]..self.start[r + 1])
            .find(|&v| self.alive(v))
            .unwrap_or(self.head[r] as usize);
        let mut out = Vec::with_capacity(self.len[r]);
        let mut v = first;
        loop {
            out.push(v);
            v = self.nodes[v].next as usize;
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
        self.ring_ids(r)
            .into_iter()
            .map(|v| self.nodes[v].p)
            .collect()
    }

    /// `true` if removing live vertex `b` keeps every ring simple and all rings disjoint
    /// (see the module documentation): the ring keeps more than 3 vertices (and not 3
    /// collinear ones), and no other live vertex lies in the closed triangle `abc`.
    ///
    /// The grid stores only points, so "other" is decided by coordinates: the scanned
    /// entries equal to `a`, `b` or `c` are `a`, `b` and `c` themselves — exactly 3, as the
    /// box holds them — unless another vertex coincides with one of them (impossible in a
    /// valid region, but e.g. a ring given with a closing duplicate), and then that vertex
    /// lies in the closed triangle and blocks, as with a test by id.
    pub(crate) fn can_remove(&self, b: usize) -> bool {
        let nb = self.nodes[b];
        if nb.slot == DEAD {
            return false;
        }
        let len = self.len[self.ring(b)];
        if len <= 3 {
            return false;
        }
        let (na, nc) = (self.nodes[nb.prev as usize], self.nodes[nb.next as usize]);
        let (a, pb, c) = (na.p, nb.p, nc.p);
        // prefetch the outer neighbours, whose points the new keys of `a` and `c` need if
        // the removal goes ahead (see `touch`)
        touch(&self.nodes[na.prev as usize].slot);
        touch(&self.nodes[nc.next as usize].slot);
        if len == 4 {
            let d = self.nodes[nc.next as usize].p;
            if orient2d(a, c, d) == 0.0 {
                return false;
            }
        }
        let o = orient_sign(a, pb, c);
        let lo = a.min(pb).min(c);
        let hi = a.max(pb).max(c);
        let corners = std::cell::Cell::new(0u32);
        let contains = |p: DVec2| -> bool {
            if p.cmplt(lo).any() || p.cmpgt(hi).any() {
                return false;
            }
            if p == a || p == pb || p == c {
                corners.set(corners.get() + 1);
                return corners.get() > 3;
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
        !self
            .grid
            .any_in_box(lo, hi, [na.slot, nb.slot, nc.slot], contains)
    }

    /// Starts loading vertex `v`'s node into the cache (see [`touch`]).
    #[inline(always)]
    fn warm(&self, v: usize) {
        if let Some(n) = self.nodes.get(v) {
            touch(&n.slot);
        }
    }
    /// Starts loading what [`Workspace::can_remove`] reads after `v`'s node: the nodes of its
    /// neighbours and its grid cell (its table slot and the cell's first points). Call it once
    /// `v`'s node is in cache ([`Workspace::warm`] an iteration earlier), or it waits for it.
    #[inline(always)]
    fn warm_around(&self, v: usize) {
        if let Some(n) = self.nodes.get(v) {
            if n.slot != DEAD {
                touch(&self.nodes[n.prev as usize].slot);
                touch(&self.nodes[n.next as usize].slot);
                if let Some(s) = self.grid.table.get(n.slot as usize) {
                    if let Some(p) = self.grid.pts.get(s.start as usize) {
                        touch(&p.x);
                    }
                }
            }
        }
    }

    /// Removes live vertex `b` (callers check [`Workspace::can_remove`] first) and bumps the
    /// stamps of its neighbours.
    pub(crate) fn remove(&mut self, b: usize) {
        let nb = self.nodes[b];
        debug_assert!(nb.slot != DEAD);
        let (ia, ic) = (nb.prev as usize, nb.next as usize);
        let na = &mut self.nodes[ia];
        na.next = ic as u32;
        na.stamp = na.stamp.wrapping_add(1);
        let nc = &mut self.nodes[ic];
        nc.prev = ia as u32;
        nc.stamp = nc.stamp.wrapping_add(1);
        self.nodes[b].slot = DEAD;
        let r = self.ring(b);
        self.len[r] -= 1;
        if self.head[r] as usize == b {
            self.head[r] = ia as u32;
        }
        self.grid.remove(nb.slot, nb.p);
    }
}

/// Software prefetch of the cache line holding `x` (a hint: no effect on any result). The
/// removal loop is bound by cache misses on data whose address is known an iteration ahead
/// (the next queue candidates, the neighbours whose keys a removal will update); starting the
/// load early lets the miss overlap with the current iteration's work instead of stalling the
/// next one. On x86-64 this is `prefetcht0` (`_mm_prefetch`); a plain read kept alive with
/// `black_box` was measured too, but it stalls at retirement and gained about half as much.
/// Elsewhere it does nothing.
#[inline(always)]
fn touch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: `_mm_prefetch` is `unsafe` only because it is a `target_feature(enable = "sse")`
    // function, and SSE is part of the x86-64 baseline, so it is available on every x86-64
    // CPU. The pointer comes from a valid reference, and a prefetch never faults nor changes
    // memory.
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>((x as *const T).cast::<i8>());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
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
/// `start..start + live` of live points in one array `pts`, stored cell by cell (CSR-style) —
/// so one probe gives the cell's contents. The home slot keeps the 4 × 4 blocks of cells
/// together (hash of the block, cell position in the low bits), so the cells under one
/// triangle's bounding box share one or two cache lines of the table. Each vertex's
/// [`Node`] records its cell's slot, so the cells of a triangle's own vertices need no
/// hashing and a removal none either: it finds the point in its cell's range (a few entries,
/// just scanned by the topology check, so in cache) and swaps it with the cell's last live one.
/// Only points are stored (16 bytes an entry; no ids and no per-vertex position, which cost a
/// cache miss per removal to keep up to date): the topology check identifies `a`, `b`, `c` by
/// coordinates. Replaces a `HashMap<(i64, i64), Vec<u32>>` and, before it, a dynamic R*-tree
/// (`docs/benchmarks.md`).
#[derive(Debug, Clone)]
struct Grid {
    lo: DVec2,
    inv_cell: f64,
    table: Vec<Slot>,
    mask: usize,
    /// Number of occupied cells.
    cells: usize,
    pts: Vec<DVec2>,
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

    /// Builds the grid of the nodes' points and stores each node's slot in [`Node::slot`].
    fn new(nodes: &mut [Node], mean_edge: f64) -> Self {
        let (lo, hi) = nodes.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), n| (lo.min(n.p), hi.max(n.p)),
        );
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
            pts: vec![DVec2::ZERO; nodes.len()],
        };
        // insert the occupied cells, record each vertex's slot and count each cell's vertices,
        // growing the table to keep its load ≤ 1/4; slots move when it grows, so then the
        // slots and counts are redone once the table is final (sized for ≈ 2 vertices per
        // cell, the table rarely grows: the 100k ring has ≈ 8 per cell)
        g.resize((nodes.len() / 2).next_power_of_two().max(16));
        let mut grown = false;
        for n in nodes.iter_mut() {
            let (x, y) = g.coord(n.p);
            let h = g.insert(Self::pack(x, y));
            n.slot = h as u32;
            g.table[h].live += 1;
            if 4 * g.cells > g.table.len() {
                grown = true;
                let old = std::mem::take(&mut g.table);
                g.resize(2 * old.len());
                for s in old.iter().filter(|s| s.key != Self::EMPTY) {
                    g.insert(s.key);
                }
            }
        }
        if grown {
            for s in g.table.iter_mut() {
                s.live = 0;
            }
            for n in nodes.iter_mut() {
                let (x, y) = g.coord(n.p);
                let h = g.insert(Self::pack(x, y));
                n.slot = h as u32;
                g.table[h].live += 1;
            }
        }
        // ranges (prefix sums in table order), then place the points
        let mut acc = 0u32;
        for s in g.table.iter_mut().filter(|s| s.key != Self::EMPTY) {
            s.start = acc;
            acc += s.live;
            s.live = 0;
        }
        for n in nodes.iter() {
            let s = &mut g.table[n.slot as usize];
            let k = (s.start + s.live) as usize;
            s.live += 1;
            g.pts[k] = n.p;
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
    /// The cell `(⌊(x − lo.x)/cell⌋, ⌊(y − lo.y)/cell⌋)` of a point. The floor is a truncating
    /// cast corrected by one below zero (equal to `floor` for every value in range, without
    /// the libm call that `f64::floor` is on baseline x86-64).
    #[inline]
    fn coord(&self, p: DVec2) -> (i64, i64) {
        let q = (p - self.lo) * self.inv_cell;
        let floor = |t: f64| {
            let i = t as i64;
            i - ((i as f64) > t) as i64
        };
        (floor(q.x), floor(q.y))
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
    /// Removes the live point `p` of the cell in `slot`.
    #[inline]
    fn remove(&mut self, slot: u32, p: DVec2) {
        let s = &mut self.table[slot as usize];
        let a = s.start as usize;
        let last = a + s.live as usize - 1;
        let cell = &mut self.pts[a..=last];
        let k = cell.iter().position(|&q| q == p);
        debug_assert!(k.is_some(), "point {p} not in its cell");
        if let Some(k) = k {
            cell[k] = cell[cell.len() - 1];
            s.live -= 1;
        }
    }
    /// `true` if `f(point)` holds for some live point in the cells meeting the box
    /// `[lo, hi]`. `near` are the slots of cells known to meet the box (no hashing for them).
    #[inline]
    fn any_in_box(&self, lo: DVec2, hi: DVec2, near: [u32; 3], f: impl Fn(DVec2) -> bool) -> bool {
        let (x0, y0) = self.coord(lo);
        let (x1, y1) = self.coord(hi);
        let scan = |s: &Slot| -> bool {
            let a = s.start as usize;
            self.pts[a..a + s.live as usize].iter().any(|&p| f(p))
        };
        let span = (x1 - x0 + 1) as f64 * (y1 - y0 + 1) as f64;
        if span > 2.0 * self.cells as f64 {
            return self.table.iter().any(|s| {
                if s.key == Self::EMPTY {
                    return false;
                }
                let (x, y) = Self::unpack(s.key);
                x >= x0 && x <= x1 && y >= y0 && y <= y1 && scan(s)
            });
        }
        let known = near.map(|h| h as usize);
        let known_keys = known.map(|h| self.table[h].key);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let key = Self::pack(x, y);
                let h = match known_keys.iter().position(|&k| k == key) {
                    Some(i) => Some(known[i]),
                    None => self.find(x, y),
                };
                if let Some(h) = h {
                    if scan(&self.table[h]) {
                        return true;
                    }
                }
            }
        }
        false
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
    /// Starts loading `v`'s entries of `pos` and `want` (see [`touch`]).
    #[inline(always)]
    fn warm(&self, v: usize) {
        if let (Some(p), Some(w)) = (self.pos.get(v), self.want.get(v)) {
            touch(p);
            touch(w);
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
/// * `sorted`: the **initial** keys, sorted once (`sort_unstable` on `(key, vertex, stamp)`
///   triples, ordered by `(key, vertex)` as the vertex is unique; cache-friendly) and consumed
///   front to back. An entry is stale iff its vertex's [`Node::stamp`] changed since (a
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
struct Queue {
    sorted: Vec<(u64, u32, u32)>,
    pos: usize,
    heap: IndexedHeap,
}

impl Queue {
    /// Pops the smallest queued vertex.
    #[inline]
    fn pop(&mut self, ws: &Workspace) -> Option<usize> {
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
    let n = ws.num_vertices();
    let mut sorted = Vec::with_capacity(ids.len());
    for &v in &ids {
        let (a, b, c) = ws.triangle(v);
        let k = key(a, b, c);
        if k < threshold {
            sorted.push((order_bits(k), v as u32, ws.stamp(v)));
        }
    }
    sorted.sort_unstable();
    let mut q = Queue {
        sorted,
        pos: 0,
        heap: IndexedHeap::new(n),
    };
    let mut removed = 0;
    // skipped vertices with their stamps: one is re-queued in a retry round only if no
    // neighbour change re-queued it since
    let mut skipped: Vec<(u32, u32)> = Vec::new();
    for _ in 0..=RETRY_ROUNDS {
        let mut removed_round = 0;
        while let Some(v) = q.pop(ws) {
            // every queued key is below the threshold (only those are queued)
            if ws.ring_len(r) <= 3 {
                break;
            }
            // prefetch the heap positions the key updates will read (see `touch`)
            let (ia, ic) = ws.neighbours(v);
            q.heap.warm(ia);
            q.heap.warm(ic);
            if !ws.can_remove(v) {
                skipped.push((v as u32, ws.stamp(v)));
                continue;
            }
            ws.remove(v);
            // second prefetch stage for the heap's root (its node was prefetched at the pop)
            if let Some(&(_, u)) = q.heap.items.first() {
                ws.warm_around(u as usize);
            }
            removed += 1;
            removed_round += 1;
            // `remove` bumped the stamps of `ia`, `ic`: their `sorted` entries are stale
            for w in [ia, ic] {
                let (a, b, c) = ws.triangle(w);
                let k = key(a, b, c);
                if k < threshold {
                    q.heap.set(w, order_bits(k));
                } else {
                    q.heap.remove(w);
                }
            }
        }
        if removed_round == 0 || skipped.is_empty() || ws.ring_len(r) <= 3 {
            break;
        }
        q.heap.clear();
        q.pos = q.sorted.len();
        for (v, st) in skipped.drain(..) {
            let v = v as usize;
            // still live and not re-queued since (a neighbour change would have done that)
            if ws.alive(v) && ws.stamp(v) == st {
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
            if ws.ring_len(r) <= 3 {
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
        if !ws.alive(b) || ws.ring_len(r) <= 3 {
            return false;
        }
        let (ia, ic) = ws.neighbours(b);
        let (a, pb, c) = (ws.point(ia), ws.point(b), ws.point(ic));
        if ws.ring_len(r) == 4 && orient2d(a, c, ws.point(ws.neighbours(ic).1)) == 0.0 {
            return false;
        }
        let o = orient2d(a, pb, c);
        (0..ws.num_vertices())
            .filter(|&v| ws.alive(v) && v != ia && v != b && v != ic)
            .all(|v| {
                let p = ws.point(v);
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
                for b in 0..ws.num_vertices() {
                    if ws.alive(b) {
                        prop_assert_eq!(ws.can_remove(b), brute_can_remove(&ws, b), "vertex {}", b);
                    }
                }
                let b = step as usize % ws.num_vertices();
                if ws.alive(b) && ws.can_remove(b) {
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
