//! Vertex classification ILPs [Ruiz-Gironés & Sarrate, (6), (8)]. The paper calls `ā_i` "the initially
//! detected classification" without saying whether it is the rounded label or the measured angle, and
//! gives no values for the weights; we take the **measured value** `ā_i = θ_i/(π/2)` and by default `ρ_i = ω_i = 1`,
//! so the cost is the angular deviation, and make the type bounds explicit:
//!
//! ```text
//! min  Σ_i ρ_i D_i + ω_i d_i
//! s.t. Σ_i α_i = 4(1 − H)            (H = 0 gives (6), H ≥ 1 gives (8))
//!      D_i ≥ α_i − ā_i,  d_i ≥ ā_i − α_i,  D_i + d_i ≤ 1,  D_i, d_i ≥ 0,
//!      −2 ≤ α_i ≤ 1,  α_i ∈ Z.
//! ```
//!
//! The per-vertex cost `ρ_i (α_i − ā_i)^+ + ω_i (ā_i − α_i)^+` is convex and separable, so the exact
//! optimum is also obtained by a greedy resource allocation (start every vertex at its lowest admissible
//! label, apply the cheapest unit raises until the sum is reached). That greedy solution is used to
//! **certify** the MILP's objective and as the fallback when the MILP answer fails verification.

use serde::{Deserialize, Serialize};

use crate::error::CompatError;
use crate::lp::{
    round_integral, LinearProgram, LpOutcome, MilpBackend, Sense, VarDef, MILP_TIME_LIMIT,
};

/// Vertex type of the submapping vertex classification ([Ruiz-Gironés & Sarrate, Fig 3]), by integer
/// label.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum VertexKind {
    /// Reversal (Reverso), label −2.
    Reversal,
    /// Corner (Esquina), label −1.
    Corner,
    /// Side (Lado), label 0.
    Side,
    /// End (Final), label +1.
    End,
}

impl VertexKind {
    /// Kind of an integer label in `−2..=1`.
    pub fn from_label(label: i8) -> Option<VertexKind> {
        match label {
            -2 => Some(VertexKind::Reversal),
            -1 => Some(VertexKind::Corner),
            0 => Some(VertexKind::Side),
            1 => Some(VertexKind::End),
            _ => None,
        }
    }
}

/// Options of [`classify_vertices`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct VertexClassOptions {
    /// Number of holes `H` (0: ILP (6); ≥ 1: ILP (8), global sum `4(1 − H)`).
    pub holes: usize,
    /// Weights `ρ_i` of the positive parts (default all 1).
    pub rho: Option<Vec<f64>>,
    /// Weights `ω_i` of the negative parts (default all 1).
    pub omega: Option<Vec<f64>>,
    /// MILP backend.
    pub backend: MilpBackend,
}

impl Default for VertexClassOptions {
    fn default() -> Self {
        VertexClassOptions {
            holes: 0,
            rho: None,
            omega: None,
            backend: MilpBackend::Microlp,
        }
    }
}

impl VertexClassOptions {
    /// Sets [`holes`](Self::holes): number of holes `H` (0: ILP (6); ≥ 1: ILP (8), global sum
    /// `4(1 − H)`).
    #[must_use]
    pub fn holes(mut self, holes: usize) -> Self {
        self.holes = holes;
        self
    }

    /// Sets [`rho`](Self::rho): weights `ρ_i` of the positive parts (default all 1).
    #[must_use]
    pub fn rho(mut self, rho: Option<Vec<f64>>) -> Self {
        self.rho = rho;
        self
    }

    /// Sets [`omega`](Self::omega): weights `ω_i` of the negative parts (default all 1).
    #[must_use]
    pub fn omega(mut self, omega: Option<Vec<f64>>) -> Self {
        self.omega = omega;
        self
    }

    /// Sets [`backend`](Self::backend): MILP backend.
    #[must_use]
    pub fn backend(mut self, backend: MilpBackend) -> Self {
        self.backend = backend;
        self
    }
}

/// Result of the classification.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VertexClassification {
    /// Integer labels `α_i ∈ {−2, −1, 0, 1}`.
    pub labels: Vec<i8>,
    /// Vertex kinds.
    pub kinds: Vec<VertexKind>,
    /// Objective `Σ ρ_i D_i + ω_i d_i`, recomputed from the labels.
    pub cost: f64,
    /// The exact optimum from the greedy certificate.
    pub certified_optimum: f64,
    /// `true` when the MILP answer was rejected and the greedy solution is returned.
    pub used_fallback: bool,
    /// Why earlier attempts were rejected.
    pub rejected: Vec<String>,
}

