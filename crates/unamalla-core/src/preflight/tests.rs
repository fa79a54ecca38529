//! Unit tests of the preflight checks: the size limits, byte counts, the narrow features and holes
//! named beside failing cells, and the closest rings.

use super::*;

#[test]
fn sizes_are_compared_with_the_limit() {
    // 10⁹ cells × 12,000 bytes = 1.2e13 bytes ≈ 10.9 TiB > 4 GiB
    let e = check_size(
        "--cells",
        1_000_000_000u64,
        1e9,
        "cells",
        COST_PER_MESH_CELL,
        DEFAULT_MEMORY_LIMIT,
    )
    .unwrap_err();
    let s = e.to_string();
    assert!(
        s.starts_with("--cells 1000000000: needs about 10.9 TiB"),
        "{s}"
    );
    assert!(s.contains("above the memory limit of 4.0 GiB"), "{s}");
    assert!(s.contains(MEMORY_LIMIT_ENV), "{s}");
    // 20,000 cells: 240 MB, fine
    check_size(
        "--cells",
        20000,
        2e4,
        "cells",
        COST_PER_MESH_CELL,
        DEFAULT_MEMORY_LIMIT,
    )
    .unwrap();
    // an overflowing count (inf) is too large, not accepted
    assert!(check_size("--size", "x", f64::INFINITY, "nodes", 1.0, u64::MAX).is_err());
}

/// A 10 × 10 square with three clockwise square holes: A (0.4 wide, centred at (5, 5)),
/// B (0.3 wide, at (2, 2)) and C (2 wide, at (7, 2)).
fn three_holes() -> Region {
    let sq = |c: DVec2, w: f64| {
        let r = 0.5 * w;
        vec![
            c + DVec2::new(-r, -r),
            c + DVec2::new(-r, r),
            c + DVec2::new(r, r),
            c + DVec2::new(r, -r),
        ]
    };
    Region::new(
        sq(DVec2::new(5.0, 5.0), 10.0).into_iter().rev().collect(),
        vec![
            sq(DVec2::new(5.0, 5.0), 0.4),
            sq(DVec2::new(2.0, 2.0), 0.3),
            sq(DVec2::new(7.0, 2.0), 2.0),
        ],
    )
    .unwrap()
}

/// Two failing cells beside hole A, one beside the wide hole C: at cell size 0.63 the
/// cause named is hole 0 (A: narrower than a cell, 2 cells within h), with B counted as
/// the other narrow hole and the remedies computed from A (area 0.16, half width 0.2); at
/// cell size 0.3 (below A's width) no hole is blamed.
#[test]
fn failing_cells_beside_a_hole_narrower_than_a_cell_name_the_hole() {
    let r = three_holes();
    // a cell of 0.1 × 0.1 with its lower left corner at (x, y)
    let cell = |x: f64, y: f64| [[x, y], [x + 0.1, y], [x + 0.1, y + 0.1], [x, y + 0.1]];
    let v = crate::verify::Verification {
        cells: 100,
        non_convex_cells: 3,
        non_convex_examples: vec![1, 2, 3],
        non_convex_at: vec![cell(5.5, 5.0), cell(5.0, 4.6), cell(8.2, 2.0)],
        min_corner: -1.0,
        ..Default::default()
    };
    let s = small_hole(&v, &r, 0.63).expect("hole A is blamed");
    assert_eq!((s.hole, s.cells, s.others), (0, 2, 1));
    assert!((s.width - 0.4).abs() < 1e-12 && (s.area - 0.16).abs() < 1e-12);
    assert_eq!(s.at, [5.0, 5.0]);
    let msg = explain_guarantee(
        crate::verify::GuaranteeNotMet(Box::new(v.clone())),
        &r,
        0.63,
    )
    .to_string();
    assert!(msg.contains("hole 0 (4.000e-1 across"), "{msg}");
    // 0.16 × 1.001, printed above 0.16 so that the suggested option does drop the hole
    assert!(msg.contains("--min-hole-area 1.602e-1"), "{msg}");
    assert!(!msg.contains("  "), "{msg}");
    assert!(msg.contains("--cell-size 2.000e-1"), "{msg}");
    assert!(msg.contains("1 other hole(s)"), "{msg}");
    assert!(msg.contains("3 of 100 cells are not convex"), "{msg}");
    assert!(small_hole(&v, &r, 0.3).is_none());
    // failing cells far from every narrow hole: not blamed on a hole
    let far = crate::verify::Verification {
        non_convex_at: vec![cell(9.5, 9.5)],
        ..v
    };
    assert!(small_hole(&far, &r, 0.63).is_none());
}

