//! Every [`Problem`] as an [argmin](https://argmin-rs.org) problem (feature `argmin`, on by
//! default).
//!
//! [`ArgminProblem`] implements argmin's [`CostFunction`](argmin::core::CostFunction),
//! [`Gradient`](argmin::core::Gradient) and [`Hessian`](argmin::core::Hessian) for any
//! functional of `unamalla-functionals` (quad and hex functionals alike, and any user type that
//! implements the capability traits), each from the matching capability: argmin's cost from
//! [`Cost`], its gradient from [`Gradient`], its Hessian from [`Hessian`] (all three also use
//! [`Variables`] for the length check and [`ElementMeasures`] for the convexity guard), so a
//! problem without a Hessian still runs argmin's L-BFGS. The parameter vector is the problem's variable vector `Vec<f64>`
//! (free-node coordinates interleaved, see [`Problem`]) and the Hessian is a
//! [`SparseHessian`], the assembled CSR matrix, which is the operator argmin's Newton-CG and
//! Steihaug trust-region subproblem multiply with (`ArgminDot<Vec<f64>, Vec<f64>>`). So a user
//! can run argmin's `LBFGS`, `NewtonCG` and `TrustRegion<Steihaug>` on our functionals, e.g.
//!
//! ```
//! use std::sync::Arc;
//! use argmin::core::{Executor, State};
//! use argmin::solver::linesearch::{condition::ArmijoCondition, BacktrackingLineSearch};
//! use argmin::solver::quasinewton::LBFGS;
//! use unamalla_functionals::{QuadFunctional, QuadTopology, Smoothness};
//! use unamalla_optim::argmin_adapter::ArgminProblem;
//! use unamalla_optim::fixtures::sinusoidal;
//!
//! let grid = sinusoidal(12, 12, 0.05, 1.0).unwrap();
//! let topo = Arc::new(QuadTopology::from_mesh(&grid).unwrap());
//! let x0 = topo.initial_x();
//! let winslow = QuadFunctional::new(topo, Smoothness::new());
//! // cost = +∞ at trial points with a non-convex cell: argmin's backtracking rejects them
//! let problem = ArgminProblem::with_convexity_guard(&winslow, &x0, 0.0).unwrap();
//! let ls = BacktrackingLineSearch::new(ArmijoCondition::new(1e-4).unwrap());
//! let res = Executor::new(problem, LBFGS::new(ls, 5))
//!     .configure(|s| s.param(x0).max_iters(50))
//!     .run()
//!     .unwrap();
//! assert!(res.problem.problem.as_ref().unwrap().is_convex(res.state.get_best_param().unwrap()));
//! ```
//!
//! ## The convexity guard, and why argmin's solvers need it
//! Our solvers ([`crate::solver`]) keep a convex start convex: trial points with a non-convex
//! cell are rejected inside the line search and the trust region (fraction-to-the-boundary step
//! plus bisection, see the crate docs). argmin's solvers have no such hook. Without a guard
//! ([`ArgminProblem::new`]) a functional such as Winslow's `l/α` (finite and *negative* for
//! `α < 0`, Winslow 1966; Knupp & Steinberg 1993, §8) can be decreased by jumping over the
//! pole at `α = 0`, and a quasi-Newton line search happily accepts the folded point. With
//! [`ArgminProblem::with_convexity_guard`] the cost is `+∞` at every point whose smallest
//! measure (α of a corner triangle, or the Jacobian of a tetrahedron) among the elements with
//! a free vertex is at or below the threshold. argmin 0.11 reacts to that as follows (tested in
//! `tests/argmin.rs`):
//! * `BacktrackingLineSearch` with the Armijo condition (Nocedal & Wright 2006, Alg. 3.1)
//!   treats `+∞` as "not sufficient decrease" and shortens the step: L-BFGS and Newton-CG with
//!   it keep a convex start convex;
//! * `TrustRegion` (Nocedal & Wright 2006, Alg. 4.1) gets `ρ = −∞`, rejects the step and
//!   shrinks the radius: it stays convex as well;
//! * `MoreThuenteLineSearch` (Moré & Thuente 1994) returns an error ("NaN or Inf encountered
//!   during iteration") when a trial value is infinite instead of shortening the step, so it is
//!   not usable with the guard; without the guard it can accept a folded point.
//!
//! What the adapter cannot give argmin: its `NewtonCG` has no preconditioner and no limit on
//! the inner CG iterations, and its `TrustRegion` uses the Euclidean norm (our TN-TR uses the
//! preconditioner's norm); see docs/benchmarks.md for the timing comparison.

use std::sync::OnceLock;

#[cfg(doc)]
use unamalla_functionals::Problem;
use unamalla_functionals::{Cost, Csr, ElementMeasures, Gradient, Hessian, Variables};

