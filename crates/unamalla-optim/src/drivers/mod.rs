//! Continuation drivers and the high-level `smooth` entry points.
//!
//! * [`adaptive_k`]: [González Flores, Algorithm 4.1, Algorithm 4.2] with the practical update of
//!   §4.6.1 (`k = max(k*ᾱ, −1.0015α₋ + 0.01ᾱ)`, `k* = −0.01`, a few iterations per `k`), the C²
//!   continuation below `α̂ = −k + 0.015(α₋ + k)` (not the printed (4.42), see
//!   [`recommended_alpha_hat`]), the double homotopy `σ̂(k) = (1−σ)(k₀ − k)/(k₀ − k*ᾱ)` (5.20),
//!   optional Length pre-smoothing, then the classic phase on `σ·f₁(k*) + (1−σ)·f₂`.
//! * [`omega_continuation`] / [`omega_continuation_hex`]: [Cortés Aguirre 2012, §3.4, Algorithm A]
//!   — minimize `H_ω`, halve `ω` until the mesh is ε-convex (floor `10⁻⁸`, relative to the mean
//!   measure), then one refinement run.
//! * [`coplanarity_continuation`]: [Cortés Aguirre 2012, §4.2, Algorithm B] — `H_ω + C·Σk²`,
//!   `C = 1/(2μ)`, `μ₀ = 0.1`, `μ ← 0.1μ` while `μ > 10⁻¹²`.
//! * [`block_smoothing`]: [Méndez 2023, (6.8), (6.9)] `F = (1−σ)·w·F_AO + σ·H_ω` (each normalized
//!   to 1 on the ideal grid) from an ε-convex start, with the safeguard at `ε·ᾱ`, so the result is
//!   ε-convex; a non-ε-convex start is first untangled by [`adaptive_k`].
//!
//! Contract: every driver keeps a convex start convex (the [`Session`] safeguard), and reports
//! in [`SmoothReport::convex`] / [`SmoothReport::eps_convex`] whether a folded start became
//! convex.

use std::str::FromStr;
use std::sync::Arc;
use std::time::Duration;

use unamalla_functionals::prelude::*;
use unamalla_functionals::{
    recommended_alpha_hat, Area, AreaOrthogonality, HOmega, HexFunctional, HexTopology,
    IvanenkoConvex, KArea, KSmoothness, KernelExpr, Length, Orthogonality, QuadFunctional,
    QuadTopology, Scaling3, WithHessian,
};
use unamalla_mesh::{FreeNodes, HasHexCells, HasQuadCells};

use crate::error::OptimError;
use crate::monitor::{Observer, Phase, Session};
use crate::psd_model::PsdModel;
use crate::solver::{
    minimize_with, HessianMode, QuadLocalGuard, SolveResult, Solver, SolverOptions,
};
use crate::status::{Status, StopReason};
use unamalla_functionals::quad::psd::PsdProjection;

mod adaptive_k;
mod block;
mod classic;
mod coplanarity;
mod omega;
mod smooth;

pub use adaptive_k::*;
pub use block::*;
pub use classic::*;
pub use coplanarity::*;
pub use omega::*;
pub use smooth::*;

