//! The choices of a solver run: the method ([`Solver`]), the pointwise and Hessian modes, the
//! [`SolverOptions`] and the [`StopRules`].

use std::str::FromStr;

#[cfg(doc)]
use unamalla_functionals::{Hessian, Problem};

use crate::error::OptimError;
use crate::linalg::Preconditioner;
use crate::linesearch::LineSearchParams;
use crate::status::StopReason;

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
/// * **quality plateau** ([`StopReason::Plateau`]): over the last `P + 1` iterates (`P` =
///   [`plateau_window`](Self::plateau_window), `W` when 0)
///   `max q − min q ≤ plateau_alpha·max q` and `max s − min s ≤ plateau_share` — what a user
///   measures no longer changes even if `F` still creeps down along the flat directions of
///   `F_AO` ([Méndez 2023, (6.8)]; the diagonal shear waves of docs/benchmarks.md, "Why 1000² in
///   5 s is out of reach at σ = 0.1"). Needs a quality probe;
///   without one this test is off.
///
/// **Neither test fires while the trust region regrows** ([`StopRules::regrowing`]): when the
/// last two per-iteration decreases of `F` each grew by at least [`REGROWTH_FACTOR`],
/// `d_k ≥ 1.5·d_{k−1} ≥ 1.5²·d_{k−2} > 0` with `d_i = F_{i−1} − F_i`. Why: when the
/// fraction-to-the-boundary safeguard cuts a trust-region step (a cell reaching the ε floor of
/// α₋/ᾱ), the radius shrinks to the cut step, which can be 10⁻⁵ of the radius before, and then
/// doubles after each successful step; while it regrows the steps are tiny, `d` doubles from
/// one iteration to the next and neither `F` nor the share moves — and a window of 10
/// iterations fits inside such a stretch (17 iterations for a cut from 1.39 to 8·10⁻⁶ in the
/// gulf-of-mexico run at 20,000 cells). The small changes there are the radius's doing, not
/// convergence: with the plateau firing in them (measured with `smooth_study` at 20,000 cells,
/// docs/benchmarks.md, "Default smoothing against the converged optimum"), tyrrhenian-sea
/// (its untangling patches run as in the converged run) ended at 96.20 % μ ≥ 0.8 against
/// 96.74 % for the run to convergence, and gulf-of-mexico (patches as before) at 92.74 % where
/// the guard lets it go on to 94.23 % (96.80 and 94.75 % with all of today's rules; 95.05 %
/// converged). In a creep along flat directions, which the tests are
/// there to end, `d` is steady or falling, so two growths in a row by half again are rare, and
/// each only puts a stop off by an iteration.
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
    /// Relative spread of `α₋/ᾱ` over the plateau window below which (with `plateau_share`)
    /// the run stops (0 = plateau test off).
    pub plateau_alpha: f64,
    /// Spread of the μ ≥ 0.8 share (percentage points) over the plateau window below which
    /// (with `plateau_alpha`) the run stops.
    pub plateau_share: f64,
    /// `P`, the window of the quality plateau in accepted iterations (0 = `window`). Kept
    /// by [`StopRules::polish`], which shortens only the window of `F`.
    #[serde(default)]
    pub plateau_window: usize,
}

impl Default for StopRules {
    fn default() -> Self {
        Self {
            window: 0,
            window_ftol: 0.0,
            plateau_alpha: 0.0,
            plateau_share: 0.0,
            plateau_window: 0,
        }
    }
}

/// Window (accepted iterations) of the window FTOL of [`StopRules::polish`].
pub const POLISH_WINDOW: usize = 2;

/// Growth factor of the per-iteration decrease of `F` that [`StopRules::regrowing`] reads as a
/// trust region regrowing (the radius doubles after each successful step on its boundary, so
/// the decrease doubles: 1.5 lies halfway between a steady creep, 1, and the regrowth, 2).
pub const REGROWTH_FACTOR: f64 = 1.5;

