//! Regression tests for defects found by the fuzz targets of `fuzz/` (see
//! `docs/reliability.md`).

use unamalla_mesh::{DVec2, Region};

/// `fuzz/` target `region`: far from the origin the textbook shoelace sum `½ Σ p_k × p_{k+1}`
/// cancels catastrophically (products ~10³⁰ at 10¹⁵, rounding errors ~10¹⁴), so the area and
/// the orientation of a small ring came out wrong and a counter-clockwise outer ring could be
/// "normalised" to clockwise. The area is now summed relative to the first vertex and the
/// orientation decided exactly.
#[test]
fn ring_far_from_origin_keeps_exact_area_and_orientation() {
    // base 1e15 is exactly representable and so is base + small integer (ulp(1e15) = 0.125)
    for base in [1e9, 1e12, 1e15] {
        let p = |x: f64, y: f64| DVec2::new(base + x, base + y);
        // triangle (0,0), (4,1), (1,4) relative to the base: doubled area = 4·4 − 1·1 = 15,
        // counter-clockwise
        let ccw = vec![p(0.0, 0.0), p(4.0, 1.0), p(1.0, 4.0)];
        let r = Region::new(ccw.clone(), vec![]).unwrap();
        assert_eq!(
            r.outer().points(),
            &ccw[..],
            "base {base}: CCW input must be kept"
        );
        assert_eq!(r.area(), 7.5, "base {base}");
        assert_eq!(r.outer().signed_area(), 7.5, "base {base}");
        // the same ring clockwise is reversed keeping vertex 0 first
        let cw: Vec<DVec2> = vec![ccw[0], ccw[2], ccw[1]];
        let r = Region::new(cw, vec![]).unwrap();
        assert_eq!(
            r.outer().points(),
            &ccw[..],
            "base {base}: CW input must be reversed"
        );
    }
}

/// Same defect for holes: a hole near (10¹², 10¹²) given counter-clockwise must be stored
/// clockwise, and the region's area is outer − hole exactly (all values are small integers
/// relative to the base, so the fan sums are exact).
#[test]
fn hole_far_from_origin_is_stored_clockwise() {
    let base = 1e12;
    let p = |x: f64, y: f64| DVec2::new(base + x, base + y);
    let outer = vec![p(0.0, 0.0), p(10.0, 0.0), p(10.0, 10.0), p(0.0, 10.0)];
    let hole_ccw = vec![p(2.0, 2.0), p(4.0, 2.0), p(4.0, 4.0), p(2.0, 4.0)];
    let r = Region::new(outer, vec![hole_ccw.clone()]).unwrap();
    let h = r.holes()[0].points();
    assert_eq!(h[0], hole_ccw[0]);
    assert_eq!(h[1], hole_ccw[3], "hole must be reversed to clockwise");
    assert_eq!(r.holes()[0].signed_area(), -4.0);
    assert_eq!(r.area(), 100.0 - 4.0);
}

/// `fuzz/` target `region`, input `Lattice(scale 1e300, [(72, −107), (0, 0), (−107, 0)])`:
/// with coordinates ~10³⁰² the products inside `orient2d` overflow to ±∞, so the orientation
/// (and any intersection test) was meaningless and a clockwise ring was kept clockwise.
/// Coordinates beyond `MAX_COORDINATE` (or non-zero below `MIN_COORDINATE`) are now rejected.
#[test]
fn coordinates_beyond_the_exact_predicates_range_are_rejected() {
    use unamalla_mesh::region::{MAX_COORDINATE, MIN_COORDINATE};
    use unamalla_mesh::{GeometryError, RingId};
    let s = 1e300;
    let huge = vec![
        DVec2::new(72.0 * s, -107.0 * s),
        DVec2::new(0.0, 0.0),
        DVec2::new(-107.0 * s, 0.0),
    ];
    assert!(matches!(
        Region::new(huge, vec![]),
        Err(GeometryError::CoordinateOutOfRange {
            ring: RingId::Outer,
            vertex: 0,
            ..
        })
    ));
    let tiny: Vec<DVec2> = [(0.0, 0.0), (2.0, 0.0), (0.0, 3.0)]
        .iter()
        .map(|&(x, y)| DVec2::new(x * 1e-300, y * 1e-300))
        .collect();
    assert!(matches!(
        Region::new(
            vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(1.0, 0.0),
                DVec2::new(0.0, 1.0)
            ],
            vec![tiny]
        ),
        Err(GeometryError::CoordinateOutOfRange {
            ring: RingId::Hole(0),
            vertex: 1,
            ..
        })
    ));
    // the limits themselves are accepted: right triangle with legs 1e150 → area 5e299, and
    // legs 1e-100 → area 5e-201 (both finite, non-zero, exact in binary up to rounding of the
    // decimal constants)
    for l in [MAX_COORDINATE, MIN_COORDINATE] {
        let r = Region::new(
            vec![DVec2::new(0.0, 0.0), DVec2::new(l, 0.0), DVec2::new(0.0, l)],
            vec![],
        )
        .unwrap();
        assert_eq!(r.area(), 0.5 * l * l);
    }
}
