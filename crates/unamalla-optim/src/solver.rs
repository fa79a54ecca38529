//! The solvers: truncated Newton with a trust region (Steihaug–CG) or a Moré–Thuente line
//! search, L-BFGS(m), and pointwise (Gauss–Seidel) Newton ([González Flores, App. B]; the
//! references are listed in `docs/references.md` of the repository; [Méndez 2023, §6.4.2] and
//! [Cortés Aguirre 2012, §3.3] use TRON, a trust-region truncated Newton).
//!
//! All of them report every iteration to a [`Session`], which also enforces the convexity
//! safeguard: when the iterate is convex (every element with a free vertex above the session's
//! threshold), trial points that are not are rejected. The entry points [`minimize`] and
//! [`minimize_with`] choose the method at run time and take a [`Problem`] (every capability);
//! the methods themselves use only part of it:
//!
//! | method | capabilities used |
//! |---|---|
//! | every method, the safeguard | [`Variables`], [`Gradient`], [`ElementMeasures`] |
//! | truncated Newton | + [`Hessian`] (the quadratic model: assembled, or `hess_vec` matrix-free) |
//! | L-BFGS, nonlinear CG | nothing more |
//! | pointwise Newton | + [`PointwiseModel`], and [`Hessian::hessian_pattern`] for the node colouring |
//!
//! The model Hessian of truncated Newton is whatever the problem's [`Hessian`] gives: a model
//! other than the exact Hessian (such as [`PsdModel`](crate::psd_model::PsdModel)) is supplied
//! by replacing that capability alone with [`WithHessian`](unamalla_functionals::WithHessian).

use std::str::FromStr;
use std::sync::Arc;

use rayon::prelude::*;
use unamalla_functionals::{
    Csr, ElementMeasures, Gradient, Hessian, PointwiseModel, Problem, QuadTopology, Variables,
};

use crate::error::OptimError;
use crate::linalg::{
    add_scaled, axpy, dot, inv3_spd, norm, scale_add, PrecondApply, Preconditioner,
};
use crate::linesearch::{more_thuente, LineSearchParams, LineSearchResult};
use crate::monitor::{Control, Session};
use crate::status::{LineSearchFailure, StopReason};

/// The optimization method (names as accepted by `unamalla smooth --solver`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum Solver {
    /// `tn-tr`: truncated Newton with a trust region (Steihaug–CG, negative-curvature exit);
    /// UNAMALLA's default and the TRON family of [Méndez 2023, §6.4.2] and
    /// [Cortés Aguirre 2012, §3.3].
    #[default]
    TnTr,
    /// `tn-ls`: truncated Newton with a Moré–Thuente line search.
    TnLs,
    /// `lbfgs`: L-BFGS with memory [`SolverOptions::lbfgs_memory`] (UNAMALLA: 3 or 5).
    Lbfgs,
    /// `pointwise`: Gauss–Seidel sweeps of local 2×2 / 3×3 Newton steps (García).
    Pointwise,
    /// `ncg-fr`: nonlinear conjugate gradients of Fletcher & Reeves (1964), one of the methods
    /// of UNAMALLA's predecessor ([González Flores, Preface]): `d₀ = −g₀`,
    /// `d_{k+1} = −g_{k+1} + β_k d_k`, `β_k = ‖g_{k+1}‖²/‖g_k‖²`, with a strong-Wolfe line search
    /// of curvature constant at most 0.1 (below ½, so every `d_k` is a descent direction:
    /// Al-Baali 1985) and a restart `d = −g` every `n` iterations or when `d` is not a descent
    /// direction.
    NcgFr,
}

impl Solver {
    /// All solvers.
    pub const ALL: [Solver; 5] = [
        Solver::TnTr,
        Solver::TnLs,
        Solver::Lbfgs,
        Solver::Pointwise,
        Solver::NcgFr,
    ];
    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Solver::TnTr => "tn-tr",
            Solver::TnLs => "tn-ls",
            Solver::Lbfgs => "lbfgs",
            Solver::Pointwise => "pointwise",
            Solver::NcgFr => "ncg-fr",
        }
    }
}

impl std::fmt::Display for Solver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Solver {
    type Err = OptimError;
    fn from_str(s: &str) -> Result<Self, OptimError> {
        Solver::ALL
            .into_iter()
            .find(|v| v.name() == s)
            .ok_or_else(|| OptimError::UnknownName {
                what: "solver",
                name: s.to_string(),
                expected: "tn-tr, tn-ls, lbfgs, pointwise, ncg-fr",
            })
    }
}

/// Mode of pointwise Newton (UNAMALLA "Newton Point to Point").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum PointwiseMode {
    /// Solve the local 2×2 (3×3) Newton system.
    #[default]
    Simultaneous,
    /// One-dimensional Newton steps coordinate by coordinate ("by components").
    Components,
}

impl PointwiseMode {
    /// The command-line name (`simultaneous`, `components`; UNAMALLA's "simultaneous" and
    /// "by components" modes of Newton Point to Point, [González Flores, §A.4.3, §B.5.2]).
    pub fn name(self) -> &'static str {
        match self {
            PointwiseMode::Simultaneous => "simultaneous",
            PointwiseMode::Components => "components",
        }
    }
}

impl FromStr for PointwiseMode {
    type Err = OptimError;
    fn from_str(s: &str) -> Result<Self, OptimError> {
        [PointwiseMode::Simultaneous, PointwiseMode::Components]
            .into_iter()
            .find(|v| v.name() == s)
            .ok_or_else(|| OptimError::UnknownName {
                what: "pointwise mode",
                name: s.to_string(),
                expected: "simultaneous, components",
            })
    }
}

/// How truncated Newton forms Hessian-vector products.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum HessianMode {
    /// Assemble the sparse Hessian once per outer iteration and multiply (fast; memory
    /// `≈ 12 bytes × 18 × 2 × free nodes` in 2D).
    #[default]
    Assembled,
    /// Matrix-free products through [`Hessian::hess_vec`] (no preconditioner is available
    /// then; Jacobi/block-Jacobi still use an assembled diagonal only in `Assembled` mode).
    MatrixFree,
    /// Assembled like `Assembled`, but the drivers of quad functionals hand the solver the
    /// functional with its [`Hessian`] replaced by a [`PsdModel`](crate::psd_model::PsdModel)
    /// ([`WithHessian`](unamalla_functionals::WithHessian)): every corner triangle's leg
    /// Hessian projected onto the PSD cone before assembly (`unamalla_functionals::quad::psd`),
    /// a Gauss–Newton-like model whose CG never meets negative curvature. For any other [`Problem`] this is
    /// `Assembled` (the solver asks the problem for its Hessian). Used by `block_smoothing`
    /// ((6.8)) only. Measured (docs/benchmarks.md, "Large grids"): 8–14× slower than the exact
    /// Hessian on the sinusoidal 100² grid, because `F_AO`'s leg Hessian is indefinite for
    /// every triangle, so the model differs from the Hessian even at the minimum.
    ProjectedPsd,
}

