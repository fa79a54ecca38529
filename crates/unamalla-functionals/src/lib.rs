//! # unamalla-functionals
//!
//! The discrete variational functionals of the UNAMALLA tradition — the stage that makes cells
//! convex and good — with exact gradients, sparse Hessians (CSR, pattern built once from the
//! connectivity, values refreshed in place), Hessian-vector products and per-node local models
//! for pointwise Newton. Everything is written against the `unamalla-mesh` traits, so one
//! structured grid, a merged block mesh and an arbitrary conformal quad/hex mesh read from a file
//! are handled alike. Variables are the coordinates of the free nodes; fixed nodes are data.
//!
//! ## 2D: sums over corner triangles
//! Each counter-clockwise quad `[v₀, v₁, v₂, v₃]` has four corner triangles: at corner `k`,
//! `P = v_k`, legs `a = v_{k+1} − P`, `b = v_{k−1} − P`, and
//! `α = det(a, b)` (doubled signed area), `l = |a|² + |b|²`, `o = a·b`
//! ([Méndez 2023, §6.4.2, Table 6.2, Fig 6.12]; [González Flores, (2.53), Fig 2.19]; the
//! references are listed in `docs/references.md` of the repository). A cell is convex iff its
//! four α are positive; `Σα = 4·area(Ω)`, `ᾱ = Σα/N`. A functional is `F = Σ_q f(α_q, l_q, o_q)`
//! with `f` a weighted sum of the leaf kernels below ([`kernel`]):
//!
//! | kernel | term | source |
//! |---|---|---|
//! | [`Length`] / [`WeightedLength`] | `l`; `2(ω‖e_ξ‖² + (1−ω)‖e_η‖²)` | [Méndez 2023, Table 6.2]; [González Flores, (1.10)–(1.11)] |
//! | [`Area`] (t-Area) | `α²` | [González Flores, (3.33)] |
//! | [`CastilloArea`] | `A_cell²` | [González Flores, (3.30)] |
//! | [`A4P`] | `(α − ᾱ)⁴` | [González Flores, (3.70)] |
//! | [`Orthogonality`] | `o²` | [Méndez 2023, Table 6.2] |
//! | [`AreaOrthogonality`] | `½(α² + o²) = ½‖a‖²‖b‖²` (apex at the corner; the table prints the wrong apex) | [Méndez 2023, Table 6.2] |
//! | [`Smoothness`] (Winslow) | `l/α`, non-uniform spacing `(ρ‖e_ξ‖² + ρ⁻¹‖e_η‖²)/α` | [González Flores, (2.55), (2.78)–(2.93)] |
//! | [`RegularizedSmoothness`] | `l·φ̃(α)`, pole at `−ε_c`, `ε_c = ᾱ/2` | [González Flores, §2.4, (2.61)–(2.65)], switch on `α = det` |
//! | [`RegularizedInverseArea`] | `φ̃(α)` | [González Flores, (3.71)] |
//! | [`GenericArea`] | any `f(α)` with `f′`, `f″` | [González Flores, (3.54)–(3.60)] |
//! | [`KSmoothness`] | `(l + 2k)/(k + α)`, C² quadratic below `α̂` | [González Flores, (4.37)–(4.41)], `α̂` not as printed in (4.42) |
//! | [`KArea`] | `1/(k + α)`, C² quadratic below `α̂` | [González Flores, (4.23), (4.43)] |
//! | [`SOmegaEps`] | `f(ω(α/ᾱ − ε))`, `f` of (56) | [Abelló et al., §2.2, (55)–(56)], scale-invariant argument |
//! | [`HOmega`] | `l·φ_ω(α)`, `φ_ω = 1/α` (α ≥ ω), `(2ω − α)/ω²` below (C¹) | [Méndez 2023, §6.4.2], continuous `φ_ω` |
//! | [`IvanenkoConvex`] | `((ε − α)₊)²` (zero iff every `α ≥ ε`) | [González Flores, (2.50)], after Ivanenko |
//!
//! Every leaf is a variant of [`Leaf`] (the leaf list is written once, in [`kernel::expr`]).
//! A functional is one [`KernelExpr`], a weighted sum of (possibly cell-weighted) leaves:
//! `f = Σᵢ wᵢ·Eᵢ` with each `Eᵢ` a leaf `fᵢ` or `c(cell)·E` (per-cell weights `c`, the boundary
//! density `w` of [Méndez 2023, (6.9)]), built with normalizations ([`KernelExpr::normalized`],
//! `F/(N·f(ideal triangle))`, [González Flores, §5.1]), weighted sums
//! ([`KernelExpr::weighted_sum`], [`KernelExpr::convex`], e.g. [Méndez 2023, (6.8)]
//! `(1−σ)F_AO + σH_ω`) and per-cell weights ([`KernelExpr::cell_weighted`]). User
//! kernels implement [`TriKernel`] and enter as [`Leaf::Custom`] (e.g. a [`GenericArea`]).
//!
//! Gradients and Hessians come from one generic chain rule through `(α, |a|², |b|², o)`
//! (formulas in [`quad`]). The evaluator computes the four corner triangles of a cell together
//! as four SIMD lanes ([`TriKernel::corners_value_grad`], [`CornerLanes`]), reuses the squared
//! edge lengths shared by two corners, skips the structurally zero second partials
//! ([`TriKernel::hessian_sparsity`]), writes gradients and Hessian blocks at precomputed
//! positions without a zeroing pass, and uses AVX2 when the CPU has it (bit-identical results).
//! It inspects the expression once and runs a fused, monomorphized kernel for the sums it knows
//! (`w₁F_AO + w₂H_ω`), a loop over the terms otherwise; both do the same arithmetic in the same
//! order. The tests keep a straightforward per-triangle path and check that both agree.
//!
//! ## 3D: hexahedra
//! [`HexFunctional`] ([`hex`]): the quasi-harmonic `H_ω` over the 10 tetrahedra of each hexahedron
//! ([Cortés Aguirre 2012, §3.2]: decompositions A = 1245, 3427, 6572, 8547 + 7425 and B = 2316,
//! 4138, 5861, 7683 + 1386, corner and interior Jacobian stencils, optional parametric scaling; the
//! list as completed in [`hex`]), `H_ω = 1/(10N_c) ΣΣ λ φ_ω(V)`,
//! `λ = (‖r_ξ‖² + ‖r_η‖² + ‖r_ζ‖²)^{3/2}/3^{3/2}` (3.27); and the face-coplanarity penalty
//! `C·Σ k²`, `k = (AB × AD)·AC/(‖AB × AD‖‖AC‖)` over the six faces of interior cells
//! ([Cortés Aguirre 2012, §4.1, (4.2)–(4.4)]).
//!
//! ## The optimization interface
//! Small capability traits in the manner of argmin's `CostFunction` / `Gradient` / `Hessian`
//! ([`problem`]): [`Variables`] (the free-node variables), [`Cost`] (`F(x)`), [`Gradient`]
//! (`F` and `∇F`), [`Hessian`] (sparse pattern and refresh, Hessian-vector product),
//! [`PointwiseModel`] (`F` restricted to one node) and [`ElementMeasures`] (the per-element
//! convexity measures of the safeguard). [`Problem`] is all six (blanket implementation); the
//! solvers of `unamalla-optim` bound their code by the capabilities they use. [`QuadFunctional`]
//! and [`HexFunctional`] implement every one; a wrapper that changes one capability implements
//! that trait alone and is combined with the inner problem by [`WithHessian`] or
//! [`WithMeasures`]. `use unamalla_functionals::prelude::*` brings the traits into scope.
//! Topologies ([`QuadTopology`], [`HexTopology`]) hold the free-variable map,
//! the fixed coordinates and the parallel schedule and are shared through `Arc`, so changing ω
//! or k only swaps the kernel. Evaluation is parallel (rayon) and bit-for-bit deterministic for
//! any number of threads (chunk colouring, see [`assembly`]); no allocation happens per
//! evaluation.
//!
//! ## Command-line support
//! [`FunctionalSpec::from_name`] and [`evaluate`] back `unamalla eval`; in raw mode the value is
//! the plain sum of the documented per-triangle terms.

