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
//!
//! Files: this module holds the [`Workspace`] and its topology check; `grid` the bucket grid
//! of live vertices, `queue` the priority queue of the removal order, `run` the removal loops
//! (`sequential`, `batch`).

use glam::DVec2;
use unamalla_mesh::geometry::{orient2d, point_on_segment};

mod grid;
mod queue;
mod run;
#[cfg(test)]
mod tests;

pub(crate) use run::{batch, sequential, Stop};

use self::grid::Grid;

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
