//! The result of the stage: blocks with their rings, edge bookkeeping and corners, the cuts,
//! the binary decomposition tree and the block adjacency graph ([Méndez 2023, §4.3, §5.1]).

use serde::{Deserialize, Serialize};
use unamalla_mesh::{DVec2, Region};

use crate::error::DecomposeError;
use crate::geom::{ring_angle, signed_area};

mod check;

pub(crate) use check::{boundary_tol, check_corners, check_cuts, classify};

/// What one edge of a block ring is (`edges[i]` describes `ring[i] → ring[i+1]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum EdgeKind {
    /// A piece of the original boundary, on region ring `ring` (0 = outer, k = hole k−1).
    Boundary {
        /// Region ring.
        ring: usize,
    },
    /// The whole cut `cut`, shared with block `neighbour`.
    Cut {
        /// Cut id.
        cut: usize,
        /// The block on the other side.
        neighbour: usize,
    },
}

/// One block of the decomposition: a simple counter-clockwise polygon with four corners.
#[derive(Debug, Clone, PartialEq)]
pub struct Block {
    /// Block id (= index in [`Decomposition::blocks`]).
    pub id: usize,
    /// The boundary, counter-clockwise, open. Every cut endpoint on it is a vertex.
    pub ring: Vec<DVec2>,
    /// The four corners as indices into `ring`, in counter-clockwise order: the sides are
    /// bottom = `corners[0] → corners[1]`, right, top, left ([Méndez 2023, §5.1]).
    pub corners: [usize; 4],
    /// Per ring edge: original boundary or cut (`edges.len() == ring.len()`).
    pub edges: Vec<EdgeKind>,
    /// `true` if the block is a triangle whose corners follow the triangle-block rule
    /// (points inserted near critical vertices, [Méndez 2023, §5.1.1]).
    pub triangle: bool,
}

/// A cut: a straight segment between two boundary points, inside the region, shared by two
/// blocks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cut {
    /// Cut id (= index in [`Decomposition::cuts`]).
    pub id: usize,
    /// First endpoint.
    pub a: DVec2,
    /// Second endpoint.
    pub b: DVec2,
    /// The two blocks it separates.
    pub blocks: [usize; 2],
}

/// Which algorithm produced a split of the decomposition tree.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Step {
    /// Algorithm 2: a hole removed by two cuts.
    HoleRemoval,
    /// Algorithm 3: a concavity cut.
    Concavity,
    /// Algorithm 4: a triangle around a critical angle.
    CriticalAngle,
    /// A cut given in a decomposition file.
    User,
    /// A cut of the chord layout (hole bridge or transverse cut, module `chords`).
    Chord,
    /// A cut added by the corner repair (a block without four usable corners, module
    /// `repair`; beyond the thesis).
    CornerRepair,
}

/// A node of the binary decomposition tree T ([Méndez 2023, §4.3]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TreeNode {
    /// Path label: "" for the root, then "1"/"2" per level joined by dots (thesis Fig 4.24).
    pub label: String,
    /// Parent node.
    pub parent: Option<usize>,
    /// The two children (empty for a leaf).
    pub children: Vec<usize>,
    /// How this node was split (`None` for a leaf).
    pub step: Option<Step>,
    /// Cuts made at this node.
    pub cuts: Vec<usize>,
    /// For a leaf, the id of the block containing it (after the merge pass one block may
    /// contain several leaves).
    pub block: Option<usize>,
}

impl TreeNode {
    /// The root of a decomposition tree: the whole region, no parent, no step, no cuts yet.
    pub(crate) fn root() -> Self {
        TreeNode {
            label: String::new(),
            parent: None,
            children: Vec::new(),
            step: None,
            cuts: Vec::new(),
            block: None,
        }
    }
}

/// A maximal piece Q_j of a block side: one whole cut, or a run of original boundary between
/// corners / cut endpoints ([Méndez 2023, §5.1]).
#[derive(Debug, Clone, PartialEq)]
pub struct SideCurve {
    /// The points, in the block's counter-clockwise order (first and last are corners or cut
    /// endpoints).
    pub points: Vec<DVec2>,
    /// What the curve is (for a cut: which cut and the neighbour block).
    pub kind: EdgeKind,
    /// Ring index of the first point in the block ring.
    pub start: usize,
}

/// An admissible decomposition of a region into blocks.
#[derive(Debug, Clone, PartialEq)]
pub struct Decomposition {
    /// The blocks (leaves), `blocks[k].id == k`.
    pub blocks: Vec<Block>,
    /// The cuts, `cuts[c].id == c`.
    pub cuts: Vec<Cut>,
    /// The binary decomposition tree (node 0 = root); empty when loaded from a file that gave
    /// the blocks explicitly.
    pub tree: Vec<TreeNode>,
}

