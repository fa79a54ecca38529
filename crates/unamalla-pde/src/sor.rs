//! SOR with the automatic relaxation factor (crate docs of [`unamalla_pde`](crate)).

use super::stencil::Row;
use super::{PdeError, SolveOptions};

/// What SOR did.
pub(crate) struct SorReport {
    pub iterations: usize,
    pub omega: f64,
    pub rho_jacobi: Option<f64>,
}

/// Largest Jacobi spectral radius used for ω (keeps `1 − μ²` away from 0).
const MU_MAX: f64 = 1.0 - 1e-12;
/// Hageman–Young damping exponent `F` of the test `r > (ω − 1)^F`.
const HY_F: f64 = 0.65;

/// Young's optimal factor for a Jacobi spectral radius `mu`.
pub(crate) fn young_omega(mu: f64) -> f64 {
    let mu = mu.clamp(0.0, MU_MAX);
    2.0 / (1.0 + (1.0 - mu * mu).sqrt())
}

/// Power-method estimate of the spectral radius of the Jacobi iteration matrix
/// `B = I − D⁻¹A` (homogeneous Dirichlet data), in the norm `‖v‖² = Σ |A_ii| v_i²`, for which
/// `B` is self-adjoint when `A` is symmetric, so `‖Bv‖/‖v‖` increases to `ρ(B)` even when
/// `±ρ` are both eigenvalues.
///
/// Returns the estimate and whether it converged (relative change ≤ 1e-10 between two
/// iterations) within `max_it` iterations.
pub(crate) fn jacobi_rho(rows: &[Row], start: &[f64], max_it: usize) -> (f64, bool) {
    let n = start.len();
    let mut v = vec![0.0; n];
    for r in rows {
        v[r.node] = start[r.node];
    }
    let norm = |v: &[f64]| -> f64 {
        rows.iter()
            .map(|r| r.diag.abs() * v[r.node] * v[r.node])
            .sum::<f64>()
            .sqrt()
    };
    let mut nv0 = norm(&v);
    if nv0.is_nan() || nv0 <= 0.0 {
        for r in rows {
            v[r.node] = 1.0;
        }
        nv0 = norm(&v);
    }
    if nv0.is_nan() || nv0 <= 0.0 {
        return (0.0, true);
    }
    for r in rows {
        v[r.node] /= nv0;
    }
    let mut next = vec![0.0; n];
    let mut est = 0.0;
    for k in 0..max_it {
        for r in rows {
            next[r.node] = -r.off_diagonal(&v) / r.diag;
        }
        let nn = norm(&next);
        if !nn.is_finite() || nn <= 0.0 {
            return (est, true);
        }
        let prev = est;
        est = nn;
        for r in rows {
            v[r.node] = next[r.node] / nn;
        }
        if k > 5 && (est - prev).abs() <= 1e-10 * est {
            return (est, true);
        }
    }
    (est, false)
}

