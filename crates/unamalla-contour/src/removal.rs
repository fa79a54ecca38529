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
//! The live vertices are kept in a sparse bucket grid (cells of about four mean edge lengths):
//! removal is O(cell size) and a query visits the cells under the triangle's bounding box.

use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap};
use std::hash::{BuildHasherDefault, Hasher};

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
        let o = orient2d(a, pb, c);
        let lo = a.min(pb).min(c);
        let hi = a.max(pb).max(c);
        let contains = |p: DVec2| -> bool {
            if p.cmplt(lo).any() || p.cmpgt(hi).any() {
                return false;
            }
            if o > 0.0 {
                orient2d(a, pb, p) >= 0.0 && orient2d(pb, c, p) >= 0.0 && orient2d(c, a, p) >= 0.0
            } else if o < 0.0 {
                orient2d(a, pb, p) <= 0.0 && orient2d(pb, c, p) <= 0.0 && orient2d(c, a, p) <= 0.0
            } else {
                point_on_segment(a, c, p)
                    || point_on_segment(a, pb, p)
                    || point_on_segment(pb, c, p)
            }
        };
        match self.grid.find_in_box(lo, hi, |v| {
            (v != ia && v != b && v != ic && contains(self.pts[v])).then_some(v)
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
        let p = self.pts[b];
        self.grid.remove(b as u32, p);
    }
}

/// A sparse uniform bucket grid over the live vertices: cells of side ≈ 4 × the mean edge
/// length, stored in a hash map (only occupied cells exist), so a cell holds a handful of
/// vertices whatever the ring's shape — a dense grid sized by the bounding box puts hundreds of
/// vertices of a long curve into one cell. Removal is O(cell size); a query visits the cells
/// under the triangle's bounding box (or, for a huge box, the occupied cells). Chosen over a
/// dynamic R*-tree (`rstar` insert/remove), whose queries and removals dominated the
/// 100k-vertex benchmark (`docs/benchmarks.md`).
#[derive(Debug, Clone)]
struct Grid {
    lo: DVec2,
    inv_cell: f64,
    cells: HashMap<(i64, i64), Vec<u32>, BuildHasherDefault<CellHasher>>,
}

