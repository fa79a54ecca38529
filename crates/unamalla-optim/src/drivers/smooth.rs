//! The high-level entry points: [`smooth`] / [`smooth_each`] (quad meshes, a
//! [`SmoothFunctional`] chosen by name) and [`smooth_hex`].

use super::*;

/// The functional (and driver) of [`smooth`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum SmoothFunctional {
    /// `ao-homega`: [Méndez 2023, (6.8), (6.9)] with the ε-convexity guarantee
    /// ([`block_smoothing`]).
    BlockSmoothing {
        /// σ (weight of `H_ω`).
        sigma: f64,
        /// Boundary density `w` (1 = plain (6.8)).
        density: f64,
        /// Band width in cell layers.
        layers: usize,
    },
    /// `karea-length`, `ksmooth-area`, `karea`, `ksmooth`: the adaptive driver
    /// ([`adaptive_k`]) with weight σ of the adaptive functional.
    AdaptiveK {
        /// The pair.
        functional: KFunctional,
        /// σ.
        sigma: f64,
    },
    /// `homega`: Algorithm A ([`omega_continuation`]).
    OmegaContinuation,
    /// `ivanenko`: Ivanenko's convex-mesh functional with `ε` = [`SmoothOptions::eps`]
    /// ([`ivanenko_untangle`]).
    Ivanenko,
    /// `area-length`, `area-ortho`: the classic combinations ([`classic_combination`]) with
    /// weight σ of t-Area.
    Classic {
        /// The pair.
        combination: ClassicCombination,
        /// σ.
        sigma: f64,
    },
}

impl SmoothFunctional {
    /// Plain (6.8) (boundary density 1, band of 2 layers) with weight `sigma` of `H_ω`.
    pub fn block_smoothing(sigma: f64) -> Self {
        SmoothFunctional::BlockSmoothing {
            sigma,
            density: 1.0,
            layers: 2,
        }
    }
}

impl Default for SmoothFunctional {
    /// (6.8) with σ = 0.1 (the Laguna Honda example of [Méndez 2023, Example 6.3]).
    fn default() -> Self {
        SmoothFunctional::block_smoothing(0.1)
    }
}

impl SmoothFunctional {
    /// The same functional with weight `sigma` (the weight of `H_ω` for `ao-homega`, of the
    /// adaptive functional for the adaptive pairs, of t-Area for the classic pairs). An error
    /// for a σ outside `[0, 1]`, for a driver without a weight (`homega`, `karea`, `ksmooth`) and
    /// for Area–Orthogonality with σ ≠ 0.5 (its weight is fixed).
    pub fn with_sigma(self, sigma: f64) -> Result<Self, OptimError> {
        check_sigma("sigma", sigma)?;
        Ok(match self {
            SmoothFunctional::BlockSmoothing {
                density, layers, ..
            } => SmoothFunctional::BlockSmoothing {
                sigma,
                density,
                layers,
            },
            SmoothFunctional::AdaptiveK {
                functional: f @ (KFunctional::KAreaLength | KFunctional::KSmoothArea),
                ..
            } => SmoothFunctional::AdaptiveK {
                functional: f,
                sigma,
            },
            SmoothFunctional::Classic { combination, .. } => {
                if combination.fixed_sigma().is_some_and(|f| f != sigma) {
                    return Err(OptimError::InvalidOption {
                        name: "sigma",
                        value: sigma,
                        reason: "the Area-Orthogonality weight is fixed at 0.5",
                    });
                }
                SmoothFunctional::Classic { combination, sigma }
            }
            _ => {
                return Err(OptimError::InvalidOption {
                    name: "sigma",
                    value: sigma,
                    reason:
                        "this functional is not a combination (homega, karea, ksmooth, ivanenko)",
                })
            }
        })
    }
}

impl FromStr for SmoothFunctional {
    type Err = OptimError;
    fn from_str(s: &str) -> Result<Self, OptimError> {
        let k = |functional| SmoothFunctional::AdaptiveK {
            functional,
            sigma: 0.5,
        };
        Ok(match s {
            "ao-homega" => SmoothFunctional::default(),
            "karea-length" => k(KFunctional::KAreaLength),
            "ksmooth-area" => k(KFunctional::KSmoothArea),
            "karea" => k(KFunctional::KArea),
            "ksmooth" => k(KFunctional::KSmoothness),
            "homega" => SmoothFunctional::OmegaContinuation,
            "ivanenko" => SmoothFunctional::Ivanenko,
            "area-length" => SmoothFunctional::Classic {
                combination: ClassicCombination::AreaLength,
                sigma: 0.5,
            },
            "area-ortho" => SmoothFunctional::Classic {
                combination: ClassicCombination::AreaOrthogonality,
                sigma: 0.5,
            },
            _ => {
                return Err(OptimError::UnknownName {
                    what: "functional",
                    name: s.to_string(),
                    expected: "ao-homega, karea-length, ksmooth-area, karea, ksmooth, homega, area-length, area-ortho, ivanenko",
                })
            }
        })
    }
}

