//! ESRI Shapefile polygons (shape types 5 `Polygon`, 15 `PolygonZ` and 25 `PolygonM`; the
//! extra `Z`/`M` ordinates are ignored), read and written by a small parser of our own.
//!
//! # Format (ESRI Shapefile Technical Description, July 1998)
//!
//! A `.shp` file is a 100-byte header followed by variable-length records:
//!
//! | bytes | field | byte order |
//! |---|---|---|
//! | 0..4 | file code 9994 | big-endian `i32` |
//! | 24..28 | file length in 16-bit words, header included | big-endian `i32` |
//! | 28..32 | version 1000 | little-endian `i32` |
//! | 32..36 | shape type of the file | little-endian `i32` |
//! | 36..100 | bounding box `Xmin Ymin Xmax Ymax Zmin Zmax Mmin Mmax` | little-endian `f64` |
//!
//! Each record is an 8-byte header — record number and content length in 16-bit words, both
//! big-endian `i32` — and the content, which starts with the little-endian shape type. A null
//! shape (type 0) is just that type (4 bytes). A polygon's content is
//!
//! | content bytes | field |
//! |---|---|
//! | 0..4 | shape type 5 / 15 / 25 |
//! | 4..36 | bounding box `Xmin Ymin Xmax Ymax` (`f64`) |
//! | 36..40 | `NumParts` (`i32`) |
//! | 40..44 | `NumPoints` (`i32`) |
//! | 44..44 + 4·`NumParts` | index of each part's first point (`i32`) |
//! | then 16·`NumPoints` | the points, `x y` (`f64`) |
//! | then (types 15, 25) | `Z` and/or `M` ranges and arrays, ignored here |
//!
//! so a polygon record has at least `44 + 4·NumParts + 16·NumPoints` bytes of content.
//!
//! # Robustness
//!
//! Every size read from the file is checked against the bytes that are really there **before**
//! anything is allocated, so no input makes the reader reserve more memory than the file's own
//! size (the `shapefile` crate this module used to wrap trusted the counts and was made to
//! reserve gigabytes by 300-byte inputs; see `docs/reliability.md`). The rules, each reported as
//! [`IoError::MalformedBinary`] with the byte offset of the offending field:
//!
//! * the file has the whole 100-byte header, and the declared file length is at least 100
//!   bytes; records are read from byte 100 up to the declared length (bytes after it are
//!   ignored, a file shorter than it is truncated);
//! * every record header and every record's content lie within the declared length and the
//!   file; a record's content length is not negative and holds at least its shape type;
//! * the shape type is one of the specification's (0, 1, 3, 5, 8, 11, 13, 15, 18, 21, 23, 25,
//!   28, 31); a null shape's content is exactly its 4-byte type;
//! * a polygon record holds its 44 fixed bytes, `NumParts ≥ 0`, `NumPoints ≥ 0` and
//!   `44 + 4·NumParts + 16·NumPoints` bytes; the first part starts at point 0 and the part start
//!   indices are non-decreasing and at most `NumPoints`.
//!
//! The reader moves to the next record by the declared content length (never by how much it
//! read), so padding after a polygon's points (or the `Z`/`M` data) cannot be mistaken for a
//! record header. Record numbers and the header's shape type are not checked against the
//! records (real files disagree on them harmlessly); a file whose first four bytes are not the
//! file code 9994 is [`IoError::Shapefile`].
//!
//! # Rings and parts
//!
//! The specification stores outer rings **clockwise** and holes **counter-clockwise** (the
//! opposite of this crate family's convention); each ring is classified by its orientation:
//! clockwise or degenerate is an outer ring, counter-clockwise a hole. The orientation is the
//! exact sign of `orient2d` at the ring's lexicographically smallest vertex (a convex corner of
//! any simple ring, as in `unamalla_mesh::Region`), and only when that turn is degenerate the
//! sign of the shoelace area `A = ½ Σ_k (p_k − p_0) × (p_{k+1} − p_0)` (fan from the first
//! vertex, which loses less precision far from the origin than the textbook sum); the writer
//! uses the same test, so whatever it writes as an outer ring reads back as one. Every outer ring starts a **part**; each hole
//! is attached to the outer ring of the same shape that contains its first vertex (even-odd
//! rule), otherwise to the preceding outer ring, otherwise to the shape's first one; a shape
//! made of holes only gives one part per hole. Parts are numbered over all polygon shapes of
//! the file in order, and a [`PartSelector`] picks one (by default the largest).
//! [`Region::new`] then normalises the orientation (outer counter-clockwise, holes clockwise)
//! and validates the part. Null shapes are skipped; when no polygon is found the error is
//! [`IoError::NoPolygon`] listing the other shape types met.
//!
//! Only the `.shp` file is needed for reading (the `.shx` index and `.dbf` attributes are not
//! used). [`write_region_shapefile`] writes the `.shp` and its `.shx` index (both atomically,
//! the `.shp` last) with one polygon shape; attribute tables (`.dbf`) are not written.

