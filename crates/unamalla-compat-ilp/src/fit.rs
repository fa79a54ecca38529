//! Target-fit counts: compatible point counts that stay **close to a target** on every curve,
//! instead of the smallest counts above lower bounds (problem (5.10)).
//!
//! Problem (5.10) `min Σ m_j, m_j ≥ ⌈ℓ_j/h⌉ + 1` lets one short curve whose bound exceeds its share
//! force its resolution along every block of the sheet it lies on (the opposite-side equalities
//! propagate it): the counts overshoot the requested cell count by 1.3–2.1× on real regions. The fit
//! instead asks every curve `j` for its target `t_j = ℓ_j/h + 1` points and pays for deviations in
//! cells:
//!
//! ```text
//! min Σ_j w_j · c(m_j; t_j)   s.t.   A m = b  (5.1)–(5.4),   m_j ≥ max(2, min_j),   m_j = pin_j,
//! ```
//!
//! `w_j` = the depth of `j`'s block across `j` in tenths of cells ([`FitTargets::for_cell_size`]),
//! so that one point more on a curve costs about the cells it adds, and `c(·; t)` the convex,
//! piecewise-linear deviation cost ([`deviation_cost`]): slope 1 within `±t/4` of the target, 2 up to
//! `±t/2`, 4 beyond — in its integer form, each unit step `n → n+1` costs the slope at its midpoint
//! `n + ½`, so every cost is an integer and `c` is convex on the integers with minimum 0 at
//! `n* = ⌈t − ½⌉`.
//!
//! ## Solution
//!
//! After the reduction of (5.11) (cut copies merged into classes, `x = m − lb ≥ 0`) every class
//! column has at most two ±1 entries; when the rows can be re-signed into a network matrix (the
//! orientation of the crate documentation), the fit is a **min-cost circulation with convex arc
//! costs** (Ahuja, Magnanti & Orlin, *Network Flows*, 1993, §14.2): each class arc is split into
//! parallel arcs, one per linear piece of its cost (capacity = the piece's length, the last one
//! uncapacitated). Pieces with negative cost (below the target) are saturated first; the remaining
//! imbalances are routed by the successive-shortest-path solver of this crate (all residual costs are
//! then ≥ 0). The node potentials `π` give row duals `y` and the answer is **certified** in exact
//! integer arithmetic ([`crate::Optimality::FitCertified`]): with `λ_c = Σ_r a_rc y_r`, every class
//! value `x_c` minimises the convex `f_c(x) − λ_c x` over `x ≥ 0`, i.e.
//!
//! ```text
//! f_c(x_c + 1) − f_c(x_c) ≥ λ_c   and   (x_c = 0  or  f_c(x_c) − f_c(x_c − 1) ≤ λ_c),
//! ```
//!
//! so `x` minimises the Lagrangian `F(x) − yᵀ(Ax − b)` over `x ≥ 0`, and for every feasible `x'`,
//! `F(x') = F(x') − yᵀ(Ax' − b) ≥ F(x) − yᵀ(Ax − b) = F(x)`.
//!
//! When the system is not a network, the fit is solved as a MILP through `good_lp` with the
//! epigraph `z_j ≥ c(k_s) + μ_s (m_j − k_s)` of each piece `s` (exact at integer `m_j`), reported
//! as not certified.

use serde::{Deserialize, Serialize};

use crate::error::CompatError;
use crate::lp::{round_integral, LinearProgram, LpOutcome, MilpBackend, Sense, VarDef};
use crate::model::{Active, Instance, Network, Reduced, INF_CAP};
use crate::problem::{CompatProblem, Side, MAX_COUNT};
use crate::solve::{infeasibility, CompatSolution, SolverPath};
use crate::system::{block_sizes, CompatSystem};
use crate::verify::{check, Optimality};

/// Targets, weights and minimums of the fit, one per curve (indexed like
/// [`CompatProblem::curves`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitTargets {
    /// Target point count `t_j` (finite, ≥ 1).
    pub targets: Vec<f64>,
    /// Weight `w_j ≥ 1` of a one-point deviation on the curve.
    pub weights: Vec<u64>,
    /// Smallest admissible count (at least 2 is always enforced).
    pub minimums: Vec<usize>,
}

