//! Block-structured meshes: structured blocks glued along whole cuts into one conformal
//! [`QuadMesh`] (the mesh union of [Méndez 2023, §6.2]).
//!
//! A [`BlockMesh2`] keeps both views: every block as a [`StructuredGrid2`] (for structured
//! output and per-block work) and the global mesh without duplicate nodes (for global smoothing
//! and unstructured output), plus the map from each block's local node ids to global ids. It
//! implements the mesh traits by delegating to the global mesh, so the functionals and
//! optimizers work on it directly; [`BlockMesh2::sync_blocks`] copies optimized global
//! coordinates back into the blocks.

use std::collections::HashMap;

use glam::DVec2;
use serde::{Deserialize, Serialize};

use crate::error::MeshError;
use crate::grid::StructuredGrid2;
use crate::traits::{FreeNodes, HasNodes, HasQuadCells};
use crate::unstructured::QuadMesh;

/// Structured blocks plus their conformal union.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BlockMesh2 {
    blocks: Vec<StructuredGrid2>,
    global: QuadMesh,
    block_nodes: Vec<Vec<usize>>,
}

impl BlockMesh2 {
    /// Merges blocks in the given order. Boundary nodes of different blocks that coincide
    /// (closer than `rel_tol` times the diagonal of the bounding box of all nodes) become one
    /// global node; interior nodes are never merged. Global node ids are assigned in order of
    /// first appearance (block 0's nodes first). Nodes on the boundary of the union are fixed.
    ///
    /// Errors: no blocks, or an edge shared by more than two cells (blocks overlapping).
    pub fn merge(blocks: Vec<StructuredGrid2>, rel_tol: f64) -> Result<Self, MeshError> {
        if blocks.is_empty() {
            return Err(MeshError::InvalidSize(
                "a block mesh needs at least one block".into(),
            ));
        }
        let (lo, hi) = blocks.iter().flat_map(|b| b.nodes().iter()).fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let tol = (rel_tol * (hi - lo).length()).max(f64::MIN_POSITIVE);
        let cell_of = |p: DVec2| ((p.x / tol).floor() as i64, (p.y / tol).floor() as i64);
        let mut buckets: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
        let mut nodes: Vec<DVec2> = Vec::new();
        let mut block_nodes = Vec::with_capacity(blocks.len());
        for b in &blocks {
            let mut map = Vec::with_capacity(b.num_nodes());
            for j in 0..b.n() {
                for i in 0..b.m() {
                    let p = b.node(i, j);
                    let mut found = None;
                    if b.is_boundary(i, j) {
                        let (cx, cy) = cell_of(p);
                        'search: for dx in -1..=1 {
                            for dy in -1..=1 {
                                if let Some(list) = buckets.get(&(cx + dx, cy + dy)) {
                                    for &g in list {
                                        if nodes[g].distance(p) <= tol {
                                            found = Some(g);
                                            break 'search;
                                        }
                                    }
                                }
                            }
                        }
                    }
                    let g = match found {
                        Some(g) => g,
                        None => {
                            nodes.push(p);
                            let g = nodes.len() - 1;
                            if b.is_boundary(i, j) {
                                buckets.entry(cell_of(p)).or_default().push(g);
                            }
                            g
                        }
                    };
                    map.push(g);
                }
            }
            block_nodes.push(map);
        }
        let mut cells = Vec::with_capacity(blocks.iter().map(|b| b.num_cells()).sum());
        for (b, map) in blocks.iter().zip(&block_nodes) {
            for c in 0..b.num_quads() {
                let q = b.quad(c);
                cells.push([map[q[0]], map[q[1]], map[q[2]], map[q[3]]]);
            }
        }
        // conformity: every edge in at most two cells
        let census = crate::quality::mesh::quad_edge_counts(cells.iter().copied(), cells.len());
        if let Some(((a, b), _)) = census.into_iter().find(|&(_, n)| n > 2) {
            return Err(MeshError::Degenerate(format!(
                "edge between global nodes {a} and {b} is shared by more than two cells; blocks overlap"
            )));
        }
        let global = QuadMesh::new(nodes, cells)?;
        Ok(Self {
            blocks,
            global,
            block_nodes,
        })
    }

    /// The blocks as structured grids.
    pub fn blocks(&self) -> &[StructuredGrid2] {
        &self.blocks
    }
    /// The global conformal mesh.
    pub fn global(&self) -> &QuadMesh {
        &self.global
    }
    /// Mutable access to the global mesh (call [`BlockMesh2::sync_blocks`] after moving nodes).
    pub fn global_mut(&mut self) -> &mut QuadMesh {
        &mut self.global
    }
    /// For block `b`, the global id of each of its local nodes (`j * m + i` order).
    pub fn block_node_map(&self, b: usize) -> &[usize] {
        &self.block_nodes[b]
    }
    /// Mutable access to the blocks, for work done block by block with each block's boundary
    /// fixed (e.g. per-block untangling); call [`BlockMesh2::sync_global`] afterwards.
    pub fn blocks_mut(&mut self) -> &mut [StructuredGrid2] {
        &mut self.blocks
    }
    /// Copies every block's **interior** node coordinates into the global mesh (the inverse of
    /// [`BlockMesh2::sync_blocks`] for nodes owned by one block). Block boundary nodes — the
    /// ones blocks share — are left as the global mesh has them, so blocks edited with their
    /// boundaries fixed stay conformal.
    pub fn sync_global(&mut self) {
        let nodes = self.global.nodes_mut();
        for (b, map) in self.blocks.iter().zip(&self.block_nodes) {
            let (m, n) = (b.m(), b.n());
            for j in 1..n.saturating_sub(1) {
                for i in 1..m.saturating_sub(1) {
                    let k = j * m + i;
                    nodes[map[k]] = b.nodes()[k];
                }
            }
        }
    }
    /// Copies the global node coordinates back into every block.
    pub fn sync_blocks(&mut self) {
        let nodes = self.global.nodes();
        for (b, map) in self.blocks.iter_mut().zip(&self.block_nodes) {
            for (local, &g) in b.nodes_mut().iter_mut().zip(map) {
                *local = nodes[g];
            }
        }
    }
}

