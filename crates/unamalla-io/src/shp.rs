//! ESRI Shapefile polygons (shape type 5, and the `M`/`Z` variants with the extra ordinates
//! ignored), read and written with the pure-Rust [`shapefile`] crate.
//!
//! The ESRI specification stores outer rings **clockwise** and holes **counter-clockwise**
//! (the opposite of this crate family's convention); [`shapefile`] classifies each ring by its
//! orientation. Every outer ring starts a **part**; each hole is attached to the outer ring that
//! contains its first vertex (the preceding outer ring if none does). Parts are numbered over
//! all polygon shapes of the file in order, and a [`PartSelector`] picks one (by default the
//! largest). [`Region::new`] then normalises the orientation (outer counter-clockwise, holes
//! clockwise) and validates the part. Null shapes are skipped; point and polyline shapes are
//! [`IoError::NoPolygon`] when no polygon is found.
//!
//! Only the `.shp` file is needed for reading (the `.shx` index and `.dbf` attributes are not
//! used). [`write_region_shapefile`] writes the `.shp` and its `.shx` index (both atomically,
//! the `.shp` last) with one polygon shape; attribute tables (`.dbf`) are not written.
//! Reader errors are reported as [`IoError::Shapefile`] with the crate's message (the format is
//! binary, so there are no line numbers), except record headers whose sizes or point counts do
//! not fit in the file, which are checked first and reported as [`IoError::MalformedBinary`]
//! with the byte offset (so no input makes the reader reserve more memory than the file size).

use std::io::Cursor;
use std::path::Path;

use shapefile::{Point, Polygon, PolygonRing, Shape, ShapeReader, ShapeWriter};
use unamalla_mesh::{DVec2, Region};

use crate::atomic::atomic_write;
use crate::error::IoError;
use crate::geojson::{select_part, PartSelector, PolygonRings};

