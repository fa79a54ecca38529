//! Reading planar regions from GeoJSON (RFC 7946).
//!
//! # What is accepted
//!
//! * A bare geometry `Polygon`, `MultiPolygon` or `GeometryCollection`, a `Feature`, or a
//!   `FeatureCollection`.
//! * Every polygon found in the document is a **part**; parts are numbered 0, 1, … in document
//!   order (features in order, the polygons of a `MultiPolygon` in order). A `FeatureCollection`
//!   contributes the **union of the polygonal parts of all its features**; the
//!   [`PartSelector`] then picks one part (by default the one whose outer ring has the largest
//!   area). Non-polygonal geometries (points, line strings) *inside* a collection are skipped;
//!   a non-polygonal geometry at the top level or as the geometry of a top-level `Feature` is
//!   an error ([`IoError::WrongGeometryType`]). A `Feature` with a `null` geometry has no parts.
//! * In each polygon ring 0 is the exterior and the rest are holes; **either orientation** is
//!   accepted (the region constructor normalises to a counter-clockwise exterior and clockwise
//!   holes).
//! * Positions may have a third (elevation) component or more; only `x, y` are used.
//! * A ring needs at least 4 positions (RFC 7946). The closing position (equal to the first) is
//!   dropped, so rings come out **open**; a ring that is not closed is tolerated and used as is.
//!
//! Vertex indices in [`GeometryError`](unamalla_mesh::GeometryError)s of the selected part
//! are 0-based position indices in the ring as written in the file.
//!
//! Errors carry the file path and the JSON path of the offending value (or the line and column
//! for malformed JSON). Nothing in this module panics on any input.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::Value;
use unamalla_mesh::region::signed_area;
use unamalla_mesh::{DVec2, Region};

use crate::error::IoError;

/// Which polygonal part of a GeoJSON document becomes the region.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum PartSelector {
    /// The part whose outer ring encloses the largest area (the first one on ties).
    #[default]
    Largest,
    /// The part with this 0-based index, in document order.
    Index(usize),
}

/// The rings of one polygonal part as read from the file, before region validation.
#[derive(Debug, Clone, PartialEq)]
pub struct PolygonRings {
    /// The exterior ring, open (closing position dropped), orientation as in the file.
    pub outer: Vec<DVec2>,
    /// The holes, open, orientation as in the file.
    pub holes: Vec<Vec<DVec2>>,
    /// JSON path of the polygon's coordinate array, e.g. `$.features[2].geometry.coordinates`.
    pub json_path: String,
    /// 0-based part index in document order.
    pub part: usize,
}

impl PolygonRings {
    /// Area enclosed by the outer ring (absolute value of the shoelace formula), holes ignored.
    pub fn outer_area(&self) -> f64 {
        signed_area(&self.outer).abs()
    }

    /// Total number of vertices over all rings (closing positions not counted).
    pub fn num_vertices(&self) -> usize {
        self.outer.len() + self.holes.iter().map(Vec::len).sum::<usize>()
    }
}

/// Reads a region from a GeoJSON file: the selected polygonal part, validated by
/// [`Region::new`] (orientation normalised; repeated consecutive points are an error — see
/// [`read_region_geojson_cleaned`]).
pub fn read_region_geojson(path: impl AsRef<Path>, part: PartSelector) -> Result<Region, IoError> {
    let path = path.as_ref();
    let rings = read_region_rings(path, part)?;
    to_region(rings, path, false).map(|(r, _)| r)
}

/// Like [`read_region_geojson`], for GeoJSON text held in memory (errors name `<string>`).
pub fn parse_region_geojson(text: &str, part: PartSelector) -> Result<Region, IoError> {
    let rings = parse_region_rings(text, part)?;
    to_region(rings, Path::new(STRING_SOURCE), false).map(|(r, _)| r)
}

/// Like [`read_region_geojson`], but consecutive repeated points are removed (with
/// [`Region::new_cleaned`]) instead of rejected; also returns how many were removed.
pub fn read_region_geojson_cleaned(
    path: impl AsRef<Path>,
    part: PartSelector,
) -> Result<(Region, usize), IoError> {
    let path = path.as_ref();
    let rings = read_region_rings(path, part)?;
    to_region(rings, path, true)
}