use crate::monitor::{NullObserver, Session};

/// Errors of the adapter (returned to argmin as its `Error`, which wraps any `std::error::Error`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ArgminAdapterError {
    /// A parameter vector of the wrong length was passed.
    #[error("the parameter vector has {got} entries, the problem has {expected} variables")]
    WrongLength {
        /// Entries of the vector passed.
        got: usize,
        /// [`Variables::num_vars`].
        expected: usize,
    },
    /// The guard's start point is not strictly inside the guard's admissible set.
    #[error(
        "the start point is not admissible for the convexity guard: smallest measure {min} \
         ≤ threshold {threshold}"
    )]
    StartNotAdmissible {
        /// Smallest measure over the elements with a free vertex.
        min: f64,
        /// The guard's threshold.
        threshold: f64,
    },
}

/// A [`Problem`] (or a part of one, see the [module docs](self)) seen through argmin's traits.
#[derive(Debug, Clone)]
pub struct ArgminProblem<'a, P: Variables + ElementMeasures + ?Sized> {
    problem: &'a P,
    /// The Hessian pattern, built at the first Hessian evaluation.
    pattern: OnceLock<Csr>,
    guard: Option<Guard>,
}

/// The convexity guard: which elements count and the threshold.
#[derive(Debug, Clone)]
struct Guard {
    /// `true` for the elements with at least one free vertex (all-fixed elements are boundary
    /// data: nothing a solver does can change them).
    mask: Vec<bool>,
    threshold: f64,
}

/// The assembled Hessian at one point: the operator argmin multiplies with
/// (`ArgminDot<Vec<f64>, Vec<f64>>`, a parallel CSR product, bit-identical for any number of
/// threads).
#[derive(Debug, Clone, PartialEq)]
pub struct SparseHessian(pub Csr);

impl argmin_math::ArgminDot<Vec<f64>, Vec<f64>> for SparseHessian {
    fn dot(&self, v: &Vec<f64>) -> Vec<f64> {
        let mut out = vec![0.0; self.0.nrows];
        self.0.mul_vec(v, &mut out);
        out
    }
}

impl<'a, P: Variables + ElementMeasures + ?Sized> ArgminProblem<'a, P> {
    /// The plain problem: cost, gradient and Hessian of `problem` (as far as it has them), no
    /// convexity guard.
    pub fn new(problem: &'a P) -> Self {
        Self {
            problem,
            pattern: OnceLock::new(),
            guard: None,
        }
    }

    /// The problem with the convexity guard: [`CostFunction::cost`](argmin::core::CostFunction::cost) is `+∞` wherever the
    /// smallest measure over the elements with a free vertex is `≤ threshold` (0 for convex,
    /// `ε·ᾱ` for ε-convex). The elements with a free vertex are found at `x0` as the solvers'
    /// [`Session`] finds them (by perturbing the free variables).
    ///
    /// # Errors
    /// [`ArgminAdapterError::WrongLength`] if `x0` has the wrong length,
    /// [`ArgminAdapterError::StartNotAdmissible`] if `x0` itself is not above the threshold.
    pub fn with_convexity_guard(
        problem: &'a P,
        x0: &[f64],
        threshold: f64,
    ) -> Result<Self, ArgminAdapterError> {
        let mut me = Self::new(problem);
        me.check_len(x0)?;
        let mut obs = NullObserver;
        let session = Session::new(problem, x0, &mut obs);
        me.guard = Some(Guard {
            mask: session.mask().to_vec(),
            threshold,
        });
        let min = me.masked_min(x0);
        if min.is_nan() || min <= threshold {
            return Err(ArgminAdapterError::StartNotAdmissible { min, threshold });
        }
        Ok(me)
    }

    /// The wrapped problem.
    pub fn problem(&self) -> &'a P {
        self.problem
    }

    /// Smallest measure at `x` over the elements with a free vertex (over all elements if
    /// there is no guard); NaN measures give NaN.
    pub fn masked_min(&self, x: &[f64]) -> f64 {
        let mut meas = vec![0.0; self.problem.num_elements()];
        self.problem.element_measures(x, &mut meas);
        let mut min = f64::INFINITY;
        for (k, &v) in meas.iter().enumerate() {
            if self.guard.as_ref().is_none_or(|g| g.mask[k]) {
                if v.is_nan() {
                    return f64::NAN;
                }
                min = min.min(v);
            }
        }
        min
    }

    /// Whether every element with a free vertex has a positive measure at `x` (every cell of a
    /// quad mesh convex, every tetrahedron of a hex mesh positively oriented).
    pub fn is_convex(&self, x: &[f64]) -> bool {
        self.masked_min(x) > 0.0
    }

    fn check_len(&self, x: &[f64]) -> Result<(), ArgminAdapterError> {
        let expected = self.problem.num_vars();
        if x.len() != expected {
            return Err(ArgminAdapterError::WrongLength {
                got: x.len(),
                expected,
            });
        }
        Ok(())
    }
}

