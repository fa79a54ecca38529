//! Connectivity shared by the 2D and 3D functionals: the free-variable map, neighbour lists
//! (the Hessian pattern), node → cell incidences (the local models) and the **chunk colouring**
//! that makes parallel evaluation deterministic.
//!
//! # Determinism
//! Cells are cut into chunks of [`CHUNK_CELLS`] consecutive cells (a constant, independent of the
//! number of threads). Chunks that share a node get different colours (greedy colouring in chunk
//! order). Colours are processed one after the other; inside a colour the chunks run in parallel
//! and each chunk visits its cells in order, adding its contributions straight into the output
//! gradient / Hessian. Two chunks of one colour touch disjoint sets of nodes, so they write
//! disjoint entries, and every entry receives its additions in the fixed order
//! (colour, chunk, cell, term). Values are summed per chunk and the chunk sums are added in chunk
//! order. The result is therefore bit-identical for any thread count, without atomics.
//! For structured grids numbered row by row two or three colours suffice; a mesh numbered in
//! random order still works, only with less parallelism.

use std::sync::Mutex;

use rayon::prelude::*;

use crate::error::FunctionalError;

/// Number of consecutive cells per parallel chunk (fixed, so results do not depend on threads).
pub const CHUNK_CELLS: usize = 1024;

/// Marker for a fixed node in [`Assembly::var_of`].
pub(crate) const FIXED: u32 = u32::MAX;
/// Flag bit of a fixed node in [`Assembly::src`] (the other bits are the node id).
pub(crate) const FIXED_BIT: u32 = 1 << 31;

/// A raw pointer that may be shared between the threads of one colour (see the module docs).
#[derive(Clone, Copy)]
pub(crate) struct SyncPtr(*mut f64);
// SAFETY: the pointer is only dereferenced at indices that are written by exactly one chunk of
// the colour being processed (chunks of one colour share no node), and the buffer outlives the
// parallel section (it is borrowed mutably for the whole call).
unsafe impl Send for SyncPtr {}
unsafe impl Sync for SyncPtr {}
impl SyncPtr {
    pub(crate) fn new(s: &mut [f64]) -> Self {
        SyncPtr(s.as_mut_ptr())
    }
    /// Adds `v` at index `i`.
    ///
    /// # Safety
    /// `i` must be in bounds and no other thread may access index `i` concurrently.
    #[inline(always)]
    pub(crate) unsafe fn add(self, i: usize, v: f64) {
        *self.0.add(i) += v;
    }
    /// Stores `v` at index `i` if `first`, adds it otherwise (the first contribution of the
    /// deterministic schedule overwrites, so the buffer needs no zeroing pass).
    ///
    /// # Safety
    /// As for [`add`](Self::add).
    #[inline(always)]
    pub(crate) unsafe fn put(self, i: usize, v: f64, first: bool) {
        let p = self.0.add(i);
        *p = if first { v } else { *p + v };
    }
}

/// Connectivity of a mesh whose cells have `K` nodes, with free/fixed flags.
#[derive(Debug)]
pub(crate) struct Assembly<const K: usize> {
    pub num_nodes: usize,
    /// Variable-node index of each node, or [`FIXED`].
    pub var_of: Vec<u32>,
    /// Mesh node id of each variable node (increasing).
    pub free: Vec<usize>,
    pub cells: Vec<[u32; K]>,
    /// Per cell and vertex: the variable-node index of a free node, or `FIXED_BIT | node` for a
    /// fixed one (saves the `var_of` indirection in the hot loops).
    pub src: Vec<[u32; K]>,
    /// Sorted neighbour lists (variable-node indices, including the node itself) of every free
    /// node: the block pattern of the Hessian.
    pub nbr_offsets: Vec<usize>,
    pub nbr: Vec<u32>,
    /// Cells incident to each node (all nodes).
    pub inc_offsets: Vec<usize>,
    pub inc: Vec<u32>,
    /// Chunk ids grouped by colour.
    pub colors: Vec<Vec<u32>>,
    pub num_chunks: usize,
    scratch: Mutex<Vec<f64>>,
}

