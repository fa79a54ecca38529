//! Minimum-perimeter polygon (MPP) noise reduction, [Méndez 2023, §3.2.2, (3.2)]:
//!
//! ```text
//!   min  Σ_i |u_{i+1} − u_i|    subject to  ‖u_i − v_i‖_∞ ≤ h = p₀·δ,  i = 1..n (cyclic)
//! ```
//!
//! where `v_i` are the input vertices and `p₀` the input perimeter. The objective is convex but
//! **not** smooth (nor quadratic, as the thesis calls it): a norm is not differentiable where an edge has zero
//! length, which is exactly where the optimum tends to go when boxes overlap.
//!
//! **Solver.** We minimise the smoothed perimeter `f_η(u) = Σ √(|u_{i+1} − u_i|² + η²)` — convex,
//! C^∞, with gradient Lipschitz constant ≤ 4/η — over the box with the *spectral projected
//! gradient* method (SPG2 of Birgin, Martínez & Raydan, SIAM J. Optim. 10 (2000), with the
//! non-monotone Armijo line search, memory 10). Projection onto the box is a clamp, so each
//! iteration is O(n). For a convex smooth objective over a closed convex set SPG converges to
//! the global minimiser; since `0 ≤ f_η − f ≤ nη`, the minimiser of `f_η` is within `nη` of the
//! optimal perimeter. We use continuation `η = h, h/10, h/100` (warm-started), which keeps
//! early iterations well conditioned. Stopping test: the projected-gradient step
//! `‖P(w − ∇f) − w‖_∞` in box units `w = (u − v)/h` below `tol` (default 1e-6), or 1000
//! iterations per level (every iterate is feasible, so an early stop still gives a valid,
//! shorter polygon; it only leaves some noise in place). A hand-written
//! solver is used because `argmin` has no bound-constrained quasi-Newton method and the
//! problem's structure (separable box, O(n) gradient) makes SPG both simple and fast.

use glam::DVec2;

use crate::error::ContourError;

/// Tuning of the MPP solver.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct MppOptions {
    /// Stopping tolerance on the projected-gradient step, in units of the box half-width.
    pub tol: f64,
    /// Maximum SPG iterations per smoothing level.
    pub max_iter: usize,
    /// Number of smoothing levels: η = h·10^(−k), k = 0..levels.
    pub levels: usize,
}

impl Default for MppOptions {
    fn default() -> Self {
        Self {
            tol: 1e-6,
            max_iter: 1000,
            levels: 3,
        }
    }
}

impl MppOptions {
    /// Sets [`tol`](Self::tol).
    #[must_use]
    pub fn tol(mut self, tol: f64) -> Self {
        self.tol = tol;
        self
    }

    /// Sets [`max_iter`](Self::max_iter): maximum SPG iterations per smoothing level.
    #[must_use]
    pub fn max_iter(mut self, max_iter: usize) -> Self {
        self.max_iter = max_iter;
        self
    }

    /// Sets [`levels`](Self::levels): number of smoothing levels: η = h·10^(−k), k = 0..levels.
    #[must_use]
    pub fn levels(mut self, levels: usize) -> Self {
        self.levels = levels;
        self
    }
}

/// Outcome of an MPP solve.
#[derive(Debug, Clone, PartialEq)]
pub struct MppResult {
    /// The moved vertices `u_i` (same count and order as the input).
    pub points: Vec<DVec2>,
    /// Box half-width `h = p₀·δ`.
    pub half_width: f64,
    /// Perimeter of the input.
    pub perimeter_before: f64,
    /// Perimeter of the output.
    pub perimeter_after: f64,
    /// Total SPG iterations over all smoothing levels.
    pub iterations: usize,
}

fn perimeter(p: &[DVec2]) -> f64 {
    let n = p.len();
    (0..n).map(|i| p[i].distance(p[(i + 1) % n])).sum()
}

