//! VTK legacy ASCII files (docs.vtk.org, "Simple Legacy Formats").
//!
//! # Writing
//!
//! [`write_vtk_structured2`], [`write_vtk_structured3`], [`write_vtk_quads`] and
//! [`write_vtk_hexes`] write `# vtk DataFile Version 3.0` ASCII files:
//!
//! * structured grids as `DATASET STRUCTURED_GRID` with `DIMENSIONS m n 1` (2D, `z = 0`) or
//!   `DIMENSIONS m n p`; the node order of [`StructuredGrid2`](unamalla_mesh::StructuredGrid2)
//!   / [`StructuredGrid3`](unamalla_mesh::StructuredGrid3) is already VTK's x-fastest order;
//! * unstructured meshes as `DATASET UNSTRUCTURED_GRID` with `CELLS`/`CELL_TYPES`, quads of
//!   type 9 (2D, `z = 0`) and hexahedra of type 12 (VTK vertex order, the crate family's order);
//! * every cell array as `SCALARS <name> double 1` + `LOOKUP_TABLE default` in `CELL_DATA`
//!   (the section is omitted when there are no arrays);
//! * [`write_vtk_structured2_with_point_data`] and [`write_vtk_quads_with_point_data`] add
//!   per-node arrays the same way in a `POINT_DATA` section after `CELL_DATA` (e.g. a PDE
//!   solution `u`), checked like the cell arrays (one finite value per node,
//!   [`IoError::PointDataLength`](crate::IoError::PointDataLength),
//!   [`IoError::NonFinitePointValue`](crate::IoError::NonFinitePointValue)).
//!
//! Coordinates and values are written with the shortest representation that parses back to
//! the same `f64` bits, so a write/read round trip is exact. Before anything is written, each
//! cell array is checked: one value per cell
//! ([`IoError::CellDataLength`](crate::IoError::CellDataLength)), finite values
//! ([`IoError::NonFiniteValue`](crate::IoError::NonFiniteValue)), and a name that is
//! non-empty, printable ASCII without whitespace and not used twice
//! ([`IoError::InvalidArrayName`](crate::IoError::InvalidArrayName); names are rejected, never
//! rewritten). Files are replaced atomically ([`crate::atomic_write`]).
//!
//! # Reading
//!
//! [`read_vtk`] / [`parse_vtk`] read what the writers write and what other tools (VTK, ParaView,
//! meshio) write in the same subset:
//!
//! * header `# vtk DataFile Version x.y`, any title, `ASCII` (`BINARY` is reported as
//!   [`IoError::Unsupported`](crate::IoError::Unsupported)); keywords are case-insensitive
//!   and numbers may be split over lines arbitrarily;
//! * `STRUCTURED_GRID`: `DIMENSIONS m n 1` becomes [`VtkMesh::Structured2`] (every `z` must be
//!   0), `DIMENSIONS m n p` with `m, n, p ≥ 2` becomes [`VtkMesh::Structured3`]; `nx = 1` or
//!   `ny = 1` with `nz > 1` is unsupported;
//! * `UNSTRUCTURED_GRID` whose cells are all type 9 ([`VtkMesh::Quads`], every `z` must be 0)
//!   or all type 12 ([`VtkMesh::Hexes`]); `CELLS` in the classic form and in the VTK 5.1
//!   `OFFSETS`/`CONNECTIVITY` form;
//! * `CELL_DATA` and `POINT_DATA`: one-component `SCALARS` (with or without `LOOKUP_TABLE`) and
//!   one-component `FIELD` arrays are kept; `VECTORS`, `NORMALS`, `TENSORS`,
//!   `TEXTURE_COORDINATES`, `COLOR_SCALARS`, lookup-table definitions and multi-component arrays
//!   are skipped; VTK 5 `METADATA` blocks are skipped; dataset-level `FIELD` data is skipped.
//!
//! Malformed or truncated input, unsupported cell types and inconsistent counts are typed
//! errors with 1-based line numbers; the reader never panics and never trusts a declared count
//! for a large allocation.

mod read;
mod sections;
mod write;

pub use read::{parse_vtk, read_vtk, VtkFile, VtkMesh};
pub(crate) use write::check_cell_data;
pub use write::{
    write_vtk_hexes, write_vtk_quads, write_vtk_quads_with_point_data, write_vtk_structured2,
    write_vtk_structured2_with_point_data, write_vtk_structured3, CellData, PointData,
    VTK_HEXAHEDRON, VTK_QUAD,
};