impl<const K: usize> Assembly<K> {
    pub(crate) fn new(
        num_nodes: usize,
        cells: Vec<[usize; K]>,
        fixed: impl Fn(usize) -> bool,
    ) -> Result<Self, FunctionalError> {
        if cells.is_empty() {
            return Err(FunctionalError::UnsupportedSize(
                "the mesh has no cells".into(),
            ));
        }
        if num_nodes >= FIXED_BIT as usize || cells.len() >= u32::MAX as usize {
            return Err(FunctionalError::UnsupportedSize(format!(
                "{num_nodes} nodes / {} cells exceed the 32-bit indices",
                cells.len()
            )));
        }
        let mut cells32 = Vec::with_capacity(cells.len());
        for (c, cell) in cells.iter().enumerate() {
            let mut out = [0u32; K];
            for (o, &v) in out.iter_mut().zip(cell.iter()) {
                if v >= num_nodes {
                    return Err(FunctionalError::NodeOutOfRange {
                        cell: c,
                        node: v,
                        num_nodes,
                    });
                }
                *o = v as u32;
            }
            cells32.push(out);
        }
        let mut var_of = vec![FIXED; num_nodes];
        let mut free = Vec::new();
        for (v, slot) in var_of.iter_mut().enumerate() {
            if !fixed(v) {
                *slot = free.len() as u32;
                free.push(v);
            }
        }
        let src: Vec<[u32; K]> = cells32
            .iter()
            .map(|c| {
                c.map(|v| {
                    let j = var_of[v as usize];
                    if j == FIXED {
                        FIXED_BIT | v
                    } else {
                        j
                    }
                })
            })
            .collect();
        // node -> incident cells
        let mut inc_offsets = vec![0usize; num_nodes + 1];
        for cell in &cells32 {
            for &v in cell {
                inc_offsets[v as usize + 1] += 1;
            }
        }
        for i in 0..num_nodes {
            inc_offsets[i + 1] += inc_offsets[i];
        }
        let mut fill = inc_offsets.clone();
        let mut inc = vec![0u32; inc_offsets[num_nodes]];
        for (c, cell) in cells32.iter().enumerate() {
            for &v in cell {
                let v = v as usize;
                // a degenerate cell may list a node twice; keep one incidence
                if fill[v] > inc_offsets[v] && inc[fill[v] - 1] == c as u32 {
                    continue;
                }
                inc[fill[v]] = c as u32;
                fill[v] += 1;
            }
        }
        // compact away duplicate slots (rare)
        let mut compact_off = vec![0usize; num_nodes + 1];
        let mut compact = Vec::with_capacity(inc.len());
        for v in 0..num_nodes {
            compact.extend_from_slice(&inc[inc_offsets[v]..fill[v]]);
            compact_off[v + 1] = compact.len();
        }
        let (inc_offsets, inc) = (compact_off, compact);
        // neighbour lists of free nodes
        let nfree = free.len();
        let mut nbr_offsets = Vec::with_capacity(nfree + 1);
        nbr_offsets.push(0);
        let mut nbr = Vec::new();
        let mut tmp: Vec<u32> = Vec::new();
        for &v in &free {
            tmp.clear();
            for &c in &inc[inc_offsets[v]..inc_offsets[v + 1]] {
                for &w in &cells32[c as usize] {
                    let vw = var_of[w as usize];
                    if vw != FIXED {
                        tmp.push(vw);
                    }
                }
            }
            tmp.sort_unstable();
            tmp.dedup();
            nbr.extend_from_slice(&tmp);
            nbr_offsets.push(nbr.len());
        }
        // chunk colouring
        let ncells = cells32.len();
        let num_chunks = ncells.div_ceil(CHUNK_CELLS);
        let mut node_chunks_off = vec![0usize; num_nodes + 1];
        let mut last = vec![u32::MAX; num_nodes];
        for (c, cell) in cells32.iter().enumerate() {
            let ch = (c / CHUNK_CELLS) as u32;
            for &v in cell {
                if last[v as usize] != ch {
                    last[v as usize] = ch;
                    node_chunks_off[v as usize + 1] += 1;
                }
            }
        }
        for i in 0..num_nodes {
            node_chunks_off[i + 1] += node_chunks_off[i];
        }
        let mut node_chunks = vec![0u32; node_chunks_off[num_nodes]];
        let mut fillc = node_chunks_off.clone();
        last.iter_mut().for_each(|l| *l = u32::MAX);
        for (c, cell) in cells32.iter().enumerate() {
            let ch = (c / CHUNK_CELLS) as u32;
            for &v in cell {
                let v = v as usize;
                if last[v] != ch {
                    last[v] = ch;
                    node_chunks[fillc[v]] = ch;
                    fillc[v] += 1;
                }
            }
        }
        let mut color_of = vec![usize::MAX; num_chunks];
        let mut colors: Vec<Vec<u32>> = Vec::new();
        let mut forbidden: Vec<usize> = Vec::new(); // forbidden[color] == chunk id marks use
        for ch in 0..num_chunks {
            let start = ch * CHUNK_CELLS;
            let end = (start + CHUNK_CELLS).min(ncells);
            for cell in &cells32[start..end] {
                for &v in cell {
                    let v = v as usize;
                    for &other in &node_chunks[node_chunks_off[v]..node_chunks_off[v + 1]] {
                        let oc = color_of[other as usize];
                        if other as usize != ch && oc != usize::MAX {
                            if forbidden.len() <= oc {
                                forbidden.resize(oc + 1, usize::MAX);
                            }
                            forbidden[oc] = ch;
                        }
                    }
                }
            }
            let mut col = 0;
            while col < forbidden.len() && forbidden[col] == ch {
                col += 1;
            }
            color_of[ch] = col;
            if colors.len() <= col {
                colors.resize(col + 1, Vec::new());
            }
            colors[col].push(ch as u32);
        }
        Ok(Self {
            num_nodes,
            var_of,
            free,
            cells: cells32,
            src,
            nbr_offsets,
            nbr,
            inc_offsets,
            inc,
            colors,
            num_chunks,
            scratch: Mutex::new(vec![0.0; num_chunks]),
        })
    }

