//! Rectilinear regions ([Méndez 2023, Appendix B]): the block-structured mesh as the image of a **rectilinear region** `R` — a
//! union of axis-parallel rectangles, one per block — under a piecewise-bilinear map
//! `X : R → Ω`.
//!
//! Block `k` with `m_k × n_k` nodes is the rectangle `R_k = [0, m_k − 1] × [0, n_k − 1]` of its
//! index space, placed in the plane by a rigid motion of the integer lattice (one of the eight
//! orthogonal maps `T_k` and an integer offset `o_k`): node `(i, j)` of block `k` goes to
//! `o_k + T_k (i, j)`. Blocks that share a side are placed side by side across it, by a
//! breadth-first walk over the blocks from block 0 at the origin (this *develops* the index
//! space into the plane). Then `X|_{R_k} = X_k ∘ φ_k⁻¹` with `φ_k` that placement and `X_k`
//! the block's bilinear cells — the thesis's (B.1). Because every cell is convex, each `X_k`
//! has a positive Jacobian, and by Theorem B.2 (Bobylév, Ivanenko & Kazunin: a piecewise `C¹`
//! map with positive Jacobian on each piece that maps `∂R` homeomorphically onto `∂Ω` is a
//! homeomorphism) `X` is a homeomorphism whenever the development is a proper region — which
//! this module checks:
//!
//! * every node gets one position from all the blocks that hold it (the development
//!   **closes**; around a hole it need not: a frame of four trapezoids around a square hole
//!   develops into four rectangles whose corners collide — [`RectilinearError::NotClosed`]);
//! * no two rectangles overlap and no two nodes share a position
//!   ([`RectilinearError::Overlap`]).
//!
//! The thesis leaves the conditions on cuts and corners under which the development is a
//! rectilinear region to future work (Appendix B, after Theorem B.1); here they are checked
//! after the fact. The boundary of `R` is returned as rectilinear rings (unit boundary edges
//! chained and merged where collinear), outer ring first.

use std::collections::{HashMap, VecDeque};

use serde::{Deserialize, Serialize};

use crate::block::BlockMesh2;
use crate::traits::HasQuadCells;

/// Why a block mesh is not the image of a rectilinear region.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum RectilinearError {
    /// Going around a hole, the placed blocks disagree on where a node lies.
    #[error(
        "the development does not close: global node {node} is at {first:?} by one block and at \
         {second:?} by block {block}"
    )]
    NotClosed {
        /// The global node.
        node: usize,
        /// The block whose placement disagrees.
        block: usize,
        /// The position given first.
        first: [i64; 2],
        /// The position block `block` gives.
        second: [i64; 2],
    },
    /// Two placed blocks overlap (or two nodes fall on one lattice point).
    #[error("blocks {a} and {b} overlap in the development")]
    Overlap {
        /// One block.
        a: usize,
        /// The other block.
        b: usize,
    },
    /// A block shares no side with the blocks placed before it.
    #[error("block {block} shares no side with the other blocks")]
    Disconnected {
        /// The block.
        block: usize,
    },
}

/// The placement of one block's index rectangle: node `(i, j)` goes to
/// `origin + i·axis_i + j·axis_j`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Placement {
    /// Position of the block's node `(0, 0)`.
    pub origin: [i64; 2],
    /// Image of the index direction `i` (a unit lattice vector).
    pub axis_i: [i64; 2],
    /// Image of the index direction `j` (a unit lattice vector).
    pub axis_j: [i64; 2],
    /// The placed rectangle `[u_min, v_min, u_max, v_max]`.
    pub rect: [i64; 4],
}

impl Placement {
    fn at(&self, i: i64, j: i64) -> [i64; 2] {
        [
            self.origin[0] + i * self.axis_i[0] + j * self.axis_j[0],
            self.origin[1] + i * self.axis_i[1] + j * self.axis_j[1],
        ]
    }
}

/// A rectilinear region whose piecewise-bilinear image is a block mesh (module documentation).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RectilinearRegion {
    /// One placement per block.
    pub blocks: Vec<Placement>,
    /// The lattice position of every global node of the mesh.
    pub node_uv: Vec<[i64; 2]>,
    /// The boundary of `R`: rectilinear rings (corner points only), the outer ring first and
    /// counter-clockwise, holes clockwise.
    pub rings: Vec<Vec<[i64; 2]>>,
}

impl RectilinearRegion {
    /// The area of `R` (equal to the number of cells).
    pub fn area(&self) -> i64 {
        self.blocks
            .iter()
            .map(|p| (p.rect[2] - p.rect[0]) * (p.rect[3] - p.rect[1]))
            .sum()
    }
}