/// Options of one solver run.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct SolverOptions {
    /// The method.
    pub solver: Solver,
    /// MAXITER: outer iterations (pointwise: sweeps).
    pub max_iter: usize,
    /// FTOL: stop when `(F_old − F) ≤ ftol · max(|F_old|, |F|)`.
    pub ftol: f64,
    /// GTOL: stop when `‖g‖ ≤ gtol · ‖g₀‖` (`g₀` = first gradient of the run).
    pub gtol: f64,
    /// Absolute GTOL: stop when `‖g‖ ≤ gtol_abs`.
    pub gtol_abs: f64,
    /// Preconditioner of the inner CG.
    pub preconditioner: Preconditioner,
    /// Hessian products.
    pub hessian: HessianMode,
    /// Maximum inner CG iterations per outer iteration.
    pub cg_max_iter: usize,
    /// Upper bound of the forcing sequence `η_k = min(forcing_max, √(‖g‖/‖g₀‖))`
    /// (inner CG stops at `‖r‖ ≤ η_k‖g‖`).
    pub forcing_max: f64,
    /// L-BFGS memory `m`.
    pub lbfgs_memory: usize,
    /// Pointwise mode.
    pub pointwise_mode: PointwiseMode,
    /// Line-search parameters (TN-LS, L-BFGS).
    pub line_search: LineSearchParams,
    /// Convergence tests over a window of iterations (off by default).
    #[serde(default)]
    pub stop: StopRules,
}

/// Convergence tests over a window of `W` accepted iterations, tested after every accepted
/// iterate once `W` iterations of the run have been made, and only while the iterate is convex
/// (a mesh that is still being untangled is never stopped by them). All off with `window = 0`
/// ([`Default`]).
///
/// With `F_k`, `q_k = α₋/ᾱ` and `s_k` the μ ≥ 0.8 share (percent, from the session's
/// [quality probe](crate::monitor::Session::set_quality)) of iterate `k`:
/// * **window FTOL** ([`StopReason::WindowFtol`]): `F_{k−W} − F_k ≤ window_ftol·|F_k|` — the
///   average relative decrease per iteration fell below `window_ftol/W`. Unlike the one-step
///   FTOL it is not fooled by one short step (a step cut by the safeguard) and it does fire on
///   a long slow crawl, which the one-step test with a small FTOL never does;
/// * **quality plateau** ([`StopReason::Plateau`]): over the last `W + 1` iterates
///   `max q − min q ≤ plateau_alpha·max q` and `max s − min s ≤ plateau_share` — what a user
///   measures no longer changes even if `F` still creeps down along the flat directions of
///   `F_AO` ([Méndez 2023, (6.8)]; the diagonal shear waves of docs/benchmarks.md, "Why 1000² in
///   5 s is out of reach at σ = 0.1"). Needs a quality probe;
///   without one this test is off.
///
/// The projected-gradient test is GTOL ([`SolverOptions::gtol`], [`SolverOptions::gtol_abs`]):
/// the variables are the free nodes only, so the gradient the solvers see is already the
/// gradient projected onto the feasible set (fixed nodes are equality constraints).
/// Iteration caps remain [`SolverOptions::max_iter`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StopRules {
    /// `W`, the window in accepted iterations (0 = every window test off).
    pub window: usize,
    /// Relative decrease of `F` over the window below which the run stops (0 = off).
    pub window_ftol: f64,
    /// Relative spread of `α₋/ᾱ` over the window below which (with `plateau_share`) the run
    /// stops (0 = plateau test off).
    pub plateau_alpha: f64,
    /// Spread of the μ ≥ 0.8 share (percentage points) over the window below which (with
    /// `plateau_alpha`) the run stops.
    pub plateau_share: f64,
}

impl Default for StopRules {
    fn default() -> Self {
        Self {
            window: 0,
            window_ftol: 0.0,
            plateau_alpha: 0.0,
            plateau_share: 0.0,
        }
    }
}

/// Window (accepted iterations) of [`StopRules::polish`].
pub const POLISH_WINDOW: usize = 2;

impl StopRules {
    /// The rules of a *polish* run — one that starts from a solution prolonged from a coarser
    /// level (nested iteration: Brandt 1977, Math. Comp. 31(138) §1; Briggs, Henson & McCormick
    /// 2000, *A Multigrid Tutorial*, ch. 3): the window `W` shortened to `W' =`
    /// [`POLISH_WINDOW`] when it is longer, and every threshold scaled by `W'/W`, so that the
    /// *rates* the tests stand for (relative decrease of `F`, change of `α₋/ᾱ` and of the μ-share
    /// per iteration) are unchanged. The start then carries only the fine-scale error, which
    /// Newton removes in a few iterations, while a window test can fire only after `W + 1`
    /// accepted iterations: with `W = 10` a polish run spends its last seven or more iterations
    /// confirming a plateau it reached at the start. (Shortening the window without scaling the
    /// thresholds loosens them `W/W'` times: measured with `W' = 3`, the μ ≥ 0.8 share of
    /// quintana-roo at 20,000 cells fell from 98.1 to 97.4 %, with scaling to 97.8 % —
    /// `docs/benchmarks.md`.)
    ///
    /// ```
    /// use unamalla_optim::StopRules;
    /// let r = StopRules { window: 10, window_ftol: 1e-4, plateau_alpha: 0.01, plateau_share: 0.05 };
    /// let p = r.polish();
    /// assert_eq!(p.window, 2);
    /// assert!((p.window_ftol - 2e-5).abs() < 1e-18);
    /// assert!((p.plateau_alpha - 2e-3).abs() < 1e-15 && (p.plateau_share - 0.01).abs() < 1e-15);
    /// assert_eq!(StopRules::default().polish(), StopRules::default()); // tests off stay off
    /// let short = StopRules { window: 2, ..r };
    /// assert_eq!(short.polish(), short); // a window already short is kept as it is
    /// ```
    pub fn polish(self) -> Self {
        if self.window <= POLISH_WINDOW {
            return self;
        }
        let k = POLISH_WINDOW as f64 / self.window as f64;
        Self {
            window: POLISH_WINDOW,
            window_ftol: self.window_ftol * k,
            plateau_alpha: self.plateau_alpha * k,
            plateau_share: self.plateau_share * k,
        }
    }