/// Solves (3.2) for the closed ring `ring` with factor `delta` (box half-width `h = p₀·δ` in
/// the L∞ norm). `delta = 0` returns the input. Errors: fewer than 3 points, non-finite
/// coordinates, zero perimeter, or a negative / non-finite `delta`.
pub fn minimum_perimeter_polygon(
    ring: &[DVec2],
    delta: f64,
    opts: &MppOptions,
) -> Result<MppResult, ContourError> {
    if !(delta.is_finite() && delta >= 0.0) {
        return Err(ContourError::InvalidParameter {
            name: "delta",
            value: delta,
            reason: "must be finite and >= 0",
        });
    }
    let n = ring.len();
    if n < 3 {
        return Err(ContourError::DegenerateRing(format!(
            "{n} point(s); a ring needs at least 3"
        )));
    }
    if let Some(k) = ring.iter().position(|p| !p.is_finite()) {
        return Err(ContourError::DegenerateRing(format!(
            "vertex {k} has a non-finite coordinate"
        )));
    }
    let p0 = perimeter(ring);
    if !(p0 > 0.0 && p0.is_finite()) {
        return Err(ContourError::DegenerateRing("zero perimeter".into()));
    }
    let h = p0 * delta;
    if h == 0.0 {
        return Ok(MppResult {
            points: ring.to_vec(),
            half_width: 0.0,
            perimeter_before: p0,
            perimeter_after: p0,
            iterations: 0,
        });
    }
    // variables w ∈ [−1, 1]^{2n}, u_i = v_i + h w_i; objective F(w) = f_η(u)/h, ∇_w F = ∇_u f_η
    let mut w = vec![DVec2::ZERO; n];
    let mut iterations = 0;
    for level in 0..opts.levels.max(1) {
        let eta = h * 10f64.powi(-(level as i32));
        iterations += spg(ring, h, eta / h, &mut w, opts);
    }
    let points: Vec<DVec2> = ring.iter().zip(&w).map(|(&v, &wi)| v + h * wi).collect();
    Ok(MppResult {
        perimeter_after: perimeter(&points),
        points,
        half_width: h,
        perimeter_before: p0,
        iterations,
    })
}

/// Smoothed objective in box units: Σ √(|Δv/h + Δw|² + η̂²), η̂ = η/h, and its gradient.
fn eval(v: &[DVec2], h: f64, eta: f64, w: &[DVec2], grad: Option<&mut Vec<DVec2>>) -> f64 {
    let n = v.len();
    let e2 = eta * eta;
    let mut f = 0.0;
    match grad {
        Some(g) => {
            g.iter_mut().for_each(|x| *x = DVec2::ZERO);
            for i in 0..n {
                let j = (i + 1) % n;
                let d = (v[j] - v[i]) / h + (w[j] - w[i]);
                let s = (d.length_squared() + e2).sqrt();
                f += s;
                let t = d / s;
                g[j] += t;
                g[i] -= t;
            }
        }
        None => {
            for i in 0..n {
                let j = (i + 1) % n;
                let d = (v[j] - v[i]) / h + (w[j] - w[i]);
                f += (d.length_squared() + e2).sqrt();
            }
        }
    }
    f
}

#[inline]
fn clamp_box(x: DVec2) -> DVec2 {
    x.clamp(DVec2::splat(-1.0), DVec2::splat(1.0))
}

