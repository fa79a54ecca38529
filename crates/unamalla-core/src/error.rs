//! [`CoreError`]: the errors of the high-level operations, one variant per stage (each wraps the
//! stage crate's own typed error) plus the facade's own checks.

use crate::{corners, output, preflight, render, verify};

/// Errors of the high-level operations.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CoreError {
    /// Invalid region geometry.
    #[error(transparent)]
    Geometry(#[from] unamalla_mesh::GeometryError),
    /// A mesh operation failed.
    #[error(transparent)]
    Mesh(#[from] unamalla_mesh::MeshError),
    /// Reading or writing a file failed.
    #[error(transparent)]
    Io(#[from] unamalla_io::IoError),
    /// Corners could not be chosen or the given ones are invalid.
    #[error("corners: {0}")]
    Corners(#[from] corners::CornersError),
    /// Contour simplification failed.
    #[error(transparent)]
    Contour(#[from] unamalla_contour::ContourError),
    /// Decomposition failed or a decomposition file is invalid.
    #[error(transparent)]
    Decompose(#[from] unamalla_decompose::DecomposeError),
    /// The compatible point counts could not be found.
    #[error(transparent)]
    Counts(#[from] unamalla_compat_ilp::CompatError),
    /// Smoothing failed.
    #[error(transparent)]
    Optim(#[from] unamalla_optim::OptimError),
    /// A single TFI block was asked for a region with holes.
    #[error("the region has {holes} hole(s); a single TFI block needs a simply connected four-sided region (use the block-structured mesher)")]
    HolesInSingleBlock {
        /// Holes of the region.
        holes: usize,
    },
    /// A cell count of zero was asked for.
    #[error("--cells 0: a mesh needs at least 1 cell")]
    ZeroCells,
    /// A decomposition file was given together with the submapping strategy.
    #[error("a decomposition file and the submap strategy exclude each other")]
    DecompositionWithSubmap,
    /// No candidate layout could be built (and the concavity layout gave no error to report).
    #[error("no block layout could be built")]
    NoLayout,
    /// The cell-budget search of the compatible counts made no iteration (an empty curve set).
    #[error("no cell budget iteration ran")]
    NoCellBudget,
    /// CGNS output was asked for in a build without the `cgns` feature.
    #[error("CGNS output needs a build with the `cgns` feature (system CGNS library)")]
    CgnsNotBuilt,
    /// A picture could not be made ([`render`]).
    #[error(transparent)]
    Render(#[from] render::RenderError),
    /// Writing the output directory failed ([`output`]).
    #[error(transparent)]
    Output(#[from] output::OutputError),
    /// Serializing a JSON output failed.
    #[error("writing JSON: {0}")]
    Json(#[from] serde_json::Error),
    /// A B-spline map could not be built or certified.
    #[error(transparent)]
    Bspline(#[from] unamalla_bspline::BsplineError),
    /// Submapping [Ruiz-Gironés & Sarrate] failed.
    #[error(transparent)]
    Submap(#[from] unamalla_decompose::submap::SubmapError),
    /// The finished mesh failed the independent check ([`verify`]).
    #[error(transparent)]
    Guarantee(#[from] verify::GuaranteeNotMet),
    /// A size is beyond the memory limit, or a region is beyond what a stage can handle
    /// ([`preflight`]).
    #[error(transparent)]
    Preflight(#[from] preflight::PreflightError),
}
