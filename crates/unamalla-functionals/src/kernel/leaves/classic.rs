//! The classic kernels: length, weighted length, area, Castillo's area, `A4P`, orthogonality,
//! area–orthogonality, smoothness (plain, spacing-weighted and regularized), the regularized
//! inverse area and the generic area kernel.

use std::sync::Arc;

#[cfg(doc)]
use super::HOmega;
use super::{
    check_finite, check_pos, leg_weights, n_times_phi, of_alpha, phi_regularized, zero, SP_ALPHA,
    SP_L_PHI, SP_NONE,
};
use crate::error::FunctionalError;
use crate::kernel::{
    sparsity, CornerLanes, LaneGrad, LanePartials, Order, Partials, Terms, TriKernel, TriScalars,
    DIAGONAL, S_LA, S_LB, S_O,
};

/// Length `F_L`: `l = |a|² + |b|²` ([Méndez 2023, Table 6.2]; [González Flores, (1.10)]).
#[derive(Debug, Clone, Copy, Default)]
pub struct Length;
impl TriKernel for Length {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_NONE
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        n_times_phi(1.0, 1.0, 0.0, [1.0, 0.0, 0.0], s, order)
    }
}

/// Weighted length ([González Flores, (1.11)], after Ojeda): `2(ω|e_ξ|² + (1−ω)|e_η|²)` per corner
/// triangle, `0 ≤ ω ≤ 1`; `ω = ½` gives [`Length`]. (The factor 2 is ours, so that ω = ½ reproduces
/// `l`.)
#[derive(Debug, Clone, Copy)]
pub struct WeightedLength {
    omega: f64,
}
impl WeightedLength {
    /// `ω ∈ [0, 1]` is the weight of the ξ-lines.
    pub fn new(omega: f64) -> Result<Self, FunctionalError> {
        if !(0.0..=1.0).contains(&omega) {
            return Err(FunctionalError::InvalidParameter {
                name: "omega",
                value: omega,
                reason: "the weighted length needs 0 ≤ ω ≤ 1".into(),
            });
        }
        Ok(Self { omega })
    }
}
impl TriKernel for WeightedLength {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_NONE
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let (wa, wb) = leg_weights(s.corner, 2.0 * self.omega, 2.0 * (1.0 - self.omega));
        n_times_phi(wa, wb, 0.0, [1.0, 0.0, 0.0], s, order)
    }
}

/// Area / t-Area (Barrera–Pérez, [González Flores, (3.33)]): `α²`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Area;
impl TriKernel for Area {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_ALPHA
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        of_alpha([s.alpha * s.alpha, 2.0 * s.alpha, 2.0], order)
    }
}

/// Castillo cell area ([González Flores, (3.30)–(3.31)]): `Σ_cells A²`, `A = ½ det(v₂−v₀, v₃−v₁)`
/// the signed cell area; evaluated on the diagonal leg pair as `α_d²/4`.
#[derive(Debug, Clone, Copy, Default)]
pub struct CastilloArea;
impl TriKernel for CastilloArea {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_ALPHA
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        if s.corner != DIAGONAL {
            return zero();
        }
        of_alpha([0.25 * s.alpha * s.alpha, 0.5 * s.alpha, 0.5], order)
    }
    fn terms(&self) -> Terms {
        Terms {
            corners: false,
            diagonal: true,
        }
    }
}

/// A4P (Tinoco, [González Flores, (3.70)]): `(α − ᾱ)⁴`.
#[derive(Debug, Clone, Copy)]
pub struct A4P {
    alpha_bar: f64,
}
impl A4P {
    /// `ᾱ` is the mean α of the mesh (see [`crate::QuadTopology::alpha_bar`]).
    pub fn new(alpha_bar: f64) -> Result<Self, FunctionalError> {
        Ok(Self {
            alpha_bar: check_finite("alpha_bar", alpha_bar)?,
        })
    }
}
impl TriKernel for A4P {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_ALPHA
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let d = s.alpha - self.alpha_bar;
        let d2 = d * d;
        of_alpha([d2 * d2, 4.0 * d2 * d, 12.0 * d2], order)
    }
}

