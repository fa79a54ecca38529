//! Local shape improvement with boundary sliding: a pass after the variational smoothing that
//! raises the cells whose shape quality μ is below a target, moving one node at a time and
//! letting the nodes on the region boundary slide along it.
//!
//! # Why
//! The functionals of [`crate::smooth`] keep the nodes on the region boundary where the
//! transfinite interpolation put them (at arc-length positions along each block side). Where a
//! grid line meets the boundary obliquely, the cells of the boundary row stay sheared however
//! long the smoother runs, and at coarse resolution (a few cells across a channel) these rows
//! are a large part of the mesh. Letting the boundary nodes move *along* the boundary removes
//! that constraint; the interior nodes next to them must follow, so both are moved together.
//!
//! # The objective
//! For the shape quality `μ(Q) = 2·min αₖ / √((a² + c²)(b² + d²))` of
//! [`unamalla_mesh::quality::quad::mu`] (1 for every rectangle, `sin θ` for a parallelogram of
//! angle θ, `≤ 0` for a non-convex cell) and a target `τ` ([`ShapeOptions::target`]) the pass
//! decreases
//!
//! `Φ = Σ_cells (τ − μ(Q))₊²`,
//!
//! the squared shortfall below the target (cells at or above `τ` cost nothing), one node at a
//! time (a nonlinear Gauss–Seidel / coordinate-descent sweep over the nodes): the local
//! optimization-based smoothing of Freitag & Plassmann (2000, "Local optimization-based
//! simplicial mesh untangling and improvement", Int. J. Numer. Meth. Eng. 49(1–2), 109–125),
//! with the objective *summed* over the cells around the node instead of their minimum. A
//! max-min objective spreads the distortion of a flat block corner over more cells and
//! *lowers* the share of good cells (measured on the crow at 5,000 cells: 88.2 → 82.3 % after
//! six sweeps; docs/benchmarks.md, "Shape pass").
//!
//! * An **interior** node takes a Gauss–Newton step on its cells' residuals
//!   `rᵢ = (τ − μᵢ)₊` — `d = −(JᵀJ + λI)⁻¹Jᵀr`, the 2-column Jacobian `J` by central
//!   differences with step [`FD_STEP`]`·ℓ` (`ℓ` the smallest over the node's cells of the largest
//!   distance from the node to a corner), `λ = 10⁻⁹·tr JᵀJ`, `|d| ≤ `[`MAX_STEP`]`·ℓ` — halved up
//!   to [`LINE_SEARCH_HALVINGS`] times until the guards below pass and `Φ` decreases.
//! * A **boundary** node slides along its ring (the region's polyline, so it stays on the
//!   boundary): the candidates are the Gauss–Newton step along the arc and its halvings, and
//!   [`SLIDE_SAMPLES`] arc positions on either side (the objective along a ring need not be
//!   unimodal), up to [`SLIDE_REACH`] of the arc to the neighbouring boundary node and never
//!   past a *feature vertex* (a ring vertex that turns by more than
//!   [`ShapeOptions::feature_angle_deg`]); the best candidate that passes the guards is taken.
//!   A node on a feature vertex, or not on a ring (e.g. a flat corner bent inward), does not
//!   move.
//!
//! A move is accepted only if it decreases the node's share of `Φ` (ties broken by a larger
//! minimum μ), and only under three guards, so the pass can never make a mesh worse where it
//! matters:
//! 1. every cell around the node keeps `min αₖ ≥ min(its old local minimum, ε·ᾱ)` (ᾱ the mean
//!    α of the mesh at the start): **convex cells stay convex**, and ε-convex ones ε-convex;
//! 2. no cell around the node at or above `keep` ([`ShapeOptions::keep`], the μ = 0.8 of a
//!    "good" cell) drops below it, and the smallest μ around the node does not drop below
//!    `min(old smallest, keep)`: so the **share of good cells never decreases** and the
//!    mesh's minimum μ never decreases below `min(its start value, keep)`;
//! 3. the centroid of every cell around a moving boundary node (and of every cell with a
//!    boundary node around a moving interior node) moves along a segment that crosses no ring
//!    edge, so a centroid inside the region stays inside;
//! 4. every cell's area stays within a factor `ρ` ([`ShapeOptions::max_area_change`], 1.25)
//!    of its area at the start of the pass: μ is 1 for every rectangle whatever its size, and
//!    without this guard the pass roughened the smoother's size grading (chesapeake-bay at
//!    20,000 cells: 99th percentile of the area ratio of neighbouring cells 1.55 → 2.17; with
//!    ρ = 1.25, 1.72).
//!
//! Only nodes with a cell below [`ShapeOptions::active_below`] are visited. Sweeps run in node
//! order (sequential, so the result does not depend on the thread count) until a sweep lowers
//! `Φ` by less than [`ShapeOptions::min_sweep_gain`] of its value or [`ShapeOptions::max_sweeps`]
//! is reached. The work is bounded: per sweep and node at most `6 + LINE_SEARCH_HALVINGS`
//! (interior) or `3 + LINE_SEARCH_HALVINGS + 2·SLIDE_SAMPLES` (boundary) evaluations of its
//! cells.
//!
//! This pass is not a variational functional: it does not move cells that are already good
//! (above `τ` they cost nothing) and it can make neighbouring cells' sizes less even, since μ
//! is 1 for every rectangle whatever its aspect ratio. Its measured effect on the bundled
//! regions is in docs/results.md.

