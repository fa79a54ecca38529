//! # unamalla-core
//!
//! The crate users add (`cargo add unamalla-core`): a region with holes in, a
//! block-structured, singularity-free, all-convex quadrilateral mesh out.
//!
//! ```no_run
//! use unamalla_core::prelude::*;
//!
//! let region = unamalla_core::io::read_region_geojson(
//!     "fixtures/regions/puget-sound.geojson", Default::default())?;
//! let result = Mesher::new().cells(20_000).mesh(&region)?;
//! assert_eq!(result.report.non_convex_cells, 0); // checked by the mesher itself
//! assert_eq!(result.report.interior_singularities, 0);
//! // mesh.vtu, block-K.vts, mesh.msh, mesh.su2, openfoam/, report.json, pictures
//! result.write_all("out/puget-sound", &OutputOptions::default())?;
//! # Ok::<(), unamalla_core::CoreError>(())
//! ```
//!
//! [`Mesher`] runs the whole job ([`pipeline`] explains each stage and its sources): contour
//! simplification, decomposition into four-sided blocks by cuts ([Méndez 2023, Ch. 4], or
//! submapping [Ruiz-Gironés & Sarrate]), compatible point counts across the cuts (an integer
//! program), transfinite interpolation per block, merging into one conformal mesh, and
//! smoothing with the convexity-preserving functional
//! `F = (1−σ)·F_AO + σ·H_ω` (area–orthogonality and the adaptive harmonic functional),
//! islands at the cell scale carved into the smoothed mesh instead of bridged by cuts
//! ([`carve`]), then an independent check ([`verify`]) — a mesh with a non-convex cell is never returned
//! as a success. [`MeshResult::write_all`] writes the file set of `unamalla mesh`
//! ([`write`](mod@write)); [`MeshReport`] is its `report.json`.
//!
//! Other operations:
//!
//! * [`single_block`]: one structured grid on a roughly four-sided region by transfinite
//!   interpolation between four arc-length-resampled sides, with automatic corners
//!   ([`corners`]) or corners given by the user;
//! * [`bspline_maps`]: bilinear and (where certified) biquadratic B-spline maps of every block
//!   of a block mesh (crate [`bspline`], [Abelló et al.]);
//! * quality reports ([`mesh::quality::QualityReport`]) and file formats ([`io`]).
//!
//! The stage crates are re-exported ([`mesh`], [`io`], [`contour`], [`decompose`],
//! [`compat_ilp`], [`functionals`], [`optim`], [`bspline`]) together with [`glam`], whose
//! `DVec2`/`DVec3` are the points of the whole API. Two products are crates of their own,
//! added beside this one and not re-exported by it: `unamalla-hex` (structured hexahedral
//! meshes of logically hexahedral regions, Algorithms A and B of [Cortés Aguirre 2012]) and
//! `unamalla-pde` (elliptic PDEs on curvilinear grids, the 3D Euler equations on hexahedral
//! grids). The sources are listed in `docs/references.md` of the repository.
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

// user input reaches every stage: no unwrap/expect outside tests (docs/reliability.md)
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

pub mod bspline_maps;
pub mod carve;
pub mod corners;
pub mod curves;
mod error;
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
pub mod write;

pub use error::CoreError;
pub use pipeline::{MeshReport, MeshResult, MeshSize, Mesher, Stage, Strategy};
pub use write::OutputOptions;

/// The names the main job needs: `use unamalla_core::prelude::*;`.
pub mod prelude {
    pub use crate::mesh::{DVec2, Region};
    pub use crate::pipeline::{MeshReport, MeshResult, MeshSize, Mesher, Stage, Strategy};
    pub use crate::write::OutputOptions;
    pub use crate::CoreError;
}

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