impl Block {
    /// The exact bit patterns of the ring's coordinates, `[x₀, y₀, x₁, …]`: a key under which
    /// results that depend only on the block's geometry can be cached (two blocks have equal
    /// keys exactly when their rings are equal, starting at the same vertex).
    pub fn geometry_key(&self) -> Vec<u64> {
        self.ring
            .iter()
            .flat_map(|p| [p.x.to_bits(), p.y.to_bits()])
            .collect()
    }

    /// The four sides (bottom, right, top, left), each split into its curves Q_j: one per cut
    /// edge, one per maximal run of boundary edges of one region ring.
    pub fn side_curves(&self) -> [Vec<SideCurve>; 4] {
        let n = self.ring.len();
        let mut out: [Vec<SideCurve>; 4] = Default::default();
        for (s, side) in out.iter_mut().enumerate() {
            let from = self.corners[s];
            let to = self.corners[(s + 1) % 4];
            let len = (to + n - from) % n;
            let len = if len == 0 { n } else { len };
            let mut k = 0;
            while k < len {
                let e = (from + k) % n;
                let kind = self.edges[e];
                let mut pts = vec![self.ring[e], self.ring[(e + 1) % n]];
                k += 1;
                if matches!(kind, EdgeKind::Boundary { .. }) {
                    while k < len && self.edges[(from + k) % n] == kind {
                        pts.push(self.ring[(from + k + 1) % n]);
                        k += 1;
                    }
                }
                side.push(SideCurve {
                    points: pts,
                    kind,
                    start: e,
                });
            }
        }
        out
    }

    /// Interior angles (radians) at the four corners.
    pub fn corner_angles(&self) -> [f64; 4] {
        self.corners.map(|c| ring_angle(&self.ring, c))
    }

    /// Arc lengths of the four sides (bottom, right, top, left).
    pub fn side_lengths(&self) -> [f64; 4] {
        let n = self.ring.len();
        let mut out = [0.0; 4];
        for (s, o) in out.iter_mut().enumerate() {
            let from = self.corners[s];
            let to = self.corners[(s + 1) % 4];
            let mut k = from;
            loop {
                *o += self.ring[k].distance(self.ring[(k + 1) % n]);
                k = (k + 1) % n;
                if k == to {
                    break;
                }
            }
        }
        out
    }

    /// Area of the block.
    pub fn area(&self) -> f64 {
        signed_area(&self.ring)
    }
}

impl Decomposition {
    /// Edges of the block adjacency graph 𝒢: `(cut, block, block)` for every cut (two blocks
    /// may share more than one cut around a hole).
    pub fn adjacency(&self) -> Vec<(usize, usize, usize)> {
        self.cuts
            .iter()
            .map(|c| (c.id, c.blocks[0], c.blocks[1]))
            .collect()
    }