/// Like [`read_region_geojson_cleaned`], for GeoJSON text held in memory.
pub fn parse_region_geojson_cleaned(
    text: &str,
    part: PartSelector,
) -> Result<(Region, usize), IoError> {
    let rings = parse_region_rings(text, part)?;
    to_region(rings, Path::new(STRING_SOURCE), true)
}

fn to_region(rings: PolygonRings, path: &Path, clean: bool) -> Result<(Region, usize), IoError> {
    let PolygonRings {
        outer,
        holes,
        json_path,
        part,
    } = rings;
    let built = if clean {
        Region::new_cleaned(outer, holes)
    } else {
        Region::new(outer, holes).map(|r| (r, 0))
    };
    built.map_err(|source| IoError::Geometry {
        path: path.to_path_buf(),
        json_path,
        part,
        source,
    })
}

/// Path shown for inputs that were given as text rather than read from a file.
pub(crate) const STRING_SOURCE: &str = "<string>";

/// All polygonal parts of a GeoJSON document, in document order (see the module docs).
pub fn parse_polygon_parts(text: &str) -> Result<Vec<PolygonRings>, IoError> {
    parse_parts_at(text, Path::new(STRING_SOURCE))
}

/// Reads a GeoJSON file and returns the rings of the selected part, without validating them as
/// a region (use this to repair input, e.g. with `Region::new_cleaned`).
pub fn read_region_rings(
    path: impl AsRef<Path>,
    part: PartSelector,
) -> Result<PolygonRings, IoError> {
    let path = path.as_ref();
    let text = read_text(path)?;
    let parts = parse_parts_at(&text, path)?;
    select_part(parts, part, path)
}

/// Like [`read_region_rings`], for GeoJSON text held in memory.
pub fn parse_region_rings(text: &str, part: PartSelector) -> Result<PolygonRings, IoError> {
    let path = Path::new(STRING_SOURCE);
    let parts = parse_parts_at(text, path)?;
    select_part(parts, part, path)
}

