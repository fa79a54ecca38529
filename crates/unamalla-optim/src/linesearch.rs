//! Moré–Thuente line search: a port of MINPACK-2 `dcsrch`/`dcstep` (Moré & Thuente 1994),
//! the line search UNAMALLA 2.0 used ([González Flores, App. B]), whose info codes are the
//! line-search messages of [González Flores, Table A.2].
//!
//! Written here rather than taken from `argmin` because (a) trial points outside the admissible set
//! (the convexity safeguard) must be rejected by bisection toward the best point, which `argmin`'s
//! `MoreThuente` cannot express, (b) it must never panic (older argmin releases panicked with "not
//! a descent direction"; 0.11 returns an error), and (c) its failure codes map one-to-one onto the
//! UNAMALLA status messages.

use crate::status::LineSearchFailure;

/// Parameters of the Moré–Thuente search.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct LineSearchParams {
    /// Sufficient-decrease constant `μ` (Armijo).
    pub ftol: f64,
    /// Curvature constant `η` (strong Wolfe).
    pub gtol: f64,
    /// Relative tolerance on the interval of uncertainty.
    pub xtol: f64,
    /// Smallest step.
    pub stpmin: f64,
    /// Largest step.
    pub stpmax: f64,
    /// Maximum number of function evaluations.
    pub maxfev: usize,
}

impl Default for LineSearchParams {
    fn default() -> Self {
        Self {
            ftol: 1e-4,
            gtol: 0.9,
            xtol: 1e-12,
            stpmin: 1e-20,
            stpmax: 1e20,
            maxfev: 20,
        }
    }
}

impl LineSearchParams {
    /// Sets [`ftol`](Self::ftol): sufficient-decrease constant `μ` (Armijo).
    #[must_use]
    pub fn ftol(mut self, ftol: f64) -> Self {
        self.ftol = ftol;
        self
    }

    /// Sets [`gtol`](Self::gtol): curvature constant `η` (strong Wolfe).
    #[must_use]
    pub fn gtol(mut self, gtol: f64) -> Self {
        self.gtol = gtol;
        self
    }

    /// Sets [`xtol`](Self::xtol): relative tolerance on the interval of uncertainty.
    #[must_use]
    pub fn xtol(mut self, xtol: f64) -> Self {
        self.xtol = xtol;
        self
    }

    /// Sets [`stpmin`](Self::stpmin): smallest step.
    #[must_use]
    pub fn stpmin(mut self, stpmin: f64) -> Self {
        self.stpmin = stpmin;
        self
    }

    /// Sets [`stpmax`](Self::stpmax): largest step.
    #[must_use]
    pub fn stpmax(mut self, stpmax: f64) -> Self {
        self.stpmax = stpmax;
        self
    }

    /// Sets [`maxfev`](Self::maxfev): maximum number of function evaluations.
    #[must_use]
    pub fn maxfev(mut self, maxfev: usize) -> Self {
        self.maxfev = maxfev;
        self
    }
}

/// The outcome of a line search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineSearchResult {
    /// Accepted step (0 if none).
    pub stp: f64,
    /// `φ(stp)`.
    pub f: f64,
    /// `φ′(stp)`.
    pub g: f64,
    /// Function evaluations used.
    pub nfev: usize,
    /// `None` if the strong Wolfe conditions hold at `stp`; otherwise the MINPACK-2 warning.
    /// With a warning, `stp > 0` means the best point found (which satisfies sufficient
    /// decrease) was accepted and the closure was last evaluated there.
    pub warning: Option<LineSearchFailure>,
}