/// Per-vertex admissible labels `[lo, hi]` (|α − ā| ≤ 1 and −2 ≤ α ≤ 1).
fn admissible(abar: f64) -> (i64, i64) {
    let lo = ((abar - 1.0 - 1e-9).ceil() as i64).max(-2);
    let hi = ((abar + 1.0 + 1e-9).floor() as i64).min(1);
    (lo, hi)
}

fn vertex_cost(alpha: i64, abar: f64, rho: f64, omega: f64) -> f64 {
    let d = alpha as f64 - abar;
    if d > 0.0 {
        rho * d
    } else {
        -omega * d
    }
}

/// Solve ILP (6) (`holes = 0`) or (8) (`holes ≥ 1`) for the real turning values `alpha_real[i] = θ_i/(π/2)`.
pub fn classify_vertices(
    alpha_real: &[f64],
    options: &VertexClassOptions,
) -> Result<VertexClassification, CompatError> {
    let target = 4i64 * (1 - options.holes as i64);
    let program = if options.holes == 0 {
        "vertex classification (6)"
    } else {
        "vertex classification (8)"
    };
    classify_impl(alpha_real, target, program, options)
}

/// The same program with an explicit right-hand side `Σ_i α_i = target` (`options.holes` is ignored).
///
/// This is a **per-loop** variant of (8), our option next to the paper's global sum (the paper constrains
/// only the sum over all loops): the outer loop alone gets `target = 4` (program (6)) and each hole loop alone gets
/// `target = −4` (its straight-edge turning sum with the domain on the left is `−2π`).
///
/// ```
/// use unamalla_compat_ilp::{classify_vertices_to_sum, VertexClassOptions, VertexKind};
/// // a square hole traversed clockwise: four turns of −π/2
/// let c = classify_vertices_to_sum(&[-1.0; 4], -4, &VertexClassOptions::default())?;
/// assert_eq!(c.kinds, vec![VertexKind::Corner; 4]);
/// assert_eq!(c.cost, 0.0);
/// # Ok::<(), unamalla_compat_ilp::CompatError>(())
/// ```
pub fn classify_vertices_to_sum(
    alpha_real: &[f64],
    target: i64,
    options: &VertexClassOptions,
) -> Result<VertexClassification, CompatError> {
    classify_impl(
        alpha_real,
        target,
        "vertex classification (per-loop sum)",
        options,
    )
}

