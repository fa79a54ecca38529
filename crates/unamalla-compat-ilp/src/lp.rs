//! Thin wrapper over `good_lp`: a backend-independent (MI)LP description and its solution with the
//! selected backend. All returned values are raw solver output; callers verify them.

use good_lp::{
    constraint, variable, Expression, ProblemVariables, ResolutionError, Solution, SolverModel,
    WithTimeLimit,
};
use serde::{Deserialize, Serialize};

/// The MILP backend used through `good_lp`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[non_exhaustive]
pub enum MilpBackend {
    /// Pure-Rust `microlp` (default; always available).
    #[default]
    Microlp,
    /// COIN-OR Cbc (cargo feature `cbc`, needs the system Cbc library).
    #[cfg(feature = "cbc")]
    Cbc,
    /// HiGHS (cargo feature `highs`, needs cmake and C++ to build).
    #[cfg(feature = "highs")]
    Highs,
}

impl std::fmt::Display for MilpBackend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MilpBackend::Microlp => f.write_str("microlp"),
            #[cfg(feature = "cbc")]
            MilpBackend::Cbc => f.write_str("cbc"),
            #[cfg(feature = "highs")]
            MilpBackend::Highs => f.write_str("highs"),
        }
    }
}

/// Time limit (seconds) for the small MILPs (3), (6), (8).
pub(crate) const MILP_TIME_LIMIT: f64 = 60.0;

/// A variable of [`LinearProgram`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct VarDef {
    pub lower: f64,
    pub upper: f64,
    pub integer: bool,
    pub cost: f64,
}

/// Sense of a constraint row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sense {
    Eq,
    Le,
    Ge,
}

/// One constraint row: `(terms, sense, rhs)`.
pub(crate) type Row = (Vec<(usize, f64)>, Sense, f64);

/// `min cost·x` subject to rows and variable bounds.
#[derive(Debug, Clone, Default)]
pub(crate) struct LinearProgram {
    pub vars: Vec<VarDef>,
    pub rows: Vec<Row>,
}

/// Outcome of a backend call.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum LpOutcome {
    /// Raw variable values.
    Solved(Vec<f64>),
    /// The backend reports infeasibility.
    Infeasible,
    /// Any other failure (unbounded, numerical, construction).
    Failed(String),
}

impl LinearProgram {
    /// Solve with `backend`; `relax` drops integrality; `time_limit` in seconds (a solver that stops on
    /// the limit returns its best point, which the caller verifies, or a failure).
    pub fn solve(&self, backend: MilpBackend, relax: bool, time_limit: Option<f64>) -> LpOutcome {
        match backend {
            MilpBackend::Microlp => self.solve_with(good_lp::microlp, relax, time_limit),
            #[cfg(feature = "cbc")]
            MilpBackend::Cbc => self.solve_with(good_lp::coin_cbc, relax, time_limit),
            #[cfg(feature = "highs")]
            MilpBackend::Highs => self.solve_with(good_lp::highs, relax, time_limit),
        }
    }

    fn solve_with<S>(&self, solver: S, relax: bool, time_limit: Option<f64>) -> LpOutcome
    where
        S: good_lp::Solver,
        S::Model: SolverModel<Error = ResolutionError> + WithTimeLimit,
    {
        let mut pv = ProblemVariables::new();
        let vars: Vec<good_lp::Variable> = self
            .vars
            .iter()
            .map(|v| {
                let mut def = variable().min(v.lower);
                if v.upper.is_finite() {
                    def = def.max(v.upper);
                }
                if v.integer && !relax {
                    def = def.integer();
                }
                pv.add(def)
            })
            .collect();
        let mut objective = Expression::from(0.0);
        for (v, d) in vars.iter().zip(&self.vars) {
            if d.cost != 0.0 {
                objective += d.cost * *v;
            }
        }
        let mut model = pv.minimise(objective).using(solver);
        if let Some(t) = time_limit {
            model = model.with_time_limit(t);
        }
        for (terms, sense, rhs) in &self.rows {
            let mut e = Expression::from(0.0);
            for &(j, a) in terms {
                e += a * vars[j];
            }
            let c = match sense {
                Sense::Eq => constraint::eq(e, *rhs),
                Sense::Le => constraint::leq(e, *rhs),
                Sense::Ge => constraint::geq(e, *rhs),
            };
            model.add_constraint(c);
        }
        match model.solve() {
            Ok(sol) => LpOutcome::Solved(vars.iter().map(|&v| sol.value(v)).collect()),
            Err(ResolutionError::Infeasible) => LpOutcome::Infeasible,
            Err(e) => LpOutcome::Failed(e.to_string()),
        }
    }
}

/// Round raw solver values to integers; `None` if a value is not within `1e-6` of an integer or out of
/// the `i64` range.
pub(crate) fn round_integral(values: &[f64]) -> Option<Vec<i64>> {
    values
        .iter()
        .map(|&v| {
            let r = v.round();
            ((v - r).abs() <= 1e-6 && r.abs() < 9.0e15).then_some(r as i64)
        })
        .collect()
}
