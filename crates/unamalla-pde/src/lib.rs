//! # unamalla-pde
//!
//! The solvers that run *on* the meshes of the unamalla crate family: a finite-difference
//! solver for linear elliptic equations on curvilinear quad grids (below) and, in [`euler`], a
//! first-order finite-volume solver of the 3D Euler equations on structured hexahedral grids
//! (Cortés Aguirre 2012, chapter 5). The crate depends only on `unamalla-mesh` (and on `faer`
//! with the cargo feature `direct`).
//!
//! The elliptic solver is the "PDE solve" application of UNAMALLA (functional requirement 12 of
//! [González Flores, §6.1.7] and the *PDE Solver Control Panel* of §A.4.5; the references are
//! listed in `docs/references.md` of the repository):
//!
//! ```text
//! a·U_xx + 2b·U_xy + c·U_yy + d·U = g(x, y)   in Ω,     U = U_D on ∂Ω,
//! ```
//!
//! with constants `a, b, c, d` (`a·c − b² > 0`), a source `g` that is constant, sinusoidal or
//! a user closure ([`Source`]), and Dirichlet data given per side of a structured grid
//! (bottom, right, top, left = the thesis's *Bnd1..Bnd4*) as a constant, a parabola or a sine
//! arch with a given peak value, or a closure ([`SideValue`]).
//!
//! # Transformation to logical coordinates
//!
//! A grid is the image of the logical lattice `(ξ, η) = (i, j)` under the mesh map
//! `x(ξ, η)`. At every interior node the metric terms are central differences of the node
//! coordinates (unit logical spacing):
//!
//! ```text
//! x_ξ = (x_{i+1,j} − x_{i−1,j})/2        x_ξξ = x_{i+1,j} − 2x_{i,j} + x_{i−1,j}
//! x_η = (x_{i,j+1} − x_{i,j−1})/2        x_ηη = x_{i,j+1} − 2x_{i,j} + x_{i,j−1}
//! x_ξη = (x_{i+1,j+1} − x_{i+1,j−1} − x_{i−1,j+1} + x_{i−1,j−1})/4      (same for y)
//! J = x_ξ·y_η − x_η·y_ξ,   ξ_x = y_η/J,  ξ_y = −x_η/J,  η_x = −y_ξ/J,  η_y = x_ξ/J
//! ```
//!
//! (the inverse-metric identities of [González Flores, (2.11)], which prints `ξ_y = x_η/J` and
//! `η_x = y_ξ/J` without their minus signs). By the chain rule the operator
//! `L = a∂xx + 2b∂xy + c∂yy` becomes
//!
//! ```text
//! L U = A₁₁ U_ξξ + 2A₁₂ U_ξη + A₂₂ U_ηη + P U_ξ + Q U_η,
//! A₁₁ = a ξ_x² + 2b ξ_x ξ_y + c ξ_y²
//! A₁₂ = a ξ_x η_x + b (ξ_x η_y + ξ_y η_x) + c ξ_y η_y
//! A₂₂ = a η_x² + 2b η_x η_y + c η_y²
//! ```
//!
//! with `P = Lξ`, `Q = Lη`. Instead of differentiating the inverse map twice, `P` and `Q`
//! come from applying the same identity to `U = x` and `U = y` (for which `L U = 0`):
//!
//! ```text
//! [x_ξ x_η; y_ξ y_η]·[P; Q] = −(A₁₁ X_ξξ + 2A₁₂ X_ξη + A₂₂ X_ηη),   X = (x, y),
//! ```
//!
//! so the discrete operator annihilates the nodal values of `x` and `y` exactly. The
//! derivatives of `U` use the same central differences, which gives the **9-point stencil**
//! (weights `A₁₁ ± P/2` on the `ξ` neighbours, `A₂₂ ± Q/2` on the `η` neighbours, `±A₁₂/2` on
//! the diagonals, `−2(A₁₁ + A₂₂) + d` at the centre). These difference formulas are the
//! derivatives at the centre of the biquadratic interpolants of the 9 node positions and
//! values, so the scheme is the chain rule applied to those interpolants: it does not depend
//! on which of the 8 symmetries of the square is chosen as the local `(ξ, η)` frame, it is
//! exact for cubic polynomials on affine grids, and it is second-order accurate on grids that
//! are images of a smooth map (tests and `docs/results.md`).
//!
//! (The module [`euler`] holds the other application of the sources: a first-order
//! finite-volume solver of the 3D Euler equations on hexahedral grids, Cortés Aguirre 2012,
//! chapter 5; its formulas are in its module docs.)
//!
//! # Meshes
//!
//! * [`solve_grid`]: a [`StructuredGrid2`]; the boundary nodes carry the Dirichlet data of
//!   their side.
//! * [`solve_quads`]: any conformal quad mesh — the global mesh of a block mesh
//!   ([`unamalla_mesh::BlockMesh2`] or the [`unamalla_mesh::QuadMesh`] the mesher writes).
//!   Boundary nodes come from the edge census ([`unamalla_mesh::quality::quad_boundary_nodes`]);
//!   every interior node must have exactly four cells, whose eight other vertices, ordered
//!   counter-clockwise around it, are its logical 3 × 3 neighbourhood. On a block interface
//!   this neighbourhood spans both blocks, so the unknowns on an interface are shared and the
//!   discrete solution is continuous there by construction; the frame-independence above makes
//!   the result on a single structured grid identical to [`solve_grid`]'s. Block-structured
//!   meshes from the mesher are singularity-free, so every interior node qualifies; a node of
//!   another valence is an error ([`PdeError::IrregularNode`]). The Dirichlet data on a general
//!   mesh is one [`SideValue`] for the whole boundary (a constant or a closure).
//!
//! # Folded meshes
//!
//! The transformation needs `J > 0`. Before anything is assembled the mesh is checked with
//! [`unamalla_mesh::quality::corner_alphas`] (a cell is convex iff its four corner triangles
//! have `α > 0`; the triangles of [González Flores, (2.53), Fig 2.19]): a mesh with a non-convex
//! cell is reported as [`PdeError::FoldedMesh`] and is not solved; a non-positive
//! central-difference Jacobian at a node is [`PdeError::DegenerateMetric`].
//!
//! # Solvers
//!
//! * [`Method::Sor`] — successive over-relaxation in node order on the 9-point system (the
//!   thesis's solver). The relaxation factor, unless given, is chosen automatically: the
//!   spectral radius `μ` of the Jacobi iteration matrix `B = I − D⁻¹A` is estimated by the power
//!   method with the `D`-weighted norm (started from `sin(πξ)·sin(πη)` on a structured grid,
//!   the exact dominant eigenvector for the Laplacian on a rectangle, and from a constant
//!   vector on a general mesh), and Young's formula `ω = 2/(1 + √(1 − μ²))` is used. During the
//!   iteration the estimate is refined adaptively (Hageman & Young, *Applied Iterative Methods*,
//!   1981, §9.5): from the observed contraction `r` of successive corrections,
//!   `μ̂ = (r + ω − 1)/(ω √r)` (the SOR eigenvalue relation), and `ω` is increased when
//!   `μ̂` exceeds the current estimate while `r > (ω − 1)^0.65`. SOR converges for diagonally
//!   dominant stencils (e.g. the Laplacian on a convex, not too skewed grid); on strongly skewed
//!   grids or with large `d > 0` it may not, which is reported ([`PdeError::SorDiverged`],
//!   [`PdeError::NotConverged`]) — use the direct solver then.
//! * [`Method::Direct`] (cargo feature `direct`, on in the `unamalla` binary) — a sparse LU
//!   factorization with fill-reducing ordering from `faer`. The 9-point matrix is not
//!   symmetric (cross and first-derivative terms), so `nalgebra-sparse`'s Cholesky does not
//!   apply; `faer` is pure Rust and has a maintained sparse LU. The feature is off in the
//!   library by default because `faer` adds minutes to a cold build.
//!
//! Both report the final residual `max |r_i / A_ii|` (in units of `U`).
//!
//! # Example
//!
//! ```
//! use unamalla_mesh::{DVec2, StructuredGrid2};
//! use unamalla_pde::{solve_grid, Equation, SideValue, Source, SolveOptions};
//!
//! // Poisson ΔU = −2 on the unit square with U = 0 on the boundary, 21 × 21 nodes.
//! let grid = StructuredGrid2::from_fn(21, 21, |i, j| DVec2::new(i as f64 / 20.0, j as f64 / 20.0))?;
//! let eq = Equation::new(1.0, 0.0, 1.0, 0.0, Source::Constant(-2.0));
//! let bc = [SideValue::Constant(0.0), SideValue::Constant(0.0),
//!           SideValue::Constant(0.0), SideValue::Constant(0.0)];
//! let sol = solve_grid(&grid, &eq, &bc, &SolveOptions::default())?;
//! let centre = sol.u[grid.index(10, 10)];
//! assert!((centre - 0.1473).abs() < 2e-3); // series solution: 0.14734
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![warn(missing_docs)]
// user input reaches the solvers: no unwrap/expect outside tests (docs/reliability.md, section 3)
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

