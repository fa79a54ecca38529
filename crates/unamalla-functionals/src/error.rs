//! The error type of the crate.

use thiserror::Error;

/// Everything a user's input (mesh, parameters, functional names) can get wrong.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum FunctionalError {
    /// A functional name given to [`FunctionalSpec::from_name`](crate::FunctionalSpec::from_name)
    /// is not known.
    #[error("unknown functional `{name}`; valid names: {valid}")]
    UnknownFunctional {
        /// The name that was asked for.
        name: String,
        /// Comma-separated list of the accepted names.
        valid: String,
    },
    /// A parameter is outside its domain (e.g. `ω ≤ 0`, a non-finite value, `α̂ ≤ −k`).
    #[error("invalid parameter {name} = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// Why it is rejected.
        reason: String,
    },
    /// A cell references a node id that does not exist.
    #[error("cell {cell} references node {node} but the mesh has {num_nodes} nodes")]
    NodeOutOfRange {
        /// Cell id.
        cell: usize,
        /// Offending node id.
        node: usize,
        /// Number of nodes of the mesh.
        num_nodes: usize,
    },
    /// Per-cell or per-node data has the wrong length.
    #[error("{what} has length {got}, expected {expected}")]
    LengthMismatch {
        /// What the data is.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The expected length.
        expected: usize,
    },
    /// The mesh has no cells (or more nodes / cells than the 32-bit indices used internally).
    #[error("unsupported mesh size: {0}")]
    UnsupportedSize(String),
    /// A node coordinate is NaN or infinite.
    #[error("node {node} has a non-finite coordinate")]
    NonFinite {
        /// Node id.
        node: usize,
    },
}