/// The later rounds of the narrow-hole retry: the holes whose width lies in the given range
/// that are the nearest hole, within h, of a failing cell. Hole widths 0.4 (A), 0.3 (B), 2.0
/// (C); two failing cells beside A, one 0.2 from C. At h = 0.63, widths below 1.26: only A;
/// at h = 1.1, widths below 2.2: A and C; widths from h = 1.1 to 2.2: C only (A is narrower
/// than a cell); B has no failing cell; none for cells far away.
#[test]
fn holes_next_to_failures_are_the_narrow_nearest_ones() {
    let r = three_holes();
    let cell = |x: f64, y: f64| [[x, y], [x + 0.1, y], [x + 0.1, y + 0.1], [x, y + 0.1]];
    let v = crate::verify::Verification {
        non_convex_cells: 3,
        non_convex_at: vec![cell(5.5, 5.0), cell(5.0, 4.6), cell(8.2, 2.0)],
        ..Default::default()
    };
    assert_eq!(holes_next_to_failures(&v, &r, 0.63, 0.0..1.26), vec![0]);
    assert_eq!(holes_next_to_failures(&v, &r, 1.1, 0.0..2.2), vec![0, 2]);
    assert_eq!(holes_next_to_failures(&v, &r, 1.1, 1.1..2.2), vec![2]);
    // the upper end is excluded: C (2.0 wide) is not narrower than 2.0
    assert_eq!(
        holes_next_to_failures(&v, &r, 1.1, 1.1..2.0),
        Vec::<usize>::new()
    );
    // a cell outside counts by its centroid, as a non-convex one by its corners
    let outside = crate::verify::Verification {
        outside_examples: vec![(7, [8.1, 2.0])],
        ..Default::default()
    };
    assert_eq!(holes_next_to_failures(&outside, &r, 1.1, 0.0..2.2), vec![2]);
    let far = crate::verify::Verification {
        non_convex_at: vec![cell(9.5, 9.5)],
        ..Default::default()
    };
    assert!(holes_next_to_failures(&far, &r, 1.1, 0.0..2.2).is_empty());
}

#[test]
fn byte_counts_parse() {
    assert_eq!(parse_bytes("8G"), Some(8 << 30));
    assert_eq!(parse_bytes("512m"), Some(512 << 20));
    assert_eq!(parse_bytes("1000000"), Some(1_000_000));
    assert_eq!(parse_bytes("1.5K"), Some(1536));
    assert_eq!(parse_bytes("-1G"), None);
    assert_eq!(parse_bytes("lots"), None);
    assert_eq!(parse_bytes(""), None);
    assert_eq!(human(1536.0), "1.5 KiB");
    assert_eq!(human((4u64 << 30) as f64), "4.0 GiB");
}