mod direct;
pub mod euler;
pub mod manufactured;
mod sor;
mod stencil;

use std::fmt;
use std::sync::Arc;
use std::time::Instant;

use unamalla_mesh::quality::{corner_alphas, quad_boundary_nodes};
use unamalla_mesh::{DVec2, HasNodes, HasQuadCells, StructuredGrid2};

use stencil::{assemble, grid_patches, quad_patches, Row};

/// A scalar function of the position, shared and thread-safe (user closures).
pub type ScalarFn = Arc<dyn Fn(DVec2) -> f64 + Send + Sync>;

/// The right-hand side `g(x, y)`.
#[derive(Clone)]
pub enum Source {
    /// `g = value`.
    Constant(f64),
    /// `g = amplitude · sin(π(x − x₀)/L_x) · sin(π(y − y₀)/L_y)` over the bounding box
    /// `[x₀, x₀ + L_x] × [y₀, y₀ + L_y]` of the mesh: one positive sine arch in each direction,
    /// zero on the box. The thesis offers a "sinusoidal" `g` without a formula; this is our
    /// reading (inference).
    Sinusoidal {
        /// Peak value.
        amplitude: f64,
    },
    /// A user closure.
    Function(ScalarFn),
}

impl fmt::Debug for Source {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Source::Constant(v) => write!(f, "Constant({v})"),
            Source::Sinusoidal { amplitude } => {
                write!(f, "Sinusoidal {{ amplitude: {amplitude} }}")
            }
            Source::Function(_) => write!(f, "Function(..)"),
        }
    }
}

