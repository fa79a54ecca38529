//! The mesh does not depend on the units of the region: a region scaled by a power of two is
//! meshed into the same mesh scaled by that power, node for node and bit for bit.
//!
//! Multiplying by `2^k` is exact in floating point (no rounding, far from overflow and
//! underflow), and so is every sum, product, quotient and square root of scaled values, scaled
//! accordingly; every *relative* tolerance of the pipeline (to the cell size, the region's
//! diameter, the mean cell measure ᾱ, ‖x‖) therefore makes the same decision at both scales.
//! An *absolute* constant somewhere (a `max(1.0)` of coordinates, a fixed `1e-9` distance) makes
//! the two runs differ — which is what this test catches. Known gap (docs/results.md, "Units,
//! rotation and stretch"): at 20,000 cells texas and newfoundland still differ in the last bits
//! after the local untangling patches of their coarse level, a cause not found yet; the regions
//! here do not reach that path.

use std::path::Path;

use unamalla_core::io::{self, PartSelector};
use unamalla_core::mesh::{DVec2, HasNodes, HasQuadCells, Region};
use unamalla_core::pipeline::Mesher;

fn region(name: &str) -> Region {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/regions")
        .join(name);
    io::read_region_geojson(p, PartSelector::Largest).unwrap()
}

fn scaled(r: &Region, s: f64) -> Region {
    let ring = |p: &[DVec2]| p.iter().map(|&q| q * s).collect::<Vec<_>>();
    Region::new(
        ring(r.outer().points()),
        r.holes().iter().map(|h| ring(h.points())).collect(),
    )
    .unwrap()
}

#[test]
fn a_region_scaled_by_a_power_of_two_gives_the_same_mesh_scaled() {
    // hippo: a silhouette without holes; kiwi-bird: one hole (the eye)
    for (name, cells) in [("hippo.geojson", 3000), ("kiwi-bird.geojson", 3000)] {
        let r = region(name);
        let base = Mesher::new().cells(cells).mesh(&r).unwrap();
        let g0 = base.mesh.global();
        for k in [-14i32, 20] {
            let s = 2f64.powi(k);
            let m = Mesher::new().cells(cells).mesh(&scaled(&r, s)).unwrap();
            let g = m.mesh.global();
            assert_eq!(g.num_quads(), g0.num_quads(), "{name} × 2^{k}: cell count");
            assert_eq!(
                g.nodes().len(),
                g0.nodes().len(),
                "{name} × 2^{k}: node count"
            );
            for c in 0..g0.num_quads() {
                assert_eq!(g.quad(c), g0.quad(c), "{name} × 2^{k}: cell {c}");
            }
            for (i, (p, q)) in g.nodes().iter().zip(g0.nodes()).enumerate() {
                assert!(
                    *p == *q * s,
                    "{name} × 2^{k}: node {i} at {p}, the unscaled mesh's × 2^{k} is {}",
                    *q * s
                );
            }
        }
    }
}
