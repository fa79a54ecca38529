//! Region construction: every bad-input class gets its own error; orientation is normalised;
//! geometric queries on known shapes.

use std::f64::consts::PI;

use unamalla_mesh::{DVec2, GeometryError, Location, Region, RingId};

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

fn square(c: DVec2, h: f64) -> Vec<DVec2> {
    vec![c + v(-h, -h), c + v(h, -h), c + v(h, h), c + v(-h, h)]
}

#[test]
fn valid_square_with_hole_is_normalised() {
    // outer given clockwise and closed, hole given counter-clockwise
    let mut outer: Vec<_> = square(v(0., 0.), 2.0).into_iter().rev().collect();
    outer.push(outer[0]);
    let hole = square(v(0., 0.), 0.5);
    let r = Region::new(outer, vec![hole]).unwrap();
    assert!(r.outer().signed_area() > 0.0);
    assert!(r.holes()[0].signed_area() < 0.0);
    assert_eq!(r.outer().len(), 4);
    assert!((r.area() - (16.0 - 1.0)).abs() < 1e-12);
    assert!((r.perimeter() - (16.0 + 4.0)).abs() < 1e-12);
    // the input vertex 0 stays vertex 0; input vertex 1 became the last one
    assert_eq!(r.outer().points()[0], v(-2., 2.));
    assert_eq!(r.outer_index_from_input(1), Some(3));
    assert_eq!(r.locate(v(0., 0.)), Location::Outside);
    assert_eq!(r.locate(v(1., 1.)), Location::Inside);
    assert_eq!(r.locate(v(0.5, 0.)), Location::OnBoundary);
}

#[test]
fn too_few_points() {
    let e = Region::new(vec![v(0., 0.), v(1., 0.), v(0., 0.)], vec![]).unwrap_err();
    assert_eq!(
        e,
        GeometryError::TooFewPoints {
            ring: RingId::Outer,
            count: 2
        }
    );
}

#[test]
fn non_finite() {
    let e = Region::new(vec![v(0., 0.), v(1., f64::NAN), v(0., 1.)], vec![]).unwrap_err();
    assert!(matches!(
        e,
        GeometryError::NonFinite {
            ring: RingId::Outer,
            vertex: 1,
            ..
        }
    ));
    let e = Region::new(
        square(v(0., 0.), 2.),
        vec![vec![v(0., 0.), v(f64::INFINITY, 0.), v(0., 1.)]],
    )
    .unwrap_err();
    assert!(matches!(
        e,
        GeometryError::NonFinite {
            ring: RingId::Hole(0),
            vertex: 1,
            ..
        }
    ));
}

#[test]
fn repeated_points_rejected_or_cleaned() {
    let pts = vec![v(0., 0.), v(1., 0.), v(1., 0.), v(1., 1.), v(0., 1.)];
    let e = Region::new(pts.clone(), vec![]).unwrap_err();
    assert_eq!(
        e,
        GeometryError::RepeatedPoint {
            ring: RingId::Outer,
            vertex: 2
        }
    );
    let (r, removed) = Region::new_cleaned(pts, vec![]).unwrap();
    assert_eq!(removed, 1);
    assert_eq!(r.outer().len(), 4);
    // input vertex 2 was removed, input vertex 3 is stored vertex 2
    assert_eq!(r.outer_index_from_input(2), None);
    assert_eq!(r.outer_index_from_input(3), Some(2));
}

#[test]
fn zero_area() {
    let e = Region::new(vec![v(0., 0.), v(1., 1.), v(2., 2.), v(3., 3.)], vec![]).unwrap_err();
    // collinear points fold back on themselves; the zero-area check comes first
    assert_eq!(
        e,
        GeometryError::ZeroArea {
            ring: RingId::Outer
        }
    );
}

#[test]
fn self_intersection_bow_tie() {
    let e = Region::new(vec![v(0., 0.), v(2., 2.), v(2., 0.), v(0., 2.)], vec![]).unwrap_err();
    assert_eq!(
        e,
        GeometryError::SelfIntersection {
            ring: RingId::Outer,
            edge_a: 0,
            edge_b: 2
        }
    );
}

#[test]
fn self_touching_vertex_on_edge() {
    // vertex 4 touches edge 0 at (2,0)
    let pts = vec![
        v(0., 0.),
        v(4., 0.),
        v(4., 4.),
        v(3., 4.),
        v(2., 0.),
        v(1., 4.),
        v(0., 4.),
    ];
    let e = Region::new(pts, vec![]).unwrap_err();
    assert!(matches!(
        e,
        GeometryError::SelfIntersection {
            ring: RingId::Outer,
            edge_a: 0,
            ..
        }
    ));
}

#[test]
fn spike_with_zero_angle() {
    // the ring goes out to (3,1) and comes straight back along the same line
    let pts = vec![
        v(0., 0.),
        v(2., 0.),
        v(2., 1.),
        v(3., 1.),
        v(2.5, 1.),
        v(2., 2.),
        v(0., 2.),
    ];
    let e = Region::new(pts, vec![]).unwrap_err();
    assert_eq!(
        e,
        GeometryError::SelfIntersection {
            ring: RingId::Outer,
            edge_a: 2,
            edge_b: 3
        }
    );
}

#[test]
fn hole_outside() {
    let e = Region::new(square(v(0., 0.), 1.), vec![square(v(5., 5.), 0.5)]).unwrap_err();
    assert_eq!(e, GeometryError::HoleOutside { hole: 0 });
}

