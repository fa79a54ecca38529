//! UNAMALLA's own formats (`.con`, XY, RED, Geomview MESH) and plain-text rings: the example
//! contours of the Unamalla v2.0 manual [González Flores, §A.5] load as regions, hand-written
//! files with known node orders, bit-exact round trips, typed errors with line numbers, and no
//! panic on truncation.

mod common;

use std::path::{Path, PathBuf};

use common::*;
use unamalla_io::*;
use unamalla_mesh::{DVec2, HasNodes, StructuredGrid2};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn pts(v: &[(f64, f64)]) -> Vec<DVec2> {
    v.iter().map(|&(x, y)| DVec2::new(x, y)).collect()
}

fn bits2(v: &[DVec2]) -> Vec<[u64; 2]> {
    v.iter().map(|p| [p.x.to_bits(), p.y.to_bits()]).collect()
}

/// The set of points of a ring, as sorted bit patterns (orientation and start independent).
fn point_set(v: &[DVec2]) -> Vec<[u64; 2]> {
    let mut b = bits2(v);
    b.sort();
    b
}

#[test]
fn manual_hole_contour_loads_as_a_region() {
    let c = read_con(data("hole-ibflag13.con")).unwrap();
    assert_eq!(c.ibflag(), Ibflag::Cut13);
    assert_eq!(c.counts(), [2, 7, 2, 5]);
    assert_eq!(c.points().len(), 13);
    let s = c.sides();
    assert_eq!(s[0], pts(&[(0., 0.), (9., 0.)]).as_slice());
    assert_eq!(s[2], pts(&[(9., 0.), (0., 0.)]).as_slice());
    assert_eq!(s[1].len(), 7);
    assert_eq!(
        s[3],
        pts(&[(0., 0.), (20., -15.), (30., 1.), (12., 15.), (0., 0.)]).as_slice()
    );
    let r = read_region_con(data("hole-ibflag13.con")).unwrap();
    // Area 454 − 48.5 = 405.5: outer quadrilateral minus hexagonal hole, by the shoelace
    // formula (worked out by hand; the manual does not state it).
    assert_eq!(r.area(), 405.5);
    assert_eq!(r.holes().len(), 1);
    assert!(r.outer().signed_area() > 0.0 && r.holes()[0].signed_area() < 0.0);
    assert_eq!(
        point_set(r.outer().points()),
        point_set(&pts(&[(0., 0.), (20., -15.), (30., 1.), (12., 15.)]))
    );
    assert_eq!(
        point_set(r.holes()[0].points()),
        point_set(&pts(&[
            (9., 0.),
            (12., 4.),
            (16., 4.),
            (19., 1.),
            (15., -3.),
            (11., -3.)
        ]))
    );
}

#[test]
fn manual_cuad2pp_contour_loads_as_a_region() {
    let c = read_con(data("cuad2pp.con")).unwrap();
    assert_eq!(c.ibflag(), Ibflag::FourSides);
    assert_eq!(c.counts(), [2, 2, 4, 2]);
    let s = c.sides();
    // The manual's side split [González Flores, §A.5]: B1 = (0.4,0)–(0.6,0), B2 = (0.6,0)–(1,0), B3 = (1,0),(1,1),(0,1),(0,0),
    // B4 = (0,0)–(0.4,0).
    assert_eq!(s[0], pts(&[(0.4, 0.), (0.6, 0.)]).as_slice());
    assert_eq!(s[1], pts(&[(0.6, 0.), (1., 0.)]).as_slice());
    assert_eq!(
        s[2],
        pts(&[(1., 0.), (1., 1.), (0., 1.), (0., 0.)]).as_slice()
    );
    assert_eq!(s[3], pts(&[(0., 0.), (0.4, 0.)]).as_slice());
    let r = c.region().unwrap();
    assert!((r.area() - 1.0).abs() < 1e-15);
    assert_eq!(r.outer().len(), 6);
    assert!(r.holes().is_empty());
}

