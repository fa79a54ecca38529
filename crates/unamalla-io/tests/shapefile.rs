//! ESRI Shapefile polygons: files written with the `shapefile` crate itself (independent of
//! our writer) load as regions with holes attached and orientation normalised; part selection;
//! our writer round-trips; typed errors; no panic on truncation.

mod common;

use common::*;
use shapefile::{Point, Polygon, PolygonRing, Polyline, ShapeWriter};
use unamalla_io::*;
use unamalla_mesh::{DVec2, Region};

fn ring(v: &[(f64, f64)]) -> Vec<Point> {
    let mut p: Vec<Point> = v.iter().map(|&(x, y)| Point::new(x, y)).collect();
    p.push(p[0]);
    p
}

fn point_set(v: &[DVec2]) -> Vec<[u64; 2]> {
    let mut b: Vec<[u64; 2]> = v.iter().map(|p| [p.x.to_bits(), p.y.to_bits()]).collect();
    b.sort();
    b
}

/// Two polygon shapes: shape 0 a 10 × 10 square with a 2 × 2 hole, shape 1 a small triangle;
/// then a second outer ring (in the same shape) with its own hole listed *first* to check
/// containment-based assignment.
fn write_test_file(path: &std::path::Path) {
    let square = PolygonRing::Outer(ring(&[(0., 0.), (0., 10.), (10., 10.), (10., 0.)]));
    let hole = PolygonRing::Inner(ring(&[(4., 4.), (6., 4.), (6., 6.), (4., 6.)]));
    let tri = PolygonRing::Outer(ring(&[(20., 0.), (20., 1.), (21., 0.)]));
    let far_hole = PolygonRing::Inner(ring(&[(31., 1.), (32., 1.), (32., 2.), (31., 2.)]));
    let far = PolygonRing::Outer(ring(&[(30., 0.), (30., 5.), (35., 5.), (35., 0.)]));
    let shapes = vec![
        Polygon::with_rings(vec![square, hole]),
        Polygon::with_rings(vec![tri, far_hole, far]),
    ];
    // `write_shapes` consumes the writer and finalises the file.
    ShapeWriter::from_path(path)
        .unwrap()
        .write_shapes(&shapes)
        .unwrap();
}

#[test]
fn polygons_written_by_the_shapefile_crate_load_as_regions() {
    let dir = Scratch::new("shp");
    let p = dir.path("regions.shp");
    write_test_file(&p);
    let parts = read_shapefile_parts(&p).unwrap();
    assert_eq!(parts.len(), 3);
    assert_eq!(parts[0].holes.len(), 1);
    assert_eq!(
        parts[1].holes.len(),
        0,
        "the far hole is not inside the triangle"
    );
    assert_eq!(parts[2].holes.len(), 1);
    assert_eq!(parts[2].json_path, "shape 1");

    // Default: the largest part, the square with its hole.
    let r = read_region_shapefile(&p, PartSelector::Largest).unwrap();
    assert_eq!(r.area(), 100.0 - 4.0);
    assert!(
        r.outer().signed_area() > 0.0,
        "outer normalised to counter-clockwise"
    );
    assert!(
        r.holes()[0].signed_area() < 0.0,
        "hole normalised to clockwise"
    );
    assert_eq!(
        point_set(r.holes()[0].points()),
        point_set(&[
            DVec2::new(4., 4.),
            DVec2::new(6., 4.),
            DVec2::new(6., 6.),
            DVec2::new(4., 6.)
        ])
    );
    let r = read_region_shapefile(&p, PartSelector::Index(2)).unwrap();
    assert_eq!(r.area(), 25.0 - 1.0);
    let e = read_region_shapefile(&p, PartSelector::Index(3)).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::PartOutOfRange {
                index: 3,
                parts: 3,
                ..
            }
        ),
        "{e}"
    );
}

#[test]
fn our_writer_round_trips() {
    let dir = Scratch::new("shp-rt");
    let r = Region::new(
        vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(3.0, 0.1),
            DVec2::new(2.5, 2.0),
            DVec2::new(0.2, 1.0 / 3.0 + 1.0),
        ],
        vec![vec![
            DVec2::new(1.0, 0.5),
            DVec2::new(1.0, 1.0),
            DVec2::new(1.5, 0.75),
        ]],
    )
    .unwrap();
    let p = dir.path("r.shp");
    write_region_shapefile(&p, &r).unwrap();
    assert_eq!(dir.entries(), vec!["r.shp", "r.shx"]);
    let back = read_region_shapefile(&p, PartSelector::Largest).unwrap();
    assert_eq!(back.area(), r.area());
    assert_eq!(
        point_set(back.outer().points()),
        point_set(r.outer().points())
    );
    assert_eq!(
        point_set(back.holes()[0].points()),
        point_set(r.holes()[0].points())
    );
    // The raw file keeps the ESRI orientation: outer clockwise.
    let parts = read_shapefile_parts(&p).unwrap();
    let o = &parts[0].outer;
    let s: f64 = (0..o.len())
        .map(|k| o[k].perp_dot(o[(k + 1) % o.len()]))
        .sum();
    assert!(s < 0.0);
}

#[test]
fn errors_and_truncation() {
    let dir = Scratch::new("shp-bad");
    let p = dir.path("lines.shp");
    let mut w = ShapeWriter::from_path(&p).unwrap();
    w.write_shape(&Polyline::new(vec![Point::new(0., 0.), Point::new(1., 1.)]))
        .unwrap();
    w.finalize().unwrap();
    drop(w);
    let e = read_region_shapefile(&p, PartSelector::Largest).unwrap_err();
    assert!(matches!(e, IoError::NoPolygon { .. }), "{e}");

    let q = dir.path("not.shp");
    std::fs::write(&q, "this is not a shapefile at all, but long enough to have a header ......................................................................................").unwrap();
    assert!(matches!(
        read_shapefile_parts(&q),
        Err(IoError::Shapefile { .. })
    ));

    let good = dir.path("regions.shp");
    write_test_file(&good);
    let bytes = std::fs::read(&good).unwrap();
    let t = dir.path("trunc.shp");
    for k in 0..bytes.len() {
        std::fs::write(&t, &bytes[..k]).unwrap();
        assert!(
            read_region_shapefile(&t, PartSelector::Largest).is_err(),
            "prefix {k}"
        );
    }
    assert!(matches!(
        read_region_shapefile(dir.path("missing.shp"), PartSelector::Largest),
        Err(IoError::Io { .. })
    ));
}