impl FitTargets {
    /// Targets for a cell size `h > 0`: `t_j = ℓ_j/h + 1` points, weight `w_j` = the depth of the
    /// block across curve `j` in tenths of cells, `max(1, round(10·(ℓ_a + ℓ_b)/(2h)))` with `ℓ_a`,
    /// `ℓ_b` the lengths of the two sides of the block adjacent to `j`'s side, and minimum 2.
    pub fn for_cell_size(problem: &CompatProblem, h: f64) -> Result<Self, CompatError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(CompatError::InvalidParameter(format!(
                "the target cell size must be finite and > 0, got {h}"
            )));
        }
        let places = problem.places()?;
        let side_len = |k: usize, s: Side| -> f64 {
            problem.blocks[k]
                .side(s)
                .iter()
                .map(|&j| problem.curves[j].length)
                .sum()
        };
        let mut targets = Vec::with_capacity(problem.curves.len());
        let mut weights = Vec::with_capacity(problem.curves.len());
        for (j, c) in problem.curves.iter().enumerate() {
            let t = c.length / h + 1.0;
            if t > MAX_COUNT as f64 {
                return Err(CompatError::CountTooLarge {
                    curve: c.id,
                    value: t,
                    max: MAX_COUNT,
                });
            }
            targets.push(t);
            let (k, s) = places[j];
            let across = match s {
                Side::Bottom | Side::Top => side_len(k, Side::Right) + side_len(k, Side::Left),
                Side::Right | Side::Left => side_len(k, Side::Bottom) + side_len(k, Side::Top),
            };
            weights.push(((10.0 * across / (2.0 * h)).round() as u64).max(1));
        }
        Ok(FitTargets {
            targets,
            weights,
            minimums: vec![2; problem.curves.len()],
        })
    }

    /// Builder: curve index `j` gets at least `m` points.
    pub fn with_minimum(mut self, j: usize, m: usize) -> Self {
        if let Some(v) = self.minimums.get_mut(j) {
            *v = (*v).max(m);
        }
        self
    }

    /// The fit's objective `Σ_j w_j · c(m_j; t_j)` for the given counts.
    pub fn cost(&self, counts: &[usize]) -> u128 {
        counts
            .iter()
            .zip(self.targets.iter().zip(&self.weights))
            .map(|(&m, (&t, &w))| w as u128 * deviation_cost(m, t) as u128)
            .sum()
    }

    fn validate(&self, problem: &CompatProblem) -> Result<(), CompatError> {
        let p = problem.curves.len();
        if self.targets.len() != p || self.weights.len() != p || self.minimums.len() != p {
            return Err(CompatError::DimensionMismatch(format!(
                "the fit targets have {} targets, {} weights and {} minimums for {p} curves",
                self.targets.len(),
                self.weights.len(),
                self.minimums.len()
            )));
        }
        for (j, c) in problem.curves.iter().enumerate() {
            let t = self.targets[j];
            if !(t.is_finite() && t >= 1.0 && t <= MAX_COUNT as f64) {
                return Err(CompatError::InvalidParameter(format!(
                    "the fit target of curve {} must be finite and in [1, {MAX_COUNT}], got {t}",
                    c.id
                )));
            }
            if self.weights[j] == 0 || self.weights[j] > 1 << 20 {
                return Err(CompatError::InvalidParameter(format!(
                    "the fit weight of curve {} must be in [1, 2^20], got {}",
                    c.id, self.weights[j]
                )));
            }
            if self.minimums[j] > MAX_COUNT {
                return Err(CompatError::CountTooLarge {
                    curve: c.id,
                    value: self.minimums[j] as f64,
                    max: MAX_COUNT,
                });
            }
        }
        Ok(())
    }
}

/// Options of [`solve_fit`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct FitOptions {
    /// MILP backend for systems that are not networks.
    pub backend: MilpBackend,
    /// Time limit (seconds) of the MILP call.
    pub time_limit: Option<f64>,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            backend: MilpBackend::Microlp,
            time_limit: Some(60.0),
        }
    }
}

impl FitOptions {
    /// Sets [`backend`](Self::backend): MILP backend for systems that are not networks.
    #[must_use]
    pub fn backend(mut self, backend: MilpBackend) -> Self {
        self.backend = backend;
        self
    }

