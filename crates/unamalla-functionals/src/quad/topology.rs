//! [`QuadTopology`]: a quad mesh prepared for evaluation (cells, free-variable map, Hessian
//! pattern, parallel schedule, fixed coordinates), and the [`AlphaSummary`] of its corner triangles.

use std::sync::OnceLock;

use glam::DVec2;
use rayon::prelude::*;
use unamalla_mesh::{FreeNodes, HasQuadCells};

use super::lanes;
use crate::assembly::{Assembly, SyncPtr, FIXED, FIXED_BIT};
use crate::csr::Csr;
use crate::error::FunctionalError;

/// Summary of the corner-triangle measures of a quad mesh
/// ([González Flores, §4.1, (3.53), (4.31)]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlphaSummary {
    /// `α₋ = min α`.
    pub min: f64,
    /// `max α`.
    pub max: f64,
    /// `ᾱ = Σα / N` at this `x` (constant for a fixed boundary: `4·area(Ω)/N`).
    pub mean: f64,
    /// Number of corner triangles with `α ≤ 0`.
    pub nonpositive_triangles: usize,
    /// Number of cells with some `α ≤ 0` (non-convex or degenerate cells).
    pub nonconvex_cells: usize,
}

/// Topology of a quad mesh prepared for evaluation: cells, free-variable map, Hessian pattern,
/// deterministic parallel schedule and the coordinates of the fixed nodes.
#[derive(Debug)]
pub struct QuadTopology {
    pub(super) asm: Assembly<4>,
    pub(super) base: Vec<DVec2>,
    pub(super) alpha_bar: f64,
    /// Per cell, bit `i`: the contribution of vertex `i` is the first to reach its gradient
    /// entries in the schedule order (store, don't add; see [`lanes`]).
    pub(super) gfirst: Vec<u8>,
    /// Free variable nodes in no cell (their gradient entries are zeroed explicitly).
    isolated: Vec<u32>,
    /// Per cell, entry `4i + j`: position of vertex `j` in the neighbour list of vertex `i`
    /// (the CSR slot of block `(i, j)`), with [`lanes::SLOT_FIRST`] on the first contribution;
    /// built on the first Hessian refresh. `None` if a neighbour list is too long for `u16`
    /// (the reference assembly is used then).
    pub(super) slots: OnceLock<Option<Vec<[u16; 16]>>>,
}

impl QuadTopology {
    /// From any mesh implementing the traits (structured grid, merged block mesh, file mesh).
    /// Node coordinates are copied: the fixed ones are the data of the problem, the free ones
    /// give [`initial_x`](Self::initial_x).
    pub fn from_mesh<M: HasQuadCells + FreeNodes + ?Sized>(
        mesh: &M,
    ) -> Result<Self, FunctionalError> {
        let n = mesh.num_nodes();
        if mesh.num_flagged_nodes() != n {
            return Err(FunctionalError::LengthMismatch {
                what: "fixed flags",
                got: mesh.num_flagged_nodes(),
                expected: n,
            });
        }
        let cells: Vec<[usize; 4]> = (0..mesh.num_quads()).map(|c| mesh.quad(c)).collect();
        let fixed: Vec<bool> = (0..n).map(|v| mesh.is_fixed(v)).collect();
        Self::new(mesh.nodes().to_vec(), cells, fixed)
    }

    /// From raw arrays: node coordinates, counter-clockwise cells and one fixed flag per node.
    pub fn new(
        nodes: Vec<DVec2>,
        cells: Vec<[usize; 4]>,
        fixed: Vec<bool>,
    ) -> Result<Self, FunctionalError> {
        if fixed.len() != nodes.len() {
            return Err(FunctionalError::LengthMismatch {
                what: "fixed flags",
                got: fixed.len(),
                expected: nodes.len(),
            });
        }
        if let Some(v) = nodes.iter().position(|p| !p.is_finite()) {
            return Err(FunctionalError::NonFinite { node: v });
        }
        let asm = Assembly::new(nodes.len(), cells, |v| fixed[v])?;
        // first-contribution flags of the gradient, in schedule order
        let mut seen = vec![false; asm.free.len()];
        let mut gfirst = vec![0u8; asm.num_cells()];
        for c in asm.schedule() {
            for (i, &sv) in asm.src[c].iter().enumerate() {
                if sv & FIXED_BIT == 0 && !seen[sv as usize] {
                    seen[sv as usize] = true;
                    gfirst[c] |= 1 << i;
                }
            }
        }
        let isolated = (0..asm.free.len() as u32)
            .filter(|&j| !seen[j as usize])
            .collect();
        let mut t = Self {
            asm,
            base: nodes,
            alpha_bar: 0.0,
            gfirst,
            isolated,
            slots: OnceLock::new(),
        };
        let x = t.initial_x();
        t.alpha_bar = t.alpha_summary(&x).mean;
        Ok(t)
    }

