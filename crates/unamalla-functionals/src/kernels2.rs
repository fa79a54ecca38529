//! Per-triangle kernels of the 2D functionals.
//!
//! Every 2D functional of this crate is a sum of terms `f(α, |a|², |b|², o)` over **leg pairs**
//! `(a, b)` of the cells:
//!
//! * the four **corner triangles** of a counter-clockwise quad `[v₀, v₁, v₂, v₃]`: at corner `k`
//!   the corner is `P = v_k`, `Q = v_{k+1}`, `R = v_{k−1}` (indices mod 4), `a = Q − P`,
//!   `b = R − P` (seed 000 digest §5.5, Fig 6.12; seed 001 digest §1);
//! * the **diagonal pair** `a = v₂ − v₀`, `b = v₃ − v₁` (only for the Castillo cell area:
//!   `det(a, b) = 2·area(cell)`), tagged with [`DIAGONAL`].
//!
//! with `α = det(a, b)` (doubled signed area), `la = |a|²`, `lb = |b|²` (so `l = la + lb`) and
//! `o = a·b`. A kernel returns the value and the partial derivatives with respect to
//! `s = (α, la, lb, o)` ([`Partials`]); [`crate::quad`] turns them into exact gradients and
//! Hessians in the node coordinates by the chain rule (the formulas are in [`crate::quad`]).
//!
//! For corner `k`, the leg `a` is the cell's ξ-edge when `k` is even and its η-edge when `k` is
//! odd (`v₀→v₁` is the ξ direction of the cell), which is how the weighted length and the
//! non-uniform Winslow weights tell the two families of lines apart.

use std::sync::Arc;

use crate::error::FunctionalError;

/// Index of α in [`Partials`] arrays.
pub const S_ALPHA: usize = 0;
/// Index of `la = |a|²`.
pub const S_LA: usize = 1;
/// Index of `lb = |b|²`.
pub const S_LB: usize = 2;
/// Index of `o = a·b`.
pub const S_O: usize = 3;
/// `corner` tag of the diagonal leg pair of a cell.
pub const DIAGONAL: u8 = 4;

/// The scalar inputs of one term.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriScalars {
    /// `α = det(a, b)`.
    pub alpha: f64,
    /// `|a|²`.
    pub la: f64,
    /// `|b|²`.
    pub lb: f64,
    /// `a·b`.
    pub o: f64,
    /// Cell id.
    pub cell: usize,
    /// Corner `0..4`, or [`DIAGONAL`].
    pub corner: u8,
}

/// How many derivatives a kernel must compute.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Order {
    /// The value only.
    Value,
    /// Value and first partials.
    Gradient,
    /// Value, first and second partials.
    Hessian,
}

/// Value and partial derivatives of a term with respect to `s = (α, la, lb, o)`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Partials {
    /// The value.
    pub v: f64,
    /// `∂f/∂s_i`.
    pub g: [f64; 4],
    /// `∂²f/∂s_i∂s_j` (symmetric).
    pub h: [[f64; 4]; 4],
}

impl Partials {
    /// `self += w·other`.
    #[inline(always)]
    pub fn add_scaled(&mut self, w: f64, o: &Partials, order: Order) {
        self.v += w * o.v;
        if order != Order::Value {
            for i in 0..4 {
                self.g[i] += w * o.g[i];
            }
        }
        if order == Order::Hessian {
            for i in 0..4 {
                for j in 0..4 {
                    self.h[i][j] += w * o.h[i][j];
                }
            }
        }
    }
    /// `self *= w`.
    #[inline(always)]
    pub fn scale(&mut self, w: f64, order: Order) {
        let z = *self;
        *self = Partials::default();
        self.add_scaled(w, &z, order);
    }
}

/// Which leg pairs a kernel uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Terms {
    /// The four corner triangles of each cell.
    pub corners: bool,
    /// The diagonal pair of each cell.
    pub diagonal: bool,
}

impl Terms {
    /// Union of two term sets.
    pub fn or(self, o: Terms) -> Terms {
        Terms {
            corners: self.corners || o.corners,
            diagonal: self.diagonal || o.diagonal,
        }
    }
}

const CORNERS: Terms = Terms {
    corners: true,
    diagonal: false,
};

/// `true` if kernel `k` must be evaluated on the pair described by `s`.
#[inline(always)]
fn wants<K: TriKernel + ?Sized>(k: &K, s: &TriScalars) -> bool {
    let t = k.terms();
    if s.corner == DIAGONAL {
        t.diagonal
    } else {
        t.corners
    }
}

