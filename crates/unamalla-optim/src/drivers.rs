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

use unamalla_functionals::{
    recommended_alpha_hat, Area, AreaOrthogonality, HOmega, HexFunctional, HexTopology,
    IvanenkoConvex, KArea, KSmoothness, KernelExpr, Length, Orthogonality, Problem, QuadFunctional,
    QuadTopology, Scaling3,
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

/// The adaptive functional `f₁` and its partner `f₂` ([González Flores, Table 5.2, §A.4.3]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum KFunctional {
    /// `kSmooth-Area`: k-Smoothness with Area.
    KSmoothArea,
    /// `kArea-Lenght`: k-Area with Length (UNAMALLA's default).
    #[default]
    KAreaLength,
    /// k-Smoothness alone.
    KSmoothness,
    /// k-Area alone.
    KArea,
}

/// The path `σ̃(t)` of the homotopy between functionals ([González Flores, §5.3, (5.14)–(5.18)]):
/// `f̃_c = (1 − σ̃)f₁ + σ̃f_c`, `σ̃` C¹ and increasing on `[0, 1]` with `σ̃(0) = 0`, `σ̃(1) = 1`.
/// In the double homotopy of §5.4 the parameter is tied to the adaptive `k`,
/// `t = (k₀ − k)/(k₀ − k*)` ((5.20) is the linear path), so the weight of the classic functional
/// `f₂` is `σ̂ = (1 − σ)·σ̃(t)` (5.19) ([`homotopy_weight`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum HomotopySchedule {
    /// `σ̃(t) = t`: the linear homotopy (5.20), UNAMALLA's practical scheme.
    #[default]
    Linear,
    /// `σ̃(t) = t²` (5.16).
    Square,
    /// `σ̃(t) = t³` (5.17).
    Cube,
    /// `σ̃(t) = sin(πt/2)` (5.18).
    Sine,
}

impl HomotopySchedule {
    /// Every schedule.
    pub const ALL: [HomotopySchedule; 4] = [
        HomotopySchedule::Linear,
        HomotopySchedule::Square,
        HomotopySchedule::Cube,
        HomotopySchedule::Sine,
    ];
    /// The command-line name (`linear`, `t2`, `t3`, `sine`).
    pub fn name(self) -> &'static str {
        match self {
            HomotopySchedule::Linear => "linear",
            HomotopySchedule::Square => "t2",
            HomotopySchedule::Cube => "t3",
            HomotopySchedule::Sine => "sine",
        }
    }
    /// `σ̃(t)` for `t` clamped to `[0, 1]`.
    pub fn sigma_tilde(self, t: f64) -> f64 {
        let t = t.clamp(0.0, 1.0);
        match self {
            HomotopySchedule::Linear => t,
            HomotopySchedule::Square => t * t,
            HomotopySchedule::Cube => t * t * t,
            HomotopySchedule::Sine => (0.5 * std::f64::consts::PI * t).sin(),
        }
    }
}

impl std::fmt::Display for HomotopySchedule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for HomotopySchedule {
    type Err = OptimError;
    fn from_str(s: &str) -> Result<Self, OptimError> {
        HomotopySchedule::ALL
            .into_iter()
            .find(|v| v.name() == s)
            .ok_or_else(|| OptimError::UnknownName {
                what: "homotopy schedule",
                name: s.to_string(),
                expected: "linear, t2, t3, sine",
            })
    }
}

/// The weight `σ̂` of the classic functional `f₂` in the double homotopy
/// ([González Flores, §5.3–§5.4, (5.19)–(5.20)]): `σ̂ = w_final·σ̃(t)` with
/// `t = (k₀ − k)/(k₀ − k*)` clamped to `[0, 1]` and `w_final = 1 − σ` (σ = weight of the adaptive
/// `f₁`). If `k` rises again, `t` and `σ̂` fall back with it (the automatic restart of Fig 5.8).
/// With `k₀ ≤ k*` (the start is already at the floor) the target weight is returned.
pub fn homotopy_weight(
    schedule: HomotopySchedule,
    w_final: f64,
    k0: f64,
    k: f64,
    kstar: f64,
) -> f64 {
    if k0 > kstar {
        w_final * schedule.sigma_tilde((k0 - k) / (k0 - kstar))
    } else {
        w_final
    }
}

/// Options of [`adaptive_k`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AdaptiveKOptions {
    /// The functional pair.
    pub functional: KFunctional,
    /// Weight σ of the adaptive functional in the final combination (UNAMALLA: 0.5; ignored
    /// for the single functionals).
    pub sigma: f64,
    /// The floor `k*` in units of `ᾱ` (UNAMALLA: −0.01, i.e. target `α₋ > 0.01ᾱ`).
    pub k_star: f64,
    /// Solver iterations per `k` update.
    pub iters_per_k: usize,
    /// Maximum number of `k` updates.
    pub max_updates: usize,
    /// Length pre-smoothing iterations (0 = "Previous Smoothness: No").
    pub presmooth: usize,
    /// Run the classic phase after the homotopy.
    pub classic: bool,
    /// Solver options (the classic phase runs with these; the homotopy with
    /// `max_iter = iters_per_k`).
    pub solver: SolverOptions,
    /// The path `σ̃(t)` of the homotopy towards the combination ([`HomotopySchedule`]).
    #[serde(default)]
    pub schedule: HomotopySchedule,
    /// End the homotopy once the mesh is convex with `α₋ > −k*·ᾱ` — the triangle-area
    /// bound that the floor `k*` stands for ([González Flores, Algorithm 4.1]: the sequence can
    /// be continued past convexity "to a target k*" to obtain `α > −k*`).
    ///
    /// `false` (the thesis's loop, the default): the homotopy ends when the practical update
    /// `k̃ = −1.0015·α₋ + 0.01·ᾱ` (4.35) has reached the floor, i.e. only once
    /// `α₋ ≥ (0.01 − k*)·ᾱ/1.0015` — about `0.02ᾱ` for `k* = −0.01`. A mesh whose `α₋` settles
    /// between the two bounds (a boundary angle that caps it) then keeps repeating the same
    /// solve until [`max_updates`](Self::max_updates). With `true` the homotopy ends at the
    /// bound as soon as `α₋` has stopped rising ([`TARGET_STALL_UPDATES`]). [`block_smoothing`]
    /// only needs the bound itself (its ε-convexity) and sets this to `true`.
    #[serde(default)]
    pub stop_at_target: bool,
}

impl Default for AdaptiveKOptions {
    fn default() -> Self {
        Self {
            functional: KFunctional::KAreaLength,
            sigma: 0.5,
            k_star: -0.01,
            iters_per_k: 5,
            max_updates: 2000,
            presmooth: 0,
            classic: true,
            solver: SolverOptions::default(),
            schedule: HomotopySchedule::Linear,
            stop_at_target: false,
        }
    }
}

