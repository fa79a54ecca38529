//! Name-based entry point for `unamalla eval <mesh> --functional NAME [--omega w] [--k k]
//! [--raw] [--json]`.
//!
//! **Raw mode** evaluates the plain sum over all corner triangles of the mesh, with no
//! normalization or constant factor. For a corner triangle with corner `P` and legs
//! `a = Q − P`, `b = R − P` in counter-clockwise order (`Q` the next and `R` the previous vertex
//! of the cell), `α = det(a, b)`, `l = |a|² + |b|²`, `o = a·b`, the terms are:
//!
//! | name | term |
//! |---|---|
//! | `length` | `l` |
//! | `area` | `α²` |
//! | `orthogonality` | `o²` |
//! | `area-orthogonality` | `½(α² + o²)` |
//! | `smoothness` | `l/α` |
//! | `k-smoothness` | `(l + 2k)/(k + α)` (`+∞` if some `k + α ≤ 0`) |
//! | `k-area` | `1/(k + α)` (`+∞` if some `k + α ≤ 0`) |
//! | `h-omega` | `l·φ_ω(α)`, `φ_ω(α) = 1/α` for `α ≥ ω`, `(2ω − α)/ω²` below |
//! | `a4p` | `(α − ᾱ)⁴`, `ᾱ = Σα/N` |
//! | `castillo-area` | `A²` per **cell** (`A` the signed cell area) |
//! | `regularized-smoothness` | `l·φ̃(α)` with `ε_c = ᾱ/2` ([`phi_regularized`](crate::phi_regularized)) |
//! | `regularized-inverse-area` | `φ̃(α)` with `ε_c = ᾱ/2` |
//!
//! Without `--raw` the functional is normalized to 1 on the ideal grid
//! ([`KernelExpr::normalized`]). The gradient norm is the Euclidean norm of the gradient with
//! respect to the free-node coordinates. Defaults: `k = 0`, `ω = ᾱ/2` (reported back in
//! [`EvalReport`]).

use std::sync::Arc;

use serde::Serialize;
use unamalla_mesh::{FreeNodes, HasQuadCells};

use crate::error::FunctionalError;
use crate::kernel::{
    Area, AreaOrthogonality, CastilloArea, HOmega, KArea, KSmoothness, KernelExpr, Length,
    Orthogonality, RegularizedInverseArea, RegularizedSmoothness, Smoothness, A4P,
};
use crate::problem::{Gradient, Variables};
use crate::quad::{QuadFunctional, QuadTopology};

/// Names accepted by [`FunctionalSpec::from_name`].
pub const FUNCTIONAL_NAMES: &[&str] = &[
    "length",
    "area",
    "orthogonality",
    "area-orthogonality",
    "smoothness",
    "k-smoothness",
    "k-area",
    "h-omega",
    "a4p",
    "castillo-area",
    "regularized-smoothness",
    "regularized-inverse-area",
];

/// A 2D functional chosen by name, with its parameters.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum FunctionalSpec {
    /// `l`.
    Length,
    /// `α²`.
    Area,
    /// `o²`.
    Orthogonality,
    /// `½(α² + o²)`.
    AreaOrthogonality,
    /// `l/α`.
    Smoothness,
    /// `(l + 2k)/(k + α)`.
    KSmoothness {
        /// `k`.
        k: f64,
    },
    /// `1/(k + α)`.
    KArea {
        /// `k`.
        k: f64,
    },
    /// `l·φ_ω(α)`.
    HOmega {
        /// `ω`; `None` = `ᾱ/2` of the mesh.
        omega: Option<f64>,
    },
    /// `(α − ᾱ)⁴`.
    A4P,
    /// Castillo cell area.
    CastilloArea,
    /// Regularized smoothness, `ε_c = ᾱ/2`.
    RegularizedSmoothness,
    /// Regularized inverse area, `ε_c = ᾱ/2`.
    RegularizedInverseArea,
}

impl FunctionalSpec {
    /// Parses a name of [`FUNCTIONAL_NAMES`]; `omega` is used by `h-omega`, `k` (default 0) by
    /// `k-smoothness` and `k-area`. Unknown names give
    /// [`FunctionalError::UnknownFunctional`] listing the valid names.
    pub fn from_name(
        name: &str,
        omega: Option<f64>,
        k: Option<f64>,
    ) -> Result<Self, FunctionalError> {
        let k = k.unwrap_or(0.0);
        if !k.is_finite() {
            return Err(FunctionalError::InvalidParameter {
                name: "k",
                value: k,
                reason: "must be finite".into(),
            });
        }
        if let Some(w) = omega {
            if !(w.is_finite() && w > 0.0) {
                return Err(FunctionalError::InvalidParameter {
                    name: "omega",
                    value: w,
                    reason: "must be finite and > 0".into(),
                });
            }
        }
        Ok(match name {
            "length" => Self::Length,
            "area" => Self::Area,
            "orthogonality" => Self::Orthogonality,
            "area-orthogonality" => Self::AreaOrthogonality,
            "smoothness" => Self::Smoothness,
            "k-smoothness" => Self::KSmoothness { k },
            "k-area" => Self::KArea { k },
            "h-omega" => Self::HOmega { omega },
            "a4p" => Self::A4P,
            "castillo-area" => Self::CastilloArea,
            "regularized-smoothness" => Self::RegularizedSmoothness,
            "regularized-inverse-area" => Self::RegularizedInverseArea,
            _ => {
                return Err(FunctionalError::UnknownFunctional {
                    name: name.to_string(),
                    valid: FUNCTIONAL_NAMES.join(", "),
                })
            }
        })
    }