/// Dirichlet data on one side of a structured grid (or on a whole boundary).
///
/// `t ∈ [0, 1]` is the normalised arc length along the side, counted in the counter-clockwise
/// direction of the boundary (bottom left → right, right bottom → top, top right → left, left
/// top → bottom). The thesis describes each profile by its maximum value on the side,
/// "starting from the corresponding vertices"; we read that as 0 at both ends for the parabola
/// and the sine (our reading of [González Flores, §A.4.5]).
#[derive(Clone)]
pub enum SideValue {
    /// `U = value`.
    Constant(f64),
    /// `U = 4·peak·t(1 − t)`.
    Parabolic {
        /// Value at the middle of the side.
        peak: f64,
    },
    /// `U = peak·sin(πt)`.
    Sinusoidal {
        /// Value at the middle of the side.
        peak: f64,
    },
    /// A user closure of the position.
    Function(ScalarFn),
}

impl fmt::Debug for SideValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SideValue::Constant(v) => write!(f, "Constant({v})"),
            SideValue::Parabolic { peak } => write!(f, "Parabolic {{ peak: {peak} }}"),
            SideValue::Sinusoidal { peak } => write!(f, "Sinusoidal {{ peak: {peak} }}"),
            SideValue::Function(_) => write!(f, "Function(..)"),
        }
    }
}

impl SideValue {
    /// The value at position `p`, normalised arc length `t` along its side.
    pub fn value(&self, p: DVec2, t: f64) -> f64 {
        match self {
            SideValue::Constant(v) => *v,
            SideValue::Parabolic { peak } => 4.0 * peak * t * (1.0 - t),
            SideValue::Sinusoidal { peak } => peak * (std::f64::consts::PI * t).sin(),
            SideValue::Function(f) => f(p),
        }
    }
}

/// The equation `a·U_xx + 2b·U_xy + c·U_yy + d·U = g`.
#[derive(Debug, Clone)]
pub struct Equation {
    /// Coefficient of `U_xx`.
    pub a: f64,
    /// Half the coefficient of `U_xy`.
    pub b: f64,
    /// Coefficient of `U_yy`.
    pub c: f64,
    /// Coefficient of `U`.
    pub d: f64,
    /// Right-hand side.
    pub g: Source,
}

