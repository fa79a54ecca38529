//! Structured grids in 2D (`m × n` nodes) and 3D (`m × n × p` nodes).
//!
//! Node `(i, j)` of a 2D grid is stored at `j * m + i` (i fastest): `i = 0..m` runs along the
//! bottom side left to right, `j = 0..n` upward. Cell `(i, j)` (`i < m-1`, `j < n-1`) has the
//! counter-clockwise vertices `(i,j), (i+1,j), (i+1,j+1), (i,j+1)` and id `j * (m-1) + i`.
//! Sides are bottom (`j = 0`), right (`i = m-1`), top (`j = n-1`), left (`i = 0`).
//!
//! Node `(i, j, k)` of a 3D grid is stored at `(k * n + j) * m + i`; hex cell `(i, j, k)` lists
//! its vertices in VTK order: `(i,j,k), (i+1,j,k), (i+1,j+1,k), (i,j+1,k)` and the same at `k+1`.

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::error::MeshError;
use crate::traits::{FreeNodes, HasHexCells, HasNodes, HasQuadCells};

/// A structured 2D grid of `m × n` nodes ([Méndez 2023, §2.1.1]; [González Flores, Def 2.2]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StructuredGrid2 {
    m: usize,
    n: usize,
    nodes: Vec<DVec2>,
}

impl StructuredGrid2 {
    /// Builds a grid from its nodes in `j * m + i` order. Needs `m, n ≥ 2`, `nodes.len() == m n`
    /// and finite coordinates.
    pub fn new(m: usize, n: usize, nodes: Vec<DVec2>) -> Result<Self, MeshError> {
        if m < 2 || n < 2 {
            return Err(MeshError::InvalidSize(format!(
                "a structured grid needs at least 2 × 2 nodes, got {m} × {n}"
            )));
        }
        if nodes.len() != m * n {
            return Err(MeshError::InvalidSize(format!(
                "{m} × {n} grid needs {} nodes, got {}",
                m * n,
                nodes.len()
            )));
        }
        if let Some(v) = nodes.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFinite { node: v });
        }
        Ok(Self { m, n, nodes })
    }

    /// The grid of a function `f(i, j)` evaluated at every node.
    pub fn from_fn(
        m: usize,
        n: usize,
        mut f: impl FnMut(usize, usize) -> DVec2,
    ) -> Result<Self, MeshError> {
        let mut nodes = Vec::with_capacity(m.saturating_mul(n));
        for j in 0..n {
            for i in 0..m {
                nodes.push(f(i, j));
            }
        }
        Self::new(m, n, nodes)
    }

    /// Number of nodes along `i` (the bottom side).
    pub fn m(&self) -> usize {
        self.m
    }
    /// Number of nodes along `j` (the left side).
    pub fn n(&self) -> usize {
        self.n
    }
    /// Linear index of node `(i, j)`.
    #[inline]
    pub fn index(&self, i: usize, j: usize) -> usize {
        j * self.m + i
    }
    /// Node `(i, j)`.
    #[inline]
    pub fn node(&self, i: usize, j: usize) -> DVec2 {
        self.nodes[j * self.m + i]
    }
    /// Sets node `(i, j)`.
    #[inline]
    pub fn set_node(&mut self, i: usize, j: usize, p: DVec2) {
        let k = self.index(i, j);
        self.nodes[k] = p;
    }
    /// `true` for nodes on the grid's boundary.
    #[inline]
    pub fn is_boundary(&self, i: usize, j: usize) -> bool {
        i == 0 || j == 0 || i + 1 == self.m || j + 1 == self.n
    }
    /// Number of cells `(m-1)(n-1)`.
    pub fn num_cells(&self) -> usize {
        (self.m - 1) * (self.n - 1)
    }
    /// Node ids of cell `(i, j)`, counter-clockwise.
    #[inline]
    pub fn cell(&self, i: usize, j: usize) -> [usize; 4] {
        let a = self.index(i, j);
        [a, a + 1, a + self.m + 1, a + self.m]
    }
    /// The bottom side `(i, 0)`, `i = 0..m`, left to right.
    pub fn bottom(&self) -> Vec<DVec2> {
        (0..self.m).map(|i| self.node(i, 0)).collect()
    }
    /// The top side `(i, n-1)`, `i = 0..m`, left to right.
    pub fn top(&self) -> Vec<DVec2> {
        (0..self.m).map(|i| self.node(i, self.n - 1)).collect()
    }
    /// The left side `(0, j)`, `j = 0..n`, bottom to top.
    pub fn left(&self) -> Vec<DVec2> {
        (0..self.n).map(|j| self.node(0, j)).collect()
    }
    /// The right side `(m-1, j)`, `j = 0..n`, bottom to top.
    pub fn right(&self) -> Vec<DVec2> {
        (0..self.n).map(|j| self.node(self.m - 1, j)).collect()
    }
    /// Node ids of the boundary in counter-clockwise order starting at `(0,0)`: bottom forward,
    /// right upward, top backward, left downward; each corner listed once.
    pub fn boundary_loop(&self) -> Vec<usize> {
        let (m, n) = (self.m, self.n);
        let mut v = Vec::with_capacity(2 * (m + n) - 4);
        v.extend((0..m).map(|i| self.index(i, 0)));
        v.extend((1..n).map(|j| self.index(m - 1, j)));
        v.extend((0..m - 1).rev().map(|i| self.index(i, n - 1)));
        v.extend((1..n - 1).rev().map(|j| self.index(0, j)));
        v
    }
    /// Consumes the grid and returns its nodes.
    pub fn into_nodes(self) -> Vec<DVec2> {
        self.nodes
    }
}

