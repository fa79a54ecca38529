//! The S1–S5 table of `docs/results.md` (the regions of `unamalla_bspline::synthetic`): for each
//! synthetic region and net size 18×18, 30×30, 35×35, the interior control points are optimized
//! (`½S_{ω,ε} + ½F_AO`, defaults of `InteriorOptions`), the biquadratic map is built and certified,
//! and `det J` is sampled on an `N × N` grid.
//!
//! ```sh
//! cargo run --release -p unamalla-bspline --example synthetic_table -- [N] [sizes...]
//! ```
//! `N` defaults to 10000 (the paper's 10⁸ samples); sizes default to `18 30 35`.

use std::time::Instant;

use unamalla_bspline::synthetic::Synthetic;
use unamalla_bspline::{
    certify_map, optimize_interior, BernsteinOutcome, ControlNet, Degree, InteriorOptions,
    TensorMap,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let samples: usize = args
        .first()
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(10_000);
    let sizes: Vec<usize> = if args.len() > 1 {
        args[1..]
            .iter()
            .map(|s| s.parse())
            .collect::<Result<_, _>>()?
    } else {
        vec![18, 30, 35]
    };
    println!(
        "| region | net | TFI start: non-convex cells | optimized: min α/ᾱ | ε-convex | opt. s | Thm 1 (bilinear) | Thm 2: failing det. / 36·patches | Bernstein (depth 4) | min det J ({samples}²) | min det J / mean | at (ξ, η) | sample s | total s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for region in Synthetic::ALL {
        for &n in &sizes {
            let t0 = Instant::now();
            let b = region.boundary(n, n)?;
            let mut net = ControlNet::from_boundary(&b)?;
            let tfi = net.convexity();
            let rep = optimize_interior(&mut net, &InteriorOptions::default())?;
            let map = TensorMap::new(Degree::Biquadratic, net)?;
            let c = certify_map(&map, samples, 4)?;
            let total = t0.elapsed().as_secs_f64();
            let t2 = c.theorem2.as_ref().map_or("n/a".to_string(), |t| {
                format!(
                    "{} ({}/{})",
                    if t.holds { "holds" } else { "fails" },
                    t.failing_determinants,
                    36 * t.patches
                )
            });
            let bern = match c.bernstein.outcome {
                BernsteinOutcome::Certified { lower_bound } => {
                    format!("certified (det J ≥ {lower_bound:.3})")
                }
                BernsteinOutcome::Refuted { value, .. } => format!("refuted ({value:.3e})"),
                BernsteinOutcome::Inconclusive { undecided } => {
                    format!("inconclusive ({undecided} subpatches)")
                }
            };
            println!(
                "| {} {} | {n}×{n} | {} | {:.4} | {} | {:.2} | {} | {} | {} | {:.4} | {:.4} | ({:.4}, {:.4}) | {:.2} | {:.2} |",
                region.name(),
                region.description(),
                tfi.nonconvex_cells,
                rep.final_min_alpha_rel,
                if rep.eps_convex { "yes" } else { "no" },
                rep.seconds,
                if c.theorem1.holds { "holds" } else { "fails" },
                t2,
                bern,
                c.sample.min,
                c.sample.min_over_mean(),
                c.sample.argmin.0,
                c.sample.argmin.1,
                c.seconds_sampling,
                total
            );
        }
    }
    Ok(())
}