    /// Sets [`time_limit`](Self::time_limit): time limit (seconds) of the MILP call.
    #[must_use]
    pub fn time_limit(mut self, time_limit: Option<f64>) -> Self {
        self.time_limit = time_limit;
        self
    }
}

/// The integer breakpoints of the deviation cost around a target `t`.
#[derive(Debug, Clone, Copy)]
struct Deviation {
    /// `n* = ⌈t − ½⌉`: the first step `k → k+1` that increases the cost.
    nstar: i64,
    /// Last step with slope 1 above the target: `⌊1.25 t − ½⌋`.
    up1: i64,
    /// Last step with slope 2 above the target: `⌊1.5 t − ½⌋`.
    up2: i64,
    /// First step with slope −1 below the target: `⌈0.75 t − ½⌉`.
    lo1: i64,
    /// First step with slope −2 below the target: `⌈0.5 t − ½⌉`.
    lo2: i64,
}

impl Deviation {
    fn new(t: f64) -> Self {
        Deviation {
            nstar: (t - 0.5).ceil() as i64,
            up1: (1.25 * t - 0.5).floor() as i64,
            up2: (1.5 * t - 0.5).floor() as i64,
            lo1: (0.75 * t - 0.5).ceil() as i64,
            lo2: (0.5 * t - 0.5).ceil() as i64,
        }
    }

    /// `c(k + 1) − c(k)`: the slope at the midpoint `k + ½` with its sign.
    fn marginal(&self, k: i64) -> i64 {
        if k >= self.nstar {
            if k <= self.up1 {
                1
            } else if k <= self.up2 {
                2
            } else {
                4
            }
        } else if k >= self.lo1 {
            -1
        } else if k >= self.lo2 {
            -2
        } else {
            -4
        }
    }

    /// Number of integers in `[a, b]` (0 when empty).
    fn span(a: i64, b: i64) -> i64 {
        (b - a + 1).max(0)
    }

    /// `c(n) = Σ` of the step costs between `n*` and `n` (closed form).
    fn cost(&self, n: i64) -> i64 {
        if n >= self.nstar {
            let last = n - 1; // steps k = n* ..= n − 1
            let ones = Self::span(self.nstar, last.min(self.up1));
            let twos = Self::span(self.nstar.max(self.up1 + 1), last.min(self.up2));
            let fours = Self::span(self.nstar.max(self.up2 + 1), last);
            ones + 2 * twos + 4 * fours
        } else {
            let last = self.nstar - 1; // steps k = n ..= n* − 1
            let ones = Self::span(n.max(self.lo1), last);
            let twos = Self::span(n.max(self.lo2), last.min(self.lo1 - 1));
            let fours = Self::span(n, last.min(self.lo2 - 1));
            ones + 2 * twos + 4 * fours
        }
    }

    /// Every `k` where `marginal(k) ≠ marginal(k − 1)` may happen.
    fn change_points(&self) -> [i64; 5] {
        [self.lo2, self.lo1, self.nstar, self.up1 + 1, self.up2 + 1]
    }
}

/// The deviation cost `c(n; t)` of `n` points for a target of `t` points: convex and piecewise
/// linear, 0 at `n* = ⌈t − ½⌉`; each unit step `n → n+1` costs the slope of the continuous cost at
/// the step's midpoint `n + ½`: 1 within `|n + ½ − t| ≤ t/4`, 2 within `≤ t/2`, 4 beyond.
///
/// ```
/// use unamalla_compat_ilp::deviation_cost;
/// assert_eq!(deviation_cost(10, 10.0), 0);
/// assert_eq!(deviation_cost(12, 10.0), 2); // steps 10→11, 11→12 at offsets 0.5, 1.5 ≤ 2.5
/// assert_eq!(deviation_cost(14, 10.0), 5); // then 12→13 (offset 2.5 ≤ 2.5) costs 1, 13→14 (3.5) 2
/// assert_eq!(deviation_cost(4, 10.0), 11); // 9→10, 8→9, 7→8: 1 each; 6→7, 5→6: 2; 4→5 (5.5): 4
/// ```
pub fn deviation_cost(n: usize, target: f64) -> u64 {
    Deviation::new(target).cost(n as i64).max(0) as u64
}