    /// Number of mesh nodes.
    pub fn num_nodes(&self) -> usize {
        self.asm.num_nodes
    }
    /// Number of cells.
    pub fn num_cells(&self) -> usize {
        self.asm.num_cells()
    }
    /// Number of corner triangles `N = 4 · cells`.
    pub fn num_triangles(&self) -> usize {
        4 * self.asm.num_cells()
    }
    /// Number of variables (2 per free node).
    pub fn num_vars(&self) -> usize {
        2 * self.asm.free.len()
    }
    /// Mesh node ids of the free nodes, increasing.
    pub fn free_nodes(&self) -> &[usize] {
        &self.asm.free
    }
    /// Variable-node index of `node` (`x[2j]`, `x[2j+1]` are its coordinates).
    pub fn var_of(&self, node: usize) -> Option<usize> {
        match self.asm.var_of.get(node) {
            Some(&v) if v != FIXED => Some(v as usize),
            _ => None,
        }
    }
    /// Node ids of cell `c`.
    pub fn cell(&self, c: usize) -> [usize; 4] {
        self.asm.cells[c].map(|v| v as usize)
    }
    /// Number of colours of the parallel schedule (1 = fully parallel chunks).
    pub fn num_colors(&self) -> usize {
        self.asm.colors.len()
    }
    /// `ᾱ = Σα/N` of the mesh given at construction (`= 4·area(Ω)/N` for a mesh with fixed
    /// boundary; independent of the interior nodes, [González Flores, (3.53), (4.31)]).
    pub fn alpha_bar(&self) -> f64 {
        self.alpha_bar
    }
    /// The coordinates of all nodes stored in the topology (fixed nodes are the data; free
    /// nodes hold the values given at construction or by [`set_coords`](Self::set_coords)).
    pub fn coords(&self) -> &[DVec2] {
        &self.base
    }
    /// Replaces the stored coordinates (fixed-node data and initial free positions).
    pub fn set_coords(&mut self, nodes: &[DVec2]) -> Result<(), FunctionalError> {
        if nodes.len() != self.base.len() {
            return Err(FunctionalError::LengthMismatch {
                what: "node coordinates",
                got: nodes.len(),
                expected: self.base.len(),
            });
        }
        self.base.copy_from_slice(nodes);
        Ok(())
    }
    /// The variable vector of the stored coordinates.
    pub fn initial_x(&self) -> Vec<f64> {
        let mut x = vec![0.0; self.num_vars()];
        self.gather_into(&self.base, &mut x);
        x
    }
    /// The variable vector of mesh coordinates `nodes` (one per mesh node).
    pub fn gather(&self, nodes: &[DVec2]) -> Vec<f64> {
        let mut x = vec![0.0; self.num_vars()];
        self.gather_into(nodes, &mut x);
        x
    }
    /// Writes the free-node coordinates of `nodes` into `x`.
    ///
    /// # Panics
    /// If `nodes` has fewer entries than the mesh or `x.len() != num_vars()`.
    pub fn gather_into(&self, nodes: &[DVec2], x: &mut [f64]) {
        assert_eq!(x.len(), self.num_vars(), "gather: x has the wrong length");
        for (j, &v) in self.asm.free.iter().enumerate() {
            x[2 * j] = nodes[v].x;
            x[2 * j + 1] = nodes[v].y;
        }
    }
    /// Writes `x` into the free nodes of `nodes` (fixed nodes untouched).
    ///
    /// # Panics
    /// If `nodes` has fewer entries than the mesh or `x.len() != num_vars()`.
    pub fn scatter(&self, x: &[f64], nodes: &mut [DVec2]) {
        assert_eq!(x.len(), self.num_vars(), "scatter: x has the wrong length");
        for (j, &v) in self.asm.free.iter().enumerate() {
            nodes[v] = DVec2::new(x[2 * j], x[2 * j + 1]);
        }
    }
    /// All node coordinates for `x` (fixed nodes from the stored data).
    pub fn node_coords(&self, x: &[f64]) -> Vec<DVec2> {
        let mut n = self.base.clone();
        self.scatter(x, &mut n);
        n
    }

