//! The bucket grid of the live vertices of all rings (open addressing, slots cell by cell).

use glam::DVec2;

use super::Node;

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
pub(super) struct Grid {
    lo: DVec2,
    inv_cell: f64,
    pub(super) table: Vec<Slot>,
    mask: usize,
    /// Number of occupied cells.
    cells: usize,
    pub(super) pts: Vec<DVec2>,
}

/// One slot of the grid's hash table.
#[derive(Debug, Clone, Copy)]
pub(super) struct Slot {
    /// Packed cell coordinates, [`Grid::EMPTY`] for a free slot.
    key: u64,
    pub(super) start: u32,
    live: u32,
}

impl Grid {
    const EMPTY: u64 = u64::MAX;

    /// Builds the grid of the nodes' points and stores each node's slot in [`Node::slot`].
    pub(super) fn new(nodes: &mut [Node], mean_edge: f64) -> Self {
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
    pub(super) fn remove(&mut self, slot: u32, p: DVec2) {
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
    pub(super) fn any_in_box(
        &self,
        lo: DVec2,
        hi: DVec2,
        near: [u32; 3],
        f: impl Fn(DVec2) -> bool,
    ) -> bool {
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