fn classify_impl(
    alpha_real: &[f64],
    target: i64,
    program: &'static str,
    options: &VertexClassOptions,
) -> Result<VertexClassification, CompatError> {
    let n = alpha_real.len();
    if n == 0 {
        return Err(CompatError::InvalidParameter("no vertices".into()));
    }
    if let Some((i, a)) = alpha_real.iter().enumerate().find(|(_, a)| !a.is_finite()) {
        return Err(CompatError::InvalidParameter(format!(
            "vertex {i}: α = {a} is not finite"
        )));
    }
    let weights = |w: &Option<Vec<f64>>, name: &str| -> Result<Vec<f64>, CompatError> {
        match w {
            None => Ok(vec![1.0; n]),
            Some(v) if v.len() != n => Err(CompatError::DimensionMismatch(format!(
                "{} {name} weights for {n} vertices",
                v.len()
            ))),
            Some(v) if v.iter().any(|x| !(x.is_finite() && *x >= 0.0)) => Err(
                CompatError::InvalidParameter(format!("{name} weights must be finite and ≥ 0")),
            ),
            Some(v) => Ok(v.clone()),
        }
    };
    let rho = weights(&options.rho, "ρ")?;
    let omega = weights(&options.omega, "ω")?;
    let ranges: Vec<(i64, i64)> = alpha_real.iter().map(|&a| admissible(a)).collect();
    if let Some(i) = ranges.iter().position(|&(lo, hi)| lo > hi) {
        return Err(CompatError::ProgramInfeasible {
            program: "vertex classification",
            reason: format!(
                "vertex {i}: α = {} has no admissible label in −2..=1 within distance 1",
                alpha_real[i]
            ),
        });
    }
    let lo_sum: i64 = ranges.iter().map(|r| r.0).sum();
    let hi_sum: i64 = ranges.iter().map(|r| r.1).sum();
    if target < lo_sum || target > hi_sum {
        return Err(CompatError::ProgramInfeasible {
            program,
            reason: format!(
                "Σ α_i must be {target}, but the admissible labels (|α_i − ā_i| ≤ 1, −2 ≤ α_i ≤ 1) only reach {lo_sum}..={hi_sum} with {n} vertices"
            ),
        });
    }
    // exact greedy: all at lo, then cheapest unit raises (ties: smallest index)
    let mut greedy: Vec<i64> = ranges.iter().map(|r| r.0).collect();
    let mut raises: Vec<(f64, usize, i64)> = Vec::new();
    for i in 0..n {
        for a in ranges[i].0..ranges[i].1 {
            let inc = vertex_cost(a + 1, alpha_real[i], rho[i], omega[i])
                - vertex_cost(a, alpha_real[i], rho[i], omega[i]);
            raises.push((inc, i, a));
        }
    }
    raises.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
    for &(_, i, _) in raises.iter().take((target - lo_sum) as usize) {
        greedy[i] += 1;
    }
    let total_cost = |labels: &[i64]| -> f64 {
        labels
            .iter()
            .enumerate()
            .map(|(i, &a)| vertex_cost(a, alpha_real[i], rho[i], omega[i]))
            .sum()
    };
    let best = total_cost(&greedy);

    // MILP (6)/(8): variables α_i (integer), D_i, d_i
    let mut lp = LinearProgram::default();
    for _ in 0..n {
        lp.vars.push(VarDef {
            lower: -2.0,
            upper: 1.0,
            integer: true,
            cost: 0.0,
        });
    }
    for i in 0..n {
        lp.vars.push(VarDef {
            lower: 0.0,
            upper: f64::INFINITY,
            integer: false,
            cost: rho[i],
        });
        lp.vars.push(VarDef {
            lower: 0.0,
            upper: f64::INFINITY,
            integer: false,
            cost: omega[i],
        });
    }
    let dp = |i: usize| n + 2 * i;
    let dm = |i: usize| n + 2 * i + 1;
    lp.rows
        .push(((0..n).map(|i| (i, 1.0)).collect(), Sense::Eq, target as f64));
    for (i, &abar) in alpha_real.iter().enumerate() {
        lp.rows
            .push((vec![(dp(i), 1.0), (i, -1.0)], Sense::Ge, -abar));
        lp.rows
            .push((vec![(dm(i), 1.0), (i, 1.0)], Sense::Ge, abar));
        lp.rows
            .push((vec![(dp(i), 1.0), (dm(i), 1.0)], Sense::Le, 1.0));
    }
    let mut rejected = Vec::new();
    let tol = 1e-7 * (1.0 + best.abs());
    match lp.solve(options.backend, false, Some(MILP_TIME_LIMIT)) {
        LpOutcome::Solved(x) => match round_integral(&x[..n]) {
            Some(labels) => {
                let ok_range = labels
                    .iter()
                    .zip(&ranges)
                    .all(|(&a, &(lo, hi))| a >= lo && a <= hi);
                let ok_sum = labels.iter().sum::<i64>() == target;
                let cost = total_cost(&labels);
                if ok_range && ok_sum && cost <= best + tol {
                    return Ok(build(labels, cost, best, false, rejected));
                }
                rejected.push(format!(
                    "MILP ({}) answer rejected: in range {ok_range}, sum ok {ok_sum}, cost {cost} vs certified optimum {best}",
                    options.backend
                ));
            }
            None => rejected.push(format!(
                "MILP ({}) returned non-integral labels",
                options.backend
            )),
        },
        LpOutcome::Infeasible => rejected.push(format!(
            "MILP ({}) reported infeasible, but a feasible classification exists",
            options.backend
        )),
        LpOutcome::Failed(e) => rejected.push(format!("MILP ({}) failed: {e}", options.backend)),
    }
    Ok(build(greedy, best, best, true, rejected))
}

fn build(
    labels: Vec<i64>,
    cost: f64,
    best: f64,
    fallback: bool,
    rejected: Vec<String>,
) -> VertexClassification {
    let labels: Vec<i8> = labels.iter().map(|&a| a as i8).collect();
    VertexClassification {
        kinds: labels
            .iter()
            .map(|&a| VertexKind::from_label(a).unwrap_or(VertexKind::Side))
            .collect(),
        labels,
        cost,
        certified_optimum: best,
        used_fallback: fallback,
        rejected,
    }
}