#[test]
fn con_round_trip_and_clockwise_input() {
    let dir = Scratch::new("con");
    for name in ["hole-ibflag13.con", "cuad2pp.con"] {
        let c = read_con(data(name)).unwrap();
        let p = dir.path(name);
        write_con(&p, &c).unwrap();
        assert_eq!(read_con(&p).unwrap(), c);
    }
    // Awkward numbers survive exactly.
    let ring = pts(&[(0.1, 1.0 / 3.0), (1e-7, -2.5e17), (123.456, 7.0)]);
    let c = Contour::from_ring(&ring).unwrap();
    assert_eq!(c.ibflag(), Ibflag::Undefined);
    assert_eq!(c.points().len(), 4);
    let p = dir.path("awkward.con");
    write_con(&p, &c).unwrap();
    let back = read_con(&p).unwrap();
    assert_eq!(bits2(back.points()), bits2(c.points()));
    // A clockwise contour gives the same (normalised) region.
    let cw = parse_con("5 0 0 0 0 0\n0 0\n0 1\n2 1\n2 0\n0 0\n").unwrap();
    let r = cw.region().unwrap();
    assert_eq!(r.area(), 2.0);
    assert!(r.outer().signed_area() > 0.0);
}

#[test]
fn con_errors_are_typed_with_line_numbers() {
    let e = parse_con("13 7 2 7 2 5\n").unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 1, .. }), "{e}");
    let e = parse_con("4 1 2 2 2 2\n0 0\n1 0\n1 1\n0 0\n").unwrap_err();
    assert!(
        matches!(
            e,
            IoError::CountMismatch {
                line: 1,
                expected: 7,
                found: 8,
                ..
            }
        ),
        "{e}"
    );
    let e = parse_con("4 0 0 0 0 0\n0 0\n1 0\n1 x\n0 0\n").unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 4, .. }), "{e}");
    let e = parse_con("4 0 0 0 0 0\n0 0\n1 0\n1 1\n0 0.5\n").unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 5, .. }), "{e}");
    let e = parse_con("4 0 0 0 0 0\n0 0\n1 0\n1 1\n0 0\n9\n").unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 6, .. }), "{e}");
    let e = parse_con("4 0 0 0 0 0\n0 0\n1 0\n").unwrap_err();
    assert!(matches!(e, IoError::Truncated { line: 3, .. }), "{e}");
    // ibflag 13 whose side 3 is not side 1 reversed.
    let text = std::fs::read_to_string(data("hole-ibflag13.con")).unwrap();
    let bad = text.replacen(
        " 9.0  0.0\n 0.0  0.0\n20.0",
        " 9.0  0.0\n 0.5  0.0\n20.0",
        1,
    );
    assert!(matches!(parse_con(&bad), Err(IoError::Malformed { .. })));
    // A self-intersecting contour is an invalid region.
    let dir = Scratch::new("con-bad");
    let p = dir.path("bow.con");
    std::fs::write(&p, "5 0 0 0 0 0\n0 0\n1 1\n1 0\n0 1\n0 0\n").unwrap();
    assert!(matches!(
        read_region_con(&p),
        Err(IoError::InvalidRegion { .. })
    ));
}

/// `(i, j)` ↦ (i + 0.1 j, j + 0.01 i): every coordinate tells which node it is.
fn tagged_grid(m: usize, n: usize) -> StructuredGrid2 {
    StructuredGrid2::from_fn(m, n, |i, j| {
        DVec2::new(i as f64 + 0.1 * j as f64, j as f64 + 0.01 * i as f64)
    })
    .unwrap()
}

#[test]
fn hand_written_xy_and_red_files() {
    // XY: column by column, j fastest, 7 values per line, F11.4-style fields.
    let xy = "3 2\ngrid.xy\n    0.0000     0.0000     0.1000     1.0000     1.0000     0.0100     1.1000\n    1.0100     2.0000     0.0200     2.1000     1.0200\n";
    let f = parse_xy(xy).unwrap();
    assert_eq!(f.name, "grid.xy");
    assert_eq!(f.grid, tagged_grid(3, 2));
    // RED of a 3 × 3 grid: boundary counter-clockwise from (1,1), then the interior node, which
    // starts at real offset ibo = 2(2m + 2n − 4) = 16.
    let red = "3 3\ncuad.red\n0 0 1 0 2 0 2\n1 2 2 1 2 0 2\n0 1 1.25 0.75\n";
    let f = parse_red(red).unwrap();
    let want = StructuredGrid2::from_fn(3, 3, |i, j| {
        if (i, j) == (1, 1) {
            DVec2::new(1.25, 0.75)
        } else {
            DVec2::new(i as f64, j as f64)
        }
    })
    .unwrap();
    assert_eq!(f.grid, want);
    assert_eq!(f.name, "cuad.red");
}

