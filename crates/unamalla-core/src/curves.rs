//! Pipeline step 3: the curves `Q_j` of every block side and their compatible point counts.
//!
//! Every block side of a [`Decomposition`] is split into curves `Q_j` — maximal runs of one
//! region ring, or one whole cut — numbered block by block and side by side (the `J_{k,side}`
//! convention of seed 000 §5.2.1). [`BlockCurves::problem`] states the compatibility system
//! (5.1)–(5.4) of `unamalla-compat-ilp` for them, [`compatible_counts`] solves it for a
//! [`MeshSize`], and [`BlockCurves::predicted_cells`] gives the number of cells the counts make
//! without building the mesh: block `k` with `n_b` points on its bottom side and `n_l` on its
//! left side has `(n_b − 1)(n_l − 1)` cells (seed 000 (5.5)/(5.6): `M_k × N_k` points).

use std::collections::HashMap;

use unamalla_compat_ilp::{self as ilp, CompatProblem};
use unamalla_decompose::{Decomposition, EdgeKind};
use unamalla_mesh::resample::{polyline_length, resample_arc_length};
use unamalla_mesh::{tfi2, DVec2, StructuredGrid2, TfiParams};

use crate::pipeline::MeshSize;
use crate::CoreError;

/// The curves Q_j of every block side, numbered block by block and side by side (the J_{k,side}
/// convention of seed 000 §5.2.1), with the cut pairs.
#[derive(Debug, Clone)]
pub struct BlockCurves {
    /// For each block and side, the curve ids.
    sides: Vec<[Vec<usize>; 4]>,
    /// Curve polylines in block-CCW order.
    points: Vec<Vec<DVec2>>,
    /// For cut curves: (cut id, whether the polyline runs from cut.a to cut.b).
    cut_of: Vec<Option<(usize, bool)>>,
    /// For boundary curves: the region ring (0 = outer, k = hole k − 1).
    ring_of: Vec<Option<usize>>,
}

impl BlockCurves {
    /// The curves of every block side of `d`.
    pub fn new(d: &Decomposition) -> Self {
        let mut sides = Vec::with_capacity(d.blocks.len());
        let mut points = Vec::new();
        let mut cut_of = Vec::new();
        let mut ring_of = Vec::new();
        for b in &d.blocks {
            let sc = b.side_curves();
            let mut ids: [Vec<usize>; 4] = Default::default();
            for (s, curves) in sc.iter().enumerate() {
                for c in curves {
                    ids[s].push(points.len());
                    let (cut, ring) = match c.kind {
                        EdgeKind::Cut { cut, .. } => {
                            let a = d.cuts[cut].a;
                            let forward =
                                c.points[0].distance(a) <= c.points[c.points.len() - 1].distance(a);
                            (Some((cut, forward)), None)
                        }
                        EdgeKind::Boundary { ring } => (None, Some(ring)),
                    };
                    points.push(c.points.clone());
                    cut_of.push(cut);
                    ring_of.push(ring);
                }
            }
            sides.push(ids);
        }
        Self {
            sides,
            points,
            cut_of,
            ring_of,
        }
    }

    /// Number of curves `p`.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether there are no curves (never for a valid decomposition).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The curve ids of block `k`'s sides (bottom, right, top, left).
    pub fn block_sides(&self, k: usize) -> &[Vec<usize>; 4] {
        &self.sides[k]
    }

    /// The polyline of curve `j`, in its block's counter-clockwise order.
    pub fn points(&self, j: usize) -> &[DVec2] {
        &self.points[j]
    }

    /// The cut curve `j` is a copy of, if any.
    pub fn cut(&self, j: usize) -> Option<usize> {
        self.cut_of[j].map(|(c, _)| c)
    }

    /// The region ring (0 = outer, `k` = hole `k − 1`) boundary curve `j` lies on, if any.
    pub fn ring(&self, j: usize) -> Option<usize> {
        self.ring_of[j]
    }

    /// The compatibility problem (5.1)–(5.4) of the curves: curve `j` has id `j` and its
    /// polyline length, block `k` has id `k`, and the two copies of every cut form a pair.
    pub fn problem(&self) -> CompatProblem {
        let curves = self
            .points
            .iter()
            .enumerate()
            .map(|(j, p)| ilp::Curve::new(j, polyline_length(p)))
            .collect();
        let blocks = self
            .sides
            .iter()
            .enumerate()
            .map(|(k, s)| {
                ilp::Block::new(k, s[0].clone(), s[1].clone(), s[2].clone(), s[3].clone())
            })
            .collect();
        let mut first: HashMap<usize, usize> = Default::default();
        let mut cuts = Vec::new();
        for (j, c) in self.cut_of.iter().enumerate() {
            if let Some((cut, _)) = c {
                if let Some(&i) = first.get(cut) {
                    cuts.push(ilp::CutPair::new(i, j));
                } else {
                    first.insert(*cut, j);
                }
            }
        }
        CompatProblem::new(curves, blocks, cuts)
    }

