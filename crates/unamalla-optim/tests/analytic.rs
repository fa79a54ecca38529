//! Solvers on analytic problems with known minimizers (before any mesh).

use std::sync::atomic::{AtomicUsize, Ordering};

use unamalla_functionals::prelude::*;
use unamalla_functionals::{Csr, LocalModel, WithHessian};
use unamalla_optim::linesearch::LineSearchParams;
use unamalla_optim::monitor::{Control, Monitor, NullObserver, Session};
use unamalla_optim::solver::{minimize, HessianMode, PointwiseMode, Solver, SolverOptions};
use unamalla_optim::status::StopReason;

/// `F = ½ xᵀAx − bᵀx`, `A` = 2D "nodes on a chain" SPD matrix: node blocks `[[4, 1], [1, 3]]`
/// on the diagonal and `−I` between neighbouring nodes. `b = A x*` with a chosen `x*`.
struct Quadratic {
    nodes: usize,
    b: Vec<f64>,
    free: Vec<usize>,
}

impl Quadratic {
    fn new(nodes: usize, xstar: &[f64]) -> Self {
        let mut q = Self {
            nodes,
            b: vec![0.0; 2 * nodes],
            free: (0..nodes).collect(),
        };
        let mut b = vec![0.0; 2 * nodes];
        q.apply(xstar, &mut b);
        q.b = b;
        q
    }
    fn apply(&self, v: &[f64], out: &mut [f64]) {
        for i in 0..self.nodes {
            let (x, y) = (v[2 * i], v[2 * i + 1]);
            let mut ox = 4.0 * x + y;
            let mut oy = x + 3.0 * y;
            for j in [i.wrapping_sub(1), i + 1] {
                if j < self.nodes {
                    ox -= v[2 * j];
                    oy -= v[2 * j + 1];
                }
            }
            out[2 * i] = ox;
            out[2 * i + 1] = oy;
        }
    }
}

impl Variables for Quadratic {
    fn dim(&self) -> usize {
        2
    }
    fn num_vars(&self) -> usize {
        2 * self.nodes
    }
    fn free_nodes(&self) -> &[usize] {
        &self.free
    }
    fn var_of(&self, node: usize) -> Option<usize> {
        (node < self.nodes).then_some(node)
    }
}

impl Cost for Quadratic {
    fn value(&self, x: &[f64]) -> f64 {
        let mut ax = vec![0.0; x.len()];
        self.apply(x, &mut ax);
        (0..x.len())
            .map(|i| 0.5 * x[i] * ax[i] - self.b[i] * x[i])
            .sum()
    }
}

impl Gradient for Quadratic {
    fn value_grad(&self, x: &[f64], g: &mut [f64]) -> f64 {
        self.apply(x, g);
        for (gi, bi) in g.iter_mut().zip(&self.b) {
            *gi -= bi;
        }
        self.value(x)
    }
}

impl Hessian for Quadratic {
    fn hessian_pattern(&self) -> Csr {
        let n = 2 * self.nodes;
        let mut ro = vec![0];
        let mut ci = Vec::new();
        for r in 0..n {
            let node = r / 2;
            for nb in [node.wrapping_sub(1), node, node + 1] {
                if nb < self.nodes {
                    ci.push((2 * nb) as u32);
                    ci.push((2 * nb + 1) as u32);
                }
            }
            ro.push(ci.len());
        }
        Csr {
            nrows: n,
            ncols: n,
            row_offsets: ro,
            values: vec![0.0; ci.len()],
            col_indices: ci,
        }
    }
    fn hessian(&self, _x: &[f64], h: &mut Csr) {
        for r in 0..h.nrows {
            for k in h.row_offsets[r]..h.row_offsets[r + 1] {
                let c = h.col_indices[k] as usize;
                h.values[k] = if r / 2 == c / 2 {
                    [[4.0, 1.0], [1.0, 3.0]][r % 2][c % 2]
                } else if r % 2 == c % 2 {
                    -1.0
                } else {
                    0.0
                };
            }
        }
    }
    fn hess_vec(&self, _x: &[f64], v: &[f64], out: &mut [f64]) {
        self.apply(v, out)
    }
}

impl PointwiseModel for Quadratic {
    fn local(&self, x: &[f64], node: usize) -> Option<LocalModel> {
        if node >= self.nodes {
            return None;
        }
        let mut g = vec![0.0; x.len()];
        let value = self.value_grad(x, &mut g);
        Some(LocalModel {
            value,
            grad: [g[2 * node], g[2 * node + 1], 0.0],
            hess: [[4.0, 1.0, 0.0], [1.0, 3.0, 0.0], [0.0; 3]],
            dim: 2,
        })
    }
}

