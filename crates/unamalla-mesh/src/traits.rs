//! The mesh traits every other crate is written against.
//!
//! The functionals and optimizers never look at a concrete mesh type: they ask for the node
//! coordinates ([`HasNodes`]), the cell connectivity ([`HasQuadCells`] / [`HasHexCells`]) and
//! which nodes are variables ([`FreeNodes`]). A single [`StructuredGrid2`](crate::StructuredGrid2),
//! the global mesh of a [`BlockMesh2`](crate::BlockMesh2) and a [`QuadMesh`](crate::QuadMesh) read
//! from a file all implement them, so the same code optimizes all three.
//!
//! Conventions (see `docs/conventions.md`):
//! * quad cells are listed counter-clockwise `[p0, p1, p2, p3]`; for a structured grid this is
//!   `(i,j), (i+1,j), (i+1,j+1), (i,j+1)`;
//! * hex cells use VTK/Gmsh order: `0..4` the bottom face counter-clockwise seen from above,
//!   `4..8` the nodes above them.

use glam::{DVec2, DVec3};

/// A mesh that owns an array of node coordinates of type `P` (`DVec2` or `DVec3`).
pub trait HasNodes<P> {
    /// All node coordinates, indexed by node id.
    fn nodes(&self) -> &[P];
    /// Mutable access to the node coordinates (the connectivity cannot change through it).
    fn nodes_mut(&mut self) -> &mut [P];
    /// Number of nodes.
    fn num_nodes(&self) -> usize {
        self.nodes().len()
    }
}

/// A planar mesh made of quadrilateral cells, each listed counter-clockwise.
pub trait HasQuadCells: HasNodes<DVec2> {
    /// Number of quad cells.
    fn num_quads(&self) -> usize;
    /// The four node ids of cell `c`, counter-clockwise. Panics if `c >= num_quads()`
    /// (cell ids are produced by the mesh itself, never by user input).
    fn quad(&self, c: usize) -> [usize; 4];
    /// The four corner points of cell `c`.
    fn quad_points(&self, c: usize) -> [DVec2; 4] {
        let q = self.quad(c);
        let x = self.nodes();
        [x[q[0]], x[q[1]], x[q[2]], x[q[3]]]
    }
}

/// A volume mesh made of hexahedral cells in VTK/Gmsh vertex order.
pub trait HasHexCells: HasNodes<DVec3> {
    /// Number of hexahedral cells.
    fn num_hexes(&self) -> usize;
    /// The eight node ids of cell `c` in VTK order. Panics if `c >= num_hexes()`.
    fn hex(&self, c: usize) -> [usize; 8];
    /// The eight corner points of cell `c`.
    fn hex_points(&self, c: usize) -> [DVec3; 8] {
        let h = self.hex(c);
        let x = self.nodes();
        std::array::from_fn(|k| x[h[k]])
    }
}

/// Which nodes are variables of an optimization (free) and which are data (fixed).
pub trait FreeNodes {
    /// `true` if node `v` must not move.
    fn is_fixed(&self, v: usize) -> bool;
    /// Total number of nodes the flags refer to.
    fn num_flagged_nodes(&self) -> usize;
    /// The free node ids in increasing order.
    fn free_nodes(&self) -> Vec<usize> {
        (0..self.num_flagged_nodes())
            .filter(|&v| !self.is_fixed(v))
            .collect()
    }
    /// Number of free nodes.
    fn num_free(&self) -> usize {
        (0..self.num_flagged_nodes())
            .filter(|&v| !self.is_fixed(v))
            .count()
    }
}
