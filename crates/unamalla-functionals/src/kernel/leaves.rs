//! The leaf kernels: the per-term functions `f(α, la, lb, o)` of the 2D functionals (module
//! docs of [`crate::kernel`] for the scalars), the scalar functions they are built from
//! ([`phi_omega`], [`phi_regularized`], [`inv_k`], [`s_function`]) and their parameters.
//! Every leaf is a variant of [`Leaf`](super::Leaf), and any of them converts into a
//! [`KernelExpr`](super::KernelExpr).
//!
//! The fifteen leaf kernels, with their parameter checks, formulas and derivative code, are in
//! one submodule per family (`classic`, `adaptive`, `convex`, in the order of the table of the
//! crate docs); they share the building blocks of this file.

use super::{
    sparsity, CornerLanes, LaneGrad, LanePartials, Order, Partials, TriScalars, S_ALPHA, S_LA, S_LB,
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

mod adaptive;
mod classic;
mod convex;

pub use adaptive::*;
pub use classic::*;
pub use convex::*;