    /// The test that fires on `hist` (the accepted iterates of the run, oldest first, as
    /// `(F, α₋/ᾱ, μ-share)`), if any; see the type docs.
    pub fn check(&self, hist: &[(f64, f64, Option<f64>)]) -> Option<StopReason> {
        let w = self.window;
        if w == 0 || hist.len() <= w {
            return None;
        }
        let win = &hist[hist.len() - 1 - w..];
        let (f_old, f_new) = (win[0].0, win[w].0);
        if self.window_ftol > 0.0 && f_old - f_new <= self.window_ftol * f_new.abs() {
            return Some(StopReason::WindowFtol);
        }
        if self.plateau_alpha > 0.0 {
            let spread = |v: &mut dyn Iterator<Item = f64>| {
                v.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                    (lo.min(x), hi.max(x))
                })
            };
            let (qlo, qhi) = spread(&mut win.iter().map(|h| h.1));
            let shares: Option<Vec<f64>> = win.iter().map(|h| h.2).collect();
            if let Some(sh) = shares {
                let (slo, shi) = spread(&mut sh.into_iter());
                if qhi - qlo <= self.plateau_alpha * qhi.abs() && shi - slo <= self.plateau_share {
                    return Some(StopReason::Plateau);
                }
            }
        }
        None
    }
}

impl Default for SolverOptions {
    fn default() -> Self {
        Self {
            solver: Solver::TnTr,
            max_iter: 200,
            ftol: 1e-10,
            gtol: 1e-6,
            gtol_abs: 0.0,
            preconditioner: Preconditioner::BlockJacobi,
            hessian: HessianMode::Assembled,
            cg_max_iter: 200,
            forcing_max: 0.5,
            lbfgs_memory: 5,
            pointwise_mode: PointwiseMode::Simultaneous,
            line_search: LineSearchParams::default(),
            stop: StopRules::default(),
        }
    }
}

impl SolverOptions {
    /// Default options for `solver`.
    pub fn new(solver: Solver) -> Self {
        Self {
            solver,
            ..Default::default()
        }
    }
    /// Checks the options (tolerances finite and ≥ 0, L-BFGS memory ≥ 1, ...); the solvers call
    /// it first, front ends may call it to report a bad option before any work.
    pub fn validate(&self) -> Result<(), OptimError> {
        let pos = |name, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(OptimError::InvalidOption {
                    name,
                    value: v,
                    reason: "must be finite and ≥ 0",
                })
            }
        };
        pos("ftol", self.ftol)?;
        pos("gtol", self.gtol)?;
        pos("gtol_abs", self.gtol_abs)?;
        pos("forcing_max", self.forcing_max)?;
        pos("stop.window_ftol", self.stop.window_ftol)?;
        pos("stop.plateau_alpha", self.stop.plateau_alpha)?;
        pos("stop.plateau_share", self.stop.plateau_share)?;
        if self.lbfgs_memory == 0 {
            return Err(OptimError::InvalidOption {
                name: "lbfgs_memory",
                value: 0.0,
                reason: "L-BFGS needs m ≥ 1",
            });
        }
        Ok(())
    }

    /// Sets [`solver`](Self::solver): the method.
    #[must_use]
    pub fn solver(mut self, solver: Solver) -> Self {
        self.solver = solver;
        self
    }

    /// Sets [`max_iter`](Self::max_iter): MAXITER: outer iterations (pointwise: sweeps).
    #[must_use]
    pub fn max_iter(mut self, max_iter: usize) -> Self {
        self.max_iter = max_iter;
        self
    }

    /// Sets [`ftol`](Self::ftol): FTOL: stop when `(F_old − F) ≤ ftol · max(|F_old|, |F|)`.
    #[must_use]
    pub fn ftol(mut self, ftol: f64) -> Self {
        self.ftol = ftol;
        self
    }

    /// Sets [`gtol`](Self::gtol): GTOL: stop when `‖g‖ ≤ gtol · ‖g₀‖` (`g₀` = first gradient of the
    /// run).
    #[must_use]
    pub fn gtol(mut self, gtol: f64) -> Self {
        self.gtol = gtol;
        self
    }

    /// Sets [`gtol_abs`](Self::gtol_abs): absolute GTOL: stop when `‖g‖ ≤ gtol_abs`.
    #[must_use]
    pub fn gtol_abs(mut self, gtol_abs: f64) -> Self {
        self.gtol_abs = gtol_abs;
        self
    }

    /// Sets [`preconditioner`](Self::preconditioner): preconditioner of the inner CG.
    #[must_use]
    pub fn preconditioner(mut self, preconditioner: Preconditioner) -> Self {
        self.preconditioner = preconditioner;
        self
    }

    /// Sets [`hessian`](Self::hessian): Hessian products.
    #[must_use]
    pub fn hessian(mut self, hessian: HessianMode) -> Self {
        self.hessian = hessian;
        self
    }

    /// Sets [`cg_max_iter`](Self::cg_max_iter): maximum inner CG iterations per outer iteration.
    #[must_use]
    pub fn cg_max_iter(mut self, cg_max_iter: usize) -> Self {
        self.cg_max_iter = cg_max_iter;
        self
    }

    /// Sets [`forcing_max`](Self::forcing_max).
    #[must_use]
    pub fn forcing_max(mut self, forcing_max: f64) -> Self {
        self.forcing_max = forcing_max;
        self
    }

    /// Sets [`lbfgs_memory`](Self::lbfgs_memory): L-BFGS memory `m`.
    #[must_use]
    pub fn lbfgs_memory(mut self, lbfgs_memory: usize) -> Self {
        self.lbfgs_memory = lbfgs_memory;
        self
    }

    /// Sets [`pointwise_mode`](Self::pointwise_mode): pointwise mode.
    #[must_use]
    pub fn pointwise_mode(mut self, pointwise_mode: PointwiseMode) -> Self {
        self.pointwise_mode = pointwise_mode;
        self
    }

    /// Sets [`line_search`](Self::line_search): line-search parameters (TN-LS, L-BFGS).
    #[must_use]
    pub fn line_search(mut self, line_search: LineSearchParams) -> Self {
        self.line_search = line_search;
        self
    }

    /// Sets [`stop`](Self::stop): convergence tests over a window of iterations (off by default).
    #[must_use]
    pub fn stop(mut self, stop: StopRules) -> Self {
        self.stop = stop;
        self
    }
}

/// The result of one solver run.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SolveResult {
    /// Why it stopped.
    pub reason: StopReason,
    /// Outer iterations (sweeps for pointwise Newton).
    pub iterations: usize,
    /// Final value.
    pub f: f64,
    /// Final gradient norm.
    pub gnorm: f64,
    /// Function(+gradient) evaluations.
    pub fevals: usize,
    /// Inner CG iterations (truncated Newton).
    pub cg_iterations: usize,
    /// Final `α₋` over elements with a free vertex.
    pub alfamin: f64,
    /// Final `ᾱ`.
    pub alpha_bar: f64,
    /// Whether the final point is convex.
    pub convex: bool,
}

/// Local convexity check for pointwise Newton on quad meshes: the corner triangles of the
/// cells around a node, evaluated directly (no global pass).
#[derive(Debug, Clone)]
pub struct QuadLocalGuard {
    topo: Arc<QuadTopology>,
    offsets: Vec<usize>,
    cells: Vec<u32>,
}