/// Options of Algorithm A ([`omega_continuation`], [`omega_continuation_hex`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OmegaOptions {
    /// `ω₀` in units of the mean measure (`ᾱ` or the mean tetrahedron Jacobian).
    pub omega0_rel: f64,
    /// Floor of `ω`, relative ([Cortés Aguirre 2012, Algorithm A]: `ω* = 10⁻⁸`).
    pub omega_floor_rel: f64,
    /// ε of ε-convexity (`α₋ > ε·ᾱ`).
    pub eps: f64,
    /// Run the refinement step after ε-convexity is reached.
    pub refinement: bool,
    /// Solver options of each minimization ([Cortés Aguirre 2012, §3.4]: tolerances 10⁻⁴).
    pub solver: SolverOptions,
}

impl Default for OmegaOptions {
    fn default() -> Self {
        Self {
            omega0_rel: 1.0,
            omega_floor_rel: 1e-8,
            eps: 0.01,
            refinement: true,
            solver: SolverOptions {
                max_iter: 100,
                ftol: 1e-8,
                gtol: 1e-4,
                ..SolverOptions::default()
            },
        }
    }
}

/// Options of Algorithm B ([`coplanarity_continuation`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CoplanarityOptions {
    /// Fixed `ω` relative to the mean Jacobian ([Cortés Aguirre 2012, Algorithm B]: `10⁻⁸`).
    pub omega_rel: f64,
    /// `μ₀` (default 500, the thesis's Table 4.5 alternative; the thesis's default is 0.1,
    /// see [`CoplanarityOptions::thesis`]).
    pub mu0: f64,
    /// Stop when `μ ≤ mu_min` (10⁻¹²).
    pub mu_min: f64,
    /// Tolerance on `|cos|` for counting non-planar cells (criterion 2, `ε_n = 10⁻²`).
    pub planarity_tol: f64,
    /// Planarity stop: end the continuation as soon as every face of every penalized cell has
    /// max `|cos|` ≤ `stop_cos` (checked every [`check_every`](Self::check_every) solver
    /// iterations inside a μ step and after each step). `None` = the thesis's schedule, which
    /// always runs down to `μ_min`.
    pub stop_cos: Option<f64>,
    /// Solver iterations between two planarity checks inside a μ step (with `stop_cos`).
    pub check_every: usize,
    /// Solver options of each minimization.
    pub solver: SolverOptions,
}

impl CoplanarityOptions {
    /// The thesis's schedule ([Cortés Aguirre 2012, §4.2, App. B] defaults): `μ₀ = 0.1`, `μ ← 0.1μ`
    /// while `μ > 10⁻¹²`, no planarity stop.
    pub fn thesis() -> Self {
        Self {
            mu0: 0.1,
            stop_cos: None,
            ..Self::default()
        }
    }
}

impl Default for CoplanarityOptions {
    fn default() -> Self {
        Self {
            omega_rel: 1e-8,
            mu0: 500.0,
            mu_min: 1e-12,
            planarity_tol: 1e-2,
            stop_cos: Some(1e-3),
            check_every: 5,
            solver: SolverOptions {
                max_iter: 50,
                ftol: 1e-8,
                gtol: 1e-4,
                ..SolverOptions::default()
            },
        }
    }
}

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
    problem: &dyn Problem,
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

/// [González Flores, Algorithm 4.1, Algorithm 4.2] as implemented in UNAMALLA 2.0 (§4.6.1, §5.4):
/// adaptive `k` with the double homotopy, then the classic phase. `x` (free-node coordinates of
/// `topo`) is overwritten with the result.
pub fn adaptive_k(
    topo: &Arc<QuadTopology>,
    x: &mut [f64],
    opts: &AdaptiveKOptions,
    session: &mut Session<'_>,
) -> Result<SmoothReport, OptimError> {
    check_sigma("sigma", opts.sigma)?;
    if !(opts.k_star.is_finite() && opts.k_star < 1.0) {
        return Err(OptimError::InvalidOption {
            name: "k_star",
            value: opts.k_star,
            reason: "the floor k* must be finite (and below 1)",
        });
    }
    if topo.num_vars() == 0 {
        return Err(OptimError::NoFreeNodes);
    }
    let n = topo.num_triangles();
    let guard = QuadLocalGuard::new(topo.clone());
    let (probe, c0) = quad_start(topo, x, session)?;
    let ab = c0.mean;
    let (init, mut messages) = start_record(&c0);
    let w_final = match opts.functional {
        KFunctional::KSmoothArea | KFunctional::KAreaLength => 1.0 - opts.sigma,
        _ => 0.0,
    };
    let mut last = None;
    session.guard_threshold = 0.0;
    // 0. pre-smoothing with Length (truncated Newton + line search)
    if let Some((p, r)) =
        length_presmooth(topo, x, opts.presmooth, &opts.solver, ab, session, &guard)?
    {
        return Ok(report(
            session,
            &p,
            x,
            &init,
            messages,
            Some(r),
            -opts.k_star,
        ));
    }
    // 1. homotopy in k
    session.set_phase(Phase::Homotopic);
    let kstar = opts.k_star * ab;
    let mut k0: Option<f64> = None;
    let mut steps = 0;
    let mut reached = false;
    let mut stalled = None;
    let hom_opts = SolverOptions {
        max_iter: opts.iters_per_k.max(1),
        ftol: 0.0,
        ..opts.solver.clone()
    };
    // α₋ after each update (for the stall test of `stop_at_target`)
    let mut history: Vec<f64> = Vec::new();
    // the functional value after each update's solve (for [`PLATEAU_UPDATES`])
    let mut values: Vec<f64> = Vec::new();
    for upd in 0..opts.max_updates {
        let c = session.convexity(&probe, x);
        let am = c.min;
        let k = kstar.max(-1.0015 * am + 0.01 * ab);
        let k0v = *k0.get_or_insert(k);
        session.monitor.k_old = session.monitor.k_current;
        session.monitor.k_current = Some(k / ab);
        history.push(am);
        let stationary = history.len() > TARGET_STALL_UPDATES
            && am <= history[history.len() - 1 - TARGET_STALL_UPDATES] + TARGET_STALL_RISE * ab;
        if opts.stop_at_target && c.convex() && on_plateau(&values) {
            stalled = Some(StopReason::MaxIter);
            break;
        }
        if c.convex() && (k <= kstar || (opts.stop_at_target && am > -kstar && stationary)) {
            messages.push(if upd == 0 {
                Status::InitialGood
            } else {
                Status::HomotopicOk
            });
            reached = true;
            break;
        }
        steps += 1;
        let ah = recommended_alpha_hat(k, am);
        let (f1, f2) = kernels(opts.functional, k, Some(ah), n, ab)?;
        let w2 = homotopy_weight(opts.schedule, w_final, k0v, k, kstar);
        let p = QuadFunctional::new(topo.clone(), combine(f1, f2, w2));
        let r = minimize_with(&p, x, &hom_opts, session, Some(&guard))?;
        last = Some(r);
        values.push(r.f);
        if r.reason.interrupted() {
            let mut rep = report(session, &p, x, &init, messages, last, -opts.k_star);
            rep.continuation_steps = steps;
            return Ok(rep);
        }
        if r.iterations == 0 {
            // no accepted step: `x`, hence `α₋` and `k`, are unchanged, so every further
            // update would repeat this solve exactly — the homotopy has stalled
            stalled = Some(r.reason);
            break;
        }
    }
    // 2. classic phase at k*
    if opts.classic {
        session.set_phase(Phase::Classic);
        let c = session.convexity(&probe, x);
        let k = if reached {
            kstar
        } else {
            kstar.max(-1.0015 * c.min + 0.01 * ab)
        };
        let ah = recommended_alpha_hat(k, c.min);
        let (f1, f2) = kernels(opts.functional, k, Some(ah), n, ab)?;
        let p = QuadFunctional::new(topo.clone(), combine(f1, f2, w_final));
        // keep α > −k once there
        session.guard_threshold = if c.min > -k { (-k).max(0.0) } else { 0.0 };
        let r = minimize_with(&p, x, &opts.solver, session, Some(&guard))?;
        session.guard_threshold = 0.0;
        last = Some(r);
        let mut rep = report(session, &p, x, &init, messages, last, -opts.k_star);
        rep.continuation_steps = steps;
        return Ok(rep);
    }
    let mut rep = report(session, &probe, x, &init, messages, last, -opts.k_star);
    rep.continuation_steps = steps;
    if !reached {
        rep.status = Status::Stopped {
            reason: stalled.unwrap_or(StopReason::MaxIter),
            convex: rep.convex,
        };
        rep.messages.push(rep.status);
    }
    Ok(rep)
}

