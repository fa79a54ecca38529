//! 3D functionals on hex meshes ([Cortés Aguirre 2012, Ch. 3–4]; the references are listed in
//! `docs/references.md` of the repository): the quasi-harmonic `H_ω` over 10 tetrahedra per
//! hexahedron and the face-coplanarity penalty `C·Σk²`.
//!
//! # Tetrahedra ([Cortés Aguirre 2012, §3.2], the list completed here)
//! Vertices are numbered 1..8 as in the thesis (VTK order, 0-based in code). Decomposition A:
//! corner tets 1245, 3427, 6572, 8547 and interior tet 7425; decomposition B: 2316, 4138, 5861,
//! 7683 and interior tet 1386. A corner tet `PQRS` has Jacobian columns `Q−P, R−P, S−P`; the
//! interior tets use the volume-averaged stencils
//! `r_ξ = ½(r₇+r₂−r₅−r₄)`, `r_η = ½(r₇+r₄−r₅−r₂)`, `r_ζ = ½(r₇+r₅−r₂−r₄)` (7425) and
//! `r_ξ = ½(r₃+r₆−r₁−r₈)`, `r_η = ½(r₃+r₈−r₁−r₆)`, `r_ζ = ½(r₆+r₈−r₁−r₃)` (1386). The thesis
//! names the tets 1245, 6572, 8547, 5861 and the interior tet 7425 and gives the stencil of 7425;
//! the rest of the list and the stencil of 1386 are ours (exact for affine maps).
//! All ten have `V = det[r_ξ, r_η, r_ζ] > 0` on the unit cube (tested). For interior tets
//! `V = 3·vol` (not the 6·vol the thesis states for every tet).
//!
//! # Scaling switch (our reading)
//! The printed formulas use raw (index-space) differences; the thesis' reported values fit only
//! unit-parametric Jacobians `r_ξ ≈ (m−1)(r₂−r₁)` (with raw differences its Pico example, which
//! ends at `f = 2.79`, would give about 0.05). [`Scaling3::Index`] uses raw differences,
//! [`Scaling3::Parametric`] multiplies each column by the number of cells along its logical
//! direction.
//!
//! # Energy
//! Per tet `λ = (‖r_ξ‖² + ‖r_η‖² + ‖r_ζ‖²)^{3/2}/3^{3/2}` (control metric `G = I`) and the term
//! `λ·φ_ω(V)` with the C¹ [`phi_omega`]; `H_ω = 1/(10N_c) ΣΣ λφ_ω(V)` (3.27). Where `V ≥ ω`
//! the term is the energy density `E = λ/V ≥ 1` (AM–GM), with equality iff the Jacobian is a
//! similarity. Derivatives (in vector form, ours): `∂λ/∂c = r c` with `r = (s/3)^{1/2}`,
//! `s = Σ‖c‖²`, `∂²λ = rI + ccᵀ/(3r)`; `∂V/∂c₁ = c₂×c₃` (cyclic), `∂²V/∂c_a∂c_b = ε_{abc}M(c_c)`
//! with `M(w)_{ij} = ε_{ijk}w_k`; chained to the vertices through the stencils.
//!
//! # Node-block Hessian
//! With the stencil column `w_j = (w_0j, w_1j, w_2j)` of vertex `j`, `α_j = Σ_a w_aj c_a`,
//! `β_j = Σ_a w_aj ∂V/∂c_a` and `G_jl = w_j·w_l`, the chain rule
//! `H_jl = Σ_ab w_aj w_bl ∂²f/∂c_a∂c_b` collapses (using `Σ_ab w_aj w_bl ε_abc = (w_j × w_l)_c`) to
//! `H_jl = wt·[φ(r G_jl I + α_j α_lᵀ/(3r)) + φ'r(α_j β_lᵀ + β_j α_lᵀ) + λφ''β_j β_lᵀ +
//! λφ'M(Σ_c (w_j × w_l)_c c_c)]`: ten closed-form 3×3 blocks per tetrahedron (the other six
//! by symmetry) instead of spreading the 9 column blocks over up to 16 vertex pairs. The
//! blocks of a cell are summed as 8×8 node blocks and added at CSR positions computed once
//! with the pattern ([`HexTopology::block_slots`]). The face terms use the same form (legs
//! `B−A, D−A, C−A`). The previous per-tetrahedron assembly is kept (private) as the
//! fallback for meshes too large for the slot table and as the tests' reference.
//!
//! # Coplanarity ([Cortés Aguirre 2012, §4.1] criterion 2, (4.2)–(4.4))
//! For a face `ABCD`: `N = AB × AD`, `k = N·AC/(‖N‖‖AC‖)` (a signed cosine; `k² = |cos|²`). The
//! penalty is `C·Σ_cells Σ_faces k²` over the six faces (1234), (5678), (1265), (4378), (1485),
//! (2376) of the **interior cells** (default: cells with all eight nodes free; shared faces are
//! counted twice, as in the thesis). `A` is the first listed vertex of each face; the thesis'
//! "six combinations of the four vertices" is ambiguous, so the smooth single-cosine form is
//! used in the penalty, and [`face_planarity_max_cos`] (max `|cos|` over the four leave-one-out
//! choices of `A`, our reading) is offered as the reporting measure. Derivatives of
//! `k² = t²/(n₂w₂)` with `t = det[AB, AD, AC]`, `n₂ = ‖AB × AD‖²`, `w₂ = ‖AC‖²` are exact
//! (polynomial parts differentiated by hand). A face with `n₂w₂ = 0` contributes 0.

use std::sync::{Arc, OnceLock};

use glam::DVec3;
use rayon::prelude::*;
use unamalla_mesh::{FreeNodes, HasHexCells};

use crate::assembly::{Assembly, SyncPtr, FIXED, FIXED_BIT};
use crate::csr::Csr;
use crate::error::FunctionalError;
use crate::kernel::phi_omega;
#[cfg(doc)]
use crate::problem::Problem;
use crate::problem::{
    Cost, ElementMeasures, Gradient, Hessian, LocalModel, PointwiseModel, Variables,
};

/// The six faces of a hexahedron (0-based VTK indices), in 1-based vertex numbers
/// (1234), (5678), (1265), (4378), (1485), (2376) — the same table the quality module's
/// planarity test uses ([`unamalla_mesh::quality::hex::PLANARITY_FACES`]).
pub const HEX_QUAD_FACES: [[usize; 4]; 6] = unamalla_mesh::quality::hex::PLANARITY_FACES;

/// One tetrahedron of the hex split: Jacobian column `a` is `Σⱼ stencil[a][j]·X[nodes[j]]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tet {
    /// The four hex-local vertices (0-based VTK).
    pub nodes: [usize; 4],
    /// Coefficients of the three columns.
    pub stencil: [[f64; 4]; 3],
    /// Logical direction (0 = ξ, 1 = η, 2 = ζ) of each column.
    pub dirs: [usize; 3],
    /// `true` for the two interior tets.
    pub interior: bool,
}

fn unit_cube(v: usize) -> DVec3 {
    const C: [[f64; 3]; 8] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    DVec3::from_array(C[v])
}