    /// The canonical name.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Length => "length",
            Self::Area => "area",
            Self::Orthogonality => "orthogonality",
            Self::AreaOrthogonality => "area-orthogonality",
            Self::Smoothness => "smoothness",
            Self::KSmoothness { .. } => "k-smoothness",
            Self::KArea { .. } => "k-area",
            Self::HOmega { .. } => "h-omega",
            Self::A4P => "a4p",
            Self::CastilloArea => "castillo-area",
            Self::RegularizedSmoothness => "regularized-smoothness",
            Self::RegularizedInverseArea => "regularized-inverse-area",
        }
    }

    /// The raw (un-normalized) kernel for a mesh with mean `ᾱ = alpha_bar`, and the resolved
    /// `ω` (for `h-omega`).
    pub fn raw_kernel(&self, alpha_bar: f64) -> Result<(KernelExpr, Option<f64>), FunctionalError> {
        Ok(match self {
            Self::Length => (Length.into(), None),
            Self::Area => (Area.into(), None),
            Self::Orthogonality => (Orthogonality.into(), None),
            Self::AreaOrthogonality => (AreaOrthogonality.into(), None),
            Self::Smoothness => (Smoothness::new().into(), None),
            Self::KSmoothness { k } => (KSmoothness::new(*k, None)?.into(), None),
            Self::KArea { k } => (KArea::new(*k, None)?.into(), None),
            Self::HOmega { omega } => {
                let w = omega.unwrap_or(0.5 * alpha_bar);
                (HOmega::new(w)?.into(), Some(w))
            }
            Self::A4P => (A4P::new(alpha_bar)?.into(), None),
            Self::CastilloArea => (CastilloArea.into(), None),
            Self::RegularizedSmoothness => (
                RegularizedSmoothness::with_alpha_bar(alpha_bar)?.into(),
                None,
            ),
            Self::RegularizedInverseArea => {
                (RegularizedInverseArea::new(0.5 * alpha_bar)?.into(), None)
            }
        })
    }
}

/// Result of [`evaluate`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EvalReport {
    /// Canonical functional name.
    pub functional: String,
    /// The value (may be `+∞` for barrier functionals outside their domain).
    pub value: f64,
    /// Euclidean norm of the gradient over the free-node coordinates.
    pub gradient_norm: f64,
    /// `true` for the raw sum, `false` for the normalized functional.
    pub raw: bool,
    /// `ω` used (h-omega only).
    pub omega: Option<f64>,
    /// `k` used (k-functionals only).
    pub k: Option<f64>,
    /// Number of corner triangles `N`.
    pub num_triangles: usize,
    /// `ᾱ = Σα/N`.
    pub alpha_bar: f64,
    /// `α₋ = min α`.
    pub alpha_min: f64,
}

/// Evaluates value and gradient norm of `spec` on any quad mesh with free/fixed flags; `raw`
/// selects the plain sum (module docs) instead of the normalized functional.
pub fn evaluate<M: HasQuadCells + FreeNodes + ?Sized>(
    mesh: &M,
    spec: &FunctionalSpec,
    raw: bool,
) -> Result<EvalReport, FunctionalError> {
    let topo = Arc::new(QuadTopology::from_mesh(mesh)?);
    let x = topo.initial_x();
    let summary = topo.alpha_summary(&x);
    let abar = topo.alpha_bar();
    let (kernel, omega) = spec.raw_kernel(abar)?;
    let kernel = if raw {
        kernel
    } else {
        kernel.normalized(topo.num_triangles(), abar)?
    };
    let f = QuadFunctional::new(topo.clone(), kernel);
    let mut g = vec![0.0; f.num_vars()];
    let value = f.value_grad(&x, &mut g);
    let gradient_norm = g.iter().map(|v| v * v).sum::<f64>().sqrt();
    let k = match spec {
        FunctionalSpec::KSmoothness { k } | FunctionalSpec::KArea { k } => Some(*k),
        _ => None,
    };
    Ok(EvalReport {
        functional: spec.name().to_string(),
        value,
        gradient_norm,
        raw,
        omega,
        k,
        num_triangles: topo.num_triangles(),
        alpha_bar: abar,
        alpha_min: summary.min,
    })
}
