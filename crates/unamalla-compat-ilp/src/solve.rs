//! Problem (5.10): `min Σ m_j` subject to `A m = b`, `m_j ≥ L_j`, pins — solver paths, verification and
//! fallbacks, and the deletion filter that explains infeasibility.

use serde::{Deserialize, Serialize};

use crate::error::{BoundInfo, CompatError, ConflictItem, InfeasibilityReport};
use crate::lp::{round_integral, MilpBackend, Sense};
use crate::model::{Active, FlowOutcome, Instance, Reduced};
use crate::problem::{CompatProblem, LowerBounds, Side};
use crate::system::{block_sizes, BlockSize, CompatSystem, EquationKind};
use crate::verify::{check, Optimality, Verification};

/// Which method to try first. Whatever is chosen, every candidate is verified and the other paths are
/// used as fallbacks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Method {
    /// The MILP of (5.10) in its direct form through `good_lp` (default: `microlp`).
    Milp(MilpBackend),
    /// The exact combinatorial solver (min-cost transshipment on the reduced system, described in the crate
    /// documentation); needs a network-orientable system, otherwise falls back to the MILP paths.
    NetworkFlow,
}

impl Default for Method {
    fn default() -> Self {
        Method::Milp(MilpBackend::Microlp)
    }
}

/// Options of [`solve()`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct SolveOptions {
    /// How the lower bounds are derived (density `d` or target cell size `h`).
    pub bounds: LowerBounds,
    /// First method to try.
    pub method: Method,
    /// Run the deletion filter on infeasible problems to shrink the conflict to an irreducible subset
    /// (otherwise every group is reported).
    pub minimize_conflict: bool,
    /// Time limit in seconds for each MILP call (`None`: no limit). A call that hits the limit counts as a
    /// failed path and the next path is tried.
    pub time_limit: Option<f64>,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            bounds: LowerBounds::Density(1),
            method: Method::default(),
            minimize_conflict: true,
            time_limit: Some(60.0),
        }
    }
}

impl SolveOptions {
    /// Density mode with factor `d` (eq. (5.9)), default method.
    pub fn density(d: usize) -> Self {
        SolveOptions {
            bounds: LowerBounds::Density(d),
            ..Default::default()
        }
    }

    /// Target cell size `h`, default method.
    pub fn cell_size(h: f64) -> Self {
        SolveOptions {
            bounds: LowerBounds::CellSize(h),
            ..Default::default()
        }
    }

    /// Builder: choose the first method.
    pub fn with_method(mut self, method: Method) -> Self {
        self.method = method;
        self
    }

    /// Sets [`bounds`](Self::bounds): how the lower bounds are derived (density `d` or target cell
    /// size `h`).
    #[must_use]
    pub fn bounds(mut self, bounds: LowerBounds) -> Self {
        self.bounds = bounds;
        self
    }

    /// Sets [`minimize_conflict`](Self::minimize_conflict).
    #[must_use]
    pub fn minimize_conflict(mut self, minimize_conflict: bool) -> Self {
        self.minimize_conflict = minimize_conflict;
        self
    }

    /// Sets [`time_limit`](Self::time_limit): time limit in seconds for each MILP call (`None`: no
    /// limit).
    #[must_use]
    pub fn time_limit(mut self, time_limit: Option<f64>) -> Self {
        self.time_limit = time_limit;
        self
    }
}

/// The solver path that produced a returned solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum SolverPath {
    /// MILP of (5.10) as written: one integer variable per curve, all `2n + q` rows.
    DirectMilp(MilpBackend),
    /// MILP of the reduced form (5.11): cut copies merged, pins substituted, `x = m − L ≥ 0`.
    ReducedMilp(MilpBackend),
    /// Exact min-cost transshipment on the reduced, re-signed system.
    NetworkFlow,
    /// LP relaxation of the reduced form, rounding, and a greedy repair on single-row columns.
    LpRoundRepair(MilpBackend),
    /// Target fit ([`crate::solve_fit`]) as a convex-cost min-cost circulation (exact, certified).
    FitNetwork,
    /// Target fit as a MILP with piecewise-linear epigraph rows (systems that are not networks).
    FitMilp(MilpBackend),
}

