//! [`block_smoothing`]: the block smoothing `F = (1−σ)·w·F_AO + σ·H_ω` of [Méndez 2023, (6.8),
//! (6.9)] from an ε-convex start.

use super::*;

/// Options of [`block_smoothing`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
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

impl BlockSmoothingOptions {
    /// Sets [`sigma`](Self::sigma): σ of (6.8): weight of `H_ω` (Laguna Honda example: 0.1).
    #[must_use]
    pub fn sigma(mut self, sigma: f64) -> Self {
        self.sigma = sigma;
        self
    }

    /// Sets [`density`](Self::density): boundary density `w` of (6.9) (1 = the unweighted (6.8)).
    #[must_use]
    pub fn density(mut self, density: f64) -> Self {
        self.density = density;
        self
    }

    /// Sets [`layers`](Self::layers): width of the boundary band of (6.9) in cell layers.
    #[must_use]
    pub fn layers(mut self, layers: usize) -> Self {
        self.layers = layers;
        self
    }

    /// Sets [`eps`](Self::eps).
    #[must_use]
    pub fn eps(mut self, eps: f64) -> Self {
        self.eps = eps;
        self
    }

    /// Sets [`untangle`](Self::untangle).
    #[must_use]
    pub fn untangle(mut self, untangle: AdaptiveKOptions) -> Self {
        self.untangle = untangle;
        self
    }

    /// Sets [`solver`](Self::solver): solver options of the (6.8) minimization.
    #[must_use]
    pub fn solver(mut self, solver: SolverOptions) -> Self {
        self.solver = solver;
        self
    }

    /// Sets [`sigma_continuation`](Self::sigma_continuation).
    #[must_use]
    pub fn sigma_continuation(mut self, sigma_continuation: Vec<f64>) -> Self {
        self.sigma_continuation = sigma_continuation;
        self
    }

    /// Sets [`continuation_iter`](Self::continuation_iter): iteration cap of each σ-continuation
    /// stage.
    #[must_use]
    pub fn continuation_iter(mut self, continuation_iter: usize) -> Self {
        self.continuation_iter = continuation_iter;
        self
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
            // the functional with its Hessian replaced by the PSD model
            let model = WithHessian::new(p, PsdModel::new(p, PsdProjection::Clamp));
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