use std::path::Path;

use unamalla_mesh::geometry::orient2d;
use unamalla_mesh::region::signed_area;
use unamalla_mesh::{DVec2, Region};

use crate::atomic::atomic_write;
use crate::error::IoError;
use crate::geojson::{select_part, PartSelector, PolygonRings};

/// The file code in bytes 0..4 (big-endian).
const FILE_CODE: i32 = 9994;
/// Size of the main file header and of the `.shx` header.
const HEADER_LEN: usize = 100;
/// Size of a record header (record number and content length).
const RECORD_HEADER_LEN: usize = 8;
/// Fixed part of a polygon record's content: type, bounding box, `NumParts`, `NumPoints`.
const POLYGON_FIXED: usize = 44;
/// The version written and expected in bytes 28..32.
const VERSION: i32 = 1000;
/// Shape type of a polygon.
const POLYGON: i32 = 5;

/// The specification's name of a shape type, `None` for a value it does not define.
fn shape_type_name(t: i32) -> Option<&'static str> {
    Some(match t {
        0 => "NullShape",
        1 => "Point",
        3 => "Polyline",
        5 => "Polygon",
        8 => "Multipoint",
        11 => "PointZ",
        13 => "PolylineZ",
        15 => "PolygonZ",
        18 => "MultipointZ",
        21 => "PointM",
        23 => "PolylineM",
        25 => "PolygonM",
        28 => "MultipointM",
        31 => "Multipatch",
        _ => return None,
    })
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

/// Drops the closing position of a ring stored closed.
fn open_ring(points: Vec<DVec2>) -> Vec<DVec2> {
    let mut p = points;
    if p.len() >= 2 && p.first() == p.last() {
        p.pop();
    }
    p
}

/// Orientation of an open ring: `> 0` counter-clockwise, `< 0` clockwise. Decided exactly by
/// `orient2d` (Shewchuk's adaptive predicate) at the lexicographically smallest vertex and its
/// nearest distinct neighbours — for a simple ring that vertex is a convex corner, so the sign
/// is the sign of the area with no rounding (the same rule as `unamalla_mesh::Region`). When
/// that turn is degenerate (a collinear spike, or a ring that is not simple) the rounded fan
/// area ([`signed_area`], a fan from the first vertex) decides.
fn orientation(ring: &[DVec2]) -> f64 {
    let n = ring.len();
    let Some((k, &v)) = ring
        .iter()
        .enumerate()
        .min_by(|(_, a), (_, b)| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)))
    else {
        return 0.0;
    };
    let prev = (1..n).map(|i| ring[(k + n - i) % n]).find(|&p| p != v);
    let next = (1..n).map(|i| ring[(k + i) % n]).find(|&p| p != v);
    let turn = match (prev, next) {
        (Some(a), Some(c)) => orient2d(a, v, c),
        _ => 0.0,
    };
    if turn != 0.0 {
        turn
    } else {
        signed_area(ring)
    }
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

/// Bounds-checked field access on the bytes of a `.shp` file; every failure is an
/// [`IoError::MalformedBinary`] naming the offset.
struct Bytes<'a> {
    bytes: &'a [u8],
    path: &'a Path,
}