/// A per-term function `f(α, la, lb, o)` (see the module docs).
pub trait TriKernel: Send + Sync {
    /// Value and partials up to `order`. Entries beyond `order` may be left zero. It is called
    /// on corner triangles only if [`terms`](Self::terms)`.corners` and with
    /// `s.corner == DIAGONAL` only if `terms().diagonal` (the evaluator and the combinators
    /// guarantee this).
    fn eval(&self, s: &TriScalars, order: Order) -> Partials;
    /// Which leg pairs this kernel uses (corner triangles by default).
    fn terms(&self) -> Terms {
        CORNERS
    }
    /// Value only (hot path of [`Problem::value`](crate::Problem::value); defaults to
    /// [`eval`](Self::eval) with [`Order::Value`]).
    #[inline(always)]
    fn value(&self, s: &TriScalars) -> f64 {
        self.eval(s, Order::Value).v
    }
    /// Value and first partials (hot path of
    /// [`Problem::value_grad`](crate::Problem::value_grad); defaults to [`eval`](Self::eval)
    /// with [`Order::Gradient`]). Combinators override it so that no second-derivative storage
    /// is touched.
    #[inline(always)]
    fn value_grad(&self, s: &TriScalars) -> (f64, [f64; 4]) {
        let p = self.eval(s, Order::Gradient);
        (p.v, p.g)
    }
}

#[inline(always)]
fn axpy4(acc: &mut (f64, [f64; 4]), w: f64, o: (f64, [f64; 4])) {
    acc.0 += w * o.0;
    for i in 0..4 {
        acc.1[i] += w * o.1[i];
    }
}

impl<T: TriKernel + ?Sized> TriKernel for Arc<T> {
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        (**self).eval(s, order)
    }
    fn terms(&self) -> Terms {
        (**self).terms()
    }
    #[inline(always)]
    fn value(&self, s: &TriScalars) -> f64 {
        (**self).value(s)
    }
    #[inline(always)]
    fn value_grad(&self, s: &TriScalars) -> (f64, [f64; 4]) {
        (**self).value_grad(s)
    }
}

// ---------------------------------------------------------------------------------------------
// scalar functions of one variable: [f, f', f'']

/// `φ_ω` of seed 000 §5.5 with the C¹ correction of erratum 10 (seed 004 (3.26)):
/// `1/α` for `α ≥ ω`, `(2ω − α)/ω²` (the tangent of `1/α` at `ω`) below. Returns `[φ, φ′, φ″]`.
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

/// Barrera's regularized `1/α` (seed 001 digest §2.3 and erratum 2, det convention):
/// `1/α` for `α ≥ ε_c`, `4ε_c/(α + ε_c)²` for `−ε_c < α < ε_c` (C¹ at `ε_c`, pole moved to
/// `−ε_c`), `+∞` (derivatives NaN) for `α ≤ −ε_c`. Returns `[φ, φ′, φ″]`.
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
/// (seed 001 digest §2.5 (4.40–4.43) and erratum 6): for `α < α̂` it is the second-order Taylor
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

/// The function (56) of seed 003 (seed 000 §5.5 `φ`): `1/t` for `t ≥ 1`, `(t−1)(t−2)+1` below
/// (C² at 1, finite everywhere). Returns `[f, f′, f″]`.
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

/// Length `F_L`: `l = |a|² + |b|²` (seed 000 Table 6.2; seed 001 (1.10)).
#[derive(Debug, Clone, Copy, Default)]
pub struct Length;
impl TriKernel for Length {
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        n_times_phi(1.0, 1.0, 0.0, [1.0, 0.0, 0.0], s, order)
    }
}

/// Weighted length (seed 001 (1.11), Ojeda): `2(ω|e_ξ|² + (1−ω)|e_η|²)` per corner triangle,
/// `0 ≤ ω ≤ 1`; `ω = ½` gives [`Length`]. (The factor 2 is ours, so that ω = ½ reproduces `l`.)
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
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let (wa, wb) = leg_weights(s.corner, 2.0 * self.omega, 2.0 * (1.0 - self.omega));
        n_times_phi(wa, wb, 0.0, [1.0, 0.0, 0.0], s, order)
    }
}

