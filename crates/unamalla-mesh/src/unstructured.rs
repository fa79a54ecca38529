//! Unstructured conformal quad and hex meshes: an array of nodes, an array of cells and a
//! per-node *fixed* flag (boundary nodes by default).

use std::collections::HashMap;

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::error::MeshError;
use crate::grid::{StructuredGrid2, StructuredGrid3};
use crate::traits::{FreeNodes, HasHexCells, HasNodes, HasQuadCells};

/// The six faces of a VTK-ordered hexahedron, each listed so that its normal points **out** of a
/// positively oriented cell: bottom, top, front (`y` min), right, back, left.
pub const HEX_FACES: [[usize; 4]; 6] = [
    [0, 3, 2, 1],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
];

/// An unstructured conformal quadrilateral mesh.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QuadMesh {
    nodes: Vec<DVec2>,
    cells: Vec<[usize; 4]>,
    fixed: Vec<bool>,
}

impl QuadMesh {
    /// Builds a mesh; node ids in `cells` must be in range and coordinates finite. Nodes on the
    /// boundary (edges used by exactly one cell) are marked fixed.
    pub fn new(nodes: Vec<DVec2>, cells: Vec<[usize; 4]>) -> Result<Self, MeshError> {
        check_cells(nodes.len(), &cells)?;
        if let Some(v) = nodes.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFinite { node: v });
        }
        let fixed = quad_boundary_flags(nodes.len(), &cells);
        Ok(Self {
            nodes,
            cells,
            fixed,
        })
    }

    /// The mesh of a structured grid (same node numbering, cells in grid order).
    pub fn from_grid(g: &StructuredGrid2) -> Self {
        let cells = (0..g.num_quads()).map(|c| g.quad(c)).collect();
        let fixed = (0..g.num_nodes()).map(|v| g.is_fixed(v)).collect();
        Self {
            nodes: g.nodes().to_vec(),
            cells,
            fixed,
        }
    }

    /// All cells.
    pub fn cells(&self) -> &[[usize; 4]] {
        &self.cells
    }
    /// The fixed flags, one per node.
    pub fn fixed(&self) -> &[bool] {
        &self.fixed
    }
    /// Replaces the fixed flags (length must equal the number of nodes).
    pub fn set_fixed(&mut self, fixed: Vec<bool>) -> Result<(), MeshError> {
        if fixed.len() != self.nodes.len() {
            return Err(MeshError::InvalidSize(format!(
                "{} fixed flags for {} nodes",
                fixed.len(),
                self.nodes.len()
            )));
        }
        self.fixed = fixed;
        Ok(())
    }
    /// Boundary flags computed from the connectivity (edges used by exactly one cell).
    pub fn boundary_flags(&self) -> Vec<bool> {
        quad_boundary_flags(self.nodes.len(), &self.cells)
    }
}

impl HasNodes<DVec2> for QuadMesh {
    fn nodes(&self) -> &[DVec2] {
        &self.nodes
    }
    fn nodes_mut(&mut self) -> &mut [DVec2] {
        &mut self.nodes
    }
}

impl HasQuadCells for QuadMesh {
    fn num_quads(&self) -> usize {
        self.cells.len()
    }
    #[inline]
    fn quad(&self, c: usize) -> [usize; 4] {
        self.cells[c]
    }
}

impl FreeNodes for QuadMesh {
    fn is_fixed(&self, v: usize) -> bool {
        self.fixed[v]
    }
    fn num_flagged_nodes(&self) -> usize {
        self.fixed.len()
    }
}

/// An unstructured conformal hexahedral mesh (VTK vertex order).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HexMesh {
    nodes: Vec<DVec3>,
    cells: Vec<[usize; 8]>,
    fixed: Vec<bool>,
}

