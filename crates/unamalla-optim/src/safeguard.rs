//! The domain safeguard and per-run bookkeeping: [`Session`] (observer, monitor, clock, the
//! element mask and the safeguard that keeps a convex iterate convex) and the convexity
//! statistics of an iterate ([`Convexity`]).

use std::time::{Duration, Instant};

use unamalla_functionals::{ElementMeasures, Variables};

use crate::monitor::{Control, Monitor, Observer, Phase, QualityProbe};

/// Convexity statistics of an iterate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Convexity {
    /// Minimum measure over elements with a free vertex (`+∞` if there is none).
    pub min: f64,
    /// Mean measure over all elements (`ᾱ`).
    pub mean: f64,
    /// Cells with a free-vertex element of measure `≤ 0`.
    pub nonconvex_cells: usize,
    /// Elements with all vertices fixed and measure `≤ 0`.
    pub fixed_nonpositive: usize,
    /// Minimum over the all-fixed elements (`+∞` if none).
    pub fixed_min: f64,
}

impl Convexity {
    /// Every element with a free vertex has a positive measure.
    pub fn convex(&self) -> bool {
        self.min > 0.0
    }
    /// `α₋ > ε·ᾱ`.
    pub fn eps_convex(&self, eps: f64) -> bool {
        self.min > eps * self.mean
    }
}

/// Relative margin of the safeguard: the guard engages only when the current iterate's worst
/// masked element exceeds the threshold by more than `GUARD_MARGIN·ᾱ`.
///
/// An iterate whose worst element lies within rounding of the threshold admits no step at all
/// under the guard (every trial point, however short, flips that element's sign in the last
/// bits, so the trust radius collapses at once); before this margin the untangling drivers
/// could call the solver thousands of times on such an iterate without moving. With the
/// margin the solver treats such an iterate as not yet convex; the drivers' convexity targets
/// (`α₋ > ε·ᾱ`, ε ≥ 10⁻⁴) lie far above it, so the contract "a convex start stays convex"
/// holds for every start that is convex by more than `10⁻⁹·ᾱ`.
pub const GUARD_MARGIN: f64 = 1e-9;

/// Per-run state shared by solvers and drivers: the observer, the monitor, the clock, the
/// element mask (elements with a free vertex) and the domain safeguard.
///
/// The safeguard: when the current iterate has every masked element above
/// [`guard_threshold`](Self::guard_threshold) (0 by default, i.e. convex), trial points
/// with a masked element at or below the threshold are rejected by the line searches, trust
/// regions and pointwise steps. So a convex (ε-convex) start never becomes non-convex.
pub struct Session<'o> {
    observer: &'o mut dyn Observer,
    start: Instant,
    /// The monitor (phase counters accumulate over solver runs).
    pub monitor: Monitor,
    mask: Vec<bool>,
    group: usize,
    meas: Vec<f64>,
    /// Buffers of the fraction-to-the-boundary test ([`crossing_times`]), kept between
    /// calls: it runs up to six times per iteration on ~10⁵ elements.
    step: StepScratch,
    /// Absolute threshold of the safeguard (see the type docs).
    pub guard_threshold: f64,
    /// Whether the safeguard is on.
    pub guard: bool,
    active_threshold: Option<f64>,
    stop: bool,
    time_limit: Option<Duration>,
    timed_out: bool,
    quality: Option<QualityProbe>,
    pub(crate) hess: Option<unamalla_functionals::Csr>,
    pub(crate) colors: Option<Vec<Vec<usize>>>,
}

impl std::fmt::Debug for Session<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Session")
            .field("monitor", &self.monitor)
            .finish_non_exhaustive()
    }
}