/// Searches `φ(t) = F(x + t·d)` from `t = stp0`, with `φ(0) = f0`, `φ′(0) = g0 < 0`.
/// `phi(t)` returns `Some((φ(t), φ′(t)))`, or `None` if `x + t·d` is not admissible (safeguard)
/// or the value is not finite. On return, the closure was last called at the returned step
/// (if it is positive).
pub fn more_thuente<F>(
    mut phi: F,
    f0: f64,
    g0: f64,
    stp0: f64,
    p: &LineSearchParams,
) -> LineSearchResult
where
    F: FnMut(f64) -> Option<(f64, f64)>,
{
    let fail = |w| LineSearchResult {
        stp: 0.0,
        f: f0,
        g: g0,
        nfev: 0,
        warning: Some(w),
    };
    if g0.partial_cmp(&0.0) != Some(std::cmp::Ordering::Less) || !f0.is_finite() {
        return fail(LineSearchFailure::Rounding);
    }
    if p.stpmax.is_nan() || p.stpmin.is_nan() || p.stpmax < p.stpmin {
        return fail(LineSearchFailure::StpMax);
    }
    let mut stp = stp0.max(p.stpmin).min(p.stpmax);
    if !stp.is_finite() {
        return fail(LineSearchFailure::StpMax);
    }
    let (xtrapl, xtrapu) = (1.1, 4.0);
    let mut brackt = false;
    let mut stage = 1;
    let finit = f0;
    let ginit = g0;
    let gtest = p.ftol * ginit;
    let mut width = p.stpmax - p.stpmin;
    let mut width1 = width / 0.5;
    let (mut stx, mut fx, mut gx) = (0.0, finit, ginit);
    let (mut sty, mut fy, mut gy) = (0.0, finit, ginit);
    let mut stmin = 0.0;
    let mut stmax = stp + xtrapu * stp;
    let mut cap = f64::INFINITY;
    let mut nfev = 0;
    let mut last_eval = 0.0;

    let finish = |phi: &mut F, stx: f64, fx: f64, gx: f64, last: f64, nfev: usize, w| {
        // return the best point found (re-evaluated if it was not the last evaluation)
        if stx > 0.0 {
            let mut n = nfev;
            let (f, g) = if last != stx {
                n += 1;
                phi(stx).unwrap_or((fx, gx))
            } else {
                (fx, gx)
            };
            LineSearchResult {
                stp: stx,
                f,
                g,
                nfev: n,
                warning: Some(w),
            }
        } else {
            LineSearchResult {
                stp: 0.0,
                f: finit,
                g: ginit,
                nfev,
                warning: Some(w),
            }
        }
    };

    loop {
        if nfev >= p.maxfev {
            return finish(
                &mut phi,
                stx,
                fx,
                gx,
                last_eval,
                nfev,
                LineSearchFailure::MaxFev,
            );
        }
        nfev += 1;
        last_eval = stp;
        let (f, g) = match phi(stp) {
            Some(v) if v.0.is_finite() && v.1.is_finite() => v,
            _ => {
                // inadmissible trial: bisect toward the best point
                cap = cap.min(stp);
                let next = if stx < cap {
                    stx + 0.5 * (cap - stx)
                } else {
                    0.5 * cap
                };
                if (next - stx).abs() <= p.xtol * next.abs().max(f64::MIN_POSITIVE)
                    || next < p.stpmin
                {
                    return finish(
                        &mut phi,
                        stx,
                        fx,
                        gx,
                        last_eval,
                        nfev,
                        LineSearchFailure::Rounding,
                    );
                }
                stp = next;
                stmax = stmax.min(cap);
                continue;
            }
        };
        let ftest = finit + stp * gtest;
        if stage == 1 && f <= ftest && g >= 0.0 {
            stage = 2;
        }
        let mut warn = None;
        if brackt && (stp <= stmin || stp >= stmax) {
            warn = Some(LineSearchFailure::Rounding);
        }
        if brackt && stmax - stmin <= p.xtol * stmax {
            warn = Some(LineSearchFailure::Xtol);
        }
        if stp == p.stpmax && f <= ftest && g <= gtest {
            warn = Some(LineSearchFailure::StpMax);
        }
        if stp == p.stpmin && (f > ftest || g >= gtest) {
            warn = Some(LineSearchFailure::StpMin);
        }
        if f <= ftest && g.abs() <= p.gtol * (-ginit) {
            return LineSearchResult {
                stp,
                f,
                g,
                nfev,
                warning: None,
            };
        }
        if let Some(w) = warn {
            // prefer the current point if it satisfies sufficient decrease and beats stx
            if f <= ftest && f <= fx {
                return LineSearchResult {
                    stp,
                    f,
                    g,
                    nfev,
                    warning: Some(w),
                };
            }
            return finish(&mut phi, stx, fx, gx, last_eval, nfev, w);
        }
        if stage == 1 && f <= fx && f > ftest {
            let fm = f - stp * gtest;
            let mut fxm = fx - stx * gtest;
            let mut fym = fy - sty * gtest;
            let gm = g - gtest;
            let mut gxm = gx - gtest;
            let mut gym = gy - gtest;
            dcstep(
                &mut stx,
                &mut fxm,
                &mut gxm,
                &mut sty,
                &mut fym,
                &mut gym,
                &mut stp,
                fm,
                gm,
                &mut brackt,
                stmin,
                stmax,
            );
            fx = fxm + stx * gtest;
            fy = fym + sty * gtest;
            gx = gxm + gtest;
            gy = gym + gtest;
        } else {
            dcstep(
                &mut stx,
                &mut fx,
                &mut gx,
                &mut sty,
                &mut fy,
                &mut gy,
                &mut stp,
                f,
                g,
                &mut brackt,
                stmin,
                stmax,
            );
        }
        if brackt {
            if (sty - stx).abs() >= 0.66 * width1 {
                stp = stx + 0.5 * (sty - stx);
            }
            width1 = width;
            width = (sty - stx).abs();
        }
        if brackt {
            stmin = stx.min(sty);
            stmax = stx.max(sty);
        } else {
            stmin = stp + xtrapl * (stp - stx);
            stmax = stp + xtrapu * (stp - stx);
        }
        stp = stp.max(p.stpmin).min(p.stpmax);
        if brackt && (stp <= stmin || stp >= stmax || stmax - stmin <= p.xtol * stmax) {
            stp = stx;
        }
        if stp >= cap {
            stp = if stx < cap {
                stx + 0.5 * (cap - stx)
            } else {
                0.5 * cap
            };
        }
        if !stp.is_finite() {
            return finish(
                &mut phi,
                stx,
                fx,
                gx,
                last_eval,
                nfev,
                LineSearchFailure::Rounding,
            );
        }
    }
}

