//! The curves `Q_j` of every block side of a [`Decomposition`], the adapter from a
//! decomposition to the compatibility problem of `unamalla-compat-ilp`, and the resampling of
//! the curves that fills every block by transfinite interpolation.
//!
//! Every block side is split into curves `Q_j` — maximal runs of one region ring, or one whole
//! cut — numbered block by block and side by side (the `J_{k,side}` convention of
//! [Méndez 2023, §5.2.1]; the references are listed in `docs/references.md` of the
//! repository). [`BlockCurves::problem`] states the compatibility system (5.1)–(5.4) for them;
//! [`BlockCurves::predicted_cells`] gives the number of cells a set of counts makes without
//! building the mesh: block `k` with `n_b` points on its bottom side and `n_l` on its left side
//! has `(n_b − 1)(n_l − 1)` cells ([Méndez 2023, (5.5), (5.6)]: `M_k × N_k` points);
//! [`BlockCurves::grids`] resamples every curve with its count ([`resample_keeping_corners`])
//! and fills the blocks by TFI.

use std::collections::HashMap;

use unamalla_compat_ilp::{self as ilp, CompatProblem};
use unamalla_mesh::resample::{cumulative_lengths, polyline_length, resample_arc_length};
use unamalla_mesh::{tfi2, DVec2, MeshError, StructuredGrid2, TfiParams};

use crate::{Decomposition, EdgeKind};

