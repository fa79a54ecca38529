//! The solvers: truncated Newton with a trust region (Steihaug–CG) or a Moré–Thuente line
//! search, L-BFGS(m), and pointwise (Gauss–Seidel) Newton ([González Flores, App. B]; the
//! references are listed in `docs/references.md` of the repository; [Méndez 2023, §6.4.2] and
//! [Cortés Aguirre 2012, §3.3] use TRON, a trust-region truncated Newton).
//!
//! All of them report every iteration to a [`Session`], which also enforces the convexity
//! safeguard: when the iterate is convex (every element with a free vertex above the session's
//! threshold), trial points that are not are rejected. The entry points [`minimize`] and
//! [`minimize_with`] choose the method at run time and take a [`Problem`] (every capability);
//! the methods themselves use only part of it:
//!
//! | method | capabilities used |
//! |---|---|
//! | every method, the safeguard | [`Variables`], [`Gradient`], [`ElementMeasures`] |
//! | truncated Newton | + [`Hessian`] (the quadratic model: assembled, or `hess_vec` matrix-free) |
//! | L-BFGS, nonlinear CG | nothing more |
//! | pointwise Newton | + [`PointwiseModel`], and [`Hessian::hessian_pattern`] for the node colouring |
//!
//! The model Hessian of truncated Newton is whatever the problem's [`Hessian`] gives: a model
//! other than the exact Hessian (such as [`PsdModel`](crate::psd_model::PsdModel)) is supplied
//! by replacing that capability alone with [`WithHessian`](unamalla_functionals::WithHessian).

use unamalla_functionals::{ElementMeasures, Gradient, Problem, Variables};
#[cfg(doc)]
use unamalla_functionals::{Hessian, PointwiseModel};

use crate::error::OptimError;
use crate::linalg::{add_scaled, dot, norm};
use crate::linesearch::{more_thuente, LineSearchParams, LineSearchResult};
use crate::monitor::{Control, Session};
use crate::status::{LineSearchFailure, StopReason};

mod lbfgs;
mod ncg;
mod newton;
mod options;
mod pointwise;

pub use options::{
    HessianMode, PointwiseMode, Solver, SolverOptions, StopRules, POLISH_WINDOW, REGROWTH_FACTOR,
};
pub use pointwise::QuadLocalGuard;

use lbfgs::lbfgs;
use ncg::ncg_fr;
use newton::truncated_newton;
use pointwise::pointwise;

/// The result of one solver run.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SolveResult {
    /// Why it stopped.
    pub reason: StopReason,
    /// Outer iterations (sweeps for pointwise Newton).
    pub iterations: usize,
    /// Final value.
    pub f: f64,
    /// Final gradient norm.
    pub gnorm: f64,
    /// Function(+gradient) evaluations.
    pub fevals: usize,
    /// Inner CG iterations (truncated Newton).
    pub cg_iterations: usize,
    /// Final `α₋` over elements with a free vertex.
    pub alfamin: f64,
    /// Final `ᾱ`.
    pub alpha_bar: f64,
    /// Whether the final point is convex.
    pub convex: bool,
}

fn check_start<P: Variables + ?Sized>(problem: &P, x: &[f64]) -> Result<(), OptimError> {
    if problem.num_vars() == 0 {
        return Err(OptimError::NoFreeNodes);
    }
    if x.len() != problem.num_vars() {
        return Err(OptimError::InvalidOption {
            name: "x.len()",
            value: x.len() as f64,
            reason: "the starting point must have num_vars entries",
        });
    }
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(OptimError::NonFiniteStart { index: i });
    }
    Ok(())
}

/// Minimizes `problem` from `x` (overwritten with the result) with the method of `opts`,
/// reporting to `session`. Errors only for invalid input (empty problem, non-finite start,
/// non-finite value or gradient at the start, invalid options); non-convergence is a
/// [`StopReason`].
pub fn minimize<P: Problem + ?Sized>(
    problem: &P,
    x: &mut [f64],
    opts: &SolverOptions,
    session: &mut Session<'_>,
) -> Result<SolveResult, OptimError> {
    minimize_with(problem, x, opts, session, None)
}

/// [`minimize`] with an optional local convexity check for pointwise Newton on quad meshes
/// (without it, pointwise Newton checks convexity after each sweep and backtracks the sweep).
pub fn minimize_with<P: Problem + ?Sized>(
    problem: &P,
    x: &mut [f64],
    opts: &SolverOptions,
    session: &mut Session<'_>,
    local_guard: Option<&QuadLocalGuard>,
) -> Result<SolveResult, OptimError> {
    opts.validate()?;
    check_start(problem, x)?;
    let n = x.len();
    let mut g = vec![0.0; n];
    let f = problem.value_grad(x, &mut g);
    if !f.is_finite() || g.iter().any(|v| !v.is_finite()) {
        return Err(OptimError::NonFiniteValue { value: f });
    }
    let mut st = State {
        f,
        gnorm: norm(&g),
        g0norm: 0.0,
        iterations: 0,
        fevals: 1,
        cg: 0,
        cur_min: 0.0,
        alpha_bar: 0.0,
        history: Vec::new(),
    };
    st.g0norm = st.gnorm;
    let c = session.convexity(problem, x);
    st.cur_min = c.min;
    st.alpha_bar = c.mean;
    session.update(c, f, st.gnorm);
    let reason = if session.stop_requested() {
        session.interrupt_reason()
    } else if st.gnorm <= opts.gtol_abs || st.gnorm == 0.0 {
        StopReason::Gtol
    } else {
        match opts.solver {
            Solver::TnTr | Solver::TnLs => {
                truncated_newton(problem, x, &mut g, opts, session, &mut st)
            }
            Solver::Lbfgs => lbfgs(problem, x, &mut g, opts, session, &mut st),
            Solver::Pointwise => pointwise(problem, x, &mut g, opts, session, &mut st, local_guard),
            Solver::NcgFr => ncg_fr(problem, x, &mut g, opts, session, &mut st),
        }
    };
    // a run without an accepted step never reached the observer: let it see the run (time
    // budgets must be able to stop drivers that call the solver repeatedly)
    let reason = if st.iterations == 0 && !reason.interrupted() {
        if session.heartbeat() == Control::Stop {
            session.interrupt_reason()
        } else {
            reason
        }
    } else {
        reason
    };
    Ok(SolveResult {
        reason,
        iterations: st.iterations,
        f: st.f,
        gnorm: st.gnorm,
        fevals: st.fevals,
        cg_iterations: st.cg,
        alfamin: st.cur_min,
        alpha_bar: st.alpha_bar,
        convex: st.cur_min > 0.0,
    })
}