/// [Cortés Aguirre 2012, §3.4, Algorithm A] on a quad mesh: minimize `H_ω` (normalized), halve `ω`
/// until `α₋ > ε·ᾱ` or `ω` reaches the floor, then one refinement run (safeguarded at `ε·ᾱ`).
pub fn omega_continuation(
    topo: &Arc<QuadTopology>,
    x: &mut [f64],
    opts: &OmegaOptions,
    session: &mut Session<'_>,
) -> Result<SmoothReport, OptimError> {
    if topo.num_vars() == 0 {
        return Err(OptimError::NoFreeNodes);
    }
    let n = topo.num_triangles();
    let guard = QuadLocalGuard::new(topo.clone());
    let (probe, c0) = quad_start(topo, x, session)?;
    let ab = c0.mean;
    let make = |w: f64| -> Result<QuadFunctional, OptimError> {
        Ok(QuadFunctional::new(
            topo.clone(),
            KernelExpr::from(HOmega::new(w)?).normalized(n, ab)?,
        ))
    };
    let mut omega = opts.omega0_rel * ab;
    let floor = opts.omega_floor_rel * ab;
    omega_loop(
        session,
        &probe,
        x,
        opts.eps,
        ab,
        c0,
        &mut omega,
        floor,
        opts,
        &make,
        Some(&guard),
    )
}

#[allow(clippy::too_many_arguments)]
fn omega_loop<P: Problem>(
    session: &mut Session<'_>,
    probe: &dyn Problem,
    x: &mut [f64],
    eps: f64,
    mean: f64,
    c0: crate::monitor::Convexity,
    omega: &mut f64,
    floor: f64,
    opts: &OmegaOptions,
    make: &dyn Fn(f64) -> Result<P, OptimError>,
    guard: Option<&QuadLocalGuard>,
) -> Result<SmoothReport, OptimError> {
    if !(*omega > 0.0 && omega.is_finite()) {
        return Err(OptimError::InvalidOption {
            name: "omega0_rel",
            value: opts.omega0_rel,
            reason: "ω₀ must be > 0",
        });
    }
    let (init, mut messages) = start_record(&c0);
    session.set_phase(Phase::Homotopic);
    session.guard_threshold = 0.0;
    let mut last;
    let mut steps = 0;
    let mut ok = false;
    loop {
        session.monitor.omega = Some(*omega);
        let p = make(*omega)?;
        let r = minimize_with(&p, x, &opts.solver, session, guard)?;
        steps += 1;
        last = Some(r);
        if r.reason.interrupted() {
            let mut rep = report(session, &p, x, &init, messages, last, eps);
            rep.continuation_steps = steps;
            return Ok(rep);
        }
        let c = session.convexity(probe, x);
        if c.eps_convex(eps) {
            ok = true;
            break;
        }
        if *omega * 0.5 < floor {
            break;
        }
        *omega *= 0.5;
    }
    if ok {
        messages.push(Status::HomotopicOk);
        if opts.refinement {
            session.set_phase(Phase::Classic);
            session.guard_threshold = eps * mean;
            let p = make(*omega)?;
            let r = minimize_with(&p, x, &opts.solver, session, guard)?;
            session.guard_threshold = 0.0;
            last = Some(r);
        }
    }
    let mut rep = report(session, probe, x, &init, messages, last, eps);
    rep.continuation_steps = steps;
    rep.omega = Some(*omega);
    Ok(rep)
}

/// [Cortés Aguirre 2012, §3.4, Algorithm A] on a hexahedral mesh (`H_ω` over the 10 tetrahedra of
/// each hexahedron, ε-convexity `V > ε·v̄`).
pub fn omega_continuation_hex(
    topo: &Arc<HexTopology>,
    scaling: Scaling3,
    x: &mut [f64],
    opts: &OmegaOptions,
    session: &mut Session<'_>,
) -> Result<SmoothReport, OptimError> {
    if topo.num_vars() == 0 {
        return Err(OptimError::NoFreeNodes);
    }
    let probe = HexFunctional::h_omega(topo.clone(), 1.0, scaling)?;
    let c0 = session.convexity(&probe, x);
    let vbar = c0.mean;
    if !(vbar > 0.0 && vbar.is_finite()) {
        return Err(OptimError::InvalidOption {
            name: "mean volume",
            value: vbar,
            reason: "the mesh must have a positive mean tetrahedron volume",
        });
    }
    let make = |w: f64| -> Result<HexFunctional, OptimError> {
        Ok(HexFunctional::h_omega(topo.clone(), w, scaling)?)
    };
    let mut omega = opts.omega0_rel * vbar;
    let floor = opts.omega_floor_rel * vbar;
    omega_loop(
        session, &probe, x, opts.eps, vbar, c0, &mut omega, floor, opts, &make, None,
    )
}

