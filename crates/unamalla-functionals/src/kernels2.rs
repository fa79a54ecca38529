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
    /// Values of the four corner terms of one cell (lane `k` = corner `k`): the hot path of the
    /// fast 2D evaluator ([`crate::quad`]). The default calls [`value`](Self::value) per lane;
    /// after inlining, the four lanes are independent and the compiler vectorizes them.
    #[inline(always)]
    fn corners_value(&self, s: &CornerLanes) -> [f64; 4] {
        [
            self.value(&s.lane(0)),
            self.value(&s.lane(1)),
            self.value(&s.lane(2)),
            self.value(&s.lane(3)),
        ]
    }
    /// Values and first partials of the four corner terms of one cell ([`LaneGrad`]). The
    /// default calls [`value_grad`](Self::value_grad) per lane; combinators combine lane-wise
    /// so that a monomorphized sum is one straight-line, vectorizable computation.
    #[inline(always)]
    fn corners_value_grad(&self, s: &CornerLanes) -> LaneGrad {
        let mut out = LaneGrad::default();
        for k in 0..4 {
            let (v, g) = self.value_grad(&s.lane(k));
            out.v[k] = v;
            for i in 0..4 {
                out.g[i][k] = g[i];
            }
        }
        out
    }
    /// Values, first and second partials of the four corner terms of one cell
    /// ([`LanePartials`]); the default calls [`eval`](Self::eval) with [`Order::Hessian`] per
    /// lane.
    #[inline(always)]
    fn corners_hessian(&self, s: &CornerLanes) -> LanePartials {
        let mut out = LanePartials::default();
        for k in 0..4 {
            let p = self.eval(&s.lane(k), Order::Hessian);
            out.v[k] = p.v;
            for i in 0..4 {
                out.g[i][k] = p.g[i];
                for j in 0..4 {
                    out.h[i][j][k] = p.h[i][j];
                }
            }
        }
        out
    }
    /// Which second partials `∂²f/∂sᵢ∂sⱼ` (`s = (α, la, lb, o)`) may be non-zero. The fast
    /// Hessian path skips the others; for a typed kernel the answer is a constant, so the
    /// skipped products are removed at compile time. The default (all `true`) is always correct;
    /// an override must only clear entries that [`eval`](Self::eval) leaves at zero.
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        [[true; 4]; 4]
    }
    /// `Some(self)` if this kernel is a run-time [`Kernel2`] (or wraps one), so that the
    /// evaluator can flatten it once and route it to a monomorphized fused kernel
    /// ([`Kernel2::flattened`]); `None` for every other kernel (the default).
    fn as_kernel2(&self) -> Option<&Kernel2> {
        None
    }
}

/// The scalars of the four corner triangles of one cell, one **lane** per corner (lane `k` is
/// corner `k`: `a = v_{k+1} − v_k`, `b = v_{k−1} − v_k`), in structure-of-arrays form so that the
/// per-corner arithmetic of a kernel runs on all four corners at once (SIMD).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CornerLanes {
    /// `α` per corner.
    pub alpha: [f64; 4],
    /// `|a|²` per corner.
    pub la: [f64; 4],
    /// `|b|²` per corner.
    pub lb: [f64; 4],
    /// `a·b` per corner.
    pub o: [f64; 4],
    /// Cell id.
    pub cell: usize,
}

impl CornerLanes {
    /// The scalars of corner `k` (`k < 4`).
    #[inline(always)]
    pub fn lane(&self, k: usize) -> TriScalars {
        TriScalars {
            alpha: self.alpha[k],
            la: self.la[k],
            lb: self.lb[k],
            o: self.o[k],
            cell: self.cell,
            corner: k as u8,
        }
    }
}

/// Values and first partials of the four corner terms of a cell: `v[k]` and `g[s][k]` =
/// `∂f/∂s` of corner `k`, `s` indexed as in [`Partials`] (`α`, `la`, `lb`, `o`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LaneGrad {
    /// Value per corner.
    pub v: [f64; 4],
    /// `g[s][k] = ∂f_k/∂s`.
    pub g: [[f64; 4]; 4],
}

