//! The result of the stage: blocks with their rings, edge bookkeeping and corners, the cuts,
//! the binary decomposition tree and the block adjacency graph ([Méndez 2023, §4.3, §5.1]).

use std::collections::HashMap;
use std::f64::consts::PI;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use unamalla_mesh::geometry::{open_segment_hits, point_segment_distance};
use unamalla_mesh::{DVec2, Region, SegmentIndex};

use crate::error::DecomposeError;
use crate::geom::{ring_angle, signed_area};

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

/// Absolute tolerance for "lies on the region boundary": 1e-9 of the bounding-box diagonal.
pub(crate) fn boundary_tol(region: &Region) -> f64 {
    let (lo, hi) = region.bounding_box();
    1e-9 * lo.distance(hi).max(f64::MIN_POSITIVE)
}

/// Edge bookkeeping per block and the two blocks of every cut.
pub(crate) type Classified = (Vec<Vec<EdgeKind>>, Vec<[usize; 2]>);
type PointKey = (u64, u64);
type CoverList = Vec<(f64, DVec2, DVec2)>;

/// Validates the geometry of blocks and cuts (everything but corners) and derives the edge
/// bookkeeping of every block and the two blocks of every cut.
pub(crate) fn classify(
    region: &Region,
    blocks: &[Block],
    cuts: &[Cut],
) -> Result<Classified, DecomposeError> {
    let tol = boundary_tol(region);
    for (k, b) in blocks.iter().enumerate() {
        if b.id != k {
            return Err(DecomposeError::BadId {
                what: "block",
                id: b.id,
                count: blocks.len(),
            });
        }
    }
    for (k, c) in cuts.iter().enumerate() {
        if c.id != k {
            return Err(DecomposeError::BadId {
                what: "cut",
                id: c.id,
                count: cuts.len(),
            });
        }
        for &b in &c.blocks {
            if b >= blocks.len() && c.blocks != [usize::MAX; 2] {
                return Err(DecomposeError::UnknownBlock { cut: k, block: b });
            }
        }
    }
    check_cuts(region, cuts)?;
    // blocks: simple, counter-clockwise (checked in parallel; the first failing block in
    // order gives the error, as a sequential loop would)
    let block_ok = |b: &Block| -> Result<(), DecomposeError> {
        if b.ring.len() < 3 {
            return Err(DecomposeError::BlockTooSmall {
                block: b.id,
                count: b.ring.len(),
            });
        }
        let a = signed_area(&b.ring);
        if a.is_nan() || a <= 0.0 {
            return Err(DecomposeError::BlockNotCounterClockwise {
                block: b.id,
                area: a,
            });
        }
        if let Some((x, y)) = SegmentIndex::new(vec![b.ring.clone()]).first_intersection() {
            return Err(DecomposeError::BlockNotSimple {
                block: b.id,
                edge_a: x.edge,
                edge_b: y.edge,
            });
        }
        Ok(())
    };
    first_error(blocks.par_iter().map(block_ok).collect())?;
    // edges: cut or boundary
    let key = |p: DVec2| (p.x.to_bits(), p.y.to_bits());
    let mut cut_map: HashMap<(PointKey, PointKey), usize> = HashMap::new();
    for c in cuts {
        cut_map.insert((key(c.a), key(c.b)), c.id);
        cut_map.insert((key(c.b), key(c.a)), c.id);
    }
    let rings: Vec<&[DVec2]> = region.rings().map(|p| p.points()).collect();
    let index = region.edge_index();
    // each block's edges, in parallel: the kinds, the cuts used (cut, start point) and the
    // region edges covered ((ring, edge), (t of start, start, end)); gathered in block
    // order below, as a sequential loop would record them
    type BlockEdges = (
        Vec<Option<(bool, usize)>>,
        Vec<(usize, DVec2)>,
        Vec<((usize, usize), (f64, DVec2, DVec2))>,
    );
    let block_edges = |b: &Block| -> Result<BlockEdges, DecomposeError> {
        let n = b.ring.len();
        let mut ks = Vec::with_capacity(n);
        let (mut used, mut covered) = (Vec::new(), Vec::new());
        for e in 0..n {
            let u = b.ring[e];
            let v = b.ring[(e + 1) % n];
            if let Some(&c) = cut_map.get(&(key(u), key(v))) {
                used.push((c, u));
                ks.push(Some((true, c)));
                continue;
            }
            let mid = 0.5 * (u + v);
            let lo = u.min(v) - DVec2::splat(tol);
            let hi = u.max(v) + DVec2::splat(tol);
            let mut found = None;
            for er in index.candidates(lo, hi) {
                let (a, bb) = index.edge(er);
                if point_segment_distance(u, a, bb) <= tol
                    && point_segment_distance(v, a, bb) <= tol
                    && point_segment_distance(mid, a, bb) <= tol
                    && (v - u).dot(bb - a) > 0.0
                {
                    found = Some(er);
                    break;
                }
            }
            let Some(er) = found else {
                return Err(DecomposeError::BlockEdgeUnexplained {
                    block: b.id,
                    edge: e,
                    ax: u.x,
                    ay: u.y,
                    bx: v.x,
                    by: v.y,
                });
            };
            let (a, bb) = index.edge(er);
            let t = crate::geom::project_t(u, a, bb);
            covered.push(((er.ring, er.edge), (t, u, v)));
            ks.push(Some((false, er.ring)));
        }
        Ok((ks, used, covered))
    };
    let per_block: Vec<Result<BlockEdges, DecomposeError>> =
        blocks.par_iter().map(block_edges).collect();
    let mut uses: Vec<Vec<(usize, DVec2)>> = vec![Vec::new(); cuts.len()];
    // per region edge: (t of start, start, end)
    let mut cover: HashMap<(usize, usize), CoverList> = HashMap::new();
    let mut kinds: Vec<Vec<Option<(bool, usize)>>> = Vec::with_capacity(blocks.len());
    for (b, r) in blocks.iter().zip(per_block) {
        let (ks, used, covered) = r?;
        for (c, u) in used {
            uses[c].push((b.id, u));
        }
        for (edge, entry) in covered {
            cover.entry(edge).or_default().push(entry);
        }
        kinds.push(ks);
    }
    // every cut used exactly twice, opposite directions, two different blocks
    let mut sides = Vec::with_capacity(cuts.len());
    for c in cuts {
        let u = &uses[c.id];
        if u.len() != 2 || u[0].1 == u[1].1 || u[0].0 == u[1].0 {
            return Err(DecomposeError::CutNotShared {
                cut: c.id,
                count: u.len(),
            });
        }
        let found = [u[0].0, u[1].0];
        let mut f = found;
        f.sort_unstable();
        let mut l = c.blocks;
        l.sort_unstable();
        // `[usize::MAX; 2]` = not given (files may omit the blocks of a cut)
        if c.blocks != [usize::MAX; 2] && f != l {
            return Err(DecomposeError::CutBlocksMismatch {
                cut: c.id,
                listed: c.blocks,
                found,
            });
        }
        sides.push(found);
    }
    // boundary covered exactly once
    for (r, ring) in rings.iter().enumerate() {
        let n = ring.len();
        for e in 0..n {
            let a = ring[e];
            let b = ring[(e + 1) % n];
            let Some(list) = cover.get_mut(&(r, e)) else {
                return Err(DecomposeError::BoundaryNotCovered { ring: r, edge: e });
            };
            list.sort_by(|x, y| x.0.total_cmp(&y.0));
            let ok = list[0].1.distance(a) <= tol
                && list.last().is_some_and(|l| l.2.distance(b) <= tol)
                && list.windows(2).all(|w| w[0].2 == w[1].1);
            if !ok {
                return Err(DecomposeError::BoundaryNotCovered { ring: r, edge: e });
            }
        }
    }
    // areas
    let total: f64 = blocks.iter().map(|b| signed_area(&b.ring)).sum();
    let area = region.area();
    if (total - area).abs() > 1e-7 * area.abs().max(f64::MIN_POSITIVE) {
        return Err(DecomposeError::AreaMismatch {
            blocks: total,
            region: area,
        });
    }
    Ok((
        kinds
            .into_iter()
            .enumerate()
            .map(|(bid, ks)| {
                ks.into_iter()
                    .map(|k| match k {
                        Some((true, c)) => {
                            let s = sides[c];
                            EdgeKind::Cut {
                                cut: c,
                                neighbour: if s[0] == bid { s[1] } else { s[0] },
                            }
                        }
                        Some((false, ring)) => EdgeKind::Boundary { ring },
                        None => EdgeKind::Boundary { ring: 0 },
                    })
                    .collect()
            })
            .collect(),
        sides,
    ))
}

