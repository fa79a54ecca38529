//! Runs every solver with the adaptive-k driver and with Algorithm A on the folded TFI grids
//! of the test regions of [González Flores] (`unamalla_optim::fixtures`; the references are listed
//! in `docs/references.md` of the repository) and prints the Markdown table of
//! `docs/benchmarks.md`.
//!
//! `cargo run --release -p unamalla-optim --example options_table`
//!
//! With the argument `options` it prints instead the table of the options added for the
//! source's remaining rows (docs/results.md, section "González Flores options: homotopy paths,
//! …"): the paths `t²`, `t³`, `sin(πt/2)` ([González Flores, §5.3]), L-BFGS with `m = 3`,
//! pointwise Newton by components, the classic combinations t-Area–Length (σ = 0.5, 0.9) and
//! t-Area–Orthogonality (Table 5.1), and Ivanenko's convex-mesh functional ((2.50)).

use std::sync::Arc;

use unamalla_functionals::{Length, QuadFunctional, QuadTopology};
use unamalla_mesh::StructuredGrid2;
use unamalla_optim::drivers::{
    adaptive_k, classic_combination, ivanenko_untangle, omega_continuation, AdaptiveKOptions,
    ClassicCombination, ClassicOptions, HomotopySchedule, OmegaOptions,
};
use unamalla_optim::fixtures::{cuad2pp, ivanenko, one_hole, perturbed};
use unamalla_optim::monitor::{NullObserver, Session};
use unamalla_optim::solver::{PointwiseMode, Solver, SolverOptions};

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
    if std::env::args().nth(1).as_deref() == Some("options") {
        options_table(&fixtures);
        return;
    }
    println!("| fixture | driver | solver | initial Inocon | iterations (homot.+classic) | time [ms] | final α₋/ᾱ | F | Inocon | all-fixed α ≤ 0 | status |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for (name, grid) in &fixtures {
        let topo = Arc::new(QuadTopology::from_mesh(grid).expect("topology"));
        for driver in ["adaptive-k", "Algorithm A"] {
            for solver in Solver::ALL {
                let mut x = topo.initial_x();
                let probe = QuadFunctional::new(topo.clone(), Length);
                let mut obs = NullObserver;
                let mut s = Session::new(&probe, &x, &mut obs);
                let so = SolverOptions::new(solver);
                let rep = if driver == "adaptive-k" {
                    let ipk = iters_per_k(solver);
                    adaptive_k(
                        &topo,
                        &mut x,
                        &AdaptiveKOptions::default().iters_per_k(ipk).solver(so),
                        &mut s,
                    )
                } else {
                    omega_continuation(
                        &topo,
                        &mut x,
                        &OmegaOptions::default().solver(so.max_iter(100).ftol(1e-8).gtol(1e-4)),
                        &mut s,
                    )
                }
                .expect("driver");
                println!(
                    "| {name} | {driver} | {solver} | {} | {} | {} |",
                    cells(&rep),
                    rep.fixed_nonpositive,
                    rep.status
                );
            }
        }
    }
}

/// The table of the new options: one row per (fixture, option).
fn options_table(fixtures: &[(String, StructuredGrid2)]) {
    println!("| fixture | option | initial Inocon | iterations (homot.+classic) | time [ms] | final α₋/ᾱ | F | Inocon | status |");
    println!("|---|---|---|---|---|---|---|---|---|");
    enum Opt {
        Adaptive(&'static str, HomotopySchedule, SolverOptions),
        Classic(&'static str, ClassicCombination, f64),
        Ivanenko(&'static str),
    }
    let tn = SolverOptions::new(Solver::TnTr);
    let opts = vec![
        Opt::Adaptive(
            "karea-length, homotopy t², tn-tr",
            HomotopySchedule::Square,
            tn.clone(),
        ),
        Opt::Adaptive(
            "karea-length, homotopy t³, tn-tr",
            HomotopySchedule::Cube,
            tn.clone(),
        ),
        Opt::Adaptive(
            "karea-length, homotopy sine, tn-tr",
            HomotopySchedule::Sine,
            tn.clone(),
        ),
        Opt::Adaptive(
            "karea-length, linear, lbfgs m = 3",
            HomotopySchedule::Linear,
            SolverOptions::new(Solver::Lbfgs).lbfgs_memory(3),
        ),
        Opt::Adaptive(
            "karea-length, linear, pointwise by components",
            HomotopySchedule::Linear,
            SolverOptions::new(Solver::Pointwise).pointwise_mode(PointwiseMode::Components),
        ),
        Opt::Classic(
            "area-length σ = 0.5, tn-tr",
            ClassicCombination::AreaLength,
            0.5,
        ),
        Opt::Classic(
            "area-length σ = 0.9, tn-tr",
            ClassicCombination::AreaLength,
            0.9,
        ),
        Opt::Classic(
            "area-ortho (σ = 0.5), tn-tr",
            ClassicCombination::AreaOrthogonality,
            0.5,
        ),
        Opt::Ivanenko("ivanenko ε = 0.01, tn-tr"),
    ];
    for (name, grid) in fixtures {
        let topo = Arc::new(QuadTopology::from_mesh(grid).expect("topology"));
        for o in &opts {
            let mut x = topo.initial_x();
            let probe = QuadFunctional::new(topo.clone(), Length);
            let mut obs = NullObserver;
            let mut s = Session::new(&probe, &x, &mut obs);
            let (label, rep) = match o {
                Opt::Adaptive(label, schedule, so) => {
                    let ipk = iters_per_k(so.solver);
                    let r = adaptive_k(
                        &topo,
                        &mut x,
                        &AdaptiveKOptions::default()
                            .iters_per_k(ipk)
                            .solver(so.clone())
                            .schedule(*schedule),
                        &mut s,
                    );
                    (label, r)
                }
                Opt::Ivanenko(label) => {
                    (label, ivanenko_untangle(&topo, &mut x, 0.01, &tn, &mut s))
                }
                Opt::Classic(label, c, sigma) => {
                    let r = classic_combination(
                        &topo,
                        &mut x,
                        &ClassicOptions::new(*c, *sigma)
                            .presmooth(0)
                            .eps(0.01)
                            .solver(tn.clone()),
                        &mut s,
                    );
                    (label, r)
                }
            };
            let rep = rep.expect("driver");
            println!("| {name} | {label} | {} | {} |", cells(&rep), rep.status);
        }
    }
}

/// Iterations per `k` update: 5 for truncated Newton, 10 otherwise (the benchmark's setting).
fn iters_per_k(solver: Solver) -> usize {
    if matches!(solver, Solver::TnTr | Solver::TnLs) {
        5
    } else {
        10
    }
}

/// The columns "initial Inocon" … "Inocon" of a row.
fn cells(rep: &unamalla_optim::SmoothReport) -> String {
    format!(
        "{} | {} ({}+{}) | {:.1} | {:.4} | {:.6} | {}",
        rep.initial_inocon,
        rep.iterations(),
        rep.iter_homotopic,
        rep.iter_classic,
        rep.elapsed.as_secs_f64() * 1e3,
        rep.alfamin_rel(),
        rep.f,
        rep.inocon,
    )
}