/// The 10 tetrahedra (decomposition A then B, interior tet last in each).
pub fn hex_tets() -> [Tet; 10] {
    const CORNER: [[f64; 4]; 3] = [
        [-1.0, 1.0, 0.0, 0.0],
        [-1.0, 0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0, 1.0],
    ];
    let corner = |d: [usize; 4]| Tet {
        nodes: d.map(|v| v - 1),
        stencil: CORNER,
        dirs: [0; 3],
        interior: false,
    };
    let h = 0.5;
    let mut t = [
        corner([1, 2, 4, 5]),
        corner([3, 4, 2, 7]),
        corner([6, 5, 7, 2]),
        corner([8, 5, 4, 7]),
        Tet {
            nodes: [6, 3, 1, 4], // 7, 4, 2, 5
            stencil: [[h, -h, h, -h], [h, h, -h, -h], [h, -h, -h, h]],
            dirs: [0; 3],
            interior: true,
        },
        corner([2, 3, 1, 6]),
        corner([4, 1, 3, 8]),
        corner([5, 8, 6, 1]),
        corner([7, 6, 8, 3]),
        Tet {
            nodes: [0, 2, 7, 5], // 1, 3, 8, 6
            stencil: [[-h, h, -h, h], [-h, h, h, -h], [-h, -h, h, h]],
            dirs: [0; 3],
            interior: true,
        },
    ];
    for tet in t.iter_mut() {
        for a in 0..3 {
            let mut c = DVec3::ZERO;
            for j in 0..4 {
                c += tet.stencil[a][j] * unit_cube(tet.nodes[j]);
            }
            let ac = c.abs();
            tet.dirs[a] = if ac.x >= ac.y && ac.x >= ac.z {
                0
            } else if ac.y >= ac.z {
                1
            } else {
                2
            };
        }
    }
    t
}

/// The Jacobian scaling of the tetrahedra (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scaling3 {
    /// Raw differences of vertex coordinates (index space), as printed in the thesis.
    Index,
    /// Unit-parametric: columns along ξ, η, ζ multiplied by `m−1`, `n−1`, `p−1`
    /// (the node counts of a structured `m × n × p` grid).
    Parametric {
        /// Nodes along ξ.
        m: usize,
        /// Nodes along η.
        n: usize,
        /// Nodes along ζ.
        p: usize,
    },
    /// Arbitrary positive factors for the ξ, η, ζ columns.
    Custom([f64; 3]),
}

impl Scaling3 {
    fn factors(self) -> Result<[f64; 3], FunctionalError> {
        let f = match self {
            Scaling3::Index => [1.0; 3],
            Scaling3::Parametric { m, n, p } => {
                if m < 2 || n < 2 || p < 2 {
                    return Err(FunctionalError::UnsupportedSize(format!(
                        "parametric scaling needs at least 2 nodes per direction, got {m} × {n} × {p}"
                    )));
                }
                [(m - 1) as f64, (n - 1) as f64, (p - 1) as f64]
            }
            Scaling3::Custom(f) => f,
        };
        for v in f {
            if !(v.is_finite() && v > 0.0) {
                return Err(FunctionalError::InvalidParameter {
                    name: "scaling",
                    value: v,
                    reason: "scaling factors must be finite and > 0".into(),
                });
            }
        }
        Ok(f)
    }
}

/// Signed cosine `k = (AB × AD)·AC/(‖AB × AD‖‖AC‖)` of the face `p = [A, B, C, D]`
/// ([Cortés Aguirre 2012, (4.2)]); 0 for a degenerate face.
pub fn face_coplanarity_cos(p: [DVec3; 4]) -> f64 {
    let (u, v, w) = (p[1] - p[0], p[3] - p[0], p[2] - p[0]);
    let n = u.cross(v);
    let d = n.length() * w.length();
    if d > 0.0 {
        n.dot(w) / d
    } else {
        0.0
    }
}

/// Max `|cos|` of [`face_coplanarity_cos`] over the four cyclic relabellings of the face
/// (our leave-one-out reading of the "six combinations of the four vertices" that
/// [Cortés Aguirre 2012, §4.1] checks).
pub fn face_planarity_max_cos(p: [DVec3; 4]) -> f64 {
    (0..4)
        .map(|r| face_coplanarity_cos([p[r], p[(r + 1) & 3], p[(r + 2) & 3], p[(r + 3) & 3]]).abs())
        .fold(0.0, f64::max)
}

/// Topology of a hex mesh prepared for evaluation (see [`crate::QuadTopology`] for the 2D twin).
#[derive(Debug)]
pub struct HexTopology {
    asm: Assembly<8>,
    base: Vec<DVec3>,
    interior: Vec<bool>,
    /// Per cell, the CSR position of the first entry of each 3×3 node block (see
    /// [`HexTopology::block_slots`]); built on the first Hessian assembly.
    slots: OnceLock<Option<Vec<[u32; 64]>>>,
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
    fn row_len(&self, v: u32) -> usize {
        3 * (self.asm.nbr_offsets[v as usize + 1] - self.asm.nbr_offsets[v as usize])
    }