/// One class of the reduced problem with its convex cost `f_c(x) = Σ_j w_j c(lb + x; t_j)`.
struct ClassCost {
    lb: i64,
    members: Vec<(Deviation, i64)>,
}

impl ClassCost {
    /// `f_c(x + 1) − f_c(x)`.
    fn marginal(&self, x: i64) -> i64 {
        self.members
            .iter()
            .map(|(d, w)| w * d.marginal(self.lb + x))
            .sum()
    }

    /// `f_c(x)`.
    fn value(&self, x: i64) -> i64 {
        self.members
            .iter()
            .map(|(d, w)| w * d.cost(self.lb + x))
            .sum()
    }

    /// Linear pieces `(start x, length or None for the last, slope)`, adjacent equal slopes merged.
    fn pieces(&self) -> Vec<(i64, Option<i64>, i64)> {
        let mut starts: Vec<i64> = vec![0];
        for (d, _) in &self.members {
            starts.extend(
                d.change_points()
                    .iter()
                    .map(|&k| k - self.lb)
                    .filter(|&x| x > 0),
            );
        }
        starts.sort_unstable();
        starts.dedup();
        let mut out: Vec<(i64, Option<i64>, i64)> = Vec::new();
        for (i, &x) in starts.iter().enumerate() {
            let slope = self.marginal(x);
            let len = starts.get(i + 1).map(|&y| y - x);
            match out.last_mut() {
                Some(last) if last.2 == slope => last.1 = len.map(|l| last.1.unwrap_or(0) + l),
                _ => out.push((x, len, slope)),
            }
        }
        out
    }

    /// The smallest minimiser of `f_c` over `x ≥ 0` (for classes in no equation).
    fn argmin(&self) -> i64 {
        self.pieces()
            .iter()
            .filter(|p| p.2 < 0)
            .map(|p| p.0 + p.1.unwrap_or(0))
            .max()
            .unwrap_or(0)
    }
}

/// The network arc `(tail, head)` of a class with entries on the signed rows; `ground` for a
/// single entry.
fn arc_of(entries: &[(usize, i64)], sigma: &[i64], ground: usize) -> Option<(usize, usize)> {
    match *entries {
        [(u, a)] => Some(if sigma[u] * a > 0 {
            (u, ground)
        } else {
            (ground, u)
        }),
        [(u, a), (v, _)] => Some(if sigma[u] * a > 0 { (u, v) } else { (v, u) }),
        _ => None,
    }
}