impl QuadLocalGuard {
    /// Builds the node → cells incidence of a topology.
    pub fn new(topo: Arc<QuadTopology>) -> Self {
        let n = topo.num_nodes();
        let mut cnt = vec![0usize; n + 1];
        for c in 0..topo.num_cells() {
            for v in topo.cell(c) {
                cnt[v + 1] += 1;
            }
        }
        for i in 0..n {
            cnt[i + 1] += cnt[i];
        }
        let mut fill = cnt.clone();
        let mut cells = vec![0u32; cnt[n]];
        for c in 0..topo.num_cells() {
            for v in topo.cell(c) {
                cells[fill[v]] = c as u32;
                fill[v] += 1;
            }
        }
        Self {
            topo,
            offsets: cnt,
            cells,
        }
    }

    /// Minimum α over the corner triangles that contain `node`, at `x`.
    pub fn node_min_alpha(&self, x: &[f64], node: usize) -> f64 {
        let pt = |v: usize| match self.topo.var_of(v) {
            Some(j) => glam::DVec2::new(x[2 * j], x[2 * j + 1]),
            None => self.topo.coords()[v],
        };
        let mut m = f64::INFINITY;
        for &c in &self.cells[self.offsets[node]..self.offsets[node + 1]] {
            let cell = self.topo.cell(c as usize);
            let Some(i) = cell.iter().position(|&v| v == node) else {
                continue;
            };
            let p = cell.map(pt);
            for k in 0..4 {
                if k == (i + 2) & 3 {
                    continue;
                }
                let a = (p[(k + 1) & 3] - p[k]).perp_dot(p[(k + 3) & 3] - p[k]);
                m = m.min(if a.is_nan() { f64::NEG_INFINITY } else { a });
            }
        }
        m
    }
}

fn check_start<P: Variables + ?Sized>(problem: &P, x: &[f64]) -> Result<(), OptimError> {
    if problem.num_vars() == 0 {
        return Err(OptimError::NoFreeNodes);
    }
    if x.len() != problem.num_vars() {
        return Err(OptimError::InvalidOption {
            name: "x.len()",
            value: x.len() as f64,
            reason: "the starting point must have num_vars entries",
        });
    }
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(OptimError::NonFiniteStart { index: i });
    }
    Ok(())
}

/// Minimizes `problem` from `x` (overwritten with the result) with the method of `opts`,
/// reporting to `session`. Errors only for invalid input (empty problem, non-finite start,
/// non-finite value or gradient at the start, invalid options); non-convergence is a
/// [`StopReason`].
pub fn minimize<P: Problem + ?Sized>(
    problem: &P,
    x: &mut [f64],
    opts: &SolverOptions,
    session: &mut Session<'_>,
) -> Result<SolveResult, OptimError> {
    minimize_with(problem, x, opts, session, None)
}

/// [`minimize`] with an optional local convexity check for pointwise Newton on quad meshes
/// (without it, pointwise Newton checks convexity after each sweep and backtracks the sweep).
pub fn minimize_with<P: Problem + ?Sized>(
    problem: &P,
    x: &mut [f64],
    opts: &SolverOptions,
    session: &mut Session<'_>,
    local_guard: Option<&QuadLocalGuard>,
) -> Result<SolveResult, OptimError> {
    opts.validate()?;
    check_start(problem, x)?;
    let n = x.len();
    let mut g = vec![0.0; n];
    let f = problem.value_grad(x, &mut g);
    if !f.is_finite() || g.iter().any(|v| !v.is_finite()) {
        return Err(OptimError::NonFiniteValue { value: f });
    }
    let mut st = State {
        f,
        gnorm: norm(&g),
        g0norm: 0.0,
        iterations: 0,
        fevals: 1,
        cg: 0,
        cur_min: 0.0,
        alpha_bar: 0.0,
        history: Vec::new(),
    };
    st.g0norm = st.gnorm;
    let c = session.convexity(problem, x);
    st.cur_min = c.min;
    st.alpha_bar = c.mean;
    session.update(c, f, st.gnorm);
    let reason = if session.stop_requested() {
        session.interrupt_reason()
    } else if st.gnorm <= opts.gtol_abs || st.gnorm == 0.0 {
        StopReason::Gtol
    } else {
        match opts.solver {
            Solver::TnTr | Solver::TnLs => {
                truncated_newton(problem, x, &mut g, opts, session, &mut st)
            }
            Solver::Lbfgs => lbfgs(problem, x, &mut g, opts, session, &mut st),
            Solver::Pointwise => pointwise(problem, x, &mut g, opts, session, &mut st, local_guard),
            Solver::NcgFr => ncg_fr(problem, x, &mut g, opts, session, &mut st),
        }
    };
    // a run without an accepted step never reached the observer: let it see the run (time
    // budgets must be able to stop drivers that call the solver repeatedly)
    let reason = if st.iterations == 0 && !reason.interrupted() {
        if session.heartbeat() == Control::Stop {
            session.interrupt_reason()
        } else {
            reason
        }
    } else {
        reason
    };
    Ok(SolveResult {
        reason,
        iterations: st.iterations,
        f: st.f,
        gnorm: st.gnorm,
        fevals: st.fevals,
        cg_iterations: st.cg,
        alfamin: st.cur_min,
        alpha_bar: st.alpha_bar,
        convex: st.cur_min > 0.0,
    })
}

struct State {
    f: f64,
    gnorm: f64,
    g0norm: f64,
    iterations: usize,
    fevals: usize,
    cg: usize,
    cur_min: f64,
    alpha_bar: f64,
    /// `(F, α₋/ᾱ, μ-share)` of the accepted iterates (only with [`StopRules`] on).
    history: Vec<(f64, f64, Option<f64>)>,
}

impl State {
    /// Records an accepted iterate; returns a stop reason if a test fires.
    #[allow(clippy::too_many_arguments)]
    fn accept<P: ElementMeasures + ?Sized>(
        &mut self,
        problem: &P,
        x: &[f64],
        f_new: f64,
        gnorm: f64,
        opts: &SolverOptions,
        session: &mut Session<'_>,
        truncated: bool,
    ) -> Option<StopReason> {
        let f_old = self.f;
        self.f = f_new;
        self.gnorm = gnorm;
        self.iterations += 1;
        let (ctl, c) = session.iterate(problem, x, f_new, gnorm);
        self.cur_min = c.min;
        self.alpha_bar = c.mean;
        if ctl == Control::Stop {
            return Some(session.interrupt_reason());
        }
        if gnorm <= opts.gtol * self.g0norm || gnorm <= opts.gtol_abs {
            return Some(StopReason::Gtol);
        }
        // FTOL is not tested after a step cut short by the safeguard (a small decrease there
        // says nothing about optimality)
        if !truncated && (f_old - f_new) <= opts.ftol * f_old.abs().max(f_new.abs()) {
            return Some(StopReason::Ftol);
        }
        if opts.stop.window > 0 {
            if c.nonconvex_cells > 0 {
                // the window tests apply to convex iterates only
                self.history.clear();
            } else {
                let share = if opts.stop.plateau_alpha > 0.0 {
                    session.quality(x)
                } else {
                    None
                };
                self.history.push((f_new, c.min / c.mean, share));
                if let Some(r) = opts.stop.check(&self.history) {
                    return Some(r);
                }
                if self.history.len() > 4 * opts.stop.window {
                    self.history
                        .drain(..self.history.len() - opts.stop.window - 1);
                }
            }
        }
        if self.iterations >= opts.max_iter {
            return Some(StopReason::MaxIter);
        }
        None
    }
}