/// [Cortés Aguirre 2012, §4.2, Algorithm B]: from a convex (Algorithm A) mesh, minimize
/// `H_ω + C·Σk²` with `C = 1/(2μ)` for `μ = μ₀, 0.1μ₀, …` while `μ > μ_min`; the safeguard keeps
/// the mesh convex.
///
/// # Default schedule (measured in `docs/results.md`, "Algorithm B")
/// * **μ₀ = 500** (`C₀ = 10⁻³`), the thesis's Table 4.5 alternative, instead of its default
///   0.1 (`C₀ = 5`). `H_ω` carries the thesis's `1/(10N_c)` normalization (of order 1) while
///   `Σk²` runs over all `6·N_int` interior faces, so `C₀ = 5` makes the penalty dominate
///   from the first iteration: on the Pico-like 21³ case the interior cells are pushed
///   against the convexity safeguard, every μ step stops at its iteration limit with steps
///   of 1–3 CG iterations, and 12 cells stay non-hexahedral. `C₀ = 10⁻³` lets the harmonic
///   term shape the mesh while the planarity constraints stiffen gradually; it finished every
///   built-in case (measured).
/// * **Planarity stop** (`stop_cos = 10⁻³`, a factor 10 below the counting tolerance
///   `ε_n = 10⁻²` of criterion 2): the continuation ends as soon as every penalized face
///   has max `|cos|` ≤ `stop_cos`, checked every `check_every = 5` iterations (see
///   `coplanarity_step`). The thesis's schedule always runs to `μ = 10⁻¹²`: on the sphere
///   20³ the faces were already at `|cos| < 10⁻²` after 10 iterations of the first step and
///   the remaining ≈ 140 iterations (with > 100 CG iterations each, since the forcing sequence
///   tightens as the gradient falls) only drove `|cos|` from 10⁻⁵ to 10⁻¹².
/// * The thesis's schedule is [`CoplanarityOptions::thesis`] (CLI: `--b-schedule thesis`).
pub fn coplanarity_continuation(
    topo: &Arc<HexTopology>,
    scaling: Scaling3,
    x: &mut [f64],
    opts: &CoplanarityOptions,
    session: &mut Session<'_>,
) -> Result<SmoothReport, OptimError> {
    if topo.num_vars() == 0 {
        return Err(OptimError::NoFreeNodes);
    }
    if !(opts.mu0 > 0.0 && opts.mu_min >= 0.0 && opts.mu0.is_finite()) {
        return Err(OptimError::InvalidOption {
            name: "mu0",
            value: opts.mu0,
            reason: "μ₀ must be > 0 and μ_min ≥ 0",
        });
    }
    let probe = HexFunctional::h_omega(topo.clone(), 1.0, scaling)?;
    let c0 = session.convexity(&probe, x);
    let (init, mut messages) = start_record(&c0);
    let omega = (opts.omega_rel * c0.mean).max(f64::MIN_POSITIVE);
    session.set_phase(Phase::Homotopic);
    session.guard_threshold = 0.0;
    session.monitor.omega = Some(omega);
    let mut mu = opts.mu0;
    let mut last = None;
    let mut steps = 0;
    let mut p = HexFunctional::h_omega(topo.clone(), omega, scaling)?;
    let planar = |x: &[f64]| match opts.stop_cos {
        Some(tol) => topo.planarity_report(x, tol).1 == 0,
        None => false,
    };
    let mut done = planar(x);
    while mu > opts.mu_min && !done {
        session.monitor.mu = Some(mu);
        p.set_coplanarity(Some(1.0 / (2.0 * mu)))?;
        let r = if opts.stop_cos.is_some() {
            coplanarity_step(&p, x, opts, session, &planar, &mut done)?
        } else {
            minimize_with(&p, x, &opts.solver, session, None)?
        };
        steps += 1;
        last = Some(r);
        if r.reason.interrupted() {
            break;
        }
        done |= planar(x);
        mu *= 0.1;
    }
    // a continuation cut short because the faces are planar ends with that reason, whatever
    // stopped its last μ step (FTOL, MAXITER, …)
    if done {
        if let Some(r) = last.as_mut() {
            r.reason = StopReason::Planar;
        }
    }
    if last.is_none() {
        messages.push(Status::InitialGood);
    }
    let mut rep = report(session, &p, x, &init, messages, last, 0.0);
    rep.continuation_steps = steps;
    rep.omega = Some(omega);
    rep.mu = session.monitor.mu;
    rep.planarity = Some(topo.planarity_report(x, opts.planarity_tol));
    Ok(rep)
}

/// One μ step of Algorithm B with the planarity stop: the solver runs in chunks of
/// `check_every` iterations (at most `solver.max_iter` in all) and the step ends early once
/// [`HexTopology::planarity_report`] finds every penalized face at `|cos| ≤ stop_cos`
/// (`done` is then set). GTOL stays relative to the gradient at the start of the step (it
/// is passed to each chunk as an absolute tolerance); the forcing sequence and the trust
/// radius restart with each chunk.
fn coplanarity_step(
    p: &HexFunctional,
    x: &mut [f64],
    opts: &CoplanarityOptions,
    session: &mut Session<'_>,
    planar: &dyn Fn(&[f64]) -> bool,
    done: &mut bool,
) -> Result<crate::solver::SolveResult, OptimError> {
    let mut g = vec![0.0; x.len()];
    p.value_grad(x, &mut g);
    let g0 = g.iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut chunk = SolverOptions {
        gtol: 0.0,
        gtol_abs: opts.solver.gtol_abs.max(opts.solver.gtol * g0),
        ..opts.solver.clone()
    };
    let total = opts.solver.max_iter.max(1);
    let every = opts.check_every.max(1);
    let mut used = 0;
    let mut acc: Option<crate::solver::SolveResult> = None;
    loop {
        chunk.max_iter = every.min(total - used);
        let r = minimize_with(p, x, &chunk, session, None)?;
        used += r.iterations;
        let merged = match acc {
            Some(a) => crate::solver::SolveResult {
                iterations: a.iterations + r.iterations,
                fevals: a.fevals + r.fevals,
                cg_iterations: a.cg_iterations + r.cg_iterations,
                ..r
            },
            None => r,
        };
        acc = Some(merged);
        if r.reason != StopReason::MaxIter || used >= total || r.iterations == 0 {
            return Ok(merged);
        }
        if planar(x) {
            *done = true;
            return Ok(merged);
        }
    }
}

