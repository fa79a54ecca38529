//! Step 8: TFI per piece, merge, and the block-decomposition view of a submapping.

use std::collections::HashMap;

use unamalla_mesh::{tfi2, BlockMesh2, DVec2, StructuredGrid2, TfiParams};

use super::{EdgeTag, NodeKind, SubmapError, Submapping};
use crate::decomposition::{Block, Cut, Decomposition, EdgeKind};

impl Submapping {
    /// Physical points of the four sides of piece `k` (bottom, right, top, left in the TFI
    /// convention: bottom/top left to right, left/right bottom to top).
    pub fn side_points(&self, k: usize) -> [Vec<DVec2>; 4] {
        self.pieces[k]
            .sides
            .clone()
            .map(|s| s.iter().map(|&id| self.nodes[id]).collect())
    }

    /// One structured grid per piece by discrete Coons TFI with arc-length parameters (the paper
    /// gives no TFI formula; this is the standard one).
    pub fn grids(&self) -> Result<Vec<StructuredGrid2>, SubmapError> {
        (0..self.pieces.len())
            .map(|k| {
                let [b, r, t, l] = self.side_points(k);
                Ok(tfi2(&b, &r, &t, &l, TfiParams::ArcLength)?)
            })
            .collect()
    }

    /// The TFI grids merged into one conformal block mesh (shared cut and virtual-edge nodes
    /// become single interior nodes).
    pub fn block_mesh(&self) -> Result<BlockMesh2, SubmapError> {
        Ok(BlockMesh2::merge(self.grids()?, 1e-9)?)
    }

    /// Number of mesh cells (`Σ a_k b_k` over the pieces).
    pub fn num_cells(&self) -> usize {
        self.pieces
            .iter()
            .map(|p| {
                let (a, b) = p.cells();
                a * b
            })
            .sum()
    }

    /// Number of nodes that are free during smoothing (cut and virtual-edge nodes).
    pub fn num_free_boundary_nodes(&self) -> usize {
        self.node_kinds
            .iter()
            .filter(|k| **k != NodeKind::Boundary)
            .count()
    }

    /// The pieces as a [`Decomposition`] (blocks with corners; a "cut" per maximal straight run of
    /// piece boundary shared by the same two pieces, so a cut line ending on another cut line or on
    /// a virtual edge appears as two or three cuts meeting at an interior point). The tree is
    /// empty. Useful for the decomposition file and picture; the tests check that it passes
    /// [`Decomposition::validate`] for every shape of [`super::shapes`].
    pub fn to_decomposition(&self) -> Decomposition {
        // directed unit edge (u, v) → piece
        let mut owner: HashMap<(usize, usize), usize> = HashMap::new();
        for (k, p) in self.pieces.iter().enumerate() {
            let n = p.boundary.len();
            for i in 0..n {
                owner.insert((p.boundary[i], p.boundary[(i + 1) % n]), k);
            }
        }
        let mut cut_ids: HashMap<(usize, usize, usize, usize), usize> = HashMap::new();
        let mut cuts: Vec<Cut> = Vec::new();
        let mut blocks = Vec::with_capacity(self.pieces.len());
        for (k, p) in self.pieces.iter().enumerate() {
            let n = p.boundary.len();
            let nb = |i: usize| -> Option<usize> {
                match p.tags[i] {
                    EdgeTag::Boundary(_) => None,
                    _ => owner
                        .get(&(p.boundary[(i + 1) % n], p.boundary[i]))
                        .copied(),
                }
            };
            // runs start at every corner and wherever (tag, neighbour) changes
            let (a, b) = p.cells();
            let corner_pos = [0, a, a + b, 2 * a + b];
            let mut ring = Vec::new();
            let mut edges = Vec::new();
            let mut corners = [0usize; 4];
            let mut i = 0;
            while i < n {
                if let Some(c) = corner_pos.iter().position(|&c| c == i) {
                    corners[c] = ring.len();
                }
                let tag = p.tags[i];
                let neighbour = nb(i);
                match (tag, neighbour) {
                    (EdgeTag::Boundary(_), _) | (_, None) => {
                        let r = match tag {
                            EdgeTag::Boundary(r) => r,
                            _ => 0,
                        };
                        ring.push(self.nodes[p.boundary[i]]);
                        edges.push(EdgeKind::Boundary { ring: r });
                        i += 1;
                    }
                    (_, Some(other)) => {
                        let start = i;
                        i += 1;
                        while i < n
                            && !corner_pos.contains(&i)
                            && p.tags[i] == tag
                            && nb(i) == Some(other)
                        {
                            i += 1;
                        }
                        let (u, v) = (p.boundary[start], p.boundary[i % n]);
                        let key = (k.min(other), k.max(other), u.min(v), u.max(v));
                        let id = *cut_ids.entry(key).or_insert_with(|| {
                            cuts.push(Cut {
                                id: cuts.len(),
                                a: self.nodes[u],
                                b: self.nodes[v],
                                blocks: [k, other],
                            });
                            cuts.len() - 1
                        });
                        ring.push(self.nodes[u]);
                        edges.push(EdgeKind::Cut {
                            cut: id,
                            neighbour: other,
                        });
                    }
                }
            }
            blocks.push(Block {
                id: k,
                ring,
                corners,
                edges,
                triangle: false,
            });
        }
        Decomposition {
            blocks,
            cuts,
            tree: Vec::new(),
        }
    }
}
