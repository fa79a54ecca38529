//! # unamalla-compat-ilp — compatible point counts and the integer programs of the pipeline
//!
//! Stage 3b of the unamalla pipeline ([Méndez 2023, §5.2]; [Ruiz-Gironés & Sarrate, (3), (6), (8)]; the
//! references are listed in `docs/references.md` of the repository): given a decomposition of the region
//! into blocks, each with four sides (bottom, right, top, left) made of boundary curves `Q_j`
//! (pieces of `∂Ω` or one of the two copies of a cut), choose the number of points `m_j` on every curve so
//! that opposite sides of each block carry the same number of points and both copies of a cut agree.
//!
//! ## Formulas implemented
//!
//! *Compatibility equations* ([Méndez 2023, §5.2.1, (5.1)–(5.4)]), `s_{k,side}` = number of curves on a
//! side, junction points counted once:
//!
//! ```text
//! m_{ι_i} − m_{ς_i} = 0                                      i = 1..q      (5.1)
//! Σ_{j∈J_{k,b}} m_j − Σ_{j∈J_{k,t}} m_j = s_{k,b} − s_{k,t}     k = 1..n      (5.2)
//! Σ_{j∈J_{k,r}} m_j − Σ_{j∈J_{k,l}} m_j = s_{k,r} − s_{k,l}     k = 1..n      (5.3)
//! ```
//!
//! assembled as `A m = b` with `A ∈ Z^{(2n+q)×p}` in the row order of (5.4) ([`CompatSystem::assemble`]).
//! *Block sizes* (5.5)/(5.6): `M_k = Σ_{J_{k,b}} m_j − s_{k,b} + 1`, `N_k = Σ_{J_{k,r}} m_j − s_{k,r} + 1`
//! ([`block_sizes`]).
//!
//! *Integer program* (5.10) with the ceiling of (5.8)/(5.9) (the thesis prints a floor in (5.10)/(5.11);
//! the ceiling is its stated intent) and `m_j ≥ 2`, as a curve has two end points ([`solve()`]):
//!
//! ```text
//! min Σ_j m_j   s.t.   A m = b,   m_j ≥ L_j,   m_j ∈ Z,
//! L_j = max(2, d·⌈ℓ_j/ℓ_min⌉)          (density mode, eq. (5.9))
//! L_j = max(2, ⌈ℓ_j/h⌉ + 1)            (target cell size h)
//! m_j = pin_j                          (user-pinned curves)
//! ```
//!
//! *Target fit* ([`solve_fit`], module [`fit`]): the same equations, `m_j ≥ max(2, min_j)`, and
//! `min Σ_j w_j·c(m_j; t_j)` with targets `t_j = ℓ_j/h + 1`, weights `w_j` = the depth of the block
//! across curve `j` in cells and the convex piecewise-linear deviation cost `c` of [`deviation_cost`]
//! (slopes 1, 2, 4 within `±t/4`, `±t/2`, beyond). Unlike (5.10) it does not carry the largest
//! bound of a sheet of blocks across the whole sheet; the pipeline uses it for cell counts and cell
//! sizes. Solved exactly as a convex-cost min-cost circulation (Ahuja, Magnanti & Orlin 1993, §14.2)
//! with a reduced-cost optimality certificate ([`Optimality::FitCertified`]), or as a MILP when the
//! system is not a network.
//!
//! *Interval assignment* ILP [Ruiz-Gironés & Sarrate, (3)], `min Σ_e n_e/l(e) + M`, `M ≥ n_e/N_e`
//! ([`assign_intervals`]), and *vertex classification* ILPs [Ruiz-Gironés & Sarrate, (6), (8)], with the
//! measured angles as the `ā_i` (see [`vertex`]), `−2 ≤ α_i ≤ 1`, `Σ α_i = 4(1 − H)`
//! ([`classify_vertices`]).
//!
//! ## Solvers and verification
//!
//! MILPs go through `good_lp`; the default backend is the pure-Rust `microlp`, with `cbc` and `highs` as
//! optional cargo features ([`MilpBackend`]). Because `microlp` has known wrong-answer reports, **every
//! answer is verified independently** in exact integer arithmetic (equations, bounds, pins, integrality)
//! before it is returned ([`Verification`]).
//!
//! For (5.10) the crate also has an exact combinatorial path ([`Method::NetworkFlow`]). After merging the
//! two copies of each cut and substituting `x = m − L` (the shift of (5.11)), every column has at most two
//! non-zeros. When the block rows can be re-signed so that each such column has one `+1` and one `−1` (the
//! orientation condition behind Prop. 5.2 / Hoffman–Kruskal, which the thesis assumes for all cuts at
//! once; it can fail, e.g. around holes), the
//! problem is an uncapacitated min-cost transshipment with positive costs, solved by successive shortest
//! paths. Its node potentials give an integral LP dual `y`; checking `(Aᵀy)_j ≤ 1` and equality of the
//! dual and primal objectives **certifies optimality** of whatever path produced the counts
//! ([`Optimality::Certified`]). A sub-optimal MILP answer is therefore caught and replaced.
//!
//! Fallback order for [`Method::Milp`] (the default, with `microlp`): direct MILP → reduced MILP (the
//! (5.11) form) → network flow → LP relaxation + rounding + repair. For [`Method::NetworkFlow`]: network
//! flow → direct MILP → reduced MILP → LP rounding. Each MILP call has a time limit
//! ([`SolveOptions::time_limit`], default 60 s). Rejected attempts are listed in
//! [`CompatSolution::rejected`]; the LP-rounding repair is a greedy last resort that may return feasible
//! but uncertified counts (reported in [`Verification::optimality`]).
//!
//! Measured in release on 2 cores (see `docs/benchmarks.md`): 100 blocks take ≈ 16–19 ms with `microlp`
//! (including the certificate) and ≈ 2–3 ms with the network flow; 1000 blocks ≈ 0.55–0.7 s and ≈ 65 ms.
//!
//! ## Example
//!
//! ```
//! use unamalla_compat_ilp::{fixtures::thesis_example_5_1, solve, SolveOptions};
//!
//! let problem = thesis_example_5_1(); // Fig 5.1: 3 blocks, 2 cuts, 17 curves
//! let sol = solve(&problem, &SolveOptions::density(1))?;
//! assert_eq!(sol.objective, 109);
//! let sizes: Vec<(usize, usize)> = sol.block_sizes.iter().map(|s| (s.m, s.n)).collect();
//! assert_eq!(sizes, [(6, 6), (8, 16), (8, 8)]);
//! assert!(sol.verification.passed());
//! # Ok::<(), unamalla_compat_ilp::CompatError>(())
//! ```
//!
//! ## Infeasibility
//!
//! Equalities plus lower bounds can be infeasible, e.g. with pins or degenerate corner choices (the thesis's
//! total-unimodularity argument gives integral vertices, not a non-empty feasible set).
//! [`solve()`] then returns [`CompatError::Infeasible`] whose [`InfeasibilityReport`] names a small set of
//! conflicting constraint groups — side equations (block id, sides, curve ids), cut equations, pins — found
//! by a deletion filter, so that removing any one of them makes the rest feasible.
//!
//! ## Conventions
//!
//! Curves are referenced by 0-based **index** into [`CompatProblem::curves`]; each curve has a user-facing
//! `id` used in messages and printed equations (`m{id}`). [`CompatProblem::from_index_sets`] builds the
//! thesis numbering `J_{k,side}` of §5.2.1 (curves block by block, sides in the order b, r, t, l; the thesis's
//! Example 5.1 numbers block 3 differently, see [`fixtures::thesis_example_5_1`]).
// No unwrap/expect in library code: user input must give an error, never a panic (see
// docs/reliability.md). Tests may use them; a local `#[allow]` needs a comment naming the invariant.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

pub mod error;
pub mod fit;
pub mod fixtures;
pub mod interval;
mod lp;
mod model;
pub mod problem;
pub mod solve;
pub mod system;
pub mod verify;
pub mod vertex;

pub use error::{BoundInfo, CompatError, ConflictItem, InfeasibilityReport};
pub use fit::{deviation_cost, solve_fit, FitOptions, FitTargets};
pub use interval::{
    assign_intervals, Direction, IntervalEdge, IntervalOptions, IntervalProblem, IntervalSolution,
    IntervalVerification,
};
pub use lp::MilpBackend;
pub use problem::{Block, CompatProblem, Curve, CutPair, LowerBounds, Side, MAX_COUNT};
pub use solve::{solve, verify_counts, CompatSolution, Method, SolveOptions, SolverPath};
pub use system::{block_sizes, BlockSize, CompatSystem, Equation, EquationKind};
pub use verify::{Optimality, Verification};
pub use vertex::{
    classify_vertices, classify_vertices_to_sum, VertexClassOptions, VertexClassification,
    VertexKind,
};
