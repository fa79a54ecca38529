//! Truncated Newton: the preconditioned Steihaug–Toint CG on the quadratic model and the outer
//! iteration with a trust region or a Moré–Thuente line search.

use unamalla_functionals::{Csr, ElementMeasures, Gradient, Hessian, Variables};

use super::{guarded_line_search, HessianMode, Solver, SolverOptions, State};
use crate::linalg::{add_scaled, axpy, dot, norm, scale_add, PrecondApply, Preconditioner};
use crate::monitor::Session;
use crate::status::StopReason;

/// Elements that would reach the safeguard's threshold before this multiple of a full step
/// hold their nodes back ([`Session::hold_back`]): after a full step each remaining element
/// keeps about half of its distance to the threshold.
const HOLD_BACK_REACH: f64 = 2.0;

struct CgWork {
    r: Vec<f64>,
    y: Vec<f64>,
    d: Vec<f64>,
    hd: Vec<f64>,
    hz: Vec<f64>,
    z: Vec<f64>,
}

struct CgOut {
    gz: f64,
    zhz: f64,
    iters: usize,
    boundary: bool,
    pred: f64,
    znorm_m: f64,
}

/// Preconditioned Steihaug–Toint CG on `H z = −g` inside `‖z‖_M ≤ radius` (radius may be
/// infinite: plain truncated CG with a negative-curvature exit).
fn steihaug(
    hv: &dyn Fn(&[f64], &mut [f64]),
    g: &[f64],
    pre: &dyn Fn(&[f64], &mut [f64]),
    radius: f64,
    tol: f64,
    maxit: usize,
    w: &mut CgWork,
) -> CgOut {
    let CgWork { r, y, d, hd, hz, z } = w;
    z.iter_mut().for_each(|v| *v = 0.0);
    hz.iter_mut().for_each(|v| *v = 0.0);
    r.copy_from_slice(g);
    pre(r, y);
    d.iter_mut().zip(y.iter()).for_each(|(d, y)| *d = -y);
    let mut ry = dot(r, y);
    let (mut zmz, mut zmd, mut dmd) = (0.0, 0.0, ry);
    let mut out = CgOut {
        gz: 0.0,
        zhz: 0.0,
        iters: 0,
        boundary: false,
        pred: 0.0,
        znorm_m: 0.0,
    };
    let to_boundary = |zmz: f64, zmd: f64, dmd: f64| {
        let disc = (zmd * zmd + dmd * (radius * radius - zmz)).max(0.0);
        (-zmd + disc.sqrt()) / dmd
    };
    for it in 0..maxit.max(1) {
        hv(d, hd);
        let kappa = dot(d, hd);
        if kappa.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || !kappa.is_finite() {
            // negative curvature (or breakdown)
            if radius.is_finite() {
                let tau = to_boundary(zmz, zmd, dmd);
                axpy(tau, d, z);
                axpy(tau, hd, hz);
                out.boundary = true;
            } else if it == 0 {
                z.copy_from_slice(d);
                hz.copy_from_slice(hd);
            }
            out.iters = it + 1;
            break;
        }
        let a = ry / kappa;
        let zmz_new = zmz + 2.0 * a * zmd + a * a * dmd;
        if radius.is_finite() && zmz_new >= radius * radius {
            let tau = to_boundary(zmz, zmd, dmd);
            axpy(tau, d, z);
            axpy(tau, hd, hz);
            out.boundary = true;
            out.iters = it + 1;
            break;
        }
        axpy(a, d, z);
        axpy(a, hd, hz);
        zmz = zmz_new;
        axpy(a, hd, r);
        out.iters = it + 1;
        if norm(r) <= tol {
            break;
        }
        pre(r, y);
        let ry_new = dot(r, y);
        if ry_new.is_nan() || ry_new <= 0.0 || !ry_new.is_finite() {
            // the preconditioner is not positive definite on this residual (possible only for
            // an indefinite Hessian): keep the current iterate
            break;
        }
        let beta = ry_new / ry;
        ry = ry_new;
        zmd = beta * (zmd + a * dmd);
        dmd = ry + beta * beta * dmd;
        // d ← −y + β d
        y.iter_mut().for_each(|v| *v = -*v);
        scale_add(beta, d, y);
        y.iter_mut().for_each(|v| *v = -*v);
    }
    out.gz = dot(g, z);
    out.zhz = dot(z, hz);
    out.pred = -(out.gz + 0.5 * out.zhz);
    out.znorm_m = zmz.max(0.0).sqrt();
    if out.boundary {
        out.znorm_m = radius;
    }
    out
}