impl Equation {
    /// `a·U_xx + 2b·U_xy + c·U_yy + d·U = g`.
    pub fn new(a: f64, b: f64, c: f64, d: f64, g: Source) -> Self {
        Self { a, b, c, d, g }
    }

    /// Poisson's equation `ΔU = g`.
    pub fn poisson(g: Source) -> Self {
        Self::new(1.0, 0.0, 1.0, 0.0, g)
    }

    /// Checks the coefficients: finite and elliptic (`a·c − b² > 0`).
    pub fn validate(&self) -> Result<(), PdeError> {
        for (name, v) in [("a", self.a), ("b", self.b), ("c", self.c), ("d", self.d)] {
            if !v.is_finite() {
                return Err(PdeError::NonFiniteCoefficient { name, value: v });
            }
        }
        if let Source::Constant(v) | Source::Sinusoidal { amplitude: v } = self.g {
            if !v.is_finite() {
                return Err(PdeError::NonFiniteCoefficient {
                    name: "g",
                    value: v,
                });
            }
        }
        let disc = self.a * self.c - self.b * self.b;
        if disc <= 0.0 {
            return Err(PdeError::NotElliptic {
                a: self.a,
                b: self.b,
                c: self.c,
                discriminant: disc,
            });
        }
        Ok(())
    }
}

/// Which linear solver.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Method {
    /// Successive over-relaxation; `omega: None` chooses ω automatically (module docs).
    Sor {
        /// A fixed relaxation factor in `(0, 2)`, or `None` for the automatic choice.
        omega: Option<f64>,
    },
    /// Sparse LU (feature `direct`).
    Direct,
}

impl Default for Method {
    fn default() -> Self {
        Method::Sor { omega: None }
    }
}

impl Method {
    /// The method's short name: `sor` or `direct`.
    pub fn name(self) -> &'static str {
        match self {
            Method::Sor { .. } => "sor",
            Method::Direct => "direct",
        }
    }
}

/// Options of the solvers. Build them from [`SolveOptions::default`] and the setters; new
/// options may be added in minor releases.
///
/// ```
/// use unamalla_pde::{Method, SolveOptions};
///
/// let opts = SolveOptions::default()
///     .method(Method::Sor { omega: Some(1.5) })
///     .tol(1e-9)
///     .max_iterations(500);
/// assert_eq!(opts.method, Method::Sor { omega: Some(1.5) });
/// assert_eq!((opts.tol, opts.max_iterations), (1e-9, 500));
/// assert_eq!(opts.method.name(), "sor");
/// assert_eq!(Method::Direct.name(), "direct");
/// ```
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct SolveOptions {
    /// The solver.
    pub method: Method,
    /// SOR stops when the largest Gauss–Seidel correction of a sweep is below
    /// `tol · max(1, max |U|)`.
    pub tol: f64,
    /// SOR sweep limit.
    pub max_iterations: usize,
}

impl Default for SolveOptions {
    fn default() -> Self {
        Self {
            method: Method::default(),
            tol: 1e-11,
            max_iterations: 200_000,
        }
    }
}

impl SolveOptions {
    /// Sets [`method`](Self::method): the solver.
    #[must_use]
    pub fn method(mut self, method: Method) -> Self {
        self.method = method;
        self
    }

    /// Sets [`tol`](Self::tol).
    #[must_use]
    pub fn tol(mut self, tol: f64) -> Self {
        self.tol = tol;
        self
    }

    /// Sets [`max_iterations`](Self::max_iterations): SOR sweep limit.
    #[must_use]
    pub fn max_iterations(mut self, max_iterations: usize) -> Self {
        self.max_iterations = max_iterations;
        self
    }
}

/// The discrete solution and how it was obtained.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// `U` at every node of the mesh, in node order (Dirichlet values on the boundary).
    pub u: Vec<f64>,
    /// The solver used.
    pub method: Method,
    /// SOR sweeps (0 for the direct solver).
    pub iterations: usize,
    /// The final relaxation factor (SOR).
    pub omega: Option<f64>,
    /// The final estimate of the Jacobi spectral radius (automatic SOR).
    pub rho_jacobi: Option<f64>,
    /// `max_i |r_i / A_ii|` of the final iterate, `r = g − A U`.
    pub residual: f64,
    /// Number of unknowns (interior nodes).
    pub unknowns: usize,
    /// Wall time of the solve in seconds (assembly included).
    pub seconds: f64,
}

