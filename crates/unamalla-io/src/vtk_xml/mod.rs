//! VTK XML files: `.vts` (structured grid), `.vtu` (unstructured grid), `.vtm` (multiblock
//! index); ASCII data arrays, binary (base64) ones above [`BINARY_THRESHOLD_POINTS`] points.
//!
//! # Writing
//!
//! * [`write_vts2`] / [`write_vts3`]: one structured block as `<VTKFile type="StructuredGrid">`
//!   with `WholeExtent = Piece Extent = "0 m-1 0 n-1 0 p-1"` (`0 0` for `k` in 2D), points as
//!   a `Float64` array of 3 components in the grid's node order (i fastest, which is VTK's
//!   order; `z = 0` in 2D), cell arrays as `Float64` `<CellData>` arrays in cell order.
//! * [`write_vtu_quads`] / [`write_vtu_hexes`]: `<VTKFile type="UnstructuredGrid">` with
//!   `Int64` `connectivity` and `offsets` and `UInt8` `types` (9 = quad, 12 = hexahedron).
//! * [`write_vtm`]: a `vtkMultiBlockDataSet` index whose `<DataSet file="…">` entries are the
//!   given paths, written relative to the index (ParaView opens the index and loads them).
//! * [`write_block_mesh`]: a whole [`BlockMesh2`](unamalla_mesh::BlockMesh2) in one call — `block-K.vts` per block,
//!   `blocks.vtm` indexing them and `mesh.vtu` for the global conformal mesh.
//!
//! Meshes with more than [`BINARY_THRESHOLD_POINTS`] points get binary data arrays.
//!
//! Every file is written atomically ([`crate::atomic_write`]); cell arrays are validated first
//! exactly like the legacy writers do (one finite value per cell, printable ASCII names without
//! whitespace, no duplicates). Numbers use the shortest round-trip representation, so a
//! write/read round trip is bit-exact.
//!
//! # Reading
//!
//! [`read_vtk_xml`] / [`parse_vtk_xml`] read `.vts` and `.vtu` files in ASCII format (the subset
//! the writers produce, and what VTK/ParaView/meshio write with `format="ascii"`) into the same
//! [`VtkFile`](crate::vtk::VtkFile) the legacy reader returns (its `title` is empty). One `<Piece>` whose extent is
//! the whole extent; unstructured grids of all quads or all hexahedra. Binary data arrays
//! (`format="binary"`: base64, uncompressed, `UInt64` or `UInt32` header — what the writers
//! produce above the threshold and VTK/meshio write with `binary`) are read too; `appended`
//! and compressed arrays are reported as [`IoError::Unsupported`](crate::IoError::Unsupported). [`read_vtm`] lists the data sets of a
//! `.vtm`, resolved against its directory. Errors carry 1-based line numbers.
//!
//! Files: `write` (the writers), `read` (the readers), `binary` (base64 data arrays, both
//! ways).

mod binary;
mod read;
mod write;

pub use binary::BINARY_THRESHOLD_POINTS;
pub use read::{parse_vtk_xml, read_vtk_xml, read_vtm, VtmEntry};
pub use write::{
    write_block_mesh, write_vtm, write_vts2, write_vts3, write_vtu_hexes, write_vtu_quads,
    BlockMeshFiles,
};