// No unwrap/expect in library code: user input must give an error, never a panic (see
// docs/reliability.md). Tests may use them; a local `#[allow]` needs a comment naming the invariant.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]
// Index loops mirror the component formulas of the derivatives (i, j, a, b as in the docs).
#![allow(clippy::needless_range_loop)]

// The unit tests that moved from `tests/` (they use the test-only reference path) name the
// crate as its users do.
#[cfg(test)]
extern crate self as unamalla_functionals;

pub mod assembly;
pub mod csr;
pub mod error;
pub mod eval;
pub mod hex;
pub mod kernel;
#[cfg(feature = "nalgebra-sparse")]
pub mod nalgebra_sparse_conv;
pub mod problem;
pub mod quad;

pub use csr::Csr;
pub use error::FunctionalError;
pub use eval::{evaluate, EvalReport, FunctionalSpec, FUNCTIONAL_NAMES};
pub use hex::{
    energy_variants, face_coplanarity_cos, face_planarity_max_cos, hex_tets, EnergyVariants,
    HexFunctional, HexTopology, Scaling3, Tet, HEX_QUAD_FACES,
};
pub use kernel::{
    inv_k, phi_omega, phi_regularized, recommended_alpha_hat, s_function, Area, AreaOrthogonality,
    CastilloArea, CornerLanes, GenericArea, HOmega, IvanenkoConvex, KArea, KSmoothness, KernelExpr,
    LaneGrad, LanePartials, Leaf, Length, Order, Orthogonality, Partials, RegularizedInverseArea,
    RegularizedSmoothness, SArgument, SOmegaEps, Smoothness, SpacingWeights, Terms, TriKernel,
    TriScalars, WeightedLength, A4P,
};
#[cfg(feature = "nalgebra-sparse")]
pub use nalgebra_sparse_conv::CsrConversionError;
pub use problem::{
    prelude, Cost, ElementMeasures, Gradient, Hessian, LocalModel, PointwiseModel, Problem,
    Variables, WithHessian, WithMeasures,
};
pub use quad::{AlphaSummary, QuadFunctional, QuadTopology};