pub(crate) fn read_text(path: &Path) -> Result<String, IoError> {
    std::fs::read_to_string(path).map_err(|source| IoError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Picks one part; `parts` must come from a successful parse (hence be non-empty), but an empty
/// list is handled too.
pub(crate) fn select_part(
    parts: Vec<PolygonRings>,
    part: PartSelector,
    path: &Path,
) -> Result<PolygonRings, IoError> {
    let count = parts.len();
    let index = match part {
        PartSelector::Index(k) => k,
        PartSelector::Largest => {
            let mut best: Option<(usize, f64)> = None;
            for (k, p) in parts.iter().enumerate() {
                let a = p.outer_area();
                if best.is_none_or(|(_, b)| a > b) {
                    best = Some((k, a));
                }
            }
            best.map(|(k, _)| k).unwrap_or(0)
        }
    };
    parts
        .into_iter()
        .nth(index)
        .ok_or_else(|| IoError::PartOutOfRange {
            path: path.to_path_buf(),
            index,
            parts: count,
        })
}

pub(crate) fn parse_parts_at(text: &str, path: &Path) -> Result<Vec<PolygonRings>, IoError> {
    let value: Value = serde_json::from_str(text).map_err(|e| IoError::Json {
        path: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message: strip_position(&e.to_string()),
    })?;
    let mut walker = Walker {
        path,
        parts: Vec::new(),
        skipped: Vec::new(),
    };
    walker.object(&value, "$".to_string(), false)?;
    if walker.parts.is_empty() {
        return Err(IoError::NoPolygon {
            path: path.to_path_buf(),
            found: walker.skipped,
        });
    }
    Ok(walker.parts)
}

/// serde_json appends " at line L column C" to its messages; the error carries those already.
fn strip_position(msg: &str) -> String {
    match msg.rfind(" at line ") {
        Some(k) => msg[..k].to_string(),
        None => msg.to_string(),
    }
}

struct Walker<'p> {
    path: &'p Path,
    parts: Vec<PolygonRings>,
    /// Types of non-polygonal geometries skipped inside collections.
    skipped: Vec<String>,
}

const EXPECTED_TOP: &str =
    "Polygon, MultiPolygon, GeometryCollection, Feature or FeatureCollection";

impl Walker<'_> {
    fn pb(&self) -> PathBuf {
        self.path.to_path_buf()
    }

    fn missing(&self, json_path: &str, problem: String) -> IoError {
        IoError::MissingMember {
            path: self.pb(),
            json_path: json_path.to_string(),
            problem,
        }
    }

    fn member<'v>(&self, obj: &'v Value, jp: &str, key: &str) -> Result<&'v Value, IoError> {
        obj.get(key)
            .ok_or_else(|| self.missing(jp, format!("missing member {key:?}")))
    }

    fn array<'v>(&self, v: &'v Value, jp: &str, what: &str) -> Result<&'v Vec<Value>, IoError> {
        v.as_array().ok_or_else(|| {
            self.missing(jp, format!("{what} must be an array, found {}", kind_of(v)))
        })
    }

    /// A GeoJSON object; `in_collection` is true inside a FeatureCollection or
    /// GeometryCollection, where non-polygonal geometries are skipped.
    fn object(&mut self, v: &Value, jp: String, in_collection: bool) -> Result<(), IoError> {
        if !v.is_object() {
            return Err(self.missing(
                &jp,
                format!("expected a GeoJSON object, found {}", kind_of(v)),
            ));
        }
        let ty = self.member(v, &jp, "type")?;
        let ty = ty.as_str().ok_or_else(|| {
            self.missing(
                &jp,
                format!("member \"type\" must be a string, found {}", kind_of(ty)),
            )
        })?;
        match ty {
            "Polygon" => {
                let cjp = format!("{jp}.coordinates");
                let coords = self.member(v, &jp, "coordinates")?;
                let p = self.polygon(coords, cjp)?;
                self.parts.push(p);
            }
            "MultiPolygon" => {
                let cjp = format!("{jp}.coordinates");
                let coords = self.member(v, &jp, "coordinates")?;
                let polys = self.array(coords, &cjp, "MultiPolygon coordinates")?;
                if polys.is_empty() {
                    return Err(IoError::EmptyGeometry {
                        path: self.pb(),
                        json_path: cjp,
                        what: "MultiPolygon",
                    });
                }
                for (k, poly) in polys.iter().enumerate() {
                    let p = self.polygon(poly, format!("{cjp}[{k}]"))?;
                    self.parts.push(p);
                }
            }
            "GeometryCollection" => {
                let gjp = format!("{jp}.geometries");
                let geoms = self.member(v, &jp, "geometries")?;
                let geoms = self.array(geoms, &gjp, "\"geometries\"")?;
                for (k, g) in geoms.iter().enumerate() {
                    self.object(g, format!("{gjp}[{k}]"), true)?;
                }
            }
            "Feature" => {
                let g = self.member(v, &jp, "geometry")?;
                if !g.is_null() {
                    self.object(g, format!("{jp}.geometry"), in_collection)?;
                }
            }
            "FeatureCollection" => {
                let fjp = format!("{jp}.features");
                let feats = self.member(v, &jp, "features")?;
                let feats = self.array(feats, &fjp, "\"features\"")?;
                for (k, f) in feats.iter().enumerate() {
                    self.object(f, format!("{fjp}[{k}]"), true)?;
                }
            }
            "Point" | "MultiPoint" | "LineString" | "MultiLineString" if in_collection => {
                self.skipped.push(ty.to_string());
            }
            other => {
                return Err(IoError::WrongGeometryType {
                    path: self.pb(),
                    json_path: jp,
                    found: other.to_string(),
                    expected: EXPECTED_TOP,
                })
            }
        }
        Ok(())
    }

    /// The coordinate array of one Polygon.
    fn polygon(&self, coords: &Value, jp: String) -> Result<PolygonRings, IoError> {
        let rings = self.array(coords, &jp, "Polygon coordinates")?;
        if rings.is_empty() {
            return Err(IoError::EmptyGeometry {
                path: self.pb(),
                json_path: jp,
                what: "Polygon",
            });
        }
        let mut out = Vec::with_capacity(rings.len());
        for (r, ring) in rings.iter().enumerate() {
            out.push(self.ring(ring, &format!("{jp}[{r}]"))?);
        }
        let mut it = out.into_iter();
        let outer = it.next().unwrap_or_default();
        Ok(PolygonRings {
            outer,
            holes: it.collect(),
            json_path: jp,
            part: self.parts.len(),
        })
    }

    fn ring(&self, ring: &Value, jp: &str) -> Result<Vec<DVec2>, IoError> {
        let positions = self.array(ring, jp, "a linear ring")?;
        if positions.len() < 4 {
            return Err(IoError::RingTooShort {
                path: self.pb(),
                json_path: jp.to_string(),
                positions: positions.len(),
            });
        }
        let mut pts = Vec::with_capacity(positions.len());
        for (k, pos) in positions.iter().enumerate() {
            pts.push(self.position(pos, &format!("{jp}[{k}]"))?);
        }
        if pts.len() > 1 && pts.first() == pts.last() {
            pts.pop();
        }
        Ok(pts)
    }

    fn position(&self, pos: &Value, jp: &str) -> Result<DVec2, IoError> {
        let bad = |problem: String| IoError::BadCoordinate {
            path: self.pb(),
            json_path: jp.to_string(),
            problem,
        };
        let arr = pos.as_array().ok_or_else(|| {
            bad(format!(
                "a position must be an array of numbers, found {}",
                kind_of(pos)
            ))
        })?;
        if arr.len() < 2 {
            return Err(bad(format!(
                "a position needs at least 2 numbers, found {}",
                arr.len()
            )));
        }
        let mut xy = [0.0; 2];
        for (c, slot) in xy.iter_mut().enumerate() {
            let v = &arr[c];
            *slot = v.as_f64().ok_or_else(|| IoError::BadCoordinate {
                path: self.pb(),
                json_path: format!("{jp}[{c}]"),
                problem: format!("coordinate must be a number, found {}", kind_of(v)),
            })?;
        }
        Ok(DVec2::new(xy[0], xy[1]))
    }
}

