//! The error type of the hexahedral generators.

use crate::error::MeshError;

/// Why a hexahedral region or generator input was rejected. Faces are named as in
/// [`HexFaceId`](super::HexFaceId) (`i_min` … `k_max`, with the thesis's names M1–M6 in the
/// message), nodes by their 0-based logical indices `(i, j, k)` in the volume grid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum HexGenError {
    /// A size is too small (a logically hexahedral region needs at least 2 nodes per
    /// direction; some functions need more, e.g. appendix A needs 4).
    #[error("invalid size {dims:?}: {reason}")]
    TooSmall {
        /// The offending sizes.
        dims: (usize, usize, usize),
        /// What was required.
        reason: &'static str,
    },
    /// A face grid has the wrong number of points for the region's sizes.
    #[error("face {face} has {got} points; a {m} × {n} × {p} region needs {expected}")]
    FaceSize {
        /// The face.
        face: &'static str,
        /// Number of points given.
        got: usize,
        /// Number expected.
        expected: usize,
        /// Region sizes.
        m: usize,
        /// Region sizes.
        n: usize,
        /// Region sizes.
        p: usize,
    },
    /// Two opposite faces have different grid sizes.
    #[error(
        "opposite faces {face_a} ({a0} × {a1}) and {face_b} ({b0} × {b1}) must have the same size"
    )]
    OppositeSizes {
        /// First face.
        face_a: &'static str,
        /// Its size.
        a0: usize,
        /// Its size.
        a1: usize,
        /// Opposite face.
        face_b: &'static str,
        /// Its size.
        b0: usize,
        /// Its size.
        b1: usize,
    },
    /// Two adjacent faces disagree on a node of their shared edge.
    #[error("faces {face_a} and {face_b} disagree at node ({i}, {j}, {k}) of their shared edge (distance {distance:e})")]
    EdgeMismatch {
        /// First face.
        face_a: &'static str,
        /// Second face.
        face_b: &'static str,
        /// Node index i.
        i: usize,
        /// Node index j.
        j: usize,
        /// Node index k.
        k: usize,
        /// Distance between the two faces' points.
        distance: f64,
    },
    /// A coordinate is NaN or infinite.
    #[error("{what}: point {index} has a non-finite coordinate")]
    NonFinite {
        /// Which input (a face name, "data", …).
        what: &'static str,
        /// The point's index in that input.
        index: usize,
    },
    /// A parameter is out of range.
    #[error("parameter {name} = {value}: {reason}")]
    InvalidParameter {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The requirement.
        reason: &'static str,
    },
    /// Scattered data cannot define a surface (e.g. no points).
    #[error("scattered data: {0}")]
    Data(String),
    /// An underlying mesh operation failed.
    #[error(transparent)]
    Mesh(#[from] MeshError),
}