/// The curves Q_j of every block side, numbered block by block and side by side (the J_{k,side}
/// convention of [Méndez 2023, §5.2.1]), with the cut pairs.
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

    /// Number of blocks.
    pub fn blocks(&self) -> usize {
        self.sides.len()
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
    /// `Σ_{j ∈ J_{k,s}} m_j − s_{k,s} + 1` (junction points counted once, [Méndez 2023, (5.5)]).
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
    ) -> Result<Vec<StructuredGrid2>, MeshError> {
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
                None => resample_keeping_corners(p, m, CORNER_TURN_DEG)?,
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

/// Turning angle (degrees) above which an interior vertex of a boundary curve is a corner that
/// the resampling keeps as a node ([`resample_keeping_corners`]).
pub const CORNER_TURN_DEG: f64 = 20.0;

/// `m ≥ 2` points on the polyline `p`, by arc length, except that the sharpest interior vertices
/// turning by more than `min_turn_deg` (at most `m − 2` of them) are nodes: the polyline is split
/// there and its `m − 1` segments are shared among the pieces in proportion to their lengths
/// (largest remainders, at least one each). Plain arc-length resampling cuts such a corner with a
/// chord up to a segment long, so the mesh boundary leaves the region there when the counts are
/// small.
pub fn resample_keeping_corners(
    p: &[DVec2],
    m: usize,
    min_turn_deg: f64,
) -> Result<Vec<DVec2>, MeshError> {
    let arc = cumulative_lengths(p);
    match corner_plan(p, &arc, m, min_turn_deg) {
        None => Ok(resample_arc_length(p, m.max(2))?),
        Some(nodes) => Ok(nodes.iter().map(|&s| point_at(p, &arc, s)).collect()),
    }
}

/// The arc-length positions of the nodes of [`resample_keeping_corners`] (`None`: no corner is
/// kept, plain arc-length resampling).
fn corner_plan(p: &[DVec2], arc: &[f64], m: usize, min_turn_deg: f64) -> Option<Vec<f64>> {
    let m = m.max(2);
    let cos_max = min_turn_deg.to_radians().cos();
    // interior vertices by turning angle (sharpest first, ties by position)
    let mut corners: Vec<(f64, usize)> = (1..p.len().saturating_sub(1))
        .filter_map(|i| {
            let a = p[i] - p[i - 1];
            let b = p[i + 1] - p[i];
            let (la, lb) = (a.length(), b.length());
            if la == 0.0 || lb == 0.0 {
                return None;
            }
            let c = a.dot(b) / (la * lb);
            (c < cos_max).then_some((c, i))
        })
        .collect();
    corners.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    // a kept corner is at least half a mean segment from the ends and from the other kept
    // corners, so no piece gets a segment much shorter than the rest
    let total = *arc.last()?;
    let gap = 0.5 * total / (m - 1) as f64;
    let mut kept: Vec<usize> = Vec::new();
    for &(_, i) in &corners {
        if kept.len() + 2 >= m {
            break;
        }
        let far = |a: f64| (arc[i] - a).abs() >= gap;
        if far(0.0) && far(total) && kept.iter().all(|&k| far(arc[k])) {
            kept.push(i);
        }
    }
    if kept.is_empty() {
        return None;
    }
    kept.sort_unstable();
    let mut bounds = vec![0.0];
    bounds.extend(kept.iter().map(|&i| arc[i]));
    bounds.push(total);
    let lengths: Vec<f64> = bounds.windows(2).map(|w| w[1] - w[0]).collect();
    let pieces = lengths.len();
    let segs = m - 1;
    let spare = segs - pieces;
    let share: Vec<f64> = lengths
        .iter()
        .map(|l| {
            if total > 0.0 {
                l / total * spare as f64
            } else {
                0.0
            }
        })
        .collect();
    let mut alloc: Vec<usize> = share.iter().map(|s| 1 + s.floor() as usize).collect();
    let mut left = segs - alloc.iter().sum::<usize>();
    let mut order: Vec<usize> = (0..pieces).collect();
    order.sort_by(|&a, &b| {
        (share[b] - share[b].floor())
            .total_cmp(&(share[a] - share[a].floor()))
            .then(a.cmp(&b))
    });
    for &i in order.iter().cycle().take(pieces * 2) {
        if left == 0 {
            break;
        }
        alloc[i] += 1;
        left -= 1;
    }
    let mut nodes = vec![0.0];
    for (i, &k) in alloc.iter().enumerate() {
        for j in 1..=k {
            nodes.push(if j == k {
                bounds[i + 1]
            } else {
                bounds[i] + lengths[i] * j as f64 / k as f64
            });
        }
    }
    Some(nodes)
}

/// The point at arc length `s` of the polyline (`arc` its cumulative lengths).
fn point_at(p: &[DVec2], arc: &[f64], s: f64) -> DVec2 {
    let i = arc.partition_point(|&a| a <= s).clamp(1, p.len() - 1);
    let (a, b) = (arc[i - 1], arc[i]);
    if b <= a {
        return p[i];
    }
    let t = ((s - a) / (b - a)).clamp(0.0, 1.0);
    p[i - 1] + (p[i] - p[i - 1]) * t
}

/// The largest distance of a vertex of `p` from the resampled polyline of `m` points
/// ([`resample_keeping_corners`] with [`CORNER_TURN_DEG`]): each vertex is measured against the
/// chord between the two nodes around it.
pub fn chord_deviation(p: &[DVec2], m: usize) -> f64 {
    let arc = cumulative_lengths(p);
    let total = arc.last().copied().unwrap_or(0.0);
    let nodes: Vec<f64> = corner_plan(p, &arc, m, CORNER_TURN_DEG).unwrap_or_else(|| {
        let m = m.max(2);
        (0..m).map(|k| total * k as f64 / (m - 1) as f64).collect()
    });
    let mut worst: f64 = 0.0;
    let mut k = 0;
    for (i, &v) in p.iter().enumerate() {
        while k + 2 < nodes.len() && nodes[k + 1] <= arc[i] {
            k += 1;
        }
        let a = point_at(p, &arc, nodes[k]);
        let b = point_at(p, &arc, nodes[k + 1]);
        worst = worst.max(unamalla_mesh::geometry::point_segment_distance(v, a, b));
    }
    worst
}

/// Fewest points (≥ 2) whose resampling keeps `p` within `tol` ([`chord_deviation`]), by
/// bisection between 2 and `hi` (the deviation shrinks as points are added, up to the kept
/// corners' rounding); `hi` when even that is not enough.
pub fn points_for_deviation(p: &[DVec2], tol: f64, hi: usize) -> usize {
    if p.len() <= 2 || chord_deviation(p, 2) <= tol {
        return 2;
    }
    let (mut lo, mut hi) = (2usize, hi.max(3));
    if chord_deviation(p, hi) > tol {
        return hi;
    }
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if chord_deviation(p, mid) <= tol {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}