use std::collections::HashMap;

use unamalla_mesh::quality::quad::{corner_alphas, mu};
use unamalla_mesh::{DVec2, QuadMesh, Region, SegmentIndex};

use crate::monitor::{Control, Monitor, Observer, Phase};

/// Candidate arc positions on each side of a sliding boundary node (besides its Gauss–Newton
/// step).
pub const SLIDE_SAMPLES: usize = 8;
/// Step halvings of the line search along a Gauss–Newton step.
pub const LINE_SEARCH_HALVINGS: usize = 8;
/// Cells around a node the pass handles (more: the node is left alone).
pub const MAX_AROUND: usize = 8;
/// Central-difference step of the Jacobian, relative to the node's local size `ℓ`.
pub const FD_STEP: f64 = 1e-6;
/// Longest Gauss–Newton step of an interior node, relative to `ℓ`.
pub const MAX_STEP: f64 = 0.5;
/// A sliding node moves at most this fraction of the arc to its boundary neighbour (so two
/// neighbours never cross).
pub const SLIDE_REACH: f64 = 0.45;

/// Options of [`improve_shape`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct ShapeOptions {
    /// The target `τ` of `Φ = Σ (τ − μ)₊²`.
    pub target: f64,
    /// Nodes with a cell whose μ is below this are visited.
    pub active_below: f64,
    /// Guard 2: a cell at or above this μ is never pushed below it.
    pub keep: f64,
    /// Guard 1: `ε` of the convexity guard `min αₖ ≥ min(old, ε·ᾱ)`.
    pub eps: f64,
    /// Sweeps at most.
    pub max_sweeps: usize,
    /// A sweep that lowers `Φ` by less than this fraction of its value ends the pass.
    pub min_sweep_gain: f64,
    /// Let boundary nodes slide along the region boundary (needs the region).
    pub slide: bool,
    /// A ring vertex turning by more than this many degrees is a feature: no node slides past
    /// it or away from it.
    pub feature_angle_deg: f64,
    /// Guard 4: the area of every cell stays within this factor `ρ` of its area at the start
    /// of the pass (`A₀/ρ ≤ A ≤ ρ·A₀`), so the size grading the smoother made is kept.
    pub max_area_change: f64,
}

impl Default for ShapeOptions {
    fn default() -> Self {
        Self {
            target: 0.85,
            active_below: 0.9,
            keep: unamalla_mesh::quality::MU_GOOD,
            eps: 1e-3,
            max_sweeps: 40,
            min_sweep_gain: 1e-3,
            slide: true,
            feature_angle_deg: 20.0,
            max_area_change: 1.25,
        }
    }
}

impl ShapeOptions {
    /// `self` with the target `τ` (and `active_below = τ + 0.05`).
    pub fn with_target(mut self, target: f64) -> Self {
        self.target = target;
        self.active_below = target + 0.05;
        self
    }
    /// `self` with at most `n` sweeps (0: the pass does nothing).
    pub fn with_max_sweeps(mut self, n: usize) -> Self {
        self.max_sweeps = n;
        self
    }
    /// `self` with guard 4's factor `ρ` ([`ShapeOptions::max_area_change`], at least 1).
    pub fn with_max_area_change(mut self, rho: f64) -> Self {
        self.max_area_change = rho;
        self
    }
    /// `self` with boundary sliding on or off.
    pub fn with_slide(mut self, slide: bool) -> Self {
        self.slide = slide;
        self
    }
}

