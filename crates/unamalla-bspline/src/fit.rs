//! Least-squares fit of a boundary curve to a sampled polyline, with fixed end points.
//!
//! The source method (Abelló Ugalde, Hernández Mederos, Barrera Sánchez, González Flores,
//! "B-spline parametrization of planar regions with irregular boundary", §2.1) assumes the four
//! boundary curves are already quadratic B-splines on the uniform knots (23)/(24) and does not
//! say how they are obtained. This module fits them: Piegl & Tiller (1997), *The NURBS Book*,
//! 2nd ed., §9.4.1 "Least squares curve approximation", eqs. (9.63)–(9.67): given samples
//! `q_0..q_K` at parameters `u_0 = 0 < … < u_K = 1`, the control points `P_0 = q_0`,
//! `P_{n−1} = q_K` are fixed and `P_1..P_{n−2}` minimize
//! `Σ_{k=1}^{K−1} |q_k − Σ_i P_i B_i(u_k)|²`, i.e. solve the normal equations
//! `(NᵀN) P = Nᵀ R`, `R_k = q_k − B_0(u_k) q_0 − B_{n−1}(u_k) q_K` (one right-hand side per
//! coordinate). `NᵀN` is symmetric positive definite when every interior basis function is
//! non-zero at some sample (Schoenberg–Whitney); it is factored by nalgebra's dense Cholesky,
//! and a failed factorization is reported as [`BsplineError::Fit`].
//!
//! **Fairing.** A ragged side (a coastline with a lagoon behind a barrier island, a spit) has
//! no simple control polygon among its least-squares fits with few control points: the fit
//! follows both shores of a narrow spike and the polygon crosses itself. The fit then adds a
//! second-difference penalty on the control points (the P-spline of Eilers & Marx, 1996,
//! "Flexible smoothing with B-splines and penalties", *Statistical Science* 11(2), eq. (7)):
//! minimize `Σ_k |r_k|² + w Σ_{i=1}^{n−2} |P_{i−1} − 2P_i + P_{i+1}|²`, so the normal equations
//! become `(NᵀN + w DᵀD) P = Nᵀ R − w Dᵀ d₀` (`d₀` the fixed ends' part of the differences).
//! The weight is `w = λ · tr(NᵀN) / tr(DᵀD)` so that the dimensionless `λ` ([`Fairing`]) weighs
//! the two terms alike at `λ = 1` whatever the sample count. As `λ → ∞` the interior control
//! points tend to the minimizer of the penalty alone, equally spaced on the chord `q_0 q_K`.
//!
//! Parameters ([`FitParameters`]): chord length, Piegl & Tiller eq. (9.5), or centripetal,
//! eq. (9.6) (Lee, 1989, "Choosing nodes in parametric curve interpolation"), both after the
//! polyline is densified so that no segment is longer than `1/(4(n−2))` of its length (so that
//! with chord-length parameters every uniform knot span holds samples).

use glam::DVec2;
use nalgebra::DMatrix;

use crate::error::BsplineError;
use crate::knots::{KnotVector, MAX_ORDER};

/// How sample parameters are chosen from a polyline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum FitParameters {
    /// `u_k − u_{k−1} ∝ |q_k − q_{k−1}|` (Piegl & Tiller 1997, eq. (9.5)).
    ChordLength,
    /// `u_k − u_{k−1} ∝ |q_k − q_{k−1}|^{1/2}` (Piegl & Tiller 1997, eq. (9.6)).
    Centripetal,
}

/// The fairing weight `λ` of the second-difference penalty (module docs).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum Fairing {
    /// This `λ ≥ 0` (0 is the plain least-squares fit).
    Fixed(f64),
    /// Per side, the smallest `λ` of [`FAIRING_LADDER`] reached by raising `λ` on the sides
    /// whose fit makes the boundary control polygon invalid (a crossing, a reflex corner:
    /// [`crate::BoundaryCurves::validate`]) until it is valid; used by
    /// [`crate::BoundaryCurves::fit_ring`].
    Auto,
}

