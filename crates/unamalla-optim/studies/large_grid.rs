//! Untangle + smooth ((6.8), ε = 0.01) the TFI grid of the sinusoidal four-sided region, directly
//! from the TFI grid and/or coarse-to-fine ([`smooth_coarse_to_fine`], ratio 3), and print a
//! Markdown table.
//!
//! `cargo run --release -p unamalla-optim --example large_grid -- SIZES [SOLVERS] [MODE] [PRECOND] [HESSIAN] [FTOL] [GTOL] [SIGMA]`
//! * `SIZES`: nodes per side, e.g. `100,301,1000`;
//! * `SOLVERS`: e.g. `tn-tr,tn-ls` (default all four);
//! * `MODE`: `direct`, `c2f` or `both` (default `both`; coarse-to-fine needs `(n−1)` divisible
//!   by 3 with a coarse level of at least 30 nodes);
//! * `PRECOND`: the CG preconditioner of truncated Newton, `multigrid` (default) or
//!   `block-jacobi`, `jacobi`, `none`;
//! * `HESSIAN`: `exact` (default) or `psd` (the PSD-projected model Hessian,
//!   [`HessianMode::ProjectedPsd`]);
//! * `FTOL`: the finest level's FTOL (default 1e-9); `GTOL`: relative GTOL (default 0 = off);
//! * `SIGMA`: σ of (6.8) (default 0.1).
//!
//! The time column is wall time; `cpu` (in the per-level lines and after the table row) is
//! the process CPU time (user + system, all threads) from `/proc/self/stat`.
//!
//! Tolerance (the same for every size, so the scaling is comparable): the run stops when the
//! relative decrease of F in a step is at most FTOL (default 1e-9; `(F_old − F) ≤ FTOL·F`; near the
//! optimum Newton's decrease approximates `F_old − F*`); GTOL is off unless given; MAXITER 500. The
//! coarse levels of coarse-to-fine stop at FTOL 1e-6. The scaling table of `docs/benchmarks.md`
//! ("Large grids") uses FTOL 1e-6 on every level (`… exact 1e-6 0`): on 301² it gives F within
//! 2·10⁻⁶ (relative) of the FTOL-1e-9 result.

use std::time::Instant;

use unamalla_mesh::StructuredGrid2;
use unamalla_optim::fixtures::sinusoidal;
use unamalla_optim::{
    smooth, smooth_coarse_to_fine, CoarseToFineOptions, HessianMode, NullObserver, Preconditioner,
    SmoothFunctional, SmoothOptions, Solver, SolverOptions,
};

/// CPU time of this process (user + system, all threads) in seconds, from `/proc/self/stat`
/// (clock ticks of 1/100 s); 0 where unavailable.
fn cpu_seconds() -> f64 {
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    let Some(rest) = s.rsplit(')').next() else {
        return 0.0;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let t = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    // fields 14 and 15 of stat (utime, stime) are 12 and 13 after the ")"
    (t(11) + t(12)) / 100.0
}

const AMP: f64 = 0.1;
const WAVES: f64 = 2.0;

fn region(n: usize) -> StructuredGrid2 {
    sinusoidal(n, n, AMP, WAVES).expect("region")
}

/// The benchmark's options (see the module docs for the tolerance).
fn options(
    solver: Solver,
    pre: Preconditioner,
    hessian: HessianMode,
    ftol: f64,
    gtol: f64,
    sigma: f64,
) -> SmoothOptions {
    SmoothOptions::default()
        .functional(SmoothFunctional::block_smoothing(sigma))
        .solver(
            SolverOptions::new(solver)
                .max_iter(500)
                .ftol(ftol)
                .gtol(gtol)
                .preconditioner(pre)
                .hessian(hessian),
        )
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
    let hessian = match args.get(5).map(String::as_str) {
        Some("psd") => HessianMode::ProjectedPsd,
        _ => HessianMode::Assembled,
    };
    let ftol: f64 = args.get(6).map_or(1e-9, |s| s.parse().expect("ftol"));
    let gtol: f64 = args.get(7).map_or(0.0, |s| s.parse().expect("gtol"));
    let sigma: f64 = args.get(8).map_or(0.1, |s| s.parse().expect("sigma"));
    println!(
        "| nodes | solver | preconditioner | start | iterations | CG iterations | time [s] | final α₋/ᾱ | F | status |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for &n in &sizes {
        for &s in &solvers {
            let opts = options(s, pre, hessian, ftol, gtol, sigma);
            let pname = if matches!(s, Solver::TnTr | Solver::TnLs) {
                let h = if hessian == HessianMode::ProjectedPsd {
                    "PSD model"
                } else {
                    "exact H"
                };
                format!("{}, {h}", pre.name())
            } else {
                "–".to_string()
            };
            if mode != "c2f" {
                let mut g = region(n);
                let t0 = Instant::now();
                let c0 = cpu_seconds();
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
                eprintln!("  cpu {:.3} s", cpu_seconds() - c0);
            }
            if mode != "direct" {
                let co = CoarseToFineOptions::default().smooth(opts.clone());
                let mut g = region(n);
                let t0 = Instant::now();
                let c0 = cpu_seconds();
                let rep = smooth_coarse_to_fine(&mut g, &co, &mut NullObserver).expect("c2f");
                let total = t0.elapsed().as_secs_f64();
                eprintln!("  cpu {:.3} s (all levels)", cpu_seconds() - c0);
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
