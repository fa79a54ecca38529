//! GeoJSON region reading: accepted document shapes, orientation normalisation, part selection,
//! typed errors, and the real regions in `fixtures/regions`.

mod common;

use std::path::Path;

use common::Scratch;
use unamalla_io::*;
use unamalla_mesh::{DVec2, GeometryError, RingId};

fn pts(v: &[(f64, f64)]) -> Vec<DVec2> {
    v.iter().map(|&(x, y)| DVec2::new(x, y)).collect()
}

/// Signed area by the shoelace formula, written here independently of the crates under test.
fn shoelace(ring: &[DVec2]) -> f64 {
    let n = ring.len();
    (0..n)
        .map(|k| {
            let (a, b) = (ring[k], ring[(k + 1) % n]);
            a.x * b.y - b.x * a.y
        })
        .sum::<f64>()
        / 2.0
}

const SQUARE_WITH_HOLE: &str = r#"{"type": "Polygon", "coordinates": [
    [[0, 0], [4, 0], [4, 4], [0, 4], [0, 0]],
    [[1, 1], [1, 2], [2, 2], [2, 1], [1, 1]]
]}"#;

#[test]
fn polygon_with_hole() {
    let r = parse_region_geojson(SQUARE_WITH_HOLE, PartSelector::Largest).unwrap();
    assert_eq!(r.outer().points().len(), 4, "closing point dropped");
    assert_eq!(r.holes().len(), 1);
    assert_eq!(r.holes()[0].points().len(), 4);
    assert_eq!(r.area(), 16.0 - 1.0);
    assert!(shoelace(r.outer().points()) > 0.0);
    assert!(shoelace(r.holes()[0].points()) < 0.0);
}

#[test]
fn either_orientation_is_normalised() {
    // Outer clockwise and hole counter-clockwise (the reverse of RFC 7946's recommendation).
    let cw = r#"{"type": "Polygon", "coordinates": [
        [[0, 0], [0, 4], [4, 4], [4, 0], [0, 0]],
        [[1, 1], [2, 1], [2, 2], [1, 2], [1, 1]]
    ]}"#;
    let a = parse_region_geojson(cw, PartSelector::Largest).unwrap();
    let b = parse_region_geojson(SQUARE_WITH_HOLE, PartSelector::Largest).unwrap();
    for r in [&a, &b] {
        assert_eq!(shoelace(r.outer().points()), 16.0);
        assert_eq!(shoelace(r.holes()[0].points()), -1.0);
    }
    let mut pa: Vec<(f64, f64)> = a.outer().points().iter().map(|p| (p.x, p.y)).collect();
    let mut pb: Vec<(f64, f64)> = b.outer().points().iter().map(|p| (p.x, p.y)).collect();
    pa.sort_by(|x, y| x.partial_cmp(y).unwrap());
    pb.sort_by(|x, y| x.partial_cmp(y).unwrap());
    assert_eq!(pa, pb);

    // An unclosed ring (tolerated) with 4 positions.
    let open = r#"{"type": "Polygon", "coordinates": [[[0, 0], [3, 0], [3, 1], [0, 1]]]}"#;
    let r = parse_region_geojson(open, PartSelector::Largest).unwrap();
    assert_eq!(r.outer().points().len(), 4);
    assert_eq!(r.area(), 3.0);
}

/// Parts: 0 = unit square (outer area 1), 1 = 3 × 3 square with a 2 × 2 hole (outer area 9,
/// net area 5), 2 = 2 × 3 rectangle (area 6). "Largest" compares outer-ring areas → part 1.
const MULTI: &str = r#"{"type": "MultiPolygon", "coordinates": [
    [[[10, 10], [11, 10], [11, 11], [10, 11], [10, 10]]],
    [[[0, 0], [3, 0], [3, 3], [0, 3], [0, 0]],
     [[0.5, 0.5], [0.5, 2.5], [2.5, 2.5], [2.5, 0.5], [0.5, 0.5]]],
    [[[20, 0], [22, 0], [22, 3], [20, 3], [20, 0]]]
]}"#;

