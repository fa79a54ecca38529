//! The error type of the crate.

use unamalla_functionals::FunctionalError;
use unamalla_mesh::MeshError;

/// Errors of the optimizers and drivers. Anything a user's input can cause is reported here;
/// a run that merely fails to converge is not an error but a [`Status`](crate::Status).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OptimError {
    /// Building or re-parametrizing a functional failed (e.g. non-finite node coordinates).
    #[error("functional: {0}")]
    Functional(#[from] FunctionalError),
    /// A mesh operation failed.
    #[error("mesh: {0}")]
    Mesh(#[from] MeshError),
    /// The mesh has no free node: there is nothing to optimize.
    #[error("the mesh has no free nodes; nothing to optimize")]
    NoFreeNodes,
    /// The starting point contains NaN or infinite coordinates.
    #[error("the starting point has a non-finite coordinate at variable {index}")]
    NonFiniteStart {
        /// Index of the first offending variable.
        index: usize,
    },
    /// The functional is not finite (or its gradient is not) at the starting point.
    #[error("the functional or its gradient is not finite at the starting point (F = {value})")]
    NonFiniteValue {
        /// The value found.
        value: f64,
    },
    /// An option is out of range.
    #[error("invalid option {name} = {value}: {reason}")]
    InvalidOption {
        /// Option name.
        name: &'static str,
        /// Offending value.
        value: f64,
        /// Why it is invalid.
        reason: &'static str,
    },
    /// A solver or functional name was not recognised.
    #[error("unknown {what} `{name}` (expected one of: {expected})")]
    UnknownName {
        /// What kind of name (solver, functional).
        what: &'static str,
        /// The name given.
        name: String,
        /// The accepted names.
        expected: &'static str,
    },
}
