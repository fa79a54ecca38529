//! [`adaptive_k`]: untangling and smoothing by the k-functionals with the adaptive k
//! ([González Flores, Algorithm 4.1, Algorithm 4.2]), its options and the homotopy schedules.

use super::*;

/// The adaptive functional `f₁` and its partner `f₂` ([González Flores, Table 5.2, §A.4.3]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum KFunctional {
    /// `kSmooth-Area`: k-Smoothness with Area.
    KSmoothArea,
    /// `kArea-Lenght`: k-Area with Length (UNAMALLA's default).
    #[default]
    KAreaLength,
    /// k-Smoothness alone.
    KSmoothness,
    /// k-Area alone.
    KArea,
}

/// The path `σ̃(t)` of the homotopy between functionals ([González Flores, §5.3, (5.14)–(5.18)]):
/// `f̃_c = (1 − σ̃)f₁ + σ̃f_c`, `σ̃` C¹ and increasing on `[0, 1]` with `σ̃(0) = 0`, `σ̃(1) = 1`.
/// In the double homotopy of §5.4 the parameter is tied to the adaptive `k`,
/// `t = (k₀ − k)/(k₀ − k*)` ((5.20) is the linear path), so the weight of the classic functional
/// `f₂` is `σ̂ = (1 − σ)·σ̃(t)` (5.19) ([`homotopy_weight`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum HomotopySchedule {
    /// `σ̃(t) = t`: the linear homotopy (5.20), UNAMALLA's practical scheme.
    #[default]
    Linear,
    /// `σ̃(t) = t²` (5.16).
    Square,
    /// `σ̃(t) = t³` (5.17).
    Cube,
    /// `σ̃(t) = sin(πt/2)` (5.18).
    Sine,
}

impl HomotopySchedule {
    /// Every schedule.
    pub const ALL: [HomotopySchedule; 4] = [
        HomotopySchedule::Linear,
        HomotopySchedule::Square,
        HomotopySchedule::Cube,
        HomotopySchedule::Sine,
    ];
    /// The command-line name (`linear`, `t2`, `t3`, `sine`).
    pub fn name(self) -> &'static str {
        match self {
            HomotopySchedule::Linear => "linear",
            HomotopySchedule::Square => "t2",
            HomotopySchedule::Cube => "t3",
            HomotopySchedule::Sine => "sine",
        }
    }
    /// `σ̃(t)` for `t` clamped to `[0, 1]`.
    pub fn sigma_tilde(self, t: f64) -> f64 {
        let t = t.clamp(0.0, 1.0);
        match self {
            HomotopySchedule::Linear => t,
            HomotopySchedule::Square => t * t,
            HomotopySchedule::Cube => t * t * t,
            HomotopySchedule::Sine => (0.5 * std::f64::consts::PI * t).sin(),
        }
    }
}

impl std::fmt::Display for HomotopySchedule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for HomotopySchedule {
    type Err = OptimError;
    fn from_str(s: &str) -> Result<Self, OptimError> {
        HomotopySchedule::ALL
            .into_iter()
            .find(|v| v.name() == s)
            .ok_or_else(|| OptimError::UnknownName {
                what: "homotopy schedule",
                name: s.to_string(),
                expected: "linear, t2, t3, sine",
            })
    }
}

/// The weight `σ̂` of the classic functional `f₂` in the double homotopy
/// ([González Flores, §5.3–§5.4, (5.19)–(5.20)]): `σ̂ = w_final·σ̃(t)` with
/// `t = (k₀ − k)/(k₀ − k*)` clamped to `[0, 1]` and `w_final = 1 − σ` (σ = weight of the adaptive
/// `f₁`). If `k` rises again, `t` and `σ̂` fall back with it (the automatic restart of Fig 5.8).
/// With `k₀ ≤ k*` (the start is already at the floor) the target weight is returned.
pub fn homotopy_weight(
    schedule: HomotopySchedule,
    w_final: f64,
    k0: f64,
    k: f64,
    kstar: f64,
) -> f64 {
    if k0 > kstar {
        w_final * schedule.sigma_tilde((k0 - k) / (k0 - kstar))
    } else {
        w_final
    }
}