/// The `λ` tried in turn by [`Fairing::Auto`]: 0, then `10^{-4}` to `10^{3}` by factors of
/// `√10` (16 fits at most).
pub const FAIRING_LADDER: [f64; 16] = [
    0.0, 1e-4, 3.162e-4, 1e-3, 3.162e-3, 1e-2, 3.162e-2, 1e-1, 3.162e-1, 1.0, 3.162, 10.0, 31.62,
    100.0, 316.2, 1000.0,
];

/// Residuals of a fit at its samples.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FitReport {
    /// Number of samples.
    pub samples: usize,
    /// Root-mean-square distance `|x(u_k) − q_k|`.
    pub rms: f64,
    /// Largest distance `|x(u_k) − q_k|`.
    pub max: f64,
}

/// Parameters `u_0 = 0 ≤ … ≤ u_K = 1` of `points` (at least two, not all equal).
pub fn parameters(points: &[DVec2], kind: FitParameters) -> Result<Vec<f64>, BsplineError> {
    if points.len() < 2 {
        return Err(BsplineError::Fit(format!(
            "{} sample point(s), need at least 2",
            points.len()
        )));
    }
    let e = match kind {
        FitParameters::ChordLength => 1.0,
        FitParameters::Centripetal => 0.5,
    };
    let mut u = Vec::with_capacity(points.len());
    u.push(0.0);
    for w in points.windows(2) {
        let d = w[1].distance(w[0]).powf(e);
        u.push(u[u.len() - 1] + d);
    }
    let total = u[u.len() - 1];
    if !(total > 0.0 && total.is_finite()) {
        return Err(BsplineError::Fit(format!(
            "the sample polyline has length {total:e}"
        )));
    }
    for x in &mut u {
        *x /= total;
    }
    Ok(u)
}

/// `points` with every segment split into equal pieces no longer than `max_len`.
pub fn densify(points: &[DVec2], max_len: f64) -> Vec<DVec2> {
    let mut out = Vec::with_capacity(points.len());
    for w in points.windows(2) {
        out.push(w[0]);
        let d = w[1].distance(w[0]);
        let pieces = if max_len > 0.0 && d.is_finite() {
            (d / max_len).ceil().clamp(1.0, 1e6) as usize
        } else {
            1
        };
        for p in 1..pieces {
            out.push(w[0].lerp(w[1], p as f64 / pieces as f64));
        }
    }
    if let Some(&last) = points.last() {
        out.push(last);
    }
    out
}