impl HexMesh {
    /// Builds a mesh; nodes on boundary faces (faces used by exactly one cell) are marked fixed.
    pub fn new(nodes: Vec<DVec3>, cells: Vec<[usize; 8]>) -> Result<Self, MeshError> {
        check_cells(nodes.len(), &cells)?;
        if let Some(v) = nodes.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFinite { node: v });
        }
        let fixed = hex_boundary_flags(nodes.len(), &cells);
        Ok(Self {
            nodes,
            cells,
            fixed,
        })
    }

    /// The mesh of a structured 3D grid (same numbering).
    pub fn from_grid(g: &StructuredGrid3) -> Self {
        let cells = (0..g.num_hexes()).map(|c| g.hex(c)).collect();
        let fixed = (0..g.num_nodes()).map(|v| g.is_fixed(v)).collect();
        Self {
            nodes: g.nodes().to_vec(),
            cells,
            fixed,
        }
    }

    /// All cells.
    pub fn cells(&self) -> &[[usize; 8]] {
        &self.cells
    }
    /// The fixed flags, one per node.
    pub fn fixed(&self) -> &[bool] {
        &self.fixed
    }
    /// Replaces the fixed flags (length must equal the number of nodes).
    pub fn set_fixed(&mut self, fixed: Vec<bool>) -> Result<(), MeshError> {
        if fixed.len() != self.nodes.len() {
            return Err(MeshError::InvalidSize(format!(
                "{} fixed flags for {} nodes",
                fixed.len(),
                self.nodes.len()
            )));
        }
        self.fixed = fixed;
        Ok(())
    }
}

impl HasNodes<DVec3> for HexMesh {
    fn nodes(&self) -> &[DVec3] {
        &self.nodes
    }
    fn nodes_mut(&mut self) -> &mut [DVec3] {
        &mut self.nodes
    }
}

impl HasHexCells for HexMesh {
    fn num_hexes(&self) -> usize {
        self.cells.len()
    }
    #[inline]
    fn hex(&self, c: usize) -> [usize; 8] {
        self.cells[c]
    }
}

impl FreeNodes for HexMesh {
    fn is_fixed(&self, v: usize) -> bool {
        self.fixed[v]
    }
    fn num_flagged_nodes(&self) -> usize {
        self.fixed.len()
    }
}

fn check_cells<const K: usize>(num_nodes: usize, cells: &[[usize; K]]) -> Result<(), MeshError> {
    for (c, cell) in cells.iter().enumerate() {
        if let Some(&node) = cell.iter().find(|&&v| v >= num_nodes) {
            return Err(MeshError::NodeOutOfRange {
                cell: c,
                node,
                num_nodes,
            });
        }
    }
    Ok(())
}

/// Nodes on edges that belong to exactly one quad.
fn quad_boundary_flags(num_nodes: usize, cells: &[[usize; 4]]) -> Vec<bool> {
    let mut flags = vec![false; num_nodes];
    for ((a, b), n) in crate::quality::mesh::quad_edge_counts(cells.iter().copied(), cells.len()) {
        if n == 1 {
            flags[a] = true;
            flags[b] = true;
        }
    }
    flags
}

/// Nodes on faces that belong to exactly one hex.
fn hex_boundary_flags(num_nodes: usize, cells: &[[usize; 8]]) -> Vec<bool> {
    let mut count: HashMap<[usize; 4], u32> = HashMap::with_capacity(cells.len() * 3);
    for c in cells {
        for f in HEX_FACES {
            let mut key = [c[f[0]], c[f[1]], c[f[2]], c[f[3]]];
            key.sort_unstable();
            *count.entry(key).or_insert(0) += 1;
        }
    }
    let mut flags = vec![false; num_nodes];
    for (key, n) in count {
        if n == 1 {
            for v in key {
                flags[v] = true;
            }
        }
    }
    flags
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_mesh_from_grid_matches_boundary_detection() {
        let g =
            StructuredGrid2::from_fn(5, 4, |i, j| DVec2::new(i as f64, (j * j) as f64)).unwrap();
        let q = QuadMesh::from_grid(&g);
        assert_eq!(q.fixed(), q.boundary_flags().as_slice());
        assert_eq!(q.num_free(), 3 * 2);
    }

    #[test]
    fn hex_mesh_boundary_flags_match_grid() {
        let g =
            StructuredGrid3::from_fn(4, 3, 5, |i, j, k| DVec3::new(i as f64, j as f64, k as f64))
                .unwrap();
        let h = HexMesh::from_grid(&g);
        let rebuilt = HexMesh::new(h.nodes().to_vec(), h.cells().to_vec()).unwrap();
        assert_eq!(rebuilt.fixed(), h.fixed());
        assert_eq!(h.num_free(), 2 * 3); // (4−2)(3−2)(5−2)
    }

    #[test]
    fn out_of_range_cell_is_rejected() {
        let e = QuadMesh::new(vec![DVec2::ZERO; 3], vec![[0, 1, 2, 3]]).unwrap_err();
        assert_eq!(
            e,
            MeshError::NodeOutOfRange {
                cell: 0,
                node: 3,
                num_nodes: 3
            }
        );
    }
}