/// What [`improve_shape`] did.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShapeReport {
    /// Sweeps run.
    pub sweeps: usize,
    /// Accepted moves of interior nodes (over all sweeps).
    pub moved: usize,
    /// Accepted slides of boundary nodes (over all sweeps).
    pub slid: usize,
    /// Boundary nodes allowed to slide.
    pub slidable: usize,
    /// `Φ` before the pass.
    pub objective_before: f64,
    /// `Φ` after the pass.
    pub objective_after: f64,
    /// Cells with μ ≥ [`ShapeOptions::keep`] before, percent.
    pub good_before: f64,
    /// Cells with μ ≥ [`ShapeOptions::keep`] after, percent.
    pub good_after: f64,
    /// Smallest μ before.
    pub min_mu_before: f64,
    /// Smallest μ after.
    pub min_mu_after: f64,
    /// The observer stopped the pass.
    pub cancelled: bool,
}

/// The ring geometry a boundary node slides on: vertices, cumulative arc length and the arc
/// positions of the feature vertices.
#[derive(Debug, Clone)]
struct Ring {
    pts: Vec<DVec2>,
    /// `cum[i]`: arc length from vertex 0 to vertex `i`; `cum[n]` = perimeter.
    cum: Vec<f64>,
    /// Arc positions of the feature vertices, increasing.
    features: Vec<f64>,
}

impl Ring {
    fn new(pts: &[DVec2], feature_angle: f64) -> Self {
        let n = pts.len();
        let mut cum = Vec::with_capacity(n + 1);
        let mut s = 0.0;
        cum.push(0.0);
        for i in 0..n {
            s += pts[i].distance(pts[(i + 1) % n]);
            cum.push(s);
        }
        let features = (0..n)
            .filter(|&i| {
                let d1 = pts[i] - pts[(i + n - 1) % n];
                let d2 = pts[(i + 1) % n] - pts[i];
                d1.perp_dot(d2).atan2(d1.dot(d2)).abs() > feature_angle
            })
            .map(|i| cum[i])
            .collect();
        Self {
            pts: pts.to_vec(),
            cum,
            features,
        }
    }

    fn len(&self) -> f64 {
        self.cum[self.cum.len() - 1]
    }

    /// `s` wrapped into `(−L/2, L/2]`.
    fn wrap_offset(&self, d: f64) -> f64 {
        let l = self.len();
        let mut d = d.rem_euclid(l);
        if d > 0.5 * l {
            d -= l;
        }
        d
    }

    /// The point at arc position `s` (any real, taken modulo the perimeter).
    fn at(&self, s: f64) -> DVec2 {
        let l = self.len();
        let s = s.rem_euclid(l);
        let n = self.pts.len();
        // the edge e with cum[e] <= s < cum[e + 1]
        let e = self
            .cum
            .partition_point(|&c| c <= s)
            .saturating_sub(1)
            .min(n - 1);
        let len = self.cum[e + 1] - self.cum[e];
        let t = if len > 0.0 {
            ((s - self.cum[e]) / len).clamp(0.0, 1.0)
        } else {
            0.0
        };
        self.pts[e].lerp(self.pts[(e + 1) % n], t)
    }

    /// Offset (in `(0, L)`) of the first feature strictly after `s`, if any.
    fn next_feature(&self, s: f64) -> Option<f64> {
        let l = self.len();
        let s = s.rem_euclid(l);
        let i = self.features.partition_point(|&f| f <= s);
        match (self.features.get(i), self.features.first()) {
            (Some(&f), _) => Some(f - s),
            (None, Some(&f)) => Some(f + l - s),
            _ => None,
        }
    }

    /// Offset (in `(0, L)`) of the last feature strictly before `s`, if any.
    fn prev_feature(&self, s: f64) -> Option<f64> {
        let l = self.len();
        let s = s.rem_euclid(l);
        let i = self.features.partition_point(|&f| f < s);
        match (
            i.checked_sub(1).map(|k| self.features[k]),
            self.features.last(),
        ) {
            (Some(f), _) => Some(s - f),
            (None, Some(&f)) => Some(s + l - f),
            _ => None,
        }
    }
}

