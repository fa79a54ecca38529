//! The error type of the hexahedral product.

use std::path::PathBuf;

use unamalla_functionals::FunctionalError;
use unamalla_io::IoError;
use unamalla_mesh::hexgen::HexGenError;
use unamalla_optim::OptimError;

/// Errors of the hexahedral pipeline.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum HexError {
    /// A generator or region check failed.
    #[error(transparent)]
    Gen(#[from] HexGenError),
    /// The optimiser failed.
    #[error(transparent)]
    Optim(#[from] OptimError),
    /// The functional could not be set up.
    #[error(transparent)]
    Functional(#[from] FunctionalError),
    /// Writing an output file failed.
    #[error(transparent)]
    Io(#[from] IoError),
    /// A face-grid file could not be read or parsed.
    #[error("{}: line {line}: {reason}", path.display())]
    FaceFile {
        /// The file.
        path: PathBuf,
        /// 1-based line number (0 when the file could not be opened).
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// The case name is not a built-in region.
    #[error("unknown hex case '{0}'; built-in cases: sphere, ellipsoid, box, pico, cosin, shell, parabs, elipsoideg, yacimiento, sydney (or a directory of six face grids)")]
    UnknownCase(String),
    /// Some fixed tetrahedron has `V ≤ 0` (Def. 11): no interior node can repair it.
    #[error("the region is not admissible: fixed tetrahedron {tet} of cell {cell} has V = {v:e} ≤ 0 ({count} such tetrahedra)")]
    Inadmissible {
        /// First offending cell.
        cell: usize,
        /// Its tetrahedron (row of the 10-tetrahedra table).
        tet: usize,
        /// Its `V`.
        v: f64,
        /// Number of offending tetrahedra.
        count: usize,
    },
}