/// Errors of the PDE solver; each names the offending coefficient, node or cell.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PdeError {
    /// A coefficient is NaN or infinite.
    #[error("coefficient {name} = {value} is not finite")]
    NonFiniteCoefficient {
        /// `a`, `b`, `c`, `d` or `g`.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// `a·c − b² ≤ 0`: the equation is not elliptic.
    #[error(
        "the equation is not elliptic: a·c − b² = {discriminant} ≤ 0 (a = {a}, b = {b}, c = {c})"
    )]
    NotElliptic {
        /// `a`.
        a: f64,
        /// `b`.
        b: f64,
        /// `c`.
        c: f64,
        /// `a·c − b²`.
        discriminant: f64,
    },
    /// The mesh has non-convex (folded or degenerate) cells; the transformed equation is not
    /// defined there. Untangle the mesh first (`unamalla smooth`).
    #[error("the mesh is folded: {non_convex_cells} non-convex cell(s) (first: cell {first_cell}, min corner α = {alpha_min:.3e}); untangle it first (e.g. `unamalla smooth`)")]
    FoldedMesh {
        /// Number of cells with some corner `α ≤ 0`.
        non_convex_cells: usize,
        /// The first of them.
        first_cell: usize,
        /// The smallest corner `α` of the mesh.
        alpha_min: f64,
    },
    /// The central-difference Jacobian at a node is not positive.
    #[error("node {node}: the central-difference Jacobian is {jacobian:.3e} ≤ 0 (the grid is too skewed there)")]
    DegenerateMetric {
        /// The node.
        node: usize,
        /// Its Jacobian.
        jacobian: f64,
    },
    /// An interior node is not surrounded by exactly four cells in a cycle.
    #[error("interior node {node} has {cells} cell(s) around it; the 9-point scheme needs exactly 4 in a cycle (a singularity-free mesh)")]
    IrregularNode {
        /// The node.
        node: usize,
        /// Number of cells around it.
        cells: usize,
    },
    /// The mesh has no interior node: nothing to solve.
    #[error("the mesh has no interior node")]
    NoInteriorNodes,
    /// The boundary data cannot be used on this mesh.
    #[error("boundary data: {0}")]
    Boundary(String),
    /// The source or boundary closure gave NaN or ∞.
    #[error("the {what} is not finite at node {node} ({x}, {y})")]
    NonFiniteData {
        /// `source g` or `boundary value`.
        what: &'static str,
        /// The node.
        node: usize,
        /// Its x.
        x: f64,
        /// Its y.
        y: f64,
    },
    /// An invalid solver option.
    #[error("invalid option: {0}")]
    InvalidOption(String),
    /// SOR diverged.
    #[error("SOR diverged at sweep {iteration} (ω = {omega:.4}, correction {correction:.3e}); the stencil is not diagonally dominant here — try the direct solver")]
    SorDiverged {
        /// The sweep.
        iteration: usize,
        /// ω.
        omega: f64,
        /// The largest correction of that sweep.
        correction: f64,
    },
    /// SOR did not reach the tolerance within the sweep limit.
    #[error("SOR did not converge in {iterations} sweeps (last correction {correction:.3e}, ω = {omega:.4})")]
    NotConverged {
        /// Sweeps done.
        iterations: usize,
        /// The last correction.
        correction: f64,
        /// ω.
        omega: f64,
    },
    /// The direct solver is not compiled in.
    #[error("the direct solver needs the cargo feature `direct` of unamalla-pde")]
    DirectUnavailable,
    /// The direct solver failed (singular system, e.g. `d` at an eigenvalue).
    #[error("direct solve failed: {0}")]
    Singular(String),
}

/// A mesh prepared for solving: node positions, the 9-node patch of every interior node and
/// the Dirichlet values of the boundary nodes.
struct Prepared<'a> {
    nodes: &'a [DVec2],
    patches: Vec<(usize, [usize; 9])>,
    dirichlet: Vec<Option<f64>>,
    /// Start vector of the Jacobi power iteration (per node).
    start: Vec<f64>,
}