impl HasNodes<DVec2> for BlockMesh2 {
    fn nodes(&self) -> &[DVec2] {
        self.global.nodes()
    }
    fn nodes_mut(&mut self) -> &mut [DVec2] {
        self.global.nodes_mut()
    }
}

impl HasQuadCells for BlockMesh2 {
    fn num_quads(&self) -> usize {
        self.global.num_quads()
    }
    fn quad(&self, c: usize) -> [usize; 4] {
        self.global.quad(c)
    }
}

impl FreeNodes for BlockMesh2 {
    fn is_fixed(&self, v: usize) -> bool {
        self.global.is_fixed(v)
    }
    fn num_flagged_nodes(&self) -> usize {
        self.global.num_flagged_nodes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(x0: f64, y0: f64, m: usize, n: usize) -> StructuredGrid2 {
        StructuredGrid2::from_fn(m, n, |i, j| DVec2::new(x0 + i as f64, y0 + j as f64)).unwrap()
    }

    #[test]
    fn two_blocks_share_their_common_side() {
        // [0,3]×[0,2] and [3,5]×[0,2]: 4×3 and 3×3 nodes, sharing 3 nodes on x = 3
        let bm = BlockMesh2::merge(vec![grid(0., 0., 4, 3), grid(3., 0., 3, 3)], 1e-9).unwrap();
        assert_eq!(bm.num_nodes(), 12 + 9 - 3);
        assert_eq!(bm.num_quads(), 6 + 4);
        // the shared middle node (3,1) is interior to the union: free
        let g = bm.block_node_map(0)[bm.blocks()[0].index(3, 1)];
        assert_eq!(g, bm.block_node_map(1)[bm.blocks()[1].index(0, 1)]);
        assert!(!bm.is_fixed(g));
        // interior nodes of the union: (1,1), (2,1), (3,1), (4,1)
        assert_eq!(bm.num_free(), 4);
    }

    #[test]
    fn sync_copies_global_moves_into_blocks() {
        let mut bm = BlockMesh2::merge(vec![grid(0., 0., 3, 3), grid(2., 0., 3, 3)], 1e-9).unwrap();
        let g = bm.block_node_map(1)[bm.blocks()[1].index(0, 1)];
        bm.nodes_mut()[g] = DVec2::new(2.1, 1.05);
        bm.sync_blocks();
        assert_eq!(bm.blocks()[0].node(2, 1), DVec2::new(2.1, 1.05));
        assert_eq!(bm.blocks()[1].node(0, 1), DVec2::new(2.1, 1.05));
    }

    #[test]
    fn sync_global_copies_block_interiors_and_keeps_shared_nodes() {
        // [0,2]×[0,2] and [2,4]×[0,2], 3×3 nodes each: one interior node per block, (1,1) and
        // (3,1); the shared side x = 2 is a block boundary
        let mut bm = BlockMesh2::merge(vec![grid(0., 0., 3, 3), grid(2., 0., 3, 3)], 1e-9).unwrap();
        bm.blocks_mut()[0].nodes_mut()[4] = DVec2::new(0.9, 1.2); // (1,1) of block 0
        bm.blocks_mut()[1].nodes_mut()[4] = DVec2::new(3.2, 0.8); // (1,1) of block 1
        bm.blocks_mut()[1].nodes_mut()[3] = DVec2::new(9.0, 9.0); // (0,1) of block 1: shared
        bm.sync_global();
        let g0 = bm.block_node_map(0)[4];
        let g1 = bm.block_node_map(1)[4];
        let gs = bm.block_node_map(1)[3];
        assert_eq!(bm.nodes()[g0], DVec2::new(0.9, 1.2));
        assert_eq!(bm.nodes()[g1], DVec2::new(3.2, 0.8));
        // the shared node is a block-boundary node: not copied
        assert_eq!(bm.nodes()[gs], DVec2::new(2.0, 1.0));
    }

    #[test]
    fn overlapping_blocks_are_rejected() {
        let e = BlockMesh2::merge(
            vec![grid(0., 0., 3, 3), grid(0., 0., 3, 3), grid(0., 0., 3, 3)],
            1e-9,
        );
        assert!(matches!(e, Err(MeshError::Degenerate(_))));
        assert!(BlockMesh2::merge(vec![], 1e-9).is_err());
    }
}