    /// Points of cell `c` and the variable-node index of each vertex ([`FIXED`] if fixed).
    #[inline(always)]
    fn cell_points(&self, x: &[f64], c: usize) -> ([DVec3; 8], [u32; 8]) {
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

/// A tet with its stencil already multiplied by the scaling factors, and the two stencil
/// invariants of its node-block Hessian (see [`tet_term_blocks`]).
#[derive(Debug, Clone, Copy)]
struct ScaledTet {
    nodes: [usize; 4],
    w: [[f64; 4]; 3],
    /// `gram[j][l] = Σ_a w_aj w_al`.
    gram: [[f64; 4]; 4],
    /// `wx[j][l] = w_j × w_l` with `w_j = (w_0j, w_1j, w_2j)`.
    wx: [[DVec3; 4]; 4],
}

impl ScaledTet {
    fn new(nodes: [usize; 4], w: [[f64; 4]; 3]) -> Self {
        let col = |j: usize| DVec3::new(w[0][j], w[1][j], w[2][j]);
        Self {
            nodes,
            w,
            gram: std::array::from_fn(|j| std::array::from_fn(|l| col(j).dot(col(l)))),
            wx: std::array::from_fn(|j| std::array::from_fn(|l| col(j).cross(col(l)))),
        }
    }
}

/// The Hessian of one cell as 8×8 node blocks (`[a][b]` = the 3×3 block of local vertices `a`,
/// `b`, row-major), the form the CSR slots of [`HexTopology::block_slots`] are written from.
type CellBlocks = [[[f64; 9]; 8]; 8];

/// Adds the 3×3 block `blk` at `(a, b)` and its transpose at `(b, a)` (once if `a == b`; the
/// diagonal blocks built here are symmetric).
#[inline(always)]
fn add_block_sym(hb: &mut CellBlocks, a: usize, b: usize, blk: &[f64; 9]) {
    if a == b {
        for (o, v) in hb[a][a].iter_mut().zip(blk) {
            *o += v;
        }
    } else {
        for x in 0..3 {
            for y in 0..3 {
                hb[a][b][3 * x + y] += blk[3 * x + y];
                hb[b][a][3 * y + x] += blk[3 * x + y];
            }
        }
    }
}

/// `M(w)_{ij} = ε_{ijk} w_k`.
#[inline(always)]
fn eps_mat(w: DVec3) -> [[f64; 3]; 3] {
    [[0.0, w.z, -w.y], [-w.z, 0.0, w.x], [w.y, -w.x, 0.0]]
}

/// Hessian blocks of `det[c₀, c₁, c₂]`: `[a][b] = ε_{abc} M(c_c)`.
#[inline(always)]
fn det_hess(c: &[DVec3; 3]) -> [[[[f64; 3]; 3]; 3]; 3] {
    let mut h = [[[[0.0; 3]; 3]; 3]; 3];
    let m0 = eps_mat(c[0]);
    let m1 = eps_mat(c[1]);
    let m2 = eps_mat(c[2]);
    for i in 0..3 {
        for j in 0..3 {
            h[0][1][i][j] = m2[i][j];
            h[1][0][i][j] = -m2[i][j];
            h[1][2][i][j] = m0[i][j];
            h[2][1][i][j] = -m0[i][j];
            h[2][0][i][j] = m1[i][j];
            h[0][2][i][j] = -m1[i][j];
        }
    }
    h
}

/// Adds `sa·sb·H[a][b]` for three "legs" to the cell Hessian; `legs[a]` lists the `(node,
/// coefficient)` pairs of leg `a`.
#[inline(always)]
fn scatter_hess3(
    legs: &[[(usize, f64); 4]; 3],
    hc: &[[[[f64; 3]; 3]; 3]; 3],
    h: &mut [[f64; 24]; 24],
) {
    for a in 0..3 {
        for &(na, wa) in &legs[a] {
            if wa == 0.0 {
                continue;
            }
            for b in 0..3 {
                for &(nb, wb) in &legs[b] {
                    if wb == 0.0 {
                        continue;
                    }
                    let s = wa * wb;
                    for i in 0..3 {
                        for j in 0..3 {
                            h[3 * na + i][3 * nb + j] += s * hc[a][b][i][j];
                        }
                    }
                }
            }
        }
    }
}

/// One tet term `wt·λ·φ_ω(V)`; adds gradient (and Hessian) to the cell arrays.
#[inline(always)]
fn tet_term(
    t: &ScaledTet,
    p: &[DVec3; 8],
    omega: f64,
    wt: f64,
    g: &mut [DVec3; 8],
    h: Option<&mut [[f64; 24]; 24]>,
) -> f64 {
    let mut c = [DVec3::ZERO; 3];
    for (a, ca) in c.iter_mut().enumerate() {
        for j in 0..4 {
            *ca += t.w[a][j] * p[t.nodes[j]];
        }
    }
    let s = c[0].length_squared() + c[1].length_squared() + c[2].length_squared();
    let r = (s / 3.0).sqrt();
    let lam = r * r * r;
    let dv = [c[1].cross(c[2]), c[2].cross(c[0]), c[0].cross(c[1])];
    let v = c[0].dot(dv[0]);
    let phi = phi_omega(omega, v);
    let val = wt * lam * phi[0];
    let mut gc = [DVec3::ZERO; 3];
    for a in 0..3 {
        gc[a] = wt * (phi[0] * r * c[a] + lam * phi[1] * dv[a]);
        for j in 0..4 {
            g[t.nodes[j]] += t.w[a][j] * gc[a];
        }
    }
    if let Some(h) = h {
        let vh = det_hess(&c);
        let inv3r = if r > 0.0 { 1.0 / (3.0 * r) } else { 0.0 };
        let mut hc = [[[[0.0; 3]; 3]; 3]; 3];
        for a in 0..3 {
            let la = (r * c[a]).to_array();
            let va = dv[a].to_array();
            let ca = c[a].to_array();
            for b in 0..3 {
                let lb = (r * c[b]).to_array();
                let vb = dv[b].to_array();
                let cb = c[b].to_array();
                for i in 0..3 {
                    for j in 0..3 {
                        let mut lh = ca[i] * cb[j] * inv3r;
                        if a == b && i == j {
                            lh += r;
                        }
                        hc[a][b][i][j] = wt
                            * (phi[0] * lh
                                + phi[1] * (la[i] * vb[j] + va[i] * lb[j])
                                + lam * phi[2] * va[i] * vb[j]
                                + lam * phi[1] * vh[a][b][i][j]);
                    }
                }
            }
        }
        let legs: [[(usize, f64); 4]; 3] =
            std::array::from_fn(|a| std::array::from_fn(|j| (t.nodes[j], t.w[a][j])));
        scatter_hess3(&legs, &hc, h);
    }
    val
}

/// One tet term `wt·λ·φ_ω(V)` in node-block form; adds the gradient to `g` and, if asked,
/// the Hessian w.r.t. the tet's four vertices to the cell blocks `hb`.
///
/// With the columns `c_a = Σ_j w_aj X_j`, `α_j = Σ_a w_aj c_a`, `β_j = Σ_a w_aj ∂V/∂c_a`,
/// `G_jl = Σ_a w_aj w_al` and `w_j = (w_0j, w_1j, w_2j)`, the chain rule
/// `H_jl = Σ_ab w_aj w_bl ∂²f/∂c_a∂c_b` applied to the column Hessian of [`tet_term`]
/// (`∂²λ = rI + c_a c_bᵀ/(3r)`, `∂²V/∂c_a∂c_b = ε_abc M(c_c)`) gives, in closed form,
///
/// `H_jl = wt·[φ·(r G_jl I + α_j α_lᵀ/(3r)) + φ'·r(α_j β_lᵀ + β_j α_lᵀ) + λφ''·β_j β_lᵀ
///          + λφ'·M(Σ_c (w_j × w_l)_c c_c)]`
///
/// (`Σ_ab w_aj w_bl ε_abc = (w_j × w_l)_c`). Only the ten blocks `j ≤ l` are computed; the
/// others are their transposes. Checked against [`tet_term`] (the 24×24 reference) in tests.
#[inline(always)]
fn tet_term_blocks(
    t: &ScaledTet,
    p: &[DVec3; 8],
    omega: f64,
    wt: f64,
    g: &mut [DVec3; 8],
    hb: Option<&mut CellBlocks>,
) -> f64 {
    let mut c = [DVec3::ZERO; 3];
    for (a, ca) in c.iter_mut().enumerate() {
        for j in 0..4 {
            *ca += t.w[a][j] * p[t.nodes[j]];
        }
    }
    let s = c[0].length_squared() + c[1].length_squared() + c[2].length_squared();
    let r = (s / 3.0).sqrt();
    let lam = r * r * r;
    let dv = [c[1].cross(c[2]), c[2].cross(c[0]), c[0].cross(c[1])];
    let v = c[0].dot(dv[0]);
    let phi = phi_omega(omega, v);
    let val = wt * lam * phi[0];
    let al: [DVec3; 4] =
        std::array::from_fn(|j| t.w[0][j] * c[0] + t.w[1][j] * c[1] + t.w[2][j] * c[2]);
    let be: [DVec3; 4] =
        std::array::from_fn(|j| t.w[0][j] * dv[0] + t.w[1][j] * dv[1] + t.w[2][j] * dv[2]);
    let (kg, kb) = (wt * phi[0] * r, wt * lam * phi[1]);
    for j in 0..4 {
        g[t.nodes[j]] += kg * al[j] + kb * be[j];
    }
    if let Some(hb) = hb {
        let inv3r = if r > 0.0 { 1.0 / (3.0 * r) } else { 0.0 };
        let k0 = wt * phi[0] * r;
        let k1 = wt * phi[0] * inv3r;
        let k2 = wt * phi[1] * r;
        let k3 = wt * lam * phi[2];
        let k4 = kb;
        // H_jl = k0 G_jl I + α_j P_lᵀ + β_j Q_lᵀ + M(z_jl)
        let pp: [DVec3; 4] = std::array::from_fn(|l| k1 * al[l] + k2 * be[l]);
        let qq: [DVec3; 4] = std::array::from_fn(|l| k2 * al[l] + k3 * be[l]);
        for j in 0..4 {
            let aj = al[j].to_array();
            let bj = be[j].to_array();
            for l in j..4 {
                let pl = pp[l].to_array();
                let ql = qq[l].to_array();
                let mut blk = [0.0; 9];
                for x in 0..3 {
                    for y in 0..3 {
                        blk[3 * x + y] = aj[x] * pl[y] + bj[x] * ql[y];
                    }
                }
                let d = k0 * t.gram[j][l];
                blk[0] += d;
                blk[4] += d;
                blk[8] += d;
                if j != l {
                    let wx = t.wx[j][l];
                    let z = k4 * (wx.x * c[0] + wx.y * c[1] + wx.z * c[2]);
                    // M(z)_{xy} = ε_{xyk} z_k
                    blk[1] += z.z;
                    blk[2] -= z.y;
                    blk[3] -= z.z;
                    blk[5] += z.x;
                    blk[6] += z.y;
                    blk[7] -= z.x;
                }
                add_block_sym(hb, t.nodes[j], t.nodes[l], &blk);
            }
        }
    }
    val
}

/// One face term `C·k²` in node-block form (the same derivatives as [`face_term`]; the legs
/// `B−A, D−A, C−A` have stencil `+1` on their own vertex and `−1` on `A`, so the blocks are
/// `H_{k l} = h_{kl}`, `H_{A l} = −Σ_k h_{kl}`, `H_{A A} = Σ_{kl} h_{kl}`).
#[inline(always)]
fn face_term_blocks(
    f: [usize; 4],
    p: &[DVec3; 8],
    cpen: f64,
    g: &mut [DVec3; 8],
    hb: Option<&mut CellBlocks>,
) -> f64 {
    let want_h = hb.is_some();
    let Some((val, gy, hc)) = face_parts(f, p, cpen, want_h) else {
        return 0.0;
    };
    let (a, b, cc, d) = (f[0], f[1], f[2], f[3]);
    let leg_node = [b, d, cc];
    for k in 0..3 {
        g[leg_node[k]] += gy[k];
        g[a] -= gy[k];
    }
    if let (Some(hb), Some(hc)) = (hb, hc) {
        let flat =
            |k: usize, l: usize| -> [f64; 9] { std::array::from_fn(|e| hc[k][l][e / 3][e % 3]) };
        let mut row_sum = [[0.0; 9]; 3]; // Σ_k h_{kl}, per l
        let mut aa = [0.0; 9];
        for k in 0..3 {
            for l in k..3 {
                let blk = flat(k, l);
                add_block_sym(hb, leg_node[k], leg_node[l], &blk);
            }
            for l in 0..3 {
                let blk = flat(k, l);
                for e in 0..9 {
                    row_sum[l][e] += blk[e];
                    aa[e] += blk[e];
                }
            }
        }
        for l in 0..3 {
            let neg: [f64; 9] = std::array::from_fn(|e| -row_sum[l][e]);
            add_block_sym(hb, a, leg_node[l], &neg);
        }
        add_block_sym(hb, a, a, &aa);
    }
    val
}

/// Leg-Hessian blocks `h[k][l]` (3×3) of a face term w.r.t. its legs `B−A, D−A, C−A`.
type LegHess = [[[[f64; 3]; 3]; 3]; 3];

/// Value, leg gradients (w.r.t. `B−A, D−A, C−A`) and, with `want_h`, leg Hessian of the face
/// term `C·k²` of the hex-local face `f`; `None` for a degenerate face (`n₂w₂ = 0`).
#[inline(always)]
fn face_parts(
    f: [usize; 4],
    p: &[DVec3; 8],
    cpen: f64,
    want_h: bool,
) -> Option<(f64, [DVec3; 3], Option<LegHess>)> {
    let (a, b, cc, d) = (f[0], f[1], f[2], f[3]);
    // legs: u = B − A, v = D − A, w = C − A
    let y = [p[b] - p[a], p[d] - p[a], p[cc] - p[a]];
    let (u, v, w) = (y[0], y[1], y[2]);
    let uv = u.dot(v);
    let (uu, vv) = (u.length_squared(), v.length_squared());
    let n2 = uu * vv - uv * uv;
    let w2 = w.length_squared();
    let dd = n2 * w2;
    if dd.is_nan() || dd <= 0.0 {
        return None;
    }
    let dt = [v.cross(w), w.cross(u), u.cross(v)];
    let t = u.dot(dt[0]);
    let val = cpen * t * t / dd;
    // partials of g = t²/D
    let gt = cpen * 2.0 * t / dd;
    let gd = -cpen * t * t / (dd * dd);
    let dn2 = [
        2.0 * vv * u - 2.0 * uv * v,
        2.0 * uu * v - 2.0 * uv * u,
        DVec3::ZERO,
    ];
    let dw2 = [DVec3::ZERO, DVec3::ZERO, 2.0 * w];
    let d_den: [DVec3; 3] = std::array::from_fn(|k| w2 * dn2[k] + n2 * dw2[k]);
    let gy: [DVec3; 3] = std::array::from_fn(|k| gt * dt[k] + gd * d_den[k]);
    if !want_h {
        return Some((val, gy, None));
    }
    {
        let gtt = cpen * 2.0 / dd;
        let gtd = -cpen * 2.0 * t / (dd * dd);
        let gdd = cpen * 2.0 * t * t / (dd * dd * dd);
        let th = det_hess(&[u, v, w]);
        // Hessian of n2 (blocks uu, uv, vu, vv) and w2 (ww)
        let ua = u.to_array();
        let va = v.to_array();
        let mut n2h = [[[[0.0; 3]; 3]; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                let dij = if i == j { 1.0 } else { 0.0 };
                n2h[0][0][i][j] = 2.0 * vv * dij - 2.0 * va[i] * va[j];
                n2h[1][1][i][j] = 2.0 * uu * dij - 2.0 * ua[i] * ua[j];
                n2h[0][1][i][j] = 4.0 * ua[i] * va[j] - 2.0 * va[i] * ua[j] - 2.0 * uv * dij;
                n2h[1][0][j][i] = n2h[0][1][i][j];
            }
        }
        let mut hc = [[[[0.0; 3]; 3]; 3]; 3];
        for k in 0..3 {
            let tk = dt[k].to_array();
            let dk = d_den[k].to_array();
            let nk = dn2[k].to_array();
            let wk = dw2[k].to_array();
            for l in 0..3 {
                let tl = dt[l].to_array();
                let dl = d_den[l].to_array();
                let nl = dn2[l].to_array();
                let wl = dw2[l].to_array();
                for i in 0..3 {
                    for j in 0..3 {
                        let mut ddh = w2 * n2h[k][l][i][j] + nk[i] * wl[j] + wk[i] * nl[j];
                        if k == 2 && l == 2 && i == j {
                            ddh += 2.0 * n2;
                        }
                        hc[k][l][i][j] = gtt * tk[i] * tl[j]
                            + gtd * (tk[i] * dl[j] + dk[i] * tl[j])
                            + gdd * dk[i] * dl[j]
                            + gt * th[k][l][i][j]
                            + gd * ddh;
                    }
                }
            }
        }
        Some((val, gy, Some(hc)))
    }
}

/// One face term `C·k²` for the hex-local face `f` (24×24 reference form).
#[inline(always)]
fn face_term(
    f: [usize; 4],
    p: &[DVec3; 8],
    cpen: f64,
    g: &mut [DVec3; 8],
    h: Option<&mut [[f64; 24]; 24]>,
) -> f64 {
    let Some((val, gy, hc)) = face_parts(f, p, cpen, h.is_some()) else {
        return 0.0;
    };
    let (a, b, cc, d) = (f[0], f[1], f[2], f[3]);
    g[b] += gy[0];
    g[d] += gy[1];
    g[cc] += gy[2];
    g[a] -= gy[0] + gy[1] + gy[2];
    if let (Some(h), Some(hc)) = (h, hc) {
        let legs = [
            [(b, 1.0), (a, -1.0), (a, 0.0), (a, 0.0)],
            [(d, 1.0), (a, -1.0), (a, 0.0), (a, 0.0)],
            [(cc, 1.0), (a, -1.0), (a, 0.0), (a, 0.0)],
        ];
        scatter_hess3(&legs, &hc, h);
    }
    val
}

/// The 3D functional `h_scale·Σ_cells Σ_tets λφ_ω(V) + C·Σ_interior cells Σ_faces k²`
/// ([Cortés Aguirre 2012, (3.27), (4.4)]); either term can be switched off.
#[derive(Debug, Clone)]
pub struct HexFunctional {
    topo: Arc<HexTopology>,
    tets: [ScaledTet; 10],
    omega: Option<f64>,
    h_scale: f64,
    coplanarity: Option<f64>,
}

impl HexFunctional {
    /// `H_ω` with the thesis' normalization `1/(10N_c)` (3.27), `ω > 0`.
    pub fn h_omega(
        topo: Arc<HexTopology>,
        omega: f64,
        scaling: Scaling3,
    ) -> Result<Self, FunctionalError> {
        check_pos("omega", omega)?;
        let f = scaling.factors()?;
        let tets = hex_tets().map(|t| {
            ScaledTet::new(
                t.nodes,
                std::array::from_fn(|a| t.stencil[a].map(|v| v * f[t.dirs[a]])),
            )
        });
        let h_scale = 1.0 / (10.0 * topo.num_cells() as f64);
        Ok(Self {
            topo,
            tets,
            omega: Some(omega),
            h_scale,
            coplanarity: None,
        })
    }
    /// Only the coplanarity penalty `C·Σk²`, `C ≥ 0` (Algorithm B uses `C = 1/(2μ)`).
    pub fn coplanarity(topo: Arc<HexTopology>, c: f64) -> Result<Self, FunctionalError> {
        let mut f = Self::h_omega(topo, 1.0, Scaling3::Index)?;
        f.omega = None;
        f.set_coplanarity(Some(c))?;
        Ok(f)
    }
    /// Adds (or replaces) the coplanarity penalty with weight `C ≥ 0`.
    pub fn with_coplanarity(mut self, c: f64) -> Result<Self, FunctionalError> {
        self.set_coplanarity(Some(c))?;
        Ok(self)
    }
    /// Sets or removes the coplanarity penalty.
    pub fn set_coplanarity(&mut self, c: Option<f64>) -> Result<(), FunctionalError> {
        if let Some(c) = c {
            if !(c.is_finite() && c >= 0.0) {
                return Err(FunctionalError::InvalidParameter {
                    name: "C",
                    value: c,
                    reason: "the penalty weight must be finite and ≥ 0".into(),
                });
            }
        }
        self.coplanarity = c;
        Ok(())
    }
    /// Sets `ω` of the `H_ω` term (Algorithm A halves it), or switches the term off.
    pub fn set_omega(&mut self, omega: Option<f64>) -> Result<(), FunctionalError> {
        if let Some(w) = omega {
            check_pos("omega", w)?;
        }
        self.omega = omega;
        Ok(())
    }
    /// Replaces the factor of the `H_ω` sum (default `1/(10N_c)`; 1 gives the plain sum).
    pub fn set_h_scale(&mut self, s: f64) -> Result<(), FunctionalError> {
        self.h_scale = check_finite("h_scale", s)?;
        Ok(())
    }
    /// The topology.
    pub fn topology(&self) -> &Arc<HexTopology> {
        &self.topo
    }
    /// Current `ω`.
    pub fn omega(&self) -> Option<f64> {
        self.omega
    }

    /// The ten Jacobian determinants of cell `c` at `x` (scaled as configured).
    fn tet_dets(&self, p: &[DVec3; 8]) -> [f64; 10] {
        self.tets.map(|t| {
            let c: [DVec3; 3] = std::array::from_fn(|a| {
                (0..4).fold(DVec3::ZERO, |acc, j| acc + t.w[a][j] * p[t.nodes[j]])
            });
            c[0].dot(c[1].cross(c[2]))
        })
    }

    /// Value of cell `c`, adding its gradient (and Hessian) to the local arrays; with
    /// `only = Some(i)` terms not involving local node `i` are skipped.
    #[inline(always)]
    fn cell_eval(
        &self,
        c: usize,
        p: &[DVec3; 8],
        only: Option<usize>,
        g: &mut [DVec3; 8],
        mut h: Option<&mut [[f64; 24]; 24]>,
    ) -> f64 {
        let mut v = 0.0;
        if let Some(w) = self.omega {
            for t in &self.tets {
                if let Some(i) = only {
                    if !t.nodes.contains(&i) {
                        continue;
                    }
                }
                v += tet_term(t, p, w, self.h_scale, g, h.as_deref_mut());
            }
        }
        if let Some(cp) = self.coplanarity {
            if self.topo.interior[c] {
                for f in HEX_QUAD_FACES {
                    if let Some(i) = only {
                        if !f.contains(&i) {
                            continue;
                        }
                    }
                    v += face_term(f, p, cp, g, h.as_deref_mut());
                }
            }
        }
        v
    }
}

impl HexFunctional {
    /// Value of cell `c`, adding its gradient and (if asked) its node-block Hessian.
    #[inline(always)]
    fn cell_eval_blocks(
        &self,
        c: usize,
        p: &[DVec3; 8],
        g: &mut [DVec3; 8],
        mut hb: Option<&mut CellBlocks>,
    ) -> f64 {
        let mut v = 0.0;
        if let Some(w) = self.omega {
            for t in &self.tets {
                v += tet_term_blocks(t, p, w, self.h_scale, g, hb.as_deref_mut());
            }
        }
        if let Some(cp) = self.coplanarity {
            if self.topo.interior[c] {
                for f in HEX_QUAD_FACES {
                    v += face_term_blocks(f, p, cp, g, hb.as_deref_mut());
                }
            }
        }
        v
    }

    /// The Hessian by the original per-tetrahedron assembly: each term's column Hessian is
    /// spread over a 24×24 cell matrix (`scatter_hess3`), whose entries are then located in the
    /// CSR rows by binary search. The fallback of the node-block [`Hessian::hessian`] when its
    /// slot table cannot be built, and the reference the tests check it against (same values up
    /// to rounding); `h` must come from [`Hessian::hessian_pattern`].
    ///
    /// # Panics
    /// If `x` or `h` do not fit the mesh.
    fn hessian_scatter(&self, x: &[f64], h: &mut Csr) {
        assert_eq!(x.len(), self.num_vars(), "hessian: x has the wrong length");
        assert!(
            self.topo.asm.matches_pattern(3, h),
            "hessian: matrix does not come from hessian_pattern"
        );
        let Csr {
            row_offsets,
            values,
            ..
        } = h;
        crate::csr::par_zero(values);
        let hp = SyncPtr::new(values);
        let ro: &[usize] = row_offsets;
        let asm = &self.topo.asm;
        asm.run_colored(|c| {
            let (p, vars) = self.topo.cell_points(x, c);
            let mut lg = [DVec3::ZERO; 8];
            let mut lh = [[0.0; 24]; 24];
            self.cell_eval(c, &p, None, &mut lg, Some(&mut lh));
            for i in 0..8 {
                let vi = vars[i];
                if vi == FIXED {
                    continue;
                }
                for jn in 0..8 {
                    let vj = vars[jn];
                    if vj == FIXED {
                        continue;
                    }
                    let k = asm.nbr_pos(vi, vj);
                    for dx in 0..3 {
                        let base = ro[3 * vi as usize + dx] + 3 * k;
                        for dy in 0..3 {
                            // SAFETY: row of a node of this cell; see `assembly`.
                            unsafe { hp.add(base + dy, lh[3 * i + dx][3 * jn + dy]) };
                        }
                    }
                }
            }
            0.0
        });
    }
}

fn check_pos(name: &'static str, v: f64) -> Result<f64, FunctionalError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(FunctionalError::InvalidParameter {
            name,
            value: v,
            reason: "must be finite and > 0".into(),
        })
    }
}