/// Checks convexity with the quality module's corner triangles.
fn check_convex<M: HasQuadCells + ?Sized>(mesh: &M) -> Result<(), PdeError> {
    let mut count = 0;
    let mut first = 0;
    let mut amin = f64::INFINITY;
    for c in 0..mesh.num_quads() {
        let al = corner_alphas(&mesh.quad_points(c));
        let m = al.iter().copied().fold(f64::INFINITY, f64::min);
        amin = amin.min(m);
        // `!(m > 0)` also catches NaN coordinates
        if m.is_nan() || m <= 0.0 {
            if count == 0 {
                first = c;
            }
            count += 1;
        }
    }
    if count > 0 {
        return Err(PdeError::FoldedMesh {
            non_convex_cells: count,
            first_cell: first,
            alpha_min: amin,
        });
    }
    Ok(())
}

/// The Dirichlet values of a structured grid's boundary, side by side (bottom, right, top,
/// left, counter-clockwise). A corner takes the mean of its two sides' values.
pub fn grid_boundary_values(
    grid: &StructuredGrid2,
    bc: &[SideValue; 4],
) -> Result<Vec<Option<f64>>, PdeError> {
    let (m, n) = (grid.m(), grid.n());
    let mut sum = vec![0.0; m * n];
    let mut cnt = vec![0u8; m * n];
    // sides as node index lists in counter-clockwise order
    let sides: [Vec<usize>; 4] = [
        (0..m).map(|i| grid.index(i, 0)).collect(),
        (0..n).map(|j| grid.index(m - 1, j)).collect(),
        (0..m).rev().map(|i| grid.index(i, n - 1)).collect(),
        (0..n).rev().map(|j| grid.index(0, j)).collect(),
    ];
    for (side, ids) in sides.iter().enumerate() {
        let pts: Vec<DVec2> = ids.iter().map(|&k| grid.nodes()[k]).collect();
        let mut s = vec![0.0; pts.len()];
        for k in 1..pts.len() {
            s[k] = s[k - 1] + pts[k].distance(pts[k - 1]);
        }
        let total = s.last().copied().unwrap_or(0.0);
        for (k, &id) in ids.iter().enumerate() {
            let t = if total > 0.0 {
                s[k] / total
            } else {
                k as f64 / (ids.len().max(2) - 1) as f64
            };
            let v = bc[side].value(pts[k], t);
            if !v.is_finite() {
                return Err(PdeError::NonFiniteData {
                    what: "boundary value",
                    node: id,
                    x: pts[k].x,
                    y: pts[k].y,
                });
            }
            sum[id] += v;
            cnt[id] += 1;
        }
    }
    Ok(sum
        .iter()
        .zip(&cnt)
        .map(|(&s, &c)| (c > 0).then(|| s / c as f64))
        .collect())
}

/// Solves the equation on a structured grid with Dirichlet data per side `bc = [bottom,
/// right, top, left]` (the thesis's Bnd1..Bnd4).
pub fn solve_grid(
    grid: &StructuredGrid2,
    eq: &Equation,
    bc: &[SideValue; 4],
    opts: &SolveOptions,
) -> Result<Solution, PdeError> {
    let t0 = Instant::now();
    eq.validate()?;
    check_convex(grid)?;
    let (m, n) = (grid.m(), grid.n());
    if m < 3 || n < 3 {
        return Err(PdeError::NoInteriorNodes);
    }
    let dirichlet = grid_boundary_values(grid, bc)?;
    let pi = std::f64::consts::PI;
    let start = (0..m * n)
        .map(|k| {
            let (i, j) = (k % m, k / m);
            (pi * i as f64 / (m - 1) as f64).sin() * (pi * j as f64 / (n - 1) as f64).sin()
        })
        .collect();
    let prep = Prepared {
        nodes: grid.nodes(),
        patches: grid_patches(m, n),
        dirichlet,
        start,
    };
    run(&prep, eq, opts, t0)
}