/// A boundary node that may slide: its ring and its two boundary neighbours.
#[derive(Debug, Clone, Copy)]
struct Slider {
    ring: usize,
    nbr: [usize; 2],
}

/// The boundary sliding data of a mesh on a region: which fixed nodes lie on which ring, where.
#[derive(Debug, Clone)]
pub struct BoundarySlide {
    rings: Vec<Ring>,
    /// Arc position of every fixed node found on a ring (sliding or not).
    arcs: HashMap<usize, f64>,
    sliders: HashMap<usize, Slider>,
    index: SegmentIndex,
}

impl BoundarySlide {
    /// Finds, for every fixed node of `mesh` with exactly two boundary neighbours, the ring of
    /// `region` it lies on (within `1e-9` of the region's diameter) and its arc position; nodes
    /// on a feature vertex (turning by more than `feature_angle_deg`) or on no ring are left
    /// out and stay where they are.
    pub fn new(mesh: &QuadMesh, region: &Region, feature_angle_deg: f64) -> Self {
        let fa = feature_angle_deg.to_radians();
        let rings: Vec<Ring> = region.rings().map(|p| Ring::new(p.points(), fa)).collect();
        let index = region.edge_index();
        let (lo, hi) = region.bounding_box();
        let tol = 1e-9 * (hi - lo).length().max(f64::MIN_POSITIVE);
        let fixed = mesh.fixed();
        let nodes = unamalla_mesh::HasNodes::nodes(mesh);
        // boundary edges (used by one cell) with both ends fixed
        let mut nbrs: HashMap<usize, Vec<usize>> = HashMap::new();
        for [a, b] in unamalla_mesh::quality::quad_boundary_edges(mesh) {
            if fixed[a] && fixed[b] {
                nbrs.entry(a).or_default().push(b);
                nbrs.entry(b).or_default().push(a);
            }
        }
        let locate = |p: DVec2| -> Option<(usize, f64)> {
            let d = DVec2::splat(tol);
            index
                .candidates(p - d, p + d)
                .map(|e| {
                    let (a, b) = index.edge(e);
                    let ab = b - a;
                    let t = if ab.length_squared() > 0.0 {
                        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    let dist = p.distance(a + t * ab);
                    (dist, e.ring, rings[e.ring].cum[e.edge] + t * ab.length())
                })
                .filter(|&(dist, _, _)| dist <= tol)
                // deterministic: nearest, then smallest (ring, arc)
                .min_by(|x, y| x.partial_cmp(y).unwrap_or(std::cmp::Ordering::Equal))
                .map(|(_, r, s)| (r, s))
        };
        let on_ring: HashMap<usize, (usize, f64)> = nbrs
            .keys()
            .filter_map(|&v| locate(nodes[v]).map(|l| (v, l)))
            .collect();
        let mut sliders = HashMap::new();
        for (&v, nb) in &nbrs {
            if nb.len() != 2 {
                continue;
            }
            let Some(&(ring, arc)) = on_ring.get(&v) else {
                continue;
            };
            // both boundary neighbours on the same ring (not, e.g., a flat corner bent inward)
            if !nb
                .iter()
                .all(|w| on_ring.get(w).is_some_and(|&(r, _)| r == ring))
            {
                continue;
            }
            let r = &rings[ring];
            let at_feature = r
                .features
                .iter()
                .any(|&f| r.wrap_offset(f - arc).abs() <= tol);
            if at_feature {
                continue;
            }
            let mut nbr = [nb[0], nb[1]];
            nbr.sort_unstable();
            sliders.insert(v, Slider { ring, nbr });
        }
        Self {
            rings,
            arcs: on_ring.into_iter().map(|(v, (_, s))| (v, s)).collect(),
            sliders,
            index,
        }
    }

    /// Boundary nodes that may slide.
    pub fn num_sliders(&self) -> usize {
        self.sliders.len()
    }
}

/// `(τ − μ)₊²`.
#[inline]
fn shortfall(target: f64, m: f64) -> f64 {
    let d = (target - m).max(0.0);
    d * d
}

/// The cells around one node and the state the guards compare against.
#[derive(Debug, Clone, Copy)]
struct Local {
    /// `Σ (τ − μ)₊²` over the node's cells.
    phi: f64,
    /// Smallest μ over the node's cells.
    min_mu: f64,
    /// Smallest corner α over the node's cells.
    min_alpha: f64,
    /// Bit `k`: the node's `k`-th cell has μ ≥ keep.
    good: u64,
}

/// Residuals `(τ − μ)₊` of the cells around one node, in [`Pass::around`] order (zero-padded).
type Residuals = [f64; MAX_AROUND];

/// The pass's working state: the cells, their incidence and orientation, the guards' data.
struct Pass<'a> {
    cells: &'a [[usize; 4]],
    /// Cell ids around each node (CSR: `adj[start[v]..start[v + 1]]`, in cell order).
    start: Vec<usize>,
    adj: Vec<usize>,
    /// Orientation sign of the mesh (+1: counter-clockwise cells).
    sign: f64,
    opts: &'a ShapeOptions,
    /// Guard 1's `ε·ᾱ`.
    alpha_floor: f64,
    /// The region's ring edges (guard 3), when a region is known.
    index: Option<&'a SegmentIndex>,
    /// Cells with a fixed node (only their centroids can cross the boundary when an interior
    /// node moves).
    touches: Vec<bool>,
    /// Guard 4: the sum of the four corner α (four times the area) of every cell at the start.
    area0: Vec<f64>,
}