/// The eight orthogonal maps of the lattice, as the images of the two index axes.
const AXES: [([i64; 2], [i64; 2]); 8] = [
    ([1, 0], [0, 1]),
    ([0, 1], [-1, 0]),
    ([-1, 0], [0, -1]),
    ([0, -1], [1, 0]),
    ([1, 0], [0, -1]),
    ([0, 1], [1, 0]),
    ([-1, 0], [0, 1]),
    ([0, -1], [-1, 0]),
];

/// Develops the index spaces of the blocks of `mesh` into a rectilinear region (module
/// documentation), or says why it is not one.
pub fn develop(mesh: &BlockMesh2) -> Result<RectilinearRegion, RectilinearError> {
    let blocks = mesh.blocks();
    let nn = crate::traits::HasNodes::nodes(mesh).len();
    // blocks holding each global node, and each block's local (i, j) of it
    let mut holders: Vec<Vec<(usize, i64, i64)>> = vec![Vec::new(); nn];
    for (b, g) in blocks.iter().enumerate() {
        let m = g.m();
        for (local, &v) in mesh.block_node_map(b).iter().enumerate() {
            holders[v].push((b, (local % m) as i64, (local / m) as i64));
        }
    }
    let mut uv: Vec<Option<[i64; 2]>> = vec![None; nn];
    let mut placed: Vec<Option<Placement>> = vec![None; blocks.len()];
    let rect_of = |origin: [i64; 2], ai: [i64; 2], aj: [i64; 2], m: usize, n: usize| {
        let p = Placement {
            origin,
            axis_i: ai,
            axis_j: aj,
            rect: [0; 4],
        };
        let (a, c) = (p.at(0, 0), p.at(m as i64 - 1, n as i64 - 1));
        Placement {
            rect: [
                a[0].min(c[0]),
                a[1].min(c[1]),
                a[0].max(c[0]),
                a[1].max(c[1]),
            ],
            ..p
        }
    };
    let mut order = Vec::with_capacity(blocks.len());
    let mut queue = VecDeque::new();
    for start in 0..blocks.len() {
        if placed[start].is_some() {
            continue;
        }
        if start > 0 {
            // the merged mesh is connected: a block reached only here shares no side
            return Err(RectilinearError::Disconnected { block: start });
        }
        placed[0] = Some(rect_of(
            [0, 0],
            [1, 0],
            [0, 1],
            blocks[0].m(),
            blocks[0].n(),
        ));
        queue.push_back(0);
        while let Some(a) = queue.pop_front() {
            order.push(a);
            let pa = placed[a].unwrap_or_else(|| unreachable!());
            // record block a's nodes, checking the ones already placed
            for (local, &v) in mesh.block_node_map(a).iter().enumerate() {
                let m = blocks[a].m();
                let q = pa.at((local % m) as i64, (local / m) as i64);
                match uv[v] {
                    None => uv[v] = Some(q),
                    Some(p) if p != q => {
                        return Err(RectilinearError::NotClosed {
                            node: v,
                            block: a,
                            first: p,
                            second: q,
                        })
                    }
                    _ => {}
                }
            }
            // neighbours sharing at least two nodes (a side) with block a, in block order
            let mut shared: HashMap<usize, Vec<(usize, i64, i64)>> = HashMap::new();
            for &v in mesh.block_node_map(a) {
                for &(b, i, j) in &holders[v] {
                    if b != a && placed[b].is_none() {
                        shared.entry(b).or_default().push((v, i, j));
                    }
                }
            }
            let mut nbrs: Vec<usize> = shared
                .iter()
                .filter(|(_, s)| s.len() >= 2)
                .map(|(&b, _)| b)
                .collect();
            nbrs.sort_unstable();
            for b in nbrs {
                let s = &shared[&b];
                let (v0, i0, j0) = s[0];
                let p0 = uv[v0].unwrap_or_else(|| unreachable!());
                let (m, n) = (blocks[b].m(), blocks[b].n());
                // the orientations mapping every shared node onto its position; of the two
                // (mirror images across the shared side), the one on the far side of block a
                let centre_a = [pa.rect[0] + pa.rect[2], pa.rect[1] + pa.rect[3]];
                let mut best: Option<(i64, Placement)> = None;
                for (ai, aj) in AXES {
                    let origin = [
                        p0[0] - i0 * ai[0] - j0 * aj[0],
                        p0[1] - i0 * ai[1] - j0 * aj[1],
                    ];
                    let cand = rect_of(origin, ai, aj, m, n);
                    if s.iter().any(|&(v, i, j)| Some(cand.at(i, j)) != uv[v]) {
                        continue;
                    }
                    let centre_b = [cand.rect[0] + cand.rect[2], cand.rect[1] + cand.rect[3]];
                    let d = (centre_a[0] - centre_b[0]).pow(2) + (centre_a[1] - centre_b[1]).pow(2);
                    if best.is_none_or(|(bd, _)| d > bd) {
                        best = Some((d, cand));
                    }
                }
                match best {
                    Some((_, p)) => {
                        placed[b] = Some(p);
                        queue.push_back(b);
                    }
                    None => {
                        return Err(RectilinearError::NotClosed {
                            node: v0,
                            block: b,
                            first: p0,
                            second: p0,
                        })
                    }
                }
            }
        }
    }
    let placements: Vec<Placement> = placed
        .into_iter()
        .enumerate()
        .map(|(b, p)| p.ok_or(RectilinearError::Disconnected { block: b }))
        .collect::<Result<_, _>>()?;
    let node_uv: Vec<[i64; 2]> = uv.into_iter().map(|p| p.unwrap_or([0, 0])).collect();
    // no two rectangles overlap (open interiors), no two nodes on one lattice point
    for a in 0..placements.len() {
        for b in a + 1..placements.len() {
            let (r, s) = (placements[a].rect, placements[b].rect);
            if r[0] < s[2] && s[0] < r[2] && r[1] < s[3] && s[1] < r[3] {
                return Err(RectilinearError::Overlap { a, b });
            }
        }
    }
    let mut seen: HashMap<[i64; 2], usize> = HashMap::with_capacity(nn);
    for (v, &p) in node_uv.iter().enumerate() {
        if let Some(&w) = seen.get(&p) {
            let block_of = |v: usize| holders[v].first().map_or(0, |h| h.0);
            return Err(RectilinearError::Overlap {
                a: block_of(w),
                b: block_of(v),
            });
        }
        seen.insert(p, v);
    }
    let rings = boundary_rings(mesh, &node_uv);
    Ok(RectilinearRegion {
        blocks: placements,
        node_uv,
        rings,
    })
}