/// Solves the equation on a conformal quad mesh (e.g. the global mesh of a block mesh) with
/// the same Dirichlet data on the whole boundary, which must be a [`SideValue::Constant`] or a
/// [`SideValue::Function`] (the profiles need a side). See the module docs for the scheme.
pub fn solve_quads<M: HasQuadCells + ?Sized>(
    mesh: &M,
    eq: &Equation,
    bc: &SideValue,
    opts: &SolveOptions,
) -> Result<Solution, PdeError> {
    let t0 = Instant::now();
    eq.validate()?;
    if matches!(
        bc,
        SideValue::Parabolic { .. } | SideValue::Sinusoidal { .. }
    ) {
        return Err(PdeError::Boundary(
            "parabolic and sinusoidal profiles need the four sides of a structured grid; on a general quad mesh give a constant or a closure".into(),
        ));
    }
    check_convex(mesh)?;
    let boundary = quad_boundary_nodes(mesh);
    let patches = quad_patches(mesh, &boundary)?;
    if patches.is_empty() {
        return Err(PdeError::NoInteriorNodes);
    }
    let nodes = mesh.nodes();
    let mut dirichlet = vec![None; nodes.len()];
    for (k, &b) in boundary.iter().enumerate() {
        if b {
            let v = bc.value(nodes[k], 0.0);
            if !v.is_finite() {
                return Err(PdeError::NonFiniteData {
                    what: "boundary value",
                    node: k,
                    x: nodes[k].x,
                    y: nodes[k].y,
                });
            }
            dirichlet[k] = Some(v);
        }
    }
    let start = boundary
        .iter()
        .map(|&b| if b { 0.0 } else { 1.0 })
        .collect();
    let prep = Prepared {
        nodes,
        patches,
        dirichlet,
        start,
    };
    run(&prep, eq, opts, t0)
}

fn run(
    prep: &Prepared<'_>,
    eq: &Equation,
    opts: &SolveOptions,
    t0: Instant,
) -> Result<Solution, PdeError> {
    if !opts.tol.is_finite() || opts.tol <= 0.0 {
        return Err(PdeError::InvalidOption(format!(
            "tol must be a positive number, got {}",
            opts.tol
        )));
    }
    if let Method::Sor { omega: Some(w) } = opts.method {
        if w.is_nan() || w <= 0.0 || w >= 2.0 {
            return Err(PdeError::InvalidOption(format!(
                "the SOR relaxation factor must be in (0, 2), got {w}"
            )));
        }
    }
    let g = source_values(prep.nodes, &prep.patches, &eq.g)?;
    let rows: Vec<Row> = assemble(prep.nodes, &prep.patches, eq, &g)?;
    // initial iterate: Dirichlet values on the boundary, their mean inside
    let (bsum, bcnt) = prep
        .dirichlet
        .iter()
        .flatten()
        .fold((0.0, 0usize), |(s, c), v| (s + v, c + 1));
    let mean = if bcnt > 0 { bsum / bcnt as f64 } else { 0.0 };
    let mut u: Vec<f64> = prep.dirichlet.iter().map(|d| d.unwrap_or(mean)).collect();
    let unknowns = rows.len();
    let mut sol = match opts.method {
        Method::Sor { omega } => {
            let r = sor::solve(&rows, &mut u, omega, &prep.start, opts)?;
            Solution {
                u,
                method: opts.method,
                iterations: r.iterations,
                omega: Some(r.omega),
                rho_jacobi: r.rho_jacobi,
                residual: 0.0,
                unknowns,
                seconds: 0.0,
            }
        }
        Method::Direct => {
            direct::solve(&rows, &mut u)?;
            Solution {
                u,
                method: opts.method,
                iterations: 0,
                omega: None,
                rho_jacobi: None,
                residual: 0.0,
                unknowns,
                seconds: 0.0,
            }
        }
    };
    sol.residual = stencil::residual(&rows, &sol.u);
    sol.seconds = t0.elapsed().as_secs_f64();
    Ok(sol)
}

/// `g` at the interior nodes (indexed like `patches`).
fn source_values(
    nodes: &[DVec2],
    patches: &[(usize, [usize; 9])],
    g: &Source,
) -> Result<Vec<f64>, PdeError> {
    let (lo, hi) = nodes.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let ext = (hi - lo).max(DVec2::splat(f64::MIN_POSITIVE));
    let pi = std::f64::consts::PI;
    patches
        .iter()
        .map(|&(k, _)| {
            let p = nodes[k];
            let v = match g {
                Source::Constant(v) => *v,
                Source::Sinusoidal { amplitude } => {
                    amplitude
                        * (pi * (p.x - lo.x) / ext.x).sin()
                        * (pi * (p.y - lo.y) / ext.y).sin()
                }
                Source::Function(f) => f(p),
            };
            if v.is_finite() {
                Ok(v)
            } else {
                Err(PdeError::NonFiniteData {
                    what: "source g",
                    node: k,
                    x: p.x,
                    y: p.y,
                })
            }
        })
        .collect()
}

#[cfg(test)]
mod tests;
