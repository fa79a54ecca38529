//! The error type of `unamalla-contour`.

use unamalla_mesh::GeometryError;

/// Why a simplification could not be carried out.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ContourError {
    /// A method name that is not one of [`crate::Method::NAMES`].
    #[error("unknown simplification method `{name}`; valid methods: {valid}")]
    UnknownMethod {
        /// The name that was given.
        name: String,
        /// The valid names, comma separated.
        valid: String,
    },
    /// A numeric parameter is out of its admissible range (NaN, infinite, negative, …).
    #[error("invalid parameter {name} = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name (`epsilon`, `delta`, `min_hole_area`, …).
        name: &'static str,
        /// The value given.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
    /// A ring given to a ring-level function is unusable (too few points, non-finite
    /// coordinates, repeated consecutive points, zero perimeter).
    #[error("degenerate ring: {0}")]
    DegenerateRing(String),
    /// Vertex indices that do not describe a subsequence of a ring (see
    /// [`crate::subset_hausdorff`]): empty, out of range or not strictly increasing.
    #[error("invalid kept-vertex indices: {0}")]
    InvalidIndices(String),
    /// The final validation of the simplified region failed. The removal and repair steps
    /// are designed so that this cannot happen; if it does, no invalid region is returned.
    #[error("the simplified region failed validation: {0}")]
    InvalidResult(#[from] GeometryError),
}