/// Multiplicative hasher for the grid's integer cell keys (SipHash is needlessly slow here).
#[derive(Default)]
struct CellHasher(u64);
impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_i64(&mut self, x: i64) {
        self.write_u64(x as u64);
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

impl Grid {
    fn new(pts: &[DVec2], mean_edge: f64) -> Self {
        let lo = pts
            .iter()
            .fold(DVec2::splat(f64::INFINITY), |lo, &p| lo.min(p));
        let hi = pts
            .iter()
            .fold(DVec2::splat(f64::NEG_INFINITY), |hi, &p| hi.max(p));
        let ext = (hi - lo).max_element();
        // ≈ 4 mean edges per cell, but never more than ~2^20 cells per axis
        let mut cell = (4.0 * mean_edge).max(ext / 1_048_576.0);
        if !(cell > 0.0 && cell.is_finite()) {
            cell = 1.0;
        }
        let mut g = Self {
            lo,
            inv_cell: 1.0 / cell,
            cells: HashMap::with_capacity_and_hasher(pts.len() / 2 + 1, Default::default()),
        };
        for (i, &p) in pts.iter().enumerate() {
            let c = g.coord(p);
            g.cells.entry(c).or_default().push(i as u32);
        }
        g
    }
    #[inline]
    fn coord(&self, p: DVec2) -> (i64, i64) {
        let q = ((p - self.lo) * self.inv_cell).floor();
        (q.x as i64, q.y as i64)
    }
    fn remove(&mut self, id: u32, p: DVec2) {
        let c = self.coord(p);
        if let Some(cell) = self.cells.get_mut(&c) {
            if let Some(k) = cell.iter().position(|&v| v == id) {
                cell.swap_remove(k);
            }
            if cell.is_empty() {
                self.cells.remove(&c);
            }
        }
    }
    /// Calls `f` on every vertex id in the cells meeting the box `[lo, hi]` until it returns
    /// `Some`.
    fn find_in_box<T>(
        &self,
        lo: DVec2,
        hi: DVec2,
        mut f: impl FnMut(usize) -> Option<T>,
    ) -> Option<T> {
        let (x0, y0) = self.coord(lo);
        let (x1, y1) = self.coord(hi);
        let span = (x1 - x0 + 1) as f64 * (y1 - y0 + 1) as f64;
        if span > 2.0 * self.cells.len() as f64 {
            for (&(x, y), cell) in &self.cells {
                if x >= x0 && x <= x1 && y >= y0 && y <= y1 {
                    for &v in cell {
                        if let Some(t) = f(v as usize) {
                            return Some(t);
                        }
                    }
                }
            }
            return None;
        }
        for y in y0..=y1 {
            for x in x0..=x1 {
                if let Some(cell) = self.cells.get(&(x, y)) {
                    for &v in cell {
                        if let Some(t) = f(v as usize) {
                            return Some(t);
                        }
                    }
                }
            }
        }
        None
    }
}

/// A min-heap entry: key, vertex, version stamp.
#[derive(Debug, Clone, Copy)]
struct Entry {
    key: f64,
    v: u32,
    stamp: u32,
}
impl PartialEq for Entry {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        // reversed: BinaryHeap is a max-heap; ties broken by the lower vertex id first
        o.key.total_cmp(&self.key).then(o.v.cmp(&self.v))
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

/// Sequential (one vertex at a time) removal on ring `r` with a priority queue: repeatedly
/// take the live vertex of smallest `key`, stop when it is not below the threshold, skip it if
/// its removal is topologically unsafe, otherwise remove it and update only its two
/// neighbours' keys (lazy deletion by version stamps). O(n log n). A skipped vertex comes
/// back when a neighbour changes; the vertices still skipped when the queue runs out are
/// retried in up to [`RETRY_ROUNDS`] further rounds (other removals may have emptied their
/// triangles). Returns the number removed.
pub(crate) fn sequential<K>(ws: &mut Workspace, r: usize, key: K, stop: Stop) -> usize
where
    K: Fn(DVec2, DVec2, DVec2) -> f64,
{
    let Stop::Below(threshold) = stop;
    let ids = ws.ring_ids(r);
    let mut stamp = vec![0u32; ws.pts.len()];
    let mut cur = vec![0.0f64; ws.pts.len()];
    let mut heap = BinaryHeap::with_capacity(2 * ids.len());
    for &v in &ids {
        let (a, b, c) = ws.triangle(v);
        let k = key(a, b, c);
        cur[v] = k;
        if k < threshold {
            heap.push(Entry {
                key: k,
                v: v as u32,
                stamp: 0,
            });
        }
    }
    let mut removed = 0;
    let mut skipped: Vec<(u32, u32)> = Vec::new();
    for _ in 0..=RETRY_ROUNDS {
        let mut removed_round = 0;
        while let Some(e) = heap.pop() {
            let v = e.v as usize;
            if !ws.alive[v] || e.stamp != stamp[v] {
                continue;
            }
            if e.key.partial_cmp(&threshold) != Some(Ordering::Less) || ws.len[r] <= 3 {
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
                cur[w] = k;
                stamp[w] = stamp[w].wrapping_add(1);
                if k < threshold {
                    heap.push(Entry {
                        key: k,
                        v: w as u32,
                        stamp: stamp[w],
                    });
                }
            }
        }
        if removed_round == 0 || skipped.is_empty() || ws.len[r] <= 3 {
            break;
        }
        heap.clear();
        for (v, st) in skipped.drain(..) {
            let v = v as usize;
            // still live and not re-queued since (a neighbour change would have done that)
            if ws.alive[v] && stamp[v] == st {
                heap.push(Entry {
                    key: cur[v],
                    v: v as u32,
                    stamp: st,
                });
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
}