/// Area / t-Area (Barrera–Pérez, seed 001 (3.33)): `α²`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Area;
impl TriKernel for Area {
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        of_alpha([s.alpha * s.alpha, 2.0 * s.alpha, 2.0], order)
    }
}

/// Castillo cell area (seed 001 (3.30–3.31)): `Σ_cells A²`, `A = ½ det(v₂−v₀, v₃−v₁)` the signed
/// cell area; evaluated on the diagonal leg pair as `α_d²/4`.
#[derive(Debug, Clone, Copy, Default)]
pub struct CastilloArea;
impl TriKernel for CastilloArea {
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

/// A4P (Tinoco, seed 001 (3.70)): `(α − ᾱ)⁴`.
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
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let d = s.alpha - self.alpha_bar;
        let d2 = d * d;
        of_alpha([d2 * d2, 4.0 * d2 * d, 12.0 * d2], order)
    }
}

/// Orthogonality `F_O`: `o² = (a·b)²` (seed 000 Table 6.2, corner apex per seed 003 erratum 11).
#[derive(Debug, Clone, Copy, Default)]
pub struct Orthogonality;
impl TriKernel for Orthogonality {
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
/// identity with the apex at the **corner** (seed 000 digest §5.5 note and erratum 10: the
/// printed `½‖r−p‖²‖q−p‖²` has the wrong apex).
#[derive(Debug, Clone, Copy, Default)]
pub struct AreaOrthogonality;
impl TriKernel for AreaOrthogonality {
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
}

/// Per-cell logical spacing weights for Winslow on a non-uniform logical grid (seed 001 digest
/// §2.2, (2.78–2.93)): cell `c` has `ρ_c = Δη_c/Δξ_c`, and the corner term becomes
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

/// Winslow / smoothness `F_S`: `l/α` per corner triangle (seed 001 (2.55), seed 000 Table 6.2),
/// optionally with the non-uniform logical spacing weights ([`SpacingWeights`]). Defined for
/// `α ≠ 0` (negative on folded triangles); use [`RegularizedSmoothness`] or [`HOmega`] on
/// folded meshes.
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
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let (wa, wb) = self.weights.as_ref().map_or((1.0, 1.0), |w| w.legs(s));
        let r = 1.0 / s.alpha;
        n_times_phi(wa, wb, 0.0, [r, -r * r, 2.0 * r * r * r], s, order)
    }
}

/// Regularized smoothness (Barrera, seed 001 digest §2.3, erratum 2): `l·φ̃(α)` with
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
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let (wa, wb) = self.weights.as_ref().map_or((1.0, 1.0), |w| w.legs(s));
        n_times_phi(wa, wb, 0.0, phi_regularized(self.eps_c, s.alpha), s, order)
    }
}

/// Regularized inverse area (seed 001 (3.71) regularized "like smoothness"): `φ̃(α)` with
/// [`phi_regularized`].
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
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        of_alpha(phi_regularized(self.eps_c, s.alpha), order)
    }
}

/// The general discrete area functional `Σ f(α)` (seed 001 (3.54–3.60)) for any user function
/// returning `[f(α), f′(α), f″(α)]`.
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

/// The recommended matching point of the k-functionals' quadratic continuation (seed 001
/// digest erratum 6, replacing the inconsistent printed (4.42)): `α̂ = −k + 0.015·(α₋ + k)`,
/// 1.5 % of the gap between the pole `−k` and the current minimum `α₋` (needs `α₋ > −k`).
pub fn recommended_alpha_hat(k: f64, alpha_minus: f64) -> f64 {
    -k + 0.015 * (alpha_minus + k)
}

/// k-Smoothness (seed 001 (4.37–4.39)): `(l + 2k)/(k + α)` on `α > −k`, with the optional C²
/// quadratic continuation below `α̂` (4.40–4.41; the continuation multiplies `l + 2k` by the
/// Taylor polynomial of `1/(k+α)` at `α̂`, so its constants are per triangle). Without `α̂` the
/// value is `+∞` for `α ≤ −k` (the barrier of Prop 4.1).
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

/// k-Area (seed 001 (4.23–4.24)): `1/(k + α)`, with the optional C² continuation below `α̂`
/// (4.43).
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
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        of_alpha(inv_k(self.k, self.alpha_hat, s.alpha), order)
    }
}

// ---------------------------------------------------------------------------------------------
// convexity-guaranteeing kernels