/// SPG2 with non-monotone line search; returns the number of iterations.
fn spg(v: &[DVec2], h: f64, eta: f64, w: &mut [DVec2], opts: &MppOptions) -> usize {
    const MEMORY: usize = 10;
    const GAMMA: f64 = 1e-4;
    const LMIN: f64 = 1e-12;
    const LMAX: f64 = 1e12;
    let n = v.len();
    let mut g = vec![DVec2::ZERO; n];
    let mut f = eval(v, h, eta, w, Some(&mut g));
    let mut hist = std::collections::VecDeque::with_capacity(MEMORY);
    hist.push_back(f);
    // initial spectral step: 1/‖P(w − g) − w‖_∞ (BMR recommendation)
    let pg_norm = |w: &[DVec2], g: &[DVec2]| {
        w.iter()
            .zip(g)
            .map(|(&wi, &gi)| (clamp_box(wi - gi) - wi).abs().max_element())
            .fold(0.0f64, f64::max)
    };
    let first = pg_norm(w, &g);
    if first <= opts.tol {
        return 0;
    }
    let mut lambda = (1.0 / first).clamp(LMIN, LMAX);
    let mut d = vec![DVec2::ZERO; n];
    let mut wn = vec![DVec2::ZERO; n];
    let mut gn = vec![DVec2::ZERO; n];
    for it in 0..opts.max_iter {
        let mut gtd = 0.0;
        for i in 0..n {
            d[i] = clamp_box(w[i] - lambda * g[i]) - w[i];
            gtd += g[i].dot(d[i]);
        }
        let fmax = hist.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mut alpha = 1.0;
        let mut fnew;
        loop {
            for i in 0..n {
                wn[i] = w[i] + alpha * d[i];
            }
            fnew = eval(v, h, eta, &wn, None);
            if fnew <= fmax + GAMMA * alpha * gtd || alpha < 1e-12 {
                break;
            }
            // safeguarded quadratic interpolation
            let at = -0.5 * alpha * alpha * gtd / (fnew - f - alpha * gtd);
            alpha = if at >= 0.1 * alpha && at <= 0.9 * alpha {
                at
            } else {
                0.5 * alpha
            };
        }
        let fn2 = eval(v, h, eta, &wn, Some(&mut gn));
        let (mut ss, mut sy) = (0.0, 0.0);
        for i in 0..n {
            let s = wn[i] - w[i];
            ss += s.length_squared();
            sy += s.dot(gn[i] - g[i]);
        }
        w.copy_from_slice(&wn);
        std::mem::swap(&mut g, &mut gn);
        f = fn2;
        if hist.len() == MEMORY {
            hist.pop_front();
        }
        hist.push_back(f);
        lambda = if sy <= 0.0 {
            LMAX
        } else {
            (ss / sy).clamp(LMIN, LMAX)
        };
        if pg_norm(w, &g) <= opts.tol || ss == 0.0 {
            return it + 1;
        }
    }
    opts.max_iter
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zigzag_straightens_inside_the_boxes() {
        // a rectangle 100 × 50 whose bottom side zigzags by ±0.01; boxes are wide enough
        // (h = p0·δ ≥ 0.3 · 1e-2·…) to flatten the zigzag completely
        let mut ring = Vec::new();
        for k in 0..=100 {
            let y = if k % 2 == 0 { 0.01 } else { -0.01 };
            ring.push(DVec2::new(
                k as f64,
                if k == 0 || k == 100 { 0.0 } else { y },
            ));
        }
        ring.push(DVec2::new(100., 50.));
        ring.push(DVec2::new(0., 50.));
        let p0 = perimeter(&ring);
        let delta = 0.05 / p0; // h = 0.05 > zigzag amplitude
        let res = minimum_perimeter_polygon(&ring, delta, &MppOptions::default()).unwrap();
        assert!((res.half_width - 0.05).abs() < 1e-12);
        // every vertex stays in its box
        for (u, v) in res.points.iter().zip(&ring) {
            assert!((*u - *v).abs().max_element() <= res.half_width * (1.0 + 1e-12));
        }
        // the perimeter cannot beat the perimeter of the inset rectangle (corners move by ≤ h)
        // and must be within n·η_final of it; the zigzag contributed ≈ 100·(√(1+0.02²) − 1)
        let lower = 2.0 * (100.0 - 2.0 * 0.05) + 2.0 * (50.0 - 2.0 * 0.05);
        assert!(res.perimeter_after >= lower - 1e-9);
        assert!(
            res.perimeter_after <= 300.0 + 1e-3,
            "{}",
            res.perimeter_after
        );
        // bottom vertices become collinear (deviation far below the zigzag amplitude)
        let ys: Vec<f64> = res.points[1..100].iter().map(|p| p.y).collect();
        let spread = ys.iter().cloned().fold(f64::MIN, f64::max)
            - ys.iter().cloned().fold(f64::MAX, f64::min);
        // peak-to-peak of the input zigzag is 0.02; the MPP flattens it by at least 10×
        assert!(spread < 2e-3, "spread {spread}");
    }

    #[test]
    fn rejects_bad_input() {
        let sq = [DVec2::ZERO, DVec2::X, DVec2::ONE];
        assert!(minimum_perimeter_polygon(&sq, -1.0, &MppOptions::default()).is_err());
        assert!(minimum_perimeter_polygon(&sq[..2], 0.1, &MppOptions::default()).is_err());
        let same = [DVec2::ONE; 3];
        assert!(minimum_perimeter_polygon(&same, 0.1, &MppOptions::default()).is_err());
        let r = minimum_perimeter_polygon(&sq, 0.0, &MppOptions::default()).unwrap();
        assert_eq!(r.points, sq.to_vec());
    }
}