/// Solve the fit (see the module documentation) and verify the counts: equations, minimums, pins
/// and — on network systems — the reduced-cost certificate ([`Optimality::FitCertified`]). The
/// returned [`CompatSolution`] has `objective = Σ m_j` and `lower_bounds` = the minimums in force.
///
/// Errors: validation errors, [`CompatError::Infeasible`] (minimums and pins conflict with the
/// equations, with the conflict found by the deletion filter of [`crate::solve()`]),
/// [`CompatError::SolverFailed`] when the MILP fails or its answer does not verify.
pub fn solve_fit(
    problem: &CompatProblem,
    targets: &FitTargets,
    options: &FitOptions,
) -> Result<CompatSolution, CompatError> {
    let system = CompatSystem::assemble(problem)?;
    targets.validate(problem)?;
    let lower: Vec<i64> = targets.minimums.iter().map(|&m| m.max(2) as i64).collect();
    let pins: Vec<Option<i64>> = problem
        .curves
        .iter()
        .map(|c| c.pinned.map(|p| p as i64))
        .collect();
    let inst = Instance {
        system: &system,
        num_side_rows: 2 * problem.blocks.len(),
        cuts: problem.cuts.iter().map(|c| (c.first, c.second)).collect(),
        lower: lower.clone(),
        pins: pins.clone(),
        time_limit: options.time_limit,
    };
    let active = Active::all(inst.num_side_rows, inst.cuts.len(), lower.len());
    let infeasible = || infeasibility(problem, &system, &lower, options.time_limit);
    let reduced = inst.reduce(&active).map_err(|_| infeasible())?;
    let costs: Vec<ClassCost> = reduced
        .classes
        .iter()
        .map(|c| ClassCost {
            lb: c.lb,
            members: c
                .members
                .iter()
                .map(|&j| {
                    (
                        Deviation::new(targets.targets[j]),
                        targets.weights[j] as i64,
                    )
                })
                .collect(),
        })
        .collect();
    let (x, path, optimality) = match reduced.orientation() {
        Some(sigma) => {
            let (x, y) = fit_flow(&reduced, &costs, &sigma).ok_or_else(infeasible)?;
            let optimality = certify(&reduced, &costs, &x, &y);
            (x, SolverPath::FitNetwork, optimality)
        }
        None => {
            let x = match fit_milp(&reduced, &costs, options) {
                Ok(Some(x)) => x,
                Ok(None) => return Err(infeasible()),
                Err(e) => {
                    return Err(CompatError::SolverFailed {
                        attempts: vec![format!("fit MILP ({}): {e}", options.backend)],
                    })
                }
            };
            let reason = "the system is not a network matrix after re-signing rows: MILP optimum \
                          as reported by the backend"
                .to_string();
            (
                x,
                SolverPath::FitMilp(options.backend),
                Optimality::NotCertified { reason },
            )
        }
    };
    // counts per curve
    let mut counts = vec![0i64; lower.len()];
    for (ci, c) in reduced.classes.iter().enumerate() {
        for &j in &c.members {
            counts[j] = c.fixed.unwrap_or(c.lb + x[ci]);
        }
    }
    let mut verification = check(&system, &lower, &pins, &counts, true, None);
    verification.optimality = optimality;
    if !verification.passed()
        || counts.iter().any(|&m| m < 2)
        || matches!(verification.optimality, Optimality::Suboptimal { .. })
    {
        return Err(CompatError::SolverFailed {
            attempts: vec![format!(
                "{path}: rejected by verification: {}",
                verification
                    .failure()
                    .unwrap_or_else(|| "count below 2".into())
            )],
        });
    }
    let counts: Vec<usize> = counts.iter().map(|&m| m as usize).collect();
    let objective = counts.iter().map(|&m| m as u64).sum();
    let sizes = block_sizes(problem, &counts)?;
    Ok(CompatSolution {
        counts,
        objective,
        block_sizes: sizes,
        lower_bounds: lower.iter().map(|&l| l as usize).collect(),
        path,
        rejected: Vec::new(),
        verification,
    })
}

/// Convex-cost min-cost circulation on the signed rows. Returns the class values `x` (fixed
/// classes 0) and the row duals `y` on the reduced rows, or `None` when infeasible.
fn fit_flow(reduced: &Reduced, costs: &[ClassCost], sigma: &[i64]) -> Option<(Vec<i64>, Vec<i64>)> {
    let nr = reduced.rhs.len();
    let g = nr;
    let src = nr + 1;
    let snk = nr + 2;
    let mut net = Network::new(nr + 3);
    let mut x = vec![0i64; reduced.classes.len()];
    // net outflow required at every signed row (ground: minus their sum)
    let mut bal: Vec<i64> = (0..nr).map(|r| sigma[r] * reduced.rhs[r]).collect();
    bal.push(-bal.iter().sum::<i64>());
    // (class, edge, +1 forward piece / −1 saturated negative piece)
    let mut edges: Vec<(usize, usize, i64)> = Vec::new();
    for (ci, c) in reduced.classes.iter().enumerate() {
        if c.fixed.is_some() {
            continue;
        }
        if c.entries.is_empty() {
            x[ci] = costs[ci].argmin();
            continue;
        }
        let (tail, head) = arc_of(&c.entries, sigma, g)?;
        for (_, len, slope) in costs[ci].pieces() {
            if slope < 0 {
                // saturated: cancelling it is a residual arc head → tail with cost −slope > 0
                let cap = len?; // the last piece has a positive slope
                x[ci] += cap;
                bal[tail] -= cap;
                bal[head] += cap;
                edges.push((ci, net.add_edge(head, tail, cap, -slope), -1));
            } else {
                let cap = len.unwrap_or(INF_CAP);
                edges.push((ci, net.add_edge(tail, head, cap, slope), 1));
            }
        }
    }
    let mut need = 0i64;
    for (u, &b) in bal.iter().enumerate() {
        if b > 0 {
            net.add_edge(src, u, b, 0);
            need += b;
        } else if b < 0 {
            net.add_edge(u, snk, -b, 0);
        }
    }
    let (flow, pot) = net.min_cost_flow(src, snk, need);
    if flow < need {
        return None;
    }
    for &(ci, e, dir) in &edges {
        x[ci] += dir * net.flow(e);
    }
    let y = (0..nr).map(|r| sigma[r] * (pot[g] - pot[r])).collect();
    Some((x, y))
}

