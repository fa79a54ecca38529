//! argmin's solvers on our functionals through `unamalla_optim::argmin_adapter` (feature
//! `argmin`): L-BFGS, Newton-CG and the Steihaug trust region from a convex start, with and
//! without the convexity guard, against our own truncated Newton.
#![cfg(feature = "argmin")]

use std::sync::Arc;

use argmin::core::{CostFunction, Executor, Gradient, State};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::linesearch::{condition::ArmijoCondition, BacktrackingLineSearch};
use argmin::solver::newton::NewtonCG;
use argmin::solver::quasinewton::LBFGS;
use argmin::solver::trustregion::{Steihaug, TrustRegion};
use unamalla_functionals::{
    HexFunctional, HexTopology, Problem, QuadFunctional, QuadTopology, Scaling3, Smoothness,
};
use unamalla_mesh::{DVec3, StructuredGrid3};
use unamalla_optim::argmin_adapter::ArgminProblem;
use unamalla_optim::fixtures::sinusoidal;
use unamalla_optim::monitor::{NullObserver, Session};
use unamalla_optim::solver::{minimize, Solver, SolverOptions};

type Winslow = QuadFunctional;

/// Winslow's functional `Σ l/α` on the TFI grid of the sinusoidal square (convex start).
fn winslow(n: usize) -> (Winslow, Vec<f64>) {
    let g = sinusoidal(n, n, 0.08, 2.0).unwrap();
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let x0 = topo.initial_x();
    (QuadFunctional::new(topo, Smoothness::new()), x0)
}

/// Our TN-TR to a tight gradient tolerance: the reference minimum.
fn reference_min<P: Problem>(p: &P, x0: &[f64]) -> f64 {
    let mut x = x0.to_vec();
    let opts = SolverOptions::new(Solver::TnTr)
        .max_iter(500)
        .ftol(0.0)
        .gtol(1e-10);
    let mut obs = NullObserver;
    let mut session = Session::new(p, &x, &mut obs);
    let r = minimize(p, &mut x, &opts, &mut session).unwrap();
    assert!(r.convex);
    r.f
}

fn gnorm<P: Problem>(a: &ArgminProblem<'_, P>, x: &[f64]) -> f64 {
    a.gradient(&x.to_vec())
        .unwrap()
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt()
}

fn backtracking() -> BacktrackingLineSearch<Vec<f64>, Vec<f64>, ArmijoCondition<f64>, f64> {
    BacktrackingLineSearch::new(ArmijoCondition::new(1e-4).unwrap())
}

#[test]
fn guarded_argmin_solvers_keep_a_convex_start_convex_and_reach_our_minimum() {
    let (f, x0) = winslow(21);
    let f_star = reference_min(&f, &x0);
    let g0 = gnorm(&ArgminProblem::new(&f), &x0);
    let check = |name: &str, x: &[f64], cost: f64| {
        let a = ArgminProblem::new(&f);
        assert!(a.is_convex(x), "{name}: the result has a non-convex cell");
        // a minimizer of the same problem: F within 1e-8 (relative) of our TN-TR's and a
        // gradient reduced by 10⁶
        assert!(
            (cost - f_star).abs() <= 1e-8 * f_star.abs(),
            "{name}: F {cost} vs {f_star}"
        );
        assert!(gnorm(&a, x) <= 1e-6 * g0, "{name}: ‖g‖ {}", gnorm(&a, x));
    };

    let p = ArgminProblem::with_convexity_guard(&f, &x0, 0.0).unwrap();
    let lbfgs = LBFGS::new(backtracking(), 5)
        .with_tolerance_grad(1e-7 * g0)
        .unwrap();
    let r = Executor::new(p, lbfgs)
        .configure(|s| s.param(x0.clone()).max_iters(3000))
        .run()
        .unwrap();
    check(
        "L-BFGS",
        r.state.get_best_param().unwrap(),
        r.state.get_best_cost(),
    );

    let p = ArgminProblem::with_convexity_guard(&f, &x0, 0.0).unwrap();
    // argmin 0.11's Newton-CG converges only linearly here (hundreds of iterations where our
    // TN needs tens): its inner CG compares the *squared* residual (cg.rs, `r.dot(&r)`) with
    // min(½, √‖g‖)·‖g‖, so once ‖g‖ < 1 the CG stops after about one iteration
    let ncg = NewtonCG::new(backtracking()).with_tolerance(1e-14).unwrap();
    let r = Executor::new(p, ncg)
        .configure(|s| s.param(x0.clone()).max_iters(1000))
        .run()
        .unwrap();
    check(
        "Newton-CG",
        r.state.get_best_param().unwrap(),
        r.state.get_best_cost(),
    );

    let p = ArgminProblem::with_convexity_guard(&f, &x0, 0.0).unwrap();
    let tr = TrustRegion::new(Steihaug::new().with_max_iters(500))
        .with_radius(0.01)
        .unwrap();
    let r = Executor::new(p, tr)
        .configure(|s| s.param(x0.clone()).max_iters(300))
        .run()
        .unwrap();
    check(
        "trust region",
        r.state.get_best_param().unwrap(),
        r.state.get_best_cost(),
    );
}