/// Options of [`smooth`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct SmoothOptions {
    /// The functional / driver.
    pub functional: SmoothFunctional,
    /// The solver and its stopping options (every phase uses this solver).
    pub solver: SolverOptions,
    /// ε of the ε-convexity target (`α₋ > ε·ᾱ`; adaptive-k uses `k* = −ε`).
    pub eps: f64,
    /// Length pre-smoothing iterations (adaptive-k and untangling; 0 = none).
    pub presmooth: usize,
    /// Solver iterations per `k` update (0 = 5 for truncated Newton, 10 otherwise).
    pub iters_per_k: usize,
    /// Maximum `k` updates.
    pub max_k_updates: usize,
    /// An explicit wall-clock limit of the run in seconds (`None`, the default: the run ends on
    /// its convergence tests and iteration caps only, so its result does not depend on the
    /// machine). When it is reached the status says "STOP by TIME LIMIT"
    /// ([`StopReason::TimeLimit`]).
    #[serde(default)]
    pub time_limit: Option<f64>,
    /// σ continuation of the (6.8) driver ([`BlockSmoothingOptions::sigma_continuation`]).
    #[serde(default)]
    pub sigma_continuation: Vec<f64>,
    /// Iteration cap of each σ-continuation stage (0 = 50).
    #[serde(default)]
    pub continuation_iter: usize,
    /// The homotopy path of the adaptive pairs ([`HomotopySchedule`]).
    #[serde(default)]
    pub schedule: HomotopySchedule,
}

impl Default for SmoothOptions {
    fn default() -> Self {
        Self {
            functional: SmoothFunctional::default(),
            solver: SolverOptions::default(),
            eps: 0.01,
            presmooth: 0,
            iters_per_k: 0,
            max_k_updates: 2000,
            time_limit: None,
            sigma_continuation: Vec::new(),
            continuation_iter: 0,
            schedule: HomotopySchedule::Linear,
        }
    }
}

impl SmoothOptions {
    fn adaptive(&self, functional: KFunctional, sigma: f64, classic: bool) -> AdaptiveKOptions {
        let ipk = if self.iters_per_k > 0 {
            self.iters_per_k
        } else if matches!(self.solver.solver, Solver::TnTr | Solver::TnLs) {
            5
        } else {
            10
        };
        AdaptiveKOptions {
            functional,
            sigma,
            k_star: -self.eps,
            iters_per_k: ipk,
            max_updates: self.max_k_updates,
            presmooth: self.presmooth,
            classic,
            solver: self.solver.clone(),
            schedule: self.schedule,
            stop_at_target: false,
        }
    }

    /// Sets [`functional`](Self::functional): the functional / driver.
    #[must_use]
    pub fn functional(mut self, functional: SmoothFunctional) -> Self {
        self.functional = functional;
        self
    }

    /// Sets [`solver`](Self::solver): the solver and its stopping options (every phase uses this
    /// solver).
    #[must_use]
    pub fn solver(mut self, solver: SolverOptions) -> Self {
        self.solver = solver;
        self
    }

    /// Sets [`eps`](Self::eps): ε of the ε-convexity target (`α₋ > ε·ᾱ`; adaptive-k uses
    /// `k* = −ε`).
    #[must_use]
    pub fn eps(mut self, eps: f64) -> Self {
        self.eps = eps;
        self
    }

    /// Sets [`presmooth`](Self::presmooth): length pre-smoothing iterations (adaptive-k and
    /// untangling; 0 = none).
    #[must_use]
    pub fn presmooth(mut self, presmooth: usize) -> Self {
        self.presmooth = presmooth;
        self
    }

    /// Sets [`iters_per_k`](Self::iters_per_k).
    #[must_use]
    pub fn iters_per_k(mut self, iters_per_k: usize) -> Self {
        self.iters_per_k = iters_per_k;
        self
    }

    /// Sets [`max_k_updates`](Self::max_k_updates): maximum `k` updates.
    #[must_use]
    pub fn max_k_updates(mut self, max_k_updates: usize) -> Self {
        self.max_k_updates = max_k_updates;
        self
    }