/// Options of [`block_smoothing`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BlockSmoothingOptions {
    /// σ of (6.8): weight of `H_ω` (Laguna Honda example: 0.1).
    pub sigma: f64,
    /// Boundary density `w` of (6.9) (1 = the unweighted (6.8)).
    pub density: f64,
    /// Width of the boundary band of (6.9) in cell layers.
    pub layers: usize,
    /// ε of the guarantee: the result has `α₋ > ε·ᾱ` (and `ω = ε·ᾱ`, so `H_ω` is Winslow's
    /// `l/α` on the whole admissible set).
    pub eps: f64,
    /// Untangling options for a start that is not ε-convex (its `k_star` is set to `−ε`).
    pub untangle: AdaptiveKOptions,
    /// Solver options of the (6.8) minimization.
    pub solver: SolverOptions,
    /// σ continuation: before the run at `sigma`, (6.8) is minimized at each of these σ in
    /// order (e.g. `[1.0]`: the H_ω-dominant, Winslow-type first stage), warm-started, with at
    /// most `continuation_iter` iterations each and the same stop rules. Empty: none.
    pub sigma_continuation: Vec<f64>,
    /// Iteration cap of each σ-continuation stage.
    pub continuation_iter: usize,
}

impl Default for BlockSmoothingOptions {
    fn default() -> Self {
        Self {
            sigma: 0.1,
            density: 1.0,
            layers: 2,
            eps: 0.01,
            untangle: AdaptiveKOptions {
                classic: false,
                ..AdaptiveKOptions::default()
            },
            solver: SolverOptions::default(),
            sigma_continuation: Vec::new(),
            continuation_iter: 50,
        }
    }
}

/// [Méndez 2023, (6.8), (6.9)]: `F = (1−σ)·w·F_AO + σ·H_ω` with the ε-convexity guarantee (see the
/// module docs). `x` is overwritten.
pub fn block_smoothing(
    topo: &Arc<QuadTopology>,
    x: &mut [f64],
    opts: &BlockSmoothingOptions,
    session: &mut Session<'_>,
) -> Result<SmoothReport, OptimError> {
    check_sigma("sigma", opts.sigma)?;
    if !(opts.eps > 0.0 && opts.eps < 1.0) {
        return Err(OptimError::InvalidOption {
            name: "eps",
            value: opts.eps,
            reason: "ε must lie in (0, 1)",
        });
    }
    if !(opts.density.is_finite() && opts.density > 0.0) {
        return Err(OptimError::InvalidOption {
            name: "density",
            value: opts.density,
            reason: "the boundary density must be finite and > 0",
        });
    }
    if topo.num_vars() == 0 {
        return Err(OptimError::NoFreeNodes);
    }
    let n = topo.num_triangles();
    let (probe, c0) = quad_start(topo, x, session)?;
    let ab = c0.mean;
    let (init, mut messages) = start_record(&c0);
    if !c0.eps_convex(opts.eps) {
        let uo = AdaptiveKOptions {
            k_star: -opts.eps,
            classic: false,
            stop_at_target: true,
            ..opts.untangle.clone()
        };
        let r = adaptive_k(topo, x, &uo, session)?;
        messages.extend(r.messages.iter().skip(1).copied());
        if matches!(r.status, Status::Stopped { reason, .. } if reason.interrupted()) {
            let mut rep = report(session, &probe, x, &init, messages, None, opts.eps);
            rep.status = r.status;
            return Ok(rep);
        }
    }
    let c = session.convexity(&probe, x);
    let ao = KernelExpr::from(AreaOrthogonality).normalized(n, ab)?;
    let ao = if opts.density != 1.0 {
        ao.cell_weighted(topo.boundary_density(opts.density, opts.layers))?
    } else {
        ao
    };
    let omega = opts.eps * ab;
    let h = KernelExpr::from(HOmega::new(omega)?).normalized(n, ab)?;
    let functional = |sigma: f64| {
        QuadFunctional::new(
            topo.clone(),
            KernelExpr::weighted_sum(vec![(1.0 - sigma, ao.clone()), (sigma, h.clone())]),
        )
    };
    session.set_phase(Phase::Classic);
    session.monitor.k_current = None;
    session.monitor.k_old = None;
    session.monitor.omega = Some(omega);
    session.guard_threshold = if c.eps_convex(opts.eps) {
        opts.eps * ab
    } else {
        0.0
    };
    let guard = QuadLocalGuard::new(topo.clone());
    if opts.solver.stop.plateau_alpha > 0.0 {
        session.set_quality(Some(crate::monitor::quad_mu_share(topo.clone())));
    }
    let run = |p: &QuadFunctional, x: &mut [f64], so: &SolverOptions, session: &mut Session<'_>| {
        if so.hessian == HessianMode::ProjectedPsd {
            let model = PsdModel::new(p, PsdProjection::Clamp);
            minimize_with(&model, x, so, session, Some(&guard))
        } else {
            minimize_with(p, x, so, session, Some(&guard))
        }
    };
    for &sc in &opts.sigma_continuation {
        check_sigma("sigma_continuation", sc)?;
        let so = SolverOptions {
            max_iter: opts.continuation_iter,
            ..opts.solver.clone()
        };
        let r = run(&functional(sc), x, &so, session)?;
        if r.reason.interrupted() {
            break;
        }
        // the next stage starts from here: the guard follows the iterate's ε-convexity
        let c = session.convexity(&probe, x);
        session.guard_threshold = if c.eps_convex(opts.eps) {
            opts.eps * ab
        } else {
            0.0
        };
    }
    let p = functional(opts.sigma);
    // (an interrupted continuation returns at once, with the interrupt's reason)
    let r = run(&p, x, &opts.solver, session)?;
    session.guard_threshold = 0.0;
    let mut rep = report(session, &p, x, &init, messages, Some(r), opts.eps);
    rep.omega = Some(omega);
    Ok(rep)
}

/// The classic combinations of [González Flores, Table 5.1, §A.4.3] (the `Area-Lenght` and
/// `Area-Ortho.` entries of the Functional menu), each the convex combination `σ·F̃₁ + (1 − σ)·F̃₂`
/// of normalized functionals (§5.1; σ is the weight of the first-named functional, (5.1)–(5.2)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ClassicCombination {
    /// t-Area – Length: `σ·Σα²/(Nᾱ²) + (1 − σ)·Σl/(2Nᾱ)` (Table 5.1 weights .95, .7, .5; the
    /// text recommends 0.9 as an automatic value; the menu's default is 0.5).
    AreaLength,
    /// t-Area – Orthogonality: `½·Σα²/(Nᾱ²) + ½·Σo²/(Nᾱ²)`, `o = a·b`, with the weight fixed at
    /// 0.5 (Table 5.1; the weight slider is disabled for it, §A.4.3). By Lagrange's identity
    /// `α² + o² = |a|²|b|²` this is `Σ|a|²|b|²/(2Nᾱ²)`.
    AreaOrthogonality,
}

