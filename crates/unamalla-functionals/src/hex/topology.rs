//! [`HexTopology`]: a hex mesh prepared for evaluation (cells, free nodes, interior cells, the
//! CSR pattern and its node-block slots).

use std::sync::OnceLock;

use glam::DVec3;
use rayon::prelude::*;
use unamalla_mesh::{FreeNodes, HasHexCells};

use super::{face_planarity_max_cos, HEX_QUAD_FACES};
use crate::assembly::{Assembly, FIXED, FIXED_BIT};
use crate::csr::Csr;
use crate::error::FunctionalError;

/// Topology of a hex mesh prepared for evaluation (see [`crate::QuadTopology`] for the 2D twin).
#[derive(Debug)]
pub struct HexTopology {
    pub(super) asm: Assembly<8>,
    pub(super) base: Vec<DVec3>,
    pub(super) interior: Vec<bool>,
    /// Per cell, the CSR position of the first entry of each 3×3 node block (see
    /// [`HexTopology::block_slots`]); built on the first Hessian assembly.
    pub(super) slots: OnceLock<Option<Vec<[u32; 64]>>>,
}

impl HexTopology {
    /// From any hex mesh implementing the traits.
    pub fn from_mesh<M: HasHexCells + FreeNodes + ?Sized>(
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
        let cells: Vec<[usize; 8]> = (0..mesh.num_hexes()).map(|c| mesh.hex(c)).collect();
        let fixed: Vec<bool> = (0..n).map(|v| mesh.is_fixed(v)).collect();
        Self::new(mesh.nodes().to_vec(), cells, fixed)
    }

    /// From raw arrays (cells in VTK order, one fixed flag per node).
    pub fn new(
        nodes: Vec<DVec3>,
        cells: Vec<[usize; 8]>,
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
        let interior = asm
            .cells
            .iter()
            .map(|c| c.iter().all(|&v| asm.var_of[v as usize] != FIXED))
            .collect();
        Ok(Self {
            asm,
            base: nodes,
            interior,
            slots: OnceLock::new(),
        })
    }

    /// Number of nodes.
    pub fn num_nodes(&self) -> usize {
        self.asm.num_nodes
    }
    /// Number of cells `N_c`.
    pub fn num_cells(&self) -> usize {
        self.asm.num_cells()
    }
    /// Number of variables (3 per free node).
    pub fn num_vars(&self) -> usize {
        3 * self.asm.free.len()
    }
    /// Free node ids, increasing.
    pub fn free_nodes(&self) -> &[usize] {
        &self.asm.free
    }
    /// Variable-node index of `node`.
    pub fn var_of(&self, node: usize) -> Option<usize> {
        match self.asm.var_of.get(node) {
            Some(&v) if v != FIXED => Some(v as usize),
            _ => None,
        }
    }
    /// Number of colours of the parallel schedule.
    pub fn num_colors(&self) -> usize {
        self.asm.colors.len()
    }
    /// Which cells carry the coplanarity penalty.
    pub fn interior_cells(&self) -> &[bool] {
        &self.interior
    }
    /// Replaces the set of penalized cells (one flag per cell).
    pub fn set_interior_cells(&mut self, flags: Vec<bool>) -> Result<(), FunctionalError> {
        if flags.len() != self.num_cells() {
            return Err(FunctionalError::LengthMismatch {
                what: "interior cell flags",
                got: flags.len(),
                expected: self.num_cells(),
            });
        }
        self.interior = flags;
        Ok(())
    }
    /// Stored coordinates (fixed-node data and initial free positions).
    pub fn coords(&self) -> &[DVec3] {
        &self.base
    }
    /// The variable vector of the stored coordinates.
    pub fn initial_x(&self) -> Vec<f64> {
        self.gather(&self.base)
    }
    /// The variable vector of mesh coordinates `nodes`.
    ///
    /// # Panics
    /// If `nodes` has fewer entries than the mesh.
    pub fn gather(&self, nodes: &[DVec3]) -> Vec<f64> {
        let mut x = vec![0.0; self.num_vars()];
        for (j, &v) in self.asm.free.iter().enumerate() {
            x[3 * j..3 * j + 3].copy_from_slice(&nodes[v].to_array());
        }
        x
    }
    /// Writes `x` into the free nodes of `nodes`.
    ///
    /// # Panics
    /// If the lengths do not match the mesh.
    pub fn scatter(&self, x: &[f64], nodes: &mut [DVec3]) {
        assert_eq!(x.len(), self.num_vars(), "scatter: x has the wrong length");
        for (j, &v) in self.asm.free.iter().enumerate() {
            nodes[v] = DVec3::new(x[3 * j], x[3 * j + 1], x[3 * j + 2]);
        }
    }
    /// All node coordinates for `x`.
    pub fn node_coords(&self, x: &[f64]) -> Vec<DVec3> {
        let mut n = self.base.clone();
        self.scatter(x, &mut n);
        n
    }
    /// The Hessian sparsity pattern (3×3 blocks).
    pub fn hessian_pattern(&self) -> Csr {
        Csr::from_block_pattern(3, &self.asm.nbr_offsets, &self.asm.nbr)
    }