#[test]
fn multipolygon_part_selection() {
    let r = parse_region_geojson(MULTI, PartSelector::default()).unwrap();
    assert_eq!(r.outer().area(), 9.0);
    assert_eq!(r.area(), 5.0);
    assert_eq!(r.holes().len(), 1);

    let r = parse_region_geojson(MULTI, PartSelector::Index(2)).unwrap();
    assert_eq!(r.area(), 6.0);
    assert!(r.holes().is_empty());
    let r = parse_region_geojson(MULTI, PartSelector::Index(0)).unwrap();
    assert_eq!(r.area(), 1.0);

    let e = parse_region_geojson(MULTI, PartSelector::Index(3)).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::PartOutOfRange {
                index: 3,
                parts: 3,
                ..
            }
        ),
        "{e:?}"
    );

    let parts = parse_polygon_parts(MULTI).unwrap();
    assert_eq!(parts.len(), 3);
    assert_eq!(
        parts.iter().map(|p| p.part).collect::<Vec<_>>(),
        vec![0, 1, 2]
    );
    assert_eq!(parts[1].json_path, "$.coordinates[1]");
    assert_eq!(parts[1].num_vertices(), 8);
    let raw = parse_region_rings(MULTI, PartSelector::Largest).unwrap();
    assert_eq!(raw.part, 1);
    assert_eq!(
        raw.outer,
        pts(&[(0.0, 0.0), (3.0, 0.0), (3.0, 3.0), (0.0, 3.0)])
    );
}

#[test]
fn feature_and_feature_collection() {
    let feature = format!(
        r#"{{"type": "Feature", "properties": {{"name": "x"}}, "geometry": {SQUARE_WITH_HOLE}}}"#
    );
    let r = parse_region_geojson(&feature, PartSelector::Largest).unwrap();
    assert_eq!(r.area(), 15.0);

    // The union of the parts of all features (a point feature is skipped, a null geometry has
    // no parts): parts = [square-with-hole (outer 16), MULTI's three parts (1, 9, 6)].
    let fc = format!(
        r#"{{"type": "FeatureCollection", "features": [
            {{"type": "Feature", "properties": {{}}, "geometry": {{"type": "Point", "coordinates": [1, 2]}}}},
            {feature},
            {{"type": "Feature", "properties": null, "geometry": null}},
            {{"type": "Feature", "geometry": {MULTI}}}
        ]}}"#
    );
    let parts = parse_polygon_parts(&fc).unwrap();
    assert_eq!(parts.len(), 4);
    assert_eq!(parts[0].json_path, "$.features[1].geometry.coordinates");
    assert_eq!(parts[3].json_path, "$.features[3].geometry.coordinates[2]");
    let r = parse_region_geojson(&fc, PartSelector::Largest).unwrap();
    assert_eq!(r.area(), 15.0);
    let r = parse_region_geojson(&fc, PartSelector::Index(3)).unwrap();
    assert_eq!(r.area(), 6.0);

    // Only non-polygonal features: a clear error listing what was found.
    let e = parse_region_geojson(
        r#"{"type": "FeatureCollection", "features": [
            {"type": "Feature", "geometry": {"type": "LineString", "coordinates": [[0, 0], [1, 1]]}}]}"#,
        PartSelector::Largest,
    )
    .unwrap_err();
    assert!(
        matches!(e, IoError::NoPolygon { ref found, .. } if found == &["LineString"]),
        "{e:?}"
    );
    assert!(e.to_string().contains("LineString"), "{e}");
}

#[test]
fn third_coordinate_is_ignored() {
    let text = r#"{"type": "Polygon", "coordinates": [[[0, 0, 5], [2, 0, 6.5], [2, 1, -3], [0, 1, 0], [0, 0, 5]]]}"#;
    let r = parse_region_geojson(text, PartSelector::Largest).unwrap();
    assert_eq!(r.area(), 2.0);
    assert!(r.outer().points().contains(&DVec2::new(2.0, 1.0)));
}