impl HasNodes<DVec2> for StructuredGrid2 {
    fn nodes(&self) -> &[DVec2] {
        &self.nodes
    }
    fn nodes_mut(&mut self) -> &mut [DVec2] {
        &mut self.nodes
    }
}

impl HasQuadCells for StructuredGrid2 {
    fn num_quads(&self) -> usize {
        self.num_cells()
    }
    #[inline]
    fn quad(&self, c: usize) -> [usize; 4] {
        let w = self.m - 1;
        self.cell(c % w, c / w)
    }
}

impl FreeNodes for StructuredGrid2 {
    fn is_fixed(&self, v: usize) -> bool {
        self.is_boundary(v % self.m, v / self.m)
    }
    fn num_flagged_nodes(&self) -> usize {
        self.nodes.len()
    }
}

/// A structured 3D grid of `m × n × p` nodes ([Cortés Aguirre 2012, §3.2, (3.14)]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StructuredGrid3 {
    m: usize,
    n: usize,
    p: usize,
    nodes: Vec<DVec3>,
}

impl StructuredGrid3 {
    /// Builds a grid from its nodes in `(k * n + j) * m + i` order; needs `m, n, p ≥ 2`.
    pub fn new(m: usize, n: usize, p: usize, nodes: Vec<DVec3>) -> Result<Self, MeshError> {
        if m < 2 || n < 2 || p < 2 {
            return Err(MeshError::InvalidSize(format!(
                "a structured 3D grid needs at least 2 × 2 × 2 nodes, got {m} × {n} × {p}"
            )));
        }
        if nodes.len() != m * n * p {
            return Err(MeshError::InvalidSize(format!(
                "{m} × {n} × {p} grid needs {} nodes, got {}",
                m * n * p,
                nodes.len()
            )));
        }
        if let Some(v) = nodes.iter().position(|q| !q.is_finite()) {
            return Err(MeshError::NonFinite { node: v });
        }
        Ok(Self { m, n, p, nodes })
    }

    /// The grid of a function `f(i, j, k)` evaluated at every node.
    pub fn from_fn(
        m: usize,
        n: usize,
        p: usize,
        mut f: impl FnMut(usize, usize, usize) -> DVec3,
    ) -> Result<Self, MeshError> {
        let mut nodes = Vec::with_capacity(m.saturating_mul(n).saturating_mul(p));
        for k in 0..p {
            for j in 0..n {
                for i in 0..m {
                    nodes.push(f(i, j, k));
                }
            }
        }
        Self::new(m, n, p, nodes)
    }