fn check_finite(name: &'static str, v: f64) -> Result<f64, FunctionalError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(FunctionalError::InvalidParameter {
            name,
            value: v,
            reason: "must be finite".into(),
        })
    }
}

impl Variables for HexFunctional {
    fn dim(&self) -> usize {
        3
    }
    fn num_vars(&self) -> usize {
        self.topo.num_vars()
    }
    fn free_nodes(&self) -> &[usize] {
        self.topo.free_nodes()
    }
    fn var_of(&self, node: usize) -> Option<usize> {
        self.topo.var_of(node)
    }
}

impl Cost for HexFunctional {
    fn value(&self, x: &[f64]) -> f64 {
        assert_eq!(x.len(), self.num_vars(), "value: x has the wrong length");
        self.topo.asm.run_value(|c| {
            let (p, _) = self.topo.cell_points(x, c);
            let mut g = [DVec3::ZERO; 8];
            self.cell_eval(c, &p, None, &mut g, None)
        })
    }
}

impl Gradient for HexFunctional {
    fn value_grad(&self, x: &[f64], g: &mut [f64]) -> f64 {
        assert_eq!(
            x.len(),
            self.num_vars(),
            "value_grad: x has the wrong length"
        );
        assert_eq!(
            g.len(),
            self.num_vars(),
            "value_grad: g has the wrong length"
        );
        crate::csr::par_zero(g);
        let gp = SyncPtr::new(g);
        self.topo.asm.run_colored(|c| {
            let (p, vars) = self.topo.cell_points(x, c);
            let mut lg = [DVec3::ZERO; 8];
            let v = self.cell_eval(c, &p, None, &mut lg, None);
            for i in 0..8 {
                if vars[i] != FIXED {
                    let j = 3 * vars[i] as usize;
                    // SAFETY: node of this cell; see `assembly` (colouring).
                    unsafe {
                        gp.add(j, lg[i].x);
                        gp.add(j + 1, lg[i].y);
                        gp.add(j + 2, lg[i].z);
                    }
                }
            }
            v
        })
    }
}

