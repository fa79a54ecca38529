//! Criterion benchmark, side by side in one run: our truncated Newton (trust region, line
//! search) and L-BFGS against argmin 0.11's L-BFGS, Newton-CG and Steihaug trust region, on the
//! same problems through `unamalla_optim::argmin_adapter`.
//!
//! Problem: Winslow's functional `Σ l/α` ([Winslow 1966]; [González Flores, (2.55)]) on the TFI
//! grid of the sinusoidal square (`fixtures::sinusoidal(n, n, 0.08, 2.0)`, convex), `n` = 100 and
//! 300 nodes per side (19,208 and 177,608 variables). Every solver starts from the TFI grid and
//! stops at the first iterate with `F − F* ≤ 10⁻⁶ (F₀ − F*)`, where `F*` is our TN-TR's minimum at
//! GTOL 10⁻¹⁰ (computed once, untimed); an iteration cap ends a run that does not get there
//! (reported on stderr with the iterations, `F − F*` and whether the result is convex).
//!
//! * ours: `tn-tr` and `tn-ls` with the multigrid preconditioner, `lbfgs` with m = 5 (stopped by
//!   an observer at the target; every solver has the convexity safeguard);
//! * argmin: `LBFGS` (m = 5) and `NewtonCG` with the Armijo backtracking line search,
//!   `TrustRegion<Steihaug>` (argmin's defaults otherwise), all on the guarded adapter (cost
//!   `+∞` at non-convex points: without it L-BFGS folds the mesh, see `tests/argmin.rs` of
//!   unamalla-optim), stopped by argmin's `target_cost`.
//!
//! Before each solver's criterion samples, one probe run (outside criterion's samples) prints its
//! iterations, the remaining gap, convexity and its wall time on stderr. The sizes can be
//! restricted with `UNAMALLA_BENCH_SIZES`, e.g. `UNAMALLA_BENCH_SIZES=100` (default `100,300`).
//!
//! `cargo bench -p unamalla-workspace --bench argmin_comparison [-- FILTER]`
// criterion_group! defines an undocumented `pub fn`; a bench has no public API to document.
#![allow(missing_docs)]

use std::sync::Arc;

use argmin::core::{Executor, State};
use argmin::solver::linesearch::{condition::ArmijoCondition, BacktrackingLineSearch};
use argmin::solver::newton::NewtonCG;
use argmin::solver::quasinewton::LBFGS;
use argmin::solver::trustregion::{Steihaug, TrustRegion};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use unamalla_functionals::prelude::*;
use unamalla_functionals::{QuadFunctional, QuadTopology, Smoothness};
use unamalla_optim::argmin_adapter::ArgminProblem;
use unamalla_optim::fixtures::sinusoidal;
use unamalla_optim::monitor::{Control, Monitor, NullObserver, Session};
use unamalla_optim::solver::{minimize, Solver, SolverOptions};
use unamalla_optim::Preconditioner;

type Winslow = QuadFunctional;

/// Iteration caps (outer iterations).
const CAP_NEWTON: u64 = 300;
const CAP_LBFGS: u64 = 20_000;

struct Case {
    f: Winslow,
    x0: Vec<f64>,
    f_star: f64,
    target: f64,
}

fn case(n: usize) -> Case {
    let g = sinusoidal(n, n, 0.08, 2.0).expect("region");
    let topo = Arc::new(QuadTopology::from_mesh(&g).expect("topology"));
    let x0 = topo.initial_x();
    let f = QuadFunctional::new(topo, Smoothness::new());
    let mut x = x0.clone();
    let opts = SolverOptions::new(Solver::TnTr)
        .max_iter(1000)
        .ftol(0.0)
        .gtol(1e-10)
        .preconditioner(Preconditioner::Multigrid);
    let mut obs = NullObserver;
    let mut session = Session::new(&f, &x, &mut obs);
    let r = minimize(&f, &mut x, &opts, &mut session).expect("reference run");
    assert!(r.convex, "the reference minimum is convex");
    let f0 = f.value(&x0);
    Case {
        target: r.f + 1e-6 * (f0 - r.f),
        f_star: r.f,
        f,
        x0,
    }
}