/// Elements that would reach the safeguard's threshold before this multiple of a full step
/// hold their nodes back ([`Session::hold_back`]): after a full step each remaining element
/// keeps about half of its distance to the threshold.
const HOLD_BACK_REACH: f64 = 2.0;

struct CgWork {
    r: Vec<f64>,
    y: Vec<f64>,
    d: Vec<f64>,
    hd: Vec<f64>,
    hz: Vec<f64>,
    z: Vec<f64>,
}

struct CgOut {
    gz: f64,
    zhz: f64,
    iters: usize,
    boundary: bool,
    pred: f64,
    znorm_m: f64,
}

/// Preconditioned Steihaug–Toint CG on `H z = −g` inside `‖z‖_M ≤ radius` (radius may be
/// infinite: plain truncated CG with a negative-curvature exit).
fn steihaug(
    hv: &dyn Fn(&[f64], &mut [f64]),
    g: &[f64],
    pre: &dyn Fn(&[f64], &mut [f64]),
    radius: f64,
    tol: f64,
    maxit: usize,
    w: &mut CgWork,
) -> CgOut {
    let CgWork { r, y, d, hd, hz, z } = w;
    z.iter_mut().for_each(|v| *v = 0.0);
    hz.iter_mut().for_each(|v| *v = 0.0);
    r.copy_from_slice(g);
    pre(r, y);
    d.iter_mut().zip(y.iter()).for_each(|(d, y)| *d = -y);
    let mut ry = dot(r, y);
    let (mut zmz, mut zmd, mut dmd) = (0.0, 0.0, ry);
    let mut out = CgOut {
        gz: 0.0,
        zhz: 0.0,
        iters: 0,
        boundary: false,
        pred: 0.0,
        znorm_m: 0.0,
    };
    let to_boundary = |zmz: f64, zmd: f64, dmd: f64| {
        let disc = (zmd * zmd + dmd * (radius * radius - zmz)).max(0.0);
        (-zmd + disc.sqrt()) / dmd
    };
    for it in 0..maxit.max(1) {
        hv(d, hd);
        let kappa = dot(d, hd);
        if kappa.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || !kappa.is_finite() {
            // negative curvature (or breakdown)
            if radius.is_finite() {
                let tau = to_boundary(zmz, zmd, dmd);
                axpy(tau, d, z);
                axpy(tau, hd, hz);
                out.boundary = true;
            } else if it == 0 {
                z.copy_from_slice(d);
                hz.copy_from_slice(hd);
            }
            out.iters = it + 1;
            break;
        }
        let a = ry / kappa;
        let zmz_new = zmz + 2.0 * a * zmd + a * a * dmd;
        if radius.is_finite() && zmz_new >= radius * radius {
            let tau = to_boundary(zmz, zmd, dmd);
            axpy(tau, d, z);
            axpy(tau, hd, hz);
            out.boundary = true;
            out.iters = it + 1;
            break;
        }
        axpy(a, d, z);
        axpy(a, hd, hz);
        zmz = zmz_new;
        axpy(a, hd, r);
        out.iters = it + 1;
        if norm(r) <= tol {
            break;
        }
        pre(r, y);
        let ry_new = dot(r, y);
        if ry_new.is_nan() || ry_new <= 0.0 || !ry_new.is_finite() {
            // the preconditioner is not positive definite on this residual (possible only for
            // an indefinite Hessian): keep the current iterate
            break;
        }
        let beta = ry_new / ry;
        ry = ry_new;
        zmd = beta * (zmd + a * dmd);
        dmd = ry + beta * beta * dmd;
        // d ← −y + β d
        y.iter_mut().for_each(|v| *v = -*v);
        scale_add(beta, d, y);
        y.iter_mut().for_each(|v| *v = -*v);
    }
    out.gz = dot(g, z);
    out.zhz = dot(z, hz);
    out.pred = -(out.gz + 0.5 * out.zhz);
    out.znorm_m = zmz.max(0.0).sqrt();
    if out.boundary {
        out.znorm_m = radius;
    }
    out
}

fn ensure_hessian<P: Variables + Hessian + ?Sized>(problem: &P, session: &mut Session<'_>) {
    let ok = matches!(&session.hess, Some(h) if h.nrows == problem.num_vars());
    if !ok {
        session.hess = Some(problem.hessian_pattern());
    }
}

