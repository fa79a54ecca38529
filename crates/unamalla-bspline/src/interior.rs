//! Interior control points: a convex structured mesh on the boundary control polygon `Ω'`
//! ([Abelló et al., §2.2]).
//!
//! The interior points `P_{i,j}` (`2 ≤ i ≤ n−1`, `2 ≤ j ≤ m−1`, 1-based) are the free vertices of
//! an `n × m` structured mesh whose boundary vertices are the fixed boundary control points. They
//! minimize the combined functional (57) with the paper's setting `σ = ½`, `F_c = F_AO`:
//!
//! `F(G) = ½·S_{ω,ε}(G) + ½·F_AO(G)/ᾱ²`, with
//! `S_{ω,ε} = Σ_q f(ω(α_q/ᾱ − ε))` and `f(t) = 1/t` (`t ≥ 1`), `(t−1)(t−2)+1` (`t < 1`) (55)–(56),
//! `F_AO = Σ_q ½(α_q² + o_q²)` over the `4(n−1)(m−1)` corner triangles.
//!
//! Readings: the argument of `f` is the scale-invariant `ω(α/ᾱ − ε)` (the printed (55), `ωα − εᾱ`,
//! lowers the threshold as ω grows, which does not fit the "ω large ⇒ ε-convex" claim;
//! [Méndez 2023, §6.4.2] writes `φ(ω(α_q − ε))`), and `F_AO` is divided by `ᾱ²`, which is the
//! paper's functional in coordinates scaled so that `ᾱ = 1` (so that the dimensionless `S` is not
//! swamped by `F_AO`, which has units of length⁴). `ᾱ` is constant (fixed by the boundary), so the
//! scaling does not move the minimizer in any other way. The whole sum is divided by the number of
//! triangles, which only conditions the numbers.
//!
//! Expressed with `unamalla-functionals`:
//! `1/N · (σ·SOmegaEps(ω, ε, ᾱ, ScaleInvariant) + (1−σ)·(1/ᾱ² · AreaOrthogonality))` as a
//! [`KernelExpr`] built with `nested_sum` (the grouping evaluated as written), on the mesh's `QuadTopology`, minimized by `unamalla-optim` (truncated Newton with trust
//! region by default — the paper used TN or L-BFGS-B) from the TFI start, which may be folded
//! (`f` is finite for `α ≤ 0`). The optimizer's safeguard keeps a convex iterate convex.
//!
//! The paper does not report ω and ε. Defaults here (our choice): `ε = 0.05`, `ω = 20`. If the
//! result is not ε-convex, ω is doubled and the minimization resumed from the current mesh ("ω
//! large enough" of the existence theorem), up to [`InteriorOptions::omega_doublings`] times. The
//! result is checked with Definition 2.

use std::sync::Arc;
use std::time::Instant;

use unamalla_functionals::{
    AreaOrthogonality, FunctionalError, KernelExpr, QuadFunctional, QuadTopology, SArgument,
    SOmegaEps,
};
use unamalla_optim::monitor::{NullObserver, Session};
use unamalla_optim::{minimize, SolverOptions, StopReason};

use crate::error::BsplineError;
use crate::net::ControlNet;

/// Options of [`optimize_interior`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct InteriorOptions {
    /// `ω > 0` of `S_{ω,ε}` (first value; doubled if needed).
    pub omega: f64,
    /// `ε ∈ [0, 1)` of `S_{ω,ε}` and of the ε-convexity target.
    pub eps: f64,
    /// `σ ∈ (0, 1]`, the weight of `S` in (57) (the paper: ½).
    pub sigma: f64,
    /// How many times ω may be doubled when the result is not ε-convex.
    pub omega_doublings: usize,
    /// The solver and its stopping options.
    pub solver: SolverOptions,
}

impl Default for InteriorOptions {
    fn default() -> Self {
        Self {
            omega: 20.0,
            eps: 0.05,
            sigma: 0.5,
            omega_doublings: 3,
            solver: SolverOptions::default().max_iter(500),
        }
    }
}

impl InteriorOptions {
    /// Sets [`omega`](Self::omega): `ω > 0` of `S_{ω,ε}` (first value; doubled if needed).
    #[must_use]
    pub fn omega(mut self, omega: f64) -> Self {
        self.omega = omega;
        self
    }

    /// Sets [`eps`](Self::eps).
    #[must_use]
    pub fn eps(mut self, eps: f64) -> Self {
        self.eps = eps;
        self
    }

    /// Sets [`sigma`](Self::sigma).
    #[must_use]
    pub fn sigma(mut self, sigma: f64) -> Self {
        self.sigma = sigma;
        self
    }

    /// Sets [`omega_doublings`](Self::omega_doublings): how many times ω may be doubled when the
    /// result is not ε-convex.
    #[must_use]
    pub fn omega_doublings(mut self, omega_doublings: usize) -> Self {
        self.omega_doublings = omega_doublings;
        self
    }

    /// Sets [`solver`](Self::solver): the solver and its stopping options.
    #[must_use]
    pub fn solver(mut self, solver: SolverOptions) -> Self {
        self.solver = solver;
        self
    }
}

