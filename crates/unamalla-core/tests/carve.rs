//! Islands carved into the mesh instead of bridged by cuts ([`unamalla_core::carve`],
//! `Mesher::carve_islands`, and the carving retries of `Mesher::mesh_observed`).
//!
//! The region: a 100 × 100 sea with a 4 × 4 lattice of octagonal islands of circumradius 1.6
//! (width 2 · 1.6 · cos 22.5° ≈ 2.96), at 1,600 cells (h ≈ 2.49: the islands are about 1.2 cells
//! across, the scale at which a layout gives each island blocks a cell or two thick).

use unamalla_core::mesh::quality::non_convex_cells;
use unamalla_core::mesh::{DVec2, HasNodes, Polygon, Region};
use unamalla_core::pipeline::{Mesher, NEAR_HOLE_WIDTH};
use unamalla_core::verify::{verify_quads, VerifyOptions};

fn octagon(c: DVec2, r: f64) -> Vec<DVec2> {
    (0..8)
        .map(|k| {
            let t = std::f64::consts::PI * (0.125 + k as f64 / 4.0);
            c + r * DVec2::new(t.cos(), t.sin())
        })
        .collect()
}

fn sea() -> Region {
    let outer = vec![
        DVec2::ZERO,
        DVec2::new(100.0, 0.0),
        DVec2::new(100.0, 100.0),
        DVec2::new(0.0, 100.0),
    ];
    let holes = (0..16)
        .map(|k| {
            octagon(
                DVec2::new(20.0 + 20.0 * (k % 4) as f64, 20.0 + 20.0 * (k / 4) as f64),
                1.6,
            )
        })
        .collect();
    Region::new(outer, holes).unwrap()
}

/// Distance from `p` to the polygon's boundary.
fn to_contour(p: DVec2, ring: &Polygon) -> f64 {
    let q = ring.points();
    (0..q.len())
        .map(|k| {
            let (a, b) = (q[k], q[(k + 1) % q.len()]);
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            p.distance(a + t * (b - a))
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn islands_narrower_than_two_cells_are_carved_onto_their_contours() {
    let input = sea();
    let r = Mesher::new()
        .cells(1_600)
        .carve_islands(NEAR_HOLE_WIDTH)
        .mesh(&input)
        .expect("the sea is meshed");
    // every island carved, none dropped
    assert_eq!(r.report.holes_carved, (0..16).collect::<Vec<_>>());
    assert!(r.report.holes_dropped.is_empty());
    // the mesh passes the independent check against the region with the carved holes, has
    // no non-convex cell and no interior singularity
    let v = verify_quads(
        r.mesh.global(),
        Some(&r.simplified),
        &VerifyOptions::default(),
    );
    assert!(v.passed(), "{v}");
    assert!(non_convex_cells(r.mesh.global()).is_empty());
    assert_eq!(r.report.interior_singularities, 0);
    assert_eq!(r.simplified.holes().len(), 16);
    // each hole of the meshed region is a ring of mesh nodes on one island's contour
    let nodes = r.mesh.global().nodes();
    for hole in r.simplified.holes() {
        let c = hole.points().iter().copied().sum::<DVec2>() / hole.len() as f64;
        let island = input
            .holes()
            .iter()
            .min_by(|a, b| {
                let d = |p: &Polygon| p.points()[0].distance(c);
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        assert!(hole.len() >= 4);
        for &p in hole.points() {
            assert!(to_contour(p, island) < 1e-9, "{p} off its island");
            assert!(nodes.contains(&p), "{p} is not a mesh node");
        }
    }
    // the report's per-block quality covers the layout's blocks, each with the cells of the
    // pieces it was split into around the islands: every cell counted once
    let layout_blocks = r.report.layout.as_ref().map_or(0, |l| l.blocks.len());
    assert!(layout_blocks > 0 && layout_blocks < r.report.blocks);
    assert_eq!(r.report.block_quality.len(), layout_blocks);
    let counted: usize = r.report.block_quality.iter().map(|b| b.cells).sum();
    assert_eq!(counted, r.report.cells);
    // the request is honoured (±15 %)
    let cells = r.report.cells as f64;
    assert!((cells / 1_600.0 - 1.0).abs() <= 0.15, "{cells}");
    assert!(
        r.report
            .notes
            .iter()
            .any(|n| n.starts_with("carved 16 of the 16 island(s)")),
        "{:?}",
        r.report.notes
    );
}

#[test]
fn carving_is_deterministic() {
    let run = || {
        Mesher::new()
            .cells(1_600)
            .carve_islands(NEAR_HOLE_WIDTH)
            .mesh(&sea())
            .unwrap()
    };
    let (a, b) = (run(), run());
    assert_eq!(a.mesh.global().cells(), b.mesh.global().cells());
    let bits = |r: &unamalla_core::pipeline::MeshResult| {
        r.mesh
            .global()
            .nodes()
            .iter()
            .flat_map(|p| [p.x.to_bits(), p.y.to_bits()])
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&a), bits(&b));
}

/// The regression test of the category "a sea with many islands about a cell across": the
/// block layouts that bridge the islands with cuts stay below the quality target (blocks a cell
/// or two thick between the islands); by default the pipeline then carves the islands into the
/// mesh of the open sea, which meets it and is kept.
#[test]
fn a_sea_of_islands_below_the_quality_target_is_meshed_again_with_them_carved() {
    let bridged = Mesher::new()
        .cells(1_600)
        .carve_dropped_holes(false)
        .mesh(&sea())
        .unwrap();
    assert!(bridged.report.holes_carved.is_empty());
    assert_eq!(bridged.simplified.holes().len(), 16);
    let r = Mesher::new().cells(1_600).mesh(&sea()).unwrap();
    assert_eq!(r.report.holes_carved, (0..16).collect::<Vec<_>>());
    assert!(r.report.holes_dropped.is_empty());
    let (b, c) = (bridged.report.mu_ge_0_8_percent, r.report.mu_ge_0_8_percent);
    assert!(c >= 90.0 && c > b, "bridged {b} %, carved {c} %");
    assert!(
        r.report
            .notes
            .iter()
            .any(|n| n.contains("with the islands carved") && n.ends_with("(kept)")),
        "{:?}",
        r.report.notes
    );
    let v = verify_quads(
        r.mesh.global(),
        Some(&r.simplified),
        &VerifyOptions::default(),
    );
    assert!(v.passed(), "{v}");
}