    #[inline]
    pub(crate) fn num_cells(&self) -> usize {
        self.cells.len()
    }

    /// `true` if `h` has exactly the block pattern built by [`Csr::from_block_pattern`] from
    /// these neighbour lists (row offsets and size; checked before any unchecked write).
    pub(crate) fn matches_pattern(&self, dim: usize, h: &crate::csr::Csr) -> bool {
        let nfree = self.free.len();
        if h.nrows != dim * nfree
            || h.ncols != dim * nfree
            || h.row_offsets.len() != dim * nfree + 1
            || h.values.len() != dim * dim * self.nbr.len()
            || h.col_indices.len() != h.values.len()
        {
            return false;
        }
        (0..nfree).into_par_iter().with_min_len(4096).all(|a| {
            let deg = self.nbr_offsets[a + 1] - self.nbr_offsets[a];
            (0..=dim).all(|r| {
                h.row_offsets[dim * a + r] == dim * dim * self.nbr_offsets[a] + r * dim * deg
            })
        })
    }

    /// Position of variable node `b` in the neighbour list of variable node `a`.
    #[inline]
    pub(crate) fn nbr_pos(&self, a: u32, b: u32) -> usize {
        let list = &self.nbr[self.nbr_offsets[a as usize]..self.nbr_offsets[a as usize + 1]];
        match list.binary_search(&b) {
            Ok(k) => k,
            Err(_) => unreachable!("neighbour lists contain every pair of nodes sharing a cell"),
        }
    }

    /// Runs `per_cell` over all cells with the deterministic chunk colouring and returns the
    /// sum of its results (chunk sums added in chunk order). `per_cell` may write to output
    /// buffers through [`SyncPtr`] at entries owned by the nodes of its cell.
    pub(crate) fn run_colored<F>(&self, per_cell: F) -> f64
    where
        F: Fn(usize) -> f64 + Sync,
    {
        self.run_colored_chunks(|start, end| {
            let mut s = 0.0;
            for c in start..end {
                s += per_cell(c);
            }
            s
        })
    }