/// How the argument of `f` in `S_{ω,ε}` is formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SArgument {
    /// `t = ω(α/ᾱ − ε)` — the scale-invariant reading recommended by the seed 003 digest
    /// (§5.3 note, erratum 13); equals seed 000's `ω(α − ε)` after scaling so that `ᾱ = 1`.
    #[default]
    ScaleInvariant,
    /// `t = ωα − εᾱ`, eq. (55) of seed 003 as printed.
    Literal,
}

/// `S_{ω,ε} = Σ f(t(α))` with `f` of (56) ([`s_function`]) (Barrera et al.; seed 003 §5.3,
/// seed 000 §5.5). Finite for any mesh.
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

/// Quasi-harmonic `H_ω` (seed 000 §5.5 with erratum 10, seed 004 §1 (1.42) read as a product):
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
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        n_times_phi(1.0, 1.0, 0.0, phi_omega(self.omega, s.alpha), s, order)
    }
}

// ---------------------------------------------------------------------------------------------
// combinators

/// `factor · inner` (normalizations, constant factors).
#[derive(Debug, Clone)]
pub struct Scaled<K> {
    /// The factor.
    pub factor: f64,
    /// The scaled kernel.
    pub inner: K,
}
impl<K: TriKernel> TriKernel for Scaled<K> {
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let mut p = self.inner.eval(s, order);
        p.scale(self.factor, order);
        p
    }
    fn terms(&self) -> Terms {
        self.inner.terms()
    }
    #[inline(always)]
    fn value(&self, s: &TriScalars) -> f64 {
        self.factor * self.inner.value(s)
    }
    #[inline(always)]
    fn value_grad(&self, s: &TriScalars) -> (f64, [f64; 4]) {
        let mut acc = (0.0, [0.0; 4]);
        axpy4(&mut acc, self.factor, self.inner.value_grad(s));
        acc
    }
}

/// `wa·a + wb·b` — e.g. the convex combination `σF₁ + (1−σ)F₂` (seed 001 erratum 7: σ is the
/// weight of the first functional; seed 000 (6.8) is `Sum::convex(1−σ, F_AO, H_ω)`).
#[derive(Debug, Clone)]
pub struct Sum<A, B> {
    /// Weight of `a`.
    pub wa: f64,
    /// First kernel.
    pub a: A,
    /// Weight of `b`.
    pub wb: f64,
    /// Second kernel.
    pub b: B,
}
impl<A: TriKernel, B: TriKernel> Sum<A, B> {
    /// `σ·a + (1−σ)·b`, `0 ≤ σ ≤ 1`.
    pub fn convex(sigma: f64, a: A, b: B) -> Result<Self, FunctionalError> {
        if !(0.0..=1.0).contains(&sigma) {
            return Err(FunctionalError::InvalidParameter {
                name: "sigma",
                value: sigma,
                reason: "a convex combination needs 0 ≤ σ ≤ 1".into(),
            });
        }
        Ok(Self {
            wa: sigma,
            a,
            wb: 1.0 - sigma,
            b,
        })
    }
}
impl<A: TriKernel, B: TriKernel> TriKernel for Sum<A, B> {
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let mut p = Partials::default();
        if wants(&self.a, s) {
            let q = self.a.eval(s, order);
            p.add_scaled(self.wa, &q, order);
        }
        if wants(&self.b, s) {
            let q = self.b.eval(s, order);
            p.add_scaled(self.wb, &q, order);
        }
        p
    }
    fn terms(&self) -> Terms {
        self.a.terms().or(self.b.terms())
    }
    #[inline(always)]
    fn value(&self, s: &TriScalars) -> f64 {
        let mut v = 0.0;
        if wants(&self.a, s) {
            v += self.wa * self.a.value(s);
        }
        if wants(&self.b, s) {
            v += self.wb * self.b.value(s);
        }
        v
    }
    #[inline(always)]
    fn value_grad(&self, s: &TriScalars) -> (f64, [f64; 4]) {
        let mut acc = (0.0, [0.0; 4]);
        if wants(&self.a, s) {
            axpy4(&mut acc, self.wa, self.a.value_grad(s));
        }
        if wants(&self.b, s) {
            axpy4(&mut acc, self.wb, self.b.value_grad(s));
        }
        acc
    }
}

