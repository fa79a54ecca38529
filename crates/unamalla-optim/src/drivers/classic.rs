//! [`classic_combination`] and [`ivanenko_untangle`]: one fixed functional (a classic
//! combination, or Ivanenko's untangling functional) minimized with the safeguard.

use super::*;

/// The classic combinations of [González Flores, Table 5.1, §A.4.3] (the `Area-Lenght` and
/// `Area-Ortho.` entries of the Functional menu), each the convex combination `σ·F̃₁ + (1 − σ)·F̃₂`
/// of normalized functionals (§5.1; σ is the weight of the first-named functional, (5.1)–(5.2)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
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
#[non_exhaustive]
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

impl ClassicOptions {
    /// The pair `combination` with weight `sigma`, no pre-smoothing, ε = 0.01 and the default
    /// solver options (the values [`smooth`] uses for [`SmoothFunctional::Classic`] with the
    /// default [`SmoothOptions`]).
    pub fn new(combination: ClassicCombination, sigma: f64) -> Self {
        Self {
            combination,
            sigma,
            presmooth: 0,
            eps: 0.01,
            solver: SolverOptions::default(),
        }
    }

    /// Sets [`combination`](Self::combination): the pair.
    #[must_use]
    pub fn combination(mut self, combination: ClassicCombination) -> Self {
        self.combination = combination;
        self
    }

    /// Sets [`sigma`](Self::sigma): σ, the weight of t-Area.
    #[must_use]
    pub fn sigma(mut self, sigma: f64) -> Self {
        self.sigma = sigma;
        self
    }

    /// Sets [`presmooth`](Self::presmooth): length pre-smoothing iterations (0 = "Previous
    /// Smoothness: No").
    #[must_use]
    pub fn presmooth(mut self, presmooth: usize) -> Self {
        self.presmooth = presmooth;
        self
    }

    /// Sets [`eps`](Self::eps): ε of the reported ε-convexity (`α₋ > ε·ᾱ`).
    #[must_use]
    pub fn eps(mut self, eps: f64) -> Self {
        self.eps = eps;
        self
    }

    /// Sets [`solver`](Self::solver): solver options.
    #[must_use]
    pub fn solver(mut self, solver: SolverOptions) -> Self {
        self.solver = solver;
        self
    }
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