impl ClassicCombination {
    /// The fixed weight, if the source fixes one (0.5 for Area–Orthogonality).
    pub fn fixed_sigma(self) -> Option<f64> {
        match self {
            ClassicCombination::AreaLength => None,
            ClassicCombination::AreaOrthogonality => Some(0.5),
        }
    }
    /// The normalized kernel `σ·F̃₁ + (1 − σ)·F̃₂` for `n` corner triangles of mean `ᾱ`.
    pub fn kernel(self, sigma: f64, n: usize, alpha_bar: f64) -> Result<KernelExpr, OptimError> {
        check_sigma("sigma", sigma)?;
        if let Some(f) = self.fixed_sigma() {
            if sigma != f {
                return Err(OptimError::InvalidOption {
                    name: "sigma",
                    value: sigma,
                    reason: "the Area-Orthogonality weight is fixed at 0.5",
                });
            }
        }
        let f2 = match self {
            ClassicCombination::AreaLength => KernelExpr::from(Length),
            ClassicCombination::AreaOrthogonality => KernelExpr::from(Orthogonality),
        };
        Ok(KernelExpr::convex(
            sigma,
            KernelExpr::from(Area).normalized(n, alpha_bar)?,
            f2.normalized(n, alpha_bar)?,
        )?)
    }
}

/// Options of [`classic_combination`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ClassicOptions {
    /// The pair.
    pub combination: ClassicCombination,
    /// σ, the weight of t-Area.
    pub sigma: f64,
    /// Length pre-smoothing iterations (0 = "Previous Smoothness: No").
    pub presmooth: usize,
    /// ε of the reported ε-convexity (`α₋ > ε·ᾱ`).
    pub eps: f64,
    /// Solver options.
    pub solver: SolverOptions,
}

/// Minimizes a classic combination ([`ClassicCombination`]) from `x` with the safeguard (a
/// convex start stays convex). Unlike the adaptive functionals these do not untangle: the
/// thesis reports none of its four test regions convex with t-Area–Length at σ = .5 or .95
/// (Figs 5.2–5.3); a folded start is minimized without the safeguard and the report says
/// whether it came out convex.
pub fn classic_combination(
    topo: &Arc<QuadTopology>,
    x: &mut [f64],
    opts: &ClassicOptions,
    session: &mut Session<'_>,
) -> Result<SmoothReport, OptimError> {
    let (_probe, c0) = quad_start(topo, x, session)?;
    let n = topo.num_triangles();
    let guard = QuadLocalGuard::new(topo.clone());
    let ab = c0.mean;
    let kernel = opts.combination.kernel(opts.sigma, n, ab)?;
    let (init, messages) = start_record(&c0);
    session.guard_threshold = 0.0;
    if let Some((p, r)) =
        length_presmooth(topo, x, opts.presmooth, &opts.solver, ab, session, &guard)?
    {
        return Ok(report(session, &p, x, &init, messages, Some(r), opts.eps));
    }
    session.set_phase(Phase::Classic);
    let p = QuadFunctional::new(topo.clone(), kernel);
    let r = minimize_with(&p, x, &opts.solver, session, Some(&guard))?;
    Ok(report(session, &p, x, &init, messages, Some(r), opts.eps))
}

/// Untangles with Ivanenko's convex-mesh functional `Σ((ε_I − α)₊)²` ([González Flores, (2.50)],
/// after Ivanenko), scaled by `1/(N·ε_I²)`: the value is 0 exactly when every triangle has
/// `α ≥ ε_I`. The minimization approaches that zero set from below and the stopping tests end it a
/// hair short (measured on Ivanenko's folded 11 × 11 grid with `ε_I = 0.01ᾱ`: `α₋ = 0.0099994ᾱ`),
/// so the functional is given `ε_I = 2·eps·ᾱ` and the report's ε-convexity is checked at `eps`. The
/// functional only pushes small triangles up; it has no smoothing term (the thesis uses it for an
/// initial convex mesh). A start that is already ε-convex is returned unchanged.
pub fn ivanenko_untangle(
    topo: &Arc<QuadTopology>,
    x: &mut [f64],
    eps: f64,
    solver: &SolverOptions,
    session: &mut Session<'_>,
) -> Result<SmoothReport, OptimError> {
    let (probe, c0) = quad_start(topo, x, session)?;
    if !(eps.is_finite() && eps > 0.0) {
        return Err(OptimError::InvalidOption {
            name: "eps",
            value: eps,
            reason: "Ivanenko's ε must be finite and > 0",
        });
    }
    let n = topo.num_triangles();
    let guard = QuadLocalGuard::new(topo.clone());
    let ab = c0.mean;
    let (init, mut messages) = start_record(&c0);
    if c0.eps_convex(eps) {
        messages.push(Status::InitialGood);
        return Ok(report(session, &probe, x, &init, messages, None, eps));
    }
    let e = 2.0 * eps * ab;
    let k = KernelExpr::from(IvanenkoConvex::new(e)?).scaled(1.0 / (n as f64 * e * e));
    session.set_phase(Phase::Homotopic);
    session.guard_threshold = 0.0;
    let p = QuadFunctional::new(topo.clone(), k);
    let r = minimize_with(&p, x, solver, session, Some(&guard))?;
    Ok(report(session, &p, x, &init, messages, Some(r), eps))
}

/// The functional (and driver) of [`smooth`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum SmoothFunctional {
    /// `ao-homega`: [Méndez 2023, (6.8), (6.9)] with the ε-convexity guarantee
    /// ([`block_smoothing`]).
    BlockSmoothing {
        /// σ (weight of `H_ω`).
        sigma: f64,
        /// Boundary density `w` (1 = plain (6.8)).
        density: f64,
        /// Band width in cell layers.
        layers: usize,
    },
    /// `karea-length`, `ksmooth-area`, `karea`, `ksmooth`: the adaptive driver
    /// ([`adaptive_k`]) with weight σ of the adaptive functional.
    AdaptiveK {
        /// The pair.
        functional: KFunctional,
        /// σ.
        sigma: f64,
    },
    /// `homega`: Algorithm A ([`omega_continuation`]).
    OmegaContinuation,
    /// `ivanenko`: Ivanenko's convex-mesh functional with `ε` = [`SmoothOptions::eps`]
    /// ([`ivanenko_untangle`]).
    Ivanenko,
    /// `area-length`, `area-ortho`: the classic combinations ([`classic_combination`]) with
    /// weight σ of t-Area.
    Classic {
        /// The pair.
        combination: ClassicCombination,
        /// σ.
        sigma: f64,
    },
}