/// The first error of `results` (in order), as a loop stopping there would return it.
fn first_error(results: Vec<Result<(), DecomposeError>>) -> Result<(), DecomposeError> {
    results.into_iter().collect()
}

/// Cuts: finite, endpoints on the boundary (or at a joint shared with another cut, where the
/// triangle-block rule split a cut), inside the region, pairwise disjoint.
pub(crate) fn check_cuts(region: &Region, cuts: &[Cut]) -> Result<(), DecomposeError> {
    let tol = boundary_tol(region);
    let index = region.edge_index();
    let max_x = region.bounding_box().1.x;
    // each cut on its own, in parallel; the first failing cut in order gives the error, as a
    // sequential loop would
    let cut_ok = |c: &Cut| -> Result<(), DecomposeError> {
        for (name, p) in [('a', c.a), ('b', c.b)] {
            if !p.is_finite() {
                return Err(DecomposeError::NonFinite {
                    what: format!("cut {} endpoint {name}", c.id),
                });
            }
            let lo = p - DVec2::splat(tol);
            let hi = p + DVec2::splat(tol);
            let on = index.candidates(lo, hi).any(|er| {
                let (a, b) = index.edge(er);
                point_segment_distance(p, a, b) <= tol
            });
            // a joint where a cut was split by the triangle-block rule: shared with another cut
            // (only looked for when the end is not on the boundary: the test is pure)
            let joint = || cuts.iter().any(|d| d.id != c.id && (d.a == p || d.b == p));
            if !on && !joint() {
                return Err(DecomposeError::CutEndNotOnBoundary {
                    cut: c.id,
                    endpoint: name,
                    x: p.x,
                    y: p.y,
                });
            }
        }
        let err = DecomposeError::CutCrossesBoundary {
            cut: c.id,
            ax: c.a.x,
            ay: c.a.y,
            bx: c.b.x,
            by: c.b.y,
        };
        if c.a == c.b {
            return Err(err);
        }
        // endpoints may sit a rounding error off the boundary: test the segment shrunk at both
        // ends by a relative 1e-9 or, far from the origin, by 64 units in the last place of
        // the coordinates (at 10⁹ an ulp is 1.2·10⁻⁷, so a 1e-9 shrink of a short cut does
        // not move its ends at all)
        let d = c.b - c.a;
        let scale = c.a.abs().max(c.b.abs()).max_element();
        let shrink = (1e-9f64)
            .max(64.0 * f64::EPSILON * scale / d.length())
            .min(0.25);
        let a2 = c.a + shrink * d;
        let b2 = c.b - shrink * d;
        if !(contains_point_with(region, &index, max_x, a2)
            && contains_point_with(region, &index, max_x, b2)
            && !index.open_segment_blocked(a2, b2))
        {
            return Err(err);
        }
        Ok(())
    };
    first_error(cuts.par_iter().map(cut_ok).collect())?;
    if cuts.len() > 1 {
        let cut_index = SegmentIndex::new(cuts.iter().map(|c| vec![c.a, c.b]).collect());
        let disjoint = |c: &Cut| -> Result<(), DecomposeError> {
            for er in cut_index.candidates(c.a, c.b) {
                if er.ring == c.id {
                    continue;
                }
                let (p, q) = cut_index.edge(er);
                if open_segment_hits(c.a, c.b, p, q) || open_segment_hits(p, q, c.a, c.b) {
                    return Err(DecomposeError::CutsIntersect {
                        cut_a: c.id.min(er.ring),
                        cut_b: c.id.max(er.ring),
                    });
                }
            }
            Ok(())
        };
        first_error(cuts.par_iter().map(disjoint).collect())?;
    }
    Ok(())
}