/// Runs SOR in place on `u` (boundary entries hold the Dirichlet data and are not touched).
pub(crate) fn solve(
    rows: &[Row],
    u: &mut [f64],
    omega: Option<f64>,
    start: &[f64],
    opts: &SolveOptions,
) -> Result<SorReport, PdeError> {
    // the power-method estimate; when it has not converged it is a lower bound and is
    // refined during the iteration
    let (mut mu, mut w, rho, adaptive) = match omega {
        Some(w) => (0.0, w, None, false),
        None => {
            let (mu, converged) = jacobi_rho(rows, start, 500);
            let mu = mu.min(MU_MAX);
            (mu, young_omega(mu), Some(mu), !converged)
        }
    };
    let bmax = {
        let mut is_row = vec![false; u.len()];
        for r in rows {
            is_row[r.node] = true;
        }
        u.iter()
            .zip(&is_row)
            .filter(|(_, &b)| !b)
            .map(|(v, _)| v.abs())
            .fold(0.0, f64::max)
    };
    let mut history: Vec<f64> = Vec::new();
    let mut first = None;
    let mut last = f64::INFINITY;
    // before an adaptive increase of ω: (ω, μ, iterate) to fall back to if the new ω does
    // not contract (the 9-point and non-symmetric stencils are outside Young's theory)
    let mut fallback: Option<(f64, f64, Vec<f64>)> = None;
    let mut adaptive = adaptive;
    for it in 1..=opts.max_iterations {
        let mut maxd: f64 = 0.0;
        let mut sum2 = 0.0;
        let mut umax = bmax;
        for r in rows {
            let gs = (r.rhs - r.off_diagonal(u)) / r.diag;
            let delta = gs - u[r.node];
            let nu = u[r.node] + w * delta;
            u[r.node] = nu;
            maxd = maxd.max(delta.abs());
            sum2 += delta * delta;
            umax = umax.max(nu.abs());
        }
        last = maxd;
        let f = *first.get_or_insert(maxd.max(f64::MIN_POSITIVE));
        let diverging = !maxd.is_finite() || !umax.is_finite() || maxd > 1e12 * f.max(1.0);
        let stalled = adaptive
            && history.len() >= 30
            && history.len().is_multiple_of(10)
            && history[history.len() - 1] >= history[history.len() - 11];
        if diverging || stalled {
            if let Some((w0, mu0, u0)) = fallback.take() {
                // undo the last increase and stop adapting
                w = w0;
                mu = mu0;
                u.copy_from_slice(&u0);
                adaptive = false;
                history.clear();
                continue;
            }
        }
        if diverging {
            return Err(PdeError::SorDiverged {
                iteration: it,
                omega: w,
                correction: maxd,
            });
        }
        if maxd <= opts.tol * umax.max(1.0) {
            return Ok(SorReport {
                iterations: it,
                omega: w,
                rho_jacobi: rho.map(|_| mu),
            });
        }
        if adaptive {
            history.push(sum2.sqrt());
            // windows of ≥ 30 sweeps since the last change: near the optimum the SOR matrix
            // has 2 × 2 Jordan blocks, whose transient k·λᵏ would inflate a short-window ratio
            let h = history.len();
            if h >= 30 && h.is_multiple_of(10) {
                let r = (history[h - 1] / history[h - 11]).powf(0.1);
                if r < 1.0 && r > (w - 1.0).max(0.0).powf(HY_F) {
                    let mu_hat = (r + w - 1.0) / (w * r.sqrt());
                    if mu_hat > mu && mu_hat < 1.0 {
                        fallback = Some((w, mu, u.to_vec()));
                        mu = mu_hat.min(MU_MAX);
                        w = young_omega(mu);
                        history.clear();
                    }
                }
            }
        }
    }
    Err(PdeError::NotConverged {
        iterations: opts.max_iterations,
        correction: last,
        omega: w,
    })
}

#[cfg(test)]
mod tests {
    use unamalla_mesh::{DVec2, HasNodes, StructuredGrid2};

    use super::super::stencil::{assemble, grid_patches};
    use super::super::{Equation, Source};
    use super::*;

    #[test]
    fn jacobi_radius_of_the_laplacian_on_a_rectangle() {
        // 5-point Laplacian on an m × n rectangle grid with spacings hx, hy: Jacobi eigenvalues
        // (hy²cos(pπ/(m−1)) + hx²cos(qπ/(n−1)))/(hx² + hy²), largest at p = q = 1.
        let (m, n) = (31, 21);
        let (hx, hy) = (0.1, 0.07);
        let g = StructuredGrid2::from_fn(m, n, |i, j| DVec2::new(hx * i as f64, hy * j as f64))
            .unwrap();
        let patches = grid_patches(m, n);
        let rows = assemble(
            g.nodes(),
            &patches,
            &Equation::poisson(Source::Constant(0.0)),
            &vec![0.0; patches.len()],
        )
        .unwrap();
        let pi = std::f64::consts::PI;
        let exact = (hy * hy * (pi / (m - 1) as f64).cos() + hx * hx * (pi / (n - 1) as f64).cos())
            / (hx * hx + hy * hy);
        // the structured start vector is the exact eigenvector: converged at once
        let start: Vec<f64> = (0..m * n)
            .map(|k| {
                (pi * (k % m) as f64 / (m - 1) as f64).sin()
                    * (pi * (k / m) as f64 / (n - 1) as f64).sin()
            })
            .collect();
        let (est, converged) = jacobi_rho(&rows, &start, 500);
        assert!(converged);
        assert!((est - exact).abs() < 1e-10, "{est} vs {exact}");
        // from a constant start the estimate is below ρ and approaches it
        let (est1, _) = jacobi_rho(&rows, &vec![1.0; m * n], 500);
        assert!(
            est1 <= exact + 1e-12 && est1 > exact - 1e-3,
            "{est1} vs {exact}"
        );
    }

    #[test]
    fn young_factor() {
        // μ = 0 → Gauss–Seidel; μ = 0.8 → 2/(1+0.6) = 1.25
        assert_eq!(young_omega(0.0), 1.0);
        assert!((young_omega(0.8) - 1.25).abs() < 1e-15);
    }
}