    /// Points of cell `c` and the variable-node index of each vertex ([`FIXED`] if fixed).
    #[inline(always)]
    pub(super) fn cell_points(&self, x: &[f64], c: usize) -> ([DVec2; 4], [u32; 4]) {
        let src = self.asm.src[c];
        let mut p = [DVec2::ZERO; 4];
        let mut vars = [FIXED; 4];
        for i in 0..4 {
            let s = src[i];
            if s & FIXED_BIT == 0 {
                let j = 2 * s as usize;
                p[i] = DVec2::new(x[j], x[j + 1]);
                vars[i] = s;
            } else {
                p[i] = self.base[(s & !FIXED_BIT) as usize];
            }
        }
        (p, vars)
    }

    /// α of every corner triangle at `x` (`out[4c + k]`, corner `k` of cell `c`).
    ///
    /// # Panics
    /// If `out.len() != num_triangles()` or `x.len() != num_vars()`.
    pub fn alphas(&self, x: &[f64], out: &mut [f64]) {
        assert_eq!(
            out.len(),
            self.num_triangles(),
            "alphas: out has the wrong length"
        );
        assert_eq!(x.len(), self.num_vars(), "alphas: x has the wrong length");
        out.par_chunks_mut(4).enumerate().for_each(|(c, o)| {
            let (p, _) = self.cell_points(x, c);
            for k in 0..4 {
                o[k] = (p[(k + 1) & 3] - p[k]).perp_dot(p[(k + 3) & 3] - p[k]);
            }
        });
    }

    /// `α₋`, `ᾱ` and non-convex counts at `x`.
    pub fn alpha_summary(&self, x: &[f64]) -> AlphaSummary {
        let mut a = vec![0.0; self.num_triangles()];
        self.alphas(x, &mut a);
        let mut s = AlphaSummary {
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            mean: 0.0,
            nonpositive_triangles: 0,
            nonconvex_cells: 0,
        };
        let mut sum = 0.0;
        for cell in a.chunks(4) {
            let mut bad = false;
            for &v in cell {
                s.min = s.min.min(v);
                s.max = s.max.max(v);
                sum += v;
                if v <= 0.0 {
                    s.nonpositive_triangles += 1;
                    bad = true;
                }
            }
            s.nonconvex_cells += bad as usize;
        }
        s.mean = sum / a.len() as f64;
        s
    }

