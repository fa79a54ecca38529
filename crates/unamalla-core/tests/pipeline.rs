//! End-to-end properties of the mesher on real regions (small meshes so the suite stays fast;
//! the full-size runs are in `docs/results.md`).

use std::collections::HashSet;
use std::path::Path;

use unamalla_core::io::{self, PartSelector};
use unamalla_core::mesh::geometry::point_segment_distance;
use unamalla_core::mesh::{HasNodes, HasQuadCells, Region};
use unamalla_core::pipeline::{MeshResult, Mesher};

fn load(name: &str) -> Region {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/regions")
        .join(name);
    io::read_region_geojson(p, PartSelector::Largest).unwrap()
}

fn distance_to_rings(r: &Region, p: unamalla_core::mesh::DVec2) -> f64 {
    let mut d = f64::INFINITY;
    for ring in r.rings() {
        let pts = ring.points();
        for k in 0..pts.len() {
            d = d.min(point_segment_distance(p, pts[k], pts[(k + 1) % pts.len()]));
        }
    }
    d
}

fn check(result: &MeshResult, holes: usize) {
    let rep = &result.report;
    let mesh = result.mesh.global();
    assert_eq!(rep.non_convex_cells, 0, "non-convex cells");
    assert_eq!(rep.interior_singularities, 0, "interior singularities");
    assert!(rep.holes_dropped.is_empty());
    // no duplicate nodes
    let mut seen = HashSet::new();
    for p in mesh.nodes() {
        assert!(
            seen.insert((p.x.to_bits(), p.y.to_bits())),
            "duplicate node {p}"
        );
    }
    // conformity: the only boundary loops are the region's rings (a non-conformal cut would
    // leave its edges unmatched and add boundary edges inside the region)
    let loops = io::msh::boundary_loops(mesh);
    assert_eq!(loops.len(), 1 + holes, "boundary loops");
    // every boundary node lies on the simplified boundary, except the two neighbours of each
    // flat block corner, which the pipeline moves inward on purpose (`report.bent_corners`, by
    // tan 5° of the shorter boundary edge at the corner — one of this node's two boundary edges —
    // plus the corner's height on the reflex side, at most sin 0.5° of it: below tan 6° of
    // the node's longer boundary edge)
    let (lo, hi) = result.simplified.bounding_box();
    let tol = 1e-9 * (hi - lo).length();
    let mut off = 0;
    for l in &loops {
        let n = l.edges.len();
        for (k, e) in l.edges.iter().enumerate() {
            let p = mesh.nodes()[e[0]];
            let next = mesh.nodes()[e[1]];
            let prev = mesh.nodes()[l.edges[(k + n - 1) % n][0]];
            let d = distance_to_rings(&result.simplified, p);
            if d > tol {
                off += 1;
                let longer = p.distance(next).max(p.distance(prev));
                assert!(
                    d <= 6f64.to_radians().tan() * longer,
                    "boundary node {p} is {d} off the boundary"
                );
            }
        }
    }
    assert!(
        off <= 2 * rep.bent_corners,
        "{off} boundary nodes off the boundary, {} bent corners",
        rep.bent_corners
    );
    // the two blocks of every cut share its nodes through their local→global maps (cut nodes
    // move during smoothing, so this is checked topologically: the blocks share at least the
    // cut's two endpoints; the real conformity check is the boundary-loop count above, where an
    // unmatched cut would show up as an extra loop)
    let mut owners: Vec<Vec<usize>> = vec![Vec::new(); mesh.num_nodes()];
    for b in 0..result.mesh.blocks().len() {
        for &g in result.mesh.block_node_map(b) {
            if owners[g].last() != Some(&b) {
                owners[g].push(b);
            }
        }
    }
    for cut in &result.decomposition.cuts {
        let [b0, b1] = cut.blocks;
        let shared = owners
            .iter()
            .filter(|o| o.contains(&b0) && o.contains(&b1))
            .count();
        assert!(
            shared >= 2,
            "cut {} between blocks {b0} and {b1} shares {shared} nodes",
            cut.id
        );
    }
    assert_eq!(rep.cells, mesh.num_quads());
    assert_eq!(rep.blocks, result.decomposition.blocks.len());
}

