//! # unamalla-optim
//!
//! The optimization stage of unamalla: solvers for the discrete functionals of
//! `unamalla-functionals` and the continuation drivers that make meshes convex and smooth.
//! Design follows `argmin`'s separation: a problem made of small capability traits
//! (`unamalla_functionals::problem`: [`Variables`](unamalla_functionals::Variables),
//! [`Cost`](unamalla_functionals::Cost), [`Gradient`](unamalla_functionals::Gradient),
//! [`Hessian`](unamalla_functionals::Hessian) — sparse matrix and Hessian-vector product —,
//! [`PointwiseModel`](unamalla_functionals::PointwiseModel) and
//! [`ElementMeasures`](unamalla_functionals::ElementMeasures); all six are a
//! [`Problem`](unamalla_functionals::Problem)), a solver ([`solver`]), an observer
//! ([`monitor`]) and the convexity safeguard ([`safeguard`]). The solver entry points take a
//! `Problem` (the method is chosen at run time); the methods and the [`Session`] are bounded by
//! the capabilities they use (L-BFGS and NCG never touch the Hessian, the safeguard only needs
//! the element measures). A variant of a problem replaces one capability and keeps the rest:
//! [`psd_model::PsdModel`] is a `Hessian` only, and
//! [`WithHessian`](unamalla_functionals::WithHessian) combines it with the functional. Sources are cited as `[Key, §x]` or `[Key, (eq)]`; the keys are listed in
//! `docs/references.md` of the repository.
//!
//! ## Solvers ([`solver`]; [González Flores, App. B])
//! * **Truncated Newton, trust region** ([`Solver::TnTr`], UNAMALLA's default; the TRON family of
//!   [Méndez 2023, §6.4.2] and [Cortés Aguirre 2012, §3.3]): preconditioned Steihaug–Toint CG in
//!   the `M`-norm, negative-curvature exit to the boundary, forcing sequence
//!   `η_k = min(η_max, √(‖g_k‖/‖g₀‖))`, radius update on `ρ = ared/pred`.
//! * **Truncated Newton, line search** ([`Solver::TnLs`]): the same inner CG (negative
//!   curvature: stop, or preconditioned steepest descent at the first inner iteration) and a
//!   Moré–Thuente line search ([`linesearch`], a port of MINPACK-2 `dcsrch`).
//! * **L-BFGS(m)** ([`Solver::Lbfgs`], two-loop recursion, `m` = 3 or 5 in UNAMALLA, any `m`).
//! * **Nonlinear CG** ([`Solver::NcgFr`], [Fletcher & Reeves 1964]; the predecessor system's
//!   third method, [González Flores, Preface]): `β = ‖g_{k+1}‖²/‖g_k‖²`, strong-Wolfe
//!   Moré–Thuente line search with curvature constant ≤ 0.1, restart every `n` iterations.
//! * **Pointwise Newton** ([`Solver::Pointwise`], García; [González Flores, §B.5.2]): Gauss–Seidel
//!   sweeps over the free nodes, each solving the local 2×2 (3×3) Newton system
//!   ("simultaneous") or one coordinate at a time ("by components"), with an Armijo test on
//!   the local value. Nodes are coloured (no two nodes of a colour share a cell), so each
//!   colour is updated in parallel and the result equals a sequential sweep in colour order.
//!
//! Preconditioners ([`linalg::Preconditioner`]): none, Jacobi, block-Jacobi (node blocks of
//! the assembled CSR Hessian; default), and a smoothed-aggregation multigrid V-cycle
//! ([`multigrid`]) whose CG iteration count grows only slowly with the grid size. Hessian
//! products use the assembled CSR matrix (refreshed once per outer iteration) or matrix-free
//! [`Hessian::hess_vec`](unamalla_functionals::Hessian::hess_vec).
//!
//! **Why not `argmin`.** The solvers are written here, not taken from `argmin` 0.11, for
//! correctness reasons: every trial point must pass the convexity safeguard below (argmin's
//! line searches and trust regions have no hook to reject a point short of returning `+∞`,
//! which its Moré–Thuente answers with an error, "NaN or Inf encountered", instead of a shorter
//! step), its `NewtonCG` has no preconditioner, and the MINPACK-2 failure codes are needed
//! verbatim for the UNAMALLA messages. (argmin 0.11 returns errors where older releases
//! panicked, e.g. "Search direction must be a descent direction".) With feature `argmin`
//! (default) every [`Problem`](unamalla_functionals::Problem) is an argmin problem
//! ([`argmin_adapter`]: argmin's cost, gradient and Hessian from the matching capabilities);
//! the timing comparison is in docs/benchmarks.md.
//!
//! ## Safeguard (the convexity contract)
//! A [`Session`] finds the elements with at least one free vertex (by
//! perturbing the variables) and, whenever the current iterate has all of them above a
//! threshold (0, or `ε·ᾱ` in the ε-convex phases), rejects trial points that do not (line
//! search: bisection toward the best point; trust region: `ρ = −∞`; pointwise: the node step
//! is halved, checked locally with [`solver::QuadLocalGuard`] or, for hexahedra, by a global
//! check with backtracking of the sweep). Hence a convex start stays convex. Elements whose
//! vertices are all fixed are boundary data: they are excluded and counted separately.
//!
//! When the functional's optimum has cells *at* the threshold (the ε-convex smoothing of a
//! region with very thin passages), two details matter (found on gulf-of-mexico):
//! * the trust-region step is cut at the exact first crossing (α is quadratic along a 2D
//!   step); if that shortens the step, the nodes of the blocking cells are **held back**
//!   instead ([`Session::hold_back`]: their direction components
//!   are zeroed until no cell would reach the threshold within twice the step) and the
//!   held-back step is taken when its model decrease is larger — otherwise one cell at the
//!   threshold shortens every node's step and the whole run stalls;
//! * an iterate that ends within the margin `10⁻⁹·ᾱ` of the threshold (or, by rounding, a hair
//!   below it) keeps a guard at `α₋ − 10⁻⁹·ᾱ` ([`Session::guard_active`]);
//!   before, the guard switched off there and the run could fold cells again (the pipeline
//!   then had to fall back to the start of the run). Test: `tests/guard.rs`.
//!
//! ## Stopping and status ([`status`]; [González Flores, Table A.2])
//! FTOL (relative decrease of F), GTOL (‖g‖ relative to the first gradient, or absolute),
//! MAXITER, stop by the observer, line-search failures (xtol, rounding, STPMIN, STPMAX, FCN
//! calls) and trust-radius collapse; beyond Table A.2, the window tests of [`StopRules`]
//! (relative decrease of F over `W` iterations, quality plateau of α₋/ᾱ and the μ ≥ 0.8
//! share) and an explicit time limit
//! ([`Session::set_time_limit`], "STOP by TIME LIMIT" —
//! never a default: without it a run's result does not depend on the machine). [`Status`]'s `Display` prints the UNAMALLA messages.
//!
//! ## Observer ([`monitor`]; [González Flores, Table A.1])
//! Every iteration the observer receives a [`Monitor`]: Alfamin (α₋), ᾱ,
//! Kcurrent/Kold (k/ᾱ), ω, μ, Inocon, F, ‖g‖, IterSmooth/IterHomotopic/IterClassic, elapsed
//! time; it may stop the run. [`ProgressObserver`] prints one
//! updating line to stderr.
//!
//! ## Drivers ([`drivers`])
//! * [`adaptive_k`](drivers::adaptive_k): [González Flores, Algorithm 4.1, Algorithm 4.2] with
//!   the practical update `k = max(k*ᾱ, −1.0015α₋ + 0.01ᾱ)`, `k* = −0.01` (§4.6.1, (4.35)), a few
//!   iterations per `k`, the C² continuation below `α̂` (§4.6.3, with the matching point of
//!   [`recommended_alpha_hat`](unamalla_functionals::recommended_alpha_hat), not the printed
//!   (4.42)), the double homotopy `σ̂(k)` (5.20), optional Length pre-smoothing, then the
//!   classic phase; the path of the double homotopy is selectable ([`HomotopySchedule`]:
//!   linear (5.20), `t²`, `t³`, `sin(πt/2)`, [González Flores, §5.3, (5.16)–(5.18)]).
//! * [`classic_combination`]: the classic t-Area–Length and t-Area–Orthogonality
//!   combinations of the same thesis ([González Flores, Table 5.1]), which do not untangle.
//! * [`ivanenko_untangle`]: Ivanenko's convex-mesh functional `Σ((ε − α)₊)²`
//!   ([González Flores, (2.50)]).
//! * [`omega_continuation`](drivers::omega_continuation) /
//!   [`omega_continuation_hex`](drivers::omega_continuation_hex):
//!   [Cortés Aguirre 2012, §3.4, Algorithm A].
//! * [`coplanarity_continuation`](drivers::coplanarity_continuation):
//!   [Cortés Aguirre 2012, §4.2, Algorithm B].
//! * [`block_smoothing`](drivers::block_smoothing): [Méndez 2023, §6.4.2, (6.8), (6.9)] with the
//!   ε-convexity guarantee.
//! * [`smooth`] / [`smooth_hex`]: the entry points used by `unamalla smooth`; they never return
//!   more non-convex cells than they were given ([`SmoothReport::restored`]).
//! * [`smooth_each`]: independent meshes (the blocks before merging) in parallel.
//! * [`smooth_coarse_to_fine`] ([`coarse_to_fine`]): one structured grid solved on coarser
//!   grids of the same region first (subsampled start, bilinear prolongation, exact boundary
//!   put back by a transfinite correction, repair), then finished on the fine grid.
//!
//! ## Fixtures ([`fixtures`])
//! The test regions of [González Flores] (`cuad2pp`, the one-hole contour, Ivanenko's region) as
//! TFI grids, and the sinusoidal benchmark region.