impl Hessian for HexFunctional {
    fn hessian_pattern(&self) -> Csr {
        self.topo.hessian_pattern()
    }

    /// Node-block assembly: per cell the Hessian w.r.t. its eight vertices is built
    /// as 8×8 closed-form 3×3 blocks (`tet_term_blocks`, `face_term_blocks`, see the module docs) and added at
    /// the CSR positions precomputed once with the pattern ([`HexTopology::block_slots`]).
    /// Cells run in the deterministic chunk colouring of `assembly` (bit-identical for any
    /// thread count). Falls back to the per-tetrahedron scatter assembly (private) when the
    /// slot table cannot be built (more than `u32::MAX` entries).
    fn hessian(&self, x: &[f64], h: &mut Csr) {
        assert_eq!(x.len(), self.num_vars(), "hessian: x has the wrong length");
        assert_eq!(
            h.nrows,
            self.num_vars(),
            "hessian: matrix has the wrong size"
        );
        assert!(
            self.topo.asm.matches_pattern(3, h),
            "hessian: matrix does not come from hessian_pattern"
        );
        let Some(slots) = self.topo.block_slots() else {
            self.hessian_scatter(x, h);
            return;
        };
        let values = &mut h.values;
        crate::csr::par_zero(values);
        let hp = SyncPtr::new(values);
        let topo = &*self.topo;
        topo.asm.run_colored(|c| {
            let (p, vars) = topo.cell_points(x, c);
            let mut lg = [DVec3::ZERO; 8];
            let mut hb: CellBlocks = [[[0.0; 9]; 8]; 8];
            self.cell_eval_blocks(c, &p, &mut lg, Some(&mut hb));
            let sl = &slots[c];
            for a in 0..8 {
                if vars[a] == FIXED {
                    continue;
                }
                let rl = topo.row_len(vars[a]);
                for b in 0..8 {
                    let s0 = sl[8 * a + b];
                    if s0 == u32::MAX {
                        continue;
                    }
                    let blk = &hb[a][b];
                    for dx in 0..3 {
                        let base = s0 as usize + dx * rl;
                        for dy in 0..3 {
                            // SAFETY: a block of two nodes of this cell (slot table built from
                            // the same pattern, checked by `matches_pattern`); see `assembly`.
                            unsafe { hp.add(base + dy, blk[3 * dx + dy]) };
                        }
                    }
                }
            }
            0.0
        });
    }