/// `w_c · inner` with one weight per cell (the boundary density `w` of seed 000 (6.9)).
#[derive(Debug, Clone)]
pub struct CellWeighted<K> {
    weights: Arc<[f64]>,
    inner: K,
}
impl<K: TriKernel> CellWeighted<K> {
    /// One finite weight per cell, in cell order (see
    /// [`QuadTopology::boundary_density`](crate::QuadTopology::boundary_density)).
    pub fn new(weights: Vec<f64>, inner: K) -> Result<Self, FunctionalError> {
        for &w in &weights {
            check_finite("weight", w)?;
        }
        Ok(Self {
            weights: weights.into(),
            inner,
        })
    }
    /// Number of weights.
    pub fn len(&self) -> usize {
        self.weights.len()
    }
    /// `true` if there are no weights.
    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }
}
impl<K: TriKernel> TriKernel for CellWeighted<K> {
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let w = self.weights.get(s.cell).copied().unwrap_or(1.0);
        let mut p = self.inner.eval(s, order);
        p.scale(w, order);
        p
    }
    fn terms(&self) -> Terms {
        self.inner.terms()
    }
    #[inline(always)]
    fn value(&self, s: &TriScalars) -> f64 {
        self.weights.get(s.cell).copied().unwrap_or(1.0) * self.inner.value(s)
    }
    #[inline(always)]
    fn value_grad(&self, s: &TriScalars) -> (f64, [f64; 4]) {
        let mut acc = (0.0, [0.0; 4]);
        let w = self.weights.get(s.cell).copied().unwrap_or(1.0);
        axpy4(&mut acc, w, self.inner.value_grad(s));
        acc
    }
}

/// A run-time assembled kernel: any of the kernels above, and weighted sums of them (used by the
/// name-based entry point and by callers that choose functionals at run time; the generic
/// [`Sum`] is faster for fixed combinations).
#[derive(Clone)]
pub enum Kernel2 {
    /// [`Length`].
    Length,
    /// [`WeightedLength`].
    WeightedLength(WeightedLength),
    /// [`Area`].
    Area,
    /// [`CastilloArea`].
    CastilloArea,
    /// [`A4P`].
    A4P(A4P),
    /// [`Orthogonality`].
    Orthogonality,
    /// [`AreaOrthogonality`].
    AreaOrthogonality,
    /// [`Smoothness`].
    Smoothness(Smoothness),
    /// [`RegularizedSmoothness`].
    RegularizedSmoothness(RegularizedSmoothness),
    /// [`RegularizedInverseArea`].
    RegularizedInverseArea(RegularizedInverseArea),
    /// [`KSmoothness`].
    KSmoothness(KSmoothness),
    /// [`KArea`].
    KArea(KArea),
    /// [`SOmegaEps`].
    SOmegaEps(SOmegaEps),
    /// [`HOmega`].
    HOmega(HOmega),
    /// Any user kernel, e.g. a [`GenericArea`].
    Custom(Arc<dyn TriKernel>),
    /// `Σ wᵢ Kᵢ` (convex combinations of two or more functionals, normalizations).
    Combination(Vec<(f64, Kernel2)>),
    /// Per-cell weights applied to a kernel.
    CellWeighted(Arc<[f64]>, Box<Kernel2>),
}

impl std::fmt::Debug for Kernel2 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Kernel2::Custom(_) => f.write_str("Custom(<kernel>)"),
            Kernel2::Combination(v) => f.debug_tuple("Combination").field(v).finish(),
            Kernel2::CellWeighted(w, k) => write!(f, "CellWeighted({} weights, {k:?})", w.len()),
            Kernel2::Length => f.write_str("Length"),
            Kernel2::WeightedLength(k) => write!(f, "{k:?}"),
            Kernel2::Area => f.write_str("Area"),
            Kernel2::CastilloArea => f.write_str("CastilloArea"),
            Kernel2::A4P(k) => write!(f, "{k:?}"),
            Kernel2::Orthogonality => f.write_str("Orthogonality"),
            Kernel2::AreaOrthogonality => f.write_str("AreaOrthogonality"),
            Kernel2::Smoothness(k) => write!(f, "{k:?}"),
            Kernel2::RegularizedSmoothness(k) => write!(f, "{k:?}"),
            Kernel2::RegularizedInverseArea(k) => write!(f, "{k:?}"),
            Kernel2::KSmoothness(k) => write!(f, "{k:?}"),
            Kernel2::KArea(k) => write!(f, "{k:?}"),
            Kernel2::SOmegaEps(k) => write!(f, "{k:?}"),
            Kernel2::HOmega(k) => write!(f, "{k:?}"),
        }
    }
}