/// Control points of the order-`order` curve on `knots` minimizing the squared residuals at the
/// given `(u_k, q_k)` plus `λ =` `fairing` times the second-difference penalty, the first and
/// last control points fixed to `q_0` and `q_K` (module docs).
pub fn fit_with_parameters(
    points: &[DVec2],
    params: &[f64],
    knots: &KnotVector,
    fairing: f64,
) -> Result<Vec<DVec2>, BsplineError> {
    if !(fairing >= 0.0 && fairing.is_finite()) {
        return Err(BsplineError::Fit(format!(
            "fairing weight {fairing} (need a finite λ ≥ 0)"
        )));
    }
    let n = knots.num_basis();
    let k = knots.order();
    if params.len() != points.len() || points.len() < 2 {
        return Err(BsplineError::Fit(format!(
            "{} points and {} parameters (need equal counts, at least 2)",
            points.len(),
            params.len()
        )));
    }
    if let Some(i) = points.iter().position(|p| !p.is_finite()) {
        return Err(BsplineError::NonFinite {
            what: "fit samples",
            index: i,
        });
    }
    if n < 2 {
        return Err(BsplineError::Fit(format!("{n} basis function(s)")));
    }
    let (q0, qk) = (points[0], points[points.len() - 1]);
    if n == 2 {
        return Ok(vec![q0, qk]);
    }
    let ni = n - 2; // unknowns P_1..P_{n−2}
    let mut ata = DMatrix::<f64>::zeros(ni, ni);
    let mut rhs = DMatrix::<f64>::zeros(ni, 2);
    let mut b = [0.0; MAX_ORDER];
    for (&u, &q) in params.iter().zip(points).skip(1).take(points.len() - 2) {
        let mu = knots.nonzero_basis(u, &mut b, None);
        let first = mu + 1 - k;
        let mut r = q;
        for a in 0..k {
            let i = first + a;
            if i == 0 {
                r -= b[a] * q0;
            } else if i == n - 1 {
                r -= b[a] * qk;
            }
        }
        for a in 0..k {
            let i = first + a;
            if i == 0 || i == n - 1 {
                continue;
            }
            rhs[(i - 1, 0)] += b[a] * r.x;
            rhs[(i - 1, 1)] += b[a] * r.y;
            for c in 0..k {
                let j = first + c;
                if j == 0 || j == n - 1 {
                    continue;
                }
                ata[(i - 1, j - 1)] += b[a] * b[c];
            }
        }
    }
    if fairing > 0.0 {
        // rows i = 1..n−2 of D: (1, −2, 1) on P_{i−1}, P_i, P_{i+1}; tr(DᵀD) = Σ_rows 6
        let w = fairing * ata.trace() / (6 * ni) as f64;
        let fixed = |j: usize| {
            if j == 0 {
                Some(q0)
            } else if j == n - 1 {
                Some(qk)
            } else {
                None
            }
        };
        for row in 1..n - 1 {
            let stencil = [(row - 1, 1.0), (row, -2.0), (row + 1, 1.0)];
            for &(a, ca) in &stencil {
                if fixed(a).is_some() {
                    continue;
                }
                for &(b, cb) in &stencil {
                    match fixed(b) {
                        Some(p) => {
                            rhs[(a - 1, 0)] -= w * ca * cb * p.x;
                            rhs[(a - 1, 1)] -= w * ca * cb * p.y;
                        }
                        None => ata[(a - 1, b - 1)] += w * ca * cb,
                    }
                }
            }
        }
    }
    let chol = ata.cholesky().ok_or_else(|| {
        BsplineError::Fit(format!(
            "the normal equations of {ni} interior control points are singular: some basis function is zero at every sample (too few samples for {n} control points)"
        ))
    })?;
    let sol = chol.solve(&rhs);
    let mut out = Vec::with_capacity(n);
    out.push(q0);
    for i in 0..ni {
        out.push(DVec2::new(sol[(i, 0)], sol[(i, 1)]));
    }
    out.push(qk);
    if let Some(i) = out.iter().position(|p| !p.is_finite()) {
        return Err(BsplineError::NonFinite {
            what: "fitted control points",
            index: i,
        });
    }
    Ok(out)
}

/// Residuals of control points `ctrl` on `knots` at the samples.
pub fn residuals(
    points: &[DVec2],
    params: &[f64],
    knots: &KnotVector,
    ctrl: &[DVec2],
) -> Result<FitReport, BsplineError> {
    let curve = crate::BSplineCurve::new(knots.clone(), ctrl.to_vec())?;
    let (mut s2, mut mx) = (0.0f64, 0.0f64);
    for (&u, &q) in params.iter().zip(points) {
        let d = curve.eval(u).distance(q);
        s2 += d * d;
        mx = mx.max(d);
    }
    let samples = points.len().min(params.len());
    Ok(FitReport {
        samples,
        rms: (s2 / samples.max(1) as f64).sqrt(),
        max: mx,
    })
}

