//! # unamalla-core
//!
//! The crate simulation codes add (`cargo add unamalla-core`). It re-exports the stage crates
//! and offers the high-level operations:
//!
//! * [`single_block`]: one structured grid on a roughly four-sided region by transfinite
//!   interpolation (seed 000 digest §5.1) between four arc-length-resampled sides (§4.5), with
//!   automatic corners ([`corners`], §4.2) or corners given by the user;
//! * [`bspline_maps`]: bilinear and (where certified) biquadratic B-spline maps of every block
//!   of a block mesh (seed 003, crate [`bspline`]);
//! * quality reports ([`mesh::quality::QualityReport`]) and file formats ([`io`]).
//!
//! Two products are crates of their own, added beside this one and not re-exported by it:
//! `unamalla-hex` (structured hexahedral meshes of logically hexahedral regions, Algorithms A
//! and B of seed 004) and `unamalla-pde` (the solvers that run on the meshes: elliptic PDEs on
//! curvilinear grids, the 3D Euler equations on hexahedral grids).
//!
//! ```
//! use unamalla_core::{mesh::{DVec2, Region, quality::QualityReport}, single_block};
//!
//! // a curved four-sided region
//! let mut ring = Vec::new();
//! for k in 0..20 { let t = k as f64 / 20.0; ring.push(DVec2::new(4.0 * t, 0.3 * (6.0 * t).sin())); }
//! for k in 0..10 { let t = k as f64 / 10.0; ring.push(DVec2::new(4.0, 2.0 * t)); }
//! for k in 0..20 { let t = k as f64 / 20.0; ring.push(DVec2::new(4.0 * (1.0 - t), 2.0)); }
//! for k in 0..10 { let t = k as f64 / 10.0; ring.push(DVec2::new(0.0, 2.0 * (1.0 - t))); }
//! let region = Region::new(ring, vec![]).unwrap();
//! let grid = single_block::tfi_region(&region, single_block::Corners::Auto, 41, 21).unwrap();
//! let report = QualityReport::for_quads(&grid);
//! assert_eq!(report.non_convex_cells, 0);
//! ```

#![warn(missing_docs)]
// user input reaches every stage: no unwrap/expect outside tests (issue #14)
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

pub mod bspline_maps;
pub mod corners;
pub mod curves;
pub mod flat_corners;
pub mod multilevel;
pub mod output;
pub mod pipeline;
pub mod predict;
pub mod preflight;
pub mod render;
pub mod single_block;
pub mod untangle;
pub mod verify;

/// The `glam` release whose `DVec2`/`DVec3` are the points of the whole API (re-exported so users
/// get the matching types without naming a version of their own).
pub use glam;
pub use unamalla_bspline as bspline;
pub use unamalla_compat_ilp as compat_ilp;
pub use unamalla_contour as contour;
pub use unamalla_decompose as decompose;
pub use unamalla_functionals as functionals;
pub use unamalla_io as io;
pub use unamalla_optim as optim;

/// The README's examples, compiled and run by `cargo test --doc`.
#[doc = include_str!("../../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
pub use unamalla_mesh as mesh;

/// Errors of the high-level operations.
#[derive(Debug, thiserror::Error)]
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
    Corners(String),
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
    /// The operation does not apply to this region.
    #[error("{0}")]
    Unsupported(String),
    /// A B-spline map could not be built or certified.
    #[error(transparent)]
    Bspline(#[from] unamalla_bspline::BsplineError),
    /// Submapping (seed 002) failed.
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