impl Kernel2 {
    /// `σ·a + (1−σ)·b` (σ is the weight of the first functional, seed 001 erratum 7).
    pub fn convex(sigma: f64, a: Kernel2, b: Kernel2) -> Result<Kernel2, FunctionalError> {
        if !(0.0..=1.0).contains(&sigma) {
            return Err(FunctionalError::InvalidParameter {
                name: "sigma",
                value: sigma,
                reason: "a convex combination needs 0 ≤ σ ≤ 1".into(),
            });
        }
        Ok(Kernel2::Combination(vec![(sigma, a), (1.0 - sigma, b)]))
    }
    /// `factor · self`.
    pub fn scaled(self, factor: f64) -> Kernel2 {
        Kernel2::Combination(vec![(factor, self)])
    }
    /// Applies one weight per cell.
    pub fn cell_weighted(self, weights: Vec<f64>) -> Result<Kernel2, FunctionalError> {
        for &w in &weights {
            check_finite("weight", w)?;
        }
        Ok(Kernel2::CellWeighted(weights.into(), Box::new(self)))
    }

    /// The value of one corner-triangle term on the **ideal** triangle of a mesh with mean `ᾱ`
    /// (right isosceles with legs `√ᾱ`: `α = ᾱ`, `la = lb = ᾱ`, `o = 0`), used as the
    /// normalization constant per triangle (seed 001 digest §3.1, seed 000 Obs 6.8). For
    /// functionals whose ideal value is 0 (orthogonality, A4P) the conventional scale `ᾱ²`
    /// resp. `ᾱ⁴` is returned. `None` for kernels without a natural scale (custom, weighted).
    pub fn ideal_term(&self, alpha_bar: f64) -> Option<f64> {
        let s = TriScalars {
            alpha: alpha_bar,
            la: alpha_bar,
            lb: alpha_bar,
            o: 0.0,
            cell: 0,
            corner: 0,
        };
        match self {
            Kernel2::Orthogonality => Some(alpha_bar * alpha_bar),
            Kernel2::A4P(_) => Some(alpha_bar.powi(4)),
            // one cell (4 corner triangles) has area ᾱ: Castillo per cell ᾱ², i.e. ᾱ²/4 per
            // corner triangle
            Kernel2::CastilloArea => Some(0.25 * alpha_bar * alpha_bar),
            Kernel2::Custom(_) | Kernel2::CellWeighted(..) => None,
            Kernel2::Combination(v) => {
                let mut t = 0.0;
                for (w, k) in v {
                    t += w * k.ideal_term(alpha_bar)?;
                }
                Some(t)
            }
            other => Some(other.eval(&s, Order::Value).v),
        }
    }

    /// The normalized functional `F / (N·ideal_term(ᾱ))` for `N` corner triangles, so that it is
    /// 1 on the ideal grid (seed 001 §5.1: e.g. area `Σα²/(Nᾱ²)`, length `Σl/(2Nᾱ)`,
    /// k-smoothness `Σ(l+2k)/(k+α)/(2N)`, k-area `(k+ᾱ)/N·Σ1/(k+α)`).
    pub fn normalized(
        self,
        num_triangles: usize,
        alpha_bar: f64,
    ) -> Result<Kernel2, FunctionalError> {
        let t = self
            .ideal_term(alpha_bar)
            .ok_or_else(|| FunctionalError::InvalidParameter {
                name: "normalization",
                value: f64::NAN,
                reason: "this kernel has no ideal value".into(),
            })?;
        let k = t * num_triangles as f64;
        if !(k.is_finite() && k > 0.0) {
            return Err(FunctionalError::InvalidParameter {
                name: "normalization",
                value: k,
                reason: "the ideal value must be finite and > 0".into(),
            });
        }
        Ok(self.scaled(1.0 / k))
    }
}