fn kind_of(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// The GeoJSON text of a region: one `Feature` with a `Polygon` geometry, ring 0 the exterior
/// (counter-clockwise), then the holes (clockwise), every ring closed (RFC 7946). Coordinates are
/// written with the shortest representation that reads back to the same `f64`.
pub fn region_to_geojson(region: &Region) -> String {
    let ring = |pts: &[DVec2]| -> String {
        let mut s = String::from("[");
        for p in pts.iter().chain(pts.first()) {
            if s.len() > 1 {
                s.push(',');
            }
            s.push_str(&format!("[{:?},{:?}]", p.x, p.y));
        }
        s.push(']');
        s
    };
    let rings: Vec<String> = region.rings().map(|r| ring(r.points())).collect();
    format!(
        "{{\"type\":\"Feature\",\"properties\":{{}},\"geometry\":{{\"type\":\"Polygon\",\"coordinates\":[{}]}}}}\n",
        rings.join(",")
    )
}

/// Writes [`region_to_geojson`] atomically.
pub fn write_region_geojson(path: impl AsRef<Path>, region: &Region) -> Result<(), IoError> {
    let text = region_to_geojson(region);
    crate::atomic::atomic_write(path.as_ref(), |w| w.write_all(text.as_bytes()))
}

#[cfg(test)]
mod write_tests {
    use super::*;

    #[test]
    fn written_region_reads_back_identically() {
        let outer = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(3.0, 0.1),
            DVec2::new(2.9, 2.0),
            DVec2::new(0.1, 1.0 / 3.0 + 1.0),
        ];
        let hole = vec![
            DVec2::new(1.0, 0.5),
            DVec2::new(1.5, 1.0),
            DVec2::new(2.0, 0.5),
        ];
        let r = Region::new(outer, vec![hole]).unwrap();
        let text = region_to_geojson(&r);
        let back = parse_region_geojson(&text, PartSelector::Largest).unwrap();
        assert_eq!(back, r);
    }
}

/// What a GeoJSON document says about its region besides the rings: boundary names
/// ([`crate::patches`] convention) and declared units or CRS ([`crate::geo`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RegionAnnotations {
    /// Patch names of the rings and named stretches.
    pub names: crate::patches::BoundaryNames,
    /// `properties.units` of the region's feature, if any (e.g. `"km"`: planar).
    pub units: Option<String>,
    /// The pre-RFC 7946 top-level `crs` member's name, if any.
    pub crs: Option<String>,
}

impl RegionAnnotations {
    /// Whether the document declares planar coordinates: `units` given, or a `crs` that is not
    /// CRS84 / EPSG:4326.
    pub fn declares_planar(&self) -> bool {
        self.units.is_some()
            || self.crs.as_deref().is_some_and(|c| {
                let c = c.to_ascii_uppercase();
                !(c.contains("CRS84") || c.ends_with("4326"))
            })
    }
}