impl LaneGrad {
    /// `self += w·o`, lane-wise.
    #[inline(always)]
    pub fn add_scaled(&mut self, w: f64, o: &LaneGrad) {
        for k in 0..4 {
            self.v[k] += w * o.v[k];
        }
        for i in 0..4 {
            for k in 0..4 {
                self.g[i][k] += w * o.g[i][k];
            }
        }
    }
    /// `self += w_k·o` with one weight per lane.
    #[inline(always)]
    pub fn add_scaled_lanes(&mut self, w: &[f64; 4], o: &LaneGrad) {
        for k in 0..4 {
            self.v[k] += w[k] * o.v[k];
        }
        for i in 0..4 {
            for k in 0..4 {
                self.g[i][k] += w[k] * o.g[i][k];
            }
        }
    }
}

/// Values, first and second partials of the four corner terms of a cell: `h[s][t][k]` =
/// `∂²f_k/∂s∂t`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LanePartials {
    /// Value per corner.
    pub v: [f64; 4],
    /// `g[s][k] = ∂f_k/∂s`.
    pub g: [[f64; 4]; 4],
    /// `h[s][t][k] = ∂²f_k/∂s∂t` (symmetric in `s`, `t`).
    pub h: [[[f64; 4]; 4]; 4],
}

impl LanePartials {
    /// `self += w·o`, lane-wise.
    #[inline(always)]
    pub fn add_scaled(&mut self, w: f64, o: &LanePartials) {
        self.add_scaled_masked(w, o, &[[true; 4]; 4]);
    }
    /// `self += w·o` on the second partials marked in `mask` only (the others of `o` must be
    /// zero, e.g. `mask` = the [`TriKernel::hessian_sparsity`] of the kernel that produced
    /// `o`; for a typed kernel the mask is a constant and the skipped products vanish at
    /// compile time).
    #[inline(always)]
    pub fn add_scaled_masked(&mut self, w: f64, o: &LanePartials, mask: &[[bool; 4]; 4]) {
        for k in 0..4 {
            self.v[k] += w * o.v[k];
        }
        for i in 0..4 {
            for k in 0..4 {
                self.g[i][k] += w * o.g[i][k];
            }
            for j in 0..4 {
                if mask[i][j] {
                    for k in 0..4 {
                        self.h[i][j][k] += w * o.h[i][j][k];
                    }
                }
            }
        }
    }
}

#[inline(always)]
fn axpy_lanes(acc: &mut [f64; 4], w: f64, o: [f64; 4]) {
    for k in 0..4 {
        acc[k] += w * o[k];
    }
}

/// Sparsity of `∂²f/∂s²` with the given `(i, j)` entries (and their transposes) non-zero.
pub(crate) const fn sparsity(entries: &[(usize, usize)]) -> [[bool; 4]; 4] {
    let mut m = [[false; 4]; 4];
    let mut k = 0;
    while k < entries.len() {
        let (i, j) = entries[k];
        m[i][j] = true;
        m[j][i] = true;
        k += 1;
    }
    m
}

/// Entry-wise `a ∨ b` of two sparsity patterns.
#[inline(always)]
pub(crate) fn sparsity_or(a: [[bool; 4]; 4], b: [[bool; 4]; 4]) -> [[bool; 4]; 4] {
    let mut m = a;
    for i in 0..4 {
        for j in 0..4 {
            m[i][j] |= b[i][j];
        }
    }
    m
}

const SP_NONE: [[bool; 4]; 4] = [[false; 4]; 4];
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
    #[inline(always)]
    fn corners_value(&self, s: &CornerLanes) -> [f64; 4] {
        (**self).corners_value(s)
    }
    #[inline(always)]
    fn corners_value_grad(&self, s: &CornerLanes) -> LaneGrad {
        (**self).corners_value_grad(s)
    }
    #[inline(always)]
    fn corners_hessian(&self, s: &CornerLanes) -> LanePartials {
        (**self).corners_hessian(s)
    }
    fn as_kernel2(&self) -> Option<&Kernel2> {
        (**self).as_kernel2()
    }
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        (**self).hessian_sparsity()
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
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_NONE
    }
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
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_NONE
    }
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
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_ALPHA
    }
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