    /// Like [`run_colored`](Self::run_colored) with one call per chunk: `per_chunk(start, end)`
    /// processes cells `start..end` in order and returns their sum (accumulated from 0.0 in
    /// cell order, so the result equals the per-cell form bit for bit).
    pub(crate) fn run_colored_chunks<F>(&self, per_chunk: F) -> f64
    where
        F: Fn(usize, usize) -> f64 + Sync,
    {
        let mut guard = match self.scratch.lock() {
            Ok(g) => g,
            Err(p) => p.into_inner(),
        };
        let ncells = self.cells.len();
        let sums = SyncPtr::new(&mut guard);
        for color in &self.colors {
            color.par_iter().with_max_len(1).for_each(|&ch| {
                let ch = ch as usize;
                let start = ch * CHUNK_CELLS;
                let end = (start + CHUNK_CELLS).min(ncells);
                let s = per_chunk(start, end);
                // SAFETY: chunk `ch` is processed exactly once; index < num_chunks.
                unsafe {
                    let p = sums;
                    *p.0.add(ch) = s;
                }
            });
        }
        guard.iter().sum()
    }

    /// Value-only parallel sum with one call per chunk (see
    /// [`run_colored_chunks`](Self::run_colored_chunks)); chunk sums combined in chunk order.
    pub(crate) fn run_value_chunks<F>(&self, per_chunk: F) -> f64
    where
        F: Fn(usize, usize) -> f64 + Sync,
    {
        let mut guard = match self.scratch.lock() {
            Ok(g) => g,
            Err(p) => p.into_inner(),
        };
        let ncells = self.cells.len();
        guard
            .par_iter_mut()
            .with_max_len(1)
            .enumerate()
            .for_each(|(ch, out)| {
                let start = ch * CHUNK_CELLS;
                let end = (start + CHUNK_CELLS).min(ncells);
                *out = per_chunk(start, end);
            });
        guard.iter().sum()
    }

    /// Serial form of [`run_value_chunks`](Self::run_value_chunks) (same sums, same order): the
    /// tests' check that the parallel value does not depend on the thread count.
    #[cfg(test)]
    pub(crate) fn run_serial_chunks<F>(&self, per_chunk: F) -> f64
    where
        F: Fn(usize, usize) -> f64,
    {
        let ncells = self.cells.len();
        let mut total = 0.0;
        for ch in 0..self.num_chunks {
            let start = ch * CHUNK_CELLS;
            let end = (start + CHUNK_CELLS).min(ncells);
            total += per_chunk(start, end);
        }
        total
    }

    /// The cells in the order of the deterministic schedule of
    /// [`run_colored`](Self::run_colored) (colour by colour, chunks of a colour in list order,
    /// cells of a chunk in order). Chunks of one colour share no node, so for every node the
    /// order of its contributions is the order of this sequence whatever the thread count.
    pub(crate) fn schedule(&self) -> impl Iterator<Item = usize> + '_ {
        let ncells = self.cells.len();
        self.colors.iter().flat_map(move |color| {
            color.iter().flat_map(move |&ch| {
                let start = ch as usize * CHUNK_CELLS;
                start..(start + CHUNK_CELLS).min(ncells)
            })
        })
    }

    /// Runs `per_cell` over all cells, sequentially in cell order, summing the results.
    #[allow(dead_code)] // the serial per-cell form of `run_colored`, for evaluators without chunks
    pub(crate) fn run_serial_sum<F>(&self, per_cell: F) -> f64
    where
        F: Fn(usize) -> f64 + Sync,
    {
        // same grouping as run_colored so that values agree bit for bit
        let ncells = self.cells.len();
        let mut total = 0.0;
        for ch in 0..self.num_chunks {
            let start = ch * CHUNK_CELLS;
            let end = (start + CHUNK_CELLS).min(ncells);
            let mut s = 0.0;
            for c in start..end {
                s += per_cell(c);
            }
            total += s;
        }
        total
    }

    /// Value-only parallel sum: chunks in parallel, per-chunk sums combined in chunk order.
    pub(crate) fn run_value<F>(&self, per_cell: F) -> f64
    where
        F: Fn(usize) -> f64 + Sync,
    {
        let mut guard = match self.scratch.lock() {
            Ok(g) => g,
            Err(p) => p.into_inner(),
        };
        let ncells = self.cells.len();
        guard
            .par_iter_mut()
            .with_max_len(1)
            .enumerate()
            .for_each(|(ch, out)| {
                let start = ch * CHUNK_CELLS;
                let end = (start + CHUNK_CELLS).min(ncells);
                let mut s = 0.0;
                for c in start..end {
                    s += per_cell(c);
                }
                *out = s;
            });
        guard.iter().sum()
    }
}