    /// Sets [`time_limit`](Self::time_limit).
    #[must_use]
    pub fn time_limit(mut self, time_limit: Option<f64>) -> Self {
        self.time_limit = time_limit;
        self
    }

    /// Sets [`sigma_continuation`](Self::sigma_continuation).
    #[must_use]
    pub fn sigma_continuation(mut self, sigma_continuation: Vec<f64>) -> Self {
        self.sigma_continuation = sigma_continuation;
        self
    }

    /// Sets [`continuation_iter`](Self::continuation_iter): iteration cap of each σ-continuation
    /// stage (0 = 50).
    #[must_use]
    pub fn continuation_iter(mut self, continuation_iter: usize) -> Self {
        self.continuation_iter = continuation_iter;
        self
    }

    /// Sets [`schedule`](Self::schedule): the homotopy path of the adaptive pairs
    /// ([`HomotopySchedule`]).
    #[must_use]
    pub fn schedule(mut self, schedule: HomotopySchedule) -> Self {
        self.schedule = schedule;
        self
    }
}

/// Smooths (and, if needed, untangles) a quad mesh in place: the free nodes of `mesh` are
/// moved, fixed nodes stay. Returns the report; an error only for invalid input (no free
/// nodes, non-finite coordinates, invalid options, a boundary enclosing no area).
pub fn smooth<M: HasQuadCells + FreeNodes + ?Sized>(
    mesh: &mut M,
    opts: &SmoothOptions,
    observer: &mut dyn Observer,
) -> Result<SmoothReport, OptimError> {
    let topo = Arc::new(QuadTopology::from_mesh(&*mesh)?);
    if topo.num_vars() == 0 {
        return Err(OptimError::NoFreeNodes);
    }
    let mut x = topo.initial_x();
    let x0 = x.clone();
    let probe = QuadFunctional::new(topo.clone(), KernelExpr::from(Length));
    let mut session = Session::new(&probe, &x, observer);
    if let Some(t) = opts.time_limit {
        if !(t.is_finite() && t >= 0.0) {
            return Err(OptimError::InvalidOption {
                name: "time_limit",
                value: t,
                reason: "the time limit must be a finite number of seconds ≥ 0",
            });
        }
        session.set_time_limit(Some(Duration::from_secs_f64(t)));
    }
    let mut rep = match &opts.functional {
        SmoothFunctional::BlockSmoothing {
            sigma,
            density,
            layers,
        } => {
            let bo = BlockSmoothingOptions {
                sigma: *sigma,
                density: *density,
                layers: *layers,
                eps: opts.eps,
                untangle: opts.adaptive(KFunctional::KAreaLength, 0.5, false),
                solver: opts.solver.clone(),
                sigma_continuation: opts.sigma_continuation.clone(),
                continuation_iter: if opts.continuation_iter > 0 {
                    opts.continuation_iter
                } else {
                    50
                },
            };
            block_smoothing(&topo, &mut x, &bo, &mut session)?
        }
        SmoothFunctional::AdaptiveK { functional, sigma } => adaptive_k(
            &topo,
            &mut x,
            &opts.adaptive(*functional, *sigma, true),
            &mut session,
        )?,
        SmoothFunctional::OmegaContinuation => {
            let oo = OmegaOptions {
                eps: opts.eps,
                solver: opts.solver.clone(),
                ..OmegaOptions::default()
            };
            omega_continuation(&topo, &mut x, &oo, &mut session)?
        }
        SmoothFunctional::Ivanenko => {
            ivanenko_untangle(&topo, &mut x, opts.eps, &opts.solver, &mut session)?
        }
        SmoothFunctional::Classic { combination, sigma } => {
            let co = ClassicOptions {
                combination: *combination,
                sigma: *sigma,
                presmooth: opts.presmooth,
                eps: opts.eps,
                solver: opts.solver.clone(),
            };
            classic_combination(&topo, &mut x, &co, &mut session)?
        }
    };
    // never hand back more inverted cells than we were given (a run stopped early in the
    // middle of an untangling homotopy can be worse than its start)
    rep.keep_start_if_worse(&mut x, &x0);
    topo.scatter(&x, mesh.nodes_mut());
    Ok(rep)
}

