//! One entry point for region files of every format this crate reads, with feature selection,
//! boundary names and the coordinate system settled ([`load_region`]).
//!
//! | extension | reader | names | CRS evidence |
//! |---|---|---|---|
//! | `.geojson`, `.json` | [`crate::geojson`] | [`crate::patches`] convention | RFC 7946 lon/lat unless `units`/`crs` declared |
//! | `.shp` (+ `.dbf`, `.prj`) | [`crate::shp`] | – | `.prj` with `GEOGCS` and no `PROJCS`: lon/lat |
//! | `.con` | [`crate::legacy`] | – | none |
//! | anything else | [`crate::rings`] (plain text) | – | none |
//!
//! **Feature selection** (`feature = "KEY=VALUE"`): the GeoJSON feature whose
//! `properties.KEY` equals `VALUE` (a string, or a number written the same), or the shapefile
//! record whose `.dbf` attribute `KEY` equals `VALUE` (trailing blanks ignored); of that
//! feature's polygons the largest is used. Without it the largest polygon of the file is used.

use std::path::Path;

use serde_json::Value;
use unamalla_mesh::Region;

use crate::error::IoError;
use crate::geo::{looks_geographic, CrsChoice, LocalProjection};
use crate::geojson::{
    parse_parts_at, read_text, select_part, PartSelector, PolygonRings, RegionAnnotations,
};
use crate::patches::BoundaryNames;

/// How to read a region file.
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct LoadOptions {
    /// `KEY=VALUE` feature selector (see the module docs).
    pub feature: Option<String>,
    /// Coordinate system choice.
    pub crs: CrsChoice,
}

impl LoadOptions {
    /// Sets [`feature`](Self::feature): `KEY=VALUE` feature selector (see the module docs).
    #[must_use]
    pub fn feature(mut self, feature: Option<String>) -> Self {
        self.feature = feature;
        self
    }

    /// Sets [`crs`](Self::crs): coordinate system choice.
    #[must_use]
    pub fn crs(mut self, crs: CrsChoice) -> Self {
        self.crs = crs;
        self
    }
}

/// A region read by [`load_region`], in the coordinates the mesher works in.
#[derive(Debug)]
pub struct LoadedRegion {
    /// The region (projected to km when the input was geographic or had a `--crs`).
    pub region: Region,
    /// Boundary names, stretches in the same coordinates as `region`.
    pub names: BoundaryNames,
    /// The projection applied, if any (its inverse back-projects mesh nodes to lon/lat).
    pub projection: Option<LocalProjection>,
    /// Consecutive repeated points removed while reading.
    pub removed_points: usize,
    /// Messages for the user (which CRS was assumed and why; what to pass to change it).
    pub notes: Vec<String>,
    /// Set when the coordinates look geographic but are meshed as planar without the user
    /// having chosen so: the caller should show it as a warning.
    pub warning: Option<String>,
}

fn parse_selector(sel: &str) -> Result<(&str, &str), IoError> {
    sel.split_once('=')
        .map(|(k, v)| (k.trim(), v.trim()))
        .filter(|(k, _)| !k.is_empty())
        .ok_or_else(|| IoError::FeatureNotFound {
            selector: sel.to_string(),
            reason: "expected KEY=VALUE".into(),
        })
}

fn value_matches(v: &Value, want: &str) -> bool {
    match v {
        Value::String(s) => s == want,
        Value::Number(n) => n.to_string() == want,
        Value::Bool(b) => b.to_string() == want,
        _ => false,
    }
}

/// The largest part among those for which `keep(json_path)` holds.
fn largest_of(
    parts: Vec<PolygonRings>,
    keep: impl Fn(&str) -> bool,
    path: &Path,
    sel: &str,
) -> Result<PolygonRings, IoError> {
    let chosen: Vec<PolygonRings> = parts.into_iter().filter(|p| keep(&p.json_path)).collect();
    if chosen.is_empty() {
        return Err(IoError::FeatureNotFound {
            selector: sel.to_string(),
            reason: format!("no polygon of {} has that attribute", path.display()),
        });
    }
    select_part(chosen, PartSelector::Largest, path)
}

fn to_region(rings: PolygonRings, path: &Path) -> Result<(Region, usize), IoError> {
    let PolygonRings {
        outer,
        holes,
        json_path,
        part,
    } = rings;
    Region::new_cleaned(outer, holes).map_err(|source| IoError::Geometry {
        path: path.to_path_buf(),
        json_path,
        part,
        source,
    })
}