impl std::fmt::Display for SolverPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SolverPath::DirectMilp(b) => write!(f, "direct MILP ({b})"),
            SolverPath::ReducedMilp(b) => write!(f, "reduced MILP ({b})"),
            SolverPath::NetworkFlow => write!(f, "network flow (exact)"),
            SolverPath::LpRoundRepair(b) => write!(f, "LP relaxation + rounding + repair ({b})"),
            SolverPath::FitNetwork => write!(f, "target fit, convex-cost network flow (exact)"),
            SolverPath::FitMilp(b) => write!(f, "target fit MILP ({b})"),
        }
    }
}

/// A verified solution of problem (5.10).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CompatSolution {
    /// Point counts `m_j`, indexed like [`CompatProblem::curves`].
    pub counts: Vec<usize>,
    /// Objective `Σ m_j`.
    pub objective: u64,
    /// Block sizes `M_k × N_k` (5.5)/(5.6), in block order.
    pub block_sizes: Vec<BlockSize>,
    /// Lower bounds `L_j` in force (pins not applied).
    pub lower_bounds: Vec<usize>,
    /// The path that produced the counts.
    pub path: SolverPath,
    /// Earlier paths that were tried and rejected, with the reason (empty when the first path succeeded).
    pub rejected: Vec<String>,
    /// Outcome of the independent verification of `counts`.
    pub verification: Verification,
}

impl CompatSolution {
    /// Whether a fallback path produced the counts.
    pub fn used_fallback(&self) -> bool {
        !self.rejected.is_empty()
    }

    /// Count of the curve with the given **id**.
    pub fn count_of(&self, problem: &CompatProblem, curve_id: usize) -> Option<usize> {
        problem
            .curves
            .iter()
            .position(|c| c.id == curve_id)
            .map(|j| self.counts[j])
    }
}

/// Everything `solve` derives before trying solver paths.
struct Prepared<'a> {
    problem: &'a CompatProblem,
    system: &'a CompatSystem,
    lower: Vec<i64>,
    pins: Vec<Option<i64>>,
    time_limit: Option<f64>,
}

impl<'a> Prepared<'a> {
    fn instance(&self) -> Instance<'a> {
        Instance {
            system: self.system,
            num_side_rows: 2 * self.problem.blocks.len(),
            cuts: self
                .problem
                .cuts
                .iter()
                .map(|c| (c.first, c.second))
                .collect(),
            lower: self.lower.clone(),
            pins: self.pins.clone(),
            time_limit: self.time_limit,
        }
    }

    fn all_active(&self) -> Active {
        Active::all(
            2 * self.problem.blocks.len(),
            self.problem.cuts.len(),
            self.problem.curves.len(),
        )
    }
}

