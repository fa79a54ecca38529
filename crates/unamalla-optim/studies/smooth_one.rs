//! Smooths the sinusoidal region with one solver and a live progress line (diagnostics).
//!
//! `cargo run --release -p unamalla-optim --example smooth_one -- 300 tn-tr [none|jacobi|block-jacobi|multigrid]`

use std::time::Instant;

use unamalla_optim::fixtures::sinusoidal;
use unamalla_optim::{
    smooth, Preconditioner, ProgressObserver, SmoothOptions, Solver, SolverOptions,
};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(100, |s| s.parse().expect("size"));
    let s: Solver = args
        .get(2)
        .map_or(Solver::TnTr, |s| s.parse().expect("solver"));
    let pre: Preconditioner = args.get(3).map_or(Preconditioner::BlockJacobi, |s| {
        s.parse().expect("preconditioner")
    });
    let mut g = sinusoidal(n, n, 0.1, 2.0).expect("region");
    let mut obs = ProgressObserver::default();
    let t = Instant::now();
    let opts =
        SmoothOptions::default().solver(SolverOptions::new(s).max_iter(500).preconditioner(pre));
    let r = smooth(&mut g, &opts, &mut obs).expect("smooth");
    obs.finish();
    println!(
        "{n}² {s} {pre:?}: {:.3}s, {} it, {} CG it (last run), α₋/ᾱ {:.4}, F {:.6}, {}",
        t.elapsed().as_secs_f64(),
        r.iterations(),
        r.cg_iterations,
        r.alfamin_rel(),
        r.f,
        r.status
    );
}