    /// The distinct neighbours of a block in 𝒢, sorted.
    pub fn neighbours(&self, block: usize) -> Vec<usize> {
        let mut v: Vec<usize> = self
            .cuts
            .iter()
            .filter_map(|c| {
                if c.blocks[0] == block {
                    Some(c.blocks[1])
                } else if c.blocks[1] == block {
                    Some(c.blocks[0])
                } else {
                    None
                }
            })
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// Number of independent cycles of 𝒢 (as a multigraph): edges − vertices + components,
    /// where a chain of cuts between the same two blocks that meet end to end (a cut split by
    /// the triangle-block rule) counts as one edge. Equals the number of holes of the region
    /// for a valid decomposition.
    pub fn graph_cycles(&self) -> usize {
        // cut chains: union cuts with the same block pair sharing an endpoint
        let m = self.cuts.len();
        let mut chain: Vec<usize> = (0..m).collect();
        fn top(p: &mut [usize], x: usize) -> usize {
            let mut r = x;
            while p[r] != r {
                r = p[r];
            }
            p[x] = r;
            r
        }
        let pair = |c: &Cut| (c.blocks[0].min(c.blocks[1]), c.blocks[0].max(c.blocks[1]));
        for i in 0..m {
            for j in i + 1..m {
                let (ci, cj) = (&self.cuts[i], &self.cuts[j]);
                if pair(ci) == pair(cj)
                    && (ci.a == cj.a || ci.a == cj.b || ci.b == cj.a || ci.b == cj.b)
                {
                    let (a, b) = (top(&mut chain, i), top(&mut chain, j));
                    chain[a] = b;
                }
            }
        }
        let edges = (0..m).filter(|&i| top(&mut chain, i) == i).count();
        let n = self.blocks.len();
        let mut parent: Vec<usize> = (0..n).collect();
        fn find(p: &mut [usize], x: usize) -> usize {
            let mut r = x;
            while p[r] != r {
                r = p[r];
            }
            let mut y = x;
            while p[y] != r {
                let nx = p[y];
                p[y] = r;
                y = nx;
            }
            r
        }
        let mut comps = n;
        for c in &self.cuts {
            let a = find(&mut parent, c.blocks[0]);
            let b = find(&mut parent, c.blocks[1]);
            if a != b {
                parent[a] = b;
                comps -= 1;
            }
        }
        (edges + comps).saturating_sub(n)
    }

    /// `true` if block `id` is admissible ([Méndez 2023, §4.1]): approximately convex by the
    /// concavity criteria and, unless it is a triangle block, without critical angles.
    pub fn block_admissible(&self, id: usize, tol: &crate::concavity::Tolerances) -> bool {
        let b = &self.blocks[id];
        crate::concavity::concavity(&b.ring).approximately_convex(tol)
            && (b.triangle
                || crate::concavity::critical_angles(&b.ring, tol.theta_minus).is_empty())
    }

    /// **Cut joints**: block vertices that do not lie on the region boundary (within
    /// 10⁻⁹ of the bounding-box diagonal), sorted by coordinates, each listed once.
    ///
    /// In a decomposition without joints every cut ends on the region boundary, so the
    /// blocks' structured grids meet along whole cuts and every interior mesh node has
    /// valence 4. A joint is where a cut was split by the triangle-block rule (a corner placed
    /// inside a cut): one block has a corner there while its neighbour sees a
    /// straight side, and the merged mesh gets an interior node of valence 3 and one of
    /// valence 5. The automatic decomposition avoids them (module `repair`); an empty result
    /// is the check for "no corner strictly inside a cut".
    ///
    /// ```
    /// # use unamalla_mesh::{DVec2, Region};
    /// # use unamalla_decompose::{decompose, DecomposeOptions};
    /// let square = Region::new(
    ///     vec![DVec2::new(0., 0.), DVec2::new(1., 0.), DVec2::new(1., 1.), DVec2::new(0., 1.)],
    ///     vec![],
    /// ).unwrap();
    /// let d = decompose(&square, &DecomposeOptions::default()).unwrap();
    /// assert!(d.cut_joints(&square).is_empty());
    /// ```
    pub fn cut_joints(&self, region: &Region) -> Vec<DVec2> {
        let tol = boundary_tol(region);
        let mut out: Vec<DVec2> = Vec::new();
        for b in &self.blocks {
            for &p in &b.ring {
                let on_boundary = region.rings().any(|r| {
                    let q = r.points();
                    (0..q.len()).any(|k| {
                        unamalla_mesh::geometry::point_segment_distance(
                            p,
                            q[k],
                            q[(k + 1) % q.len()],
                        ) <= tol
                    })
                });
                if !on_boundary && !out.contains(&p) {
                    out.push(p);
                }
            }
        }
        out.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
        out
    }

    /// Smallest corner angle over all blocks (radians).
    pub fn min_corner_angle(&self) -> f64 {
        self.blocks
            .iter()
            .flat_map(|b| b.corner_angles())
            .fold(f64::INFINITY, f64::min)
    }

    /// Largest corner angle over all blocks (radians).
    pub fn max_corner_angle(&self) -> f64 {
        self.blocks
            .iter()
            .flat_map(|b| b.corner_angles())
            .fold(0.0, f64::max)
    }

    /// Checks everything a consumer relies on, against the region: ids, simple
    /// counter-clockwise block rings, every block edge either a listed cut or a piece of the
    /// region boundary (the edge bookkeeping is recomputed and must match), cuts inside the
    /// region, pairwise disjoint but for shared endpoints, each an edge of exactly two blocks in
    /// opposite directions, every boundary edge covered exactly once, areas adding up to the
    /// region's, and four valid corners per block. Together these imply that the blocks tile
    /// the region without overlap.
    pub fn validate(&self, region: &Region) -> Result<(), DecomposeError> {
        let (edges, _) = classify(region, &self.blocks, &self.cuts)?;
        for (b, e) in self.blocks.iter().zip(&edges) {
            if &b.edges != e {
                return Err(DecomposeError::BadCorners {
                    block: b.id,
                    reason: "stored edge bookkeeping differs from the geometry".into(),
                });
            }
            check_corners(b.id, &b.ring, &b.corners)?;
        }
        Ok(())
    }
}