impl ElementMeasures for Quadratic {
    fn num_elements(&self) -> usize {
        0
    }
    fn element_measures(&self, _x: &[f64], _out: &mut [f64]) {}
}

/// Rosenbrock `(1 − x)² + 100(y − x²)²` as a one-node 2D problem; minimizer (1, 1).
struct Rosenbrock;

impl Rosenbrock {
    fn gh(x: &[f64]) -> (f64, [f64; 2], [[f64; 2]; 2]) {
        let (a, b) = (x[0], x[1]);
        let f = (1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2);
        let g = [
            -2.0 * (1.0 - a) - 400.0 * a * (b - a * a),
            200.0 * (b - a * a),
        ];
        let h = [
            [2.0 - 400.0 * b + 1200.0 * a * a, -400.0 * a],
            [-400.0 * a, 200.0],
        ];
        (f, g, h)
    }
}

impl Variables for Rosenbrock {
    fn dim(&self) -> usize {
        2
    }
    fn num_vars(&self) -> usize {
        2
    }
    fn free_nodes(&self) -> &[usize] {
        &[0]
    }
    fn var_of(&self, node: usize) -> Option<usize> {
        (node == 0).then_some(0)
    }
}

impl Cost for Rosenbrock {
    fn value(&self, x: &[f64]) -> f64 {
        Self::gh(x).0
    }
}

impl Gradient for Rosenbrock {
    fn value_grad(&self, x: &[f64], g: &mut [f64]) -> f64 {
        let (f, gg, _) = Self::gh(x);
        g.copy_from_slice(&gg);
        f
    }
}

impl Hessian for Rosenbrock {
    fn hessian_pattern(&self) -> Csr {
        Csr {
            nrows: 2,
            ncols: 2,
            row_offsets: vec![0, 2, 4],
            col_indices: vec![0, 1, 0, 1],
            values: vec![0.0; 4],
        }
    }
    fn hessian(&self, x: &[f64], h: &mut Csr) {
        let (_, _, hh) = Self::gh(x);
        h.values
            .copy_from_slice(&[hh[0][0], hh[0][1], hh[1][0], hh[1][1]]);
    }
    fn hess_vec(&self, x: &[f64], v: &[f64], out: &mut [f64]) {
        let (_, _, h) = Self::gh(x);
        out[0] = h[0][0] * v[0] + h[0][1] * v[1];
        out[1] = h[1][0] * v[0] + h[1][1] * v[1];
    }
}

impl PointwiseModel for Rosenbrock {
    fn local(&self, x: &[f64], node: usize) -> Option<LocalModel> {
        (node == 0).then(|| {
            let (f, g, h) = Self::gh(x);
            LocalModel {
                value: f,
                grad: [g[0], g[1], 0.0],
                hess: [[h[0][0], h[0][1], 0.0], [h[1][0], h[1][1], 0.0], [0.0; 3]],
                dim: 2,
            }
        })
    }
}

impl ElementMeasures for Rosenbrock {
    fn num_elements(&self) -> usize {
        0
    }
    fn element_measures(&self, _x: &[f64], _out: &mut [f64]) {}
}

fn all_variants() -> Vec<SolverOptions> {
    let mut v = Vec::new();
    for s in Solver::ALL {
        v.push(SolverOptions::new(s).max_iter(5000).gtol(1e-10).ftol(0.0));
    }
    for m in [3, 5, 1] {
        v.push(
            SolverOptions::new(Solver::Lbfgs)
                .lbfgs_memory(m)
                .max_iter(5000)
                .gtol(1e-10)
                .ftol(0.0),
        );
    }
    v.push(
        SolverOptions::new(Solver::Pointwise)
            .pointwise_mode(PointwiseMode::Components)
            .max_iter(20000)
            .gtol(1e-10)
            .ftol(0.0),
    );
    v
}

#[test]
fn every_solver_finds_the_minimizer_of_a_convex_quadratic() {
    let nodes = 40;
    let xstar: Vec<f64> = (0..2 * nodes)
        .map(|i| ((i * 7919) % 13) as f64 / 3.0 - 2.0)
        .collect();
    let q = Quadratic::new(nodes, &xstar);
    for opts in all_variants() {
        let mut x = vec![0.0; 2 * nodes];
        let mut obs = NullObserver;
        let mut s = Session::new(&q, &x, &mut obs);
        let r = minimize(&q, &mut x, &opts, &mut s).unwrap();
        let err = x
            .iter()
            .zip(&xstar)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            err < 1e-6,
            "{:?} {:?}: error {err}, {r:?}",
            opts.solver,
            opts.pointwise_mode
        );
    }
}