/// Smooths several independent meshes in parallel (rayon), each with [`smooth`] and its own
/// fixed nodes — e.g. the blocks of a decomposition before they are merged, each with its
/// boundary fixed ([Méndez 2023, §6.3]: the blocks are smoothed one by one before the global
/// smoothing of the merged mesh).
///
/// Meshes for which `select` returns `false` are left alone (their entry is `None`). Runs
/// still going at `deadline` are stopped there (their status says "STOP by user"); as in
/// [`smooth`], a run never returns more non-convex cells than its mesh had.
pub fn smooth_each<M, S>(
    meshes: &mut [M],
    select: S,
    opts: &SmoothOptions,
    deadline: Option<std::time::Instant>,
) -> Vec<Option<Result<SmoothReport, OptimError>>>
where
    M: HasQuadCells + FreeNodes + Send,
    S: Fn(&M) -> bool + Sync,
{
    use crate::monitor::Control;
    use rayon::prelude::*;
    meshes
        .par_iter_mut()
        .map(|m| {
            if !select(m) {
                return None;
            }
            let mut stop_at_deadline = |_: &crate::monitor::Monitor| match deadline {
                Some(t) if std::time::Instant::now() >= t => Control::Stop,
                _ => Control::Continue,
            };
            Some(smooth(m, opts, &mut stop_at_deadline))
        })
        .collect()
}

/// Which hexahedral driver [`smooth_hex`] runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum HexDriver {
    /// Algorithm A only.
    #[default]
    AlgorithmA,
    /// Algorithm A, then Algorithm B (if A reached convexity).
    AlgorithmAB,
}

/// Options of [`smooth_hex`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct HexSmoothOptions {
    /// Which algorithms.
    pub driver: HexDriver,
    /// Tetrahedron scaling of `H_ω`.
    pub scaling: Scaling3,
    /// Algorithm A options (ε default 10⁻⁴ here, as for
    /// [Cortés Aguirre 2012, Table 3.1, Table 3.2]).
    pub omega: OmegaOptions,
    /// Algorithm B options.
    pub coplanarity: CoplanarityOptions,
}

impl Default for HexSmoothOptions {
    fn default() -> Self {
        Self {
            driver: HexDriver::AlgorithmA,
            scaling: Scaling3::Index,
            omega: OmegaOptions {
                eps: 1e-4,
                ..OmegaOptions::default()
            },
            coplanarity: CoplanarityOptions::default(),
        }
    }
}

impl HexSmoothOptions {
    /// Sets [`driver`](Self::driver): which algorithms.
    #[must_use]
    pub fn driver(mut self, driver: HexDriver) -> Self {
        self.driver = driver;
        self
    }

    /// Sets [`scaling`](Self::scaling): tetrahedron scaling of `H_ω`.
    #[must_use]
    pub fn scaling(mut self, scaling: Scaling3) -> Self {
        self.scaling = scaling;
        self
    }

    /// Sets [`omega`](Self::omega).
    #[must_use]
    pub fn omega(mut self, omega: OmegaOptions) -> Self {
        self.omega = omega;
        self
    }

    /// Sets [`coplanarity`](Self::coplanarity): Algorithm B options.
    #[must_use]
    pub fn coplanarity(mut self, coplanarity: CoplanarityOptions) -> Self {
        self.coplanarity = coplanarity;
        self
    }
}

/// The hexahedral counterpart of [`smooth`]: Algorithm A (and optionally B) in place.
/// The returned report is Algorithm B's when it ran (its iteration counters include A's).
pub fn smooth_hex<M: HasHexCells + FreeNodes + ?Sized>(
    mesh: &mut M,
    opts: &HexSmoothOptions,
    observer: &mut dyn Observer,
) -> Result<SmoothReport, OptimError> {
    let topo = Arc::new(HexTopology::from_mesh(&*mesh)?);
    if topo.num_vars() == 0 {
        return Err(OptimError::NoFreeNodes);
    }
    let mut x = topo.initial_x();
    let x0 = x.clone();
    let probe = HexFunctional::h_omega(topo.clone(), 1.0, opts.scaling)?;
    let mut session = Session::new(&probe, &x, observer);
    let mut rep = omega_continuation_hex(&topo, opts.scaling, &mut x, &opts.omega, &mut session)?;
    if opts.driver == HexDriver::AlgorithmAB && rep.convex && rep.status.convex() == Some(true) {
        let a_msgs = rep.messages.clone();
        let b =
            coplanarity_continuation(&topo, opts.scaling, &mut x, &opts.coplanarity, &mut session)?;
        let mut msgs = a_msgs;
        msgs.extend(b.messages.iter().skip(1).copied());
        rep = SmoothReport {
            messages: msgs,
            initial_alfamin: rep.initial_alfamin,
            initial_inocon: rep.initial_inocon,
            eps: rep.eps,
            eps_convex: b.alfamin > rep.eps * b.alpha_bar,
            ..b
        };
    }
    rep.keep_start_if_worse(&mut x, &x0);
    topo.scatter(&x, mesh.nodes_mut());
    Ok(rep)
}