impl Bytes<'_> {
    fn err(&self, offset: usize, message: String) -> IoError {
        IoError::MalformedBinary {
            path: self.path.to_path_buf(),
            offset: offset as u64,
            message,
        }
    }

    fn array<const N: usize>(&self, at: usize, what: &str) -> Result<[u8; N], IoError> {
        at.checked_add(N)
            .and_then(|end| self.bytes.get(at..end))
            .and_then(|s| <[u8; N]>::try_from(s).ok())
            .ok_or_else(|| {
                self.err(
                    at,
                    format!(
                        "{what}: {N} bytes needed, the file ends at byte {}",
                        self.bytes.len()
                    ),
                )
            })
    }

    fn be_i32(&self, at: usize, what: &str) -> Result<i32, IoError> {
        self.array(at, what).map(i32::from_be_bytes)
    }

    fn le_i32(&self, at: usize, what: &str) -> Result<i32, IoError> {
        self.array(at, what).map(i32::from_le_bytes)
    }

    fn le_f64(&self, at: usize, what: &str) -> Result<f64, IoError> {
        self.array(at, what).map(f64::from_le_bytes)
    }
}

/// The rings of one polygon record whose content is `bytes[start..start + content]` (already
/// known to lie in the file), open, as stored. `len_at` is the offset of the record's content
/// length field (where "too short" is reported).
fn polygon_rings(
    b: &Bytes<'_>,
    record: usize,
    start: usize,
    content: usize,
    len_at: usize,
) -> Result<Vec<Vec<DVec2>>, IoError> {
    if content < POLYGON_FIXED {
        return Err(b.err(
            len_at,
            format!(
                "record {record}: content length {content} bytes is too short for a polygon \
                 ({POLYGON_FIXED} bytes of fixed fields)"
            ),
        ));
    }
    let parts_at = start + 36;
    let points_at = start + 40;
    let num_parts = b.le_i32(parts_at, "NumParts")?;
    let num_points = b.le_i32(points_at, "NumPoints")?;
    let (Ok(num_parts), Ok(num_points)) = (usize::try_from(num_parts), usize::try_from(num_points))
    else {
        let at = if num_parts < 0 { parts_at } else { points_at };
        return Err(b.err(
            at,
            format!("record {record}: negative count ({num_parts} part(s), {num_points} point(s))"),
        ));
    };
    // at most 44 + 4·(2³¹ − 1) + 16·(2³¹ − 1) < 2⁴⁶: no overflow in u64
    let need = POLYGON_FIXED as u64 + 4 * num_parts as u64 + 16 * num_points as u64;
    if need > content as u64 {
        return Err(b.err(
            parts_at,
            format!(
                "record {record}: {num_parts} part(s) and {num_points} point(s) need {need} \
                 bytes, the record has {content}"
            ),
        ));
    }
    // From here on every count is bounded by the record's content, itself inside the file.
    let index_at = start + POLYGON_FIXED;
    let mut starts = Vec::with_capacity(num_parts);
    for k in 0..num_parts {
        let at = index_at + 4 * k;
        let idx = b.le_i32(at, "part index")?;
        let prev = starts.last().copied().unwrap_or(0);
        match usize::try_from(idx) {
            Ok(0) if k == 0 => starts.push(0),
            Ok(i) if k > 0 && i >= prev && i <= num_points => starts.push(i),
            _ => {
                let expected = if k == 0 {
                    "expected 0".to_string()
                } else {
                    format!("expected {prev}..={num_points}")
                };
                return Err(b.err(
                    at,
                    format!("record {record}: part {k} starts at point {idx}, {expected}"),
                ));
            }
        }
    }
    let xy_at = index_at + 4 * num_parts;
    let mut points = Vec::with_capacity(num_points);
    for i in 0..num_points {
        let at = xy_at + 16 * i;
        points.push(DVec2::new(b.le_f64(at, "x")?, b.le_f64(at + 8, "y")?));
    }
    let mut rings = Vec::with_capacity(num_parts);
    for (k, &s) in starts.iter().enumerate() {
        let e = starts.get(k + 1).copied().unwrap_or(num_points);
        let ring = points.get(s..e).map(<[DVec2]>::to_vec).unwrap_or_default();
        rings.push(open_ring(ring));
    }
    Ok(rings)
}