impl<P: Variables + Cost + ElementMeasures + ?Sized> argmin::core::CostFunction
    for ArgminProblem<'_, P>
{
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, x: &Vec<f64>) -> Result<f64, argmin::core::Error> {
        self.check_len(x)?;
        if let Some(g) = &self.guard {
            let min = self.masked_min(x);
            if min.is_nan() || min <= g.threshold {
                return Ok(f64::INFINITY);
            }
        }
        Ok(self.problem.value(x))
    }
}

impl<P: Variables + Gradient + ElementMeasures + ?Sized> argmin::core::Gradient
    for ArgminProblem<'_, P>
{
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;

    fn gradient(&self, x: &Vec<f64>) -> Result<Vec<f64>, argmin::core::Error> {
        self.check_len(x)?;
        let mut g = vec![0.0; x.len()];
        self.problem.value_grad(x, &mut g);
        Ok(g)
    }
}

impl<P: Variables + Hessian + ElementMeasures + ?Sized> argmin::core::Hessian
    for ArgminProblem<'_, P>
{
    type Param = Vec<f64>;
    type Hessian = SparseHessian;

    fn hessian(&self, x: &Vec<f64>) -> Result<SparseHessian, argmin::core::Error> {
        self.check_len(x)?;
        let mut h = self
            .pattern
            .get_or_init(|| self.problem.hessian_pattern())
            .clone();
        self.problem.hessian(x, &mut h);
        Ok(SparseHessian(h))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use argmin::core::{CostFunction, Gradient, Hessian};
    use argmin_math::ArgminDot;
    use std::sync::Arc;
    use unamalla_functionals::{Length, QuadFunctional, QuadTopology};
    use unamalla_mesh::{DVec2, StructuredGrid2};

    /// 3 × 3 nodes of the unit square, the middle node free at `(a, b)`.
    fn one_free_node() -> (QuadFunctional, Vec<f64>) {
        let g = StructuredGrid2::from_fn(3, 3, |i, j| DVec2::new(i as f64 * 0.5, j as f64 * 0.5))
            .unwrap();
        let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
        let x0 = topo.initial_x();
        (QuadFunctional::new(topo, Length), x0)
    }

    #[test]
    fn length_functional_through_the_adapter() {
        // Length: Σ over the 16 corner triangles of |a|² + |b|²; every interior edge (4 of
        // them, from the free node p to the edge midpoints m_k) is a leg of 4 corner
        // triangles, so F(p) = 4 Σ_k |m_k − p|² + const, ∇F = 8 Σ_k (p − m_k) = 32 (p − c)
        // with c = (0.5, 0.5), ∇²F = 32 I.
        let (f, x0) = one_free_node();
        assert_eq!(x0, vec![0.5, 0.5]);
        let p = ArgminProblem::new(&f);
        let x = vec![0.6, 0.45];
        let g = p.gradient(&x).unwrap();
        assert!((g[0] - 32.0 * 0.1).abs() < 1e-12 && (g[1] + 32.0 * 0.05).abs() < 1e-12);
        let h = p.hessian(&x).unwrap();
        let hv = h.dot(&vec![1.0, -2.0]);
        assert!((hv[0] - 32.0).abs() < 1e-12 && (hv[1] + 64.0).abs() < 1e-12);
        // F(x) − F(c) = 16 |x − c|² = 16 · 0.0125
        let d = p.cost(&x).unwrap() - p.cost(&x0).unwrap();
        assert!((d - 0.2).abs() < 1e-12);
        assert!(matches!(
            p.cost(&vec![0.0; 3])
                .unwrap_err()
                .downcast_ref::<ArgminAdapterError>(),
            Some(ArgminAdapterError::WrongLength {
                got: 3,
                expected: 2
            })
        ));
    }

    #[test]
    fn guard_gives_infinity_outside_the_convex_set() {
        let (f, x0) = one_free_node();
        let p = ArgminProblem::with_convexity_guard(&f, &x0, 0.0).unwrap();
        // the free node pushed beyond the right edge midpoint (1, 0.5) folds the cells
        assert_eq!(p.cost(&vec![1.2, 0.5]).unwrap(), f64::INFINITY);
        assert!(!p.is_convex(&[1.2, 0.5]));
        assert!(p.cost(&vec![0.7, 0.4]).unwrap().is_finite());
        // a folded start is refused
        assert!(matches!(
            ArgminProblem::with_convexity_guard(&f, &[1.2, 0.5], 0.0),
            Err(ArgminAdapterError::StartNotAdmissible { .. })
        ));
    }
}