    /// The CSR slot table of the node-block Hessian assembly, computed once with the pattern:
    /// entry `8a + b` of cell `c` is the position in [`Csr::values`] of the `(0, 0)` entry of the
    /// 3×3 block (local vertex `a`, local vertex `b`) of a matrix built by
    /// [`HexTopology::hessian_pattern`], or `u32::MAX` when `a` or `b` is a fixed node. Row `r`
    /// of the block starts `r·3·deg(a)` entries further (the rows of one node block-row have
    /// equal length `3·deg`). `None` if the Hessian has more than `u32::MAX` entries (then the
    /// per-entry search of the reference assembly is used).
    pub fn block_slots(&self) -> Option<&[[u32; 64]]> {
        self.slots
            .get_or_init(|| {
                let asm = &self.asm;
                if 9 * asm.nbr.len() >= u32::MAX as usize {
                    return None;
                }
                Some(
                    asm.src
                        .par_iter()
                        .with_min_len(256)
                        .map(|src| {
                            let mut s = [u32::MAX; 64];
                            for a in 0..8 {
                                let va = src[a];
                                if va & FIXED_BIT != 0 {
                                    continue;
                                }
                                for b in 0..8 {
                                    let vb = src[b];
                                    if vb & FIXED_BIT != 0 {
                                        continue;
                                    }
                                    let k = asm.nbr_pos(va, vb);
                                    // < 9·nbr.len() < u32::MAX, checked above
                                    s[8 * a + b] =
                                        (9 * asm.nbr_offsets[va as usize] + 3 * k) as u32;
                                }
                            }
                            s
                        })
                        .collect(),
                )
            })
            .as_deref()
    }

    /// `3·deg` of variable node `v`: the length of each of its three Hessian rows.
    #[inline(always)]
    pub(super) fn row_len(&self, v: u32) -> usize {
        3 * (self.asm.nbr_offsets[v as usize + 1] - self.asm.nbr_offsets[v as usize])
    }

    /// Points of cell `c` and the variable-node index of each vertex ([`FIXED`] if fixed).
    #[inline(always)]
    pub(super) fn cell_points(&self, x: &[f64], c: usize) -> ([DVec3; 8], [u32; 8]) {
        let src = self.asm.src[c];
        let mut p = [DVec3::ZERO; 8];
        let mut vars = [FIXED; 8];
        for i in 0..8 {
            let s = src[i];
            if s & FIXED_BIT == 0 {
                let j = 3 * s as usize;
                p[i] = DVec3::new(x[j], x[j + 1], x[j + 2]);
                vars[i] = s;
            } else {
                p[i] = self.base[(s & !FIXED_BIT) as usize];
            }
        }
        (p, vars)
    }

    /// Max over the six faces of the interior cells of [`face_planarity_max_cos`] at `x`, and the
    /// number of interior cells with some face above `tol` (non-hexahedral cells, as counted in
    /// [Cortés Aguirre 2012, Table 3.3, Table 4.3]).
    pub fn planarity_report(&self, x: &[f64], tol: f64) -> (f64, usize) {
        let mut worst = 0.0f64;
        let mut bad = 0;
        for c in 0..self.num_cells() {
            if !self.interior[c] {
                continue;
            }
            let (p, _) = self.cell_points(x, c);
            let mut cell_bad = false;
            for f in HEX_QUAD_FACES {
                let k = face_planarity_max_cos(f.map(|i| p[i]));
                worst = worst.max(k);
                cell_bad |= k > tol;
            }
            bad += cell_bad as usize;
        }
        (worst, bad)
    }
}