/// Orthogonality `F_O`: `o² = (a·b)²` (seed 000 Table 6.2, corner apex per seed 003 erratum 11).
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
/// identity with the apex at the **corner** (seed 000 digest §5.5 note and erratum 10: the
/// printed `½‖r−p‖²‖q−p‖²` has the wrong apex).
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
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_L_PHI
    }
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
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_ALPHA
    }
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
/// Source: the UNAMALLA thesis (UNAM, c. 2001; author presumably G. González Flores; discrete
/// harmonic, area and adaptive functionals and the Unamalla 2.0 manual — the text available to
/// us carries no title page), §2.2, eq. (2.50), after S. A. Ivanenko's convex-mesh functional
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
/// [`Kernel2::normalized`] refuses it; scale it by hand if it is combined with another kernel.
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
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        self.inner.hessian_sparsity()
    }
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
    #[inline(always)]
    fn corners_value(&self, s: &CornerLanes) -> [f64; 4] {
        let mut acc = [0.0; 4];
        axpy_lanes(&mut acc, self.factor, self.inner.corners_value(s));
        acc
    }
    #[inline(always)]
    fn corners_value_grad(&self, s: &CornerLanes) -> LaneGrad {
        let mut acc = LaneGrad::default();
        acc.add_scaled(self.factor, &self.inner.corners_value_grad(s));
        acc
    }
    #[inline(always)]
    fn corners_hessian(&self, s: &CornerLanes) -> LanePartials {
        let mut acc = LanePartials::default();
        let m = self.inner.hessian_sparsity();
        acc.add_scaled_masked(self.factor, &self.inner.corners_hessian(s), &m);
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
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        sparsity_or(self.a.hessian_sparsity(), self.b.hessian_sparsity())
    }
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
    #[inline(always)]
    fn corners_value(&self, s: &CornerLanes) -> [f64; 4] {
        let mut acc = [0.0; 4];
        if self.a.terms().corners {
            axpy_lanes(&mut acc, self.wa, self.a.corners_value(s));
        }
        if self.b.terms().corners {
            axpy_lanes(&mut acc, self.wb, self.b.corners_value(s));
        }
        acc
    }
    #[inline(always)]
    fn corners_value_grad(&self, s: &CornerLanes) -> LaneGrad {
        let mut acc = LaneGrad::default();
        if self.a.terms().corners {
            acc.add_scaled(self.wa, &self.a.corners_value_grad(s));
        }
        if self.b.terms().corners {
            acc.add_scaled(self.wb, &self.b.corners_value_grad(s));
        }
        acc
    }
    #[inline(always)]
    fn corners_hessian(&self, s: &CornerLanes) -> LanePartials {
        let mut acc = LanePartials::default();
        if self.a.terms().corners {
            let m = self.a.hessian_sparsity();
            acc.add_scaled_masked(self.wa, &self.a.corners_hessian(s), &m);
        }
        if self.b.terms().corners {
            let m = self.b.hessian_sparsity();
            acc.add_scaled_masked(self.wb, &self.b.corners_hessian(s), &m);
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
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        self.inner.hessian_sparsity()
    }
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
    #[inline(always)]
    fn corners_value(&self, s: &CornerLanes) -> [f64; 4] {
        let mut acc = [0.0; 4];
        let w = self.weights.get(s.cell).copied().unwrap_or(1.0);
        axpy_lanes(&mut acc, w, self.inner.corners_value(s));
        acc
    }
    #[inline(always)]
    fn corners_value_grad(&self, s: &CornerLanes) -> LaneGrad {
        let mut acc = LaneGrad::default();
        let w = self.weights.get(s.cell).copied().unwrap_or(1.0);
        acc.add_scaled(w, &self.inner.corners_value_grad(s));
        acc
    }
    #[inline(always)]
    fn corners_hessian(&self, s: &CornerLanes) -> LanePartials {
        let mut acc = LanePartials::default();
        let w = self.weights.get(s.cell).copied().unwrap_or(1.0);
        let m = self.inner.hessian_sparsity();
        acc.add_scaled_masked(w, &self.inner.corners_hessian(s), &m);
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
    /// [`IvanenkoConvex`].
    IvanenkoConvex(IvanenkoConvex),
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
            Kernel2::IvanenkoConvex(k) => write!(f, "{k:?}"),
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
            Kernel2::IvanenkoConvex($k) => $e,
            _ => $other,
        }
    };
}