fn parts_from_bytes(bytes: &[u8], path: &Path) -> Result<Vec<PolygonRings>, IoError> {
    let b = Bytes { bytes, path };
    if let Ok(code) = b.be_i32(0, "file code") {
        if code != FILE_CODE {
            return Err(IoError::Shapefile {
                path: path.to_path_buf(),
                message: format!("not a shapefile: file code {code}, expected {FILE_CODE}"),
            });
        }
    }
    if bytes.len() < HEADER_LEN {
        return Err(b.err(
            bytes.len(),
            format!(
                "the file ends within the {HEADER_LEN}-byte header ({} bytes)",
                bytes.len()
            ),
        ));
    }
    let words = b.be_i32(24, "file length")?;
    let declared = usize::try_from(words)
        .ok()
        .and_then(|w| w.checked_mul(2))
        .filter(|&d| d >= HEADER_LEN)
        .ok_or_else(|| {
            b.err(
                24,
                format!("file length {words} words is shorter than the {HEADER_LEN}-byte header"),
            )
        })?;
    let header_type = b.le_i32(32, "shape type")?;
    if shape_type_name(header_type).is_none() {
        return Err(b.err(
            32,
            format!("unknown shape type {header_type} in the header"),
        ));
    }
    // records lie within the declared length, and within the file
    let limit = declared.min(bytes.len());
    let past = |at: usize, end: usize, what: String| {
        let message = if end > bytes.len() {
            format!(
                "{what} runs past the end of the file ({} bytes; the header declares {declared})",
                bytes.len()
            )
        } else {
            format!("{what} runs past the file length declared in the header ({declared} bytes)")
        };
        b.err(at, message)
    };

    let mut parts: Vec<PolygonRings> = Vec::new();
    let mut found: Vec<String> = Vec::new();
    let mut pos = HEADER_LEN;
    let mut record = 0usize;
    while pos < declared {
        let start = pos + RECORD_HEADER_LEN;
        if start > limit {
            return Err(past(
                pos,
                start,
                format!("record {record}: the record header"),
            ));
        }
        let words = b.be_i32(pos + 4, "content length")?;
        let content = usize::try_from(words)
            .ok()
            .and_then(|w| w.checked_mul(2))
            .ok_or_else(|| {
                b.err(
                    pos + 4,
                    format!("record {record}: negative content length {words} words"),
                )
            })?;
        let end = start.saturating_add(content);
        if end > limit {
            return Err(past(
                pos + 4,
                end,
                format!("record {record}: content of {content} bytes from byte {start}"),
            ));
        }
        if content < 4 {
            return Err(b.err(
                pos + 4,
                format!(
                    "record {record}: content length {content} bytes is too short for a shape type"
                ),
            ));
        }
        let shape_type = b.le_i32(start, "shape type")?;
        match shape_type {
            0 if content != 4 => {
                return Err(b.err(
                    pos + 4,
                    format!(
                        "record {record}: a null shape has 4 bytes of content, this one declares \
                         {content}"
                    ),
                ))
            }
            0 => {}
            5 | 15 | 25 => {
                let rings = polygon_rings(&b, record, start, content, pos + 4)?;
                push_shape(&mut parts, record, rings);
            }
            t => match shape_type_name(t) {
                Some(name) => {
                    if !found.iter().any(|f| f == name) {
                        found.push(name.to_string());
                    }
                }
                None => {
                    return Err(b.err(start, format!("record {record}: unknown shape type {t}")))
                }
            },
        }
        pos = end;
        record += 1;
    }
    if parts.is_empty() {
        return Err(IoError::NoPolygon {
            path: path.to_path_buf(),
            found,
        });
    }
    Ok(parts)
}