impl<'o> Session<'o> {
    /// A session for `problem` (the element mask is found by perturbing the free variables of
    /// `x`: elements whose measure does not change have only fixed vertices).
    pub fn new<P: Variables + ElementMeasures + ?Sized>(
        problem: &P,
        x: &[f64],
        observer: &'o mut dyn Observer,
    ) -> Self {
        let ne = problem.num_elements();
        let mut a = vec![0.0; ne];
        let mut b = vec![0.0; ne];
        problem.element_measures(x, &mut a);
        // relative to the coordinates' magnitude (no absolute floor: the session must not
        // depend on the units of the mesh)
        let scale = x
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(f64::MIN_POSITIVE)
            * 1e-3;
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let xp: Vec<f64> = x
            .iter()
            .map(|v| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                v + scale * (0.5 + (state >> 11) as f64 / (1u64 << 53) as f64)
            })
            .collect();
        problem.element_measures(&xp, &mut b);
        let mask = a.iter().zip(&b).map(|(p, q)| p != q).collect();
        Self {
            observer,
            start: Instant::now(),
            monitor: Monitor::default(),
            mask,
            group: if problem.dim() == 3 { 10 } else { 4 },
            meas: a,
            step: StepScratch::default(),
            guard_threshold: 0.0,
            guard: true,
            active_threshold: None,
            stop: false,
            time_limit: None,
            timed_out: false,
            quality: None,
            hess: None,
            colors: None,
        }
    }

    /// The element mask (`true` = the element has a free vertex).
    pub fn mask(&self) -> &[bool] {
        &self.mask
    }

    /// Convexity statistics at `x`.
    pub fn convexity<P: ElementMeasures + ?Sized>(&mut self, problem: &P, x: &[f64]) -> Convexity {
        problem.element_measures(x, &mut self.meas);
        let mut c = Convexity {
            min: f64::INFINITY,
            mean: 0.0,
            nonconvex_cells: 0,
            fixed_nonpositive: 0,
            fixed_min: f64::INFINITY,
        };
        let mut sum = 0.0;
        for (cell, mk) in self
            .meas
            .chunks(self.group)
            .zip(self.mask.chunks(self.group))
        {
            let mut bad = false;
            for (&v, &m) in cell.iter().zip(mk) {
                sum += v;
                if m {
                    c.min = c.min.min(v);
                    if v.is_nan() || v <= 0.0 {
                        bad = true;
                    }
                } else {
                    c.fixed_min = c.fixed_min.min(v);
                    if v <= 0.0 {
                        c.fixed_nonpositive += 1;
                    }
                }
            }
            c.nonconvex_cells += bad as usize;
        }
        if c.min.is_nan() {
            c.min = f64::NEG_INFINITY;
        }
        c.mean = sum / self.meas.len().max(1) as f64;
        c
    }

    /// Minimum masked measure at `x` (NaN measures count as `−∞`).
    pub fn masked_min<P: ElementMeasures + ?Sized>(&mut self, problem: &P, x: &[f64]) -> f64 {
        problem.element_measures(x, &mut self.meas);
        let mut m = f64::INFINITY;
        for (&v, &k) in self.meas.iter().zip(&self.mask) {
            if k {
                if v.is_nan() {
                    return f64::NEG_INFINITY;
                }
                m = m.min(v);
            }
        }
        m
    }

    /// Whether the safeguard applies at the current iterate whose masked minimum is `cur_min`,
    /// and with which threshold (used by [`admissible`](Self::admissible),
    /// [`max_step`](Self::max_step) and [`hold_back`](Self::hold_back) until the next call):
    /// the guard is on and `cur_min` exceeds [`guard_threshold`](Self::guard_threshold) by
    /// more than [`GUARD_MARGIN`]`·ᾱ` (ᾱ of the last recorded iterate) — then that threshold
    /// applies; otherwise, if the iterate is still convex by more than the margin (it sits at
    /// the threshold, e.g. after a step that stopped just short of it, or rounding put it a
    /// hair below), the threshold `cur_min − margin`: the smallest measure then cannot creep
    /// down by more than the margin per iteration, and a convex iterate never loses its
    /// convexity; otherwise the guard is off (the iterate is not convex).
    pub fn guard_active(&mut self, cur_min: f64) -> bool {
        let margin = GUARD_MARGIN * self.monitor.alpha_bar.abs();
        self.active_threshold = if !self.guard {
            None
        } else if cur_min > self.guard_threshold + margin {
            Some(self.guard_threshold)
        } else if cur_min > margin {
            Some(cur_min - margin)
        } else {
            None
        };
        self.active_threshold.is_some()
    }

    /// The threshold the safeguard applies (see [`guard_active`](Self::guard_active)).
    pub fn threshold(&self) -> f64 {
        self.active_threshold.unwrap_or(self.guard_threshold)
    }

    /// Notifies the observer without counting an iteration (used when a solver run ends
    /// without an accepted step, so that time budgets and progress displays still see the
    /// run). Returns the observer's verdict and remembers a stop request.
    pub fn heartbeat(&mut self) -> Control {
        self.monitor.elapsed = self.start.elapsed();
        self.control()
    }

    /// `true` if `x_trial` keeps every masked element above the threshold.
    pub fn admissible<P: ElementMeasures + ?Sized>(
        &mut self,
        problem: &P,
        x_trial: &[f64],
    ) -> bool {
        self.masked_min(problem, x_trial) > self.threshold()
    }

    /// Fraction-to-boundary step: the largest `t > 0` such that every masked element stays
    /// above the threshold on `[0, t)` along `x + t·d`, computed exactly in 2D (α is quadratic
    /// in `t`: three evaluations at `t = −1, 0, 1`); `+∞` in 3D (where the search bisects).
    pub fn max_step<P: Variables + ElementMeasures + ?Sized>(
        &mut self,
        problem: &P,
        x: &[f64],
        d: &[f64],
    ) -> f64 {
        self.max_step_within(problem, x, d, f64::INFINITY)
    }

    /// [`max_step`](Self::max_step) for a caller that only needs `min(t, horizon)`: every
    /// crossing at or beyond `horizon` may be reported as `+∞`. An element whose measure
    /// cannot reach the threshold before `horizon` — `c₀ − thr > |b|·h + |a|·h²` for
    /// `α(t) = a·t² + b·t + c₀` — skips the root computation (most elements of a smoothing
    /// step are far from the threshold), so the result is the same as `max_step`'s whenever
    /// that is below `horizon`.
    pub fn max_step_within<P: Variables + ElementMeasures + ?Sized>(
        &mut self,
        problem: &P,
        x: &[f64],
        d: &[f64],
        horizon: f64,
    ) -> f64 {
        if problem.dim() != 2 {
            return f64::INFINITY;
        }
        self.step.measure_start(problem, x);
        let thr = self.threshold();
        crossing_times(&mut self.step, problem, x, d, &self.mask, thr, horizon)
    }

    /// Holds back the nodes that block the step `d` from `x`: the direction components of
    /// every free node of an element that would reach the threshold before `t = reach` are
    /// set to zero, repeated (at most four rounds) until no element blocks or nothing more can
    /// be held back. Returns the fraction-to-boundary step of the resulting `d`
    /// ([`max_step_within`](Self::max_step_within) with the horizon `max(reach, 1)`: a step of
    /// at least that may be returned as `+∞`).
    ///
    /// Shortening the whole step instead (the plain fraction-to-the-boundary rule) stalls
    /// every node as soon as one cell sits at the safeguard's threshold — the situation of a
    /// smoothing run whose optimum has a few cells at the ε-convexity bound. Holding back
    /// only the blocking cells' nodes lets the rest of the mesh converge. Needs
    /// [`ElementMeasures::element_nodes`]; without it `d` is unchanged.
    pub fn hold_back<P: Variables + ElementMeasures + ?Sized>(
        &mut self,
        problem: &P,
        x: &[f64],
        d: &mut [f64],
        reach: f64,
    ) -> f64 {
        let dim = problem.dim();
        if dim != 2 {
            return f64::INFINITY;
        }
        let mut nodes = Vec::new();
        self.step.measure_start(problem, x);
        let thr = self.threshold();
        // only crossings before `reach` are held back, and the caller compares the returned
        // step with 1
        let horizon = reach.max(1.0);
        for _ in 0..4 {
            let t_min = crossing_times(&mut self.step, problem, x, d, &self.mask, thr, horizon);
            let mut moved = 0usize;
            for (e, &t) in self.step.times.iter().enumerate() {
                if t >= reach {
                    continue;
                }
                nodes.clear();
                problem.element_nodes(e, &mut nodes);
                for &v in &nodes {
                    if let Some(j) = problem.var_of(v) {
                        for c in &mut d[dim * j..dim * (j + 1)] {
                            if *c != 0.0 {
                                *c = 0.0;
                                moved += 1;
                            }
                        }
                    }
                }
            }
            if moved == 0 {
                return t_min;
            }
        }
        crossing_times(&mut self.step, problem, x, d, &self.mask, thr, horizon)
    }

    /// Sets the phase of the following iterations.
    pub fn set_phase(&mut self, phase: Phase) {
        self.monitor.phase = phase;
    }

    /// Elapsed time since the session started.
    pub fn elapsed(&self) -> Duration {
        self.start.elapsed()
    }

    /// Whether the observer asked to stop (or the time limit was reached).
    pub fn stop_requested(&self) -> bool {
        self.stop
    }

    /// An explicit time limit for the session, counted from its start (`None`: no limit, the
    /// default — the runs then end on their convergence tests and iteration caps only, so the
    /// result does not depend on the machine's speed or load). When the limit is reached the
    /// solver stops with [`StopReason::TimeLimit`](crate::StopReason::TimeLimit).
    pub fn set_time_limit(&mut self, limit: Option<Duration>) {
        self.time_limit = limit;
    }

    /// Whether the time limit stopped the session.
    pub fn timed_out(&self) -> bool {
        self.timed_out
    }

    /// Why an interrupted run stopped: [`StopReason::TimeLimit`](crate::StopReason::TimeLimit)
    /// if the time limit was reached, else [`StopReason::User`](crate::StopReason::User).
    pub fn interrupt_reason(&self) -> crate::StopReason {
        if self.timed_out {
            crate::StopReason::TimeLimit
        } else {
            crate::StopReason::User
        }
    }

    /// Sets the quality probe of the plateau test ([`StopRules`](crate::solver::StopRules)):
    /// a function of the variables returning the share (percent) of cells with μ ≥ 0.8.
    pub fn set_quality(&mut self, probe: Option<QualityProbe>) {
        self.quality = probe;
    }

    /// The quality probe's value at `x` (`None` without a probe).
    pub fn quality(&self, x: &[f64]) -> Option<f64> {
        self.quality.as_ref().map(|q| q(x))
    }

    /// The observer's verdict, overridden by the time limit.
    fn control(&mut self) -> Control {
        let mut ctl = self.observer.observe(&self.monitor);
        if let Some(l) = self.time_limit {
            if self.start.elapsed() >= l {
                self.timed_out = true;
                ctl = Control::Stop;
            }
        }
        if ctl == Control::Stop {
            self.stop = true;
        }
        ctl
    }

    /// Records one iteration at `x` with value `f` and gradient norm `gnorm`, notifies the
    /// observer, and returns its verdict. Returns the convexity statistics for the solver.
    pub fn iterate<P: ElementMeasures + ?Sized>(
        &mut self,
        problem: &P,
        x: &[f64],
        f: f64,
        gnorm: f64,
    ) -> (Control, Convexity) {
        match self.monitor.phase {
            Phase::Smooth => self.monitor.iter_smooth += 1,
            Phase::Homotopic => self.monitor.iter_homotopic += 1,
            Phase::Classic => self.monitor.iter_classic += 1,
        }
        let c = self.convexity(problem, x);
        self.update(c, f, gnorm);
        (self.control(), c)
    }

    /// Updates the monitor fields without counting an iteration.
    pub fn update(&mut self, c: Convexity, f: f64, gnorm: f64) {
        self.monitor.alfamin = c.min;
        self.monitor.alpha_bar = c.mean;
        self.monitor.inocon = c.nonconvex_cells;
        self.monitor.fixed_nonpositive = c.fixed_nonpositive;
        self.monitor.f = f;
        self.monitor.gnorm = gnorm;
        self.monitor.elapsed = self.start.elapsed();
    }
}

