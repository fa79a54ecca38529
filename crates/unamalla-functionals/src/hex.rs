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

use glam::DVec3;

use crate::error::FunctionalError;
#[cfg(doc)]
use crate::kernel::phi_omega;

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

mod assembly;
mod functional;
mod terms;
mod topology;
mod variants;

pub use functional::HexFunctional;
pub use topology::HexTopology;
pub use variants::{energy_variants, EnergyVariants};

#[cfg(test)]
mod tests;