    /// Sizes `(m, n, p)`.
    pub fn dims(&self) -> (usize, usize, usize) {
        (self.m, self.n, self.p)
    }
    /// Linear index of node `(i, j, k)`.
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.n + j) * self.m + i
    }
    /// Node `(i, j, k)`.
    #[inline]
    pub fn node(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.nodes[self.index(i, j, k)]
    }
    /// Sets node `(i, j, k)`.
    #[inline]
    pub fn set_node(&mut self, i: usize, j: usize, k: usize, q: DVec3) {
        let id = self.index(i, j, k);
        self.nodes[id] = q;
    }
    /// `true` for nodes on the grid's boundary.
    #[inline]
    pub fn is_boundary(&self, i: usize, j: usize, k: usize) -> bool {
        i == 0 || j == 0 || k == 0 || i + 1 == self.m || j + 1 == self.n || k + 1 == self.p
    }
    /// Number of cells `(m-1)(n-1)(p-1)`.
    pub fn num_cells(&self) -> usize {
        (self.m - 1) * (self.n - 1) * (self.p - 1)
    }
    /// Node ids of cell `(i, j, k)` in VTK order.
    #[inline]
    pub fn cell(&self, i: usize, j: usize, k: usize) -> [usize; 8] {
        let a = self.index(i, j, k);
        let (dx, dy, dz) = (1, self.m, self.m * self.n);
        [
            a,
            a + dx,
            a + dx + dy,
            a + dy,
            a + dz,
            a + dz + dx,
            a + dz + dx + dy,
            a + dz + dy,
        ]
    }
    /// Consumes the grid and returns its nodes.
    pub fn into_nodes(self) -> Vec<DVec3> {
        self.nodes
    }
}

impl HasNodes<DVec3> for StructuredGrid3 {
    fn nodes(&self) -> &[DVec3] {
        &self.nodes
    }
    fn nodes_mut(&mut self) -> &mut [DVec3] {
        &mut self.nodes
    }
}

impl HasHexCells for StructuredGrid3 {
    fn num_hexes(&self) -> usize {
        self.num_cells()
    }
    #[inline]
    fn hex(&self, c: usize) -> [usize; 8] {
        let w = self.m - 1;
        let h = self.n - 1;
        self.cell(c % w, (c / w) % h, c / (w * h))
    }
}

impl FreeNodes for StructuredGrid3 {
    fn is_fixed(&self, v: usize) -> bool {
        let i = v % self.m;
        let j = (v / self.m) % self.n;
        let k = v / (self.m * self.n);
        self.is_boundary(i, j, k)
    }
    fn num_flagged_nodes(&self) -> usize {
        self.nodes.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid2_cells_are_ccw_and_indexed() {
        let g = StructuredGrid2::from_fn(4, 3, |i, j| DVec2::new(i as f64, j as f64)).unwrap();
        assert_eq!(g.num_quads(), 6);
        for c in 0..g.num_quads() {
            let [a, b, cc, d] = g.quad_points(c);
            // unit square cell, CCW: doubled signed area 2
            let area2 = (b - a).perp_dot(d - a) + (d - cc).perp_dot(b - cc);
            assert!((area2 - 2.0).abs() < 1e-12);
        }
        assert_eq!(g.quad(4), g.cell(1, 1));
        assert_eq!(g.boundary_loop().len(), 2 * (4 + 3) - 4);
        assert_eq!(g.num_free(), 2);
        assert_eq!(g.free_nodes(), vec![g.index(1, 1), g.index(2, 1)]);
    }

    #[test]
    fn grid3_hex_order_is_vtk() {
        let g =
            StructuredGrid3::from_fn(3, 3, 3, |i, j, k| DVec3::new(i as f64, j as f64, k as f64))
                .unwrap();
        let h = g.hex_points(g.num_hexes() - 1);
        assert_eq!(h[0], DVec3::new(1.0, 1.0, 1.0));
        assert_eq!(h[1], DVec3::new(2.0, 1.0, 1.0));
        assert_eq!(h[2], DVec3::new(2.0, 2.0, 1.0));
        assert_eq!(h[3], DVec3::new(1.0, 2.0, 1.0));
        assert_eq!(h[6], DVec3::new(2.0, 2.0, 2.0));
        assert_eq!(g.num_free(), 1);
    }

    #[test]
    fn grid_rejects_bad_sizes() {
        assert!(StructuredGrid2::new(1, 3, vec![DVec2::ZERO; 3]).is_err());
        assert!(StructuredGrid2::new(2, 2, vec![DVec2::ZERO; 3]).is_err());
        assert!(matches!(
            StructuredGrid2::new(2, 2, vec![DVec2::ZERO, DVec2::NAN, DVec2::ONE, DVec2::X]),
            Err(MeshError::NonFinite { node: 1 })
        ));
    }
}