pub(super) fn ensure_hessian<P: Variables + Hessian + ?Sized>(
    problem: &P,
    session: &mut Session<'_>,
) {
    let ok = matches!(&session.hess, Some(h) if h.nrows == problem.num_vars());
    if !ok {
        session.hess = Some(problem.hessian_pattern());
    }
}

pub(super) fn truncated_newton<P: Variables + Gradient + Hessian + ElementMeasures + ?Sized>(
    problem: &P,
    x: &mut [f64],
    g: &mut [f64],
    opts: &SolverOptions,
    session: &mut Session<'_>,
    st: &mut State,
) -> StopReason {
    let n = x.len();
    let trust = opts.solver == Solver::TnTr;
    let assembled = opts.hessian != HessianMode::MatrixFree;
    if assembled {
        ensure_hessian(problem, session);
    }
    let mut h: Csr = if assembled {
        session
            .hess
            .take()
            .unwrap_or_else(|| problem.hessian_pattern())
    } else {
        Csr {
            nrows: 0,
            ncols: 0,
            row_offsets: vec![0],
            col_indices: Vec::new(),
            values: Vec::new(),
        }
    };
    let mut pre = PrecondApply::default();
    let mut w = CgWork {
        r: vec![0.0; n],
        y: vec![0.0; n],
        d: vec![0.0; n],
        hd: vec![0.0; n],
        hz: vec![0.0; n],
        z: vec![0.0; n],
    };
    // the held-back step (see `Session::hold_back`; trust region only)
    let mut z2 = vec![0.0; if trust { n } else { 0 }];
    let mut xt = vec![0.0; n];
    let mut gt = vec![0.0; n];
    let mut radius = f64::INFINITY;
    // CG iterations of the last outer iteration, and of the first one after the last
    // multigrid rebuild
    let mut cg_last = 0usize;
    let mut mg_built_cg: Option<usize> = None;
    let reason = 'outer: loop {
        let cg_before = st.cg;
        if assembled {
            problem.hessian(x, &mut h);
            // multigrid: the coarse levels are rebuilt only when CG needed clearly more
            // iterations than right after the last rebuild (lagged hierarchy)
            let rebuild = mg_built_cg.is_none_or(|c0| cg_last > (2 * c0).max(12));
            pre.update(opts.preconditioner, &h, problem.dim(), rebuild);
            if rebuild {
                mg_built_cg = None;
            }
        } else {
            pre.build(Preconditioner::None, &h, problem.dim());
        }
        let eta = opts.forcing_max.min((st.gnorm / st.g0norm).sqrt());
        let tol = eta * st.gnorm;
        let xr: &[f64] = x;
        let hv = |v: &[f64], out: &mut [f64]| {
            if assembled {
                h.mul_vec(v, out)
            } else {
                problem.hess_vec(xr, v, out)
            }
        };
        let hr: &Csr = &h;
        let prec = |v: &[f64], out: &mut [f64]| pre.apply_with(hr, v, out);
        let guard = session.guard_active(st.cur_min);
        let f_acc;
        let mut truncated;
        if trust {
            loop {
                truncated = false;
                let mut o = steihaug(&hv, g, &prec, radius, tol, opts.cg_max_iter, &mut w);
                st.cg += o.iters;
                if radius.is_infinite() {
                    radius = o.znorm_m.max(f64::MIN_POSITIVE);
                }
                if guard {
                    // fraction to the boundary of the admissible set
                    // (only `min(tm, 1)` is used below)
                    let mut tm = session.max_step_within(problem, xr, &w.z, 1.0);
                    if tm < 1.0 {
                        // hold back the nodes of the blocking cells instead (so that one cell
                        // at the threshold does not stall the whole mesh, nor creep towards
                        // the threshold step by step); the shortened full step only when the
                        // held-back step does not decrease the model
                        z2.copy_from_slice(&w.z);
                        let tm2 = session.hold_back(problem, xr, &mut z2, HOLD_BACK_REACH);
                        if tm2 > tm {
                            hv(&z2, &mut w.hd);
                            let (gz2, zhz2) = (dot(g, &z2), dot(&z2, &w.hd));
                            let tau2 = if tm2 < 1.0 { 0.9 * tm2 } else { 1.0 };
                            let tau = 0.9 * tm;
                            let pred2 = -(tau2 * gz2 + 0.5 * tau2 * tau2 * zhz2);
                            let pred1 = -(tau * o.gz + 0.5 * tau * tau * o.zhz);
                            if pred2 > pred1 && pred2 > 0.0 {
                                let ratio = norm(&z2) / norm(&w.z).max(f64::MIN_POSITIVE);
                                w.z.copy_from_slice(&z2);
                                o.gz = gz2;
                                o.zhz = zhz2;
                                o.pred = -(gz2 + 0.5 * zhz2);
                                o.znorm_m *= ratio;
                                tm = tm2;
                            }
                        }
                    }
                    if tm < 1.0 {
                        let tau = 0.9 * tm;
                        w.z.iter_mut().for_each(|v| *v *= tau);
                        o.pred = -(tau * o.gz + 0.5 * tau * tau * o.zhz);
                        o.znorm_m *= tau;
                        o.boundary = false;
                        // the next model step stays in the smaller ball, bending away from
                        // the boundary of the admissible set
                        radius = radius.min(o.znorm_m);
                        truncated = true;
                    }
                }
                add_scaled(xr, 1.0, &w.z, &mut xt);
                let ok = !guard || session.admissible(problem, &xt);
                let ft = if ok {
                    st.fevals += 1;
                    problem.value_grad(&xt, &mut gt)
                } else {
                    f64::NAN
                };
                let rho = if ft.is_finite() && o.pred > 0.0 {
                    (st.f - ft) / o.pred
                } else if ft.is_finite() && o.pred <= 0.0 && ft < st.f {
                    1.0
                } else {
                    f64::NEG_INFINITY
                };
                if rho < 0.25 {
                    radius = 0.25 * o.znorm_m.min(radius);
                } else if rho > 0.75 && o.boundary {
                    radius *= 2.0;
                }
                if rho > 1e-4 && gt.iter().all(|v| v.is_finite()) {
                    f_acc = ft;
                    break;
                }
                // relative to ‖x‖ (no absolute floor: the stop must not depend on the units)
                let xs = norm(xr).max(f64::MIN_POSITIVE);
                if radius <= 1e-15 * xs || o.znorm_m == 0.0 {
                    break 'outer StopReason::TrustRadius;
                }
            }
        } else {
            let o = steihaug(&hv, g, &prec, f64::INFINITY, tol, opts.cg_max_iter, &mut w);
            st.cg += o.iters;
            let mut gd = dot(g, &w.z);
            if gd.partial_cmp(&0.0) != Some(std::cmp::Ordering::Less) {
                pre.apply(g, &mut w.z);
                w.z.iter_mut().for_each(|v| *v = -*v);
                gd = dot(g, &w.z);
            }
            let search = guarded_line_search(
                problem,
                xr,
                &w.z,
                gd,
                1.0,
                guard,
                &opts.line_search,
                session,
                st,
                (&mut xt, &mut gt),
            );
            let r = match search {
                Ok((r, cut)) => {
                    truncated = cut;
                    r
                }
                Err(reason) => break 'outer reason,
            };
            f_acc = r.f;
        }
        cg_last = st.cg - cg_before;
        if mg_built_cg.is_none() {
            mg_built_cg = Some(cg_last);
        }
        x.copy_from_slice(&xt);
        g.copy_from_slice(&gt);
        let gn = norm(g);
        if let Some(r) = st.accept(problem, x, f_acc, gn, opts, session, truncated) {
            break r;
        }
    };
    if assembled {
        session.hess = Some(h);
    }
    reason
}
