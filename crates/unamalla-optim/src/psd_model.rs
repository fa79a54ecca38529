//! [`PsdModel`]: the PSD-projected model Hessian of `unamalla_functionals::quad::psd`
//! ([`HessianMode::ProjectedPsd`]) as a [`Hessian`] over a borrowed quad functional.
//!
//! It implements [`Hessian`] only: the problem a solver minimizes is
//! [`WithHessian`]`::new(&f, PsdModel::new(&f, mode))`, which takes every other capability
//! (variables, value, gradient, local models, element measures) from `f` itself. Value and
//! gradient are therefore the functional's own (exact), so every solver still minimizes the
//! same `F` and the stopping tests (FTOL, GTOL) mean the same; only the quadratic model of
//! truncated Newton changes: `m(z) = F + gᵀz + ½ zᵀ H⁺ z` with `H⁺ = Σ_T Pᵀ_T (H_u,T)⁺ P_T`
//! (each corner triangle's 4×4 leg Hessian with its negative eigenvalues clamped to 0). `H⁺` is
//! PSD, so preconditioned CG on it never meets negative curvature, the multigrid hierarchy is
//! built on a semidefinite operator, and a step of the model is a descent direction.
//!
//! The model is a [`Hessian`] implementation combined by [`WithHessian`] rather than a second
//! Hessian argument of the solvers: the solvers, the session and the drivers keep seeing one
//! problem per run, and a model changes no solver signature.
//!
//! [`Hessian::hess_vec`] stays the exact product (it is only used in
//! [`HessianMode::MatrixFree`], where no model is assembled).

use unamalla_functionals::quad::psd::PsdProjection;
use unamalla_functionals::{Csr, Hessian, QuadFunctional};

#[cfg(doc)]
use crate::solver::HessianMode;
#[cfg(doc)]
use unamalla_functionals::WithHessian;

/// The PSD-projected model Hessian of a borrowed quad functional (module docs); combine it
/// with the functional by [`WithHessian`].
#[derive(Debug, Clone, Copy)]
pub struct PsdModel<'a> {
    f: &'a QuadFunctional,
    mode: PsdProjection,
}

impl<'a> PsdModel<'a> {
    /// The model Hessian of `f`; `mode` chooses clamping (default) or absolute values of the
    /// negative eigenvalues.
    pub fn new(f: &'a QuadFunctional, mode: PsdProjection) -> Self {
        Self { f, mode }
    }
}

impl Hessian for PsdModel<'_> {
    /// The functional's pattern (the projection keeps every corner triangle's 4×4 block).
    fn hessian_pattern(&self) -> Csr {
        self.f.hessian_pattern()
    }
    /// `H⁺` at `x` ([`QuadFunctional::hessian_psd`]).
    fn hessian(&self, x: &[f64], h: &mut Csr) {
        self.f.hessian_psd(x, h, self.mode);
    }
    /// The exact product `∇²F(x) v` (module docs).
    fn hess_vec(&self, x: &[f64], v: &[f64], out: &mut [f64]) {
        self.f.hess_vec(x, v, out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::sinusoidal;
    use crate::Solver;
    use crate::{smooth, HessianMode, NullObserver, Preconditioner, SmoothOptions, SolverOptions};
    use unamalla_functionals::WithHessian;

    fn opts(hessian: HessianMode) -> SmoothOptions {
        SmoothOptions {
            solver: SolverOptions {
                max_iter: 400,
                ftol: 1e-12,
                gtol: 1e-7,
                preconditioner: Preconditioner::Multigrid,
                hessian,
                ..SolverOptions::new(Solver::TnTr)
            },
            ..SmoothOptions::default()
        }
    }

    #[test]
    fn same_minimum_as_the_exact_hessian_and_convex() {
        // both runs minimize the same (6.8) F from the same convex TFI grid: the model changes
        // only the path, so the minima agree (to the tolerance) and stay ε-convex
        let mut a = sinusoidal(16, 16, 0.1, 2.0).expect("grid");
        let mut b = a.clone();
        let ra = smooth(&mut a, &opts(HessianMode::Assembled), &mut NullObserver).expect("exact");
        let rb = smooth(&mut b, &opts(HessianMode::ProjectedPsd), &mut NullObserver).expect("psd");
        assert!(ra.eps_convex && rb.eps_convex);
        assert_eq!(rb.inocon, 0);
        assert!(
            (ra.f - rb.f).abs() <= 1e-7 * ra.f.abs(),
            "F exact {} vs PSD model {}",
            ra.f,
            rb.f
        );
    }

    #[test]
    fn model_hessian_differs_from_exact_and_is_psd_on_the_tfi_grid() {
        use std::sync::Arc;
        use unamalla_functionals::{AreaOrthogonality, HOmega, KernelExpr, QuadTopology};
        let g = sinusoidal(9, 9, 0.1, 2.0).expect("grid");
        let topo = Arc::new(QuadTopology::from_mesh(&g).expect("topo"));
        let (n, ab) = (topo.num_triangles(), topo.alpha_bar());
        let ao = KernelExpr::from(AreaOrthogonality)
            .normalized(n, ab)
            .expect("ao");
        let h = KernelExpr::from(HOmega::new(0.01 * ab).expect("omega"))
            .normalized(n, ab)
            .expect("h");
        let f = QuadFunctional::new(
            topo.clone(),
            KernelExpr::weighted_sum(vec![(0.9, ao), (0.1, h)]),
        );
        let m = WithHessian::new(&f, PsdModel::new(&f, PsdProjection::Clamp));
        let x = topo.initial_x();
        let (mut he, mut hm) = (f.hessian_pattern(), m.hessian_pattern());
        f.hessian(&x, &mut he);
        m.hessian(&x, &mut hm);
        assert!(he
            .values
            .iter()
            .zip(&hm.values)
            .any(|(a, b)| (a - b).abs() > 1e-9));
        // vᵀ H_model v ≥ 0 for a few deterministic vectors (the full PSD test is in
        // unamalla-functionals' tests/psd.rs)
        let nv = x.len();
        let mut out = vec![0.0; nv];
        for s in 1..6 {
            let v: Vec<f64> = (0..nv)
                .map(|i| ((i * s * 7919) % 13) as f64 - 6.0)
                .collect();
            hm.mul_vec(&v, &mut out);
            let q: f64 = v.iter().zip(&out).map(|(a, b)| a * b).sum();
            assert!(q >= -1e-12 * v.iter().map(|a| a * a).sum::<f64>());
        }
    }
}