fn shp_err(path: &Path, e: impl std::fmt::Display) -> IoError {
    IoError::Shapefile {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Every polygonal part of a shapefile, in file order (see the [module docs](self)); rings are
/// open and oriented as in the file. `PolygonRings::json_path` holds `shape <k>` (0-based shape
/// index).
pub fn read_shapefile_parts(path: impl AsRef<Path>) -> Result<Vec<PolygonRings>, IoError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| IoError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parts_from_bytes(&bytes, path)
}

/// Every polygonal part of a shapefile held in memory (the bytes of a `.shp` file), like
/// [`read_shapefile_parts`]; errors name the path `<string>`.
pub fn parse_shapefile_parts(bytes: &[u8]) -> Result<Vec<PolygonRings>, IoError> {
    parts_from_bytes(bytes, Path::new(crate::geojson::STRING_SOURCE))
}

/// Reads a region from a shapefile: the selected part, validated by [`Region::new`].
pub fn read_region_shapefile(
    path: impl AsRef<Path>,
    part: PartSelector,
) -> Result<Region, IoError> {
    let path = path.as_ref();
    let parts = read_shapefile_parts(path)?;
    let rings = select_part(parts, part, path)?;
    Region::new(rings.outer, rings.holes).map_err(|source| IoError::Geometry {
        path: path.to_path_buf(),
        json_path: rings.json_path,
        part: rings.part,
        source,
    })
}

fn open_ring(points: Vec<DVec2>) -> Vec<DVec2> {
    let mut p = points;
    if p.len() >= 2 && p.first() == p.last() {
        p.pop();
    }
    p
}

/// Even-odd point-in-ring test (for assigning holes to outer rings only).
fn inside(p: DVec2, ring: &[DVec2]) -> bool {
    let n = ring.len();
    let mut c = false;
    for k in 0..n {
        let (a, b) = (ring[k], ring[(k + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y) {
            c = !c;
        }
    }
    c
}

fn le_i32(bytes: &[u8], at: usize) -> Option<i64> {
    let b: [u8; 4] = bytes.get(at..at.checked_add(4)?)?.try_into().ok()?;
    Some(i64::from(i32::from_le_bytes(b)))
}

fn be_i32(bytes: &[u8], at: usize) -> Option<i64> {
    let b: [u8; 4] = bytes.get(at..at.checked_add(4)?)?.try_into().ok()?;
    Some(i64::from(i32::from_be_bytes(b)))
}

/// Checks the record headers and point counts of a `.shp` file before the [`shapefile`] crate
/// reads it: every record must fit in the file, and a record's declared part and point counts
/// must fit in its content (ESRI whitepaper: polygon/polyline content = 44 + 4·parts + 16·points
/// bytes at least, multipoint 40 + 16·points), and part start indices must be non-decreasing
/// and at most the point count. The crate reserves memory for the declared
/// counts before reading them, so without this check a 300-byte file could ask for gigabytes
/// (found by the `shapefile` fuzz target, issue #14). Records are walked like the crate does
/// without an index: from byte 100, while below the header's file length.
fn check_records(bytes: &[u8], path: &Path) -> Result<(), IoError> {
    let bad = |offset: usize, message: String| IoError::MalformedBinary {
        path: path.to_path_buf(),
        offset: offset as u64,
        message,
    };
    // not a shapefile, or too short for a header: the crate reports it
    let (Some(9994), Some(words)) = (be_i32(bytes, 0), be_i32(bytes, 24)) else {
        return Ok(());
    };
    // the crate reads a record whenever its start is below the header's length, even if
    // the record header itself extends past that length
    let declared = usize::try_from(words.max(0)).unwrap_or(0).saturating_mul(2);
    let mut pos = 100usize;
    let mut record = 0usize;
    while pos < declared && pos.saturating_add(8) <= bytes.len() {
        let words = be_i32(bytes, pos + 4).unwrap_or(0);
        let content = match usize::try_from(words) {
            Ok(w) => w.saturating_mul(2),
            Err(_) => {
                return Err(bad(
                    pos + 4,
                    format!("record {record}: negative content length {words}"),
                ))
            }
        };
        let start = pos + 8;
        if content > bytes.len() - start {
            return Err(bad(
                pos + 4,
                format!(
                    "record {record}: content length {content} bytes runs past the end of the file ({} bytes)",
                    bytes.len()
                ),
            ));
        }
        let shape_type = le_i32(bytes, start).unwrap_or(0);
        let (fixed, parts_at, points_at) = match shape_type {
            3 | 5 | 13 | 15 | 23 | 25 | 31 => (44i64, Some(start + 36), start + 40),
            8 | 18 | 28 => (40i64, None, start + 36),
            _ => (0, None, 0),
        };
        // the crate reads the shape type and the fixed fields whatever the record length says,
        // and reads the next record where this one's data ended: a null shape must be exactly
        // its 4-byte type (otherwise the crate takes its padding for the next record header)
        if content < 4
            || (fixed > 0 && (content as i64) < fixed)
            || (shape_type == 0 && content != 4)
        {
            return Err(bad(
                pos + 4,
                format!(
                    "record {record}: content length {content} bytes is too short for shape type {shape_type}"
                ),
            ));
        }
        if fixed > 0 {
            let parts = parts_at.and_then(|at| le_i32(bytes, at)).unwrap_or(0);
            let points = le_i32(bytes, points_at).unwrap_or(0);
            let need = fixed + 4 * parts + 16 * points;
            if parts < 0 || points < 0 || need > content as i64 {
                return Err(bad(
                    start + 36,
                    format!(
                        "record {record}: {parts} part(s) and {points} point(s) need {need} bytes, the record has {content}"
                    ),
                ));
            }
            // part start indices: non-decreasing, within 0..=points (the crate derives each
            // part's point count from consecutive indices and reserves that much)
            let mut prev = 0i64;
            for k in 0..parts as usize {
                let at = start + 44 + 4 * k;
                let idx = le_i32(bytes, at).unwrap_or(-1);
                if idx < prev || idx > points {
                    return Err(bad(
                        at,
                        format!(
                            "record {record}: part {k} starts at point {idx}, outside {prev}..={points}"
                        ),
                    ));
                }
                prev = idx;
            }
        }
        pos = start + content;
        record += 1;
    }
    Ok(())
}

fn parts_from_bytes(bytes: &[u8], path: &Path) -> Result<Vec<PolygonRings>, IoError> {
    check_records(bytes, path)?;
    let reader = ShapeReader::new(Cursor::new(bytes)).map_err(|e| shp_err(path, e))?;
    let shapes = reader.read().map_err(|e| shp_err(path, e))?;
    let mut parts: Vec<PolygonRings> = Vec::new();
    let mut found = Vec::new();
    for (s, shape) in shapes.into_iter().enumerate() {
        let rings: Vec<(bool, Vec<DVec2>)> = match shape {
            Shape::NullShape => continue,
            Shape::Polygon(p) => conv(p.into_inner(), |q| DVec2::new(q.x, q.y)),
            Shape::PolygonM(p) => conv(p.into_inner(), |q| DVec2::new(q.x, q.y)),
            Shape::PolygonZ(p) => conv(p.into_inner(), |q| DVec2::new(q.x, q.y)),
            other => {
                found.push(other.shapetype().to_string());
                continue;
            }
        };
        let first = parts.len();
        let mut holes = Vec::new();
        for (outer, pts) in rings {
            if outer {
                parts.push(PolygonRings {
                    outer: pts,
                    holes: Vec::new(),
                    json_path: format!("shape {s}"),
                    part: parts.len(),
                });
            } else {
                holes.push((parts.len(), pts));
            }
        }
        for (after, h) in holes {
            let p0 = h.first().copied().unwrap_or(DVec2::ZERO);
            let target = (first..parts.len())
                .find(|&k| inside(p0, &parts[k].outer))
                .or_else(|| after.checked_sub(1).filter(|&k| k >= first))
                .or_else(|| (first < parts.len()).then_some(first));
            match target {
                Some(k) => parts[k].holes.push(h),
                // A shape of holes only: treat each as its own outer ring.
                None => parts.push(PolygonRings {
                    outer: h,
                    holes: Vec::new(),
                    json_path: format!("shape {s}"),
                    part: parts.len(),
                }),
            }
        }
    }
    if parts.is_empty() {
        return Err(IoError::NoPolygon {
            path: path.to_path_buf(),
            found,
        });
    }
    Ok(parts)
}

fn conv<P>(rings: Vec<PolygonRing<P>>, f: impl Fn(&P) -> DVec2) -> Vec<(bool, Vec<DVec2>)> {
    rings
        .into_iter()
        .map(|r| {
            let outer = matches!(r, PolygonRing::Outer(_));
            let pts = open_ring(r.into_inner().iter().map(&f).collect());
            (outer, pts)
        })
        .collect()
}

/// Writes a region as a one-shape polygon shapefile: `path` (the `.shp`) and the `.shx` index
/// next to it. Rings are closed and oriented as the ESRI specification asks (outer clockwise,
/// holes counter-clockwise).
pub fn write_region_shapefile(path: impl AsRef<Path>, region: &Region) -> Result<(), IoError> {
    let path = path.as_ref();
    let ring = |pts: &[DVec2], outer: bool| {
        let mut v: Vec<Point> = pts.iter().map(|p| Point::new(p.x, p.y)).collect();
        if let Some(&p0) = v.first() {
            v.push(p0);
        }
        if outer {
            PolygonRing::Outer(v)
        } else {
            PolygonRing::Inner(v)
        }
    };
    let mut rings = vec![ring(region.outer().points(), true)];
    rings.extend(region.holes().iter().map(|h| ring(h.points(), false)));
    let polygon = Polygon::with_rings(rings);
    let mut shp = Cursor::new(Vec::new());
    let mut shx = Cursor::new(Vec::new());
    {
        let mut w = ShapeWriter::with_shx(&mut shp, &mut shx);
        w.write_shape(&polygon).map_err(|e| shp_err(path, e))?;
        w.finalize().map_err(|e| shp_err(path, e))?;
    }
    let shx_path = path.with_extension("shx");
    atomic_write(&shx_path, |w| w.write_all(shx.get_ref()))?;
    atomic_write(path, |w| w.write_all(shp.get_ref()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inside_test() {
        let sq = [
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(2.0, 2.0),
            DVec2::new(0.0, 2.0),
        ];
        assert!(inside(DVec2::new(1.0, 1.0), &sq));
        assert!(!inside(DVec2::new(3.0, 1.0), &sq));
    }
}
