//! Planar B-spline curves `x(t) = Σ_i P_i B^k_i(t)` ([Abelló et al., §2.1, (42)–(43)]).
//!
//! The derivative is again a B-spline curve, of order `k − 1` on the knots without the first and
//! last one, with control points `Q_r = (k−1)(P_{r+1} − P_r)/(t_{r+k} − t_{r+1})` (0-based;
//! `0/0 := 0`). For quadratic curves on the uniform knots (23) this is the `γ_r` factor of (37):
//! `Q_r = (n−2)·γ_r·(P_{r+1} − P_r)`.

use glam::DVec2;

use crate::error::BsplineError;
use crate::knots::KnotVector;

/// A planar B-spline curve.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplineCurve {
    knots: KnotVector,
    ctrl: Vec<DVec2>,
}

impl BSplineCurve {
    /// A curve from knots and `knots.num_basis()` finite control points.
    pub fn new(knots: KnotVector, ctrl: Vec<DVec2>) -> Result<Self, BsplineError> {
        if ctrl.len() != knots.num_basis() {
            return Err(BsplineError::Count {
                what: "curve control points",
                got: ctrl.len(),
                need: format!("{} (one per basis function)", knots.num_basis()),
            });
        }
        if let Some(i) = ctrl.iter().position(|p| !p.is_finite()) {
            return Err(BsplineError::NonFinite {
                what: "curve control points",
                index: i,
            });
        }
        Ok(Self { knots, ctrl })
    }

    /// A curve of `order` on clamped uniform knots (e.g. order 3: the boundary curves (42)/(43)
    /// on knots (23)/(24)); needs at least `order` control points.
    pub fn clamped_uniform(order: usize, ctrl: Vec<DVec2>) -> Result<Self, BsplineError> {
        let knots = KnotVector::clamped_uniform(order, ctrl.len())?;
        Self::new(knots, ctrl)
    }

    /// The knots.
    pub fn knots(&self) -> &KnotVector {
        &self.knots
    }

    /// The control points.
    pub fn control_points(&self) -> &[DVec2] {
        &self.ctrl
    }

    /// `x(t)` (`t` clamped to the domain).
    pub fn eval(&self, t: f64) -> DVec2 {
        let k = self.knots.order();
        let mut b = [0.0; 16];
        let mu = self.knots.nonzero_basis(t, &mut b, None);
        (0..k).fold(DVec2::ZERO, |s, a| s + b[a] * self.ctrl[mu + 1 - k + a])
    }

    /// `x'(t)` (`t` clamped to the domain).
    pub fn derivative_at(&self, t: f64) -> DVec2 {
        let k = self.knots.order();
        let mut b = [0.0; 16];
        let mut d = [0.0; 16];
        let mu = self.knots.nonzero_basis(t, &mut b, Some(&mut d));
        (0..k).fold(DVec2::ZERO, |s, a| s + d[a] * self.ctrl[mu + 1 - k + a])
    }

    /// The derivative curve (order `k − 1`, control points `Q_r` of the module docs). `None`
    /// for order 1 (the derivative of a step function is not a B-spline curve).
    pub fn derivative(&self) -> Option<BSplineCurve> {
        let k = self.knots.order();
        if k < 2 {
            return None;
        }
        let t = self.knots.knots();
        let q: Vec<DVec2> = (0..self.ctrl.len() - 1)
            .map(|r| {
                let den = t[r + k] - t[r + 1];
                if den > 0.0 {
                    (k - 1) as f64 * (self.ctrl[r + 1] - self.ctrl[r]) / den
                } else {
                    DVec2::ZERO
                }
            })
            .collect();
        let knots = KnotVector::new(k - 1, t[1..t.len() - 1].to_vec()).ok()?;
        BSplineCurve::new(knots, q).ok()
    }

    /// `samples ≥ 2` points at equispaced parameters over the domain.
    pub fn polyline(&self, samples: usize) -> Vec<DVec2> {
        let (a, b) = self.knots.domain();
        let s = samples.max(2);
        (0..s)
            .map(|l| self.eval(a + (b - a) * l as f64 / (s - 1) as f64))
            .collect()
    }
}