fn truncated_newton<P: Variables + Gradient + Hessian + ElementMeasures + ?Sized>(
    problem: &P,
    x: &mut [f64],
    g: &mut [f64],
    opts: &SolverOptions,
    session: &mut Session<'_>,
    st: &mut State,
) -> StopReason {
    let n = x.len();
    let trust = opts.solver == Solver::TnTr;
    let assembled = opts.hessian != HessianMode::MatrixFree;
    if assembled {
        ensure_hessian(problem, session);
    }
    let mut h: Csr = if assembled {
        session
            .hess
            .take()
            .unwrap_or_else(|| problem.hessian_pattern())
    } else {
        Csr {
            nrows: 0,
            ncols: 0,
            row_offsets: vec![0],
            col_indices: Vec::new(),
            values: Vec::new(),
        }
    };
    let mut pre = PrecondApply::default();
    let mut w = CgWork {
        r: vec![0.0; n],
        y: vec![0.0; n],
        d: vec![0.0; n],
        hd: vec![0.0; n],
        hz: vec![0.0; n],
        z: vec![0.0; n],
    };
    // the held-back step (see `Session::hold_back`; trust region only)
    let mut z2 = vec![0.0; if trust { n } else { 0 }];
    let mut xt = vec![0.0; n];
    let mut gt = vec![0.0; n];
    let mut radius = f64::INFINITY;
    // CG iterations of the last outer iteration, and of the first one after the last
    // multigrid rebuild
    let mut cg_last = 0usize;
    let mut mg_built_cg: Option<usize> = None;
    let reason = 'outer: loop {
        let cg_before = st.cg;
        if assembled {
            problem.hessian(x, &mut h);
            // multigrid: the coarse levels are rebuilt only when CG needed clearly more
            // iterations than right after the last rebuild (lagged hierarchy)
            let rebuild = mg_built_cg.is_none_or(|c0| cg_last > (2 * c0).max(12));
            pre.update(opts.preconditioner, &h, problem.dim(), rebuild);
            if rebuild {
                mg_built_cg = None;
            }
        } else {
            pre.build(Preconditioner::None, &h, problem.dim());
        }
        let eta = opts.forcing_max.min((st.gnorm / st.g0norm).sqrt());
        let tol = eta * st.gnorm;
        let xr: &[f64] = x;
        let hv = |v: &[f64], out: &mut [f64]| {
            if assembled {
                h.mul_vec(v, out)
            } else {
                problem.hess_vec(xr, v, out)
            }
        };
        let hr: &Csr = &h;
        let prec = |v: &[f64], out: &mut [f64]| pre.apply_with(hr, v, out);
        let guard = session.guard_active(st.cur_min);
        let f_acc;
        let mut truncated;
        if trust {
            loop {
                truncated = false;
                let mut o = steihaug(&hv, g, &prec, radius, tol, opts.cg_max_iter, &mut w);
                st.cg += o.iters;
                if radius.is_infinite() {
                    radius = o.znorm_m.max(f64::MIN_POSITIVE);
                }
                if guard {
                    // fraction to the boundary of the admissible set
                    // (only `min(tm, 1)` is used below)
                    let mut tm = session.max_step_within(problem, xr, &w.z, 1.0);
                    if tm < 1.0 {
                        // hold back the nodes of the blocking cells instead (so that one cell
                        // at the threshold does not stall the whole mesh, nor creep towards
                        // the threshold step by step); the shortened full step only when the
                        // held-back step does not decrease the model
                        z2.copy_from_slice(&w.z);
                        let tm2 = session.hold_back(problem, xr, &mut z2, HOLD_BACK_REACH);
                        if tm2 > tm {
                            hv(&z2, &mut w.hd);
                            let (gz2, zhz2) = (dot(g, &z2), dot(&z2, &w.hd));
                            let tau2 = if tm2 < 1.0 { 0.9 * tm2 } else { 1.0 };
                            let tau = 0.9 * tm;
                            let pred2 = -(tau2 * gz2 + 0.5 * tau2 * tau2 * zhz2);
                            let pred1 = -(tau * o.gz + 0.5 * tau * tau * o.zhz);
                            if pred2 > pred1 && pred2 > 0.0 {
                                let ratio = norm(&z2) / norm(&w.z).max(f64::MIN_POSITIVE);
                                w.z.copy_from_slice(&z2);
                                o.gz = gz2;
                                o.zhz = zhz2;
                                o.pred = -(gz2 + 0.5 * zhz2);
                                o.znorm_m *= ratio;
                                tm = tm2;
                            }
                        }
                    }
                    if tm < 1.0 {
                        let tau = 0.9 * tm;
                        w.z.iter_mut().for_each(|v| *v *= tau);
                        o.pred = -(tau * o.gz + 0.5 * tau * tau * o.zhz);
                        o.znorm_m *= tau;
                        o.boundary = false;
                        // the next model step stays in the smaller ball, bending away from
                        // the boundary of the admissible set
                        radius = radius.min(o.znorm_m);
                        truncated = true;
                    }
                }
                add_scaled(xr, 1.0, &w.z, &mut xt);
                let ok = !guard || session.admissible(problem, &xt);
                let ft = if ok {
                    st.fevals += 1;
                    problem.value_grad(&xt, &mut gt)
                } else {
                    f64::NAN
                };
                let rho = if ft.is_finite() && o.pred > 0.0 {
                    (st.f - ft) / o.pred
                } else if ft.is_finite() && o.pred <= 0.0 && ft < st.f {
                    1.0
                } else {
                    f64::NEG_INFINITY
                };
                if rho < 0.25 {
                    radius = 0.25 * o.znorm_m.min(radius);
                } else if rho > 0.75 && o.boundary {
                    radius *= 2.0;
                }
                if rho > 1e-4 && gt.iter().all(|v| v.is_finite()) {
                    f_acc = ft;
                    break;
                }
                let xs = norm(xr).max(1.0);
                if radius <= 1e-15 * xs || o.znorm_m == 0.0 {
                    break 'outer StopReason::TrustRadius;
                }
            }
        } else {
            let o = steihaug(&hv, g, &prec, f64::INFINITY, tol, opts.cg_max_iter, &mut w);
            st.cg += o.iters;
            let mut gd = dot(g, &w.z);
            if gd.partial_cmp(&0.0) != Some(std::cmp::Ordering::Less) {
                pre.apply(g, &mut w.z);
                w.z.iter_mut().for_each(|v| *v = -*v);
                gd = dot(g, &w.z);
            }
            let search = guarded_line_search(
                problem,
                xr,
                &w.z,
                gd,
                1.0,
                guard,
                &opts.line_search,
                session,
                st,
                (&mut xt, &mut gt),
            );
            let r = match search {
                Ok((r, cut)) => {
                    truncated = cut;
                    r
                }
                Err(reason) => break 'outer reason,
            };
            f_acc = r.f;
        }
        cg_last = st.cg - cg_before;
        if mg_built_cg.is_none() {
            mg_built_cg = Some(cg_last);
        }
        x.copy_from_slice(&xt);
        g.copy_from_slice(&gt);
        let gn = norm(g);
        if let Some(r) = st.accept(problem, x, f_acc, gn, opts, session, truncated) {
            break r;
        }
    };
    if assembled {
        session.hess = Some(h);
    }
    reason
}