/// What [`optimize_interior`] did.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct InteriorReport {
    /// `α₋/ᾱ` of the start (TFI) net.
    pub initial_min_alpha_rel: f64,
    /// `α₋/ᾱ` of the result.
    pub final_min_alpha_rel: f64,
    /// Non-convex cells of the start.
    pub initial_nonconvex_cells: usize,
    /// Non-convex cells of the result.
    pub final_nonconvex_cells: usize,
    /// The result is convex (Theorem 1 applies to its bilinear map).
    pub convex: bool,
    /// The result is ε-convex (Definition 2).
    pub eps_convex: bool,
    /// The last ω used.
    pub omega: f64,
    /// ε.
    pub eps: f64,
    /// Solver iterations over all runs.
    pub iterations: usize,
    /// Why the last run stopped.
    pub stop: String,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Replaces the interior points of `net` by a minimizer of `½S_{ω,ε} + ½F_AO/ᾱ²` (module docs).
/// Nets without interior points (`n` or `m` = 2) are left as they are.
pub fn optimize_interior(
    net: &mut ControlNet,
    opts: &InteriorOptions,
) -> Result<InteriorReport, BsplineError> {
    let t0 = Instant::now();
    if !(opts.omega.is_finite() && opts.omega > 0.0) {
        return Err(BsplineError::InvalidOption {
            name: "omega",
            value: opts.omega,
            reason: "must be finite and > 0",
        });
    }
    if !(opts.eps.is_finite() && (0.0..1.0).contains(&opts.eps)) {
        return Err(BsplineError::InvalidOption {
            name: "eps",
            value: opts.eps,
            reason: "must be in [0, 1)",
        });
    }
    if !(opts.sigma.is_finite() && opts.sigma > 0.0 && opts.sigma <= 1.0) {
        return Err(BsplineError::InvalidOption {
            name: "sigma",
            value: opts.sigma,
            reason: "must be in (0, 1]",
        });
    }
    let c0 = net.convexity();
    let mut rep = InteriorReport {
        initial_min_alpha_rel: c0.min_alpha_rel(),
        final_min_alpha_rel: c0.min_alpha_rel(),
        initial_nonconvex_cells: c0.nonconvex_cells,
        final_nonconvex_cells: c0.nonconvex_cells,
        convex: c0.convex(),
        eps_convex: c0.eps_convex(opts.eps),
        omega: opts.omega,
        eps: opts.eps,
        iterations: 0,
        stop: "no interior control points".into(),
        seconds: 0.0,
    };
    if net.n() < 3 || net.m() < 3 {
        rep.seconds = t0.elapsed().as_secs_f64();
        return Ok(rep);
    }
    let grid = net.to_grid()?;
    let topo = Arc::new(
        QuadTopology::from_mesh(&grid).map_err(|e| BsplineError::Optimization(e.to_string()))?,
    );
    let ab = topo.alpha_bar();
    if !(ab.is_finite() && ab > 0.0) {
        return Err(BsplineError::Optimization(format!(
            "the boundary control polygon encloses no positive area (mean α = {ab:e})"
        )));
    }
    let ntri = topo.num_triangles() as f64;
    let mut x = topo.initial_x();
    let mut omega = opts.omega;
    let mut observer = NullObserver;
    for round in 0..=opts.omega_doublings {
        let s = SOmegaEps::new(omega, opts.eps, ab, SArgument::ScaleInvariant)
            .map_err(|e| BsplineError::Optimization(e.to_string()))?;
        if !(0.0..=1.0).contains(&opts.sigma) {
            let e = FunctionalError::InvalidParameter {
                name: "sigma",
                value: opts.sigma,
                reason: "a convex combination needs 0 ≤ σ ≤ 1".into(),
            };
            return Err(BsplineError::Optimization(e.to_string()));
        }
        let ao = KernelExpr::nested_sum([(1.0 / (ab * ab), AreaOrthogonality.into())]);
        let sum = KernelExpr::nested_sum([(opts.sigma, s.into()), (1.0 - opts.sigma, ao)]);
        let kernel = KernelExpr::nested_sum([(1.0 / ntri, sum)]);
        let problem = QuadFunctional::new(topo.clone(), kernel);
        let mut session = Session::new(&problem, &x, &mut observer);
        let r = minimize(&problem, &mut x, &opts.solver, &mut session)
            .map_err(|e| BsplineError::Optimization(e.to_string()))?;
        rep.iterations += r.iterations;
        rep.stop = format!("{:?}", r.reason);
        rep.omega = omega;
        let mut nodes = grid_nodes(net);
        topo.scatter(&x, &mut nodes);
        let trial = ControlNet::new(net.n(), net.m(), nodes)?;
        let c = trial.convexity();
        *net = trial;
        rep.final_min_alpha_rel = c.min_alpha_rel();
        rep.final_nonconvex_cells = c.nonconvex_cells;
        rep.convex = c.convex();
        rep.eps_convex = c.eps_convex(opts.eps);
        if rep.eps_convex || round == opts.omega_doublings {
            break;
        }
        if matches!(r.reason, StopReason::User) {
            break;
        }
        omega *= 2.0;
    }
    rep.seconds = t0.elapsed().as_secs_f64();
    Ok(rep)
}

fn grid_nodes(net: &ControlNet) -> Vec<glam::DVec2> {
    net.points().to_vec()
}