/// [`Region::contains_point`] (`p` in the open region) with `index` =
/// [`Region::edge_index`] of `region` and `max_x` the largest `x` of its bounding box,
/// looking only at the edges whose bounding box meets the horizontal ray from `p` to the
/// right (up to `max_x`).
///
/// The same answer: `contains_point` locates `p` in each ring by the winding number of
/// `locate_in_ring` (an edge counts +1 if it goes up across the height of `p` with `p`
/// strictly on its left, −1 if it goes down with `p` strictly on its right, both by the
/// exact `orient2d`), and `p` on any edge (exactly) is on the boundary. An edge that counts
/// crosses the height of `p` to its right, and an edge holding `p` holds it in its bounding
/// box: either way the box meets the ray, so the edges left out count 0 and do not hold `p`.
/// The rules are evaluated here on the same numbers with the same predicates. `p` is inside
/// exactly when it is on no edge, the outer ring's winding number is not 0 and every hole's
/// is (a point inside a hole or on any ring is not in the open region).
pub(crate) fn contains_point_with(
    region: &Region,
    index: &SegmentIndex,
    max_x: f64,
    p: DVec2,
) -> bool {
    let mut winding = vec![0i64; region.rings().count()];
    for er in index.candidates(p, DVec2::new(max_x, p.y)) {
        let (a, b) = index.edge(er);
        let o = unamalla_mesh::geometry::orient2d(a, b, p);
        if o == 0.0 && unamalla_mesh::geometry::point_on_segment(a, b, p) {
            return false;
        }
        if a.y <= p.y {
            if b.y > p.y && o > 0.0 {
                winding[er.ring] += 1;
            }
        } else if b.y <= p.y && o < 0.0 {
            winding[er.ring] -= 1;
        }
    }
    winding[0] != 0 && winding[1..].iter().all(|&w| w == 0)
}

