//! How far the ε-convex optimum of (6.8) moves when the grid is refined: the optimum on the
//! coarse grid `(N − 1)/3 + 1`, prolongated to `N` ([`prolongate`]: the coarse-to-fine start),
//! against the optimum on `N`, for several σ. The evidence of docs/benchmarks.md, "Why 1000² in
//! 5 s is out of reach at σ = 0.1".
//!
//! `cargo run --release -p unamalla-optim --example optimum_shift -- [N] [SIGMAS]` (defaults `301`
//! and `1,0.5,0.1`). Both optima: coarse-to-fine truncated Newton (multigrid preconditioner, FTOL
//! 1e-6 on every level, the rule of docs/benchmarks.md, "Large grids"). The shift of node `(i, j)`
//! is measured in units of `h = √(mean cell area)` of the fine grid and summarized by the node's
//! layer `min(i, j, N−1−i, N−1−j)` (distance to the boundary in cells).

use unamalla_mesh::region::signed_area;
use unamalla_mesh::{HasNodes, HasQuadCells, StructuredGrid2};
use unamalla_optim::coarse_to_fine::prolongate;
use unamalla_optim::fixtures::sinusoidal;
use unamalla_optim::{
    smooth_coarse_to_fine, CoarseToFineOptions, NullObserver, Preconditioner, SmoothFunctional,
    SmoothOptions, Solver, SolverOptions,
};

fn optimum(n: usize, sigma: f64) -> Result<(StructuredGrid2, f64), Box<dyn std::error::Error>> {
    let mut g = sinusoidal(n, n, 0.1, 2.0)?;
    let co = CoarseToFineOptions::default().smooth(
        SmoothOptions::default()
            .functional(SmoothFunctional::block_smoothing(sigma))
            .solver(
                SolverOptions::new(Solver::TnTr)
                    .max_iter(500)
                    .ftol(1e-6)
                    .gtol(0.0)
                    .preconditioner(Preconditioner::Multigrid),
            ),
    );
    let rep = smooth_coarse_to_fine(&mut g, &co, &mut NullObserver)?;
    let f = rep.fine().map_or(f64::NAN, |r| r.f);
    Ok((g, f))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(Ok(301), |s| s.parse())?;
    let sigmas: Vec<f64> = args
        .get(2)
        .map_or("1,0.5,0.1", String::as_str)
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let nc = (n - 1) / 3 + 1;
    let tfi = sinusoidal(n, n, 0.1, 2.0)?;
    let area: f64 = (0..tfi.num_quads())
        .map(|c| signed_area(&tfi.quad_points(c)))
        .sum();
    let h = (area / tfi.num_quads() as f64).sqrt();
    println!("| σ | F on {nc}² | F on {n}² | rms shift, layers 0–5 | rms shift, layers 6–20 | rms shift, layers > 20 | max shift |");
    println!("|---|---|---|---|---|---|---|");
    for &sigma in &sigmas {
        let (coarse, fc) = optimum(nc, sigma)?;
        let (fine, ff) = optimum(n, sigma)?;
        let p = prolongate(&coarse, &tfi, 3)?;
        let mut sums = [0.0f64; 3];
        let mut counts = [0usize; 3];
        let mut max: f64 = 0.0;
        for (k, (a, b)) in p.nodes().iter().zip(fine.nodes()).enumerate() {
            let (i, j) = (k % n, k / n);
            let layer = i.min(j).min(n - 1 - i).min(n - 1 - j);
            let band = if layer <= 5 {
                0
            } else if layer <= 20 {
                1
            } else {
                2
            };
            let d = (*a - *b).length() / h;
            sums[band] += d * d;
            counts[band] += 1;
            max = max.max(d);
        }
        let rms = |b: usize| (sums[b] / counts[b].max(1) as f64).sqrt();
        println!(
            "| {sigma} | {fc:.6} | {ff:.6} | {:.3} h | {:.3} h | {:.3} h | {max:.2} h |",
            rms(0),
            rms(1),
            rms(2)
        );
    }
    Ok(())
}