    fn hess_vec(&self, x: &[f64], v: &[f64], out: &mut [f64]) {
        let n = self.num_vars();
        assert_eq!(x.len(), n, "hess_vec: x has the wrong length");
        assert_eq!(v.len(), n, "hess_vec: v has the wrong length");
        assert_eq!(out.len(), n, "hess_vec: out has the wrong length");
        out.par_iter_mut().with_min_len(4096).for_each(|o| *o = 0.0);
        let op = SyncPtr::new(out);
        self.topo.asm.run_colored(|c| {
            let (p, vars) = self.topo.cell_points(x, c);
            let mut lg = [DVec3::ZERO; 8];
            let mut hb: CellBlocks = [[[0.0; 9]; 8]; 8];
            self.cell_eval_blocks(c, &p, &mut lg, Some(&mut hb));
            let mut lv = [DVec3::ZERO; 8];
            for b in 0..8 {
                if vars[b] != FIXED {
                    let j = 3 * vars[b] as usize;
                    lv[b] = DVec3::new(v[j], v[j + 1], v[j + 2]);
                }
            }
            for a in 0..8 {
                if vars[a] == FIXED {
                    continue;
                }
                let mut acc = [0.0; 3];
                for b in 0..8 {
                    if vars[b] == FIXED {
                        continue;
                    }
                    let blk = &hb[a][b];
                    for dx in 0..3 {
                        acc[dx] += blk[3 * dx] * lv[b].x
                            + blk[3 * dx + 1] * lv[b].y
                            + blk[3 * dx + 2] * lv[b].z;
                    }
                }
                let j = 3 * vars[a] as usize;
                for dx in 0..3 {
                    // SAFETY: node of this cell; see `assembly`.
                    unsafe { op.add(j + dx, acc[dx]) };
                }
            }
            0.0
        });
    }
}

impl PointwiseModel for HexFunctional {
    fn local(&self, x: &[f64], node: usize) -> Option<LocalModel> {
        self.topo.var_of(node)?;
        assert_eq!(x.len(), self.num_vars(), "local: x has the wrong length");
        let asm = &self.topo.asm;
        let mut m = LocalModel {
            value: 0.0,
            grad: [0.0; 3],
            hess: [[0.0; 3]; 3],
            dim: 3,
        };
        for &c in &asm.inc[asm.inc_offsets[node]..asm.inc_offsets[node + 1]] {
            let c = c as usize;
            let i = asm.cells[c].iter().position(|&v| v as usize == node)?;
            let (p, _) = self.topo.cell_points(x, c);
            let mut lg = [DVec3::ZERO; 8];
            let mut lh = [[0.0; 24]; 24];
            m.value += self.cell_eval(c, &p, Some(i), &mut lg, Some(&mut lh));
            let gi = lg[i].to_array();
            for dx in 0..3 {
                m.grad[dx] += gi[dx];
                for dy in 0..3 {
                    m.hess[dx][dy] += lh[3 * i + dx][3 * i + dy];
                }
            }
        }
        Some(m)
    }
}