/// Buffers of the fraction-to-the-boundary test: the element measures at `x` (`a0`), at
/// `x + d` and `x − d`, the point `x ± d`, and the crossing time of each element.
#[derive(Debug, Default)]
struct StepScratch {
    a0: Vec<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
    x: Vec<f64>,
    times: Vec<f64>,
}

impl StepScratch {
    /// The measures at the start point `x`, computed once per [`Session::max_step_within`] or
    /// [`Session::hold_back`] call (which asks for up to five directions from the same `x`).
    fn measure_start<P: ElementMeasures + ?Sized>(&mut self, problem: &P, x: &[f64]) {
        self.a0.resize(problem.num_elements(), 0.0);
        problem.element_measures(x, &mut self.a0);
    }
}

/// Per element, the first `t > 0` at which its measure reaches `thr` along `x + t·d`, into
/// `s.times` (`+∞` if never, for unmasked elements, for elements already at or below `thr`,
/// and possibly for crossings at or beyond `horizon`: see [`Session::max_step_within`]);
/// returns their minimum. 2D only; `s.a0` holds the measures at `x`
/// ([`StepScratch::measure_start`]).
///
/// The measure is `α(t) = a·t² + b·t + c₀` with `b = (α(1) − α(−1))/2`,
/// `a = (α(1) + α(−1))/2 − α(0)`; the root of `α(t) = thr` is taken in the cancellation-free
/// form `q = −(b + sign(b)·√(b² − 4ac))/2`, roots `q/a` and `c/q` (`c = α(0) − thr`). The
/// elements are independent, so the loop runs in parallel; every time is computed by the
/// same arithmetic whatever the thread count (and their minimum is exact).
fn crossing_times<P: ElementMeasures + ?Sized>(
    s: &mut StepScratch,
    problem: &P,
    x: &[f64],
    d: &[f64],
    mask: &[bool],
    thr: f64,
    horizon: f64,
) -> f64 {
    use rayon::prelude::*;
    let ne = s.a0.len();
    s.plus.resize(ne, 0.0);
    s.minus.resize(ne, 0.0);
    s.x.clear();
    s.x.extend(x.iter().zip(d).map(|(a, b)| a + b));
    problem.element_measures(&s.x, &mut s.plus);
    s.x.iter_mut()
        .zip(x.iter().zip(d))
        .for_each(|(t, (a, b))| *t = a - b);
    problem.element_measures(&s.x, &mut s.minus);
    let (a0, ap, am) = (&s.a0, &s.plus, &s.minus);
    s.times.clear();
    s.times.resize(ne, f64::INFINITY);
    s.times
        .par_iter_mut()
        .enumerate()
        .with_min_len(4096)
        .for_each(|(i, t_out)| {
            if !mask[i] {
                return;
            }
            let c = a0[i] - thr;
            if c <= 0.0 {
                return;
            }
            let b = 0.5 * (ap[i] - am[i]);
            let a = 0.5 * (ap[i] + am[i]) - a0[i];
            // |α(t) − α(0)| ≤ |b|·h + |a|·h² on [0, h]: no crossing before the horizon
            // (with a relative margin far above the rounding of the root below)
            let reach = b.abs() * horizon + a.abs() * horizon * horizon;
            if c > reach * (1.0 + 1e-9) {
                return;
            }
            *t_out = if a.abs() <= 1e-14 * (b.abs() + c) {
                if b < 0.0 {
                    -c / b
                } else {
                    f64::INFINITY
                }
            } else {
                let disc = b * b - 4.0 * a * c;
                if disc < 0.0 {
                    f64::INFINITY
                } else {
                    let q = -0.5 * (b + b.signum() * disc.sqrt());
                    let (r1, r2) = (q / a, c / q);
                    let mut r = f64::INFINITY;
                    for v in [r1, r2] {
                        if v > 0.0 && v < r {
                            r = v;
                        }
                    }
                    r
                }
            };
        });
    s.times.iter().copied().fold(f64::INFINITY, f64::min)
}