impl TriKernel for Kernel2 {
    #[inline]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        match self {
            Kernel2::CastilloArea => SP_ALPHA,
            Kernel2::Combination(v) => v
                .iter()
                .fold(SP_NONE, |m, (_, k)| sparsity_or(m, k.hessian_sparsity())),
            Kernel2::CellWeighted(_, k) => k.hessian_sparsity(),
            Kernel2::Custom(k) => k.hessian_sparsity(),
            leaf => kernel2_leaf!(leaf, k => k.hessian_sparsity(), [[true; 4]; 4]),
        }
    }
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
            Kernel2::IvanenkoConvex(k) => k.eval(s, order),
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
    #[inline]
    fn corners_value(&self, s: &CornerLanes) -> [f64; 4] {
        match self {
            Kernel2::CastilloArea => [0.0; 4],
            Kernel2::Combination(v) => {
                let mut acc = [0.0; 4];
                for (w, k) in v {
                    if k.terms().corners {
                        axpy_lanes(&mut acc, *w, k.corners_value(s));
                    }
                }
                acc
            }
            Kernel2::CellWeighted(w, k) => {
                let mut acc = [0.0; 4];
                axpy_lanes(
                    &mut acc,
                    w.get(s.cell).copied().unwrap_or(1.0),
                    k.corners_value(s),
                );
                acc
            }
            Kernel2::Custom(k) => k.corners_value(s),
            leaf => kernel2_leaf!(leaf, k => k.corners_value(s), [0.0; 4]),
        }
    }
    #[inline]
    fn corners_value_grad(&self, s: &CornerLanes) -> LaneGrad {
        match self {
            Kernel2::CastilloArea => LaneGrad::default(),
            Kernel2::Combination(v) => {
                let mut acc = LaneGrad::default();
                for (w, k) in v {
                    if k.terms().corners {
                        acc.add_scaled(*w, &k.corners_value_grad(s));
                    }
                }
                acc
            }
            Kernel2::CellWeighted(w, k) => {
                let mut acc = LaneGrad::default();
                acc.add_scaled(
                    w.get(s.cell).copied().unwrap_or(1.0),
                    &k.corners_value_grad(s),
                );
                acc
            }
            Kernel2::Custom(k) => k.corners_value_grad(s),
            leaf => kernel2_leaf!(leaf, k => k.corners_value_grad(s), LaneGrad::default()),
        }
    }
    #[inline]
    fn corners_hessian(&self, s: &CornerLanes) -> LanePartials {
        match self {
            Kernel2::CastilloArea => LanePartials::default(),
            Kernel2::Combination(v) => {
                let mut acc = LanePartials::default();
                for (w, k) in v {
                    if k.terms().corners {
                        let m = k.hessian_sparsity();
                        acc.add_scaled_masked(*w, &k.corners_hessian(s), &m);
                    }
                }
                acc
            }
            Kernel2::CellWeighted(w, k) => {
                let mut acc = LanePartials::default();
                let m = k.hessian_sparsity();
                acc.add_scaled_masked(
                    w.get(s.cell).copied().unwrap_or(1.0),
                    &k.corners_hessian(s),
                    &m,
                );
                acc
            }
            Kernel2::Custom(k) => k.corners_hessian(s),
            leaf => kernel2_leaf!(leaf, k => k.corners_hessian(s), LanePartials::default()),
        }
    }
    fn as_kernel2(&self) -> Option<&Kernel2> {
        Some(self)
    }
}

impl Kernel2 {
    /// The kernel as a flat weighted sum `Σ wᵢ Kᵢ` with no nested [`Kernel2::Combination`]
    /// (weights of nested combinations multiplied out). Equal to
    /// `self` up to rounding (`w₁(w₂f)` becomes `(w₁w₂)f`). Used once per functional by the
    /// evaluator to pick a monomorphized fused kernel for common sums (e.g. seed 000 (6.8)
    /// `(1−σ)F_AO + σH_ω`, see [`crate::quad`]).
    pub fn flattened(&self) -> Vec<(f64, Kernel2)> {
        let mut out = Vec::new();
        self.flatten_into(1.0, &mut out);
        out
    }

    fn flatten_into(&self, w: f64, out: &mut Vec<(f64, Kernel2)>) {
        match self {
            Kernel2::Combination(v) => {
                for (wi, k) in v {
                    k.flatten_into(w * wi, out);
                }
            }
            k => out.push((w, k.clone())),
        }
    }
}