/// Reads a region and its annotations ([`RegionAnnotations`]) from a GeoJSON file; repeated
/// consecutive points are removed as in [`read_region_geojson_cleaned`] (their count is
/// returned).
pub fn read_annotated_region_geojson(
    path: impl AsRef<Path>,
    part: PartSelector,
) -> Result<(Region, usize, RegionAnnotations), IoError> {
    let path = path.as_ref();
    let text = read_text(path)?;
    annotated_at(&text, path, part)
}

/// Like [`read_annotated_region_geojson`], for GeoJSON text held in memory.
pub fn parse_annotated_region_geojson(
    text: &str,
    part: PartSelector,
) -> Result<(Region, usize, RegionAnnotations), IoError> {
    annotated_at(text, Path::new(STRING_SOURCE), part)
}

fn annotated_at(
    text: &str,
    path: &Path,
    part: PartSelector,
) -> Result<(Region, usize, RegionAnnotations), IoError> {
    let parts = parse_parts_at(text, path)?;
    let rings = select_part(parts, part, path)?;
    // the text parsed as JSON above, so this cannot fail; map the error anyway
    let value: Value = serde_json::from_str(text).map_err(|e| IoError::Json {
        path: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message: strip_position(&e.to_string()),
    })?;
    let ann = annotations_of(&value, &rings.json_path, path)?;
    let (region, removed) = to_region(rings, path, true)?;
    Ok((region, removed, ann))
}

