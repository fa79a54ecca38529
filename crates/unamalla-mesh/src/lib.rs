//! # unamalla-mesh
//!
//! The foundation of the unamalla crate family: geometry primitives, validated polygonal
//! regions with holes, structured and unstructured quad/hex meshes, **the mesh traits every
//! other crate is written against**, transfinite interpolation and quality metrics.
//!
//! Conventions (also in `docs/conventions.md`):
//! * coordinates are `f64`; points are [`glam::DVec2`] / [`glam::DVec3`] (re-exported here);
//! * regions: outer ring counter-clockwise, holes clockwise, rings stored open;
//! * structured 2D grid node `(i, j)`, `i` along the bottom side, `j` upward; cells
//!   counter-clockwise `(i,j), (i+1,j), (i+1,j+1), (i,j+1)`;
//! * α (triangle measure) is the doubled signed area `det(Q − P, R − P)`.

// No unwrap/expect in library code: user input must give an error, never a panic (see
// docs/reliability.md).
// Tests and doc examples may use them.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

pub mod block;
pub mod error;
pub mod geometry;
pub mod grid;
pub mod hexgen;
pub mod quality;
pub mod rectilinear;
pub mod refine;
pub mod region;
pub mod resample;
pub mod spatial;
pub mod svg;
pub mod tfi;
pub mod traits;
pub mod unstructured;

pub use block::BlockMesh2;
pub use error::{GeometryError, MeshError, RingId};
pub use geometry::Location;
pub use glam::{DVec2, DVec3};
pub use grid::{StructuredGrid2, StructuredGrid3};
pub use quality::{HexMetrics, QuadMetrics, QualityReport, ReportOptions};
pub use region::{Polygon, Region};
pub use resample::resample_arc_length;
pub use spatial::{EdgeRef, SegmentIndex};
pub use tfi::{tfi2, tfi3, HexFaces, TfiParams};
pub use traits::{FreeNodes, HasHexCells, HasNodes, HasQuadCells};
pub use unstructured::{HexMesh, QuadMesh, HEX_FACES};
