//! How the fast evaluator runs a [`KernelExpr`]: the expression is inspected once (when the
//! functional is built or its kernel replaced) and turned into a [`Plan`], a kernel the
//! monomorphized lane evaluator ([`super::lanes`]) runs:
//!
//! * [`Plan::AoHOmega`]: `w₁F_AO + w₂H_ω` without cell weights ([Méndez 2023, (6.8)], the default
//!   smoother): the fused two-leaf kernel [`Pair`], in which both leaves are inlined;
//! * [`Plan::General`]: any other expression, by its own recursive evaluation (one `match` per
//!   node, term and cell, [`ExprKernel`]).
//!
//! Both perform, per leg pair, the arithmetic of the expression's definition
//! ([`crate::kernel::expr`]): for a sum, an accumulator starting at 0 receives `wᵢ·Eᵢ` in term
//! order (for two terms the order does not change the result: `0 + x + y = 0 + y + x` in
//! IEEE arithmetic), so the results do not depend on the plan, bit for bit.

use crate::kernel::{
    axpy4, axpy_lanes, sparsity_or, wants, AreaOrthogonality, CornerLanes, HOmega, KernelExpr,
    LaneGrad, LanePartials, Leaf, Order, Partials, Terms, TriKernel, TriScalars,
};

/// `wa·a + wb·b` of two typed kernels, combined lane-wise so that the sum is one straight-line,
/// vectorizable computation.
#[derive(Debug, Clone)]
pub(crate) struct Pair<A, B> {
    /// Weight of `a`.
    pub wa: f64,
    /// First kernel.
    pub a: A,
    /// Weight of `b`.
    pub wb: f64,
    /// Second kernel.
    pub b: B,
}

impl<A: TriKernel, B: TriKernel> TriKernel for Pair<A, B> {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        sparsity_or(self.a.hessian_sparsity(), self.b.hessian_sparsity())
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let mut p = Partials::default();
        if wants(&self.a, s) {
            let q = self.a.eval(s, order);
            p.add_scaled(self.wa, &q, order);
        }
        if wants(&self.b, s) {
            let q = self.b.eval(s, order);
            p.add_scaled(self.wb, &q, order);
        }
        p
    }
    fn terms(&self) -> Terms {
        self.a.terms().or(self.b.terms())
    }
    #[inline(always)]
    fn value(&self, s: &TriScalars) -> f64 {
        let mut v = 0.0;
        if wants(&self.a, s) {
            v += self.wa * self.a.value(s);
        }
        if wants(&self.b, s) {
            v += self.wb * self.b.value(s);
        }
        v
    }
    #[inline(always)]
    fn value_grad(&self, s: &TriScalars) -> (f64, [f64; 4]) {
        let mut acc = (0.0, [0.0; 4]);
        if wants(&self.a, s) {
            axpy4(&mut acc, self.wa, self.a.value_grad(s));
        }
        if wants(&self.b, s) {
            axpy4(&mut acc, self.wb, self.b.value_grad(s));
        }
        acc
    }
    #[inline(always)]
    fn corners_value(&self, s: &CornerLanes) -> [f64; 4] {
        let mut acc = [0.0; 4];
        if self.a.terms().corners {
            axpy_lanes(&mut acc, self.wa, self.a.corners_value(s));
        }
        if self.b.terms().corners {
            axpy_lanes(&mut acc, self.wb, self.b.corners_value(s));
        }
        acc
    }
    #[inline(always)]
    fn corners_value_grad(&self, s: &CornerLanes) -> LaneGrad {
        let mut acc = LaneGrad::default();
        if self.a.terms().corners {
            acc.add_scaled(self.wa, &self.a.corners_value_grad(s));
        }
        if self.b.terms().corners {
            acc.add_scaled(self.wb, &self.b.corners_value_grad(s));
        }
        acc
    }
    #[inline(always)]
    fn corners_hessian(&self, s: &CornerLanes) -> LanePartials {
        let mut acc = LanePartials::default();
        if self.a.terms().corners {
            let m = self.a.hessian_sparsity();
            acc.add_scaled_masked(self.wa, &self.a.corners_hessian(s), &m);
        }
        if self.b.terms().corners {
            let m = self.b.hessian_sparsity();
            acc.add_scaled_masked(self.wb, &self.b.corners_hessian(s), &m);
        }
        acc
    }
}

/// The general plan: the expression's own (recursive) evaluation, with the leg pairs and the
/// Hessian sparsity of the whole expression computed once.
#[derive(Debug, Clone)]
pub(crate) struct ExprKernel {
    expr: KernelExpr,
    terms: Terms,
    sparsity: [[bool; 4]; 4],
}

impl ExprKernel {
    pub(crate) fn new(e: &KernelExpr) -> Self {
        Self {
            expr: e.clone(),
            terms: e.terms(),
            sparsity: e.hessian_sparsity(),
        }
    }
}

impl TriKernel for ExprKernel {
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        self.expr.eval(s, order)
    }
    #[inline(always)]
    fn terms(&self) -> Terms {
        self.terms
    }
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        self.sparsity
    }
    #[inline(always)]
    fn value(&self, s: &TriScalars) -> f64 {
        self.expr.value(s)
    }
    #[inline(always)]
    fn value_grad(&self, s: &TriScalars) -> (f64, [f64; 4]) {
        self.expr.value_grad(s)
    }
    #[inline(always)]
    fn corners_value(&self, s: &CornerLanes) -> [f64; 4] {
        self.expr.corners_value(s)
    }
    #[inline(always)]
    fn corners_value_grad(&self, s: &CornerLanes) -> LaneGrad {
        self.expr.corners_value_grad(s)
    }
    #[inline(always)]
    fn corners_hessian(&self, s: &CornerLanes) -> LanePartials {
        self.expr.corners_hessian(s)
    }
}

/// How the fast path evaluates the [`KernelExpr`] of a [`QuadFunctional`](crate::QuadFunctional)
/// (module docs).
#[derive(Debug, Clone)]
pub(crate) enum Plan {
    /// `w₁F_AO + w₂H_ω` ([Méndez 2023, (6.8)]), fused.
    AoHOmega(Pair<AreaOrthogonality, HOmega>),
    /// Any other expression.
    General(ExprKernel),
}

impl Plan {
    /// The plan of `e`: the fused kernel if `e` is exactly `w₁F_AO + w₂H_ω` (in either order,
    /// no cell weights), the general one otherwise.
    pub(crate) fn for_expr(e: &KernelExpr) -> Plan {
        if let KernelExpr::Sum(v) = e {
            if let [(w1, KernelExpr::Leaf(k1)), (w2, KernelExpr::Leaf(k2))] = v.as_slice() {
                match (k1, k2) {
                    (Leaf::AreaOrthogonality(_), Leaf::HOmega(h)) => {
                        return Plan::AoHOmega(Pair {
                            wa: *w1,
                            a: AreaOrthogonality,
                            wb: *w2,
                            b: *h,
                        })
                    }
                    (Leaf::HOmega(h), Leaf::AreaOrthogonality(_)) => {
                        return Plan::AoHOmega(Pair {
                            wa: *w2,
                            a: AreaOrthogonality,
                            wb: *w1,
                            b: *h,
                        })
                    }
                    _ => {}
                }
            }
        }
        Plan::General(ExprKernel::new(e))
    }
}