/// The report of a driver or of [`smooth`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SmoothReport {
    /// Final status (Table A.2 message through `Display`).
    pub status: Status,
    /// All status messages of the run, in order.
    pub messages: Vec<Status>,
    /// Every element with a free vertex has a positive measure.
    pub convex: bool,
    /// `α₋ > ε·ᾱ` for the driver's ε.
    pub eps_convex: bool,
    /// The ε used for `eps_convex`.
    pub eps: f64,
    /// Final `α₋` over elements with a free vertex.
    pub alfamin: f64,
    /// `ᾱ` (mean measure).
    pub alpha_bar: f64,
    /// Initial `α₋`.
    pub initial_alfamin: f64,
    /// Initial non-convex cells.
    pub initial_inocon: usize,
    /// Final non-convex cells.
    pub inocon: usize,
    /// Elements with all vertices fixed and measure `≤ 0` (boundary data).
    pub fixed_nonpositive: usize,
    /// Final functional value (of the last functional minimized).
    pub f: f64,
    /// Final gradient norm.
    pub gnorm: f64,
    /// Pre-smoothing iterations.
    pub iter_smooth: usize,
    /// Homotopy / continuation iterations.
    pub iter_homotopic: usize,
    /// Classic / refinement iterations.
    pub iter_classic: usize,
    /// Continuation steps (`k` updates, `ω` values, `μ` values).
    pub continuation_steps: usize,
    /// Final `k/ᾱ` (adaptive driver).
    pub k: Option<f64>,
    /// Final `ω` (absolute).
    pub omega: Option<f64>,
    /// Final `μ` (Algorithm B).
    pub mu: Option<f64>,
    /// Algorithm B: max `|cos|` over interior-cell faces and the number of non-planar
    /// interior cells.
    pub planarity: Option<(f64, usize)>,
    /// Wall time.
    pub elapsed: Duration,
    /// The run ended with more non-convex cells than it started with, so [`smooth`] /
    /// [`smooth_hex`] put the starting coordinates back (the other fields then describe the
    /// start, except the iteration counters and the time).
    #[serde(default)]
    pub restored: bool,
    /// Inner CG iterations of the last solver run (truncated Newton; 0 for the others).
    #[serde(default)]
    pub cg_iterations: usize,
}

impl SmoothReport {
    /// If the run ended with more non-convex cells than it started with, puts the starting
    /// coordinates `x0` back into `x` and the report back to the start's convexity figures
    /// (see [`Self::restored`]).
    fn keep_start_if_worse(&mut self, x: &mut [f64], x0: &[f64]) {
        if self.inocon <= self.initial_inocon {
            return;
        }
        x.copy_from_slice(x0);
        self.inocon = self.initial_inocon;
        self.alfamin = self.initial_alfamin;
        self.convex = self.initial_inocon == 0;
        self.eps_convex = self.initial_alfamin > self.eps * self.alpha_bar;
        self.restored = true;
    }

    /// Total iterations over the phases.
    pub fn iterations(&self) -> usize {
        self.iter_smooth + self.iter_homotopic + self.iter_classic
    }
    /// `α₋/ᾱ`.
    pub fn alfamin_rel(&self) -> f64 {
        self.alfamin / self.alpha_bar
    }
}

struct Init {
    min: f64,
    inocon: usize,
}

/// Common start of the 2D drivers: a `Length` probe functional on `topo` and the convexity of
/// the start `x`; errors if there is no free node or the boundary does not enclose a positive
/// mean α (ᾱ).
fn quad_start(
    topo: &Arc<QuadTopology>,
    x: &[f64],
    session: &mut Session<'_>,
) -> Result<(QuadFunctional, crate::monitor::Convexity), OptimError> {
    if topo.num_vars() == 0 {
        return Err(OptimError::NoFreeNodes);
    }
    let probe = QuadFunctional::new(topo.clone(), KernelExpr::from(Length));
    let c0 = session.convexity(&probe, x);
    let ab = c0.mean;
    if !(ab > 0.0 && ab.is_finite()) {
        return Err(OptimError::InvalidOption {
            name: "mean alpha",
            value: ab,
            reason: "the boundary must enclose a positive area (counter-clockwise)",
        });
    }
    Ok((probe, c0))
}

/// The initial record of a run: the start's α₋ and Inocon, and the first status message.
fn start_record(c0: &crate::monitor::Convexity) -> (Init, Vec<Status>) {
    let init = Init {
        min: c0.min,
        inocon: c0.nonconvex_cells,
    };
    let first = if c0.convex() {
        Status::InitialConvex
    } else {
        Status::InitialNonConvex
    };
    (init, vec![first])
}