/// Corners: four distinct indices in range, in counter-clockwise ring order, none reflex.
pub(crate) fn check_corners(
    block: usize,
    ring: &[DVec2],
    corners: &[usize; 4],
) -> Result<(), DecomposeError> {
    let n = ring.len();
    if let Some(&c) = corners.iter().find(|&&c| c >= n) {
        return Err(DecomposeError::BadCorners {
            block,
            reason: format!("corner index {c} is out of range (ring has {n} points)"),
        });
    }
    // cyclic order: the forward gaps must add up to exactly one turn
    let gaps: usize = (0..4)
        .map(|k| (corners[(k + 1) % 4] + n - corners[k]) % n)
        .sum();
    if gaps != n
        || corners
            .iter()
            .any(|c| corners.iter().filter(|d| *d == c).count() > 1)
    {
        return Err(DecomposeError::BadCorners {
            block,
            reason: format!(
                "corners {corners:?} must be four distinct indices in counter-clockwise ring order"
            ),
        });
    }
    for &c in corners {
        let a = ring_angle(ring, c);
        if a > PI + 1e-6 {
            return Err(DecomposeError::BadCorners {
                block,
                reason: format!(
                    "corner at ring index {c} is reflex ({:.1}°)",
                    a.to_degrees()
                ),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `contains_point_with` answers as `Region::contains_point` on a region with a hole and
    /// horizontal edges, at vertices, on edges, at the heights of vertices and elsewhere.
    #[test]
    fn indexed_point_location_matches_contains_point() {
        let v = DVec2::new;
        let region = Region::new(
            vec![
                v(0.0, 0.0),
                v(6.0, 0.0),
                v(6.0, 2.0),
                v(4.0, 2.0),
                v(5.0, 4.0),
                v(6.0, 6.0),
                v(0.0, 6.0),
                v(1.0, 3.0),
            ],
            vec![vec![v(2.0, 2.0), v(2.0, 4.0), v(3.0, 4.0), v(3.0, 2.0)]],
        )
        .expect("region");
        let index = region.edge_index();
        let mut points: Vec<DVec2> = region.rings().flat_map(|r| r.points().to_vec()).collect();
        for r in region.rings() {
            let p = r.points();
            for k in 0..p.len() {
                points.push(0.5 * (p[k] + p[(k + 1) % p.len()]));
            }
        }
        for i in 0..=28 {
            for j in 0..=28 {
                points.push(v(-0.5 + 0.25 * i as f64, -0.5 + 0.25 * j as f64));
            }
        }
        for p in points {
            assert_eq!(
                contains_point_with(&region, &index, region.bounding_box().1.x, p),
                region.contains_point(p),
                "{p:?}"
            );
        }
    }
}