#[test]
fn xy_red_round_trip_bitwise() {
    let dir = Scratch::new("xyred");
    let mut r = Rng::new(5);
    let g = StructuredGrid2::from_fn(5, 4, |i, j| {
        DVec2::new(i as f64 + r.unit() * 1e-3, j as f64 * 1e5 + r.unit())
    })
    .unwrap();
    let p = dir.path("g.xy");
    write_xy(&p, &g, "g.xy").unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    assert!(text.starts_with("5 4\ng.xy\n"));
    assert_eq!(text.lines().count(), 2 + (40usize).div_ceil(7));
    let f = read_xy(&p).unwrap();
    assert_eq!(bits2(f.grid.nodes()), bits2(g.nodes()));
    let p = dir.path("g.red");
    write_red(&p, &g, "g.red").unwrap();
    let f = read_red(&p).unwrap();
    assert_eq!(bits2(f.grid.nodes()), bits2(g.nodes()));
    assert_eq!(f.name, "g.red");
    // XY and RED of the same grid differ (different orders) unless read with the right reader.
    assert_ne!(read_xy(&p).map(|f| f.grid).ok(), Some(g.clone()));
    // 2 × 2 edge case: no interior.
    let small = tagged_grid(2, 2);
    write_red(&p, &small, "").unwrap();
    assert_eq!(read_red(&p).unwrap().grid, small);
    assert!(write_xy(&p, &g, "a\nb").is_err());
}

#[test]
fn xy_red_errors_are_typed() {
    assert!(matches!(
        parse_xy("1 5\nx\n"),
        Err(IoError::Malformed { line: 1, .. })
    ));
    assert!(matches!(
        parse_xy("3 2\nx\n0 0 0 1\n"),
        Err(IoError::Truncated { .. })
    ));
    let e = parse_xy("2 2\nx\n0 0 0 1\n1 0 1 z\n").unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 4, .. }), "{e}");
    let e = parse_red("2 2\nx\n0 0 1 0 1 1 0 1\n5\n").unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 4, .. }), "{e}");
    // A huge declared size is rejected without allocating.
    assert!(matches!(
        parse_xy("100000 100000\nx\n0 0\n"),
        Err(IoError::Truncated { .. })
    ));
}

#[test]
fn geomview_mesh_round_trip_and_hand_written() {
    let dir = Scratch::new("gv");
    let g = tagged_grid(4, 3);
    let z: Vec<f64> = (0..12).map(|k| (k as f64).sin()).collect();
    let p = dir.path("g.mesh");
    write_geomview_mesh(&p, &g, Some(&z)).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    assert!(text.starts_with("MESH\n4 3\n"));
    let f = read_geomview_mesh(&p).unwrap();
    assert_eq!((f.nu, f.nv), (4, 3));
    assert_eq!(f.grid().unwrap(), g);
    assert_eq!(
        f.heights().iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        z.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    );
    // Hand-written: u fastest.
    let f = parse_geomview_mesh("MESH # comment\n2 2\n0 0 0\n1 0 0\n0 1 5\n1 1 0\n").unwrap();
    assert_eq!(f.grid().unwrap().node(0, 1), DVec2::new(0.0, 1.0));
    assert_eq!(f.heights()[2], 5.0);
    assert!(matches!(
        parse_geomview_mesh("CMESH\n"),
        Err(IoError::Unsupported { .. })
    ));
    assert!(matches!(
        parse_geomview_mesh("OFF\n"),
        Err(IoError::Malformed { line: 1, .. })
    ));
    assert!(write_geomview_mesh(&p, &g, Some(&z[..3])).is_err());
}

