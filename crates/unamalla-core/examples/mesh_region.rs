//! Quick driver: `cargo run --release -p unamalla-core --example mesh_region -- <region.geojson> [cells] [smooth budget s] [feature factor]`.
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = &args[1];
    let cells: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(20_000);
    let region = unamalla_core::io::read_region_geojson(path, Default::default()).unwrap();
    let budget: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(20.0);
    let r = unamalla_core::pipeline::Mesher::new()
        .cells(cells)
        .smooth_budget(budget)
        .feature_factor(
            args.get(4)
                .and_then(|s| s.parse().ok())
                .unwrap_or(unamalla_core::pipeline::DEFAULT_FEATURE_FACTOR),
        )
        .on_progress(|s, m| eprintln!("[{s:?}] {m}"))
        .mesh(&region);
    match r {
        Ok(r) => {
            let mut rep = r.report.clone();
            rep.quality = unamalla_core::mesh::QualityReport::for_quads(&r.mesh);
            println!(
                "cells {} blocks {} nonconvex {} sing {} mu>=0.8 {:.1}% minSJ {:.3} area {:.3}% haus {:.3} smoothing {} t {:.2}s {:?}",
                rep.cells, rep.blocks, rep.non_convex_cells, rep.interior_singularities, rep.mu_ge_0_8_percent,
                rep.min_scaled_jacobian, rep.area_change_percent, rep.hausdorff, rep.smoothing, rep.seconds, rep.stage_seconds
            );
        }
        Err(e) => println!("error: {e}"),
    }
}
