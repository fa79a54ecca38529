//! Region loader shared by the contour examples: one Polygon (or, for a MultiPolygon, its part
//! with the most vertices) of a GeoJSON file, parsed with `serde_json` to stay independent of
//! `unamalla-io`.

use std::path::{Path, PathBuf};

use unamalla_mesh::{DVec2, Region};

/// Loads the region of `path` (see the module docs).
pub fn load(path: &Path) -> Result<Region, String> {
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    let json: serde_json::Value = serde_json::from_str(&text).map_err(|e| e.to_string())?;
    let geom = match json["type"].as_str() {
        Some("FeatureCollection") => &json["features"][0]["geometry"],
        Some("Feature") => &json["geometry"],
        _ => &json,
    };
    let polygon = match geom["type"].as_str() {
        Some("Polygon") => &geom["coordinates"],
        Some("MultiPolygon") => geom["coordinates"]
            .as_array()
            .and_then(|parts| {
                parts.iter().max_by_key(|p| {
                    p.as_array()
                        .and_then(|r| r.first())
                        .and_then(|r| r.as_array())
                        .map_or(0, |r| r.len())
                })
            })
            .ok_or("empty MultiPolygon")?,
        _ => return Err(format!("{}: not a Polygon", path.display())),
    };
    let rings: Vec<Vec<DVec2>> = polygon
        .as_array()
        .ok_or("no coordinates")?
        .iter()
        .map(|ring| {
            ring.as_array()
                .map(|pts| {
                    pts.iter()
                        .filter_map(|p| Some(DVec2::new(p[0].as_f64()?, p[1].as_f64()?)))
                        .collect()
                })
                .unwrap_or_default()
        })
        .collect();
    let mut it = rings.into_iter();
    let outer = it.next().ok_or("empty polygon")?;
    Region::new_cleaned(outer, it.collect())
        .map(|(r, _)| r)
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// The `*.geojson` files of the directory given as the first argument (default
/// `fixtures/regions`), sorted by name.
pub fn region_files() -> Vec<PathBuf> {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../fixtures/regions"
            ))
        });
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "geojson"))
        .collect();
    files.sort();
    files
}