#[test]
fn plain_text_rings() {
    let text =
        "# outer\n0 0\n4 0 7.5\n4 3\n0 3\n0 0\n\n\n# hole, clockwise already\n1 1\n1 2\n2 2\n";
    let r = parse_region_text(text).unwrap();
    assert_eq!(r.area(), 12.0 - 0.5);
    assert_eq!(r.outer().len(), 4);
    assert_eq!(r.holes().len(), 1);
    let rings = parse_rings_text(text).unwrap();
    assert_eq!(rings.len(), 2);
    assert_eq!(rings[0].len(), 4, "closing point dropped");
    // Comment-only lines do not split rings.
    let r2 = parse_region_text("0 0\n# note\n1 0\n1 1\n").unwrap();
    assert_eq!(r2.outer().len(), 3);

    let dir = Scratch::new("rings");
    let p = dir.path("r.txt");
    write_region_text(&p, &r).unwrap();
    let back = read_region_text(&p).unwrap();
    assert_eq!(back, r);

    let e = parse_region_text("0 0\n1 0\n1 x\n").unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 3, .. }), "{e}");
    let e = parse_region_text("0 0 0 0\n").unwrap_err();
    assert!(matches!(e, IoError::Malformed { line: 1, .. }), "{e}");
    assert!(matches!(
        parse_region_text("# nothing\n"),
        Err(IoError::Truncated { .. })
    ));
    assert!(matches!(
        parse_region_text("0 0\n1 0\n"),
        Err(IoError::InvalidRegion { .. })
    ));
}

#[test]
fn no_panic_on_any_truncation() {
    let con = std::fs::read_to_string(data("hole-ibflag13.con")).unwrap();
    let dir = Scratch::new("legacy-trunc");
    let g = tagged_grid(4, 3);
    let mut texts = vec![con];
    for (k, f) in ["a.xy", "a.red", "a.mesh", "a.txt"].iter().enumerate() {
        let p = dir.path(f);
        match k {
            0 => write_xy(&p, &g, "a").unwrap(),
            1 => write_red(&p, &g, "a").unwrap(),
            2 => write_geomview_mesh(&p, &g, None).unwrap(),
            _ => {
                write_region_text(&p, &read_region_con(data("hole-ibflag13.con")).unwrap()).unwrap()
            }
        }
        texts.push(std::fs::read_to_string(&p).unwrap());
    }
    for t in &texts {
        for k in 0..t.len() {
            let s = &t[..k];
            let _ = parse_con(s);
            let _ = parse_xy(s);
            let _ = parse_red(s);
            let _ = parse_geomview_mesh(s);
            let _ = parse_region_text(s);
        }
    }
}

/// The manual's hole region [González Flores, §A.5.1] written with `ibflag = 24` (sides 2 and 4 are the cut, side 1 the
/// outer loop, side 3 the hole) gives the same region.
#[test]
fn ibflag_24_contour() {
    let text = "13 24 5 2 7 2\n0 0\n20 -15\n30 1\n12 15\n0 0\n9 0\n12 4\n16 4\n19 1\n15 -3\n11 -3\n9 0\n0 0\n";
    let c = parse_con(text).unwrap();
    assert_eq!(c.ibflag(), Ibflag::Cut24);
    let r = c.region().unwrap();
    assert_eq!(r.area(), 405.5);
    assert_eq!(r.holes().len(), 1);
    let r13 = read_region_con(data("hole-ibflag13.con")).unwrap();
    assert_eq!(
        point_set(r.outer().points()),
        point_set(r13.outer().points())
    );
    assert_eq!(
        point_set(r.holes()[0].points()),
        point_set(r13.holes()[0].points())
    );
    // Side 4 must be side 2 reversed: with counts 5 3 6 2, side 2 is (0,0),(9,0),(12,4).
    let bad = text.replacen("13 24 5 2 7 2", "13 24 5 3 6 2", 1);
    let e = parse_con(&bad).unwrap_err();
    assert!(e.to_string().contains("reversed"), "{e}");
}