    /// Points on side `s` (0 = bottom … 3 = left) of block `k` for the given curve counts:
    /// `Σ_{j ∈ J_{k,s}} m_j − s_{k,s} + 1` (junction points counted once, seed 000 (5.5)).
    pub fn side_points(&self, counts: &[usize], k: usize, s: usize) -> usize {
        let side = &self.sides[k][s];
        side.iter().map(|&j| counts[j]).sum::<usize>() + 1 - side.len()
    }

    /// The number of cells block `k` gets with these counts: `(n_b − 1)(n_l − 1)`, `n_b`, `n_l`
    /// the points on its bottom and left sides ([`BlockCurves::side_points`]).
    pub fn block_cells(&self, counts: &[usize], k: usize) -> usize {
        let nb = self.side_points(counts, k, 0);
        let nl = self.side_points(counts, k, 3);
        nb.saturating_sub(1) * nl.saturating_sub(1)
    }

    /// The number of cells the mesh gets with these counts (one per curve, indexed like the
    /// curves): `Σ_k (n_{k,b} − 1)(n_{k,l} − 1)` over the blocks.
    pub fn predicted_cells(&self, counts: &[usize]) -> usize {
        (0..self.sides.len())
            .map(|k| self.block_cells(counts, k))
            .sum()
    }

    /// Resamples every curve with its count (cuts once, shared by both copies) and fills every
    /// block by TFI.
    pub fn grids(
        &self,
        d: &Decomposition,
        counts: &[usize],
    ) -> Result<Vec<StructuredGrid2>, CoreError> {
        let mut cut_pts: HashMap<usize, Vec<DVec2>> = Default::default();
        let mut sampled: Vec<Vec<DVec2>> = Vec::with_capacity(self.points.len());
        for (j, p) in self.points.iter().enumerate() {
            let m = counts[j];
            let pts = match self.cut_of[j] {
                Some((cut, forward)) => {
                    let canon = cut_pts.entry(cut).or_insert_with(|| {
                        let c = &d.cuts[cut];
                        resample_arc_length(&[c.a, c.b], m).unwrap_or_else(|_| vec![c.a, c.b])
                    });
                    let mut v = canon.clone();
                    if !forward {
                        v.reverse();
                    }
                    // endpoints exactly as the block ring has them
                    if let (Some(f), Some(l)) = (v.first_mut(), p.first()) {
                        *f = *l;
                    }
                    if let (Some(f), Some(l)) = (v.last_mut(), p.last()) {
                        *f = *l;
                    }
                    v
                }
                None => resample_arc_length(p, m)?,
            };
            sampled.push(pts);
        }
        let mut grids = Vec::with_capacity(self.sides.len());
        for sides in &self.sides {
            let side = |s: usize| -> Vec<DVec2> {
                let mut out: Vec<DVec2> = Vec::new();
                for &j in &sides[s] {
                    let pts = &sampled[j];
                    if out.is_empty() {
                        out.extend_from_slice(pts);
                    } else {
                        out.extend_from_slice(&pts[1..]);
                    }
                }
                out
            };
            let bottom = side(0);
            let right = side(1);
            let mut top = side(2);
            top.reverse();
            let mut left = side(3);
            left.reverse();
            grids.push(tfi2(&bottom, &right, &top, &left, TfiParams::ArcLength)?);
        }
        Ok(grids)
    }
}

/// The area of the decomposed region: the sum of the block areas.
pub fn decomposition_area(d: &Decomposition) -> f64 {
    d.blocks.iter().map(|b| b.area()).sum()
}

/// The compatible point counts of pipeline step 3 for a decomposition and a mesh size
/// (the region's area, for [`MeshSize::Cells`], is the sum of the block areas): the integer
/// program (5.10) of `unamalla-compat-ilp` with lower bounds from the cell size
/// `h = √(area / N)` (or the given `h`, or the density factor `d`). Returns the solution and
/// the curves it is indexed by.
pub fn compatible_counts(
    d: &Decomposition,
    size: MeshSize,
) -> Result<(BlockCurves, ilp::CompatSolution), CoreError> {
    let curves = BlockCurves::new(d);
    let problem = curves.problem();
    let bounds = match size {
        MeshSize::Cells(n) => {
            let n = n.max(1) as f64;
            ilp::LowerBounds::CellSize((decomposition_area(d) / n).sqrt())
        }
        MeshSize::CellSize(h) => ilp::LowerBounds::CellSize(h),
        MeshSize::Density(dens) => ilp::LowerBounds::Density(dens.max(1)),
    };
    let solve_opts = ilp::SolveOptions {
        bounds,
        ..ilp::SolveOptions::default()
    };
    let counts = ilp::solve(&problem, &solve_opts)?;
    Ok((curves, counts))
}