#[test]
fn a_spike_and_a_slit_are_narrow_features_a_circle_and_a_square_are_not() {
    // the hostile fixture's spike: sides through (5 ± 1e-7, 10) and the tip (5, 13). The
    // base vertex (5 + 1e-7, 10) is 2·10⁻⁷ from the other side's end point (5 − 1e-7, 10)
    // (and from the side itself: 2e-7 · 3 / √(9 + 10⁻¹⁴)), 3 + 3 = 6 further along the ring
    let p = |x: f64, y: f64| DVec2::new(x, y);
    let spike = Region::new(
        vec![
            p(0.0, 0.0),
            p(10.0, 0.0),
            p(10.0, 10.0),
            p(5.0 + 1e-7, 10.0),
            p(5.0, 13.0),
            p(5.0 - 1e-7, 10.0),
            p(0.0, 10.0),
        ],
        vec![],
    )
    .unwrap();
    let h = 0.58;
    let (ring, _, width, sep) = narrow_feature(&spike, MIN_GAP_FRACTION * h, h).unwrap();
    assert_eq!(ring, 0);
    assert!((width - 2e-7).abs() < 1e-12, "{width}");
    assert!((sep - 6.0).abs() < 1e-6, "{sep}");
    let e = check_narrow_features(&spike, h).unwrap_err();
    assert!(e.to_string().contains("drop --no-simplify"), "{e}");
    // a slit 10⁻³ wide and 6 deep: its walls are 10⁻³ apart, 12 + 10⁻³ along the ring
    let slit = Region::new(
        vec![
            p(0.0, 0.0),
            p(10.0, 0.0),
            p(10.0, 10.0),
            p(5.0005, 10.0),
            p(5.0005, 4.0),
            p(4.9995, 4.0),
            p(4.9995, 10.0),
            p(0.0, 10.0),
        ],
        vec![],
    )
    .unwrap();
    let (_, _, width, sep) = narrow_feature(&slit, MIN_GAP_FRACTION * h, h).unwrap();
    assert!((width - 1e-3).abs() < 1e-12, "{width}");
    assert!(sep > 6.0, "{sep}");
    // at a cell size with 0.01·h below the slit's width it is meshable
    assert!(check_narrow_features(&slit, 0.05).is_ok());
    // a circle of 10,000 vertices (spacing 6.3e-4 < 0.01·h) and a square: nothing
    let circle: Vec<DVec2> = (0..10_000)
        .map(|k| {
            let t = std::f64::consts::TAU * k as f64 / 10_000.0;
            p(t.cos(), t.sin())
        })
        .collect();
    let circle = Region::new(circle, vec![]).unwrap();
    assert!(narrow_feature(&circle, 0.001, 0.1).is_none());
    let square = Region::new(
        vec![p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)],
        vec![],
    )
    .unwrap();
    assert!(check_narrow_features(&square, 0.1).is_ok());
}

#[test]
fn the_closest_rings_are_found() {
    // square [0,10]², holes: [1,2]×[1,2] (gap 1 to the outer ring) and
    // [2.5,3]×[1,2] (gap 0.5 to the first hole)
    let sq = |x0: f64, y0: f64, x1: f64, y1: f64| {
        vec![
            DVec2::new(x0, y0),
            DVec2::new(x0, y1),
            DVec2::new(x1, y1),
            DVec2::new(x1, y0),
        ]
    };
    let outer = vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(10.0, 0.0),
        DVec2::new(10.0, 10.0),
        DVec2::new(0.0, 10.0),
    ];
    let r = Region::new(
        outer.clone(),
        vec![sq(1.0, 1.0, 2.0, 2.0), sq(2.5, 1.0, 3.0, 2.0)],
    )
    .unwrap();
    assert_eq!(ring_gaps(&r), Some((1, 2, 0.5)));
    let r = Region::new(outer.clone(), vec![sq(1e-9, 1.0, 2.0, 2.0)]).unwrap();
    let (a, b, g) = ring_gaps(&r).unwrap();
    assert_eq!((a, b), (0, 1));
    assert!((g - 1e-9).abs() < 1e-15, "{g}");
    let e = explain_failure(CoreError::NoLayout, &r, 0.1);
    let s = e.to_string();
    assert!(
        s.starts_with("hole 0 is 1.000e-9 from the outer ring"),
        "{s}"
    );
    assert!(s.contains("no block layout could be built"), "{s}");
    // a wide gap leaves the error alone
    let r = Region::new(outer, vec![sq(1.0, 1.0, 2.0, 2.0)]).unwrap();
    let e = explain_failure(CoreError::NoLayout, &r, 0.1);
    assert_eq!(e.to_string(), "no block layout could be built");
}