impl ElementMeasures for HexFunctional {
    fn num_elements(&self) -> usize {
        10 * self.topo.num_cells()
    }

    fn element_measures(&self, x: &[f64], out: &mut [f64]) {
        assert_eq!(
            out.len(),
            self.num_elements(),
            "element_measures: wrong length"
        );
        assert_eq!(
            x.len(),
            self.num_vars(),
            "element_measures: x has the wrong length"
        );
        out.par_chunks_mut(10).enumerate().for_each(|(c, o)| {
            let (p, _) = self.topo.cell_points(x, c);
            o.copy_from_slice(&self.tet_dets(&p));
        });
    }
    fn element_nodes(&self, e: usize, out: &mut Vec<usize>) {
        out.extend(self.topo.asm.cells[e / 10].iter().map(|&v| v as usize));
    }
}

/// The harmonic energy `E = λ/V` of a mesh under the readings of the thesis's discretisation
/// that could explain a reported value ([Cortés Aguirre 2012, §3.2, (3.21)–(3.22), (3.27)]; the
/// sphere of §3.4.3 ends at `f = 2.26543`). All are evaluated at `ω → 0`, i.e.
/// where `H_ω` *is* the energy (`φ_ω(V) = 1/V` for `V ≥ ω`); `E ≥ 1` per tetrahedron (AM–GM),
/// `= 1` iff its Jacobian is a similarity. See [`energy_variants`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnergyVariants {
    /// (3.22)/(3.27) as printed: `(1/N_c) Σ_cells Σ_{10 tets} (1/10)·E` — what
    /// [`HexFunctional::h_omega`] computes (the mean over all tetrahedra).
    pub printed: f64,
    /// Each of the two five-tetrahedra decompositions ("dodecaedros", §3.2) averaged on its
    /// own and the two averages added: `(1/N_c) Σ_cells [(1/5)Σ_A E + (1/5)Σ_B E]`
    /// = `2·printed` exactly.
    pub per_decomposition: f64,
    /// Volume quadrature of Azarenok's split: within each decomposition a corner tetrahedron
    /// weighs `1/6` and the interior one `1/3` of the cell (their volume shares), the two
    /// decompositions added (weights sum to 2 per cell, like `per_decomposition`).
    pub volume_weighted: f64,
    /// `printed`, but the two interior tetrahedra (7425, 1386) use the generic corner form
    /// `r_ξ = Q−P, r_η = R−P, r_ζ = S−P` on their own vertices (the mislabelled (3.33) read
    /// literally; these columns are face diagonals, `E = √2` on a cube). Raw differences, so
    /// only comparable with the others when `m = n = p` (the scaling is then uniform and `E`
    /// is scale-free).
    pub interior_raw: f64,
    /// Number of tetrahedra with `V ≤ 0` (then `E` is undefined and those terms are skipped).
    pub non_positive: usize,
}