impl SmoothFunctional {
    /// Plain (6.8) (boundary density 1, band of 2 layers) with weight `sigma` of `H_ω`.
    pub fn block_smoothing(sigma: f64) -> Self {
        SmoothFunctional::BlockSmoothing {
            sigma,
            density: 1.0,
            layers: 2,
        }
    }
}

impl Default for SmoothFunctional {
    /// (6.8) with σ = 0.1 (the Laguna Honda example of [Méndez 2023, Example 6.3]).
    fn default() -> Self {
        SmoothFunctional::block_smoothing(0.1)
    }
}

impl SmoothFunctional {
    /// The same functional with weight `sigma` (the weight of `H_ω` for `ao-homega`, of the
    /// adaptive functional for the adaptive pairs, of t-Area for the classic pairs). An error
    /// for a σ outside `[0, 1]`, for a driver without a weight (`homega`, `karea`, `ksmooth`) and
    /// for Area–Orthogonality with σ ≠ 0.5 (its weight is fixed).
    pub fn with_sigma(self, sigma: f64) -> Result<Self, OptimError> {
        check_sigma("sigma", sigma)?;
        Ok(match self {
            SmoothFunctional::BlockSmoothing {
                density, layers, ..
            } => SmoothFunctional::BlockSmoothing {
                sigma,
                density,
                layers,
            },
            SmoothFunctional::AdaptiveK {
                functional: f @ (KFunctional::KAreaLength | KFunctional::KSmoothArea),
                ..
            } => SmoothFunctional::AdaptiveK {
                functional: f,
                sigma,
            },
            SmoothFunctional::Classic { combination, .. } => {
                if combination.fixed_sigma().is_some_and(|f| f != sigma) {
                    return Err(OptimError::InvalidOption {
                        name: "sigma",
                        value: sigma,
                        reason: "the Area-Orthogonality weight is fixed at 0.5",
                    });
                }
                SmoothFunctional::Classic { combination, sigma }
            }
            _ => {
                return Err(OptimError::InvalidOption {
                    name: "sigma",
                    value: sigma,
                    reason:
                        "this functional is not a combination (homega, karea, ksmooth, ivanenko)",
                })
            }
        })
    }
}

impl FromStr for SmoothFunctional {
    type Err = OptimError;
    fn from_str(s: &str) -> Result<Self, OptimError> {
        let k = |functional| SmoothFunctional::AdaptiveK {
            functional,
            sigma: 0.5,
        };
        Ok(match s {
            "ao-homega" => SmoothFunctional::default(),
            "karea-length" => k(KFunctional::KAreaLength),
            "ksmooth-area" => k(KFunctional::KSmoothArea),
            "karea" => k(KFunctional::KArea),
            "ksmooth" => k(KFunctional::KSmoothness),
            "homega" => SmoothFunctional::OmegaContinuation,
            "ivanenko" => SmoothFunctional::Ivanenko,
            "area-length" => SmoothFunctional::Classic {
                combination: ClassicCombination::AreaLength,
                sigma: 0.5,
            },
            "area-ortho" => SmoothFunctional::Classic {
                combination: ClassicCombination::AreaOrthogonality,
                sigma: 0.5,
            },
            _ => {
                return Err(OptimError::UnknownName {
                    what: "functional",
                    name: s.to_string(),
                    expected: "ao-homega, karea-length, ksmooth-area, karea, ksmooth, homega, area-length, area-ortho, ivanenko",
                })
            }
        })
    }
}

/// Options of [`smooth`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SmoothOptions {
    /// The functional / driver.
    pub functional: SmoothFunctional,
    /// The solver and its stopping options (every phase uses this solver).
    pub solver: SolverOptions,
    /// ε of the ε-convexity target (`α₋ > ε·ᾱ`; adaptive-k uses `k* = −ε`).
    pub eps: f64,
    /// Length pre-smoothing iterations (adaptive-k and untangling; 0 = none).
    pub presmooth: usize,
    /// Solver iterations per `k` update (0 = 5 for truncated Newton, 10 otherwise).
    pub iters_per_k: usize,
    /// Maximum `k` updates.
    pub max_k_updates: usize,
    /// An explicit wall-clock limit of the run in seconds (`None`, the default: the run ends on
    /// its convergence tests and iteration caps only, so its result does not depend on the
    /// machine). When it is reached the status says "STOP by TIME LIMIT"
    /// ([`StopReason::TimeLimit`]).
    #[serde(default)]
    pub time_limit: Option<f64>,
    /// σ continuation of the (6.8) driver ([`BlockSmoothingOptions::sigma_continuation`]).
    #[serde(default)]
    pub sigma_continuation: Vec<f64>,
    /// Iteration cap of each σ-continuation stage (0 = 50).
    #[serde(default)]
    pub continuation_iter: usize,
    /// The homotopy path of the adaptive pairs ([`HomotopySchedule`]).
    #[serde(default)]
    pub schedule: HomotopySchedule,
}

impl Default for SmoothOptions {
    fn default() -> Self {
        Self {
            functional: SmoothFunctional::default(),
            solver: SolverOptions::default(),
            eps: 0.01,
            presmooth: 0,
            iters_per_k: 0,
            max_k_updates: 2000,
            time_limit: None,
            sigma_continuation: Vec::new(),
            continuation_iter: 0,
            schedule: HomotopySchedule::Linear,
        }
    }
}

impl SmoothOptions {
    fn adaptive(&self, functional: KFunctional, sigma: f64, classic: bool) -> AdaptiveKOptions {
        let ipk = if self.iters_per_k > 0 {
            self.iters_per_k
        } else if matches!(self.solver.solver, Solver::TnTr | Solver::TnLs) {
            5
        } else {
            10
        };
        AdaptiveKOptions {
            functional,
            sigma,
            k_star: -self.eps,
            iters_per_k: ipk,
            max_updates: self.max_k_updates,
            presmooth: self.presmooth,
            classic,
            solver: self.solver.clone(),
            schedule: self.schedule,
            stop_at_target: false,
        }
    }
}

