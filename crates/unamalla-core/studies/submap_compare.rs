//! Submapping (Ruiz-Gironés & Sarrate) vs the default cut decomposition (Méndez 2023) on the
//! synthetic shapes of
//! `unamalla_decompose::submap::shapes`, printed as the Markdown table of `docs/results.md`
//! (section "Submapping vs cuts").
//!
//! ```text
//! cargo run --release -p unamalla-core --example submap_compare -- [--cells N] [--fixtures DIR]
//! ```
//!
//! Both strategies get the same region (no contour simplification: the shapes are exact), the same
//! size (`--cells`, default 2000: `h = √(area/N)`) and the same smoothing (defaults, 15 s budget).
//! With `--fixtures DIR` the shapes are also written as GeoJSON (`DIR/<name>.geojson`).

use unamalla_core::decompose::submap::shapes;
use unamalla_core::io;
use unamalla_core::pipeline::{Mesher, Strategy};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let cells: usize = value("--cells").map_or(Ok(2000), |v| v.parse())?;
    let fixtures = value("--fixtures");
    if let Some(dir) = &fixtures {
        std::fs::create_dir_all(dir)?;
    }
    println!("| shape | strategy | blocks | cells | μ ≥ 0.8 / 0.4–0.8 / < 0.4 (%) | min scaled Jacobian | non-convex | interior singularities | time (s) |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for (name, region) in shapes::all()? {
        if let Some(dir) = &fixtures {
            let path = std::path::Path::new(dir).join(format!("{name}.geojson"));
            let text = io::region_to_geojson(&region);
            io::atomic_write(&path, |w| w.write_all(text.as_bytes()))?;
        }
        for strategy in [Strategy::Cuts, Strategy::Submap] {
            let r = Mesher::new()
                .simplify(None)
                .cells(cells)
                .strategy(strategy)
                .mesh(&region);
            match r {
                Ok(r) => {
                    let q = &r.report;
                    println!(
                        "| {name} | {} | {} | {} | {:.1} / {:.1} / {:.1} | {:.3} | {} | {} | {:.2} |",
                        match strategy {
                            Strategy::Cuts => "cuts",
                            _ => "submap",
                        },
                        q.blocks,
                        q.cells,
                        q.mu_bands[0],
                        q.mu_bands[1],
                        q.mu_bands[2],
                        q.min_scaled_jacobian,
                        q.non_convex_cells,
                        q.interior_singularities,
                        q.seconds
                    );
                }
                Err(e) => println!("| {name} | {strategy:?} | failed: {e} | | | | | | |"),
            }
        }
    }
    Ok(())
}