/// The reduced-cost certificate (module documentation): `x_c` minimises `f_c(x) − λ_c x` over
/// `x ≥ 0` for every free class, `λ_c = Σ_r a_rc y_r`. Exact integer arithmetic.
fn certify(reduced: &Reduced, costs: &[ClassCost], x: &[i64], y: &[i64]) -> Optimality {
    let mut cost: i128 = 0;
    for (ci, c) in reduced.classes.iter().enumerate() {
        if c.fixed.is_some() {
            continue;
        }
        let f = &costs[ci];
        cost += f.value(x[ci]) as i128;
        let lambda: i64 = c.entries.iter().map(|&(r, a)| a * y[r]).sum();
        let up = f.marginal(x[ci]) >= lambda;
        let down = x[ci] == 0 || f.marginal(x[ci] - 1) <= lambda;
        if x[ci] < 0 || !up || !down {
            return Optimality::NotCertified {
                reason: format!("the reduced-cost certificate fails on class {ci}"),
            };
        }
    }
    Optimality::FitCertified { cost }
}

/// The fit as a MILP on the reduced form (non-network systems): `x_c ≥ 0` integer, `z_j ≥ 0` with
/// the epigraph rows of every piece of `c(·; t_j)`, `min Σ w_j z_j`.
fn fit_milp(
    reduced: &Reduced,
    costs: &[ClassCost],
    options: &FitOptions,
) -> Result<Option<Vec<i64>>, String> {
    let mut lp = LinearProgram::default();
    let mut var_of = vec![usize::MAX; reduced.classes.len()];
    let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); reduced.rhs.len()];
    let mut x = vec![0i64; reduced.classes.len()];
    for (ci, c) in reduced.classes.iter().enumerate() {
        if c.fixed.is_some() {
            continue;
        }
        if c.entries.is_empty() {
            x[ci] = costs[ci].argmin();
            continue;
        }
        let xv = lp.vars.len();
        var_of[ci] = xv;
        lp.vars.push(VarDef {
            lower: 0.0,
            upper: f64::INFINITY,
            integer: true,
            cost: 0.0,
        });
        for &(r, a) in &c.entries {
            rows[r].push((xv, a as f64));
        }
        for (d, w) in &costs[ci].members {
            let z = lp.vars.len();
            lp.vars.push(VarDef {
                lower: 0.0,
                upper: f64::INFINITY,
                integer: false,
                cost: *w as f64,
            });
            let single = ClassCost {
                lb: c.lb,
                members: vec![(*d, 1)],
            };
            // z ≥ c(k) + μ (x − x_k) at every piece start x_k (slope μ): z − μ x ≥ c(k) − μ x_k
            for (xs, _, slope) in single.pieces() {
                lp.rows.push((
                    vec![(z, 1.0), (xv, -(slope as f64))],
                    Sense::Ge,
                    (single.value(xs) - slope * xs) as f64,
                ));
            }
        }
    }
    for (r, terms) in rows.into_iter().enumerate() {
        lp.rows.push((terms, Sense::Eq, reduced.rhs[r] as f64));
    }
    match lp.solve(options.backend, false, options.time_limit) {
        LpOutcome::Solved(v) => {
            let ints = round_integral(&v).ok_or("non-integral MILP values")?;
            for (ci, &xv) in var_of.iter().enumerate() {
                if xv != usize::MAX {
                    x[ci] = ints[xv];
                }
            }
            Ok(Some(x))
        }
        LpOutcome::Infeasible => Ok(None),
        LpOutcome::Failed(e) => Err(e),
    }
}