/// Orthogonality `F_O`: `o² = (a·b)²` with the apex at the corner ([Méndez 2023, Table 6.2];
/// [Abelló et al., §2.2] prints `o` with its apex at the end of a leg, which is not 0 on a
/// square).
#[derive(Debug, Clone, Copy, Default)]
pub struct Orthogonality;
impl TriKernel for Orthogonality {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        sparsity(&[(S_O, S_O)])
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let mut p = Partials {
            v: s.o * s.o,
            ..Default::default()
        };
        if order != Order::Value {
            p.g[S_O] = 2.0 * s.o;
        }
        if order == Order::Hessian {
            p.h[S_O][S_O] = 2.0;
        }
        p
    }
}

/// Area-orthogonality `F_AO`: `½(α² + o²)`, evaluated as `½|a|²|b|²` — equal by Lagrange's
/// identity with the apex at the **corner** (the `½‖r−p‖²‖q−p‖²` printed in
/// [Méndez 2023, Table 6.2] has the wrong apex).
#[derive(Debug, Clone, Copy, Default)]
pub struct AreaOrthogonality;
impl TriKernel for AreaOrthogonality {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        sparsity(&[(S_LA, S_LB)])
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let mut p = Partials {
            v: 0.5 * s.la * s.lb,
            ..Default::default()
        };
        if order != Order::Value {
            p.g[S_LA] = 0.5 * s.lb;
            p.g[S_LB] = 0.5 * s.la;
        }
        if order == Order::Hessian {
            p.h[S_LA][S_LB] = 0.5;
            p.h[S_LB][S_LA] = 0.5;
        }
        p
    }
    #[inline(always)]
    fn corners_value(&self, s: &CornerLanes) -> [f64; 4] {
        let mut v = [0.0; 4];
        for q in 0..4 {
            v[q] = 0.5 * s.la[q] * s.lb[q];
        }
        v
    }
    #[inline(always)]
    fn corners_value_grad(&self, s: &CornerLanes) -> LaneGrad {
        let mut p = LaneGrad::default();
        for q in 0..4 {
            p.v[q] = 0.5 * s.la[q] * s.lb[q];
            p.g[S_LA][q] = 0.5 * s.lb[q];
            p.g[S_LB][q] = 0.5 * s.la[q];
        }
        p
    }
    #[inline(always)]
    fn corners_hessian(&self, s: &CornerLanes) -> LanePartials {
        let g = self.corners_value_grad(s);
        let mut p = LanePartials {
            v: g.v,
            g: g.g,
            ..Default::default()
        };
        p.h[S_LA][S_LB] = [0.5; 4];
        p.h[S_LB][S_LA] = [0.5; 4];
        p
    }
}

/// Per-cell logical spacing weights for Winslow on a non-uniform logical grid
/// ([González Flores, (2.78)–(2.93)]): cell `c` has `ρ_c = Δη_c/Δξ_c`, and the corner term becomes
/// `(ρ|e_ξ|² + ρ⁻¹|e_η|²)/α`.
#[derive(Debug, Clone)]
pub struct SpacingWeights {
    rho: Arc<[f64]>,
}
impl SpacingWeights {
    /// From per-cell ratios `ρ_c = Δη_c/Δξ_c > 0` (one per cell, in cell order).
    pub fn from_ratios(rho: Vec<f64>) -> Result<Self, FunctionalError> {
        for &r in &rho {
            check_pos("rho", r)?;
        }
        Ok(Self { rho: rho.into() })
    }
    /// For an `m × n` structured grid (cells numbered `j·(m−1)+i`) whose logical partitions are
    /// `xi` (`m` increasing values) and `eta` (`n` increasing values), e.g. `g_b(i/(m−1))`.
    pub fn structured(xi: &[f64], eta: &[f64]) -> Result<Self, FunctionalError> {
        if xi.len() < 2 || eta.len() < 2 {
            return Err(FunctionalError::UnsupportedSize(
                "logical partitions need at least 2 values".into(),
            ));
        }
        let mut rho = Vec::with_capacity((xi.len() - 1) * (eta.len() - 1));
        for j in 0..eta.len() - 1 {
            for i in 0..xi.len() - 1 {
                rho.push((eta[j + 1] - eta[j]) / (xi[i + 1] - xi[i]));
            }
        }
        Self::from_ratios(rho)
    }
    /// Number of cells covered.
    pub fn len(&self) -> usize {
        self.rho.len()
    }
    /// `true` if there are no cells.
    pub fn is_empty(&self) -> bool {
        self.rho.is_empty()
    }
    #[inline(always)]
    fn legs(&self, s: &TriScalars) -> (f64, f64) {
        let r = self.rho.get(s.cell).copied().unwrap_or(1.0);
        leg_weights(s.corner, r, 1.0 / r)
    }
}