/// Solve problem (5.10) ([Méndez 2023, §5.2.2]): `min Σ_j m_j` s.t. `A m = b`, `m_j ≥ L_j` (density or cell
/// size, at least 2) and `m_j = pin_j` for pinned curves. The returned counts are verified independently;
/// failed or unverifiable paths fall back to the others (recorded in [`CompatSolution::rejected`]).
///
/// Errors: validation errors of the decomposition, [`CompatError::Infeasible`] with the conflicting
/// blocks/sides/pins, or [`CompatError::SolverFailed`] when no path yields a verified solution.
pub fn solve(
    problem: &CompatProblem,
    options: &SolveOptions,
) -> Result<CompatSolution, CompatError> {
    let system = CompatSystem::assemble(problem)?;
    let lower_us = options.bounds.compute(problem)?;
    let prep = Prepared {
        problem,
        system: &system,
        lower: lower_us.iter().map(|&l| l as i64).collect(),
        pins: problem
            .curves
            .iter()
            .map(|c| c.pinned.map(|p| p as i64))
            .collect(),
        time_limit: options.time_limit,
    };
    let inst = prep.instance();
    let active = prep.all_active();
    let reduced = match inst.reduce(&active) {
        Ok(r) => r,
        Err(_) => return Err(infeasible(&prep, options)),
    };
    let sigma = reduced.orientation();
    // exact solution + certificate when the system is a network matrix
    let exact = sigma
        .as_ref()
        .map(|s| reduced.solve_flow(s, &inst, &active));
    let duals = match &exact {
        Some(FlowOutcome::Optimal { duals, .. }) => Some(duals.clone()),
        _ => None,
    };

    let paths = match options.method {
        Method::Milp(b) => vec![
            SolverPath::DirectMilp(b),
            SolverPath::ReducedMilp(b),
            SolverPath::NetworkFlow,
            SolverPath::LpRoundRepair(b),
        ],
        Method::NetworkFlow => vec![
            SolverPath::NetworkFlow,
            SolverPath::DirectMilp(MilpBackend::Microlp),
            SolverPath::ReducedMilp(MilpBackend::Microlp),
            SolverPath::LpRoundRepair(MilpBackend::Microlp),
        ],
    };
    let mut rejected: Vec<String> = Vec::new();
    let mut infeasible_claims = 0usize;
    for path in paths {
        let raw: Result<Option<(Vec<i64>, bool)>, String> = match path {
            SolverPath::DirectMilp(b) => {
                match direct_program(&prep).solve(b, false, prep.time_limit) {
                    crate::lp::LpOutcome::Solved(x) => Ok(Some(to_ints(&x))),
                    crate::lp::LpOutcome::Infeasible => Ok(None),
                    crate::lp::LpOutcome::Failed(e) => Err(e),
                }
            }
            SolverPath::ReducedMilp(b) => reduced
                .solve_milp(&inst, b, false)
                .map(|o| o.map(|x| to_ints(&x))),
            SolverPath::NetworkFlow => match &exact {
                None => Err("the system is not a network matrix after re-signing rows".into()),
                Some(FlowOutcome::Infeasible) => Ok(None),
                Some(FlowOutcome::Optimal { counts, .. }) => Ok(Some((counts.clone(), true))),
            },
            SolverPath::LpRoundRepair(b) => match reduced.solve_milp(&inst, b, true) {
                Ok(Some(x)) => Ok(Some((repair(&reduced, &x), true))),
                Ok(None) => Ok(None),
                Err(e) => Err(e),
            },
            SolverPath::FitNetwork | SolverPath::FitMilp(_) => {
                Err("the target fit is not a path of problem (5.10)".into())
            }
        };
        match raw {
            Ok(Some((counts, integral))) => {
                let v = check(
                    &system,
                    &prep.lower,
                    &prep.pins,
                    &counts,
                    integral,
                    duals.as_deref(),
                );
                if v.passed() && counts.iter().all(|&m| m >= 2) {
                    let counts: Vec<usize> = counts.iter().map(|&m| m as usize).collect();
                    let objective = counts.iter().map(|&m| m as u64).sum();
                    let sizes = block_sizes(problem, &counts)?;
                    return Ok(CompatSolution {
                        counts,
                        objective,
                        block_sizes: sizes,
                        lower_bounds: lower_us,
                        path,
                        rejected,
                        verification: v,
                    });
                }
                rejected.push(format!(
                    "{path}: rejected by verification: {}",
                    v.failure().unwrap_or_else(|| "count below 2".into())
                ));
            }
            Ok(None) => {
                // An infeasibility claim is accepted when the exact network solver confirms it, or (for
                // non-network systems) when two MILP formulations agree.
                let confirmed = match &exact {
                    Some(FlowOutcome::Infeasible) => true,
                    Some(FlowOutcome::Optimal { .. }) => false,
                    None => {
                        infeasible_claims += 1;
                        infeasible_claims >= 2
                    }
                };
                if confirmed {
                    return Err(infeasible(&prep, options));
                }
                rejected.push(format!("{path}: reported infeasible (not confirmed)"));
            }
            Err(e) => rejected.push(format!("{path}: solver error: {e}")),
        }
    }
    Err(CompatError::SolverFailed { attempts: rejected })
}

