//! L-BFGS(m) with the guarded Moré–Thuente line search.

use unamalla_functionals::{ElementMeasures, Gradient, Variables};

use super::{guarded_line_search, SolverOptions, State};
use crate::linalg::{add_scaled, axpy, dot, norm};
use crate::monitor::Session;
use crate::status::StopReason;

pub(super) fn lbfgs<P: Variables + Gradient + ElementMeasures + ?Sized>(
    problem: &P,
    x: &mut [f64],
    g: &mut [f64],
    opts: &SolverOptions,
    session: &mut Session<'_>,
    st: &mut State,
) -> StopReason {
    let n = x.len();
    let m = opts.lbfgs_memory;
    let mut s_hist: Vec<Vec<f64>> = Vec::with_capacity(m);
    let mut y_hist: Vec<Vec<f64>> = Vec::with_capacity(m);
    let mut rho: Vec<f64> = Vec::with_capacity(m);
    let mut alpha = vec![0.0; m];
    let mut d = vec![0.0; n];
    let mut xt = vec![0.0; n];
    let mut gt = vec![0.0; n];
    let mut head = 0usize; // index of the oldest pair when full
    loop {
        // two-loop recursion
        d.iter_mut().zip(g.iter()).for_each(|(d, g)| *d = -g);
        let k = s_hist.len();
        let order: Vec<usize> = (0..k).map(|i| (head + i) % k.max(1)).collect();
        for &i in order.iter().rev() {
            let a = rho[i] * dot(&s_hist[i], &d);
            alpha[i] = a;
            axpy(-a, &y_hist[i], &mut d);
        }
        let stp0 = if k > 0 {
            let newest = *order.last().unwrap_or(&0);
            let gamma =
                dot(&s_hist[newest], &y_hist[newest]) / dot(&y_hist[newest], &y_hist[newest]);
            d.iter_mut().for_each(|v| *v *= gamma);
            1.0
        } else {
            1.0 / st.gnorm
        };
        for &i in &order {
            let b = rho[i] * dot(&y_hist[i], &d);
            axpy(alpha[i] - b, &s_hist[i], &mut d);
        }
        let mut gd = dot(g, &d);
        if gd.partial_cmp(&0.0) != Some(std::cmp::Ordering::Less) {
            d.iter_mut()
                .zip(g.iter())
                .for_each(|(d, g)| *d = -g / st.gnorm);
            gd = dot(g, &d);
            s_hist.clear();
            y_hist.clear();
            rho.clear();
            head = 0;
        }
        let guard = session.guard_active(st.cur_min);
        let (r, truncated) = match guarded_line_search(
            problem,
            x,
            &d,
            gd,
            stp0,
            guard,
            &opts.line_search,
            session,
            st,
            (&mut xt, &mut gt),
        ) {
            Ok(found) => found,
            Err(reason) => return reason,
        };
        // new pair
        let mut s = vec![0.0; n];
        add_scaled(&xt, -1.0, x, &mut s);
        let mut y = vec![0.0; n];
        add_scaled(&gt, -1.0, g, &mut y);
        let sy = dot(&s, &y);
        if sy > 1e-12 * norm(&s) * norm(&y) {
            if s_hist.len() < m {
                s_hist.push(s);
                y_hist.push(y);
                rho.push(1.0 / sy);
            } else {
                s_hist[head] = s;
                y_hist[head] = y;
                rho[head] = 1.0 / sy;
                head = (head + 1) % m;
            }
        }
        x.copy_from_slice(&xt);
        g.copy_from_slice(&gt);
        let gn = norm(g);
        if let Some(reason) = st.accept(problem, x, r.f, gn, opts, session, truncated) {
            return reason;
        }
    }
}