fn lbfgs<P: Variables + Gradient + ElementMeasures + ?Sized>(
    problem: &P,
    x: &mut [f64],
    g: &mut [f64],
    opts: &SolverOptions,
    session: &mut Session<'_>,
    st: &mut State,
) -> StopReason {
    let n = x.len();
    let m = opts.lbfgs_memory;
    let mut s_hist: Vec<Vec<f64>> = Vec::with_capacity(m);
    let mut y_hist: Vec<Vec<f64>> = Vec::with_capacity(m);
    let mut rho: Vec<f64> = Vec::with_capacity(m);
    let mut alpha = vec![0.0; m];
    let mut d = vec![0.0; n];
    let mut xt = vec![0.0; n];
    let mut gt = vec![0.0; n];
    let mut head = 0usize; // index of the oldest pair when full
    loop {
        // two-loop recursion
        d.iter_mut().zip(g.iter()).for_each(|(d, g)| *d = -g);
        let k = s_hist.len();
        let order: Vec<usize> = (0..k).map(|i| (head + i) % k.max(1)).collect();
        for &i in order.iter().rev() {
            let a = rho[i] * dot(&s_hist[i], &d);
            alpha[i] = a;
            axpy(-a, &y_hist[i], &mut d);
        }
        let stp0 = if k > 0 {
            let newest = *order.last().unwrap_or(&0);
            let gamma =
                dot(&s_hist[newest], &y_hist[newest]) / dot(&y_hist[newest], &y_hist[newest]);
            d.iter_mut().for_each(|v| *v *= gamma);
            1.0
        } else {
            1.0 / st.gnorm
        };
        for &i in &order {
            let b = rho[i] * dot(&y_hist[i], &d);
            axpy(alpha[i] - b, &s_hist[i], &mut d);
        }
        let mut gd = dot(g, &d);
        if gd.partial_cmp(&0.0) != Some(std::cmp::Ordering::Less) {
            d.iter_mut()
                .zip(g.iter())
                .for_each(|(d, g)| *d = -g / st.gnorm);
            gd = dot(g, &d);
            s_hist.clear();
            y_hist.clear();
            rho.clear();
            head = 0;
        }
        let guard = session.guard_active(st.cur_min);
        let (r, truncated) = match guarded_line_search(
            problem,
            x,
            &d,
            gd,
            stp0,
            guard,
            &opts.line_search,
            session,
            st,
            (&mut xt, &mut gt),
        ) {
            Ok(found) => found,
            Err(reason) => return reason,
        };
        // new pair
        let mut s = vec![0.0; n];
        add_scaled(&xt, -1.0, x, &mut s);
        let mut y = vec![0.0; n];
        add_scaled(&gt, -1.0, g, &mut y);
        let sy = dot(&s, &y);
        if sy > 1e-12 * norm(&s) * norm(&y) {
            if s_hist.len() < m {
                s_hist.push(s);
                y_hist.push(y);
                rho.push(1.0 / sy);
            } else {
                s_hist[head] = s;
                y_hist[head] = y;
                rho[head] = 1.0 / sy;
                head = (head + 1) % m;
            }
        }
        x.copy_from_slice(&xt);
        g.copy_from_slice(&gt);
        let gn = norm(g);
        if let Some(reason) = st.accept(problem, x, r.f, gn, opts, session, truncated) {
            return reason;
        }
    }
}

/// One Moré–Thuente line search along `d` from `x` under the convexity guard (the search of
/// the line-search solvers: truncated Newton with a line search, L-BFGS, NCG). With the guard
/// active (`guard`, from [`Session::guard_active`]) the step is capped at 0.95 of the largest
/// step that keeps every element admissible and a trial point that is not admissible counts as
/// infeasible. `trial` (point, gradient) receives the last trial, the accepted one on success.
/// Returns the search's result and whether the cap was below the first trial step `stp0`, or
/// the stop reason when no step was accepted.
#[allow(clippy::too_many_arguments)]
fn guarded_line_search<P: Variables + Gradient + ElementMeasures + ?Sized>(
    problem: &P,
    x: &[f64],
    d: &[f64],
    gd: f64,
    stp0: f64,
    guard: bool,
    params: &LineSearchParams,
    session: &mut Session<'_>,
    st: &mut State,
    trial: (&mut [f64], &mut [f64]),
) -> Result<(LineSearchResult, bool), StopReason> {
    let (xt, gt) = trial;
    let smax = if guard {
        0.95 * session.max_step(problem, x, d)
    } else {
        f64::INFINITY
    };
    let truncated = smax < stp0;
    let lsp = LineSearchParams {
        stpmax: params.stpmax.min(smax),
        ..*params
    };
    let mut fe = 0;
    let r = more_thuente(
        |t| {
            fe += 1;
            add_scaled(x, t, d, xt);
            if guard && !session.admissible(problem, xt) {
                return None;
            }
            let f = problem.value_grad(xt, gt);
            Some((f, dot(gt, d)))
        },
        st.f,
        gd,
        stp0.min(lsp.stpmax),
        &lsp,
    );
    st.fevals += fe;
    if r.stp == 0.0 {
        return Err(StopReason::LineSearch(
            r.warning.unwrap_or(LineSearchFailure::Rounding),
        ));
    }
    Ok((r, truncated))
}

/// Curvature constant of the strong-Wolfe line search of [`Solver::NcgFr`] (at most this; the
/// Fletcher–Reeves directions are descent directions for any constant below ½).
const NCG_WOLFE_GTOL: f64 = 0.1;

/// Fletcher–Reeves nonlinear CG ([`Solver::NcgFr`]). The first trial step is `1/‖g‖` after a
/// restart and otherwise `t_{k−1}·(g_{k−1}·d_{k−1})/(g_k·d_k)` (Nocedal & Wright 2006, (3.60)).
fn ncg_fr<P: Variables + Gradient + ElementMeasures + ?Sized>(
    problem: &P,
    x: &mut [f64],
    g: &mut [f64],
    opts: &SolverOptions,
    session: &mut Session<'_>,
    st: &mut State,
) -> StopReason {
    let n = x.len();
    let mut d: Vec<f64> = g.iter().map(|v| -v).collect();
    let mut xt = vec![0.0; n];
    let mut gt = vec![0.0; n];
    // previous accepted step and slope (for the initial trial step), and the iterations since
    // the last restart
    let mut prev: Option<(f64, f64)> = None;
    let mut since_restart = 0usize;
    loop {
        let mut gd = dot(g, &d);
        if since_restart >= n.max(1) || gd.partial_cmp(&0.0) != Some(std::cmp::Ordering::Less) {
            d.iter_mut().zip(g.iter()).for_each(|(d, g)| *d = -g);
            gd = dot(g, &d);
            prev = None;
            since_restart = 0;
        }
        let stp0 = match prev {
            Some((t, slope)) => (t * slope / gd).clamp(f64::MIN_POSITIVE, 1e20),
            None => 1.0 / st.gnorm,
        };
        let guard = session.guard_active(st.cur_min);
        let wolfe = LineSearchParams {
            gtol: opts.line_search.gtol.min(NCG_WOLFE_GTOL),
            ..opts.line_search
        };
        let (r, truncated) = match guarded_line_search(
            problem,
            x,
            &d,
            gd,
            stp0,
            guard,
            &wolfe,
            session,
            st,
            (&mut xt, &mut gt),
        ) {
            Ok(found) => found,
            Err(reason) => return reason,
        };
        let g_old2 = dot(g, g);
        x.copy_from_slice(&xt);
        g.copy_from_slice(&gt);
        let beta = dot(g, g) / g_old2;
        d.iter_mut()
            .zip(g.iter())
            .for_each(|(d, g)| *d = -g + beta * *d);
        prev = Some((r.stp, gd));
        since_restart += 1;
        let gn = norm(g);
        if let Some(reason) = st.accept(problem, x, r.f, gn, opts, session, truncated) {
            return reason;
        }
    }
}

