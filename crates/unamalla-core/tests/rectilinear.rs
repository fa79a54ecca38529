//! Rectilinear regions ([Méndez 2023, Appendix B]) of pipeline meshes: on simply connected
//! regions the development of the blocks' index spaces is a rectilinear region `R` whose unit
//! squares are exactly the mesh's cells (around a hole it need not close: the unit test
//! `a_frame_of_trapezoids_does_not_close` in `unamalla_mesh::rectilinear`).

use std::path::Path;

use unamalla_core::io::{read_region_geojson, PartSelector};
use unamalla_core::mesh::rectilinear::develop;
use unamalla_core::mesh::{HasQuadCells, Region};
use unamalla_core::pipeline::Mesher;

fn region(name: &str) -> Region {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/regions")
        .join(name);
    read_region_geojson(&p, PartSelector::Largest).unwrap()
}

/// Colorado (one block) and California (several blocks, no hole) at 2,000 cells: every cell's
/// four nodes go to the four corners of one unit lattice square (so `X` is the cells' bilinear
/// maps on the squares of `R`), the rectangles are the blocks' (m − 1) × (n − 1) index ranges,
/// `R`'s area is the cell count, and its boundary is one rectilinear ring through the images
/// of the mesh's boundary nodes only.
#[test]
fn simply_connected_meshes_are_images_of_rectilinear_regions() {
    for name in ["colorado.geojson", "california.geojson"] {
        let m = Mesher::new().cells(2000).mesh(&region(name)).unwrap();
        let mesh = &m.mesh;
        let r = develop(mesh).unwrap_or_else(|e| panic!("{name}: {e}"));
        for c in 0..mesh.num_quads() {
            let q = mesh.quad(c).map(|v| r.node_uv[v]);
            let (lo_u, lo_v) = (
                q.iter().map(|p| p[0]).min().unwrap(),
                q.iter().map(|p| p[1]).min().unwrap(),
            );
            let mut corners: Vec<[i64; 2]> = q.to_vec();
            corners.sort_unstable();
            assert_eq!(
                corners,
                vec![
                    [lo_u, lo_v],
                    [lo_u, lo_v + 1],
                    [lo_u + 1, lo_v],
                    [lo_u + 1, lo_v + 1]
                ],
                "{name}: cell {c}"
            );
        }
        for (b, p) in r.blocks.iter().enumerate() {
            let g = &mesh.blocks()[b];
            let (w, h) = (p.rect[2] - p.rect[0], p.rect[3] - p.rect[1]);
            let (m1, n1) = (g.m() as i64 - 1, g.n() as i64 - 1);
            assert!(
                (w, h) == (m1, n1) || (w, h) == (n1, m1),
                "{name}: block {b}"
            );
        }
        assert_eq!(r.area(), mesh.num_quads() as i64, "{name}");
        assert_eq!(r.rings.len(), 1, "{name}");
        let ring = &r.rings[0];
        for k in 0..ring.len() {
            let (p, q) = (ring[k], ring[(k + 1) % ring.len()]);
            assert!(
                p[0] == q[0] || p[1] == q[1],
                "{name}: not rectilinear at {p:?}"
            );
        }
        let fixed = mesh.global().fixed();
        for &corner in ring {
            let v = r.node_uv.iter().position(|&p| p == corner).unwrap();
            assert!(
                fixed[v],
                "{name}: ring corner {corner:?} is not a boundary node"
            );
        }
    }
}
