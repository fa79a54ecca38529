//! [`omega_continuation`] / [`omega_continuation_hex`]: Algorithm A of
//! [Cortés Aguirre 2012, §3.4], ω continuation of `H_ω`.

use super::*;

/// Options of Algorithm A ([`omega_continuation`], [`omega_continuation_hex`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
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

impl OmegaOptions {
    /// Sets [`omega0_rel`](Self::omega0_rel).
    #[must_use]
    pub fn omega0_rel(mut self, omega0_rel: f64) -> Self {
        self.omega0_rel = omega0_rel;
        self
    }

    /// Sets [`omega_floor_rel`](Self::omega_floor_rel).
    #[must_use]
    pub fn omega_floor_rel(mut self, omega_floor_rel: f64) -> Self {
        self.omega_floor_rel = omega_floor_rel;
        self
    }

    /// Sets [`eps`](Self::eps): ε of ε-convexity (`α₋ > ε·ᾱ`).
    #[must_use]
    pub fn eps(mut self, eps: f64) -> Self {
        self.eps = eps;
        self
    }

    /// Sets [`refinement`](Self::refinement): run the refinement step after ε-convexity is reached.
    #[must_use]
    pub fn refinement(mut self, refinement: bool) -> Self {
        self.refinement = refinement;
        self
    }

    /// Sets [`solver`](Self::solver).
    #[must_use]
    pub fn solver(mut self, solver: SolverOptions) -> Self {
        self.solver = solver;
        self
    }
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
    probe: &dyn ElementMeasures,
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