/// Dispatches a method call to the leaf kernels of [`Kernel2`] (non-leaf variants excluded).
macro_rules! kernel2_leaf {
    ($self:expr, $k:ident => $e:expr, $other:expr) => {
        match $self {
            Kernel2::Length => {
                let $k = &Length;
                $e
            }
            Kernel2::WeightedLength($k) => $e,
            Kernel2::Area => {
                let $k = &Area;
                $e
            }
            Kernel2::A4P($k) => $e,
            Kernel2::Orthogonality => {
                let $k = &Orthogonality;
                $e
            }
            Kernel2::AreaOrthogonality => {
                let $k = &AreaOrthogonality;
                $e
            }
            Kernel2::Smoothness($k) => $e,
            Kernel2::RegularizedSmoothness($k) => $e,
            Kernel2::RegularizedInverseArea($k) => $e,
            Kernel2::KSmoothness($k) => $e,
            Kernel2::KArea($k) => $e,
            Kernel2::SOmegaEps($k) => $e,
            Kernel2::HOmega($k) => $e,
            _ => $other,
        }
    };
}

impl TriKernel for Kernel2 {
    #[inline]
    fn value(&self, s: &TriScalars) -> f64 {
        match self {
            Kernel2::CastilloArea => CastilloArea.value(s),
            Kernel2::Combination(v) => {
                let mut acc = 0.0;
                for (w, k) in v {
                    if wants(k, s) {
                        acc += w * k.value(s);
                    }
                }
                acc
            }
            Kernel2::CellWeighted(w, k) => w.get(s.cell).copied().unwrap_or(1.0) * k.value(s),
            Kernel2::Custom(k) => k.value(s),
            _ if s.corner == DIAGONAL => 0.0,
            leaf => kernel2_leaf!(leaf, k => k.value(s), 0.0),
        }
    }

    #[inline]
    fn value_grad(&self, s: &TriScalars) -> (f64, [f64; 4]) {
        match self {
            Kernel2::CastilloArea => CastilloArea.value_grad(s),
            Kernel2::Combination(v) => {
                let mut acc = (0.0, [0.0; 4]);
                for (w, k) in v {
                    if wants(k, s) {
                        axpy4(&mut acc, *w, k.value_grad(s));
                    }
                }
                acc
            }
            Kernel2::CellWeighted(w, k) => {
                let mut acc = (0.0, [0.0; 4]);
                axpy4(
                    &mut acc,
                    w.get(s.cell).copied().unwrap_or(1.0),
                    k.value_grad(s),
                );
                acc
            }
            Kernel2::Custom(k) => k.value_grad(s),
            _ if s.corner == DIAGONAL => (0.0, [0.0; 4]),
            leaf => kernel2_leaf!(leaf, k => k.value_grad(s), (0.0, [0.0; 4])),
        }
    }

    #[inline]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let diag = s.corner == DIAGONAL;
        match self {
            Kernel2::CastilloArea => CastilloArea.eval(s, order),
            Kernel2::Combination(v) => {
                let mut p = Partials::default();
                for (w, k) in v {
                    if wants(k, s) {
                        let q = k.eval(s, order);
                        p.add_scaled(*w, &q, order);
                    }
                }
                p
            }
            Kernel2::CellWeighted(w, k) => {
                let mut p = k.eval(s, order);
                p.scale(w.get(s.cell).copied().unwrap_or(1.0), order);
                p
            }
            Kernel2::Custom(k) => k.eval(s, order),
            _ if diag => zero(),
            Kernel2::Length => Length.eval(s, order),
            Kernel2::WeightedLength(k) => k.eval(s, order),
            Kernel2::Area => Area.eval(s, order),
            Kernel2::A4P(k) => k.eval(s, order),
            Kernel2::Orthogonality => Orthogonality.eval(s, order),
            Kernel2::AreaOrthogonality => AreaOrthogonality.eval(s, order),
            Kernel2::Smoothness(k) => k.eval(s, order),
            Kernel2::RegularizedSmoothness(k) => k.eval(s, order),
            Kernel2::RegularizedInverseArea(k) => k.eval(s, order),
            Kernel2::KSmoothness(k) => k.eval(s, order),
            Kernel2::KArea(k) => k.eval(s, order),
            Kernel2::SOmegaEps(k) => k.eval(s, order),
            Kernel2::HOmega(k) => k.eval(s, order),
        }
    }
    fn terms(&self) -> Terms {
        match self {
            Kernel2::CastilloArea => CastilloArea.terms(),
            Kernel2::Combination(v) => v.iter().fold(
                Terms {
                    corners: false,
                    diagonal: false,
                },
                |t, (_, k)| t.or(k.terms()),
            ),
            Kernel2::CellWeighted(_, k) => k.terms(),
            Kernel2::Custom(k) => k.terms(),
            _ => CORNERS,
        }
    }
}