#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

#[cfg(feature = "argmin")]
pub mod argmin_adapter;
pub mod coarse_to_fine;
pub mod drivers;
pub mod error;
pub mod fixtures;
pub mod linalg;
pub mod linesearch;
pub mod monitor;
pub mod multigrid;
pub mod psd_model;
pub mod safeguard;
pub mod shape;
pub mod solver;
pub mod status;

pub use coarse_to_fine::{smooth_coarse_to_fine, CoarseToFineOptions, CoarseToFineReport};
pub use drivers::{
    classic_combination, homotopy_weight, ivanenko_untangle, smooth, smooth_each, smooth_hex,
    ClassicCombination, ClassicOptions, HexDriver, HexSmoothOptions, HomotopySchedule, KFunctional,
    SmoothFunctional, SmoothOptions, SmoothReport,
};
pub use error::OptimError;
pub use linalg::Preconditioner;
pub use monitor::{Control, Monitor, NullObserver, Observer, Phase, ProgressObserver};
pub use safeguard::{Convexity, Session};
pub use shape::{improve_shape, BoundarySlide, ShapeOptions, ShapeReport};
pub use solver::{
    minimize, HessianMode, PointwiseMode, SolveResult, Solver, SolverOptions, StopRules,
    POLISH_WINDOW, REGROWTH_FACTOR,
};
pub use status::{LineSearchFailure, Status, StopReason};
