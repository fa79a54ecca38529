//! Time to quality on the sinusoidal TFI grid: the pipeline's smoother
//! ([`unamalla_core::pipeline::default_smooth_options`]: [Méndez 2023, (6.8)] at σ = 0.5, truncated
//! Newton, the convergence tests [`unamalla_core::pipeline::DEFAULT_STOP_RULES`]) against a
//! *converged reference* — the same functional run with the window tests off, FTOL 10⁻¹², the inner
//! CG at its library default cap (200) and up to `MAXITER` iterations on the fine level (through
//! the coarse levels, which only shorten the way to the same minimum).
//!
//! `cargo run --release -p unamalla-core --example sinusoidal_quality -- N [MODE] [MAXITER]`
//! * `N`: nodes per side (e.g. `1000`);
//! * `MODE`: a comma-separated list of `default` (the options on the fine grid alone), `c2f`
//!   (the same options through [`smooth_coarse_to_fine`], ratio 3, coarse levels to FTOL
//!   10⁻⁶) and `reference` (default `default,c2f,reference`);
//! * `MAXITER`: the reference's iteration cap (default 3000).
//!
//! With `UNAMALLA_TRACE=1` every observer call prints `trace PHASE F α₋/ᾱ μ-share elapsed` on
//! stderr.
//!
//! Printed per run: iterations, wall and CPU seconds (user + system, all threads, from
//! `/proc/self/stat`), ε-convexity, α₋/ᾱ and the share of cells with μ ≥ 0.8
//! ([`unamalla_mesh::quality::MU_GOOD`]). The grid is [`unamalla_optim::fixtures::sinusoidal`]
//! with amplitude 0.1 and two waves, the fixture of `unamalla-optim`'s benchmarks.

use std::time::Instant;

use unamalla_core::pipeline::default_smooth_options;
use unamalla_mesh::quality::{quad_metrics_per_cell, MU_GOOD};
use unamalla_mesh::StructuredGrid2;
use unamalla_optim::fixtures::sinusoidal;
use unamalla_optim::monitor::{Control, Monitor};
use unamalla_optim::{smooth, smooth_coarse_to_fine, CoarseToFineOptions, StopRules};

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
    (t(11) + t(12)) / 100.0
}

/// Share (percent) of cells with μ ≥ 0.8.
fn good_share(g: &StructuredGrid2) -> f64 {
    let m = quad_metrics_per_cell(g);
    100.0 * m.iter().filter(|q| q.mu >= MU_GOOD).count() as f64 / m.len().max(1) as f64
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().and_then(|s| s.parse().ok()).unwrap_or(1000);
    let modes: Vec<&str> = args
        .get(1)
        .map(String::as_str)
        .unwrap_or("default,c2f,reference")
        .split(',')
        .collect();
    let maxiter: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3000);
    let g0 = sinusoidal(n, n, 0.1, 2.0).expect("sinusoidal grid");
    println!("{n}² nodes, TFI: μ ≥ 0.8 {:.2} %", good_share(&g0));
    println!("| run | iterations | wall s | cpu s | ε-convex | α₋/ᾱ | μ ≥ 0.8 % |");
    println!("|---|---|---|---|---|---|---|");
    for mode in modes {
        let mut o = default_smooth_options();
        if mode == "reference" {
            o.solver.stop = StopRules::default();
            o.solver.ftol = 1e-12;
            o.solver.cg_max_iter = 200;
            o.solver.max_iter = maxiter;
        }
        let trace_on = std::env::var_os("UNAMALLA_TRACE").is_some();
        let mut trace = |m: &Monitor| {
            if trace_on {
                eprintln!(
                    "trace {:?} F {:.6e} a {:.4e} mu {:?} t {:.2}",
                    m.phase,
                    m.f,
                    m.alfamin_rel(),
                    m.mu,
                    m.elapsed.as_secs_f64()
                );
            }
            Control::Continue
        };
        let mut g = g0.clone();
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let r = match mode {
            "default" => smooth(&mut g, &o, &mut trace).expect("smooth"),
            "c2f" | "reference" => {
                let co = CoarseToFineOptions::default().smooth(o);
                let rep = smooth_coarse_to_fine(&mut g, &co, &mut trace).expect("c2f");
                for l in &rep.levels {
                    eprintln!(
                        "  level {}x{}: {} iterations, {:.2} s, {:?}",
                        l.m,
                        l.n,
                        l.report.iter_classic,
                        l.report.elapsed.as_secs_f64(),
                        l.report.status
                    );
                }
                rep.fine().expect("a fine level").clone()
            }
            other => panic!("unknown mode {other}"),
        };
        let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
        println!(
            "| {mode} | {} + {} | {wall:.2} | {cpu:.2} | {} | {:.4} | {:.2} | ({:?})",
            r.iter_homotopic,
            r.iter_classic,
            r.eps_convex,
            r.alfamin / r.alpha_bar,
            good_share(&g),
            r.status
        );
    }
}