#[test]
fn hole_touching_outer() {
    // hole vertex exactly on the outer ring's bottom edge
    let hole = vec![v(0., -2.), v(1., -1.), v(-1., -1.)];
    let e = Region::new(square(v(0., 0.), 2.), vec![hole]).unwrap_err();
    assert!(matches!(
        e,
        GeometryError::RingsIntersect {
            ring_a: RingId::Outer,
            ring_b: RingId::Hole(0),
            ..
        }
    ));
}

#[test]
fn holes_overlapping_and_touching() {
    let e = Region::new(
        square(v(0., 0.), 5.),
        vec![square(v(0., 0.), 1.), square(v(1.5, 0.), 1.)],
    )
    .unwrap_err();
    assert!(matches!(
        e,
        GeometryError::RingsIntersect {
            ring_a: RingId::Hole(0),
            ring_b: RingId::Hole(1),
            ..
        }
    ));
    // touching at one corner
    let e = Region::new(
        square(v(0., 0.), 5.),
        vec![square(v(0., 0.), 1.), square(v(2., 2.), 1.)],
    )
    .unwrap_err();
    assert!(matches!(e, GeometryError::RingsIntersect { .. }));
}

#[test]
fn nested_holes() {
    let e = Region::new(
        square(v(0., 0.), 5.),
        vec![square(v(0., 0.), 2.), square(v(0., 0.), 1.)],
    )
    .unwrap_err();
    assert_eq!(e, GeometryError::NestedHole { outer: 0, inner: 1 });
}

#[test]
fn angles_and_reflex_vertices() {
    // L-shape: one reflex vertex (index 3) with angle 270°
    let l = vec![
        v(0., 0.),
        v(2., 0.),
        v(2., 1.),
        v(1., 1.),
        v(1., 2.),
        v(0., 2.),
    ];
    let r = Region::new(l, vec![]).unwrap();
    let ang = r.outer().left_angles();
    for (k, a) in ang.iter().enumerate() {
        let expect = if k == 3 { 1.5 * PI } else { 0.5 * PI };
        assert!((a - expect).abs() < 1e-12, "vertex {k}: {a}");
        assert_eq!(r.outer().is_reflex(k), k == 3);
    }
    // angle sum of a simple n-gon = (n − 2)π
    assert!((ang.iter().sum::<f64>() - 4.0 * PI).abs() < 1e-12);
    assert_eq!(r.outer().convex_hull().len(), 5);
}

#[test]
fn hole_angles_are_measured_on_the_region_side() {
    let r = Region::new(square(v(0., 0.), 3.), vec![square(v(0., 0.), 1.)]).unwrap();
    // seen from the region, the corners of a square hole are reflex (270°)
    for a in r.holes()[0].left_angles() {
        assert!((a - 1.5 * PI).abs() < 1e-12);
    }
}

#[test]
fn segment_inside_for_cuts() {
    let l = vec![
        v(0., 0.),
        v(2., 0.),
        v(2., 1.),
        v(1., 1.),
        v(1., 2.),
        v(0., 2.),
    ];
    let r = Region::new(l, vec![]).unwrap();
    // cut from the reflex vertex straight down to the bottom edge: inside
    assert!(r.segment_inside(v(1., 1.), v(1., 0.)));
    // cut between two boundary vertices across the notch: outside
    assert!(!r.segment_inside(v(2., 1.), v(1., 2.)));
    // along a boundary edge: not inside
    assert!(!r.segment_inside(v(0., 0.), v(2., 0.)));
    // diagonal through the reflex vertex: touches the boundary in its interior
    assert!(!r.segment_inside(v(0., 0.), v(2., 2.)));
    // with a hole: a segment crossing the hole is rejected
    let r = Region::new(square(v(0., 0.), 3.), vec![square(v(0., 0.), 1.)]).unwrap();
    assert!(!r.segment_inside(v(-3., 0.), v(3., 0.)));
    assert!(r.segment_inside(v(-3., 0.), v(-1., 0.)));
}

#[test]
fn large_ring_validates_quickly() {
    // 100,000-vertex star-shaped ring
    let n = 100_000;
    let pts: Vec<DVec2> = (0..n)
        .map(|k| {
            let t = k as f64 / n as f64 * std::f64::consts::TAU;
            let r = 10.0 + 0.5 * (37.0 * t).sin();
            v(r * t.cos(), r * t.sin())
        })
        .collect();
    let t0 = std::time::Instant::now();
    let r = Region::new(pts, vec![]).unwrap();
    let dt = t0.elapsed();
    eprintln!("validated {} vertices in {:?}", r.num_vertices(), dt);
    // generous bound for slow CI machines; the measured figure is in docs/benchmarks.md
    assert!(dt.as_secs_f64() < 5.0, "took {dt:?}");
}

/// The one signed-area function of the workspace (`region::signed_area`, used by every crate):
/// sign by orientation, value by hand, open or closed rings, and nothing for an empty ring.
#[test]
fn the_free_signed_area_by_hand() {
    use unamalla_mesh::region::signed_area;
    let sq = [
        DVec2::new(0.0, 0.0),
        DVec2::new(2.0, 0.0),
        DVec2::new(2.0, 3.0),
        DVec2::new(0.0, 3.0),
    ];
    assert_eq!(signed_area(&sq), 6.0);
    let mut closed = sq.to_vec();
    closed.push(sq[0]);
    assert_eq!(signed_area(&closed), 6.0);
    let mut cw = sq.to_vec();
    cw.reverse();
    assert_eq!(signed_area(&cw), -6.0);
    assert_eq!(signed_area(&[]), 0.0);
}
