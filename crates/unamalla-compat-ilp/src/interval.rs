//! Interval assignment ILP [Ruiz-Gironés & Sarrate, (3)], after Mitchell's "high fidelity interval
//! assignment":
//!
//! ```text
//! min  Σ_e ω_e n_e + M
//! s.t. Σ_{e∈I+} n_e = Σ_{e∈I−} n_e,   Σ_{e∈J+} n_e = Σ_{e∈J−} n_e,
//!      N_e·M − n_e ≥ 0,   n_e ≥ N_e,   n_e ∈ Z,   n_{e'} = n_{e''} for the two copies of a virtual edge,
//! ```
//! with `ω_e = 1/l(e)` and `M` continuous (it equals `max_e n_e/N_e` at the optimum).

use serde::{Deserialize, Serialize};

use crate::error::CompatError;
use crate::lp::{
    round_integral, LinearProgram, LpOutcome, MilpBackend, Sense, VarDef, MILP_TIME_LIMIT,
};
use crate::problem::{tolerant_ceil, MAX_COUNT};

/// Direction of an edge in computational space (the edge classification of [Ruiz-Gironés & Sarrate,
/// Fig 4]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Direction {
    /// `+i`: horizontal, left to right.
    PlusI,
    /// `−i`: horizontal, right to left.
    MinusI,
    /// `+j`: vertical, bottom to top.
    PlusJ,
    /// `−j`: vertical, top to bottom.
    MinusJ,
}

impl Direction {
    /// Direction from the `Z_4` code `0 = +i, 1 = +j, 2 = −i, 3 = −j`.
    pub fn from_code(code: i64) -> Direction {
        match code.rem_euclid(4) {
            0 => Direction::PlusI,
            1 => Direction::PlusJ,
            2 => Direction::MinusI,
            _ => Direction::MinusJ,
        }
    }

    /// Edge labels of a loop from integer vertex labels (the paper's edge classification rule in compact
    /// form): the first edge is `+i`
    /// and `d_{k+1} = d_k + α_{v_k} (mod 4)`, where `labels[k]` is the label of the vertex **between**
    /// edge `k` and edge `k+1`. Returns the labels and whether the loop closes (`Σ α ≡ 0 mod 4`).
    pub fn propagate(labels: &[i8]) -> (Vec<Direction>, bool) {
        let mut code = 0i64;
        let mut out = Vec::with_capacity(labels.len());
        for &a in labels {
            out.push(Direction::from_code(code));
            code += a as i64;
        }
        (out, code.rem_euclid(4) == 0)
    }
}

/// One edge of the interval-assignment problem.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IntervalEdge {
    /// User-facing id (used in messages).
    pub id: usize,
    /// Physical length `l(e) > 0`.
    pub length: f64,
    /// Direction class (`I+`, `I−`, `J+`, `J−`).
    pub direction: Direction,
    /// Prescribed lower bound `N_e ≥ 1`; when `None` it is derived from the target size.
    pub min_intervals: Option<usize>,
}

/// Input of ILP (3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IntervalProblem {
    /// The edges of the (simply connected, after virtual edges) loop.
    pub edges: Vec<IntervalEdge>,
    /// Index pairs of the two copies of each virtual edge (`n_{e'} = n_{e''}`).
    pub twins: Vec<(usize, usize)>,
}

/// Options of [`assign_intervals`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct IntervalOptions {
    /// Target element size `h`: `N_e = max(1, round(l(e)/h))` for edges without a prescription.
    pub target_size: f64,
    /// Include the `M = max n_e/N_e` term (objective f_2 of Example 2); `false` gives f_1.
    pub include_max_term: bool,
    /// MILP backend.
    pub backend: MilpBackend,
}

impl IntervalOptions {
    /// Objective f_2 (with `M`) for target size `h`, `microlp` backend.
    pub fn new(target_size: f64) -> Self {
        IntervalOptions {
            target_size,
            include_max_term: true,
            backend: MilpBackend::Microlp,
        }
    }

    /// Sets [`include_max_term`](Self::include_max_term).
    #[must_use]
    pub fn include_max_term(mut self, include_max_term: bool) -> Self {
        self.include_max_term = include_max_term;
        self
    }

    /// Sets [`backend`](Self::backend): MILP backend.
    #[must_use]
    pub fn backend(mut self, backend: MilpBackend) -> Self {
        self.backend = backend;
        self
    }
}

/// Checks performed on a solution of (3).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct IntervalVerification {
    /// Raw values were integral (within `1e-6`).
    pub integral: bool,
    /// Both equations of (2) hold exactly.
    pub equations_satisfied: bool,
    /// `n_e ≥ N_e` for every edge.
    pub bounds_satisfied: bool,
    /// Virtual-edge copies are equal.
    pub twins_equal: bool,
}

