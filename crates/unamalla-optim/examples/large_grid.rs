//! Untangle + smooth ((6.8), ε = 0.01) the TFI grid of the sinusoidal four-sided region, directly
//! from the TFI grid and/or coarse-to-fine ([`smooth_coarse_to_fine`], ratio 3), and print a
//! Markdown table.
//!
//! `cargo run --release -p unamalla-optim --example large_grid -- SIZES [SOLVERS] [MODE] [PRECOND]`
//! * `SIZES`: nodes per side, e.g. `100,301,1000`;
//! * `SOLVERS`: e.g. `tn-tr,tn-ls` (default all four);
//! * `MODE`: `direct`, `c2f` or `both` (default `both`; coarse-to-fine needs `(n−1)` divisible
//!   by 3 with a coarse level of at least 30 nodes);
//! * `PRECOND`: the CG preconditioner of truncated Newton, `multigrid` (default) or
//!   `block-jacobi`, `jacobi`, `none`.
//!
//! Tolerance (the same for every size, so the scaling is comparable): the run stops when the
//! relative decrease of F in a step is at most FTOL = 1e-9 (`(F_old − F) ≤ 1e-9·F`; near the
//! optimum Newton's decrease approximates `F_old − F*`); GTOL is off; MAXITER 500. The coarse
//! levels of coarse-to-fine stop at FTOL 1e-6.

use std::time::Instant;

use unamalla_mesh::StructuredGrid2;
use unamalla_optim::fixtures::sinusoidal;
use unamalla_optim::{
    smooth, smooth_coarse_to_fine, CoarseToFineOptions, NullObserver, Preconditioner,
    SmoothOptions, Solver, SolverOptions,
};

const AMP: f64 = 0.1;
const WAVES: f64 = 2.0;

fn region(n: usize) -> StructuredGrid2 {
    sinusoidal(n, n, AMP, WAVES).expect("region")
}

/// The benchmark's options (see the module docs for the tolerance).
fn options(solver: Solver, pre: Preconditioner) -> SmoothOptions {
    SmoothOptions {
        solver: SolverOptions {
            max_iter: 500,
            ftol: 1e-9,
            gtol: 0.0,
            preconditioner: pre,
            ..SolverOptions::new(solver)
        },
        ..SmoothOptions::default()
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let sizes: Vec<usize> = args
        .get(1)
        .map(|s| s.split(',').map(|v| v.parse().expect("size")).collect())
        .unwrap_or_else(|| vec![100, 301]);
    let solvers: Vec<Solver> = args
        .get(2)
        .map(|s| s.split(',').map(|v| v.parse().expect("solver")).collect())
        .unwrap_or_else(|| Solver::ALL.to_vec());
    let mode = args.get(3).map_or("both", String::as_str);
    let pre: Preconditioner = args.get(4).map_or(Preconditioner::Multigrid, |s| {
        s.parse().expect("preconditioner")
    });
    println!(
        "| nodes | solver | preconditioner | start | iterations | CG iterations | time [s] | final α₋/ᾱ | F | status |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for &n in &sizes {
        for &s in &solvers {
            let opts = options(s, pre);
            let pname = if matches!(s, Solver::TnTr | Solver::TnLs) {
                pre.name()
            } else {
                "–"
            };
            if mode != "c2f" {
                let mut g = region(n);
                let t0 = Instant::now();
                let r = smooth(&mut g, &opts, &mut NullObserver).expect("smooth");
                println!(
                    "| {n}² | {s} | {pname} | TFI | {} | {} | {:.3} | {:.4} | {:.6} | {} |",
                    r.iterations(),
                    r.cg_iterations,
                    t0.elapsed().as_secs_f64(),
                    r.alfamin_rel(),
                    r.f,
                    r.status
                );
            }
            if mode != "direct" {
                let co = CoarseToFineOptions {
                    smooth: opts.clone(),
                    ..CoarseToFineOptions::default()
                };
                let mut g = region(n);
                let t0 = Instant::now();
                let rep = smooth_coarse_to_fine(&mut g, &co, &mut NullObserver).expect("c2f");
                let total = t0.elapsed().as_secs_f64();
                let mut its = Vec::new();
                for l in &rep.levels {
                    eprintln!(
                        "  level {}²: start α₋/ᾱ {:.4}{}, {} it, {} CG, {:.3} s, {}",
                        l.m,
                        l.start_alfamin_rel,
                        if l.restarted { " (restarted)" } else { "" },
                        l.report.iterations(),
                        l.report.cg_iterations,
                        l.report.elapsed.as_secs_f64(),
                        l.report.status
                    );
                    its.push(format!("{}", l.report.iterations()));
                }
                if let Some(f) = rep.fine() {
                    println!(
                        "| {n}² | {s} | {pname} | coarse-to-fine ({}) | {} | {} (finest) | {total:.3} | {:.4} | {:.6} | {}{} |",
                        rep.levels.iter().map(|l| format!("{}²", l.m)).collect::<Vec<_>>().join(" → "),
                        its.join(" + "),
                        f.cg_iterations,
                        f.alfamin_rel(),
                        f.f,
                        f.status,
                        if rep.fallback { " (fallback)" } else { "" }
                    );
                }
            }
        }
    }
}