#[test]
fn without_the_guard_more_thuente_lbfgs_folds_the_mesh_and_with_it_stops_with_an_error() {
    let (f, x0) = winslow(21);
    let f_star = reference_min(&f, &x0);
    // Winslow's l/α is negative for α < 0: a step across the pole at α = 0 decreases F, and
    // below F* (the minimum over convex meshes) only a folded mesh can go
    let plain = ArgminProblem::new(&f);
    let r = Executor::new(plain, LBFGS::new(MoreThuenteLineSearch::new(), 5))
        .configure(|s| s.param(x0.clone()).max_iters(200))
        .run()
        .unwrap();
    let x = r.state.get_best_param().unwrap();
    assert!(
        !ArgminProblem::new(&f).is_convex(x),
        "unguarded L-BFGS stayed convex"
    );
    assert!(r.state.get_best_cost() < f_star);

    // with the guard Moré–Thuente meets F = +∞ and ends the run with an error instead of
    // shortening the step: convex, but far from the minimum
    let guarded = ArgminProblem::with_convexity_guard(&f, &x0, 0.0).unwrap();
    let r = Executor::new(guarded, LBFGS::new(MoreThuenteLineSearch::new(), 5))
        .configure(|s| s.param(x0.clone()).max_iters(200))
        .run()
        .unwrap();
    let reason = format!("{:?}", r.state.get_termination_reason());
    assert!(reason.contains("NaN or Inf"), "{reason}");
    let x = r.state.get_best_param().unwrap();
    assert!(ArgminProblem::new(&f).is_convex(x));
    let f0 = ArgminProblem::new(&f).cost(&x0).unwrap();
    assert!(r.state.get_best_cost() - f_star > 1e-3 * (f0 - f_star));
}

#[test]
fn hexahedral_functional_through_the_adapter_with_the_trust_region() {
    // H_ω on a 5 × 5 × 5 box grid with the interior nodes moved (all tetrahedra positive)
    let g = StructuredGrid3::from_fn(5, 5, 5, |i, j, k| {
        let inner = (1..4).contains(&i) && (1..4).contains(&j) && (1..4).contains(&k);
        let s = if inner {
            0.2 * ((i * 7 + j * 3 + k) as f64 * 0.9).sin()
        } else {
            0.0
        };
        DVec3::new(i as f64 + s, j as f64 - 0.5 * s, k as f64 + 0.3 * s)
    })
    .unwrap();
    let topo = Arc::new(HexTopology::from_mesh(&g).unwrap());
    let x0 = topo.initial_x();
    let f = HexFunctional::h_omega(topo, 0.8, Scaling3::Index).unwrap();
    let p = ArgminProblem::with_convexity_guard(&f, &x0, 0.0).unwrap();
    let f0 = p.cost(&x0).unwrap();
    let g0 = gnorm(&p, &x0);
    let r = Executor::new(
        p,
        TrustRegion::new(Steihaug::new()).with_radius(0.1).unwrap(),
    )
    .configure(|s| s.param(x0.clone()).max_iters(100))
    .run()
    .unwrap();
    let x = r.state.get_best_param().unwrap();
    let a = ArgminProblem::new(&f);
    assert!(a.is_convex(x), "a tetrahedron turned over");
    assert!(r.state.get_best_cost() < f0);
    // the trust region converges: ‖g‖ drops by 10⁶
    assert!(gnorm(&a, x) <= 1e-6 * g0, "‖g‖ {} vs {g0}", gnorm(&a, x));
}