impl<'a> Pass<'a> {
    fn new(
        x: &[DVec2],
        cells: &'a [[usize; 4]],
        fixed: &[bool],
        opts: &'a ShapeOptions,
        index: Option<&'a SegmentIndex>,
    ) -> Self {
        let nn = x.len();
        let mut start = vec![0usize; nn + 1];
        for c in cells {
            for &v in c {
                start[v + 1] += 1;
            }
        }
        for v in 0..nn {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut adj = vec![0usize; start[nn]];
        for (ci, c) in cells.iter().enumerate() {
            for &v in c {
                adj[fill[v]] = ci;
                fill[v] += 1;
            }
        }
        let total_alpha: f64 = cells
            .iter()
            .map(|q| {
                corner_alphas(&[x[q[0]], x[q[1]], x[q[2]], x[q[3]]])
                    .iter()
                    .sum::<f64>()
            })
            .sum();
        let sign = if total_alpha < 0.0 { -1.0 } else { 1.0 };
        let alpha_bar = (total_alpha * sign / (4 * cells.len().max(1)) as f64).max(0.0);
        Self {
            cells,
            start,
            adj,
            sign,
            opts,
            alpha_floor: opts.eps * alpha_bar,
            index,
            touches: cells.iter().map(|q| q.iter().any(|&w| fixed[w])).collect(),
            area0: cells
                .iter()
                .map(|q| {
                    sign * corner_alphas(&[x[q[0]], x[q[1]], x[q[2]], x[q[3]]])
                        .iter()
                        .sum::<f64>()
                })
                .collect(),
        }
    }

    fn around(&self, v: usize) -> &[usize] {
        &self.adj[self.start[v]..self.start[v + 1]]
    }

    /// Cell `c` (counter-clockwise) with node `v` at `p`.
    fn quad(&self, x: &[DVec2], c: usize, v: usize, p: DVec2) -> [DVec2; 4] {
        let q = self.cells[c];
        let mut pts = [x[q[0]], x[q[1]], x[q[2]], x[q[3]]];
        for k in 0..4 {
            if q[k] == v {
                pts[k] = p;
            }
        }
        if self.sign < 0.0 {
            pts.reverse();
        }
        pts
    }

    /// μ of cell `c` as it is.
    fn cell_mu(&self, x: &[DVec2], c: usize) -> f64 {
        mu(&self.quad(x, c, usize::MAX, DVec2::ZERO))
    }

    /// The local state with node `v` at `p`, or `None` if a cell is not convex or the node
    /// has more than [`MAX_AROUND`] cells.
    fn local(&self, x: &[DVec2], v: usize, p: DVec2) -> Option<Local> {
        let around = self.around(v);
        if around.len() > MAX_AROUND {
            return None;
        }
        let mut l = Local {
            phi: 0.0,
            min_mu: f64::INFINITY,
            min_alpha: f64::INFINITY,
            good: 0,
        };
        for (k, &c) in around.iter().enumerate() {
            let q = self.quad(x, c, v, p);
            let a = corner_alphas(&q);
            let amin = a[0].min(a[1]).min(a[2]).min(a[3]);
            if amin.is_nan() || amin <= 0.0 {
                return None;
            }
            // guard 4
            let ratio = (a[0] + a[1] + a[2] + a[3]) / self.area0[c];
            let rho = self.opts.max_area_change;
            if !(ratio * rho >= 1.0 && ratio <= rho) {
                return None;
            }
            let m = mu(&q);
            l.phi += shortfall(self.opts.target, m);
            l.min_mu = l.min_mu.min(m);
            l.min_alpha = l.min_alpha.min(amin);
            if m >= self.opts.keep {
                l.good |= 1 << k;
            }
        }
        Some(l)
    }

    /// The residuals with node `v` at `p`; `None` if a cell is not convex or the node has
    /// more than [`MAX_AROUND`] cells.
    fn residuals(&self, x: &[DVec2], v: usize, p: DVec2) -> Option<Residuals> {
        let around = self.around(v);
        if around.len() > MAX_AROUND {
            return None;
        }
        let mut out = [0.0; MAX_AROUND];
        for (k, &c) in around.iter().enumerate() {
            let m = mu(&self.quad(x, c, v, p));
            if m.is_nan() || m <= 0.0 {
                return None;
            }
            out[k] = (self.opts.target - m).max(0.0);
        }
        Some(out)
    }

    /// Guards 1–2 of a candidate against the node's state `old`, and whether it improves on
    /// `best` (lower `Φ`, ties broken by a larger smallest μ).
    fn better(&self, old: &Local, best: &Local, cand: Option<Local>) -> Option<Local> {
        let c = cand?;
        if c.min_alpha < old.min_alpha.min(self.alpha_floor) {
            return None;
        }
        if c.min_mu < old.min_mu.min(self.opts.keep) || old.good & !c.good != 0 {
            return None;
        }
        let improves = c.phi < best.phi - 1e-15 * (1.0 + best.phi)
            || (c.phi <= best.phi && c.min_mu > best.min_mu + 1e-12);
        improves.then_some(c)
    }

    /// Guard 3: `true` if moving node `v` from `p0` to `p` moves the centroid of one of its
    /// cells across a ring edge (all its cells for a boundary node, those with a fixed node for
    /// an interior one).
    fn crosses(&self, x: &[DVec2], v: usize, p0: DVec2, p: DVec2, all: bool) -> bool {
        let Some(index) = self.index else {
            return false;
        };
        self.around(v).iter().any(|&c| {
            (all || self.touches[c]) && {
                let c0 = centroid(&self.quad(x, c, v, p0));
                let c1 = centroid(&self.quad(x, c, v, p));
                index.intersecting(c0, c1).next().is_some()
            }
        })
    }

    /// The node's local size `ℓ`: over its cells, the smallest largest distance from the node
    /// to a corner.
    fn size(&self, x: &[DVec2], v: usize) -> f64 {
        self.around(v)
            .iter()
            .map(|&c| {
                self.cells[c]
                    .iter()
                    .map(|&w| x[w].distance(x[v]))
                    .fold(0.0, f64::max)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The new position of interior node `v` (state `old`, residuals `r0`): a Gauss–Newton
    /// step on `Φ = Σ r²` with the 2-column Jacobian by central differences (Levenberg-damped,
    /// at most [`MAX_STEP`]`·ℓ` long), halved until the guards pass and `Φ` decreases.
    fn interior_move(&self, x: &[DVec2], v: usize, old: &Local, r0: &Residuals) -> Option<DVec2> {
        let p0 = x[v];
        let size = self.size(x, v);
        let h = FD_STEP * size;
        let mut j = [[0.0; 2]; MAX_AROUND];
        for (axis, e) in [DVec2::X, DVec2::Y].into_iter().enumerate() {
            let rp = self.residuals(x, v, p0 + h * e)?;
            let rm = self.residuals(x, v, p0 - h * e)?;
            for c in 0..MAX_AROUND {
                j[c][axis] = (rp[c] - rm[c]) / (2.0 * h);
            }
        }
        let (mut a11, mut a12, mut a22, mut g1, mut g2) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for c in 0..MAX_AROUND {
            a11 += j[c][0] * j[c][0];
            a12 += j[c][0] * j[c][1];
            a22 += j[c][1] * j[c][1];
            g1 += j[c][0] * r0[c];
            g2 += j[c][1] * r0[c];
        }
        let lam = 1e-9 * (a11 + a22) + f64::MIN_POSITIVE;
        let (a11, a22) = (a11 + lam, a22 + lam);
        let det = a11 * a22 - a12 * a12;
        if det.is_nan() || det <= 0.0 {
            return None;
        }
        let mut d = -DVec2::new(a22 * g1 - a12 * g2, a11 * g2 - a12 * g1) / det;
        let len = d.length();
        if len.is_nan() || len <= 0.0 {
            return None;
        }
        if len > MAX_STEP * size {
            d *= MAX_STEP * size / len;
        }
        let mut t = 1.0;
        for _ in 0..LINE_SEARCH_HALVINGS {
            let q = p0 + t * d;
            t *= 0.5;
            if self.better(old, old, self.local(x, v, q)).is_some()
                && !self.crosses(x, v, p0, q, false)
            {
                return Some(q);
            }
        }
        None
    }

    /// The new position and arc position of boundary node `v` sliding on `ring` (its arc
    /// position `arc`, its neighbours' offsets along the ring `offs`): among the Gauss–Newton
    /// step along the arc with its halvings and [`SLIDE_SAMPLES`] samples of the reach on
    /// either side (the objective along a ring need not be unimodal), the best candidate that
    /// passes the three guards.
    #[allow(clippy::too_many_arguments)]
    fn slide_move(
        &self,
        x: &[DVec2],
        v: usize,
        old: &Local,
        r0: &Residuals,
        ring: &Ring,
        arc: f64,
        offs: [f64; 2],
    ) -> Option<(DVec2, f64)> {
        let (lo, hi) = (offs[0].min(offs[1]), offs[0].max(offs[1]));
        if !(lo < 0.0 && hi > 0.0) {
            return None;
        }
        let reach_hi = (SLIDE_REACH * hi).min(ring.next_feature(arc).unwrap_or(f64::INFINITY));
        let reach_lo = (SLIDE_REACH * -lo).min(ring.prev_feature(arc).unwrap_or(f64::INFINITY));
        let h = (FD_STEP * self.size(x, v))
            .min(0.5 * reach_hi)
            .min(0.5 * reach_lo);
        // the Gauss–Newton step along the arc (none if the difference quotients fail)
        let step = match (
            self.residuals(x, v, ring.at(arc + h)),
            self.residuals(x, v, ring.at(arc - h)),
        ) {
            (Some(rp), Some(rm)) if h > 0.0 => {
                let (mut jj, mut jr) = (0.0, 0.0);
                for c in 0..MAX_AROUND {
                    let jc = (rp[c] - rm[c]) / (2.0 * h);
                    jj += jc * jc;
                    jr += jc * r0[c];
                }
                let s = (-jr / (jj + f64::MIN_POSITIVE)).clamp(-reach_lo, reach_hi);
                if s.is_finite() {
                    s
                } else {
                    0.0
                }
            }
            _ => 0.0,
        };
        let gn = (0..LINE_SEARCH_HALVINGS)
            .map(|k| step * 0.5f64.powi(k as i32))
            .filter(|&o| o != 0.0);
        let samples = (1..=SLIDE_SAMPLES).flat_map(|k| {
            let f = k as f64 / SLIDE_SAMPLES as f64;
            [f * reach_hi, -f * reach_lo]
        });
        let p0 = x[v];
        let mut best = (*old, None);
        for off in gn.chain(samples) {
            let q = ring.at(arc + off);
            let Some(l) = self.better(old, &best.0, self.local(x, v, q)) else {
                continue;
            };
            if !self.crosses(x, v, p0, q, true) {
                best = (l, Some((q, arc + off)));
            }
        }
        best.1
    }
}

/// Runs the pass on `mesh` (see the module documentation). With `slide` (`Some`), the boundary
/// nodes it lists slide along the region's rings (if [`ShapeOptions::slide`]) and guard 3
/// checks cell centroids against its rings; the other fixed nodes never move. The observer is
/// called after every sweep (phase [`Phase::Classic`], `iter_classic` = sweep, `f` = `Φ`) and
/// can cancel the pass between sweeps.
pub fn improve_shape(
    mesh: &mut QuadMesh,
    slide: Option<&BoundarySlide>,
    opts: &ShapeOptions,
    observer: &mut dyn Observer,
) -> ShapeReport {
    let t0 = std::time::Instant::now();
    let cells = mesh.cells().to_vec();
    let fixed = mesh.fixed().to_vec();
    let x = unamalla_mesh::HasNodes::nodes_mut(mesh);
    let mut report = ShapeReport::default();
    if cells.is_empty() {
        return report;
    }
    let pass = Pass::new(x, &cells, &fixed, opts, slide.map(|s| &s.index));
    let mut mus: Vec<f64> = (0..cells.len()).map(|c| pass.cell_mu(x, c)).collect();
    let phi_of = |mus: &[f64]| mus.iter().map(|&m| shortfall(opts.target, m)).sum::<f64>();
    let good_of = |mus: &[f64]| {
        100.0 * mus.iter().filter(|&&m| m >= opts.keep).count() as f64 / mus.len() as f64
    };
    let min_of = |mus: &[f64]| mus.iter().copied().fold(f64::INFINITY, f64::min);
    report.objective_before = phi_of(&mus);
    report.good_before = good_of(&mus);
    report.min_mu_before = min_of(&mus);
    report.slidable = slide.map_or(0, BoundarySlide::num_sliders);
    let sliders = slide.filter(|_| opts.slide);
    // arc positions of the boundary nodes on rings, updated as they slide
    let mut arcs: HashMap<usize, f64> = sliders.map(|s| s.arcs.clone()).unwrap_or_default();
    for sweep in 0..opts.max_sweeps {
        let phi_start = phi_of(&mus);
        for v in 0..x.len() {
            let around = pass.around(v);
            if around.is_empty() || around.iter().all(|&c| mus[c] >= opts.active_below) {
                continue;
            }
            let slider = match (fixed[v], sliders) {
                (false, _) => None,
                (true, Some(s)) => match s.sliders.get(&v) {
                    Some(sl) => Some((s, *sl)),
                    None => continue,
                },
                (true, None) => continue,
            };
            let (Some(old), Some(r0)) = (pass.local(x, v, x[v]), pass.residuals(x, v, x[v])) else {
                continue;
            };
            if r0.iter().all(|&r| r == 0.0) {
                continue;
            }
            let moved = match slider {
                None => pass.interior_move(x, v, &old, &r0).map(|p| (p, None)),
                Some((s, sl)) => {
                    let ring = &s.rings[sl.ring];
                    let arc = arcs[&v];
                    let offs = sl
                        .nbr
                        .map(|w| ring.wrap_offset(arcs.get(&w).map_or(0.0, |&a| a - arc)));
                    pass.slide_move(x, v, &old, &r0, ring, arc, offs)
                        .map(|(p, a)| (p, Some(a.rem_euclid(ring.len()))))
                }
            };
            if let Some((p, arc)) = moved {
                x[v] = p;
                for &c in around {
                    mus[c] = pass.cell_mu(x, c);
                }
                match arc {
                    Some(a) => {
                        arcs.insert(v, a);
                        report.slid += 1;
                    }
                    None => report.moved += 1,
                }
            }
        }
        report.sweeps = sweep + 1;
        let phi = phi_of(&mus);
        let mon = Monitor {
            f: phi,
            iter_classic: sweep + 1,
            phase: Phase::Classic,
            elapsed: t0.elapsed(),
            ..Monitor::default()
        };
        if observer.observe(&mon) == Control::Stop {
            report.cancelled = true;
            break;
        }
        if phi_start - phi <= opts.min_sweep_gain * phi_start {
            break;
        }
    }
    report.objective_after = phi_of(&mus);
    report.good_after = good_of(&mus);
    report.min_mu_after = min_of(&mus);
    report
}

/// Mean of the four corners.
fn centroid(q: &[DVec2; 4]) -> DVec2 {
    (q[0] + q[1] + q[2] + q[3]) * 0.25
}
