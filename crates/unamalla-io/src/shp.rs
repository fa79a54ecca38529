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
//! binary, so there are no line numbers).

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

fn parts_from_bytes(bytes: &[u8], path: &Path) -> Result<Vec<PolygonRings>, IoError> {
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