impl IntervalVerification {
    /// All checks passed.
    pub fn passed(&self) -> bool {
        self.integral && self.equations_satisfied && self.bounds_satisfied && self.twins_equal
    }
}

/// Solution of (3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IntervalSolution {
    /// Number of intervals (elements) `n_e` per edge.
    pub intervals: Vec<usize>,
    /// The lower bounds `N_e` used.
    pub min_intervals: Vec<usize>,
    /// `M = max_e n_e/N_e`, recomputed from the counts.
    pub max_ratio: f64,
    /// Objective `Σ n_e/l(e) (+ M)`, recomputed from the counts.
    pub objective: f64,
    /// `true` when the MILP answer was rejected and LP rounding + repair produced the counts.
    pub used_fallback: bool,
    /// Reasons for rejected attempts.
    pub rejected: Vec<String>,
    /// Verification outcome.
    pub verification: IntervalVerification,
}

/// Solve the interval assignment ILP [Ruiz-Gironés & Sarrate, (3)] and verify the answer; on a failed check, fall back
/// to the LP relaxation rounded up and repaired on untwinned edges.
pub fn assign_intervals(
    problem: &IntervalProblem,
    options: &IntervalOptions,
) -> Result<IntervalSolution, CompatError> {
    let h = options.target_size;
    if !(h.is_finite() && h > 0.0) {
        return Err(CompatError::InvalidParameter(format!(
            "target size must be finite and > 0, got {h}"
        )));
    }
    let ne = problem.edges.len();
    let mut nmin = Vec::with_capacity(ne);
    for e in &problem.edges {
        if !(e.length.is_finite() && e.length > 0.0) {
            return Err(CompatError::InvalidLength {
                curve: e.id,
                length: e.length,
            });
        }
        let n = match e.min_intervals {
            Some(n) => n as f64,
            None => (e.length / h).round().max(1.0),
        };
        if n.is_nan() || n > MAX_COUNT as f64 {
            return Err(CompatError::CountTooLarge {
                curve: e.id,
                value: n,
                max: MAX_COUNT,
            });
        }
        if n < 1.0 {
            return Err(CompatError::InvalidParameter(format!(
                "edge {}: N_e must be at least 1",
                e.id
            )));
        }
        nmin.push(tolerant_ceil(n) as i64);
    }
    for &(a, b) in &problem.twins {
        if a >= ne || b >= ne || a == b {
            return Err(CompatError::DimensionMismatch(format!(
                "virtual-edge pair ({a}, {b}) is invalid for {ne} edges"
            )));
        }
    }
    // necessary condition: each axis has both directions or none
    for (p, m, name) in [
        (Direction::PlusI, Direction::MinusI, "i"),
        (Direction::PlusJ, Direction::MinusJ, "j"),
    ] {
        let np = problem.edges.iter().filter(|e| e.direction == p).count();
        let nm = problem.edges.iter().filter(|e| e.direction == m).count();
        if (np == 0) != (nm == 0) {
            let ids: Vec<String> = problem
                .edges
                .iter()
                .filter(|e| e.direction == p || e.direction == m)
                .map(|e| e.id.to_string())
                .collect();
            return Err(CompatError::ProgramInfeasible {
                program: "interval assignment (3)",
                reason: format!(
                    "edges {} are all {}{name}: Σ_{{+{name}}} n_e = Σ_{{−{name}}} n_e cannot hold with n_e ≥ 1",
                    ids.join(", "),
                    if np > 0 { "+" } else { "−" }
                ),
            });
        }
    }
    let sign = |d: Direction, axis_i: bool| -> f64 {
        match (d, axis_i) {
            (Direction::PlusI, true) | (Direction::PlusJ, false) => 1.0,
            (Direction::MinusI, true) | (Direction::MinusJ, false) => -1.0,
            _ => 0.0,
        }
    };
    let mut lp = LinearProgram::default();
    for (e, &n) in problem.edges.iter().zip(&nmin) {
        lp.vars.push(VarDef {
            lower: n as f64,
            upper: f64::INFINITY,
            integer: true,
            cost: 1.0 / e.length,
        });
    }
    let mvar = ne;
    if options.include_max_term {
        lp.vars.push(VarDef {
            lower: 0.0,
            upper: f64::INFINITY,
            integer: false,
            cost: 1.0,
        });
    }
    for axis_i in [true, false] {
        let terms: Vec<(usize, f64)> = problem
            .edges
            .iter()
            .enumerate()
            .filter(|(_, e)| sign(e.direction, axis_i) != 0.0)
            .map(|(k, e)| (k, sign(e.direction, axis_i)))
            .collect();
        if !terms.is_empty() {
            lp.rows.push((terms, Sense::Eq, 0.0));
        }
    }
    if options.include_max_term {
        for (k, &n) in nmin.iter().enumerate() {
            lp.rows
                .push((vec![(mvar, n as f64), (k, -1.0)], Sense::Ge, 0.0));
        }
    }
    for &(a, b) in &problem.twins {
        lp.rows.push((vec![(a, 1.0), (b, -1.0)], Sense::Eq, 0.0));
    }
    let verify = |n: &[i64], integral: bool| -> IntervalVerification {
        let sum_axis = |axis_i: bool| -> i128 {
            problem
                .edges
                .iter()
                .zip(n)
                .map(|(e, &v)| sign(e.direction, axis_i) as i128 * v as i128)
                .sum()
        };
        IntervalVerification {
            integral,
            equations_satisfied: sum_axis(true) == 0 && sum_axis(false) == 0,
            bounds_satisfied: n.iter().zip(&nmin).all(|(&v, &l)| v >= l),
            twins_equal: problem.twins.iter().all(|&(a, b)| n[a] == n[b]),
        }
    };
    let finish = |n: Vec<i64>, v: IntervalVerification, fb: bool, rejected: Vec<String>| {
        let max_ratio = n
            .iter()
            .zip(&nmin)
            .map(|(&v, &l)| v as f64 / l as f64)
            .fold(0.0, f64::max);
        let objective = problem
            .edges
            .iter()
            .zip(&n)
            .map(|(e, &v)| v as f64 / e.length)
            .sum::<f64>()
            + if options.include_max_term {
                max_ratio
            } else {
                0.0
            };
        IntervalSolution {
            intervals: n.iter().map(|&v| v as usize).collect(),
            min_intervals: nmin.iter().map(|&v| v as usize).collect(),
            max_ratio,
            objective,
            used_fallback: fb,
            rejected,
            verification: v,
        }
    };
    let mut rejected = Vec::new();
    match lp.solve(options.backend, false, Some(MILP_TIME_LIMIT)) {
        LpOutcome::Solved(x) => {
            let (n, integral) = match round_integral(&x[..ne]) {
                Some(v) => (v, true),
                None => (x[..ne].iter().map(|v| v.round() as i64).collect(), false),
            };
            let v = verify(&n, integral);
            if v.passed() {
                return Ok(finish(n, v, false, rejected));
            }
            rejected.push(format!(
                "MILP ({}) answer failed verification: {v:?}",
                options.backend
            ));
        }
        LpOutcome::Infeasible => {
            rejected.push(format!("MILP ({}) reported infeasible", options.backend))
        }
        LpOutcome::Failed(e) => rejected.push(format!("MILP ({}) failed: {e}", options.backend)),
    }
    // fallback: LP relaxation, round up, repair the two sums on untwinned edges
    let relaxed = match lp.solve(options.backend, true, Some(MILP_TIME_LIMIT)) {
        LpOutcome::Solved(x) => x[..ne].iter().map(|v| (v - 1e-7).ceil() as i64).collect(),
        _ => nmin.clone(),
    };
    let mut n: Vec<i64> = relaxed.iter().zip(&nmin).map(|(&v, &l)| v.max(l)).collect();
    for &(a, b) in &problem.twins {
        let m = n[a].max(n[b]);
        n[a] = m;
        n[b] = m;
    }
    let twinned: Vec<bool> = (0..ne)
        .map(|k| problem.twins.iter().any(|&(a, b)| a == k || b == k))
        .collect();
    for (p, m) in [
        (Direction::PlusI, Direction::MinusI),
        (Direction::PlusJ, Direction::MinusJ),
    ] {
        let total = |d: Direction, n: &[i64]| -> i64 {
            problem
                .edges
                .iter()
                .zip(n)
                .filter(|(e, _)| e.direction == d)
                .map(|(_, &v)| v)
                .sum()
        };
        let diff = total(p, &n) - total(m, &n);
        let target = if diff > 0 { m } else { p };
        // add to the longest untwinned edge of the deficient direction (cheapest by ω_e = 1/l)
        if let Some(k) = (0..ne)
            .filter(|&k| problem.edges[k].direction == target && !twinned[k])
            .max_by(|&a, &b| problem.edges[a].length.total_cmp(&problem.edges[b].length))
        {
            n[k] += diff.abs();
        }
    }
    let v = verify(&n, true);
    if v.passed() {
        return Ok(finish(n, v, true, rejected));
    }
    rejected.push("LP rounding + repair failed verification".into());
    Err(CompatError::SolverFailed { attempts: rejected })
}
