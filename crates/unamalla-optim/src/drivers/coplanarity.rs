//! [`coplanarity_continuation`]: Algorithm B of [Cortés Aguirre 2012, §4.2], planar interior
//! faces by the penalty `H_ω + C·Σk²`.

use super::*;

/// Options of Algorithm B ([`coplanarity_continuation`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
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

    /// Sets [`omega_rel`](Self::omega_rel).
    #[must_use]
    pub fn omega_rel(mut self, omega_rel: f64) -> Self {
        self.omega_rel = omega_rel;
        self
    }

    /// Sets [`mu0`](Self::mu0).
    #[must_use]
    pub fn mu0(mut self, mu0: f64) -> Self {
        self.mu0 = mu0;
        self
    }

    /// Sets [`mu_min`](Self::mu_min): stop when `μ ≤ mu_min` (10⁻¹²).
    #[must_use]
    pub fn mu_min(mut self, mu_min: f64) -> Self {
        self.mu_min = mu_min;
        self
    }

    /// Sets [`planarity_tol`](Self::planarity_tol).
    #[must_use]
    pub fn planarity_tol(mut self, planarity_tol: f64) -> Self {
        self.planarity_tol = planarity_tol;
        self
    }

    /// Sets [`stop_cos`](Self::stop_cos).
    #[must_use]
    pub fn stop_cos(mut self, stop_cos: Option<f64>) -> Self {
        self.stop_cos = stop_cos;
        self
    }

    /// Sets [`check_every`](Self::check_every).
    #[must_use]
    pub fn check_every(mut self, check_every: usize) -> Self {
        self.check_every = check_every;
        self
    }

    /// Sets [`solver`](Self::solver): solver options of each minimization.
    #[must_use]
    pub fn solver(mut self, solver: SolverOptions) -> Self {
        self.solver = solver;
        self
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