/// Reads the region file `path` of any supported format (see the module docs) and settles its
/// coordinate system:
///
/// * [`CrsChoice::Planar`]: as given;
/// * [`CrsChoice::LonLat`] or [`CrsChoice::Proj`]: projected to the local transverse Mercator
///   (km, [`crate::geo`]);
/// * [`CrsChoice::Auto`]: projected when the file says lon/lat (GeoJSON without declared units
///   whose coordinates are in the lon/lat range; a shapefile whose `.prj` is geographic), else
///   as given — with [`LoadedRegion::warning`] set when the coordinates nevertheless look
///   geographic.
pub fn load_region(path: impl AsRef<Path>, opts: &LoadOptions) -> Result<LoadedRegion, IoError> {
    let path = path.as_ref();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let mut notes = Vec::new();
    let (region, removed, ann, geographic_evidence) = match ext.as_str() {
        "geojson" | "json" => {
            let text = read_text(path)?;
            let parts = parse_parts_at(&text, path)?;
            let rings = match &opts.feature {
                None => select_part(parts, PartSelector::Largest, path)?,
                Some(sel) => {
                    let (key, want) = parse_selector(sel)?;
                    let value: Value = serde_json::from_str(&text).map_err(|e| IoError::Json {
                        path: path.to_path_buf(),
                        line: e.line(),
                        column: e.column(),
                        message: e.to_string(),
                    })?;
                    let feats = value["features"].as_array().cloned().unwrap_or_default();
                    let hits: Vec<String> = feats
                        .iter()
                        .enumerate()
                        .filter(|(_, f)| {
                            f.get("properties")
                                .and_then(|p| p.get(key))
                                .is_some_and(|v| value_matches(v, want))
                        })
                        .map(|(k, _)| format!("$.features[{k}]."))
                        .collect();
                    largest_of(
                        parts,
                        |jp| hits.iter().any(|h| jp.starts_with(h.as_str())),
                        path,
                        sel,
                    )?
                }
            };
            let value: Value = serde_json::from_str(&text).map_err(|e| IoError::Json {
                path: path.to_path_buf(),
                line: e.line(),
                column: e.column(),
                message: e.to_string(),
            })?;
            let ann = crate::geojson::annotations_of(&value, &rings.json_path, path)?;
            let (r, removed) = to_region(rings, path)?;
            let evidence = !ann.declares_planar() && looks_geographic(&r);
            if evidence {
                notes.push(
                    "GeoJSON coordinates in the longitude/latitude range and no units declared: \
                     read as WGS84 lon/lat (RFC 7946)"
                        .to_string(),
                );
            }
            (r, removed, ann, evidence)
        }
        "shp" => {
            let parts = crate::shp::read_shapefile_parts(path)?;
            let rings = match &opts.feature {
                None => select_part(parts, PartSelector::Largest, path)?,
                Some(sel) => {
                    let (key, want) = parse_selector(sel)?;
                    let dbf = path.with_extension("dbf");
                    let records = crate::dbf::read_dbf(&dbf)?;
                    let hits: Vec<String> = records
                        .iter()
                        .enumerate()
                        .filter(|(_, r)| r.iter().any(|(k, v)| k == key && v == want))
                        .map(|(k, _)| format!("shape {k}"))
                        .collect();
                    largest_of(parts, |jp| hits.iter().any(|h| h == jp), path, sel)?
                }
            };
            let prj = std::fs::read_to_string(path.with_extension("prj")).ok();
            let evidence = prj
                .as_deref()
                .is_some_and(|p| p.contains("GEOGCS") && !p.contains("PROJCS"));
            if evidence {
                notes.push("the .prj file describes a geographic CRS: read as lon/lat".into());
            }
            let (r, removed) = to_region(rings, path)?;
            (r, removed, RegionAnnotations::default(), evidence)
        }
        "con" => {
            no_feature(opts, path)?;
            let r = crate::legacy::read_region_con(path)?;
            (r, 0, RegionAnnotations::default(), false)
        }
        _ => {
            no_feature(opts, path)?;
            let r = crate::rings::read_region_text(path)?;
            (r, 0, RegionAnnotations::default(), false)
        }
    };
    let projection = match &opts.crs {
        CrsChoice::Planar => None,
        CrsChoice::LonLat => Some(LocalProjection::for_lonlat_region(&region)?),
        CrsChoice::Proj(s) => Some(LocalProjection::for_source_crs(s, &region)?),
        CrsChoice::Auto if geographic_evidence => {
            Some(LocalProjection::for_lonlat_region(&region)?)
        }
        CrsChoice::Auto => None,
    };
    let mut warning = None;
    if projection.is_none() && opts.crs == CrsChoice::Auto && looks_geographic(&region) {
        warning = Some(format!(
            "{}: the coordinates look like longitude/latitude (all within ±180, ±90) but the \
             file does not say so; meshing them as planar units. Pass --crs lonlat to mesh in \
             kilometres (transverse Mercator) or --crs planar to silence this",
            path.display()
        ));
    }
    let (region, names) = match &projection {
        Some(p) => {
            let (lon0, lat0) = p.centre();
            notes.push(format!(
                "projected to transverse Mercator (WGS84, k0 = 1) centred at lon {lon0:.4}, lat {lat0:.4}; lengths in km"
            ));
            let r = p.project_region(&region)?;
            let mut err = None;
            let names = ann.names.map_points(|q| match p.forward(q) {
                Ok(v) => v,
                Err(e) => {
                    err.get_or_insert(e);
                    q
                }
            });
            if let Some(e) = err {
                return Err(e);
            }
            (r, names)
        }
        None => (region, ann.names),
    };
    Ok(LoadedRegion {
        region,
        names,
        projection,
        removed_points: removed,
        notes,
        warning,
    })
}