/// The infeasibility report of the system with lower bounds `lower` (one per curve, pins from the
/// problem): the deletion filter of [`solve()`], for other objectives over the same constraints.
pub(crate) fn infeasibility(
    problem: &CompatProblem,
    system: &CompatSystem,
    lower: &[i64],
    time_limit: Option<f64>,
) -> CompatError {
    let prep = Prepared {
        problem,
        system,
        lower: lower.to_vec(),
        pins: problem
            .curves
            .iter()
            .map(|c| c.pinned.map(|p| p as i64))
            .collect(),
        time_limit,
    };
    infeasible(&prep, &SolveOptions::default())
}

/// Convert raw values to integers, reporting integrality.
fn to_ints(x: &[f64]) -> (Vec<i64>, bool) {
    match round_integral(x) {
        Some(v) => (v, true),
        None => (
            x.iter()
                .map(|v| if v.is_finite() { v.round() as i64 } else { 0 })
                .collect(),
            false,
        ),
    }
}

/// The MILP of (5.10) exactly as written: variables `m_j` integer, `m_j ≥ L_j` or `m_j = pin_j`,
/// every row of `A m = b`.
fn direct_program(prep: &Prepared<'_>) -> crate::lp::LinearProgram {
    let mut lp = crate::lp::LinearProgram::default();
    for (j, &l) in prep.lower.iter().enumerate() {
        let (lo, hi) = match prep.pins[j] {
            Some(p) => (p as f64, p as f64),
            None => (l as f64, f64::INFINITY),
        };
        lp.vars.push(crate::lp::VarDef {
            lower: lo,
            upper: hi,
            integer: true,
            cost: 1.0,
        });
    }
    for e in &prep.system.equations {
        lp.rows.push((
            e.terms.iter().map(|&(j, a)| (j, a as f64)).collect(),
            Sense::Eq,
            e.rhs as f64,
        ));
    }
    lp
}

