//! Our `.shp` reader against pyshp (an independent pure-Python reader and writer, PyPI
//! `pyshp` 3.1.6): the files in `tests/data/pyshp/` were written by pyshp and
//! `scripts/shp_pyshp_sample.py` recorded, next to each, how pyshp reads it back (points and
//! part indices as `repr` strings, which round-trip every `f64`, and pyshp's grouping of rings
//! into polygons). Regenerate with `python3 scripts/shp_pyshp_sample.py`. The test itself needs
//! no Python.
//!
//! Checked for `Polygon`, `PolygonZ` and `PolygonM` files (a null shape in between): every ring
//! we return is bit for bit the ring pyshp returns (split at pyshp's part indices, closing
//! position dropped), and per shape we find as many parts as pyshp finds polygons, with the
//! same number of holes and the same outer ring sizes.

use std::path::PathBuf;

use serde_json::Value;
use unamalla_io::{read_region_shapefile, read_shapefile_parts, PartSelector};
use unamalla_mesh::DVec2;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/pyshp")
        .join(name)
}

fn num(v: &Value) -> f64 {
    v.as_str().unwrap().parse().unwrap()
}

fn bits(r: &[DVec2]) -> Vec<[u64; 2]> {
    r.iter().map(|p| [p.x.to_bits(), p.y.to_bits()]).collect()
}

fn compare(name: &str) {
    let parts = read_shapefile_parts(data(&format!("{name}.shp"))).unwrap();
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(data(&format!("{name}.json"))).unwrap())
            .unwrap();
    let shapes = json["shapes"].as_array().unwrap();
    assert_eq!(shapes.len(), 4, "{name}: the sample has 4 shapes");
    let mut polygons_seen = 0;
    for (s, shape) in shapes.iter().enumerate() {
        let ours: Vec<_> = parts
            .iter()
            .filter(|p| p.json_path == format!("shape {s}"))
            .collect();
        let Some(polys) = shape.get("polygons").and_then(Value::as_array) else {
            assert_eq!(shape["shape_type"], 0, "{name}: shape {s}");
            assert!(ours.is_empty(), "{name}: null shape {s} gives no part");
            continue;
        };
        // pyshp's rings: points split at its part indices, closing point dropped
        let points: Vec<DVec2> = shape["points"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| DVec2::new(num(&p[0]), num(&p[1])))
            .collect();
        let starts: Vec<usize> = shape["parts"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap() as usize)
            .collect();
        let mut theirs: Vec<Vec<[u64; 2]>> = (0..starts.len())
            .map(|k| {
                let end = starts.get(k + 1).copied().unwrap_or(points.len());
                let mut r = points[starts[k]..end].to_vec();
                assert_eq!(r.first(), r.last(), "pyshp rings are closed");
                r.pop();
                bits(&r)
            })
            .collect();
        let mut mine: Vec<Vec<[u64; 2]>> = ours
            .iter()
            .flat_map(|p| std::iter::once(&p.outer).chain(&p.holes))
            .map(|r| bits(r))
            .collect();
        theirs.sort();
        mine.sort();
        assert_eq!(mine, theirs, "{name}: rings of shape {s}");
        assert_eq!(ours.len(), polys.len(), "{name}: parts of shape {s}");
        for (p, poly) in ours.iter().zip(polys) {
            assert_eq!(p.holes.len() as u64, poly["holes"].as_u64().unwrap());
            // pyshp's GeoJSON rings are closed
            assert_eq!(
                p.outer.len() as u64 + 1,
                poly["outer_len"].as_u64().unwrap()
            );
        }
        polygons_seen += polys.len();
    }
    // lake (with its island), two islands, the 64-gon
    assert_eq!(polygons_seen, 4, "{name}");
    assert_eq!(parts.len(), 4, "{name}");
}

#[test]
fn polygon_file_matches_pyshp() {
    compare("polygon");
}

#[test]
fn polygonz_file_matches_pyshp() {
    compare("polygonz");
}

#[test]
fn polygonm_file_matches_pyshp() {
    compare("polygonm");
}

/// The largest part is the projected lake (≈1.2 km², far from the origin) with its island;
/// it validates as a region. Area by the shoelace formula on the sample's coordinates (offsets
/// from (e0, n0) = (512345.25, 4123456.75), exact in binary): lake (0,0), (0,900.5),
/// (1200.125,1000), (1300,−50) has |A| = ½·|Σ x_k y_{k+1} − x_{k+1} y_k|
/// = ½·|0 + (0·1000 − 1200.125·900.5) + (1200.125·(−50) − 1300·1000) + 0|
/// = ½·(1080712.5625 + 60006.25 + 1300000) = 1220359.40625; island (0,0), (200,0), (100,150)
/// relative to (e0 + 400, n0 + 300): ½·200·150 = 15000. Region area = 1205359.40625.
#[test]
fn largest_part_is_the_lake_with_its_island() {
    let r = read_region_shapefile(data("polygon.shp"), PartSelector::Largest).unwrap();
    assert_eq!(r.holes().len(), 1);
    let area = r.area();
    assert!(
        (area - 1_205_359.406_25).abs() < 1e-6,
        "area {area} (ring sums far from the origin lose a few ulps)"
    );
}