fn no_feature(opts: &LoadOptions, path: &Path) -> Result<(), IoError> {
    match &opts.feature {
        Some(sel) => Err(IoError::FeatureNotFound {
            selector: sel.clone(),
            reason: format!(
                "{} holds one region; --feature applies to GeoJSON and Shapefile input",
                path.display()
            ),
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn tmp(name: &str, text: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("unamalla-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    const LONLAT: &str = r#"{"type":"FeatureCollection","features":[
      {"type":"Feature","properties":{"name":"a"},"geometry":{"type":"Polygon","coordinates":
        [[[10.0,60.0],[10.1,60.0],[10.1,60.05],[10.0,60.05],[10.0,60.0]]]}},
      {"type":"Feature","properties":{"name":"b"},"geometry":{"type":"Polygon","coordinates":
        [[[0,0],[1,0],[1,1],[0,1],[0,0]]]}}]}"#;

    #[test]
    fn lonlat_geojson_is_projected_to_km() {
        let p = tmp("ll.geojson", LONLAT);
        let opts = LoadOptions {
            feature: Some("name=a".into()),
            ..Default::default()
        };
        let l = load_region(&p, &opts).unwrap();
        assert!(l.projection.is_some() && l.warning.is_none());
        // 0.1° of longitude at 60° ≈ 5.58 km, 0.05° of latitude ≈ 5.57 km
        let (lo, hi) = l.region.bounding_box();
        let d = hi - lo;
        assert!(
            (d.x - 5.58).abs() < 0.02 && (d.y - 5.57).abs() < 0.02,
            "{d}"
        );
        // planar on request: no projection, no warning
        let planar = load_region(
            &p,
            &LoadOptions {
                feature: Some("name=a".into()),
                crs: CrsChoice::Planar,
            },
        )
        .unwrap();
        assert!(planar.projection.is_none() && planar.warning.is_none());
    }

    #[test]
    fn geographic_looking_text_warns() {
        let p = tmp("r.txt", "0 0\n1 0\n1 1\n0 1\n");
        let l = load_region(&p, &LoadOptions::default()).unwrap();
        assert!(l.projection.is_none());
        assert!(l.warning.unwrap().contains("--crs lonlat"));
        let e = load_region(
            &p,
            &LoadOptions {
                feature: Some("name=x".into()),
                ..Default::default()
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("--feature"), "{e}");
    }

    #[test]
    fn a_missing_feature_is_an_error_naming_the_selector() {
        let p = tmp("ll2.geojson", LONLAT);
        let e = load_region(
            &p,
            &LoadOptions {
                feature: Some("name=zzz".into()),
                ..Default::default()
            },
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("name=zzz"), "{e}");
    }

    #[test]
    fn shapefile_feature_by_attribute_and_geographic_prj() {
        let dir = std::env::temp_dir().join(format!("unamalla-input-shp-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let shp = dir.join("lake.shp");
        let sq = Region::new(
            vec![
                unamalla_mesh::DVec2::new(10.0, 60.0),
                unamalla_mesh::DVec2::new(10.1, 60.0),
                unamalla_mesh::DVec2::new(10.1, 60.05),
                unamalla_mesh::DVec2::new(10.0, 60.05),
            ],
            vec![],
        )
        .unwrap();
        crate::shp::write_region_shapefile(&shp, &sq).unwrap();
        std::fs::write(
            dir.join("lake.dbf"),
            crate::dbf::tests::encode(&[("NAME", 8)], &[vec!["Mjosa"]]),
        )
        .unwrap();
        std::fs::write(
            dir.join("lake.prj"),
            r#"GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984"]]"#,
        )
        .unwrap();
        let opts = |f: &str| LoadOptions {
            feature: Some(f.into()),
            ..Default::default()
        };
        let l = load_region(&shp, &opts("NAME=Mjosa")).unwrap();
        assert!(l.projection.is_some(), "the .prj says lon/lat");
        assert!(
            (l.region.area() - 5.58 * 5.57).abs() < 0.3,
            "{}",
            l.region.area()
        );
        let e = load_region(&shp, &opts("NAME=Tyrifjorden")).unwrap_err();
        assert!(e.to_string().contains("Tyrifjorden"));
    }
}