impl StopRules {
    /// The rules of a *polish* run — one that starts from a solution prolonged from a coarser
    /// level (nested iteration: Brandt 1977, Math. Comp. 31(138) §1; Briggs, Henson & McCormick
    /// 2000, *A Multigrid Tutorial*, ch. 3): the window FTOL's window `W` shortened to `W' =`
    /// [`POLISH_WINDOW`] when it is longer, and its threshold scaled by `W'/W`, so that the
    /// *rate* it stands for (relative decrease of `F` per iteration) is unchanged. The start
    /// then carries only the fine-scale error, which Newton removes in a few iterations, while
    /// a window test can fire only after `W + 1` accepted iterations: with `W = 10` a polish run
    /// spends its last seven or more iterations confirming what it reached at the start.
    /// (Shortening the window without scaling the threshold loosens it `W/W'` times: measured
    /// with `W' = 3`, the μ ≥ 0.8 share of quintana-roo at 20,000 cells fell from 98.1 to
    /// 97.4 %, with scaling to 97.8 % — `docs/benchmarks.md`.)
    ///
    /// The quality plateau keeps its window and thresholds (`plateau_window` is set to the
    /// plateau window of `self`): `F` is smooth, so its rate can be read over two iterations,
    /// but the μ ≥ 0.8 share counts cells crossing a threshold and moves by single cells back
    /// and forth (0.005 points each at 20,000 cells), so a spread over three iterates against
    /// the scaled 0.01 points (two cells) fires on chance agreement while the share still rises
    /// by about that much per iteration. Measured (`smooth_study` at 20,000 cells, 34 regions):
    /// with the scaled plateau quintana-roo stopped at 98.46 % against 98.91 % converged, with
    /// the plateau kept 98.67 % (its polish run then ends on the window FTOL).
    ///
    /// ```
    /// use unamalla_optim::StopRules;
    /// let r = StopRules {
    ///     window: 10,
    ///     window_ftol: 1e-4,
    ///     plateau_alpha: 0.01,
    ///     plateau_share: 0.05,
    ///     plateau_window: 0,
    /// };
    /// let p = r.polish();
    /// assert_eq!(p.window, 2);
    /// assert!((p.window_ftol - 2e-5).abs() < 1e-18);
    /// // the plateau keeps its window and thresholds
    /// assert_eq!(p.plateau_window, 10);
    /// assert_eq!((p.plateau_alpha, p.plateau_share), (0.01, 0.05));
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
            plateau_window: self.plateau_len(),
            ..self
        }
    }

    /// `P`, the window of the quality plateau ([`plateau_window`](Self::plateau_window), or
    /// `window` when that is 0).
    pub fn plateau_len(&self) -> usize {
        if self.plateau_window == 0 {
            self.window
        } else {
            self.plateau_window
        }
    }

    /// How many of the latest accepted iterates [`check`](Self::check) reads (the longer
    /// window plus one, and at least the four of [`regrowing`](Self::regrowing)); a caller may
    /// drop older ones.
    pub fn history_len(&self) -> usize {
        self.window.max(self.plateau_len()).max(3) + 1
    }

    /// Whether `F`'s last two per-iteration decreases on `hist` (oldest first, as for
    /// [`check`](Self::check)) each grew by at least [`REGROWTH_FACTOR`]:
    /// `d_k ≥ 1.5·d_{k−1}`, `d_{k−1} ≥ 1.5·d_{k−2}`, `d_{k−2} > 0`, `d_i = F_{i−1} − F_i` —
    /// a trust region regrowing after a step cut by the safeguard (see the type docs). False
    /// with fewer than four iterates.
    ///
    /// ```
    /// use unamalla_optim::StopRules;
    /// let h = |f: &[f64]| f.iter().map(|&f| (f, 0.01, Some(90.0))).collect::<Vec<_>>();
    /// // decreases 1e-6, 2e-6, 4e-6: doubling
    /// assert!(StopRules::regrowing(&h(&[1.0, 1.0 - 1e-6, 1.0 - 3e-6, 1.0 - 7e-6])));
    /// // decreases 2e-4, 1e-4, 3e-4: a creep with noise
    /// assert!(!StopRules::regrowing(&h(&[1.0, 1.0 - 2e-4, 1.0 - 3e-4, 1.0 - 6e-4])));
    /// // no decrease at all is no growth
    /// assert!(!StopRules::regrowing(&h(&[1.0, 1.0, 1.0, 1.0])));
    /// ```
    pub fn regrowing(hist: &[(f64, f64, Option<f64>)]) -> bool {
        let n = hist.len();
        if n < 4 {
            return false;
        }
        let d = |i: usize| hist[i - 1].0 - hist[i].0;
        let (d2, d1, d0) = (d(n - 3), d(n - 2), d(n - 1));
        d2 > 0.0 && d1 >= REGROWTH_FACTOR * d2 && d0 >= REGROWTH_FACTOR * d1
    }

    /// The test that fires on `hist` (the accepted iterates of the run, oldest first, as
    /// `(F, α₋/ᾱ, μ-share)`), if any; see the type docs.
    pub fn check(&self, hist: &[(f64, f64, Option<f64>)]) -> Option<StopReason> {
        let w = self.window;
        if w == 0 || hist.len() <= w || Self::regrowing(hist) {
            return None;
        }
        let win = &hist[hist.len() - 1 - w..];
        let (f_old, f_new) = (win[0].0, win[w].0);
        if self.window_ftol > 0.0 && f_old - f_new <= self.window_ftol * f_new.abs() {
            return Some(StopReason::WindowFtol);
        }
        let p = self.plateau_len();
        if self.plateau_alpha > 0.0 && hist.len() > p {
            let win = &hist[hist.len() - 1 - p..];
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