/// Round an LP solution (per-curve values) and repair the residuals greedily: for each violated reduced
/// row, raise a free class that appears only in that row and whose coefficient has the needed sign.
/// The result is checked by the caller; this is a heuristic of last resort.
fn repair(reduced: &Reduced, values: &[f64]) -> Vec<i64> {
    let mut counts: Vec<i64> = values.iter().map(|v| v.round() as i64).collect();
    let class_value = |c: &crate::model::Class, counts: &[i64]| counts[c.members[0]];
    // enforce class equality and bounds first
    for c in &reduced.classes {
        let v = c.fixed.unwrap_or_else(|| {
            c.members
                .iter()
                .map(|&j| counts[j])
                .max()
                .unwrap_or(c.lb)
                .max(c.lb)
        });
        for &j in &c.members {
            counts[j] = v;
        }
    }
    for _ in 0..4 {
        let mut changed = false;
        for (r, &rhs) in reduced.rhs.iter().enumerate() {
            let lhs: i64 = reduced
                .classes
                .iter()
                .filter(|c| c.fixed.is_none())
                .flat_map(|c| {
                    c.entries
                        .iter()
                        .filter(|e| e.0 == r)
                        .map(|e| e.1 * (class_value(c, &counts) - c.lb))
                })
                .sum();
            let diff = rhs - lhs;
            if diff == 0 {
                continue;
            }
            if let Some(c) = reduced.classes.iter().find(|c| {
                c.fixed.is_none()
                    && c.entries.len() == 1
                    && c.entries[0].0 == r
                    && c.entries[0].1.signum() == diff.signum()
                    && diff % c.entries[0].1 == 0
            }) {
                let v = class_value(c, &counts) + diff / c.entries[0].1;
                for &j in &c.members {
                    counts[j] = v;
                }
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    counts
}

/// One constraint group of the deletion filter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Group {
    Row(usize),
    Cut(usize),
    Pin(usize),
}

/// Build the infeasibility error: deletion filter over the groups (side equations, cut equations, pins).
fn infeasible(prep: &Prepared<'_>, options: &SolveOptions) -> CompatError {
    let inst = prep.instance();
    let mut active = prep.all_active();
    let mut groups: Vec<Group> = (0..2 * prep.problem.blocks.len()).map(Group::Row).collect();
    groups.extend((0..prep.problem.cuts.len()).map(Group::Cut));
    groups.extend(
        (0..prep.problem.curves.len())
            .filter(|&j| prep.pins[j].is_some())
            .map(Group::Pin),
    );
    let mut irreducible = options.minimize_conflict;
    if options.minimize_conflict {
        let mut keep: Vec<Group> = Vec::new();
        let mut stack: Vec<Vec<Group>> = vec![groups.clone()];
        // chunked deletion filter: try to drop a whole chunk; if the rest becomes feasible, split it
        while let Some(chunk) = stack.pop() {
            set(&mut active, &chunk, false);
            match feasible(&inst, &active) {
                Some(false) => continue, // still infeasible without the chunk: drop it for good
                verdict => {
                    set(&mut active, &chunk, true);
                    if chunk.len() == 1 {
                        if verdict.is_none() {
                            irreducible = false;
                        }
                        keep.push(chunk[0]);
                    } else {
                        let mid = chunk.len() / 2;
                        stack.push(chunk[mid..].to_vec());
                        stack.push(chunk[..mid].to_vec());
                    }
                }
            }
        }
        groups = keep;
    }
    groups.sort_by_key(|g| match *g {
        Group::Row(r) => (0, r),
        Group::Cut(i) => (1, i),
        Group::Pin(j) => (2, j),
    });
    let problem = prep.problem;
    let id = |j: usize| problem.curves[j].id;
    let place = problem.places().unwrap_or_default();
    let mut curves_in_conflict: Vec<usize> = Vec::new();
    let mut pinned_in_conflict: Vec<usize> = Vec::new();
    let conflict: Vec<ConflictItem> = groups
        .iter()
        .map(|g| match *g {
            Group::Row(r) => {
                let eq = &prep.system.equations[r];
                let (k, s1, s2) = match eq.kind {
                    EquationKind::BottomTop { block } => (block, Side::Bottom, Side::Top),
                    EquationKind::RightLeft { block } => (block, Side::Right, Side::Left),
                    EquationKind::Cut { .. } => (0, Side::Bottom, Side::Top),
                };
                let b = &problem.blocks[k];
                curves_in_conflict.extend(b.side(s1).iter().chain(b.side(s2)));
                ConflictItem::SideEquation {
                    block: b.id,
                    first_side: s1,
                    second_side: s2,
                    first_curves: b.side(s1).iter().map(|&j| id(j)).collect(),
                    second_curves: b.side(s2).iter().map(|&j| id(j)).collect(),
                    rhs: eq.rhs,
                }
            }
            Group::Cut(i) => {
                let c = problem.cuts[i];
                curves_in_conflict.extend([c.first, c.second]);
                let pl = |j: usize| {
                    place
                        .get(j)
                        .map(|&(k, s)| (problem.blocks[k].id, s))
                        .unwrap_or((0, Side::Bottom))
                };
                ConflictItem::CutEquation {
                    cut: i + 1,
                    first_curve: id(c.first),
                    second_curve: id(c.second),
                    first_place: pl(c.first),
                    second_place: pl(c.second),
                }
            }
            Group::Pin(j) => {
                pinned_in_conflict.push(j);
                ConflictItem::Pin {
                    curve: id(j),
                    count: prep.pins[j].unwrap_or(0) as usize,
                }
            }
        })
        .collect();
    curves_in_conflict.sort_unstable();
    curves_in_conflict.dedup();
    let bounds = curves_in_conflict
        .into_iter()
        .filter(|j| !pinned_in_conflict.contains(j))
        .map(|j| BoundInfo {
            curve: id(j),
            bound: prep.lower[j] as usize,
        })
        .collect();
    CompatError::Infeasible(InfeasibilityReport {
        conflict,
        bounds,
        irreducible,
    })
}

fn set(active: &mut Active, groups: &[Group], on: bool) {
    for g in groups {
        match *g {
            Group::Row(r) => active.side_rows[r] = on,
            Group::Cut(i) => active.cuts[i] = on,
            Group::Pin(j) => active.pins[j] = on,
        }
    }
}

/// Feasibility of the active groups: `Some(true/false)` when decided, `None` when the MILP failed.
fn feasible(inst: &Instance<'_>, active: &Active) -> Option<bool> {
    match inst.reduce(active) {
        Err(_) => Some(false),
        Ok(r) => r.is_feasible(inst, active),
    }
}

/// Verify user-supplied counts against problem (5.10) with the given bounds (equations, bounds, pins;
/// optimality certified when the system is a network matrix).
pub fn verify_counts(
    problem: &CompatProblem,
    bounds: &LowerBounds,
    counts: &[usize],
) -> Result<Verification, CompatError> {
    let system = CompatSystem::assemble(problem)?;
    if counts.len() != problem.curves.len() {
        return Err(CompatError::DimensionMismatch(format!(
            "{} counts for {} curves",
            counts.len(),
            problem.curves.len()
        )));
    }
    let lower: Vec<i64> = bounds.compute(problem)?.iter().map(|&l| l as i64).collect();
    let prep = Prepared {
        problem,
        system: &system,
        lower,
        pins: problem
            .curves
            .iter()
            .map(|c| c.pinned.map(|p| p as i64))
            .collect(),
        time_limit: None,
    };
    let inst = prep.instance();
    let active = prep.all_active();
    let duals = inst.reduce(&active).ok().and_then(|r| {
        let s = r.orientation()?;
        match r.solve_flow(&s, &inst, &active) {
            FlowOutcome::Optimal { duals, .. } => Some(duals),
            FlowOutcome::Infeasible => None,
        }
    });
    let ints: Vec<i64> = counts
        .iter()
        .map(|&m| i64::try_from(m).unwrap_or(i64::MAX))
        .collect();
    let mut v = check(
        &system,
        &prep.lower,
        &prep.pins,
        &ints,
        true,
        duals.as_deref(),
    );
    if duals.is_none() {
        v.optimality = Optimality::NotCertified {
            reason: "the system is not a network matrix (or is infeasible)".into(),
        };
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::thesis_example_5_1;

    /// The last-resort repair turns a wrong rounded LP point into one that satisfies every equation.
    #[test]
    fn repair_restores_feasibility_of_a_perturbed_point() {
        let problem = thesis_example_5_1();
        let system = CompatSystem::assemble(&problem).unwrap();
        let lower: Vec<i64> = LowerBounds::Density(1)
            .compute(&problem)
            .unwrap()
            .iter()
            .map(|&l| l as i64)
            .collect();
        let prep = Prepared {
            problem: &problem,
            system: &system,
            lower,
            pins: vec![None; 17],
            time_limit: None,
        };
        let inst = prep.instance();
        let reduced = inst.reduce(&prep.all_active()).unwrap();
        // thesis counts with m16 = 4.4 (one too many after rounding) and m1 = 6.3
        let mut x = [6, 6, 6, 6, 8, 6, 6, 6, 8, 8, 6, 4, 8, 8, 8, 3, 6].map(|v| v as f64);
        x[15] = 4.4;
        x[0] = 6.3;
        let counts = repair(&reduced, &x);
        let v = check(&system, &prep.lower, &prep.pins, &counts, true, None);
        assert!(v.equations_satisfied && v.bounds_satisfied, "{counts:?}");
    }

    /// Re-signing: Example 5.1 is a network matrix; a cut with both copies on one side is not.
    #[test]
    fn orientation_detection() {
        let problem = thesis_example_5_1();
        let system = CompatSystem::assemble(&problem).unwrap();
        let prep = Prepared {
            problem: &problem,
            system: &system,
            lower: vec![2; 17],
            pins: vec![None; 17],
            time_limit: None,
        };
        let inst = prep.instance();
        assert!(inst
            .reduce(&prep.all_active())
            .unwrap()
            .orientation()
            .is_some());

        let curves = (1..=5).map(|id| crate::Curve::new(id, 1.0)).collect();
        let doubled = CompatProblem::new(
            curves,
            vec![crate::Block::new(1, vec![0, 1], vec![2], vec![3], vec![4])],
            vec![crate::CutPair::new(0, 1)],
        );
        let system = CompatSystem::assemble(&doubled).unwrap();
        let prep = Prepared {
            problem: &doubled,
            system: &system,
            lower: vec![2; 5],
            pins: vec![None; 5],
            time_limit: None,
        };
        let inst = prep.instance();
        assert!(inst
            .reduce(&prep.all_active())
            .unwrap()
            .orientation()
            .is_none());
    }
}