/// The annotations of the polygon at `part_path` of a parsed document.
pub(crate) fn annotations_of(
    value: &Value,
    part_path: &str,
    path: &Path,
) -> Result<RegionAnnotations, IoError> {
    let bad = |jp: String, problem: String| IoError::MissingMember {
        path: path.to_path_buf(),
        json_path: jp,
        problem,
    };
    // the feature holding the selected polygon
    let (feature, fjp) = match part_path
        .strip_prefix("$.features[")
        .and_then(|r| r.split(']').next())
        .and_then(|k| k.parse::<usize>().ok())
    {
        Some(k) => (value["features"].get(k), format!("$.features[{k}]")),
        None if value["type"] == "Feature" => (Some(value), "$".to_string()),
        None => (None, String::new()),
    };
    let props = feature
        .and_then(|f| f.get("properties"))
        .filter(|p| p.is_object());
    let string_at = |key: &str| -> Result<Option<String>, IoError> {
        match props.and_then(|p| p.get(key)) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::String(s)) => Ok(Some(s.clone())),
            Some(v) => Err(bad(
                format!("{fjp}.properties.{key}"),
                format!("must be a string, found {}", kind_of(v)),
            )),
        }
    };
    let mut names = crate::patches::BoundaryNames {
        outer: string_at("patch")?,
        ..Default::default()
    };
    let units = string_at("units")?;
    let holes_jp = format!("{fjp}.properties.hole_patch");
    match props.and_then(|p| p.get("hole_patch")) {
        None | Some(Value::Null) => {}
        Some(Value::String(s)) => {
            let nholes = hole_count(value, part_path);
            names.holes = vec![Some(s.clone()); nholes];
        }
        Some(Value::Array(a)) => {
            for (k, v) in a.iter().enumerate() {
                names.holes.push(match v {
                    Value::Null => None,
                    Value::String(s) => Some(s.clone()),
                    v => {
                        return Err(bad(
                            format!("{holes_jp}[{k}]"),
                            format!("must be a string or null, found {}", kind_of(v)),
                        ))
                    }
                });
            }
        }
        Some(v) => {
            return Err(bad(
                holes_jp,
                format!("must be a string or an array, found {}", kind_of(v)),
            ))
        }
    }
    if let Some(feats) = value.get("features").and_then(Value::as_array) {
        for (k, f) in feats.iter().enumerate() {
            let jp = format!("$.features[{k}]");
            let Some(name) = f.get("properties").and_then(|p| p.get("patch")) else {
                continue;
            };
            let g = &f["geometry"];
            let lines: Vec<&Value> = match g["type"].as_str() {
                Some("LineString") => vec![&g["coordinates"]],
                Some("MultiLineString") => g["coordinates"]
                    .as_array()
                    .map(|a| a.iter().collect())
                    .unwrap_or_default(),
                _ => continue,
            };
            let name = name.as_str().ok_or_else(|| {
                bad(
                    format!("{jp}.properties.patch"),
                    format!("must be a string, found {}", kind_of(name)),
                )
            })?;
            for (l, line) in lines.into_iter().enumerate() {
                let ljp = format!("{jp}.geometry.coordinates");
                let pts = line
                    .as_array()
                    .ok_or_else(|| bad(ljp.clone(), "a line string must be an array".into()))?
                    .iter()
                    .enumerate()
                    .map(|(i, p)| {
                        match (
                            p.get(0).and_then(Value::as_f64),
                            p.get(1).and_then(Value::as_f64),
                        ) {
                            (Some(x), Some(y)) => Ok(DVec2::new(x, y)),
                            _ => Err(IoError::BadCoordinate {
                                path: path.to_path_buf(),
                                json_path: format!("{ljp}[{l}][{i}]"),
                                problem: "a position must be an array of at least 2 numbers".into(),
                            }),
                        }
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                names.stretches.push(crate::patches::Stretch {
                    name: name.to_string(),
                    points: pts,
                });
            }
        }
    }
    let crs = value
        .get("crs")
        .and_then(|c| c.get("properties"))
        .and_then(|p| p.get("name"))
        .and_then(Value::as_str)
        .map(str::to_string);
    Ok(RegionAnnotations { names, units, crs })
}

/// The number of holes of the polygon at `part_path` (its ring count − 1).
fn hole_count(value: &Value, part_path: &str) -> usize {
    let mut v = value;
    // walk "$.a[1].b.c[2]" segments
    for seg in part_path
        .trim_start_matches('$')
        .split('.')
        .filter(|s| !s.is_empty())
    {
        let mut it = seg.split('[');
        if let Some(key) = it.next() {
            v = &v[key];
        }
        for idx in it {
            if let Ok(k) = idx.trim_end_matches(']').parse::<usize>() {
                v = &v[k];
            }
        }
    }
    v.as_array().map_or(0, |a| a.len().saturating_sub(1))
}

#[cfg(test)]
mod annotation_tests {
    use super::*;

    const BOX_WITH_SEA: &str = r#"{"type":"FeatureCollection","features":[
      {"type":"Feature","properties":{"patch":"coast","hole_patch":["island"]},
       "geometry":{"type":"Polygon","coordinates":[
         [[0,0],[4,0],[4,3],[0,3],[0,0]],
         [[1,1],[1,2],[2,2],[2,1],[1,1]]]}},
      {"type":"Feature","properties":{"patch":"open-sea"},
       "geometry":{"type":"LineString","coordinates":[[4,0],[4,3],[0,3]]}},
      {"type":"Feature","properties":{"name":"not a patch"},
       "geometry":{"type":"LineString","coordinates":[[0,0],[1,0]]}}]}"#;

    #[test]
    fn ring_names_and_stretches_are_read() {
        let (r, removed, a) =
            parse_annotated_region_geojson(BOX_WITH_SEA, PartSelector::Largest).unwrap();
        assert_eq!(removed, 0);
        assert_eq!(r.holes().len(), 1);
        assert_eq!(a.names.outer.as_deref(), Some("coast"));
        assert_eq!(a.names.holes, vec![Some("island".to_string())]);
        assert_eq!(a.names.stretches.len(), 1);
        assert_eq!(a.names.stretches[0].name, "open-sea");
        assert_eq!(a.names.stretches[0].points.len(), 3);
        assert!(!a.declares_planar());
        crate::patches::validate_names(&r, &a.names).unwrap();
    }

    #[test]
    fn one_hole_name_for_all_holes_and_declared_units() {
        let text = r#"{"type":"Feature","properties":{"hole_patch":"wall","units":"km"},
          "geometry":{"type":"Polygon","coordinates":[
            [[0,0],[9,0],[9,9],[0,9],[0,0]],
            [[1,1],[1,2],[2,2],[1,1]],
            [[5,5],[5,6],[6,6],[5,5]]]}}"#;
        let (_, _, a) = parse_annotated_region_geojson(text, PartSelector::Largest).unwrap();
        assert_eq!(a.names.holes, vec![Some("wall".to_string()); 2]);
        assert_eq!(a.units.as_deref(), Some("km"));
        assert!(a.declares_planar());
    }

    #[test]
    fn a_bad_patch_member_names_its_json_path() {
        let text = r#"{"type":"Feature","properties":{"patch":3},
          "geometry":{"type":"Polygon","coordinates":[[[0,0],[1,0],[1,1],[0,0]]]}}"#;
        let e = parse_annotated_region_geojson(text, PartSelector::Largest)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("$.properties.patch") && e.contains("a number"),
            "{e}"
        );
    }
}
