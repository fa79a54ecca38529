//! The leaf kernels: the per-term functions `f(α, la, lb, o)` of the 2D functionals (module
//! docs of [`crate::kernel`] for the scalars), the scalar functions they are built from
//! ([`phi_omega`], [`phi_regularized`], [`inv_k`], [`s_function`]) and their parameters.
//! Every leaf is a variant of [`Leaf`](super::Leaf), and any of them converts into a
//! [`KernelExpr`](super::KernelExpr).
//!
//! (About 830 lines: the fifteen leaf kernels with their parameter checks, formulas and
//! derivative code, in the order of the table of the crate docs; they share the building blocks
//! at the top.)

use std::sync::Arc;

use super::{
    sparsity, CornerLanes, LaneGrad, LanePartials, Order, Partials, Terms, TriKernel, TriScalars,
    DIAGONAL, S_ALPHA, S_LA, S_LB, S_O,
};
use crate::error::FunctionalError;

pub(crate) const SP_NONE: [[bool; 4]; 4] = [[false; 4]; 4];
const SP_ALPHA: [[bool; 4]; 4] = sparsity(&[(S_ALPHA, S_ALPHA)]);
const SP_L_PHI: [[bool; 4]; 4] = sparsity(&[(S_ALPHA, S_ALPHA), (S_ALPHA, S_LA), (S_ALPHA, S_LB)]);

/// Lane form of `n_times_phi` with `wa = wb = 1`, `c = 0` (`f = (la + lb)·φ(α)`), for
/// `φ = [φ, φ′, φ″]` given per lane; the same operations per lane as the scalar form.
#[inline(always)]
fn l_times_phi_lanes(s: &CornerLanes, phi: &[[f64; 4]; 3], hessian: bool) -> LanePartials {
    let mut p = LanePartials::default();
    for q in 0..4 {
        let n = s.la[q] + s.lb[q];
        p.v[q] = n * phi[0][q];
        p.g[S_ALPHA][q] = n * phi[1][q];
        p.g[S_LA][q] = phi[0][q];
        p.g[S_LB][q] = phi[0][q];
        if hessian {
            p.h[S_ALPHA][S_ALPHA][q] = n * phi[2][q];
            p.h[S_ALPHA][S_LA][q] = phi[1][q];
            p.h[S_LA][S_ALPHA][q] = phi[1][q];
            p.h[S_ALPHA][S_LB][q] = phi[1][q];
            p.h[S_LB][S_ALPHA][q] = phi[1][q];
        }
    }
    p
}

#[inline(always)]
fn lane_grad(p: LanePartials) -> LaneGrad {
    LaneGrad { v: p.v, g: p.g }
}