#[test]
fn colorado_is_one_high_quality_block() {
    let r = Mesher::new()
        .cells(2_000)
        .mesh(&load("colorado.geojson"))
        .unwrap();
    check(&r, 0);
    assert_eq!(r.report.blocks, 1);
    assert!(r.report.mu_ge_0_8_percent >= 85.0);
    assert!(r.report.area_change_percent <= 2.0);
}

#[test]
fn kiwi_silhouette_with_a_hole() {
    let r = Mesher::new()
        .cells(3_000)
        .mesh(&load("kiwi-bird.geojson"))
        .unwrap();
    check(&r, 1);
    assert!(r.report.blocks > 1);
}

#[test]
fn horse_silhouette_with_a_hole() {
    let r = Mesher::new()
        .cells(3_000)
        .mesh(&load("horse.geojson"))
        .unwrap();
    check(&r, 1);
    assert!(
        r.report.mu_ge_0_8_percent >= 85.0,
        "{}",
        r.report.mu_ge_0_8_percent
    );
}

#[test]
fn gulf_of_mexico_with_its_sliver_island_is_convex_and_smoothed() {
    // The gulf's sliver island (a three-vertex hole ≈ 2° at its tip) and its
    // global smoothing run, whose optimum has cells at the ε-convexity bound. Before the
    // spike criterion (decomposition) and the held-back safeguard step (optimizer) this size
    // ended with the smoothing stuck in a non-convex state (μ ≥ 0.8 on 69.9 % of the cells,
    // 2026-11-22); it is deterministic here (the global run stops by FTOL well inside its
    // time budget).
    // (with every island in the block layout: by default the islands narrower than a cell
    // are carved instead, checked below)
    let region = load("gulf-of-mexico.geojson");
    let r = Mesher::new()
        .cells(6_000)
        .carve_dropped_holes(false)
        .mesh(&region)
        .unwrap();
    check(&r, region.holes().len());
    assert!(
        r.report.smoothing.starts_with("Convex grid"),
        "{}",
        r.report.smoothing
    );
    assert!(
        r.report.mu_ge_0_8_percent >= 80.0,
        "{}",
        r.report.mu_ge_0_8_percent
    );
    assert!(r.report.area_change_percent <= 2.0);
    // by default: every island narrower than a cell leaves the layout and is carved, or
    // dropped when it cannot be; the others stay; the mesh is all-convex without interior
    // singularities and its boundary loops are the meshed region's rings
    let d = Mesher::new().cells(6_000).mesh(&region).unwrap();
    let h = (region.area() / 6_000.0).sqrt();
    let width = |k: usize| unamalla_core::contour::hole_width(&region.holes()[k]);
    let mut out: Vec<usize> = d
        .report
        .holes_carved
        .iter()
        .chain(&d.report.holes_dropped)
        .copied()
        .collect();
    out.sort_unstable();
    let narrow: Vec<usize> = (0..region.holes().len())
        .filter(|&k| width(k) < h)
        .collect();
    assert_eq!(out, narrow);
    assert_eq!(
        d.simplified.holes().len(),
        region.holes().len() - d.report.holes_dropped.len()
    );
    assert_eq!(d.report.non_convex_cells, 0);
    assert_eq!(d.report.interior_singularities, 0);
    let loops = io::msh::boundary_loops(d.mesh.global());
    assert_eq!(loops.len(), 1 + d.simplified.holes().len());
}

