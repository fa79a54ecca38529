//! The PDE tables of `docs/results.md`: second-order convergence of the curvilinear solver on
//! TFI and on optimized grids of a curved region, and the payoff of mesh optimization on real
//! regions (same manufactured problem, same node count, raw TFI vs optimized).
//!
//! ```text
//! cargo run --release -p unamalla-pde --features direct --example pde_tables [-- --quick]
//! ```
//!
//! `--quick` stops the convergence study at 81 × 81 nodes; `--payoff` prints only the payoff
//! table; `--functional NAME` chooses the optimization (default `karea-length`).

use std::time::Instant;

use unamalla_core::single_block::{tfi_region, Corners};
use unamalla_io::{read_region_geojson_cleaned, PartSelector};
use unamalla_mesh::quality::alpha_stats;
use unamalla_mesh::{DVec2, HasNodes, Region, StructuredGrid2};
use unamalla_optim::{smooth, NullObserver, SmoothOptions};
use unamalla_pde::manufactured::{curved_grid, observed_order, Manufactured};
use unamalla_pde::{solve_grid, Method, PdeError, Solution, SolveOptions};

/// The two manufactured problems: (U, a, b, c, d).
fn problems() -> [(Manufactured, [f64; 4]); 2] {
    [
        (Manufactured::sin_cosh(), [1.0, 0.0, 1.0, 0.0]),
        (Manufactured::polynomial(), [2.0, 0.5, 1.0, -1.0]),
    ]
}

/// SOR with the automatic ω; where SOR fails (strongly skewed grids make the 9-point stencil
/// lose diagonal dominance) the direct sparse LU (feature `direct`), marked "LU" in the tables.
fn solve(grid: &StructuredGrid2, man: &Manufactured, k: [f64; 4]) -> Result<Solution, String> {
    let eq = man.equation(k[0], k[1], k[2], k[3]);
    let r = match solve_grid(grid, &eq, &man.sides(), &SolveOptions::default()) {
        Err(PdeError::SorDiverged { .. } | PdeError::NotConverged { .. }) => {
            let direct = SolveOptions::default().method(Method::Direct);
            solve_grid(grid, &eq, &man.sides(), &direct)
        }
        r => r,
    };
    r.map_err(|e| match e {
        PdeError::FoldedMesh {
            non_convex_cells, ..
        } => format!("refused: folded ({non_convex_cells} non-convex cells)"),
        e => e.to_string(),
    })
}

fn lu_mark(s: &Solution) -> &'static str {
    if s.method == Method::Direct {
        " (LU)"
    } else {
        ""
    }
}

/// The optimization: `unamalla_optim::smooth` with the functional named by `--functional`
/// (default `karea-length`, the thesis's default kArea-Length with σ = 0.5).
fn optimized(grid: &StructuredGrid2) -> (StructuredGrid2, f64) {
    let name = std::env::args()
        .skip_while(|a| a != "--functional")
        .nth(1)
        .unwrap_or_else(|| "karea-length".into());
    let opts = SmoothOptions::default().functional(name.parse().expect("functional name"));
    let mut g = grid.clone();
    let t = Instant::now();
    if let Err(e) = smooth(&mut g, &opts, &mut NullObserver) {
        eprintln!("smoothing failed: {e}");
    }
    (g, t.elapsed().as_secs_f64())
}