/// Options of [`adaptive_k`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct AdaptiveKOptions {
    /// The functional pair.
    pub functional: KFunctional,
    /// Weight σ of the adaptive functional in the final combination (UNAMALLA: 0.5; ignored
    /// for the single functionals).
    pub sigma: f64,
    /// The floor `k*` in units of `ᾱ` (UNAMALLA: −0.01, i.e. target `α₋ > 0.01ᾱ`).
    pub k_star: f64,
    /// Solver iterations per `k` update.
    pub iters_per_k: usize,
    /// Maximum number of `k` updates.
    pub max_updates: usize,
    /// Length pre-smoothing iterations (0 = "Previous Smoothness: No").
    pub presmooth: usize,
    /// Run the classic phase after the homotopy.
    pub classic: bool,
    /// Solver options (the classic phase runs with these; the homotopy with
    /// `max_iter = iters_per_k`).
    pub solver: SolverOptions,
    /// The path `σ̃(t)` of the homotopy towards the combination ([`HomotopySchedule`]).
    #[serde(default)]
    pub schedule: HomotopySchedule,
    /// End the homotopy once the mesh is convex with `α₋ > −k*·ᾱ` — the triangle-area
    /// bound that the floor `k*` stands for ([González Flores, Algorithm 4.1]: the sequence can
    /// be continued past convexity "to a target k*" to obtain `α > −k*`).
    ///
    /// `false` (the thesis's loop, the default): the homotopy ends when the practical update
    /// `k̃ = −1.0015·α₋ + 0.01·ᾱ` (4.35) has reached the floor, i.e. only once
    /// `α₋ ≥ (0.01 − k*)·ᾱ/1.0015` — about `0.02ᾱ` for `k* = −0.01`. A mesh whose `α₋` settles
    /// between the two bounds (a boundary angle that caps it) then keeps repeating the same
    /// solve until [`max_updates`](Self::max_updates). With `true` the homotopy ends at the
    /// bound as soon as `α₋` has stopped rising ([`TARGET_STALL_UPDATES`]). [`block_smoothing`]
    /// only needs the bound itself (its ε-convexity) and sets this to `true`.
    #[serde(default)]
    pub stop_at_target: bool,
}

impl Default for AdaptiveKOptions {
    fn default() -> Self {
        Self {
            functional: KFunctional::KAreaLength,
            sigma: 0.5,
            k_star: -0.01,
            iters_per_k: 5,
            max_updates: 2000,
            presmooth: 0,
            classic: true,
            solver: SolverOptions::default(),
            schedule: HomotopySchedule::Linear,
            stop_at_target: false,
        }
    }
}

impl AdaptiveKOptions {
    /// Sets [`functional`](Self::functional): the functional pair.
    #[must_use]
    pub fn functional(mut self, functional: KFunctional) -> Self {
        self.functional = functional;
        self
    }

    /// Sets [`sigma`](Self::sigma).
    #[must_use]
    pub fn sigma(mut self, sigma: f64) -> Self {
        self.sigma = sigma;
        self
    }

    /// Sets [`k_star`](Self::k_star).
    #[must_use]
    pub fn k_star(mut self, k_star: f64) -> Self {
        self.k_star = k_star;
        self
    }

    /// Sets [`iters_per_k`](Self::iters_per_k): solver iterations per `k` update.
    #[must_use]
    pub fn iters_per_k(mut self, iters_per_k: usize) -> Self {
        self.iters_per_k = iters_per_k;
        self
    }

    /// Sets [`max_updates`](Self::max_updates): maximum number of `k` updates.
    #[must_use]
    pub fn max_updates(mut self, max_updates: usize) -> Self {
        self.max_updates = max_updates;
        self
    }

    /// Sets [`presmooth`](Self::presmooth): length pre-smoothing iterations (0 = "Previous
    /// Smoothness: No").
    #[must_use]
    pub fn presmooth(mut self, presmooth: usize) -> Self {
        self.presmooth = presmooth;
        self
    }

    /// Sets [`classic`](Self::classic): run the classic phase after the homotopy.
    #[must_use]
    pub fn classic(mut self, classic: bool) -> Self {
        self.classic = classic;
        self
    }

    /// Sets [`solver`](Self::solver).
    #[must_use]
    pub fn solver(mut self, solver: SolverOptions) -> Self {
        self.solver = solver;
        self
    }

    /// Sets [`schedule`](Self::schedule).
    #[must_use]
    pub fn schedule(mut self, schedule: HomotopySchedule) -> Self {
        self.schedule = schedule;
        self
    }

    /// Sets [`stop_at_target`](Self::stop_at_target).
    #[must_use]
    pub fn stop_at_target(mut self, stop_at_target: bool) -> Self {
        self.stop_at_target = stop_at_target;
        self
    }
}

