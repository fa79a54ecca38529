//! Runs every solver with the adaptive-k driver and with Algorithm A on the folded TFI grids
//! of the seed 001 fixtures and prints the Markdown table of `docs/benchmarks.md`.
//!
//! `cargo run --release -p unamalla-optim --example seed001_table`

use std::sync::Arc;

use unamalla_functionals::{Kernel2, QuadFunctional, QuadTopology};
use unamalla_mesh::StructuredGrid2;
use unamalla_optim::drivers::{adaptive_k, omega_continuation, AdaptiveKOptions, OmegaOptions};
use unamalla_optim::fixtures::{cuad2pp, ivanenko, one_hole, perturbed};
use unamalla_optim::monitor::{NullObserver, Session};
use unamalla_optim::solver::{Solver, SolverOptions};

fn main() {
    let base: Vec<(&str, StructuredGrid2)> = vec![
        ("cuad2pp 22×22", cuad2pp(22, 22).expect("fixture")),
        ("one-hole 13×49", one_hole(13, 49).expect("fixture")),
        ("Ivanenko 21×21", ivanenko(21, 21).expect("fixture")),
    ];
    let mut fixtures = Vec::new();
    for (name, g) in base {
        fixtures.push((format!("{name} TFI"), g.clone()));
        fixtures.push((format!("{name} TFI perturbed 0.8"), perturbed(&g, 0.8, 7)));
    }
    println!("| fixture | driver | solver | initial Inocon | iterations (homot.+classic) | time [ms] | final α₋/ᾱ | F | Inocon | all-fixed α ≤ 0 | status |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for (name, grid) in &fixtures {
        let topo = Arc::new(QuadTopology::from_mesh(grid).expect("topology"));
        for driver in ["adaptive-k", "Algorithm A"] {
            for solver in Solver::ALL {
                let mut x = topo.initial_x();
                let probe = QuadFunctional::new(topo.clone(), Kernel2::Length);
                let mut obs = NullObserver;
                let mut s = Session::new(&probe, &x, &mut obs);
                let so = SolverOptions::new(solver);
                let rep = if driver == "adaptive-k" {
                    let ipk = if matches!(solver, Solver::TnTr | Solver::TnLs) {
                        5
                    } else {
                        10
                    };
                    adaptive_k(
                        &topo,
                        &mut x,
                        &AdaptiveKOptions {
                            iters_per_k: ipk,
                            solver: so,
                            ..Default::default()
                        },
                        &mut s,
                    )
                } else {
                    omega_continuation(
                        &topo,
                        &mut x,
                        &OmegaOptions {
                            solver: SolverOptions {
                                max_iter: 100,
                                ftol: 1e-8,
                                gtol: 1e-4,
                                ..so
                            },
                            ..Default::default()
                        },
                        &mut s,
                    )
                }
                .expect("driver");
                println!(
                    "| {name} | {driver} | {solver} | {} | {} ({}+{}) | {:.1} | {:.4} | {:.6} | {} | {} | {} |",
                    rep.initial_inocon,
                    rep.iterations(),
                    rep.iter_homotopic,
                    rep.iter_classic,
                    rep.elapsed.as_secs_f64() * 1e3,
                    rep.alfamin_rel(),
                    rep.f,
                    rep.inocon,
                    rep.fixed_nonpositive,
                    rep.status
                );
            }
        }
    }
}