fn report(
    session: &mut Session<'_>,
    problem: &dyn ElementMeasures,
    x: &[f64],
    init: &Init,
    messages: Vec<Status>,
    last: Option<SolveResult>,
    eps: f64,
) -> SmoothReport {
    let c = session.convexity(problem, x);
    let status = match (last, messages.last()) {
        (Some(r), _) => Status::Stopped {
            reason: r.reason,
            convex: c.convex(),
        },
        (None, Some(s)) => *s,
        (None, None) => Status::InitialConvex,
    };
    let mut messages = messages;
    if last.is_some() {
        messages.push(status);
    }
    let m = &session.monitor;
    SmoothReport {
        status,
        messages,
        convex: c.convex(),
        eps_convex: c.eps_convex(eps),
        eps,
        alfamin: c.min,
        alpha_bar: c.mean,
        initial_alfamin: init.min,
        initial_inocon: init.inocon,
        inocon: c.nonconvex_cells,
        fixed_nonpositive: c.fixed_nonpositive,
        f: last.map_or(m.f, |r| r.f),
        gnorm: last.map_or(m.gnorm, |r| r.gnorm),
        iter_smooth: m.iter_smooth,
        iter_homotopic: m.iter_homotopic,
        iter_classic: m.iter_classic,
        continuation_steps: 0,
        k: m.k_current,
        omega: m.omega,
        mu: m.mu,
        planarity: None,
        elapsed: session.elapsed(),
        restored: false,
        cg_iterations: last.map_or(0, |r| r.cg_iterations),
    }
}

fn kernels(
    kf: KFunctional,
    k: f64,
    alpha_hat: Option<f64>,
    n: usize,
    ab: f64,
) -> Result<(KernelExpr, Option<KernelExpr>), OptimError> {
    let f1 = match kf {
        KFunctional::KSmoothArea | KFunctional::KSmoothness => {
            KernelExpr::from(KSmoothness::new(k, alpha_hat)?)
        }
        KFunctional::KAreaLength | KFunctional::KArea => {
            KernelExpr::from(KArea::new(k, alpha_hat)?)
        }
    }
    .normalized(n, ab)?;
    let f2 = match kf {
        KFunctional::KSmoothArea => Some(KernelExpr::from(Area).normalized(n, ab)?),
        KFunctional::KAreaLength => Some(KernelExpr::from(Length).normalized(n, ab)?),
        _ => None,
    };
    Ok((f1, f2))
}

fn combine(f1: KernelExpr, f2: Option<KernelExpr>, w2: f64) -> KernelExpr {
    match f2 {
        Some(f2) if w2 > 0.0 => KernelExpr::weighted_sum(vec![(1.0 - w2, f1), (w2, f2)]),
        _ => f1,
    }
}

fn check_sigma(name: &'static str, s: f64) -> Result<(), OptimError> {
    if (0.0..=1.0).contains(&s) {
        Ok(())
    } else {
        Err(OptimError::InvalidOption {
            name,
            value: s,
            reason: "must lie in [0, 1]",
        })
    }
}

/// UNAMALLA's optional "Previous Smoothness" ([González Flores, §A.4.3]):
/// `iters` iterations of normalized Length with truncated Newton + line search. Returns the
/// functional and the solver result if the run was interrupted (stop, time limit), `None`
/// otherwise (also for `iters = 0`).
fn length_presmooth(
    topo: &Arc<QuadTopology>,
    x: &mut [f64],
    iters: usize,
    solver: &SolverOptions,
    ab: f64,
    session: &mut Session<'_>,
    guard: &QuadLocalGuard,
) -> Result<Option<(QuadFunctional, SolveResult)>, OptimError> {
    if iters == 0 {
        return Ok(None);
    }
    session.set_phase(Phase::Smooth);
    let n = topo.num_triangles();
    let p = QuadFunctional::new(topo.clone(), KernelExpr::from(Length).normalized(n, ab)?);
    let so = SolverOptions {
        solver: Solver::TnLs,
        max_iter: iters,
        ..solver.clone()
    };
    let r = minimize_with(&p, x, &so, session, Some(guard))?;
    Ok(r.reason.interrupted().then_some((p, r)))
}

