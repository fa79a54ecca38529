//! Quick driver: `cargo run --release -p unamalla-core --example mesh_region -- <region.geojson> [cells] [time limit s] [feature factor]`.
//! With `UNAMALLA_DIAG=1` it also lists every non-convex cell (block, grid position, the four
//! angles), to tell folds from flat block corners.
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = &args[1];
    let cells: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(20_000);
    let region = unamalla_core::io::read_region_geojson(path, Default::default()).unwrap();
    let limit: Option<f64> = args.get(3).and_then(|s| s.parse().ok());
    let r = unamalla_core::pipeline::Mesher::new()
        .cells(cells)
        .time_limit(limit)
        .feature_factor(
            args.get(4)
                .and_then(|s| s.parse().ok())
                .unwrap_or(unamalla_core::pipeline::DEFAULT_FEATURE_FACTOR),
        )
        .on_progress(|s, m| eprintln!("[{s:?}] {m}"))
        .mesh(&region);
    match &r {
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
    if let (Ok(r), true) = (&r, std::env::var_os("UNAMALLA_DIAG").is_some()) {
        diagnose(r);
    }
}

/// With `UNAMALLA_DIAG=1`: lists every non-convex cell by block, grid position and the angles
/// of its four corners (degrees), to tell folds from degenerate (180°) block corners.
fn diagnose(r: &unamalla_core::pipeline::MeshResult) {
    use unamalla_core::mesh::HasQuadCells;
    for (b, g) in r.mesh.blocks().iter().enumerate() {
        for c in unamalla_core::mesh::quality::non_convex_cells(g) {
            let (i, j) = (c % (g.m() - 1), c / (g.m() - 1));
            let q = g.quad_points(c);
            let ang: Vec<String> = (0..4)
                .map(|k| {
                    let a = q[(k + 1) % 4] - q[k];
                    let bb = q[(k + 3) % 4] - q[k];
                    format!("{:.1}", a.perp_dot(bb).atan2(a.dot(bb)).to_degrees())
                })
                .collect();
            println!(
                "block {b} ({}x{}) cell ({i},{j}) angles {ang:?} at {:?}",
                g.m(),
                g.n(),
                q[0]
            );
        }
    }
}