#[test]
fn every_solver_finds_the_minimizer_of_rosenbrock() {
    for opts in all_variants() {
        let mut x = vec![-1.2, 1.0];
        let mut obs = NullObserver;
        let mut s = Session::new(&Rosenbrock, &x, &mut obs);
        let r = minimize(&Rosenbrock, &mut x, &opts, &mut s).unwrap();
        assert!(
            (x[0] - 1.0).abs() < 1e-5 && (x[1] - 1.0).abs() < 1e-5,
            "{:?} {:?}: {x:?} {r:?}",
            opts.solver,
            opts.pointwise_mode
        );
    }
}

#[test]
fn observer_can_stop_the_run() {
    let mut x = vec![-1.2, 1.0];
    let mut calls = 0;
    let mut obs = |_: &Monitor| {
        calls += 1;
        if calls >= 3 {
            Control::Stop
        } else {
            Control::Continue
        }
    };
    let mut s = Session::new(&Rosenbrock, &x, &mut obs);
    let r = minimize(
        &Rosenbrock,
        &mut x,
        &SolverOptions::new(Solver::Lbfgs),
        &mut s,
    )
    .unwrap();
    assert_eq!(r.reason, StopReason::User);
    assert_eq!(r.iterations, 3);
}

#[test]
fn nan_start_is_an_error_not_a_panic() {
    let mut x = vec![f64::NAN, 1.0];
    let mut obs = NullObserver;
    let mut s = Session::new(&Rosenbrock, &[0.0, 0.0], &mut obs);
    assert!(minimize(&Rosenbrock, &mut x, &SolverOptions::default(), &mut s).is_err());
}

#[test]
fn a_run_without_an_accepted_step_still_reaches_the_observer() {
    // Start exactly at the minimizer: the gradient A·x* − b is exactly 0 (b was computed as
    // A·x* by the same routine), so every solver stops before its first iteration. The
    // observer must still see the run once (time budgets of the drivers rely on it), and a
    // stop it asks for there is reported as a user stop.
    let nodes = 6;
    let xstar: Vec<f64> = (0..2 * nodes).map(|i| i as f64 * 0.5 - 1.0).collect();
    let q = Quadratic::new(nodes, &xstar);
    for opts in all_variants() {
        let mut x = xstar.clone();
        let mut calls = 0usize;
        let mut stop = |_: &Monitor| {
            calls += 1;
            Control::Stop
        };
        let mut s = Session::new(&q, &x, &mut stop);
        let r = minimize(&q, &mut x, &opts, &mut s).unwrap();
        assert_eq!(r.iterations, 0);
        assert_eq!(r.reason, StopReason::User, "{:?}", opts.solver);
        drop(s);
        assert_eq!(calls, 1, "{:?}", opts.solver);
        assert_eq!(x, xstar);
    }
}

/// Fletcher–Reeves CG on a strictly convex quadratic in `n` variables: with exact line
/// searches it is linear CG, which reaches the minimizer in at most `n` iterations (Hestenes &
/// Stiefel 1952; Nocedal & Wright 2006, Thm 5.1). The line search is made exact by a curvature
/// constant of 10⁻¹⁰ (Moré–Thuente's cubic interpolation then lands on the line minimizer), and
/// the run must end by the gradient test within `n` iterations (here `n` = 6 and 8; the restart
/// every `n` iterations is never reached). With the default constant 0.1 it takes 12 for n = 6.
#[test]
fn fletcher_reeves_ends_within_n_iterations_on_a_quadratic() {
    for nodes in [3, 4] {
        let xstar: Vec<f64> = (0..2 * nodes).map(|i| 1.0 + 0.5 * i as f64).collect();
        let q = Quadratic::new(nodes, &xstar);
        let opts = SolverOptions::new(Solver::NcgFr)
            .max_iter(100)
            .gtol(1e-9)
            .ftol(0.0)
            .line_search(LineSearchParams::default().gtol(1e-10));
        let mut x = vec![0.0; 2 * nodes];
        let mut obs = NullObserver;
        let mut s = Session::new(&q, &x, &mut obs);
        let r = minimize(&q, &mut x, &opts, &mut s).unwrap();
        assert_eq!(r.reason, StopReason::Gtol, "{r:?}");
        assert!(
            r.iterations <= 2 * nodes,
            "{} iterations for n = {}",
            r.iterations,
            2 * nodes
        );
        let err = x
            .iter()
            .zip(&xstar)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-8, "{err}");
    }
}

