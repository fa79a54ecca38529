//! Independent verification of a candidate solution of problem (5.10): exact integer checks of the
//! equations, bounds, pins and integrality, and an optional LP-duality optimality certificate.

use serde::{Deserialize, Serialize};

use crate::system::CompatSystem;

/// Optimality status of a verified solution.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum Optimality {
    /// An integral dual solution `y` of the LP relaxation was checked (dual feasibility `(Aᵀy)_j ≤ 1` for
    /// every non-pinned curve) and its dual objective equals the objective: the counts are optimal.
    Certified {
        /// The dual objective (= the optimal value).
        dual_bound: i128,
    },
    /// A valid dual certificate shows a strictly smaller optimum: the counts are feasible but not optimal.
    Suboptimal {
        /// Objective of the candidate.
        objective: i128,
        /// Proven lower bound on the optimum.
        dual_bound: i128,
    },
    /// The target fit ([`crate::solve_fit`]): row duals `y` were checked to make every class value a
    /// minimiser of its convex cost minus `λ_c x` (the reduced-cost certificate of `fit.rs`), so the
    /// counts minimise the fit's objective.
    FitCertified {
        /// The optimal fit cost `Σ w_j c(m_j; t_j)` (pinned curves excluded).
        cost: i128,
    },
    /// No certificate is available (the system is not a network matrix after re-signing rows); the
    /// solver's own optimality claim is all there is.
    NotCertified {
        /// Why.
        reason: String,
    },
}

/// Outcome of the independent checks.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Verification {
    /// Every raw solver value was within `1e-6` of an integer (always `true` for combinatorial paths).
    pub integral: bool,
    /// Every equation of `A m = b` holds exactly.
    pub equations_satisfied: bool,
    /// Largest `|A m − b|` over the rows.
    pub max_abs_residual: u128,
    /// Every non-pinned count is at least its lower bound `L_j` (and ≥ 2).
    pub bounds_satisfied: bool,
    /// Every pinned count equals its pin.
    pub pins_satisfied: bool,
    /// Optimality status.
    pub optimality: Optimality,
}

impl Verification {
    /// Feasible, integral, and not shown to be sub-optimal.
    pub fn passed(&self) -> bool {
        self.integral
            && self.equations_satisfied
            && self.bounds_satisfied
            && self.pins_satisfied
            && !matches!(self.optimality, Optimality::Suboptimal { .. })
    }

    /// Short description of the first failed check, if any.
    pub fn failure(&self) -> Option<String> {
        if !self.integral {
            Some("non-integral values".into())
        } else if !self.equations_satisfied {
            Some(format!(
                "equations violated (max |A m − b| = {})",
                self.max_abs_residual
            ))
        } else if !self.bounds_satisfied {
            Some("a lower bound is violated".into())
        } else if !self.pins_satisfied {
            Some("a pinned count is not respected".into())
        } else if let Optimality::Suboptimal {
            objective,
            dual_bound,
        } = self.optimality
        {
            Some(format!(
                "not optimal: objective {objective} but a dual certificate proves optimum {dual_bound}"
            ))
        } else {
            None
        }
    }
}

/// Check integer counts against `A m = b`, lower bounds, pins, and (if `duals` are given, one per system
/// row) the duality certificate. `integral` reports whether the raw values were integral.
pub(crate) fn check(
    system: &CompatSystem,
    lower: &[i64],
    pins: &[Option<i64>],
    counts: &[i64],
    integral: bool,
    duals: Option<&[i64]>,
) -> Verification {
    let mut max_res: u128 = 0;
    for e in &system.equations {
        let r: i128 = e
            .terms
            .iter()
            .map(|&(j, a)| a as i128 * counts[j] as i128)
            .sum::<i128>()
            - e.rhs as i128;
        max_res = max_res.max(r.unsigned_abs());
    }
    let mut bounds_ok = true;
    let mut pins_ok = true;
    for j in 0..counts.len() {
        match pins[j] {
            Some(p) => pins_ok &= counts[j] == p,
            None => bounds_ok &= counts[j] >= lower[j] && counts[j] >= 2,
        }
    }
    let objective: i128 = counts.iter().map(|&m| m as i128).sum();
    let optimality = match duals {
        None => Optimality::NotCertified {
            reason: "no dual certificate for this system".into(),
        },
        Some(y) if y.len() != system.equations.len() => Optimality::NotCertified {
            reason: "dual certificate has the wrong length".into(),
        },
        Some(y) => {
            // column sums (Aᵀy)_j
            let mut aty = vec![0i128; counts.len()];
            let mut by: i128 = 0;
            for (e, &yr) in system.equations.iter().zip(y) {
                by += e.rhs as i128 * yr as i128;
                for &(j, a) in &e.terms {
                    aty[j] += a as i128 * yr as i128;
                }
            }
            let mut dual_feasible = true;
            let mut dual = by;
            for j in 0..counts.len() {
                let reduced = 1 - aty[j];
                match pins[j] {
                    Some(p) => dual += p as i128 * reduced,
                    None => {
                        dual_feasible &= reduced >= 0;
                        dual += lower[j].max(2) as i128 * reduced;
                    }
                }
            }
            if !dual_feasible {
                Optimality::NotCertified {
                    reason: "dual certificate is not dual feasible".into(),
                }
            } else if dual == objective {
                Optimality::Certified { dual_bound: dual }
            } else if dual < objective {
                Optimality::Suboptimal {
                    objective,
                    dual_bound: dual,
                }
            } else {
                // dual > primal is impossible for a feasible primal; the primal must be infeasible
                Optimality::NotCertified {
                    reason: "dual bound exceeds the objective (primal infeasible)".into(),
                }
            }
        }
    };
    Verification {
        integral,
        equations_satisfied: max_res == 0,
        max_abs_residual: max_res,
        bounds_satisfied: bounds_ok,
        pins_satisfied: pins_ok,
        optimality,
    }
}