/// Evaluates [`EnergyVariants`] on the cells `cells` (eight vertices each, VTK order) with
/// the Jacobian scaling `scaling` ([Cortés Aguirre 2012, §3.2]; [`Scaling3`]).
///
/// Hand values on a mesh of congruent cubes (every Jacobian a similarity): `printed = 1`,
/// `per_decomposition = volume_weighted = 2`, `interior_raw = (8 + 2√2)/10`.
pub fn energy_variants(
    cells: &[[DVec3; 8]],
    scaling: Scaling3,
) -> Result<EnergyVariants, FunctionalError> {
    let f = scaling.factors()?;
    let tets = hex_tets();
    let energy = |c: [DVec3; 3]| -> Option<f64> {
        let v = c[0].dot(c[1].cross(c[2]));
        let s = c[0].length_squared() + c[1].length_squared() + c[2].length_squared();
        (v > 0.0).then(|| (s / 3.0).powf(1.5) / v)
    };
    let mut out = EnergyVariants {
        printed: 0.0,
        per_decomposition: 0.0,
        volume_weighted: 0.0,
        interior_raw: 0.0,
        non_positive: 0,
    };
    for p in cells {
        for t in &tets {
            let col = |a: usize| {
                (0..4).fold(DVec3::ZERO, |acc, j| acc + t.stencil[a][j] * p[t.nodes[j]])
                    * f[t.dirs[a]]
            };
            let Some(e) = energy([col(0), col(1), col(2)]) else {
                out.non_positive += 1;
                continue;
            };
            out.printed += e / 10.0;
            out.per_decomposition += e / 5.0;
            out.volume_weighted += if t.interior { e / 3.0 } else { e / 6.0 };
            if t.interior {
                let [a, b, c, d] = t.nodes.map(|v| p[v]);
                if let Some(er) = energy([b - a, c - a, d - a]) {
                    out.interior_raw += er / 10.0;
                }
            } else {
                out.interior_raw += e / 10.0;
            }
        }
    }
    let n = cells.len().max(1) as f64;
    out.printed /= n;
    out.per_decomposition /= n;
    out.volume_weighted /= n;
    out.interior_raw /= n;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An `m × n × p`-node grid of the unit-spaced box with every interior node moved by a
    /// deterministic pseudo-random offset of size up to `amp` (amp > ~0.5 folds cells).
    fn grid(m: usize, n: usize, p: usize, amp: f64) -> HexTopology {
        let id = |i: usize, j: usize, k: usize| i + m * (j + n * k);
        let mut nodes = Vec::new();
        let mut fixed = Vec::new();
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for k in 0..p {
            for j in 0..n {
                for i in 0..m {
                    let b = i == 0 || j == 0 || k == 0 || i == m - 1 || j == n - 1 || k == p - 1;
                    let mut q = DVec3::new(i as f64, j as f64, 1.3 * k as f64);
                    if !b {
                        q += amp * DVec3::new(rnd(), rnd(), rnd());
                    }
                    nodes.push(q);
                    fixed.push(b);
                }
            }
        }
        let mut cells = Vec::new();
        for k in 0..p - 1 {
            for j in 0..n - 1 {
                for i in 0..m - 1 {
                    cells.push([
                        id(i, j, k),
                        id(i + 1, j, k),
                        id(i + 1, j + 1, k),
                        id(i, j + 1, k),
                        id(i, j, k + 1),
                        id(i + 1, j, k + 1),
                        id(i + 1, j + 1, k + 1),
                        id(i, j + 1, k + 1),
                    ]);
                }
            }
        }
        HexTopology::new(nodes, cells, fixed).unwrap()
    }

    /// The eight vertices of the unit cube's image under `x ↦ A·x` (VTK order).
    fn affine_cell(a: [DVec3; 3]) -> [DVec3; 8] {
        std::array::from_fn(|v| {
            let u = unit_cube(v);
            a[0] * u.x + a[1] * u.y + a[2] * u.z
        })
    }

    /// Hand values of [`energy_variants`] ([Cortés Aguirre 2012, (3.22)] and its readings).
    #[test]
    fn energy_variants_hand_values() {
        // congruent cubes of side 0.25: every tetrahedron Jacobian is a similarity, E = 1
        let cube = affine_cell([DVec3::X * 0.25, DVec3::Y * 0.25, DVec3::Z * 0.25]);
        let e = energy_variants(&[cube, cube], Scaling3::Index).unwrap();
        assert!((e.printed - 1.0).abs() < 1e-14, "{e:?}");
        assert!((e.per_decomposition - 2.0).abs() < 1e-14);
        assert!((e.volume_weighted - 2.0).abs() < 1e-14);
        // interior tets with raw face-diagonal legs: s = 6h², V = 2h³ → E = √2
        let raw = (8.0 + 2.0 * 2f64.sqrt()) / 10.0;
        assert!((e.interior_raw - raw).abs() < 1e-14, "{e:?}");
        assert_eq!(e.non_positive, 0);
        // box stretched 2× along x: every Jacobian diag(2,1,1), E = (6/3)^{3/2}/2 = √2;
        // the raw interior legs have s = 5 + 2 + 5 = 12 and V = 2·2 = 4, E = 8/4 = 2
        let stretched = affine_cell([DVec3::X * 2.0, DVec3::Y, DVec3::Z]);
        let e = energy_variants(&[stretched], Scaling3::Index).unwrap();
        assert!((e.printed - 2f64.sqrt()).abs() < 1e-14, "{e:?}");
        assert!((e.per_decomposition - 2.0 * 2f64.sqrt()).abs() < 1e-14);
        assert!((e.volume_weighted - 2.0 * 2f64.sqrt()).abs() < 1e-14);
        assert!((e.interior_raw - (8.0 * 2f64.sqrt() + 4.0) / 10.0).abs() < 1e-14);
        // parametric factors (2, 1, 1) of a 3 × 2 × 2-node grid double the x column again:
        // Jacobian diag(4, 1, 1), E = (18/3)^{3/2}/4
        let e = energy_variants(&[stretched], Scaling3::Parametric { m: 3, n: 2, p: 2 }).unwrap();
        assert!((e.printed - 6f64.powf(1.5) / 4.0).abs() < 1e-12, "{e:?}");
        // per_decomposition is exactly twice the printed normalisation on any mesh
        let topo = Arc::new(grid(4, 4, 4, 0.3));
        let cells: Vec<[DVec3; 8]> = (0..topo.num_cells())
            .map(|c| topo.cell_points(&topo.initial_x(), c).0)
            .collect();
        let e = energy_variants(&cells, Scaling3::Index).unwrap();
        assert!((e.per_decomposition - 2.0 * e.printed).abs() < 1e-12 * e.printed);
        assert!(e.printed > 1.0);
        // and `printed` is what H_ω evaluates once ω is below every V
        let h = HexFunctional::h_omega(topo.clone(), 1e-9, Scaling3::Index).unwrap();
        let hv = h.value(&topo.initial_x());
        assert!((hv - e.printed).abs() < 1e-12 * hv, "{hv} vs {}", e.printed);
    }

    #[test]
    fn node_block_hessian_equals_the_reference_assembly_and_hess_vec() {
        // convex and folded starts; every term kind (both ω branches, coplanarity only, both)
        for amp in [0.3, 1.4] {
            let topo = Arc::new(grid(6, 5, 5, amp));
            let x = topo.initial_x();
            let fs = [
                HexFunctional::h_omega(topo.clone(), 0.7, Scaling3::Index).unwrap(),
                HexFunctional::h_omega(topo.clone(), 40.0, Scaling3::Custom([1.0, 2.0, 0.5]))
                    .unwrap(),
                HexFunctional::coplanarity(topo.clone(), 3.0).unwrap(),
                HexFunctional::h_omega(
                    topo.clone(),
                    0.2,
                    Scaling3::Parametric { m: 6, n: 5, p: 5 },
                )
                .unwrap()
                .with_coplanarity(0.9)
                .unwrap(),
            ];
            for (fi, f) in fs.iter().enumerate() {
                let mut h = f.hessian_pattern();
                let mut r = f.hessian_pattern();
                f.hessian(&x, &mut h);
                f.hessian_scatter(&x, &mut r);
                let scale = r.values.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                assert!(scale > 0.0);
                for (k, (a, b)) in h.values.iter().zip(&r.values).enumerate() {
                    // the same sums in another order: rounding-level differences only
                    assert!(
                        (a - b).abs() <= 1e-12 * scale,
                        "f{fi} amp {amp} entry {k}: {a} vs {b}"
                    );
                }
                // the assembled matrix is symmetric
                for row in 0..h.nrows {
                    for e in h.row_offsets[row]..h.row_offsets[row + 1] {
                        let col = h.col_indices[e] as usize;
                        assert!((h.values[e] - h.get(col, row)).abs() <= 1e-12 * scale);
                    }
                }
                // the matrix-free product equals the CSR product
                let v: Vec<f64> = (0..f.num_vars())
                    .map(|i| ((i * 7919) % 13) as f64 - 6.0)
                    .collect();
                let mut hv = vec![0.0; v.len()];
                let mut mv = vec![0.0; v.len()];
                f.hess_vec(&x, &v, &mut hv);
                h.mul_vec(&v, &mut mv);
                for (a, b) in hv.iter().zip(&mv) {
                    assert!((a - b).abs() <= 1e-10 * scale, "{a} vs {b}");
                }
            }
        }
    }

    #[test]
    fn block_slots_point_at_the_block_entries() {
        let topo = grid(5, 5, 4, 0.2);
        let f = HexFunctional::h_omega(Arc::new(grid(5, 5, 4, 0.2)), 1.0, Scaling3::Index).unwrap();
        let h = f.hessian_pattern();
        let slots = topo.block_slots().unwrap();
        for (c, sl) in slots.iter().enumerate() {
            for a in 0..8 {
                for b in 0..8 {
                    let (va, vb) = (
                        topo.var_of(topo.asm.cells[c][a] as usize),
                        topo.var_of(topo.asm.cells[c][b] as usize),
                    );
                    match (va, vb) {
                        (Some(va), Some(vb)) => {
                            let s0 = sl[8 * a + b] as usize;
                            // row 3va + dx, column 3vb + dy
                            for dx in 0..3 {
                                let rl =
                                    3 * (topo.asm.nbr_offsets[va + 1] - topo.asm.nbr_offsets[va]);
                                for dy in 0..3 {
                                    let e = s0 + dx * rl + dy;
                                    assert!(
                                        e >= h.row_offsets[3 * va + dx]
                                            && e < h.row_offsets[3 * va + dx + 1]
                                    );
                                    assert_eq!(h.col_indices[e] as usize, 3 * vb + dy);
                                }
                            }
                        }
                        _ => assert_eq!(sl[8 * a + b], u32::MAX),
                    }
                }
            }
        }
    }

    #[test]
    fn all_ten_tets_are_positive_on_the_unit_cube_and_interior_ones_have_v_3vol() {
        let p: [DVec3; 8] = std::array::from_fn(unit_cube);
        for t in hex_tets() {
            let c: [DVec3; 3] = std::array::from_fn(|a| {
                (0..4).fold(DVec3::ZERO, |acc, j| acc + t.stencil[a][j] * p[t.nodes[j]])
            });
            let v = c[0].dot(c[1].cross(c[2]));
            // every column is a unit logical direction on the unit cube, so V = ±1 → must be +1
            assert!((v - 1.0).abs() < 1e-12, "tet {:?} has V = {v}", t.nodes);
            let q = t.nodes.map(|i| p[i]);
            let vol6 = (q[1] - q[0]).dot((q[2] - q[0]).cross(q[3] - q[0])).abs();
            if t.interior {
                // V = 3·vol = vol6 / 2
                assert!((vol6 / 2.0 - v).abs() < 1e-12);
            } else {
                assert!((vol6 - v).abs() < 1e-12);
            }
            let mut dirs = t.dirs;
            dirs.sort_unstable();
            assert_eq!(dirs, [0, 1, 2]);
        }
    }
}