/// The quadratic curve with `n ≥ 3` control points on the uniform knots (23) fitted to a
/// polyline (densified, then parametrized by `kind`) with fairing weight `λ =` `fairing`:
/// its control points and residuals.
pub fn fit_polyline(
    polyline: &[DVec2],
    n: usize,
    kind: FitParameters,
    fairing: f64,
) -> Result<(Vec<DVec2>, FitReport), BsplineError> {
    let knots = KnotVector::biquadratic(n)?;
    let len: f64 = polyline.windows(2).map(|w| w[1].distance(w[0])).sum();
    let pts = densify(polyline, len / (4.0 * (n.max(3) - 2) as f64));
    let u = parameters(&pts, kind)?;
    let ctrl = fit_with_parameters(&pts, &u, &knots, fairing)?;
    let rep = residuals(&pts, &u, &knots, &ctrl)?;
    Ok((ctrl, rep))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples of a known quadratic spline at known parameters give back its control points.
    #[test]
    fn recovers_a_known_spline() {
        let n = 9;
        let knots = KnotVector::biquadratic(n).unwrap();
        let ctrl: Vec<DVec2> = (0..n)
            .map(|i| {
                let t = i as f64;
                DVec2::new(t + 0.3 * (1.7 * t).sin(), (0.9 * t).cos() * 2.0 - 0.1 * t)
            })
            .collect();
        let curve = crate::BSplineCurve::new(knots.clone(), ctrl.clone()).unwrap();
        // irrational-ish, non-uniform parameters (several per span, ends included)
        let u: Vec<f64> = (0..=60)
            .map(|l| {
                let s = l as f64 / 60.0;
                s * s * (3.0 - 2.0 * s)
            })
            .collect();
        let q: Vec<DVec2> = u.iter().map(|&t| curve.eval(t)).collect();
        let got = fit_with_parameters(&q, &u, &knots, 0.0).unwrap();
        for (a, b) in got.iter().zip(&ctrl) {
            assert!(a.distance(*b) < 1e-9, "{a} vs {b}");
        }
    }

    /// A straight segment lies in the spline space (linear precision, control points at the
    /// Greville abscissae); chord-length parameters of equispaced samples are its own
    /// parameters, so the fit is exact: zero residual, Greville points on the line.
    #[test]
    fn straight_line_is_exact() {
        let (a, b) = (DVec2::new(1.0, -2.0), DVec2::new(4.0, 2.0));
        let q: Vec<DVec2> = (0..=40).map(|l| a.lerp(b, l as f64 / 40.0)).collect();
        let n = 7;
        let (ctrl, rep) = fit_polyline(&q, n, FitParameters::ChordLength, 0.0).unwrap();
        // knots (23) for n = 7: breakpoints l/5; Greville g_i = (t_{i+1} + t_{i+2})/2
        let g = [0.0, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0];
        for (p, gi) in ctrl.iter().zip(g) {
            assert!(p.distance(a.lerp(b, gi)) < 1e-12, "{p} vs {gi}");
        }
        assert!(rep.max < 1e-12);
    }

    /// Circle arc of radius R and angle θ, samples equispaced in angle (so chord-length
    /// parameters are u = φ/θ exactly). Competitor: Schoenberg's spline with control points
    /// f(g_i) (same end points). Taylor at t: |Vf − f| ≤ ½ sup|f''| Σ B_i(t)(g_i − t)², and for
    /// quadratics on knots (23) with spacing h = 1/(n−2): on interior spans the B_i-weighted
    /// variance of the g_i is h²/4, on the end spans (u/2 − u²/4)h² ≤ h²/4. With
    /// |f''| = Rθ²: max error ≤ Rθ²h²/8, so the least-squares RMS residual is ≤ Rθ²/(8(n−2)²).
    #[test]
    fn circle_arc_error_bound() {
        let (r, theta) = (3.0, 2.5);
        let q: Vec<DVec2> = (0..=200)
            .map(|l| {
                let p = theta * l as f64 / 200.0;
                DVec2::new(r * p.cos(), r * p.sin())
            })
            .collect();
        for n in [4usize, 6, 10, 20] {
            let (_, rep) = fit_polyline(&q, n, FitParameters::ChordLength, 0.0).unwrap();
            let bound = r * theta * theta / (8.0 * ((n - 2) * (n - 2)) as f64);
            assert!(rep.rms <= bound, "n = {n}: rms {} > bound {bound}", rep.rms);
            let (_, rc) = fit_polyline(&q, n, FitParameters::Centripetal, 0.0).unwrap();
            assert!(
                rc.rms <= bound,
                "centripetal n = {n}: rms {} > {bound}",
                rc.rms
            );
        }
    }

    /// Samples of a circle arc (radius 3, angle 2.5) equispaced in angle.
    fn arc_samples() -> Vec<DVec2> {
        (0..=200)
            .map(|l| {
                let p = 2.5 * l as f64 / 200.0;
                DVec2::new(3.0 * p.cos(), 3.0 * p.sin())
            })
            .collect()
    }

    /// As λ → ∞ only the penalty counts: `Σ|Δ²P|² = 0` with fixed ends has the unique
    /// minimizer `P_i = q_0 + i/(n−1)·(q_K − q_0)` (a linear sequence), whatever the samples.
    #[test]
    fn infinite_fairing_spaces_the_control_points_evenly_on_the_chord() {
        let q = arc_samples();
        let n = 9;
        let (ctrl, _) = fit_polyline(&q, n, FitParameters::ChordLength, 1e12).unwrap();
        let (a, b) = (q[0], q[q.len() - 1]);
        for (i, p) in ctrl.iter().enumerate() {
            let want = a.lerp(b, i as f64 / (n - 1) as f64);
            assert!(p.distance(want) < 1e-6, "P_{i} = {p}, want {want}");
        }
    }

    /// Penalized least squares: as λ grows the data term cannot decrease and the penalty
    /// cannot increase (compare the optimality of each solution at the other's λ).
    #[test]
    fn more_fairing_fits_worse_and_bends_less() {
        let q = arc_samples();
        let n = 10;
        let second_differences = |c: &[DVec2]| -> f64 {
            c.windows(3)
                .map(|w| (w[0] - 2.0 * w[1] + w[2]).length_squared())
                .sum()
        };
        let mut last: Option<(f64, f64)> = None;
        for &l in &FAIRING_LADDER {
            let (ctrl, rep) = fit_polyline(&q, n, FitParameters::ChordLength, l).unwrap();
            let (data, pen) = (rep.rms, second_differences(&ctrl));
            if let Some((d0, p0)) = last {
                assert!(data >= d0 - 1e-12, "λ = {l}: rms {data} < {d0}");
                assert!(pen <= p0 + 1e-12, "λ = {l}: penalty {pen} > {p0}");
            }
            last = Some((data, pen));
        }
        // and the ladder does change the fit: at λ = 1000 the arc is visibly flattened
        let (_, r0) = fit_polyline(&q, n, FitParameters::ChordLength, 0.0).unwrap();
        let (_, r1) = fit_polyline(&q, n, FitParameters::ChordLength, 1000.0).unwrap();
        assert!(r1.rms > 100.0 * r0.rms, "{} vs {}", r1.rms, r0.rms);
    }

    /// Both terms vanish in the direction normal to a straight segment, so a faired fit of
    /// collinear samples stays on the line.
    #[test]
    fn fairing_keeps_a_line_straight() {
        let (a, b) = (DVec2::new(1.0, -2.0), DVec2::new(4.0, 2.0));
        let q: Vec<DVec2> = (0..=40).map(|l| a.lerp(b, l as f64 / 40.0)).collect();
        let normal = (b - a).perp().normalize();
        for l in [0.01, 1.0, 100.0] {
            let (ctrl, _) = fit_polyline(&q, 7, FitParameters::Centripetal, l).unwrap();
            for p in &ctrl {
                assert!(
                    (*p - a).dot(normal).abs() < 1e-12,
                    "λ = {l}: {p} off the line"
                );
            }
        }
    }

    #[test]
    fn a_negative_or_nan_fairing_weight_is_a_typed_error() {
        let knots = KnotVector::biquadratic(5).unwrap();
        let q = arc_samples();
        let u = parameters(&q, FitParameters::ChordLength).unwrap();
        for l in [-1.0, f64::NAN, f64::INFINITY] {
            let e = fit_with_parameters(&q, &u, &knots, l).unwrap_err();
            assert!(matches!(e, BsplineError::Fit(_)), "{e}");
        }
    }

    #[test]
    fn too_few_samples_is_a_typed_error() {
        let knots = KnotVector::biquadratic(10).unwrap();
        let q = [DVec2::ZERO, DVec2::X, DVec2::ONE];
        let e = fit_with_parameters(&q, &[0.0, 0.5, 1.0], &knots, 0.0).unwrap_err();
        assert!(matches!(e, BsplineError::Fit(_)), "{e}");
        assert!(parameters(&[DVec2::ONE, DVec2::ONE], FitParameters::ChordLength).is_err());
    }
}