struct State {
    f: f64,
    gnorm: f64,
    g0norm: f64,
    iterations: usize,
    fevals: usize,
    cg: usize,
    cur_min: f64,
    alpha_bar: f64,
    /// `(F, α₋/ᾱ, μ-share)` of the accepted iterates (only with [`StopRules`] on).
    history: Vec<(f64, f64, Option<f64>)>,
}

impl State {
    /// Records an accepted iterate; returns a stop reason if a test fires.
    #[allow(clippy::too_many_arguments)]
    fn accept<P: ElementMeasures + ?Sized>(
        &mut self,
        problem: &P,
        x: &[f64],
        f_new: f64,
        gnorm: f64,
        opts: &SolverOptions,
        session: &mut Session<'_>,
        truncated: bool,
    ) -> Option<StopReason> {
        let f_old = self.f;
        self.f = f_new;
        self.gnorm = gnorm;
        self.iterations += 1;
        let (ctl, c) = session.iterate(problem, x, f_new, gnorm);
        self.cur_min = c.min;
        self.alpha_bar = c.mean;
        if ctl == Control::Stop {
            return Some(session.interrupt_reason());
        }
        if gnorm <= opts.gtol * self.g0norm || gnorm <= opts.gtol_abs {
            return Some(StopReason::Gtol);
        }
        // FTOL is not tested after a step cut short by the safeguard (a small decrease there
        // says nothing about optimality)
        if !truncated && (f_old - f_new) <= opts.ftol * f_old.abs().max(f_new.abs()) {
            return Some(StopReason::Ftol);
        }
        if opts.stop.window > 0 {
            if c.nonconvex_cells > 0 {
                // the window tests apply to convex iterates only
                self.history.clear();
            } else {
                let share = if opts.stop.plateau_alpha > 0.0 {
                    session.quality(x)
                } else {
                    None
                };
                self.history.push((f_new, c.min / c.mean, share));
                if let Some(r) = opts.stop.check(&self.history) {
                    return Some(r);
                }
                let keep = opts.stop.history_len();
                if self.history.len() > 4 * keep {
                    self.history.drain(..self.history.len() - keep);
                }
            }
        }
        if self.iterations >= opts.max_iter {
            return Some(StopReason::MaxIter);
        }
        None
    }
}

/// One Moré–Thuente line search along `d` from `x` under the convexity guard (the search of
/// the line-search solvers: truncated Newton with a line search, L-BFGS, NCG). With the guard
/// active (`guard`, from [`Session::guard_active`]) the step is capped at 0.95 of the largest
/// step that keeps every element admissible and a trial point that is not admissible counts as
/// infeasible. `trial` (point, gradient) receives the last trial, the accepted one on success.
/// Returns the search's result and whether the cap was below the first trial step `stp0`, or
/// the stop reason when no step was accepted.
#[allow(clippy::too_many_arguments)]
fn guarded_line_search<P: Variables + Gradient + ElementMeasures + ?Sized>(
    problem: &P,
    x: &[f64],
    d: &[f64],
    gd: f64,
    stp0: f64,
    guard: bool,
    params: &LineSearchParams,
    session: &mut Session<'_>,
    st: &mut State,
    trial: (&mut [f64], &mut [f64]),
) -> Result<(LineSearchResult, bool), StopReason> {
    let (xt, gt) = trial;
    let smax = if guard {
        0.95 * session.max_step(problem, x, d)
    } else {
        f64::INFINITY
    };
    let truncated = smax < stp0;
    let lsp = LineSearchParams {
        stpmax: params.stpmax.min(smax),
        ..*params
    };
    let mut fe = 0;
    let r = more_thuente(
        |t| {
            fe += 1;
            add_scaled(x, t, d, xt);
            if guard && !session.admissible(problem, xt) {
                return None;
            }
            let f = problem.value_grad(xt, gt);
            Some((f, dot(gt, d)))
        },
        st.f,
        gd,
        stp0.min(lsp.stpmax),
        &lsp,
    );
    st.fevals += fe;
    if r.stp == 0.0 {
        return Err(StopReason::LineSearch(
            r.warning.unwrap_or(LineSearchFailure::Rounding),
        ));
    }
    Ok((r, truncated))
}