/// Greedy node colouring of the free-node adjacency (nodes sharing a cell get different
/// colours), from the Hessian pattern.
fn node_colors(h: &Csr, dim: usize) -> Vec<Vec<usize>> {
    let nb = h.nrows / dim;
    let mut color = vec![usize::MAX; nb];
    let mut classes: Vec<Vec<usize>> = Vec::new();
    let mut used: Vec<bool> = Vec::new();
    for v in 0..nb {
        used.iter_mut().for_each(|u| *u = false);
        let r = v * dim;
        for k in h.row_offsets[r]..h.row_offsets[r + 1] {
            let u = h.col_indices[k] as usize / dim;
            if color[u] != usize::MAX {
                used[color[u]] = true;
            }
        }
        let c = used.iter().position(|u| !u).unwrap_or(used.len());
        if c == classes.len() {
            classes.push(Vec::new());
            used.push(false);
        }
        color[v] = c;
        classes[c].push(v);
    }
    classes
}

/// Local Newton step of one node (`comp = None`: simultaneous; `Some(c)`: coordinate `c`).
fn local_step(m: &unamalla_functionals::LocalModel, comp: Option<usize>) -> [f64; 3] {
    let dim = m.dim;
    let mut d = [0.0; 3];
    if let Some(c) = comp {
        let hcc = m.hess[c][c];
        d[c] = if hcc > 0.0 {
            -m.grad[c] / hcc
        } else {
            let s = (0..dim)
                .map(|i| m.hess[i][i].abs())
                .fold(0.0, f64::max)
                .max(f64::MIN_POSITIVE);
            -m.grad[c] / s
        };
        return d;
    }
    let ok = if dim == 2 {
        let (p, q, r) = (
            m.hess[0][0],
            0.5 * (m.hess[0][1] + m.hess[1][0]),
            m.hess[1][1],
        );
        let det = p * r - q * q;
        if p > 0.0 && det > 1e-14 * p * r {
            d[0] = -(r * m.grad[0] - q * m.grad[1]) / det;
            d[1] = -(-q * m.grad[0] + p * m.grad[1]) / det;
            true
        } else {
            false
        }
    } else if let Some(inv) = inv3_spd(&m.hess) {
        for a in 0..3 {
            d[a] = -(0..3).map(|b| inv[a][b] * m.grad[b]).sum::<f64>();
        }
        true
    } else {
        false
    };
    if !ok {
        // indefinite local Hessian: gradient step scaled by the largest diagonal entry
        let s = (0..dim)
            .map(|i| m.hess[i][i].abs())
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        for (da, ga) in d.iter_mut().zip(&m.grad).take(dim) {
            *da = -ga / s;
        }
    }
    d
}

fn pointwise<P>(
    problem: &P,
    x: &mut [f64],
    g: &mut [f64],
    opts: &SolverOptions,
    session: &mut Session<'_>,
    st: &mut State,
    local_guard: Option<&QuadLocalGuard>,
) -> StopReason
where
    P: Variables + Gradient + Hessian + PointwiseModel + ElementMeasures + ?Sized,
{
    let dim = problem.dim();
    let ok = matches!(&session.colors, Some(c) if c.iter().map(Vec::len).sum::<usize>() * dim == problem.num_vars());
    if !ok {
        ensure_hessian(problem, session);
        let classes = match session.hess.as_ref() {
            Some(h) => node_colors(h, dim),
            None => node_colors(&problem.hessian_pattern(), dim),
        };
        session.colors = Some(classes);
    }
    let colors = session.colors.take().unwrap_or_default();
    let free = problem.free_nodes().to_vec();
    let mut x0 = vec![0.0; x.len()];
    let comps: Vec<Option<usize>> = match opts.pointwise_mode {
        PointwiseMode::Simultaneous => vec![None],
        PointwiseMode::Components => (0..dim).map(Some).collect(),
    };
    struct Prop {
        v: usize,
        d: [f64; 3],
        old: [f64; 3],
        val: f64,
        gd: f64,
        t: f64,
        done: bool,
    }
    let reason = loop {
        let guard = session.guard_active(st.cur_min);
        let thr = session.threshold();
        x0.copy_from_slice(x);
        for class in &colors {
            for &comp in &comps {
                let xr: &[f64] = x;
                let mut props: Vec<Prop> = class
                    .par_iter()
                    .with_min_len(256)
                    .filter_map(|&v| {
                        let m = problem.local(xr, free[v])?;
                        let d = local_step(&m, comp);
                        let gd: f64 = (0..dim).map(|a| m.grad[a] * d[a]).sum();
                        if gd.partial_cmp(&0.0) != Some(std::cmp::Ordering::Less) || !gd.is_finite()
                        {
                            return None;
                        }
                        let mut old = [0.0; 3];
                        old[..dim].copy_from_slice(&xr[dim * v..dim * v + dim]);
                        // the same value-only evaluation as the trials below
                        let val = problem.local_value(xr, free[v]).unwrap_or(m.value);
                        Some(Prop {
                            v,
                            d,
                            old,
                            val,
                            gd,
                            t: 1.0,
                            done: false,
                        })
                    })
                    .collect();
                for _ in 0..8 {
                    for p in props.iter().filter(|p| !p.done) {
                        for a in 0..dim {
                            x[dim * p.v + a] = p.old[a] + p.t * p.d[a];
                        }
                    }
                    let xr: &[f64] = x;
                    props
                        .par_iter_mut()
                        .with_min_len(256)
                        .filter(|p| !p.done)
                        .for_each(|p| {
                            let node = free[p.v];
                            let acc = problem
                                .local_value(xr, node)
                                .is_some_and(|v| v.is_finite() && v <= p.val + 1e-4 * p.t * p.gd)
                                && (!guard
                                    || local_guard
                                        .is_none_or(|lg| lg.node_min_alpha(xr, node) > thr));
                            if acc {
                                p.done = true;
                            } else {
                                p.t *= 0.5;
                            }
                        });
                    if props.iter().all(|p| p.done) {
                        break;
                    }
                }
                for p in props.iter().filter(|p| !p.done) {
                    x[dim * p.v..dim * p.v + dim].copy_from_slice(&p.old[..dim]);
                }
            }
        }
        if guard && local_guard.is_none() && !session.admissible(problem, x) {
            // sweep-level safeguard: backtrack along the sweep displacement
            let xs = x.to_vec();
            let mut t = 0.5;
            let mut found = false;
            for _ in 0..40 {
                for i in 0..x.len() {
                    x[i] = x0[i] + t * (xs[i] - x0[i]);
                }
                if session.admissible(problem, x) {
                    found = true;
                    break;
                }
                t *= 0.5;
            }
            if !found {
                x.copy_from_slice(&x0);
                break StopReason::LineSearch(LineSearchFailure::Rounding);
            }
        }
        let f_new = problem.value_grad(x, g);
        st.fevals += 1;
        let gn = norm(g);
        if let Some(r) = st.accept(problem, x, f_new, gn, opts, session, false) {
            break r;
        }
    };
    session.colors = Some(colors);
    reason
}