/// Winslow / smoothness `F_S`: `l/α` per corner triangle ([González Flores, (2.55)];
/// [Méndez 2023, Table 6.2]), optionally with the non-uniform logical spacing weights
/// ([`SpacingWeights`]). Defined for `α ≠ 0` (negative on folded triangles); use
/// [`RegularizedSmoothness`] or [`HOmega`] on folded meshes.
#[derive(Debug, Clone, Default)]
pub struct Smoothness {
    weights: Option<SpacingWeights>,
}
impl Smoothness {
    /// Uniform logical spacing.
    pub fn new() -> Self {
        Self { weights: None }
    }
    /// With per-cell spacing weights.
    pub fn with_spacing(weights: SpacingWeights) -> Self {
        Self {
            weights: Some(weights),
        }
    }
}
impl TriKernel for Smoothness {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_L_PHI
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let (wa, wb) = self.weights.as_ref().map_or((1.0, 1.0), |w| w.legs(s));
        let r = 1.0 / s.alpha;
        n_times_phi(wa, wb, 0.0, [r, -r * r, 2.0 * r * r * r], s, order)
    }
}

/// Regularized smoothness (Barrera, [González Flores, §2.4, (2.64)]): `l·φ̃(α)` with
/// [`phi_regularized`], pole moved to `−ε_c`; default `ε_c = ᾱ/2` (2.65).
#[derive(Debug, Clone)]
pub struct RegularizedSmoothness {
    eps_c: f64,
    weights: Option<SpacingWeights>,
}
impl RegularizedSmoothness {
    /// `ε_c > 0`.
    pub fn new(eps_c: f64) -> Result<Self, FunctionalError> {
        Ok(Self {
            eps_c: check_pos("eps_c", eps_c)?,
            weights: None,
        })
    }
    /// The default `ε_c = ᾱ/2`.
    pub fn with_alpha_bar(alpha_bar: f64) -> Result<Self, FunctionalError> {
        Self::new(0.5 * alpha_bar)
    }
    /// Adds non-uniform spacing weights.
    pub fn spacing(mut self, weights: SpacingWeights) -> Self {
        self.weights = Some(weights);
        self
    }
}
impl TriKernel for RegularizedSmoothness {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_L_PHI
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let (wa, wb) = self.weights.as_ref().map_or((1.0, 1.0), |w| w.legs(s));
        n_times_phi(wa, wb, 0.0, phi_regularized(self.eps_c, s.alpha), s, order)
    }
}

/// Regularized inverse area ([González Flores, (3.71)], regularized "like smoothness"): `φ̃(α)`
/// with [`phi_regularized`].
#[derive(Debug, Clone, Copy)]
pub struct RegularizedInverseArea {
    eps_c: f64,
}
impl RegularizedInverseArea {
    /// `ε_c > 0` (default choice `ᾱ/2`).
    pub fn new(eps_c: f64) -> Result<Self, FunctionalError> {
        Ok(Self {
            eps_c: check_pos("eps_c", eps_c)?,
        })
    }
}
impl TriKernel for RegularizedInverseArea {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_ALPHA
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        of_alpha(phi_regularized(self.eps_c, s.alpha), order)
    }
}

/// The general discrete area functional `Σ f(α)` ([González Flores, (3.54)–(3.60)]) for any user
/// function returning `[f(α), f′(α), f″(α)]`.
#[derive(Clone)]
pub struct GenericArea<F> {
    f: F,
}
impl<F: Fn(f64) -> [f64; 3] + Send + Sync> GenericArea<F> {
    /// Wraps `f: α ↦ [f, f′, f″]`.
    pub fn new(f: F) -> Self {
        Self { f }
    }
}
impl<F: Fn(f64) -> [f64; 3] + Send + Sync> TriKernel for GenericArea<F> {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_ALPHA
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        of_alpha((self.f)(s.alpha), order)
    }
}
impl<F> std::fmt::Debug for GenericArea<F> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("GenericArea(<fn>)")
    }
}