/// MINPACK-2 `dcstep`: safeguarded cubic/quadratic step and interval update.
#[allow(clippy::too_many_arguments)]
fn dcstep(
    stx: &mut f64,
    fx: &mut f64,
    dx: &mut f64,
    sty: &mut f64,
    fy: &mut f64,
    dy: &mut f64,
    stp: &mut f64,
    fp: f64,
    dp: f64,
    brackt: &mut bool,
    stpmin: f64,
    stpmax: f64,
) {
    let sgnd = dp * (*dx / dx.abs());
    let stpf;
    if fp > *fx {
        let theta = 3.0 * (*fx - fp) / (*stp - *stx) + *dx + dp;
        let s = theta.abs().max(dx.abs()).max(dp.abs());
        let mut gamma = s * ((theta / s).powi(2) - (*dx / s) * (dp / s)).max(0.0).sqrt();
        if *stp < *stx {
            gamma = -gamma;
        }
        let p = (gamma - *dx) + theta;
        let q = ((gamma - *dx) + gamma) + dp;
        let r = p / q;
        let stpc = *stx + r * (*stp - *stx);
        let stpq = *stx + ((*dx / ((*fx - fp) / (*stp - *stx) + *dx)) / 2.0) * (*stp - *stx);
        stpf = if (stpc - *stx).abs() < (stpq - *stx).abs() {
            stpc
        } else {
            stpc + (stpq - stpc) / 2.0
        };
        *brackt = true;
    } else if sgnd < 0.0 {
        let theta = 3.0 * (*fx - fp) / (*stp - *stx) + *dx + dp;
        let s = theta.abs().max(dx.abs()).max(dp.abs());
        let mut gamma = s * ((theta / s).powi(2) - (*dx / s) * (dp / s)).max(0.0).sqrt();
        if *stp > *stx {
            gamma = -gamma;
        }
        let p = (gamma - dp) + theta;
        let q = ((gamma - dp) + gamma) + *dx;
        let r = p / q;
        let stpc = *stp + r * (*stx - *stp);
        let stpq = *stp + (dp / (dp - *dx)) * (*stx - *stp);
        stpf = if (stpc - *stp).abs() > (stpq - *stp).abs() {
            stpc
        } else {
            stpq
        };
        *brackt = true;
    } else if dp.abs() < dx.abs() {
        let theta = 3.0 * (*fx - fp) / (*stp - *stx) + *dx + dp;
        let s = theta.abs().max(dx.abs()).max(dp.abs());
        let mut gamma = s * ((theta / s).powi(2) - (*dx / s) * (dp / s)).max(0.0).sqrt();
        if *stp > *stx {
            gamma = -gamma;
        }
        let p = (gamma - dp) + theta;
        let q = (gamma + (*dx - dp)) + gamma;
        let r = p / q;
        let stpc = if r < 0.0 && gamma != 0.0 {
            *stp + r * (*stx - *stp)
        } else if *stp > *stx {
            stpmax
        } else {
            stpmin
        };
        let stpq = *stp + (dp / (dp - *dx)) * (*stx - *stp);
        if *brackt {
            let mut v = if (stpc - *stp).abs() < (stpq - *stp).abs() {
                stpc
            } else {
                stpq
            };
            if *stp > *stx {
                v = v.min(*stp + 0.66 * (*sty - *stp));
            } else {
                v = v.max(*stp + 0.66 * (*sty - *stp));
            }
            stpf = v;
        } else {
            let v = if (stpc - *stp).abs() > (stpq - *stp).abs() {
                stpc
            } else {
                stpq
            };
            stpf = v.min(stpmax).max(stpmin);
        }
    } else if *brackt {
        let theta = 3.0 * (fp - *fy) / (*sty - *stp) + *dy + dp;
        let s = theta.abs().max(dy.abs()).max(dp.abs());
        let mut gamma = s * ((theta / s).powi(2) - (*dy / s) * (dp / s)).max(0.0).sqrt();
        if *stp > *sty {
            gamma = -gamma;
        }
        let p = (gamma - dp) + theta;
        let q = ((gamma - dp) + gamma) + *dy;
        let r = p / q;
        stpf = *stp + r * (*sty - *stp);
    } else if *stp > *stx {
        stpf = stpmax;
    } else {
        stpf = stpmin;
    }
    if fp > *fx {
        *sty = *stp;
        *fy = fp;
        *dy = dp;
    } else {
        if sgnd < 0.0 {
            *sty = *stx;
            *fy = *fx;
            *dy = *dx;
        }
        *stx = *stp;
        *fx = fp;
        *dx = dp;
    }
    *stp = stpf;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_wolfe_point_of_a_quartic() {
        // φ(t) = (t − 2)⁴ − 16: φ(0) = 0, φ′(0) = −32
        let phi = |t: f64| Some(((t - 2.0).powi(4) - 16.0, 4.0 * (t - 2.0).powi(3)));
        let p = LineSearchParams {
            gtol: 0.1,
            ..Default::default()
        };
        let r = more_thuente(phi, 0.0, -32.0, 0.1, &p);
        assert!(r.warning.is_none(), "{r:?}");
        assert!(r.f <= 1e-4 * r.stp * -32.0);
        assert!(r.g.abs() <= 0.1 * 32.0);
    }

    #[test]
    fn bisects_away_from_inadmissible_region() {
        // quadratic with minimum at 3 but admissible only for t < 0.5
        let phi = |t: f64| {
            if t < 0.5 {
                Some(((t - 3.0).powi(2), 2.0 * (t - 3.0)))
            } else {
                None
            }
        };
        let r = more_thuente(phi, 9.0, -6.0, 1.0, &LineSearchParams::default());
        assert!(r.stp > 0.0 && r.stp < 0.5, "{r:?}");
        assert!(r.f < 9.0);
    }

    #[test]
    fn rejects_ascent_direction_without_panicking() {
        let r = more_thuente(
            |t| Some((t, 1.0)),
            0.0,
            1.0,
            1.0,
            &LineSearchParams::default(),
        );
        assert_eq!(r.stp, 0.0);
        assert_eq!(r.warning, Some(LineSearchFailure::Rounding));
    }
}