/// With [`AdaptiveKOptions::stop_at_target`], the homotopy past its target bound `α₋ > −k*·ᾱ`
/// goes on while `α₋` still rises by more than [`TARGET_STALL_RISE`]`·ᾱ` over
/// [`TARGET_STALL_UPDATES`] updates. The update `k̃` (4.35) is a function of `α₋` alone, so once
/// `α₋` is stationary every further update poses the same problem again and only converges it
/// further; while `α₋` rises, the homotopy is still smoothing the mesh (measured on the gulf of
/// Mexico at 20,000 cells: leaving at the first iterate past the bound gave μ ≥ 0.8 on
/// 90.6 % of the cells, leaving at the stall 92.2 %, the thesis's loop run to its update cap
/// 93.6 % in about twice the time).
pub const TARGET_STALL_UPDATES: usize = 4;

/// The rise of `α₋/ᾱ` over [`TARGET_STALL_UPDATES`] updates below which the homotopy counts as
/// stationary (see [`TARGET_STALL_UPDATES`]): a tenth of the target `0.01ᾱ` of the pipeline.
pub const TARGET_STALL_RISE: f64 = 1e-3;

/// With [`AdaptiveKOptions::stop_at_target`], the homotopy also ends, once the mesh is convex,
/// when its functional has stopped decreasing: over the last [`PLATEAU_UPDATES`] updates the
/// value after each solve fell by at most [`PLATEAU_DROP`] of itself. Below the target bound
/// (a corner pinned by the region boundary caps `α₋` near 0) `k` stays at `−1.0015α₋ + 0.01ᾱ`,
/// so every update minimizes nearly the same functional and the loop only spends its update
/// cap in steps of `iters_per_k` iterations (texas at 50,000 cells: `α₋/ᾱ` near 2·10⁻⁷,
/// the value 1.0155 → 1.0151 over updates 300–2,000, 10,000 iterations, 336 s). The caller
/// ([`block_smoothing`]) then runs (6.8) with the convexity guard alone. An exit on `α₋`
/// alone was tried and not kept: at 100,000 cells it cut the homotopy while the value was
/// still falling (texas μ ≥ 0.8 on 90.7 % → 87.4 %).
pub const PLATEAU_UPDATES: usize = 20;

/// The relative fall of [`PLATEAU_UPDATES`].
pub const PLATEAU_DROP: f64 = 1e-4;

/// The exit of [`PLATEAU_UPDATES`]: `values` holds the functional value after each update's
/// solve (the latest last); `true` when there are more than [`PLATEAU_UPDATES`] of them and
/// `values[n−1−W] − values[n−1] ≤ PLATEAU_DROP·|values[n−1−W]|`.
fn on_plateau(values: &[f64]) -> bool {
    let n = values.len();
    n > PLATEAU_UPDATES && {
        let old = values[n - 1 - PLATEAU_UPDATES];
        old - values[n - 1] <= PLATEAU_DROP * old.abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plateau exit by hand, window W = `PLATEAU_UPDATES`, drop 10⁻⁴: a flat history
    /// stops once it is longer than W; a fall of 2·10⁻⁴ over the window, or a history of only
    /// W entries, does not; a fall of 0.5·10⁻⁴ (texas at 50,000 cells) and a rise do.
    #[test]
    fn on_plateau_by_hand() {
        let w = PLATEAU_UPDATES;
        let flat = vec![1.0; w + 1];
        assert!(on_plateau(&flat));
        assert!(!on_plateau(&flat[..w]));
        let line =
            |drop: f64| -> Vec<f64> { (0..=w).map(|k| 1.0 - drop * k as f64 / w as f64).collect() };
        assert!(!on_plateau(&line(2e-4)));
        assert!(on_plateau(&line(0.5e-4)));
        assert!(on_plateau(&line(-1e-3)));
        // only the window counts: a steep fall before it does not keep the loop going
        let mut v = vec![2.0, 1.5];
        v.extend(flat);
        assert!(on_plateau(&v));
        // a negative value (no functional here is, but the test is relative to |old|)
        assert!(!on_plateau(
            &(0..=w).map(|k| -1.0 - 1e-3 * k as f64).collect::<Vec<_>>()
        ));
    }
}
