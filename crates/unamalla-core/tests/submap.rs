//! End to end through the pipeline with the submapping strategy ([Ruiz-Gironés & Sarrate]) on the
//! exact synthetic shapes of `unamalla_decompose::submap::shapes` (stand-ins for the paper's
//! figures, which give no coordinates): every mesh is conformal,
//! all-convex after smoothing and free of interior singularities, and its blocks are the
//! submapping's pieces.

use unamalla_core::decompose::submap::{shapes, NodeKind};
use unamalla_core::mesh::{HasNodes, HasQuadCells, Region};
use unamalla_core::pipeline::{MeshResult, Mesher, Strategy};

fn run(region: &Region, h: f64, strategy: Strategy) -> MeshResult {
    Mesher::new()
        .simplify(None)
        .cell_size(h)
        .strategy(strategy)
        .mesh(region)
        .unwrap()
}

fn check_submap(name: &str, region: &Region, h: f64) -> MeshResult {
    let r = run(region, h, Strategy::Submap);
    let s = r.submap.as_ref().expect("submapping result");
    let rep = &r.report;
    assert_eq!(rep.strategy, Strategy::Submap, "{name}");
    assert!(r.counts.is_none());
    assert_eq!(rep.non_convex_cells, 0, "{name}: non-convex cells");
    assert_eq!(
        rep.interior_singularities, 0,
        "{name}: interior singularities"
    );
    assert_eq!(rep.blocks, s.pieces.len(), "{name}");
    assert_eq!(rep.cells, s.num_cells(), "{name}");
    assert_eq!(r.decomposition.blocks.len(), s.pieces.len());
    // conformity: V − E + F = 1 − H for the merged mesh
    let mesh = &r.mesh;
    let mut edges = std::collections::HashSet::new();
    for q in 0..mesh.num_quads() {
        let c = mesh.quad(q);
        for i in 0..4 {
            let (a, b) = (c[i], c[(i + 1) % 4]);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    let euler = mesh.num_nodes() as i64 - edges.len() as i64 + mesh.num_quads() as i64;
    assert_eq!(euler, 1 - region.holes().len() as i64, "{name}: V − E + F");
    // every boundary node of the mesh lies on the region boundary (the shape pass slides
    // them along it, it never takes them off)
    let global = mesh.global();
    for (v, &fixed) in global.fixed().iter().enumerate() {
        if fixed {
            let p = global.nodes()[v];
            let on = region.rings().any(|ring| {
                let pts = ring.points();
                (0..pts.len()).any(|i| {
                    let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
                    let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
                    p.distance(a + t * (b - a)) < 1e-9
                })
            });
            assert!(on, "{name}: boundary node {p} is off the region boundary");
        }
    }
    // without the shape pass, cut and virtual-edge nodes were free (interior nodes of the
    // merged mesh) and boundary nodes stayed where the submapping put them
    let fixed_run = Mesher::new()
        .simplify(None)
        .cell_size(h)
        .strategy(Strategy::Submap)
        .shape(None)
        .mesh(region)
        .unwrap();
    let nodes = fixed_run.mesh.global().nodes();
    for (id, kind) in s.node_kinds.iter().enumerate() {
        if *kind == NodeKind::Boundary {
            let p = s.nodes[id];
            assert!(
                nodes.iter().any(|q| q.distance(p) < 1e-9),
                "{name}: boundary node {p} moved"
            );
        }
    }
    r
}

#[test]
fn l_shape() {
    let r = check_submap("l-shape", &shapes::l_shape().unwrap(), 0.1);
    // three unit squares of 10 × 10 cells
    assert_eq!(r.report.cells, 300);
    assert_eq!(r.report.blocks, 2);
    // a rectilinear shape meshed by rectangles: every cell is a square
    assert!(r.report.min_scaled_jacobian > 0.999);
}

#[test]
fn u_shape() {
    let r = check_submap("u-shape", &shapes::u_shape().unwrap(), 0.1);
    assert_eq!(r.report.cells, 500);
    assert!(r.report.min_scaled_jacobian > 0.999);
}

#[test]
fn u_slot_reversal() {
    check_submap("u-slot", &shapes::u_slot().unwrap(), 0.1);
}

#[test]
fn square_with_square_hole() {
    let r = check_submap("square-hole", &shapes::square_hole().unwrap(), 0.1);
    assert_eq!(r.report.cells, 1500); // (16 − 1) · 100
    assert!(r.report.min_scaled_jacobian > 0.999);
}

#[test]
fn plate_with_three_holes() {
    let r = check_submap("plate-3-holes", &shapes::plate_three_holes().unwrap(), 0.25);
    assert_eq!(r.report.cells, 49 * 16);
    assert!(r.report.min_scaled_jacobian > 0.999);
}

#[test]
fn half_nut() {
    let r = check_submap("half-nut", &shapes::half_nut().unwrap(), 0.1);
    assert_eq!(r.report.blocks, 1); // Ex 1: a single TFI
}

#[test]
fn mechanical_part() {
    check_submap("mechanical-part", &shapes::mechanical_part().unwrap(), 0.1);
}

#[test]
fn auto_chooses_by_angles() {
    // all right angles → submap
    let r = run(&shapes::plate_three_holes().unwrap(), 0.5, Strategy::Auto);
    assert_eq!(r.report.strategy, Strategy::Submap);
    // 60° hexagon bends → cuts
    let r = run(&shapes::half_nut().unwrap(), 0.2, Strategy::Auto);
    assert_eq!(r.report.strategy, Strategy::Cuts);
    assert!(r.submap.is_none() && r.counts.is_some());
}

#[test]
fn submap_and_decomposition_file_exclude_each_other() {
    let region = shapes::l_shape().unwrap();
    let d = unamalla_core::decompose::decompose(&region, &Default::default()).unwrap();
    let e = Mesher::new()
        .simplify(None)
        .decomposition(d)
        .strategy(Strategy::Submap)
        .mesh(&region);
    assert!(e.is_err());
}