/// The boundary edges of the mesh (cell edges used once), chained into rings in the lattice,
/// collinear points merged; outer (largest area) first, oriented counter-clockwise, holes
/// clockwise.
fn boundary_rings(mesh: &BlockMesh2, uv: &[[i64; 2]]) -> Vec<Vec<[i64; 2]>> {
    let mut uses: HashMap<(usize, usize), (u32, usize, usize)> = HashMap::new();
    for c in 0..mesh.num_quads() {
        let q = mesh.quad(c);
        for k in 0..4 {
            let (a, b) = (q[k], q[(k + 1) % 4]);
            let e = uses.entry((a.min(b), a.max(b))).or_insert((0, a, b));
            e.0 += 1;
        }
    }
    // directed boundary edges, as the cells traverse them
    let mut next: HashMap<usize, Vec<usize>> = HashMap::new();
    let mut edges: Vec<(usize, usize)> = uses
        .values()
        .filter(|e| e.0 == 1)
        .map(|e| (e.1, e.2))
        .collect();
    edges.sort_unstable();
    for &(a, b) in &edges {
        next.entry(a).or_default().push(b);
    }
    let mut used: HashMap<(usize, usize), bool> = HashMap::new();
    let mut rings: Vec<Vec<[i64; 2]>> = Vec::new();
    for &(a0, b0) in &edges {
        if used.contains_key(&(a0, b0)) {
            continue;
        }
        let mut ring = vec![uv[a0]];
        let (mut a, mut b) = (a0, b0);
        loop {
            used.insert((a, b), true);
            if b == a0 {
                break;
            }
            ring.push(uv[b]);
            let Some(nb) = next.get(&b) else { break };
            let Some(&c) = nb.iter().find(|&&c| !used.contains_key(&(b, c))) else {
                break;
            };
            a = b;
            b = c;
        }
        // merge collinear points
        let n = ring.len();
        let corners: Vec<[i64; 2]> = (0..n)
            .filter(|&k| {
                let (p, q, r) = (ring[(k + n - 1) % n], ring[k], ring[(k + 1) % n]);
                (q[0] - p[0]) * (r[1] - q[1]) - (q[1] - p[1]) * (r[0] - q[0]) != 0
            })
            .map(|k| ring[k])
            .collect();
        rings.push(corners);
    }
    let area2 = |r: &Vec<[i64; 2]>| -> i64 {
        (0..r.len())
            .map(|k| {
                let (p, q) = (r[k], r[(k + 1) % r.len()]);
                p[0] * q[1] - q[0] * p[1]
            })
            .sum()
    };
    rings.sort_by_key(|r| std::cmp::Reverse(area2(r).abs()));
    for (k, r) in rings.iter_mut().enumerate() {
        let a = area2(r);
        if (k == 0 && a < 0) || (k > 0 && a > 0) {
            r.reverse();
        }
    }
    rings
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::StructuredGrid2;
    use glam::DVec2;

    /// An axis-aligned unit grid with `m × n` nodes from `(x0, y0)`; with `turn`, the index
    /// `i` runs along `+y` and `j` along `−x` (the same cells, indexed a quarter turn off).
    fn grid(x0: f64, y0: f64, m: usize, n: usize, turn: bool) -> StructuredGrid2 {
        if turn {
            // i along +y (m nodes), j along −x (n nodes), starting at the block's bottom right
            StructuredGrid2::from_fn(m, n, |i, j| {
                DVec2::new(x0 + (n - 1 - j) as f64, y0 + i as f64)
            })
            .unwrap()
        } else {
            StructuredGrid2::from_fn(m, n, |i, j| DVec2::new(x0 + i as f64, y0 + j as f64)).unwrap()
        }
    }

    /// An L of unit cells — [0, 4] × [0, 2] and [0, 2] × [2, 5], the second indexed a quarter
    /// turn off — is its own rectilinear region: every node's lattice position is its
    /// physical position (the blocks are unit grids already), the rectangles are 4 × 2 and
    /// 2 × 3, and the boundary is the L's six corners, counter-clockwise.
    #[test]
    fn an_l_of_unit_grids_develops_onto_itself() {
        let mesh = BlockMesh2::merge(
            vec![grid(0.0, 0.0, 5, 3, false), grid(0.0, 2.0, 4, 3, true)],
            1e-9,
        )
        .unwrap();
        let r = develop(&mesh).unwrap();
        let x = crate::traits::HasNodes::nodes(&mesh);
        for (v, p) in r.node_uv.iter().enumerate() {
            assert_eq!([p[0] as f64, p[1] as f64], [x[v].x, x[v].y], "node {v}");
        }
        assert_eq!(r.blocks[0].rect, [0, 0, 4, 2]);
        assert_eq!(r.blocks[1].rect, [0, 2, 2, 5]);
        assert_eq!(r.area(), 8 + 6);
        assert_eq!(r.rings.len(), 1);
        let mut ring = r.rings[0].clone();
        let k = ring.iter().position(|&p| p == [0, 0]).unwrap();
        ring.rotate_left(k);
        assert_eq!(ring, vec![[0, 0], [4, 0], [4, 2], [2, 2], [2, 5], [0, 5]]);
    }

    /// A physically curved block mesh develops by counts, not by shape: two blocks glued
    /// along a 3-node side — the first 4 × 3 nodes, the second 5 × 3 — give rectangles of
    /// 3 × 2 and 4 × 2 cells side by side, whatever the node positions.
    #[test]
    fn the_development_uses_counts_not_positions() {
        let bent = |x0: f64, m: usize| {
            StructuredGrid2::from_fn(m, 3, |i, j| {
                let x = x0 + i as f64;
                DVec2::new(x + 0.1 * (j as f64), j as f64 + 0.05 * x * x)
            })
            .unwrap()
        };
        let mesh = BlockMesh2::merge(vec![bent(0.0, 4), bent(3.0, 5)], 1e-9).unwrap();
        let r = develop(&mesh).unwrap();
        assert_eq!(r.blocks[0].rect, [0, 0, 3, 2]);
        assert_eq!(r.blocks[1].rect, [3, 0, 7, 2]);
        assert_eq!(r.rings, vec![vec![[0, 0], [7, 0], [7, 2], [0, 2]]]);
    }

    /// A frame of four trapezoids around a square hole (outer square [0, 4]², hole [1, 3]²,
    /// each side one block of 5 × 2 nodes from the outer side to the hole): in the lattice each
    /// block is a 4 × 1 rectangle, so the hole side (2 long physically) is 4 long too, and going
    /// around the hole the corners cannot meet — the development does not close.
    #[test]
    fn a_frame_of_trapezoids_does_not_close() {
        let trap = |k: usize| {
            StructuredGrid2::from_fn(5, 2, |i, j| {
                let t = i as f64 / 4.0;
                // bottom block: outer edge (0,0)-(4,0), inner edge (1,1)-(3,1); others rotated
                let (o, inn) = (DVec2::new(4.0 * t, 0.0), DVec2::new(1.0 + 2.0 * t, 1.0));
                let p = o.lerp(inn, j as f64) - DVec2::splat(2.0);
                let a = k as f64 * std::f64::consts::FRAC_PI_2;
                DVec2::new(a.cos() * p.x - a.sin() * p.y, a.sin() * p.x + a.cos() * p.y)
                    + DVec2::splat(2.0)
            })
            .unwrap()
        };
        let mesh = BlockMesh2::merge((0..4).map(trap).collect(), 1e-9).unwrap();
        assert!(matches!(
            develop(&mesh),
            Err(RectilinearError::NotClosed { .. } | RectilinearError::Overlap { .. })
        ));
    }
}
