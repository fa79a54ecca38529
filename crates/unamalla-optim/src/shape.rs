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

use unamalla_mesh::QuadMesh;

use crate::monitor::{Control, Monitor, Observer, Phase};

mod geometry;
mod pass;

pub use geometry::BoundarySlide;

use pass::{shortfall, Pass};

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