/// The Gauss–Newton model Hessian of [`Rosenbrock`], and nothing else: with the residuals
/// `r₁ = 1 − a`, `r₂ = 10(b − a²)` (`F = r₁² + r₂²`) and `J = ∂r/∂(a, b) = [[−1, 0], [−20a, 10]]`,
/// `H_GN = 2JᵀJ = [[2 + 800a², −400a], [−400a, 200]]` — the exact Hessian without the term
/// `2r₂∇²r₂ = −400(b − a²)·e₁e₁ᵀ`, positive definite everywhere (`det = 400`). Counts its
/// refreshes.
struct GaussNewton {
    refreshes: AtomicUsize,
}

impl GaussNewton {
    fn h(x: &[f64]) -> [[f64; 2]; 2] {
        let a = x[0];
        [[2.0 + 800.0 * a * a, -400.0 * a], [-400.0 * a, 200.0]]
    }
}

impl Hessian for GaussNewton {
    fn hessian_pattern(&self) -> Csr {
        Rosenbrock.hessian_pattern()
    }
    fn hessian(&self, x: &[f64], h: &mut Csr) {
        self.refreshes.fetch_add(1, Ordering::Relaxed);
        let m = Self::h(x);
        h.values
            .copy_from_slice(&[m[0][0], m[0][1], m[1][0], m[1][1]]);
    }
    fn hess_vec(&self, x: &[f64], v: &[f64], out: &mut [f64]) {
        let m = Self::h(x);
        out[0] = m[0][0] * v[0] + m[0][1] * v[1];
        out[1] = m[1][0] * v[0] + m[1][1] * v[1];
    }
}

#[test]
fn a_replaced_hessian_alone_drives_truncated_newton_to_the_same_minimizer() {
    // the model Hessian at the start (−1.2, 1): [[2 + 800·1.44, 480], [480, 200]]
    let gn = GaussNewton {
        refreshes: AtomicUsize::new(0),
    };
    let p = WithHessian::new(&Rosenbrock, &gn);
    let mut h = p.hessian_pattern();
    p.hessian(&[-1.2, 1.0], &mut h);
    for (v, e) in h.values.iter().zip([1154.0, 480.0, 480.0, 200.0]) {
        assert!((v - e).abs() < 1e-12 * e, "{:?}", h.values);
    }
    // value and gradient are Rosenbrock's own: F(−1.2, 1) = 2.2² + 100·0.44² = 24.2,
    // ∇F = (−2·2.2 − 400·(−1.2)·(−0.44), 200·(−0.44)) = (−215.6, −88)
    let mut g = [0.0; 2];
    let f0 = p.value_grad(&[-1.2, 1.0], &mut g);
    assert!(
        (f0 - 24.2).abs() < 1e-12 && (g[0] + 215.6).abs() < 1e-12 && (g[1] + 88.0).abs() < 1e-12
    );
    for (solver, hessian) in [
        (Solver::TnTr, HessianMode::Assembled),
        (Solver::TnLs, HessianMode::Assembled),
        (Solver::TnTr, HessianMode::MatrixFree),
    ] {
        gn.refreshes.store(0, Ordering::Relaxed);
        // field by field: the options may gain fields
        let mut opts = SolverOptions::new(solver);
        opts.max_iter = 5000;
        opts.gtol = 1e-10;
        opts.ftol = 0.0;
        opts.hessian = hessian;
        let mut x = vec![-1.2, 1.0];
        let mut obs = NullObserver;
        let mut s = Session::new(&p, &x, &mut obs);
        let r = minimize(&p, &mut x, &opts, &mut s).unwrap();
        // the minimizer (1, 1) and F = 0 of the formulas: the model changes the path only
        assert!(
            (x[0] - 1.0).abs() < 1e-6 && (x[1] - 1.0).abs() < 1e-6 && r.f < 1e-12,
            "{solver:?} {hessian:?}: {x:?} {r:?}"
        );
        let used = gn.refreshes.load(Ordering::Relaxed);
        if hessian == HessianMode::Assembled {
            // one refresh per outer iteration (the last one may end without an accepted step)
            assert!(
                used > 0 && (r.iterations..=r.iterations + 1).contains(&used),
                "{solver:?}: {used} refreshes, {} iterations",
                r.iterations
            );
        } else {
            assert_eq!(used, 0, "matrix-free products never assemble");
        }
    }
}