/// One run of our solver `s` to the target: (iterations, final F, convex).
fn ours(c: &Case, s: Solver) -> (usize, f64, bool) {
    let mut x = c.x0.clone();
    let opts = SolverOptions::new(s)
        .max_iter(if s == Solver::Lbfgs {
            CAP_LBFGS as usize
        } else {
            CAP_NEWTON as usize
        })
        .ftol(0.0)
        .gtol(0.0)
        .lbfgs_memory(5)
        .preconditioner(Preconditioner::Multigrid);
    let target = c.target;
    let mut obs = |m: &Monitor| {
        if m.f <= target {
            Control::Stop
        } else {
            Control::Continue
        }
    };
    let mut session = Session::new(&c.f, &x, &mut obs);
    let r = minimize(&c.f, &mut x, &opts, &mut session).expect("our solver");
    (r.iterations, r.f, r.convex)
}

fn backtracking() -> BacktrackingLineSearch<Vec<f64>, Vec<f64>, ArmijoCondition<f64>, f64> {
    BacktrackingLineSearch::new(ArmijoCondition::new(1e-4).expect("c1"))
}

/// One run of argmin's solver `name` to the target: (iterations, final F, convex).
fn theirs(c: &Case, name: &str) -> (usize, f64, bool) {
    let p = ArgminProblem::with_convexity_guard(&c.f, &c.x0, 0.0).expect("convex start");
    let (x0, target) = (c.x0.clone(), c.target);
    let (iters, x, cost) = match name {
        "argmin-lbfgs" => {
            let r = Executor::new(p, LBFGS::new(backtracking(), 5))
                .configure(|s| s.param(x0).target_cost(target).max_iters(CAP_LBFGS))
                .run()
                .expect("argmin L-BFGS");
            let s = r.state;
            (s.get_iter(), s.get_best_param().cloned(), s.get_best_cost())
        }
        "argmin-newton-cg" => {
            let r = Executor::new(p, NewtonCG::new(backtracking()))
                .configure(|s| s.param(x0).target_cost(target).max_iters(CAP_NEWTON))
                .run()
                .expect("argmin Newton-CG");
            let s = r.state;
            (s.get_iter(), s.get_best_param().cloned(), s.get_best_cost())
        }
        _ => {
            let r = Executor::new(p, TrustRegion::new(Steihaug::new()))
                .configure(|s| s.param(x0).target_cost(target).max_iters(CAP_NEWTON))
                .run()
                .expect("argmin trust region");
            let s = r.state;
            (s.get_iter(), s.get_best_param().cloned(), s.get_best_cost())
        }
    };
    let convex = x.is_some_and(|x| ArgminProblem::new(&c.f).is_convex(&x));
    (iters as usize, cost, convex)
}

const OURS: [Solver; 3] = [Solver::TnTr, Solver::TnLs, Solver::Lbfgs];
const THEIRS: [&str; 3] = ["argmin-lbfgs", "argmin-newton-cg", "argmin-trust-region"];

fn bench(cr: &mut Criterion) {
    let mut group = cr.benchmark_group("winslow_sinusoidal");
    group.sample_size(10);
    let sizes: Vec<usize> = std::env::var("UNAMALLA_BENCH_SIZES")
        .ok()
        .map(|s| s.split(',').filter_map(|t| t.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![100, 300]);
    for n in sizes {
        let c = case(n);
        let report = |name: &str, run: &dyn Fn() -> (usize, f64, bool)| {
            let t = std::time::Instant::now();
            let (it, f, convex) = run();
            eprintln!(
                "{name}/{n}: {it} iterations, (F − F*)/(F₀ − F*) = {:.2e}, convex {convex}, \
                 probe run {:.3} s",
                (f - c.f_star) / (c.f.value(&c.x0) - c.f_star),
                t.elapsed().as_secs_f64()
            );
        };
        for s in OURS {
            report(s.name(), &|| ours(&c, s));
            group.bench_with_input(BenchmarkId::new(s.name(), n), &n, |b, _| {
                b.iter(|| ours(&c, s))
            });
        }
        for name in THEIRS {
            report(name, &|| theirs(&c, name));
            group.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter(|| theirs(&c, name))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
