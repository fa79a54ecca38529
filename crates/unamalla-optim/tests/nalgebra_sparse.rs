//! One Newton solve with nalgebra-sparse's sparse Cholesky on an SPD Hessian against our
//! conjugate gradients (the inner CG of truncated Newton).

use std::sync::Arc;

use nalgebra::DVector;
use nalgebra_sparse::factorization::CscCholesky;
use nalgebra_sparse::CscMatrix;
use unamalla_functionals::prelude::*;
use unamalla_functionals::{Length, QuadFunctional, QuadTopology, Smoothness};
use unamalla_optim::fixtures::sinusoidal;
use unamalla_optim::monitor::{NullObserver, Session};
use unamalla_optim::solver::{minimize, Solver, SolverOptions};
use unamalla_optim::Preconditioner;

/// Solves `H d = −g` at `x` with nalgebra-sparse's Cholesky of the converted Hessian.
fn cholesky_newton_step<P: Problem>(p: &P, x: &[f64]) -> Vec<f64> {
    let mut h = p.hessian_pattern();
    p.hessian(x, &mut h);
    let csc = CscMatrix::from(&h.to_nalgebra_sparse().unwrap());
    let chol = CscCholesky::factor(&csc).expect("the Hessian is SPD");
    let mut g = vec![0.0; x.len()];
    p.value_grad(x, &mut g);
    let rhs = DVector::from_iterator(g.len(), g.iter().map(|v| -v));
    chol.solve(&rhs).iter().copied().collect()
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

#[test]
fn cholesky_solve_equals_our_cg_on_the_length_functional() {
    // The length functional Σ(|a|² + |b|²) is quadratic in the free nodes with an SPD Hessian
    // (a Dirichlet graph Laplacian ⊗ I₂), so its minimizer is x₀ + d with H d = −∇F(x₀): one
    // Cholesky solve. Our TN-TR with its inner CG (no preconditioner) must reach the same point.
    let g = sinusoidal(17, 15, 0.08, 1.0).unwrap();
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let x0 = topo.initial_x();
    let f = QuadFunctional::new(topo, Length);
    let d = cholesky_newton_step(&f, &x0);
    let mut x = x0.clone();
    let opts = SolverOptions::new(Solver::TnTr)
        .max_iter(50)
        .ftol(0.0)
        .gtol(1e-13)
        .cg_max_iter(1000)
        .preconditioner(Preconditioner::None);
    let mut obs = NullObserver;
    let mut session = Session::new(&f, &x, &mut obs);
    minimize(&f, &mut x, &opts, &mut session).unwrap();
    let ours: Vec<f64> = x.iter().zip(&x0).map(|(a, b)| a - b).collect();
    let scale = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 1e-3, "the TFI start is not the minimizer");
    assert!(
        max_diff(&ours, &d) <= 1e-9 * scale,
        "CG vs Cholesky: {}",
        max_diff(&ours, &d)
    );
}

#[test]
fn cholesky_newton_step_at_the_winslow_minimum_is_negligible_and_spd() {
    // At a strict local minimum of Winslow's functional the Hessian is SPD (Cholesky succeeds)
    // and the Newton step −H⁻¹∇F is of the order of ‖∇F‖/λ_min: tiny after TN-TR at GTOL 10⁻¹⁰.
    let g = sinusoidal(15, 15, 0.08, 2.0).unwrap();
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let mut x = topo.initial_x();
    let f = QuadFunctional::new(topo, Smoothness::new());
    let d0 = cholesky_newton_step(&f, &x);
    let opts = SolverOptions::new(Solver::TnTr)
        .max_iter(200)
        .ftol(0.0)
        .gtol(1e-10);
    let mut obs = NullObserver;
    let mut session = Session::new(&f, &x, &mut obs);
    minimize(&f, &mut x, &opts, &mut session).unwrap();
    let d = cholesky_newton_step(&f, &x);
    let n0 = d0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let n1 = d.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(
        n1 <= 1e-6 * n0,
        "Newton step {n1} at the minimum vs {n0} at the start"
    );
}