fn convergence(quick: bool) {
    let sizes: &[usize] = if quick {
        &[11, 21, 41, 81]
    } else {
        &[11, 21, 41, 81, 161]
    };
    println!("## convergence on the curved region (quarter annulus, wavy outer arc)\n");
    println!(
        "| mesh | U | nodes | max error | order | rms error | order | SOR sweeps | ω | solve s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for kind in ["TFI", "optimized"] {
        let grids: Vec<StructuredGrid2> = sizes
            .iter()
            .map(|&n| {
                let g = curved_grid(n, n).expect("curved grid");
                if kind == "TFI" {
                    g
                } else {
                    optimized(&g).0
                }
            })
            .collect();
        for (man, k) in problems() {
            let mut prev: Option<(f64, f64)> = None;
            for (g, &n) in grids.iter().zip(sizes) {
                match solve(g, &man, k) {
                    Ok(s) => {
                        let e = man.error(g.nodes(), &s.u);
                        let (om, or) = prev.map_or((String::new(), String::new()), |(pm, pr)| {
                            let r = (n - 1) as f64 / ((n - 1) / 2) as f64;
                            (
                                format!("{:.2}", observed_order(pm, e.max, r)),
                                format!("{:.2}", observed_order(pr, e.rms, r)),
                            )
                        });
                        println!(
                            "| {kind} | {} | {n}×{n} | {:.3e} | {om} | {:.3e} | {or} | {} | {:.4} | {:.2} |",
                            man.name,
                            e.max,
                            e.rms,
                            s.iterations,
                            s.omega.unwrap_or(f64::NAN),
                            s.seconds
                        );
                        prev = Some((e.max, e.rms));
                    }
                    Err(e) => println!("| {kind} | {} | {n}×{n} | {e} | | | | | | |", man.name),
                }
            }
        }
    }
    println!();
}

/// The grid's nodes mapped into the unit box (keeping the aspect ratio): the manufactured
/// solutions are defined on O(1) coordinates, the regions are in km.
fn normalized(grid: &StructuredGrid2) -> StructuredGrid2 {
    let (lo, hi) = grid.nodes().iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let s = (hi - lo).max_element();
    StructuredGrid2::from_fn(grid.m(), grid.n(), |i, j| (grid.node(i, j) - lo) / s)
        .expect("same size")
}

fn payoff() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/regions");
    println!(
        "## payoff: raw TFI vs optimized, same nodes (coordinates scaled into the unit box)\n"
    );
    println!("| region | nodes | U | TFI: non-convex cells | TFI: max error | optimized: non-convex cells | optimized: max error | smoothing s |");
    println!("|---|---|---|---|---|---|---|---|");
    for (name, m, n) in [
        ("colorado", 61, 41),
        ("texas", 61, 61),
        ("south-africa", 61, 61),
        ("maryland", 81, 41),
        ("kiwi-bird", 61, 41),
        ("hippo", 61, 41),
        ("horse", 61, 41),
    ] {
        let path = dir.join(format!("{name}.geojson"));
        let region = match read_region_geojson_cleaned(&path, PartSelector::Largest) {
            Ok((r, _)) => r,
            Err(e) => {
                println!("| {name} | {e} |");
                continue;
            }
        };
        // one TFI block needs a simply connected region: regions with holes are meshed on
        // their outline (outer ring)
        let (region, name) = if region.holes().is_empty() {
            (region, name.to_string())
        } else {
            match Region::new(region.outer().points().to_vec(), vec![]) {
                Ok(r) => (r, format!("{name} (outline)")),
                Err(e) => {
                    println!("| {name} | {e} |");
                    continue;
                }
            }
        };
        let tfi = match tfi_region(&region, Corners::Auto, m, n) {
            Ok(g) => normalized(&g),
            Err(e) => {
                println!("| {name} | TFI failed: {e} |");
                continue;
            }
        };
        let (opt, secs) = optimized(&tfi);
        let (nc_t, nc_o) = (
            alpha_stats(&tfi).non_convex_cells,
            alpha_stats(&opt).non_convex_cells,
        );
        for (man, k) in problems() {
            let cell = |g: &StructuredGrid2| match solve(g, &man, k) {
                Ok(s) => format!("{:.3e}{}", man.error(g.nodes(), &s.u).max, lu_mark(&s)),
                Err(e) => e,
            };
            println!(
                "| {name} | {m}×{n} | {} | {nc_t} | {} | {nc_o} | {} | {secs:.1} |",
                man.name,
                cell(&tfi),
                cell(&opt)
            );
        }
    }
    println!();
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let only_payoff = std::env::args().any(|a| a == "--payoff");
    let t = Instant::now();
    if !only_payoff {
        convergence(quick);
    }
    payoff();
    eprintln!("total {:.1} s", t.elapsed().as_secs_f64());
}