/// Classifies the rings of shape `s` and appends its parts (see the [module docs](self)).
fn push_shape(parts: &mut Vec<PolygonRings>, s: usize, rings: Vec<Vec<DVec2>>) {
    let first = parts.len();
    let mut holes = Vec::new();
    for pts in rings {
        if orientation(&pts) <= 0.0 {
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
    // holes attach to this shape's outer rings only (not to holes of this shape that became
    // parts of their own below)
    let outers = parts.len();
    for (after, h) in holes {
        let p0 = h.first().copied().unwrap_or(DVec2::ZERO);
        let target = (first..outers)
            .find(|&k| inside(p0, &parts[k].outer))
            .or_else(|| after.checked_sub(1).filter(|&k| k >= first))
            .or_else(|| (first < outers).then_some(first));
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

fn put_be(out: &mut Vec<u8>, v: i32) {
    out.extend_from_slice(&v.to_be_bytes());
}

fn put_le(out: &mut Vec<u8>, v: i32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put_f64(out: &mut Vec<u8>, v: f64) {
    out.extend_from_slice(&v.to_le_bytes());
}

/// The 100-byte header of a `.shp` or `.shx` file of polygons.
fn header(out: &mut Vec<u8>, file_words: i32, bbox: [f64; 4]) {
    put_be(out, FILE_CODE);
    out.extend_from_slice(&[0u8; 20]);
    put_be(out, file_words);
    put_le(out, VERSION);
    put_le(out, POLYGON);
    for v in bbox {
        put_f64(out, v);
    }
    // Z and M ranges: unused for type 5
    out.extend_from_slice(&[0u8; 32]);
}

/// Writes a region as a one-shape polygon shapefile: `path` (the `.shp`) and the `.shx` index
/// next to it. Rings are closed and oriented as the ESRI specification asks (outer clockwise,
/// holes counter-clockwise).
pub fn write_region_shapefile(path: impl AsRef<Path>, region: &Region) -> Result<(), IoError> {
    let path = path.as_ref();
    let (shp, shx) = encode(region, path)?;
    let shx_path = path.with_extension("shx");
    atomic_write(&shx_path, |w| w.write_all(&shx))?;
    atomic_write(path, |w| w.write_all(&shp))
}

/// The bytes of the `.shp` and `.shx` files [`write_region_shapefile`] writes, in memory
/// (e.g. for a round trip through [`parse_shapefile_parts`]); errors name the path `<string>`.
pub fn encode_region_shapefile(region: &Region) -> Result<(Vec<u8>, Vec<u8>), IoError> {
    encode(region, Path::new(crate::geojson::STRING_SOURCE))
}

/// Encodes `region` as `.shp` and `.shx` bytes; `path` only names the file in errors.
fn encode(region: &Region, path: &Path) -> Result<(Vec<u8>, Vec<u8>), IoError> {
    // ESRI orientation: outer (`clockwise == true`) clockwise, holes counter-clockwise
    let ring = |pts: &[DVec2], clockwise: bool| {
        let mut v = pts.to_vec();
        if (orientation(&v) < 0.0) != clockwise {
            v.reverse();
        }
        if let Some(&p0) = v.first() {
            v.push(p0);
        }
        v
    };
    let mut rings = vec![ring(region.outer().points(), true)];
    rings.extend(region.holes().iter().map(|h| ring(h.points(), false)));
    let num_points: usize = rings.iter().map(Vec::len).sum();
    let content = POLYGON_FIXED as u64 + 4 * rings.len() as u64 + 16 * num_points as u64;
    let too_large = || IoError::Shapefile {
        path: path.to_path_buf(),
        message: format!(
            "{num_points} points in {} rings do not fit in a shapefile record",
            rings.len()
        ),
    };
    let words = |bytes: u64| i32::try_from(bytes / 2).map_err(|_| too_large());
    let content_words = words(content)?;
    let shp_words = words(HEADER_LEN as u64 + RECORD_HEADER_LEN as u64 + content)?;
    let num_parts = i32::try_from(rings.len()).map_err(|_| too_large())?;
    let num_points_i32 = i32::try_from(num_points).map_err(|_| too_large())?;

    let mut bbox = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for p in rings.iter().flatten() {
        bbox = [
            bbox[0].min(p.x),
            bbox[1].min(p.y),
            bbox[2].max(p.x),
            bbox[3].max(p.y),
        ];
    }

    let mut shp = Vec::with_capacity(2 * shp_words as usize);
    header(&mut shp, shp_words, bbox);
    put_be(&mut shp, 1); // record number, 1-based
    put_be(&mut shp, content_words);
    put_le(&mut shp, POLYGON);
    for v in bbox {
        put_f64(&mut shp, v);
    }
    put_le(&mut shp, num_parts);
    put_le(&mut shp, num_points_i32);
    let mut first = 0i32;
    for r in &rings {
        put_le(&mut shp, first);
        // each ring has at most num_points ≤ i32::MAX points (checked above)
        first = first.saturating_add(i32::try_from(r.len()).unwrap_or(i32::MAX));
    }
    for p in rings.iter().flatten() {
        put_f64(&mut shp, p.x);
        put_f64(&mut shp, p.y);
    }

    // index: header with the .shx length (100 bytes + one 8-byte entry), then offset and
    // content length of the record, both in 16-bit words
    let mut shx = Vec::with_capacity(HEADER_LEN + RECORD_HEADER_LEN);
    header(
        &mut shx,
        ((HEADER_LEN + RECORD_HEADER_LEN) / 2) as i32,
        bbox,
    );
    put_be(&mut shx, (HEADER_LEN / 2) as i32);
    put_be(&mut shx, content_words);

    Ok((shp, shx))
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