/// The quality targets as a test: every bundled region at the default size (about 20,000
/// cells) is all-convex (`check`) with μ ≥ 0.8 on ≥ 85 % of the cells, an area change ≤ 2 %
/// and under 30 s. Slow (≈ 3 min in release on 2 cores, and the 30 s limit assumes
/// an otherwise idle machine), so ignored by default; run it with
/// `cargo test --release -p unamalla-core --test pipeline -- --ignored --test-threads 1`.
#[test]
#[ignore]
fn every_bundled_region_meets_the_quality_targets() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/regions");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".geojson"))
        .collect();
    names.sort();
    assert_eq!(names.len(), 12);
    for name in names {
        let region = load(&name);
        let r = Mesher::new().mesh(&region).unwrap();
        let rep = &r.report;
        eprintln!(
            "{name}: {} cells, μ ≥ 0.8 on {:.1} %, {:.1} s",
            rep.cells, rep.mu_ge_0_8_percent, rep.seconds
        );
        check(&r, region.holes().len());
        assert!(
            rep.mu_ge_0_8_percent >= 85.0,
            "{name}: μ {}",
            rep.mu_ge_0_8_percent
        );
        assert!(
            rep.area_change_percent <= 2.0,
            "{name}: area {}",
            rep.area_change_percent
        );
        assert!(rep.seconds < 30.0, "{name}: {} s", rep.seconds);
    }
}

/// A square with a 33.4° spike (tip at (15, 5), base from (10, 3.5) to (10, 6.5)): a critical
/// angle (below θ₋ = 40°), so the decomposition gives the spike a triangle block. By default the
/// tip is a block corner, so exactly one cell has the tip node, with the whole angle; the
/// thesis's rule (`blunt_critical_tips`) puts the tip inside a short side, shared by two cells
/// of about half the angle each.
#[test]
fn a_sharp_tip_is_one_cell_by_default_and_two_half_cells_when_blunted() {
    use unamalla_core::decompose::DecomposeOptions;
    use unamalla_core::mesh::DVec2;
    let v = DVec2::new;
    let region = Region::new(
        vec![
            v(0.0, 0.0),
            v(10.0, 0.0),
            v(10.0, 3.5),
            v(15.0, 5.0),
            v(10.0, 6.5),
            v(10.0, 10.0),
            v(0.0, 10.0),
        ],
        vec![],
    )
    .unwrap();
    let tip = v(15.0, 5.0);
    let tip_angle = 2.0 * (1.5f64 / 5.0).atan();
    // the cells having the tip as a node, and their angles there
    let at_tip = |r: &MeshResult| -> Vec<f64> {
        let g = r.mesh.global();
        let node = (0..g.num_nodes())
            .find(|&k| g.nodes()[k].distance(tip) < 1e-9)
            .expect("the tip is a mesh node");
        (0..g.num_quads())
            .filter_map(|c| {
                let q = g.quad(c);
                let i = q.iter().position(|&n| n == node)?;
                let p = g.nodes()[node];
                let a = g.nodes()[q[(i + 3) % 4]] - p;
                let b = g.nodes()[q[(i + 1) % 4]] - p;
                Some(a.angle_to(b).abs())
            })
            .collect()
    };
    let corner = Mesher::new().cells(2000).mesh(&region).unwrap();
    check(&corner, 0);
    let cells = at_tip(&corner);
    assert_eq!(cells.len(), 1, "{cells:?}");
    assert!(
        (cells[0] - tip_angle).abs() < 1e-9,
        "{cells:?} vs {tip_angle}"
    );
    let blunt = Mesher::new()
        .cells(2000)
        .decompose_options(DecomposeOptions::default().blunt_critical_tips(true))
        .mesh(&region)
        .unwrap();
    let cells = at_tip(&blunt);
    assert_eq!(cells.len(), 2, "{cells:?}");
    assert!((cells[0] + cells[1] - tip_angle).abs() < 1e-9, "{cells:?}");
    assert!(cells.iter().all(|&a| a < 0.75 * tip_angle), "{cells:?}");
}
