//! Untangle + smooth ((6.8), ε = 0.01) the TFI grid of the sinusoidal four-sided region with
//! each solver, directly and coarse-to-fine (refine ×3 per level, boundary reset to the exact
//! fine boundary). Prints a Markdown table.
//!
//! `cargo run --release -p unamalla-optim --example large_grid -- 100,300,1000 [solvers]`
//! (sizes are nodes per side; solvers default to all four, e.g. `tn-tr,lbfgs`; a third
//! argument `c2f` runs only the coarse-to-fine variant).

use std::time::Instant;

use unamalla_functionals::QuadTopology;
use unamalla_mesh::StructuredGrid2;
use unamalla_optim::fixtures::sinusoidal;
use unamalla_optim::{smooth, NullObserver, SmoothOptions, SmoothReport, Solver, SolverOptions};

const AMP: f64 = 0.1;
const WAVES: f64 = 2.0;

fn region(n: usize) -> StructuredGrid2 {
    sinusoidal(n, n, AMP, WAVES).expect("region")
}

fn run(g: &mut StructuredGrid2, solver: Solver) -> SmoothReport {
    let opts = SmoothOptions {
        solver: SolverOptions {
            max_iter: 500,
            ..SolverOptions::new(solver)
        },
        ..SmoothOptions::default()
    };
    smooth(g, &opts, &mut NullObserver).expect("smooth")
}

/// Coarse-to-fine: solve on `(n−1)/3ᵏ + 1` nodes, refine ×3, reset the boundary, repeat.
fn coarse_to_fine(n: usize, solver: Solver) -> (StructuredGrid2, usize, f64) {
    let mut levels = vec![n];
    while (levels[levels.len() - 1] - 1) % 3 == 0 && (levels[levels.len() - 1] - 1) / 3 >= 60 {
        let l = levels[levels.len() - 1];
        levels.push((l - 1) / 3 + 1);
    }
    levels.reverse();
    let mut g = region(levels[0]);
    let mut it = 0;
    let r0 = run(&mut g, solver);
    eprintln!(
        "level {}: {:.3}s, {} it",
        levels[0],
        r0.elapsed.as_secs_f64(),
        r0.iterations()
    );
    for &l in &levels[1..] {
        let mut f = g.refined(2, 2).expect("refine");
        let exact = region(l);
        for j in 0..l {
            for i in 0..l {
                if exact.is_boundary(i, j) {
                    f.set_node(i, j, exact.node(i, j));
                }
            }
        }
        let r = run(&mut f, solver);
        eprintln!(
            "level {l}: {:.3}s, {} it, initial Inocon {}, {}",
            r.elapsed.as_secs_f64(),
            r.iterations(),
            r.initial_inocon,
            r.status
        );
        it += r.iterations();
        g = f;
    }
    let t = QuadTopology::from_mesh(&g).expect("topology");
    let s = t.alpha_summary(&t.initial_x());
    (g, it, s.min / s.mean)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let sizes: Vec<usize> = args
        .get(1)
        .map(|s| s.split(',').map(|v| v.parse().expect("size")).collect())
        .unwrap_or_else(|| vec![100, 300]);
    let solvers: Vec<Solver> = args
        .get(2)
        .map(|s| s.split(',').map(|v| v.parse().expect("solver")).collect())
        .unwrap_or_else(|| Solver::ALL.to_vec());
    let c2f_only = args.get(3).is_some_and(|a| a == "c2f");
    println!("| nodes | solver | start | initial Inocon | iterations | time [s] | final α₋/ᾱ | F | status |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for &n in &sizes {
        for &s in &solvers {
            let mut g = region(n);
            let t0 = Instant::now();
            let r = if c2f_only { None } else { Some(run(&mut g, s)) };
            if let Some(r) = r {
                println!(
                    "| {n}² | {s} | TFI | {} | {} | {:.3} | {:.4} | {:.6} | {} |",
                    r.initial_inocon,
                    r.iterations(),
                    t0.elapsed().as_secs_f64(),
                    r.alfamin_rel(),
                    r.f,
                    r.status
                );
            }
            if (n - 1) % 3 == 0 && (n - 1) / 3 >= 60 {
                let t0 = Instant::now();
                let (_, it, m) = coarse_to_fine(n, s);
                println!(
                    "| {n}² | {s} | coarse-to-fine | – | {it} (finest levels) | {:.3} | {m:.4} | – | – |",
                    t0.elapsed().as_secs_f64()
                );
            }
        }
    }
}