#[test]
fn malformed_json_reports_line_and_column() {
    let text = "{\"type\": \"Polygon\",\n \"coordinates\": [[[0, 0], [1, 0],\n [1, 1] [0, 0]]]}";
    let e = parse_region_geojson(text, PartSelector::Largest).unwrap_err();
    assert!(matches!(e, IoError::Json { line: 3, .. }), "{e:?}");
    assert_eq!(e.line(), Some(3));
    assert!(e.to_string().starts_with("<string>:3:"), "{e}");

    let dir = Scratch::new("badjson");
    let p = dir.path("bad.geojson");
    std::fs::write(&p, "{\n\n  \"type\": \"Polygon\",\n  oops\n}").unwrap();
    let e = read_region_geojson(&p, PartSelector::Largest).unwrap_err();
    match &e {
        IoError::Json { path, line, .. } => {
            assert_eq!(path, &p);
            assert_eq!(*line, 4);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn wrong_geometry_type_and_bad_content() {
    let e = parse_region_geojson(
        r#"{"type": "LineString", "coordinates": [[0, 0], [1, 1]]}"#,
        PartSelector::Largest,
    )
    .unwrap_err();
    assert!(
        matches!(e, IoError::WrongGeometryType { ref found, ref json_path, .. } if found == "LineString" && json_path == "$"),
        "{e:?}"
    );
    let e = parse_region_geojson(
        r#"{"type": "Feature", "geometry": {"type": "Point", "coordinates": [0, 0]}}"#,
        PartSelector::Largest,
    )
    .unwrap_err();
    assert!(
        matches!(e, IoError::WrongGeometryType { ref json_path, .. } if json_path == "$.geometry"),
        "{e:?}"
    );
    // Ring with 3 positions (a closed "digon").
    let e = parse_region_geojson(
        r#"{"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [0, 0]]]}"#,
        PartSelector::Largest,
    )
    .unwrap_err();
    assert!(
        matches!(e, IoError::RingTooShort { positions: 3, ref json_path, .. } if json_path == "$.coordinates[0]"),
        "{e:?}"
    );
    // Non-numeric coordinate.
    let e = parse_region_geojson(
        r#"{"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, "1"], [0, 0]]]}"#,
        PartSelector::Largest,
    )
    .unwrap_err();
    assert_eq!(e.json_path(), Some("$.coordinates[0][2][1]"), "{e:?}");
    assert!(matches!(e, IoError::BadCoordinate { .. }));
    // A position with one number.
    let e = parse_region_geojson(
        r#"{"type": "Polygon", "coordinates": [[[0, 0], [1], [1, 1], [0, 0]]]}"#,
        PartSelector::Largest,
    )
    .unwrap_err();
    assert!(
        matches!(e, IoError::BadCoordinate { .. }) && e.json_path() == Some("$.coordinates[0][1]"),
        "{e:?}"
    );
    // Missing coordinates, missing type, not an object.
    let e = parse_region_geojson(r#"{"type": "Polygon"}"#, PartSelector::Largest).unwrap_err();
    assert!(
        matches!(e, IoError::MissingMember { .. }) && e.to_string().contains("coordinates"),
        "{e}"
    );
    let e = parse_region_geojson(r#"{"coordinates": []}"#, PartSelector::Largest).unwrap_err();
    assert!(
        matches!(e, IoError::MissingMember { .. }) && e.to_string().contains("type"),
        "{e}"
    );
    let e = parse_region_geojson("[1, 2]", PartSelector::Largest).unwrap_err();
    assert!(matches!(e, IoError::MissingMember { .. }), "{e:?}");
    // Empty MultiPolygon, empty Polygon.
    let e = parse_region_geojson(
        r#"{"type": "MultiPolygon", "coordinates": []}"#,
        PartSelector::Largest,
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            IoError::EmptyGeometry {
                what: "MultiPolygon",
                ..
            }
        ),
        "{e:?}"
    );
    let e = parse_region_geojson(
        r#"{"type": "Polygon", "coordinates": []}"#,
        PartSelector::Largest,
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            IoError::EmptyGeometry {
                what: "Polygon",
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn invalid_region_is_a_geometry_error_and_cleaning_is_opt_in() {
    // Bow tie: edges 0 (0,0)-(2,2) and 2 (2,0)-(0,2) cross.
    let e = parse_region_geojson(
        r#"{"type": "Polygon", "coordinates": [[[0, 0], [2, 2], [2, 0], [0, 2], [0, 0]]]}"#,
        PartSelector::Largest,
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            IoError::Geometry {
                part: 0,
                source: GeometryError::SelfIntersection {
                    ring: RingId::Outer,
                    ..
                },
                ..
            }
        ),
        "{e:?}"
    );

    let dup =
        r#"{"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, 0], [1, 1], [0, 1], [0, 0]]]}"#;
    let e = parse_region_geojson(dup, PartSelector::Largest).unwrap_err();
    assert!(
        matches!(
            e,
            IoError::Geometry {
                source: GeometryError::RepeatedPoint { vertex: 2, .. },
                ..
            }
        ),
        "{e:?}"
    );
    let dir = Scratch::new("dup");
    let p = dir.path("dup.geojson");
    std::fs::write(&p, dup).unwrap();
    let (r, removed) = read_region_geojson_cleaned(&p, PartSelector::Largest).unwrap();
    assert_eq!(removed, 1);
    assert_eq!(r.area(), 1.0);
    assert_eq!(r.outer().points().len(), 4);
    let (r2, removed2) = parse_region_geojson_cleaned(dup, PartSelector::Largest).unwrap();
    assert_eq!((r2, removed2), (r, 1));
}

/// No panic on any prefix of a valid document (all are errors except the full text).
#[test]
fn no_panic_on_truncated_json() {
    for text in [SQUARE_WITH_HOLE, MULTI] {
        for cut in 0..text.len() {
            assert!(parse_region_geojson(&text[..cut], PartSelector::Largest).is_err());
        }
        assert!(parse_region_geojson(text, PartSelector::Largest).is_ok());
    }
}

#[test]
fn every_fixture_region_loads() {
    // (file, total vertices over all rings without closing points, holes), counted from the GeoJSON
    // text by a separate script (largest polygon by shoelace area, closing point dropped).
    let expected: [(&str, usize, usize); 34] = [
        ("adriatic-sea", 1922, 10),
        ("california", 312, 0),
        ("caribbean-greater-antilles", 3606, 11),
        ("chesapeake-bay", 1546, 4),
        ("colorado", 40, 0),
        ("cow", 91, 2),
        ("crete", 387, 0),
        ("crow", 52, 1),
        ("danish-straits", 1958, 9),
        ("dragon", 57, 1),
        ("fish", 43, 1),
        ("florida", 353, 0),
        ("guerrero", 189, 1),
        ("gulf-of-finland", 952, 9),
        ("gulf-of-mexico", 5325, 9),
        ("gulf-of-st-lawrence", 3383, 9),
        ("hippo", 118, 4),
        ("hokkaido", 625, 0),
        ("horse", 74, 1),
        ("java", 893, 0),
        ("kiwi-bird", 53, 1),
        ("maryland", 260, 0),
        ("newfoundland", 3160, 0),
        ("norway-mainland", 7896, 0),
        ("oaxaca", 207, 0),
        ("puget-sound", 755, 6),
        ("quintana-roo", 213, 0),
        ("sakhalin", 1030, 0),
        ("sinaloa", 303, 0),
        ("south-africa", 2163, 1),
        ("tamaulipas", 371, 0),
        ("texas", 678, 0),
        ("tyrrhenian-sea", 1819, 7),
        ("visayan-seas", 1542, 17),
    ];
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/regions");
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("geojson") {
            continue;
        }
        let stem = path.file_stem().unwrap().to_str().unwrap().to_string();
        let region = read_region_geojson(&path, PartSelector::Largest)
            .unwrap_or_else(|e| panic!("{stem}: {e}"));
        let &(_, verts, holes) = expected
            .iter()
            .find(|(n, _, _)| *n == stem)
            .unwrap_or_else(|| panic!("no expected counts for fixture {stem}"));
        assert_eq!(region.num_vertices(), verts, "{stem}: vertices");
        assert_eq!(region.holes().len(), holes, "{stem}: holes");
        assert!(shoelace(region.outer().points()) > 0.0, "{stem}: outer CCW");
        for h in region.holes() {
            assert!(shoelace(h.points()) < 0.0, "{stem}: holes CW");
        }
        assert!(region.area() > 0.0);
        seen += 1;
    }
    assert_eq!(seen, expected.len(), "every listed fixture was found");
}
