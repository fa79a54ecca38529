//! The adaptive kernels: `k`-smoothness, `k`-area and Ivanenko's convex kernel, with the
//! check and recommended value of their `α̂`.

use super::{check_finite, check_pos, inv_k, n_times_phi, of_alpha, zero, SP_ALPHA, SP_L_PHI};
use crate::error::FunctionalError;
use crate::kernel::{Order, Partials, TriKernel, TriScalars};

fn check_alpha_hat(k: f64, alpha_hat: Option<f64>) -> Result<(), FunctionalError> {
    check_finite("k", k)?;
    if let Some(ah) = alpha_hat {
        if !(ah.is_finite() && ah > -k) {
            return Err(FunctionalError::InvalidParameter {
                name: "alpha_hat",
                value: ah,
                reason: format!("the matching point must satisfy α̂ > −k = {}", -k),
            });
        }
    }
    Ok(())
}

/// The matching point of the k-functionals' quadratic continuation used here:
/// `α̂ = −k + 0.015·(α₋ + k)`, 1.5 % of the gap between the pole `−k` and the current minimum `α₋`
/// (needs `α₋ > −k`). [González Flores, (4.42)] prints `α̂ = −k + 0.015·α₋`, applied when
/// `α̂ < 0.15·α₋`, which puts `α̂` left of the pole when `α₋ < 0`.
pub fn recommended_alpha_hat(k: f64, alpha_minus: f64) -> f64 {
    -k + 0.015 * (alpha_minus + k)
}

/// k-Smoothness ([González Flores, (4.37)–(4.39)]): `(l + 2k)/(k + α)` on `α > −k`, with the
/// optional C² quadratic continuation below `α̂` (4.40–4.41; the continuation multiplies `l + 2k`
/// by the Taylor polynomial of `1/(k+α)` at `α̂`, so its constants are per triangle). Without `α̂`
/// the value is `+∞` for `α ≤ −k` (the barrier of Prop 4.1).
#[derive(Debug, Clone, Copy)]
pub struct KSmoothness {
    k: f64,
    alpha_hat: Option<f64>,
}
impl KSmoothness {
    /// `k` finite; `α̂ > −k` if given.
    pub fn new(k: f64, alpha_hat: Option<f64>) -> Result<Self, FunctionalError> {
        check_alpha_hat(k, alpha_hat)?;
        Ok(Self { k, alpha_hat })
    }
    /// The parameter `k`.
    pub fn k(&self) -> f64 {
        self.k
    }
}
impl TriKernel for KSmoothness {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_L_PHI
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        n_times_phi(
            1.0,
            1.0,
            2.0 * self.k,
            inv_k(self.k, self.alpha_hat, s.alpha),
            s,
            order,
        )
    }
}

/// k-Area ([González Flores, (4.23)–(4.24)]): `1/(k + α)`, with the optional C² continuation below
/// `α̂` (4.43).
#[derive(Debug, Clone, Copy)]
pub struct KArea {
    k: f64,
    alpha_hat: Option<f64>,
}
impl KArea {
    /// `k` finite; `α̂ > −k` if given.
    pub fn new(k: f64, alpha_hat: Option<f64>) -> Result<Self, FunctionalError> {
        check_alpha_hat(k, alpha_hat)?;
        Ok(Self { k, alpha_hat })
    }
    /// The parameter `k`.
    pub fn k(&self) -> f64 {
        self.k
    }
}
impl TriKernel for KArea {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_ALPHA
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        of_alpha(inv_k(self.k, self.alpha_hat, s.alpha), order)
    }
}

/// Ivanenko's functional for a convex initial mesh: `((ε − α)₊)²` per corner triangle, with
/// `(t)₊ = max(0, t)` and `ε > 0`.
///
/// Source: [González Flores, (2.50)], after S. A. Ivanenko's convex-mesh functional
/// `I_{I0} = Σ_{i,j} Σ_{k=1..4} ((ε − J(Δ_ij^{(k)}))₊)²`. Here `J(Δ)` is the triangle Jacobian
/// in this crate's convention, `α = det(a, b)` (the doubled signed area). The thesis prints the
/// term as `(ε − J(Δ)₊)²`; the reading used here puts the positive part around the whole
/// difference, which is the only one that is zero exactly when every `α ≥ ε` (so a zero value
/// certifies an ε-convex mesh, and every cell is convex).
///
/// Derivatives in `α`: `f′ = −2(ε − α)₊`, `f″ = 2` for `α < ε` and `0` above. The function is
/// C¹ and piecewise quadratic; `f″` jumps at `α = ε`, where the Hessian returned is the one of
/// the side `α ≥ ε` (zero). It is finite on every mesh, folded or not, so it needs no
/// regularization. It has no ideal value (it is 0 on every ε-convex mesh), so
/// [`KernelExpr::normalized`](crate::kernel::KernelExpr::normalized) refuses it; scale it by hand if it is combined with another kernel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IvanenkoConvex {
    eps: f64,
}
impl IvanenkoConvex {
    /// `ε` finite and `> 0` (absolute, in units of `α`; e.g. `0.01·ᾱ`).
    pub fn new(eps: f64) -> Result<Self, FunctionalError> {
        Ok(Self {
            eps: check_pos("eps", eps)?,
        })
    }
    /// `ε = eps_rel·ᾱ` for the mean `ᾱ > 0` of the mesh.
    pub fn relative(eps_rel: f64, alpha_bar: f64) -> Result<Self, FunctionalError> {
        let ab = check_pos("alpha_bar", alpha_bar)?;
        Self::new(check_pos("eps_rel", eps_rel)? * ab)
    }
    /// The threshold `ε`.
    pub fn eps(&self) -> f64 {
        self.eps
    }
}
impl TriKernel for IvanenkoConvex {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_ALPHA
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let d = self.eps - s.alpha;
        if d > 0.0 {
            of_alpha([d * d, -2.0 * d, 2.0], order)
        } else {
            zero()
        }
    }
}