    /// Per-cell density weights for [Méndez 2023, (6.9)]: `density` on the cells within `layers`
    /// cell layers of the mesh boundary (layer 1 = cells touching a boundary node, where boundary
    /// nodes are those on edges used by one cell), 1 elsewhere. The thesis uses an integer density
    /// below 10 and does not give the band width.
    pub fn boundary_density(&self, density: f64, layers: usize) -> Vec<f64> {
        let n = self.asm.num_nodes;
        let mut edges: std::collections::HashMap<(u32, u32), u32> =
            std::collections::HashMap::new();
        for cell in &self.asm.cells {
            for k in 0..4 {
                let (a, b) = (cell[k], cell[(k + 1) & 3]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        let mut near = vec![false; n];
        for ((a, b), cnt) in edges {
            if cnt == 1 {
                near[a as usize] = true;
                near[b as usize] = true;
            }
        }
        let mut w = vec![1.0; self.num_cells()];
        for _ in 0..layers {
            let mut hit = Vec::new();
            for (c, cell) in self.asm.cells.iter().enumerate() {
                if cell.iter().any(|&v| near[v as usize]) {
                    w[c] = density;
                    hit.push(c);
                }
            }
            for c in hit {
                for &v in &self.asm.cells[c] {
                    near[v as usize] = true;
                }
            }
        }
        w
    }

    /// The Hessian sparsity pattern (2×2 blocks for every pair of free nodes sharing a cell).
    pub fn hessian_pattern(&self) -> Csr {
        Csr::from_block_pattern(2, &self.asm.nbr_offsets, &self.asm.nbr)
    }

    /// The per-cell Hessian slot table (built once, in schedule order for the first flags).
    pub(super) fn hessian_slots(&self) -> Option<&[[u16; 16]]> {
        self.slots
            .get_or_init(|| {
                let asm = &self.asm;
                let mut seen = vec![false; asm.nbr.len()];
                let mut slots = vec![[0u16; 16]; asm.num_cells()];
                for c in asm.schedule() {
                    let src = asm.src[c];
                    for i in 0..4 {
                        if src[i] & FIXED_BIT != 0 {
                            continue;
                        }
                        for j in 0..4 {
                            if src[j] & FIXED_BIT != 0 {
                                continue;
                            }
                            let k = asm.nbr_pos(src[i], src[j]);
                            if k > lanes::SLOT_MAX {
                                return None;
                            }
                            let b = asm.nbr_offsets[src[i] as usize] + k;
                            let mut e = k as u16;
                            if !seen[b] {
                                seen[b] = true;
                                e |= lanes::SLOT_FIRST;
                            }
                            slots[c][4 * i + j] = e;
                        }
                    }
                }
                Some(slots)
            })
            .as_deref()
    }

    /// Zeroes `h` (a matrix of this topology's Hessian pattern) and adds into it the 8 × 8 cell
    /// Hessians `cell(c, points) = (H_c, w_c)` of every cell (parallel over the colouring);
    /// returns `Σ w_c` (a per-cell count the caller wants, e.g. projected triangles). With
    /// `use_slots` the positions come from the slot tables when they exist; otherwise (and for
    /// the reference path, which must not share the fast path's tables) from the neighbour
    /// lists.
    pub(super) fn assemble_cell_hessians<F>(
        &self,
        x: &[f64],
        h: &mut Csr,
        use_slots: bool,
        cell: F,
    ) -> f64
    where
        F: Fn(usize, &[DVec2; 4]) -> ([[f64; 8]; 8], f64) + Sync,
    {
        let Csr {
            row_offsets,
            values,
            ..
        } = h;
        crate::csr::par_zero(values);
        let hp = SyncPtr::new(values);
        let ro: &[usize] = row_offsets;
        let slots = if use_slots {
            self.hessian_slots()
        } else {
            None
        };
        let asm = &self.asm;
        asm.run_colored(|c| {
            let (p, vars) = self.cell_points(x, c);
            let (lh, w) = cell(c, &p);
            for i in 0..4 {
                let vi = vars[i];
                if vi == FIXED {
                    continue;
                }
                for jn in 0..4 {
                    let vj = vars[jn];
                    if vj == FIXED {
                        continue;
                    }
                    let k = match slots {
                        Some(sl) => (sl[c][4 * i + jn] & !lanes::SLOT_FIRST) as usize,
                        None => asm.nbr_pos(vi, vj),
                    };
                    for dx in 0..2 {
                        let base = ro[2 * vi as usize + dx] + 2 * k;
                        // SAFETY: row of a node of this cell (colouring, see `assembly`); `k` is
                        // the position of `vj` in the neighbour list of `vi`, so both entries lie
                        // in that row of the pattern (the callers checked the pattern).
                        unsafe {
                            hp.add(base, lh[2 * i + dx][2 * jn]);
                            hp.add(base + 1, lh[2 * i + dx][2 * jn + 1]);
                        }
                    }
                }
            }
            w
        })
    }

    /// Zeroes the entries of free nodes that belong to no cell (the fast paths never write them).
    pub(super) fn zero_isolated(&self, g: &mut [f64]) {
        for &j in &self.isolated {
            g[2 * j as usize] = 0.0;
            g[2 * j as usize + 1] = 0.0;
        }
    }
}
