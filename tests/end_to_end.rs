//! End-to-end over real bundled regions, through the facade a user adds (`unamalla-core`), with
//! the product's promises checked independently of the pipeline's own report: every cell
//! convex (all four corner cross products positive, [Méndez 2023, §6.4.2]), no interior
//! singularity (every interior node in exactly four cells) and the requested cell count within
//! ±15 % (the targets of README "Status").

use std::collections::HashMap;

use unamalla_core::io::input::{load_region, LoadOptions};
use unamalla_core::mesh::{DVec2, HasQuadCells};
use unamalla_core::pipeline::Mesher;

fn fixture(name: &str) -> String {
    format!("{}/fixtures/regions/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// (non-convex cells, interior nodes whose valence is not 4) of a quad mesh, from the cells
/// alone: an edge in one cell is a boundary edge, its nodes are boundary nodes.
fn independent_check<M: HasQuadCells>(m: &M) -> (usize, usize) {
    let x = m.nodes();
    let mut nonconvex = 0;
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    let mut valence = vec![0usize; x.len()];
    for c in 0..m.num_quads() {
        let q = m.quad(c);
        let convex = (0..4).all(|k| {
            let p: DVec2 = x[q[k]];
            let a = x[q[(k + 1) % 4]] - p;
            let b = x[q[(k + 3) % 4]] - p;
            a.perp_dot(b) > 0.0
        });
        nonconvex += !convex as usize;
        for k in 0..4 {
            let (u, v) = (q[k], q[(k + 1) % 4]);
            *edges.entry((u.min(v), u.max(v))).or_default() += 1;
            valence[q[k]] += 1;
        }
    }
    let mut boundary = vec![false; x.len()];
    for (&(u, v), &n) in &edges {
        if n == 1 {
            boundary[u] = true;
            boundary[v] = true;
        }
    }
    let singular = (0..x.len())
        .filter(|&v| !boundary[v] && valence[v] != 4)
        .count();
    (nonconvex, singular)
}

#[test]
fn bundled_regions_mesh_all_convex_without_interior_singularities() {
    // a silhouette with a hole, a state outline, an island's coastline
    for (name, cells) in [
        ("kiwi-bird.geojson", 3000usize),
        ("colorado.geojson", 2000),
        ("crete.geojson", 3000),
    ] {
        let loaded = load_region(fixture(name), &LoadOptions::default()).unwrap();
        let res = Mesher::new().cells(cells).mesh(&loaded.region).unwrap();
        let mesh = res.mesh.global();
        let (nonconvex, singular) = independent_check(mesh);
        assert_eq!(nonconvex, 0, "{name}: non-convex cells");
        assert_eq!(singular, 0, "{name}: interior singularities");
        let n = mesh.num_quads() as f64;
        assert!(
            (n - cells as f64).abs() <= 0.15 * cells as f64,
            "{name}: {n} cells for {cells} requested"
        );
        // the report agrees with the independent count
        assert_eq!(res.report.non_convex_cells, 0);
        assert_eq!(res.report.interior_singularities, 0);
        assert_eq!(res.report.cells, mesh.num_quads());
    }
}
