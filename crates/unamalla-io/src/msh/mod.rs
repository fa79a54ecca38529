//! Gmsh MSH 4.1 ASCII files (`gmsh.texi`, "MSH file format"), with named boundary groups.
//!
//! # Writing
//!
//! [`write_msh_quads`] (2D) and [`write_msh_hexes`] (3D) write
//!
//! * `$MeshFormat` `4.1 0 8`;
//! * `$PhysicalNames`: the cells' group (`domain`, dimension 2 or 3, physical tag 1) and every
//!   boundary group (dimension 1 or 2, physical tags 2, 3, … in the order given);
//! * `$Entities`: one surface (2D) or volume (3D) entity, tag 1, carrying the domain's physical
//!   tag, and one curve (2D) or surface (3D) entity per group, tags 1, 2, …, each carrying its
//!   group's physical tag, with bounding boxes;
//! * `$Nodes`: one block with every node (tags `1..=N` = node id + 1), classified on the domain
//!   entity, `z = 0` in 2D;
//! * `$Elements`: the cells (quads, type 3, or hexahedra, type 5, tags `1..=C`), then each
//!   group's line elements (type 1, 2D) or quads (type 3, 3D) on its own entity, tags continuing.
//!
//! The mesher passes its rings and cuts as groups: [`EdgeGroup`]s of node-id pairs in 2D
//! ([`boundary_edge_groups`] computes `outer`, `hole-1`, … from a quad mesh), [`FaceGroup`]s of
//! quads in 3D ([`hex_boundary_faces`] lists the boundary faces of a hex mesh). Groups are
//! validated before the file is touched ([`IoError::InvalidGroup`](crate::IoError::InvalidGroup)): names non-empty, without
//! `"` or control characters, distinct from each other and from the domain name; node ids in
//! range. Files are replaced atomically; coordinates use the shortest round-trip decimal form.
//!
//! # Reading
//!
//! [`read_msh`] / [`parse_msh`] read MSH 4.1 ASCII (other versions and binary files are
//! [`IoError::Unsupported`](crate::IoError::Unsupported)): `$MeshFormat`, `$PhysicalNames`, `$Entities`, `$Nodes`
//! (parametric coordinates are skipped), `$Elements`; other sections are skipped. Nodes keep
//! their file order (node id = position in `$Nodes`). If there are hexahedra (type 5) the mesh
//! is a [`HexMesh`](unamalla_mesh::HexMesh) and quads (type 3) on entities with physical groups form [`FaceGroup`]s;
//! otherwise the quads form a [`QuadMesh`](unamalla_mesh::QuadMesh) (every `z` must be 0) and lines (type 1) on entities
//! with physical groups form [`EdgeGroup`]s. Groups are named by `$PhysicalNames` (unnamed
//! physical groups are called `physical-<tag>`) and ordered by physical tag. Points (type 15)
//! and boundary elements without a physical group are ignored; triangles, tetrahedra, prisms,
//! pyramids and higher-order elements are [`IoError::Unsupported`](crate::IoError::Unsupported). Errors carry line numbers.
//!
//! Files: `write` (the writers), `read` (the reader), `boundary` (boundary loops and faces of
//! a mesh, for the groups); the element type numbers and the group types are here.

mod boundary;
mod read;
mod write;

pub use boundary::{boundary_edge_groups, boundary_loops, hex_boundary_faces};
pub use read::{parse_msh, read_msh, MshFile, MshMesh};
pub use write::{write_msh_blocks, write_msh_hexes, write_msh_quads};

/// Gmsh element type of a 2-node line.
pub const MSH_LINE: u32 = 1;
/// Gmsh element type of a 4-node quadrangle.
pub const MSH_QUAD: u32 = 3;
/// Gmsh element type of an 8-node hexahedron.
pub const MSH_HEX: u32 = 5;
/// Gmsh element type of a 1-node point.
pub const MSH_POINT: u32 = 15;

/// A named group of boundary edges of a 2D mesh (written as line elements, type 1).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EdgeGroup {
    /// The physical group name, e.g. `"outer"`, `"hole-1"`, `"cut-3"`.
    pub name: String,
    /// The edges as node-id pairs (0-based ids of the mesh).
    pub edges: Vec<[usize; 2]>,
}

/// A named group of boundary faces of a 3D mesh (written as quad elements, type 3).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FaceGroup {
    /// The physical group name.
    pub name: String,
    /// The faces as 4 node ids (0-based), ideally ordered so the normal points out.
    pub faces: Vec<[usize; 4]>,
}

/// One closed chain of boundary edges of a quad mesh (see [`boundary_loops`]).
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryLoop {
    /// The edges in order, each oriented as in its cell (domain on the left), so consecutive
    /// edges share a node and the last edge ends where the first starts.
    pub edges: Vec<[usize; 2]>,
    /// Signed area enclosed by the loop: positive for an outer boundary (counter-clockwise),
    /// negative for a hole (clockwise).
    pub signed_area: f64,
}