/// `φ_ω` on four lanes (the same branch-free selection as [`phi_omega`]).
#[inline(always)]
fn phi_omega_lanes(omega: f64, a: &[f64; 4], second: bool) -> [[f64; 4]; 3] {
    let w2 = 1.0 / (omega * omega);
    let mut out = [[0.0; 4]; 3];
    for q in 0..4 {
        let r = 1.0 / a[q];
        let hi = a[q] >= omega;
        out[0][q] = if hi { r } else { (2.0 * omega - a[q]) * w2 };
        out[1][q] = if hi { -r * r } else { -w2 };
        if second {
            out[2][q] = if hi { 2.0 * r * r * r } else { 0.0 };
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// scalar functions of one variable: [f, f', f'']

/// `φ_ω` of [Méndez 2023, §6.4.2] in the C¹ form of [Cortés Aguirre 2012, (3.26)]: `1/α` for
/// `α ≥ ω`, `(2ω − α)/ω²` (the tangent of `1/α` at `ω`) below. (Méndez prints `2(ω − α)/ω²`
/// below `ω`, which jumps from 0 to `1/ω` at `α = ω`.) Returns `[φ, φ′, φ″]`.
#[inline(always)]
pub fn phi_omega(omega: f64, a: f64) -> [f64; 3] {
    // both branches are computed and selected (no data-dependent jump in the hot loop)
    let r = 1.0 / a;
    let w2 = 1.0 / (omega * omega);
    let hi = a >= omega;
    [
        if hi { r } else { (2.0 * omega - a) * w2 },
        if hi { -r * r } else { -w2 },
        if hi { 2.0 * r * r * r } else { 0.0 },
    ]
}

/// Barrera's regularized `1/α` ([González Flores, §2.4, (2.61)–(2.64)]), with `α = det(a, b)`
/// (twice the area): `1/α` for `α ≥ ε_c`, `4ε_c/(α + ε_c)²` for `−ε_c < α < ε_c` (C¹ at `ε_c`,
/// pole moved to `−ε_c`), `+∞` (derivatives NaN) for `α ≤ −ε_c`. (2.64) is printed with `α` the
/// area and the switch at `α ≥ ε_c`; the function is C¹ only with the switch on the doubled area,
/// as here. Returns `[φ, φ′, φ″]`.
#[inline(always)]
pub fn phi_regularized(eps_c: f64, a: f64) -> [f64; 3] {
    if a >= eps_c {
        let r = 1.0 / a;
        [r, -r * r, 2.0 * r * r * r]
    } else if a > -eps_c {
        let r = 1.0 / (a + eps_c);
        let r2 = r * r;
        [
            4.0 * eps_c * r2,
            -8.0 * eps_c * r2 * r,
            24.0 * eps_c * r2 * r2,
        ]
    } else {
        [f64::INFINITY, f64::NAN, f64::NAN]
    }
}

/// `1/(k + α)` with the optional C² quadratic continuation below the matching point `α̂`
/// ([González Flores, §4.6.3, (4.40)–(4.43)]; for the choice of `α̂` see
/// [`recommended_alpha_hat`]): for `α < α̂` it is the second-order Taylor
/// polynomial at `α̂`, `c + b(α−α̂) + a(α−α̂)²` with `c = 1/(k+α̂)`, `b = −1/(k+α̂)²`,
/// `a = 1/(k+α̂)³`. Without `α̂` it is `+∞` (derivatives NaN) for `k + α ≤ 0`.
#[inline(always)]
pub fn inv_k(k: f64, alpha_hat: Option<f64>, a: f64) -> [f64; 3] {
    if let Some(ah) = alpha_hat {
        if a < ah {
            let r = 1.0 / (k + ah);
            let d = a - ah;
            return [
                r + d * (-r * r + d * r * r * r),
                -r * r + 2.0 * d * r * r * r,
                2.0 * r * r * r,
            ];
        }
    }
    let t = k + a;
    if t <= 0.0 {
        return [f64::INFINITY, f64::NAN, f64::NAN];
    }
    let r = 1.0 / t;
    [r, -r * r, 2.0 * r * r * r]
}

/// The function (56) of [Abelló et al., §2.2] (`φ` of [Méndez 2023, §6.4.2]): `1/t` for `t ≥ 1`,
/// `(t−1)(t−2)+1` below (C² at 1, finite everywhere). Returns `[f, f′, f″]`.
#[inline(always)]
pub fn s_function(t: f64) -> [f64; 3] {
    if t >= 1.0 {
        let r = 1.0 / t;
        [r, -r * r, 2.0 * r * r * r]
    } else {
        [(t - 1.0) * (t - 2.0) + 1.0, 2.0 * t - 3.0, 2.0]
    }
}

// ---------------------------------------------------------------------------------------------
// building blocks

/// `f = g(α)` with `[g, g', g'']`.
#[inline(always)]
fn of_alpha(g: [f64; 3], order: Order) -> Partials {
    let mut p = Partials {
        v: g[0],
        ..Default::default()
    };
    if order != Order::Value {
        p.g[S_ALPHA] = g[1];
    }
    if order == Order::Hessian {
        p.h[S_ALPHA][S_ALPHA] = g[2];
    }
    p
}

/// `f = (wa·la + wb·lb + c)·φ(α)` with `φ = [φ, φ', φ'']`.
#[inline(always)]
fn n_times_phi(wa: f64, wb: f64, c: f64, phi: [f64; 3], s: &TriScalars, order: Order) -> Partials {
    let n = wa * s.la + wb * s.lb + c;
    let mut p = Partials {
        v: n * phi[0],
        ..Default::default()
    };
    if order != Order::Value {
        p.g[S_ALPHA] = n * phi[1];
        p.g[S_LA] = wa * phi[0];
        p.g[S_LB] = wb * phi[0];
    }
    if order == Order::Hessian {
        p.h[S_ALPHA][S_ALPHA] = n * phi[2];
        p.h[S_ALPHA][S_LA] = wa * phi[1];
        p.h[S_LA][S_ALPHA] = wa * phi[1];
        p.h[S_ALPHA][S_LB] = wb * phi[1];
        p.h[S_LB][S_ALPHA] = wb * phi[1];
    }
    p
}

#[inline(always)]
fn zero() -> Partials {
    Partials::default()
}

pub(crate) fn check_pos(name: &'static str, v: f64) -> Result<f64, FunctionalError> {
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

pub(crate) fn check_finite(name: &'static str, v: f64) -> Result<f64, FunctionalError> {
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

/// Per-cell ξ/η weights `(w_ξ, w_η)` of the corner at `corner` mapped to the legs `(a, b)`.
#[inline(always)]
fn leg_weights(corner: u8, wxi: f64, weta: f64) -> (f64, f64) {
    if corner & 1 == 0 {
        (wxi, weta)
    } else {
        (weta, wxi)
    }
}

// ---------------------------------------------------------------------------------------------
// classic kernels

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

// ---------------------------------------------------------------------------------------------
// adaptive kernels

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
/// [`KernelExpr::normalized`](super::KernelExpr::normalized) refuses it; scale it by hand if it is combined with another kernel.
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

// ---------------------------------------------------------------------------------------------
// convexity-guaranteeing kernels

/// How the argument of `f` in `S_{ω,ε}` is formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SArgument {
    /// `t = ω(α/ᾱ − ε)` — the scale-invariant reading of [Abelló et al., (55)] (as printed, the
    /// threshold shrinks as ω grows, which does not fit the paper's "ω large ⇒ ε-convex"); equals
    /// the `ω(α − ε)` of [Méndez 2023, §6.4.2] after scaling so that `ᾱ = 1`.
    #[default]
    ScaleInvariant,
    /// `t = ωα − εᾱ`, [Abelló et al., (55)] as printed.
    Literal,
}

/// `S_{ω,ε} = Σ f(t(α))` with `f` of (56) ([`s_function`]) (Barrera et al., as given in
/// [Abelló et al., §2.2] and [Méndez 2023, §6.4.2]). Finite for any mesh.
#[derive(Debug, Clone, Copy)]
pub struct SOmegaEps {
    omega: f64,
    eps: f64,
    alpha_bar: f64,
    arg: SArgument,
}
impl SOmegaEps {
    /// `ω > 0`, `ε` finite, `ᾱ > 0` (mean α of the mesh).
    pub fn new(
        omega: f64,
        eps: f64,
        alpha_bar: f64,
        arg: SArgument,
    ) -> Result<Self, FunctionalError> {
        Ok(Self {
            omega: check_pos("omega", omega)?,
            eps: check_finite("eps", eps)?,
            alpha_bar: check_pos("alpha_bar", alpha_bar)?,
            arg,
        })
    }
}
impl TriKernel for SOmegaEps {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_ALPHA
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let (t, dt) = match self.arg {
            SArgument::ScaleInvariant => {
                let d = self.omega / self.alpha_bar;
                (d * s.alpha - self.omega * self.eps, d)
            }
            SArgument::Literal => (self.omega * s.alpha - self.eps * self.alpha_bar, self.omega),
        };
        let f = s_function(t);
        of_alpha([f[0], f[1] * dt, f[2] * dt * dt], order)
    }
}

/// Quasi-harmonic `H_ω` ([Méndez 2023, §6.4.2] with the C¹ `φ_ω`; [Cortés Aguirre 2012, (1.42)],
/// printed `Σλ/φ_ω`, read as the product `Σλ·φ_ω`):
/// `l·φ_ω(α)` with [`phi_omega`]. Finite for any mesh; equals Winslow's `l/α` where `α ≥ ω`.
#[derive(Debug, Clone, Copy)]
pub struct HOmega {
    omega: f64,
}
impl HOmega {
    /// `ω > 0`.
    pub fn new(omega: f64) -> Result<Self, FunctionalError> {
        Ok(Self {
            omega: check_pos("omega", omega)?,
        })
    }
    /// The parameter `ω`.
    pub fn omega(&self) -> f64 {
        self.omega
    }
}
impl TriKernel for HOmega {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_L_PHI
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        n_times_phi(1.0, 1.0, 0.0, phi_omega(self.omega, s.alpha), s, order)
    }
    #[inline(always)]
    fn corners_value(&self, s: &CornerLanes) -> [f64; 4] {
        let phi = phi_omega_lanes(self.omega, &s.alpha, false);
        let mut v = [0.0; 4];
        for q in 0..4 {
            v[q] = (s.la[q] + s.lb[q]) * phi[0][q];
        }
        v
    }
    #[inline(always)]
    fn corners_value_grad(&self, s: &CornerLanes) -> LaneGrad {
        lane_grad(l_times_phi_lanes(
            s,
            &phi_omega_lanes(self.omega, &s.alpha, false),
            false,
        ))
    }
    #[inline(always)]
    fn corners_hessian(&self, s: &CornerLanes) -> LanePartials {
        l_times_phi_lanes(s, &phi_omega_lanes(self.omega, &s.alpha, true), true)
    }
}