/// Smooths (and, if needed, untangles) a quad mesh in place: the free nodes of `mesh` are
/// moved, fixed nodes stay. Returns the report; an error only for invalid input (no free
/// nodes, non-finite coordinates, invalid options, a boundary enclosing no area).
pub fn smooth<M: HasQuadCells + FreeNodes + ?Sized>(
    mesh: &mut M,
    opts: &SmoothOptions,
    observer: &mut dyn Observer,
) -> Result<SmoothReport, OptimError> {
    let topo = Arc::new(QuadTopology::from_mesh(&*mesh)?);
    if topo.num_vars() == 0 {
        return Err(OptimError::NoFreeNodes);
    }
    let mut x = topo.initial_x();
    let x0 = x.clone();
    let probe = QuadFunctional::new(topo.clone(), KernelExpr::from(Length));
    let mut session = Session::new(&probe, &x, observer);
    if let Some(t) = opts.time_limit {
        if !(t.is_finite() && t >= 0.0) {
            return Err(OptimError::InvalidOption {
                name: "time_limit",
                value: t,
                reason: "the time limit must be a finite number of seconds ≥ 0",
            });
        }
        session.set_time_limit(Some(Duration::from_secs_f64(t)));
    }
    let mut rep = match &opts.functional {
        SmoothFunctional::BlockSmoothing {
            sigma,
            density,
            layers,
        } => {
            let bo = BlockSmoothingOptions {
                sigma: *sigma,
                density: *density,
                layers: *layers,
                eps: opts.eps,
                untangle: opts.adaptive(KFunctional::KAreaLength, 0.5, false),
                solver: opts.solver.clone(),
                sigma_continuation: opts.sigma_continuation.clone(),
                continuation_iter: if opts.continuation_iter > 0 {
                    opts.continuation_iter
                } else {
                    50
                },
            };
            block_smoothing(&topo, &mut x, &bo, &mut session)?
        }
        SmoothFunctional::AdaptiveK { functional, sigma } => adaptive_k(
            &topo,
            &mut x,
            &opts.adaptive(*functional, *sigma, true),
            &mut session,
        )?,
        SmoothFunctional::OmegaContinuation => {
            let oo = OmegaOptions {
                eps: opts.eps,
                solver: opts.solver.clone(),
                ..OmegaOptions::default()
            };
            omega_continuation(&topo, &mut x, &oo, &mut session)?
        }
        SmoothFunctional::Ivanenko => {
            ivanenko_untangle(&topo, &mut x, opts.eps, &opts.solver, &mut session)?
        }
        SmoothFunctional::Classic { combination, sigma } => {
            let co = ClassicOptions {
                combination: *combination,
                sigma: *sigma,
                presmooth: opts.presmooth,
                eps: opts.eps,
                solver: opts.solver.clone(),
            };
            classic_combination(&topo, &mut x, &co, &mut session)?
        }
    };
    // never hand back more inverted cells than we were given (a run stopped early in the
    // middle of an untangling homotopy can be worse than its start)
    rep.keep_start_if_worse(&mut x, &x0);
    topo.scatter(&x, mesh.nodes_mut());
    Ok(rep)
}

/// Smooths several independent meshes in parallel (rayon), each with [`smooth`] and its own
/// fixed nodes — e.g. the blocks of a decomposition before they are merged, each with its
/// boundary fixed ([Méndez 2023, §6.3]: the blocks are smoothed one by one before the global
/// smoothing of the merged mesh).
///
/// Meshes for which `select` returns `false` are left alone (their entry is `None`). Runs
/// still going at `deadline` are stopped there (their status says "STOP by user"); as in
/// [`smooth`], a run never returns more non-convex cells than its mesh had.
pub fn smooth_each<M, S>(
    meshes: &mut [M],
    select: S,
    opts: &SmoothOptions,
    deadline: Option<std::time::Instant>,
) -> Vec<Option<Result<SmoothReport, OptimError>>>
where
    M: HasQuadCells + FreeNodes + Send,
    S: Fn(&M) -> bool + Sync,
{
    use crate::monitor::Control;
    use rayon::prelude::*;
    meshes
        .par_iter_mut()
        .map(|m| {
            if !select(m) {
                return None;
            }
            let mut stop_at_deadline = |_: &crate::monitor::Monitor| match deadline {
                Some(t) if std::time::Instant::now() >= t => Control::Stop,
                _ => Control::Continue,
            };
            Some(smooth(m, opts, &mut stop_at_deadline))
        })
        .collect()
}

/// Which hexahedral driver [`smooth_hex`] runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum HexDriver {
    /// Algorithm A only.
    #[default]
    AlgorithmA,
    /// Algorithm A, then Algorithm B (if A reached convexity).
    AlgorithmAB,
}

/// Options of [`smooth_hex`].
#[derive(Debug, Clone, PartialEq)]
pub struct HexSmoothOptions {
    /// Which algorithms.
    pub driver: HexDriver,
    /// Tetrahedron scaling of `H_ω`.
    pub scaling: Scaling3,
    /// Algorithm A options (ε default 10⁻⁴ here, as for
    /// [Cortés Aguirre 2012, Table 3.1, Table 3.2]).
    pub omega: OmegaOptions,
    /// Algorithm B options.
    pub coplanarity: CoplanarityOptions,
}

impl Default for HexSmoothOptions {
    fn default() -> Self {
        Self {
            driver: HexDriver::AlgorithmA,
            scaling: Scaling3::Index,
            omega: OmegaOptions {
                eps: 1e-4,
                ..OmegaOptions::default()
            },
            coplanarity: CoplanarityOptions::default(),
        }
    }
}

/// The hexahedral counterpart of [`smooth`]: Algorithm A (and optionally B) in place.
/// The returned report is Algorithm B's when it ran (its iteration counters include A's).
pub fn smooth_hex<M: HasHexCells + FreeNodes + ?Sized>(
    mesh: &mut M,
    opts: &HexSmoothOptions,
    observer: &mut dyn Observer,
) -> Result<SmoothReport, OptimError> {
    let topo = Arc::new(HexTopology::from_mesh(&*mesh)?);
    if topo.num_vars() == 0 {
        return Err(OptimError::NoFreeNodes);
    }
    let mut x = topo.initial_x();
    let x0 = x.clone();
    let probe = HexFunctional::h_omega(topo.clone(), 1.0, opts.scaling)?;
    let mut session = Session::new(&probe, &x, observer);
    let mut rep = omega_continuation_hex(&topo, opts.scaling, &mut x, &opts.omega, &mut session)?;
    if opts.driver == HexDriver::AlgorithmAB && rep.convex && rep.status.convex() == Some(true) {
        let a_msgs = rep.messages.clone();
        let b =
            coplanarity_continuation(&topo, opts.scaling, &mut x, &opts.coplanarity, &mut session)?;
        let mut msgs = a_msgs;
        msgs.extend(b.messages.iter().skip(1).copied());
        rep = SmoothReport {
            messages: msgs,
            initial_alfamin: rep.initial_alfamin,
            initial_inocon: rep.initial_inocon,
            eps: rep.eps,
            eps_convex: b.alfamin > rep.eps * b.alpha_bar,
            ..b
        };
    }
    rep.keep_start_if_worse(&mut x, &x0);
    topo.scatter(&x, mesh.nodes_mut());
    Ok(rep)
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
