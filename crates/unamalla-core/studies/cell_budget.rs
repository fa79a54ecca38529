//! Cell counts of pipeline step 3 without meshing: for each region and requested count N, the
//! cells of the lower-bound counts (problem (5.10), `h = √(area/N)`, the solver before the target
//! fit) and of the target fit with the budget loop ([`compatible_counts`]). The mesh has exactly
//! the predicted cells (TFI and merging keep the block grids).
//!
//! `cargo run --release -p unamalla-core --example cell_budget -- REGION.geojson... [--cells 5000,20000]`
use std::time::Instant;

use unamalla_core::compat_ilp as ilp;
use unamalla_core::curves::{compatible_counts, decomposition_area};
use unamalla_core::decompose::decompose;
use unamalla_core::decompose::BlockCurves;
use unamalla_core::pipeline::{MeshSize, Mesher};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut sizes = vec![5_000usize, 20_000, 100_000];
    let mut files = Vec::new();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--cells" {
            if let Some(v) = it.next() {
                sizes = v.split(',').filter_map(|s| s.parse().ok()).collect();
            }
        } else {
            files.push(a.clone());
        }
    }
    println!("| region | N | blocks | lower-bound cells | ×N | fit cells | ×N | fit iterations | fit ms |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for f in &files {
        let name = std::path::Path::new(f)
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        let region = match unamalla_core::io::read_region_geojson(f, Default::default()) {
            Ok(r) => r,
            Err(e) => {
                println!("| {name} | – | read error: {e} |");
                continue;
            }
        };
        for &n in &sizes {
            let mesher = Mesher::new().cells(n);
            let row = (|| -> Result<String, String> {
                let prep = mesher.prepare_region(&region).map_err(|e| e.to_string())?;
                let d =
                    decompose(&prep.mesh_region, &Default::default()).map_err(|e| e.to_string())?;
                let curves = BlockCurves::new(&d);
                let h = (decomposition_area(&d) / n as f64).sqrt();
                let old = ilp::solve(&curves.problem(), &ilp::SolveOptions::cell_size(h))
                    .map(|s| curves.predicted_cells(&s.counts).to_string())
                    .unwrap_or_else(|e| format!("error: {e}"));
                let t = Instant::now();
                let new = compatible_counts(&d, MeshSize::Cells(n)).map_err(|e| e.to_string())?;
                let ms = t.elapsed().as_secs_f64() * 1e3;
                let ratio = |s: &str| {
                    s.parse::<f64>()
                        .map(|c| format!("{:.2}", c / n as f64))
                        .unwrap_or_else(|_| "–".into())
                };
                let mut row = format!(
                    "| {name} | {n} | {} | {old} | {} | {} | {} | {} | {ms:.0} |",
                    d.blocks.len(),
                    ratio(&old),
                    new.predicted_cells,
                    ratio(&new.predicted_cells.to_string()),
                    new.iterations,
                );
                for note in &new.notes {
                    row.push_str(&format!("\n<!-- {name} {n}: {note} -->"));
                }
                Ok(row)
            })();
            match row {
                Ok(r) => println!("{r}"),
                Err(e) => println!("| {name} | {n} | error: {e} |"),
            }
        }
    }
}