/// [González Flores, Algorithm 4.1, Algorithm 4.2] as implemented in UNAMALLA 2.0 (§4.6.1, §5.4):
/// adaptive `k` with the double homotopy, then the classic phase. `x` (free-node coordinates of
/// `topo`) is overwritten with the result.
pub fn adaptive_k(
    topo: &Arc<QuadTopology>,
    x: &mut [f64],
    opts: &AdaptiveKOptions,
    session: &mut Session<'_>,
) -> Result<SmoothReport, OptimError> {
    check_sigma("sigma", opts.sigma)?;
    if !(opts.k_star.is_finite() && opts.k_star < 1.0) {
        return Err(OptimError::InvalidOption {
            name: "k_star",
            value: opts.k_star,
            reason: "the floor k* must be finite (and below 1)",
        });
    }
    if topo.num_vars() == 0 {
        return Err(OptimError::NoFreeNodes);
    }
    let n = topo.num_triangles();
    let guard = QuadLocalGuard::new(topo.clone());
    let (probe, c0) = quad_start(topo, x, session)?;
    let ab = c0.mean;
    let (init, mut messages) = start_record(&c0);
    let w_final = match opts.functional {
        KFunctional::KSmoothArea | KFunctional::KAreaLength => 1.0 - opts.sigma,
        _ => 0.0,
    };
    let mut last = None;
    session.guard_threshold = 0.0;
    // 0. pre-smoothing with Length (truncated Newton + line search)
    if let Some((p, r)) =
        length_presmooth(topo, x, opts.presmooth, &opts.solver, ab, session, &guard)?
    {
        return Ok(report(
            session,
            &p,
            x,
            &init,
            messages,
            Some(r),
            -opts.k_star,
        ));
    }
    // 1. homotopy in k
    session.set_phase(Phase::Homotopic);
    let kstar = opts.k_star * ab;
    let mut k0: Option<f64> = None;
    let mut steps = 0;
    let mut reached = false;
    let mut stalled = None;
    let hom_opts = SolverOptions {
        max_iter: opts.iters_per_k.max(1),
        ftol: 0.0,
        ..opts.solver.clone()
    };
    // α₋ after each update (for the stall test of `stop_at_target`)
    let mut history: Vec<f64> = Vec::new();
    // the functional value after each update's solve (for [`PLATEAU_UPDATES`])
    let mut values: Vec<f64> = Vec::new();
    for upd in 0..opts.max_updates {
        let c = session.convexity(&probe, x);
        let am = c.min;
        let k = kstar.max(-1.0015 * am + 0.01 * ab);
        let k0v = *k0.get_or_insert(k);
        session.monitor.k_old = session.monitor.k_current;
        session.monitor.k_current = Some(k / ab);
        history.push(am);
        let stationary = history.len() > TARGET_STALL_UPDATES
            && am <= history[history.len() - 1 - TARGET_STALL_UPDATES] + TARGET_STALL_RISE * ab;
        if opts.stop_at_target && c.convex() && on_plateau(&values) {
            stalled = Some(StopReason::MaxIter);
            break;
        }
        if c.convex() && (k <= kstar || (opts.stop_at_target && am > -kstar && stationary)) {
            messages.push(if upd == 0 {
                Status::InitialGood
            } else {
                Status::HomotopicOk
            });
            reached = true;
            break;
        }
        steps += 1;
        let ah = recommended_alpha_hat(k, am);
        let (f1, f2) = kernels(opts.functional, k, Some(ah), n, ab)?;
        let w2 = homotopy_weight(opts.schedule, w_final, k0v, k, kstar);
        let p = QuadFunctional::new(topo.clone(), combine(f1, f2, w2));
        let r = minimize_with(&p, x, &hom_opts, session, Some(&guard))?;
        last = Some(r);
        values.push(r.f);
        if r.reason.interrupted() {
            let mut rep = report(session, &p, x, &init, messages, last, -opts.k_star);
            rep.continuation_steps = steps;
            return Ok(rep);
        }
        if r.iterations == 0 {
            // no accepted step: `x`, hence `α₋` and `k`, are unchanged, so every further
            // update would repeat this solve exactly — the homotopy has stalled
            stalled = Some(r.reason);
            break;
        }
    }
    // 2. classic phase at k*
    if opts.classic {
        session.set_phase(Phase::Classic);
        let c = session.convexity(&probe, x);
        let k = if reached {
            kstar
        } else {
            kstar.max(-1.0015 * c.min + 0.01 * ab)
        };
        let ah = recommended_alpha_hat(k, c.min);
        let (f1, f2) = kernels(opts.functional, k, Some(ah), n, ab)?;
        let p = QuadFunctional::new(topo.clone(), combine(f1, f2, w_final));
        // keep α > −k once there
        session.guard_threshold = if c.min > -k { (-k).max(0.0) } else { 0.0 };
        let r = minimize_with(&p, x, &opts.solver, session, Some(&guard))?;
        session.guard_threshold = 0.0;
        last = Some(r);
        let mut rep = report(session, &p, x, &init, messages, last, -opts.k_star);
        rep.continuation_steps = steps;
        return Ok(rep);
    }
    let mut rep = report(session, &probe, x, &init, messages, last, -opts.k_star);
    rep.continuation_steps = steps;
    if !reached {
        rep.status = Status::Stopped {
            reason: stalled.unwrap_or(StopReason::MaxIter),
            convex: rep.convex,
        };
        rep.messages.push(rep.status);
    }
    Ok(rep)
}
