//! The error type of `unamalla-io`.
//!
//! Every variant that is caused by the *content* of an input says where: a 1-based **line number**
//! for text formats (VTK legacy, malformed JSON), or a **JSON path** such as
//! `$.features[0].geometry.coordinates[1][3]` for well-formed JSON with the wrong content.
//! Inputs parsed from a string (not a file) are reported with the path `<string>`.

use std::io;
use std::path::PathBuf;

use unamalla_mesh::{GeometryError, MeshError};

/// Why reading or writing a file failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IoError {
    /// The operating system reported an error (open, read, write, sync, rename).
    #[error("{}: {source}", .path.display())]
    Io {
        /// The file concerned (for writes: the target file, not the temporary one).
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: io::Error,
    },

    /// The input is not valid JSON.
    #[error("{}:{line}:{column}: malformed JSON: {message}", .path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// 1-based line of the error.
        line: usize,
        /// 1-based column of the error.
        column: usize,
        /// What the JSON parser said.
        message: String,
    },

    /// A GeoJSON object has a type that cannot describe a region (e.g. `LineString`), or no type.
    #[error("{}: {json_path}: GeoJSON type {found:?} cannot be read as a region; expected {expected}", .path.display())]
    WrongGeometryType {
        /// The file.
        path: PathBuf,
        /// Where the object is.
        json_path: String,
        /// The type found.
        found: String,
        /// What would have been accepted.
        expected: &'static str,
    },

    /// A required member (`type`, `coordinates`, `geometry`, `features`, …) is missing or has the
    /// wrong JSON kind (e.g. `coordinates` is not an array).
    #[error("{}: {json_path}: {problem}", .path.display())]
    MissingMember {
        /// The file.
        path: PathBuf,
        /// Where the member was expected.
        json_path: String,
        /// What is wrong, e.g. "missing member \"coordinates\"".
        problem: String,
    },

    /// A coordinate is not a JSON number (or a position has fewer than two numbers).
    #[error("{}: {json_path}: {problem}", .path.display())]
    BadCoordinate {
        /// The file.
        path: PathBuf,
        /// Where the bad coordinate or position is.
        json_path: String,
        /// What is wrong.
        problem: String,
    },

    /// A linear ring has fewer than the 4 positions RFC 7946 requires (a closed triangle).
    #[error("{}: {json_path}: ring has {positions} position(s); a GeoJSON linear ring needs at least 4", .path.display())]
    RingTooShort {
        /// The file.
        path: PathBuf,
        /// Where the ring is.
        json_path: String,
        /// How many positions it has.
        positions: usize,
    },

    /// A `Polygon` has no rings, or a `MultiPolygon` has no polygons.
    #[error("{}: {json_path}: empty {what}", .path.display())]
    EmptyGeometry {
        /// The file.
        path: PathBuf,
        /// Where the geometry is.
        json_path: String,
        /// `"Polygon"` or `"MultiPolygon"`.
        what: &'static str,
    },

    /// The document contains no polygonal geometry at all (e.g. a `FeatureCollection` of points).
    #[error("{}: no Polygon or MultiPolygon geometry found{}", .path.display(), fmt_found(.found))]
    NoPolygon {
        /// The file.
        path: PathBuf,
        /// The geometry types that were found instead (may be empty).
        found: Vec<String>,
    },

    /// A part index was requested that does not exist.
    #[error("{}: part {index} requested, but the file has {parts} polygonal part(s) (0-based)", .path.display())]
    PartOutOfRange {
        /// The file.
        path: PathBuf,
        /// The requested index.
        index: usize,
        /// How many parts there are.
        parts: usize,
    },

    /// The selected part was read correctly but is not a valid region.
    #[error("{}: {json_path} (part {part}): invalid region: {source}", .path.display())]
    Geometry {
        /// The file.
        path: PathBuf,
        /// Where the polygon is (its `coordinates` array).
        json_path: String,
        /// Which part (0-based, in the order of [`crate::geojson`]'s part list).
        part: usize,
        /// The validation error; its vertex indices are 0-based positions in the ring as written.
        #[source]
        source: GeometryError,
    },

    /// A text file is malformed: unexpected keyword, bad number, bad header, …
    #[error("{}:{line}: {message}", .path.display())]
    Malformed {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },

    /// The file ends before a section is complete.
    #[error("{}:{line}: unexpected end of file while reading {expected}", .path.display())]
    Truncated {
        /// The file.
        path: PathBuf,
        /// 1-based number of the last line.
        line: usize,
        /// What was being read.
        expected: String,
    },

    /// A declared count disagrees with the data or with another count.
    #[error("{}:{line}: {what}: expected {expected}, found {found}", .path.display())]
    CountMismatch {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// Which count.
        what: String,
        /// What was expected.
        expected: usize,
        /// What the file says or contains.
        found: usize,
    },

    /// A feature of the format that this reader does not support (binary files, polydata, …).
    #[error("{}:{line}: unsupported: {what}", .path.display())]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is unsupported.
        what: String,
    },

    /// A VTK cell type other than quad (9) or hexahedron (12), or a mix of both.
    #[error("{}:{line}: cell {cell} has VTK type {cell_type}; only all-quad (9) or all-hexahedron (12) meshes are supported", .path.display())]
    UnsupportedCellType {
        /// The file.
        path: PathBuf,
        /// 1-based line of the offending type.
        line: usize,
        /// 0-based cell index.
        cell: usize,
        /// Its VTK type.
        cell_type: i64,
    },

    /// A 2D mesh (quads, or a structured grid with `nz = 1`) has a node with `z ≠ 0`.
    #[error("{}:{line}: node {node} has z = {z}; a 2D mesh must lie in the plane z = 0", .path.display())]
    NotPlanar {
        /// The file.
        path: PathBuf,
        /// 1-based line of the coordinate.
        line: usize,
        /// 0-based node index.
        node: usize,
        /// The offending z.
        z: f64,
    },

    /// The mesh in the file is inconsistent (node index out of range, non-finite coordinate, …).
    #[error("{}: invalid mesh: {source}", .path.display())]
    Mesh {
        /// The file.
        path: PathBuf,
        /// The mesh construction error.
        #[source]
        source: MeshError,
    },

    /// A cell data array given to a writer does not have one value per cell.
    #[error("{}: cell array {name:?} has {found} values, the mesh has {expected} cells", .path.display())]
    CellDataLength {
        /// The target file.
        path: PathBuf,
        /// The array name.
        name: String,
        /// Number of cells.
        expected: usize,
        /// Number of values given.
        found: usize,
    },

    /// A cell data value given to a writer is NaN or infinite (ASCII VTK readers disagree on how
    /// to spell those, so they are rejected).
    #[error("{}: cell array {name:?}, cell {cell}: non-finite value {value}", .path.display())]
    NonFiniteValue {
        /// The target file.
        path: PathBuf,
        /// The array name.
        name: String,
        /// The cell.
        cell: usize,
        /// The value.
        value: f64,
    },

    /// A point data array given to a writer does not have one value per node.
    #[error("{}: point array {name:?} has {found} values, the mesh has {expected} nodes", .path.display())]
    PointDataLength {
        /// The target file.
        path: PathBuf,
        /// The array name.
        name: String,
        /// Number of nodes.
        expected: usize,
        /// Number of values given.
        found: usize,
    },

    /// A point data value given to a writer is NaN or infinite.
    #[error("{}: point array {name:?}, node {node}: non-finite value {value}", .path.display())]
    NonFinitePointValue {
        /// The target file.
        path: PathBuf,
        /// The array name.
        name: String,
        /// The node.
        node: usize,
        /// The value.
        value: f64,
    },

    /// A data array name given to a writer is not usable (empty, whitespace or control
    /// characters, non-ASCII, or a duplicate). Names are rejected, never silently changed.
    #[error("{}: invalid array name {name:?}: {reason}", .path.display())]
    InvalidArrayName {
        /// The target file.
        path: PathBuf,
        /// The name.
        name: String,
        /// Why it was rejected.
        reason: &'static str,
    },
    /// A binary file is malformed (bad record marker, truncated record, impossible size, …).
    #[error("{}: byte {offset}: {message}", .path.display())]
    MalformedBinary {
        /// The file.
        path: PathBuf,
        /// 0-based byte offset where the problem was found.
        offset: u64,
        /// What is wrong.
        message: String,
    },

    /// The rings read from a contour or region file do not form a valid region.
    #[error("{}: invalid region: {source}", .path.display())]
    InvalidRegion {
        /// The file.
        path: PathBuf,
        /// The validation error (vertex indices are 0-based positions in the ring as read).
        #[source]
        source: GeometryError,
    },

    /// A boundary patch name or stretch is unusable (see [`crate::patches`]).
    #[error("boundary patch {name:?}: {reason}")]
    InvalidPatch {
        /// The patch name.
        name: String,
        /// Why it was rejected.
        reason: String,
    },

    /// A `--feature KEY=VALUE` selector matched no polygon (or is malformed).
    #[error("--feature {selector:?}: {reason}")]
    FeatureNotFound {
        /// The selector as given.
        selector: String,
        /// Why nothing was selected.
        reason: String,
    },

    /// A coordinate reference system could not be set up or applied (see [`crate::geo`]).
    #[error("coordinate system: {0}")]
    Crs(String),

    /// A named group of boundary elements given to a writer is unusable (bad name, node id out
    /// of range, duplicate name, …).
    #[error("{}: group {name:?}: {reason}", .path.display())]
    InvalidGroup {
        /// The target file.
        path: PathBuf,
        /// The group name.
        name: String,
        /// Why it was rejected.
        reason: String,
    },

    /// The input given to a writer cannot be represented in the format (e.g. a 3D Plot3D file
    /// with 2D blocks, a record too large for a Fortran record marker).
    #[error("{}: cannot write: {reason}", .path.display())]
    Unrepresentable {
        /// The target file.
        path: PathBuf,
        /// Why.
        reason: String,
    },

    /// The file is not a shapefile (its first four bytes are not the file code 9994), or a
    /// region is too large for a shapefile record; structural problems of a `.shp` file are
    /// [`IoError::MalformedBinary`] with the byte offset (see [`crate::shp`]).
    #[error("{}: shapefile: {message}", .path.display())]
    Shapefile {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

fn fmt_found(found: &[String]) -> String {
    if found.is_empty() {
        String::new()
    } else {
        format!(" (found: {})", found.join(", "))
    }
}

impl IoError {
    /// The 1-based line number the error refers to, if it has one.
    pub fn line(&self) -> Option<usize> {
        match self {
            IoError::Json { line, .. }
            | IoError::Malformed { line, .. }
            | IoError::Truncated { line, .. }
            | IoError::CountMismatch { line, .. }
            | IoError::Unsupported { line, .. }
            | IoError::UnsupportedCellType { line, .. }
            | IoError::NotPlanar { line, .. } => Some(*line),
            _ => None,
        }
    }

    /// The JSON path the error refers to, if it has one.
    pub fn json_path(&self) -> Option<&str> {
        match self {
            IoError::WrongGeometryType { json_path, .. }
            | IoError::MissingMember { json_path, .. }
            | IoError::BadCoordinate { json_path, .. }
            | IoError::RingTooShort { json_path, .. }
            | IoError::EmptyGeometry { json_path, .. }
            | IoError::Geometry { json_path, .. } => Some(json_path),
            _ => None,
        }
    }
}
