//! Fletcher–Reeves nonlinear CG with a strong-Wolfe line search.

use unamalla_functionals::{ElementMeasures, Gradient, Variables};

#[cfg(doc)]
use super::Solver;
use super::{guarded_line_search, SolverOptions, State};
use crate::linalg::{dot, norm};
use crate::linesearch::LineSearchParams;
use crate::monitor::Session;
use crate::status::StopReason;

/// Curvature constant of the strong-Wolfe line search of [`Solver::NcgFr`] (at most this; the
/// Fletcher–Reeves directions are descent directions for any constant below ½).
const NCG_WOLFE_GTOL: f64 = 0.1;

/// Fletcher–Reeves nonlinear CG ([`Solver::NcgFr`]). The first trial step is `1/‖g‖` after a
/// restart and otherwise `t_{k−1}·(g_{k−1}·d_{k−1})/(g_k·d_k)` (Nocedal & Wright 2006, (3.60)).
pub(super) fn ncg_fr<P: Variables + Gradient + ElementMeasures + ?Sized>(
    problem: &P,
    x: &mut [f64],
    g: &mut [f64],
    opts: &SolverOptions,
    session: &mut Session<'_>,
    st: &mut State,
) -> StopReason {
    let n = x.len();
    let mut d: Vec<f64> = g.iter().map(|v| -v).collect();
    let mut xt = vec![0.0; n];
    let mut gt = vec![0.0; n];
    // previous accepted step and slope (for the initial trial step), and the iterations since
    // the last restart
    let mut prev: Option<(f64, f64)> = None;
    let mut since_restart = 0usize;
    loop {
        let mut gd = dot(g, &d);
        if since_restart >= n.max(1) || gd.partial_cmp(&0.0) != Some(std::cmp::Ordering::Less) {
            d.iter_mut().zip(g.iter()).for_each(|(d, g)| *d = -g);
            gd = dot(g, &d);
            prev = None;
            since_restart = 0;
        }
        let stp0 = match prev {
            Some((t, slope)) => (t * slope / gd).clamp(f64::MIN_POSITIVE, 1e20),
            None => 1.0 / st.gnorm,
        };
        let guard = session.guard_active(st.cur_min);
        let wolfe = LineSearchParams {
            gtol: opts.line_search.gtol.min(NCG_WOLFE_GTOL),
            ..opts.line_search
        };
        let (r, truncated) = match guarded_line_search(
            problem,
            x,
            &d,
            gd,
            stp0,
            guard,
            &wolfe,
            session,
            st,
            (&mut xt, &mut gt),
        ) {
            Ok(found) => found,
            Err(reason) => return reason,
        };
        let g_old2 = dot(g, g);
        x.copy_from_slice(&xt);
        g.copy_from_slice(&gt);
        let beta = dot(g, g) / g_old2;
        d.iter_mut()
            .zip(g.iter())
            .for_each(|(d, g)| *d = -g + beta * *d);
        prev = Some((r.stp, gd));
        since_restart += 1;
        let gn = norm(g);
        if let Some(reason) = st.accept(problem, x, r.f, gn, opts, session, truncated) {
            return reason;
        }
    }
}
