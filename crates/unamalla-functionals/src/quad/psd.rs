//! A positive semidefinite model Hessian for the 2D functionals (an option): every corner
//! triangle's Hessian is projected onto the PSD cone *before* assembly.
//!
//! # Formulas
//! A corner (or diagonal) triangle term `f(α, |a|², |b|², a·b)` depends on the node coordinates
//! only through its two legs `u = (aₓ, a_y, bₓ, b_y)`; its exact Hessian with respect to the
//! legs is the 4×4 matrix `H_u = Jᵀ(∂²f/∂s²)J + Σ_s f_s ∇²_u s` of the [`quad`](super) module
//! docs, and the node Hessian of the term is `Pᵀ H_u P` with the constant ±1 leg-incidence map
//! `P` (`a = X_{n₁} − X_{n₀}`, `b = X_{n₃} − X_{n₂}`). The model replaces `H_u` by its
//! projection
//!
//! * [`PsdProjection::Clamp`]: `H_u⁺ = Q max(Λ, 0) Qᵀ` (the PSD matrix nearest to `H_u` in the
//!   Frobenius norm), or
//! * [`PsdProjection::Abs`]: `|H_u| = Q |Λ| Qᵀ` (the "flipped" model: the same curvature
//!   magnitudes, positive),
//!
//! where `H_u = Q Λ Qᵀ` is the eigen-decomposition (cyclic Jacobi rotations, 4×4). Since
//! `xᵀ Pᵀ H_u⁺ P x = (Px)ᵀ H_u⁺ (Px) ≥ 0`, every projected term is PSD in the node coordinates
//! and so is their sum: the assembled model Hessian is PSD, and where every `H_u` is already
//! PSD it equals the exact Hessian (a term whose `H_u` passes an `LDLᵀ` test with positive
//! pivots is not touched, so it is bit-identical to the reference per-triangle assembly).
//!
//! This is the per-element projected Newton model used for mesh and elasticity energies (e.g.
//! [Teran et al. 2005], "Robust quasistatic finite elements"): a Gauss–Newton-like convexification
//! that keeps the exact gradient, so a Newton-type method with this model is a descent method with
//! a positive semidefinite inner system (CG without negative curvature). Note that
//! `F_AO = ½|a|²|b|²` ([Méndez 2023, Table 6.2], the first term of (6.8)) has an indefinite `H_u`
//! for every triangle (on `span{(â,0), (0,b̂)}` it is `[[|b|², 2|a||b|], [2|a||b|, |a|²]]`, whose
//! determinant `−3|a|²|b|²` is negative), so the model differs from the exact Hessian wherever that
//! term has weight.

use super::{leg_hessian, pair_range, scalars, scatter_leg_hessian, Plan, QuadFunctional, LEGS};
use crate::csr::Csr;
use crate::kernel::{Order, Terms, TriKernel};

/// How [`QuadFunctional::hessian_psd`] projects a triangle's leg Hessian (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PsdProjection {
    /// Negative eigenvalues set to 0 (nearest PSD matrix).
    #[default]
    Clamp,
    /// Negative eigenvalues replaced by their absolute values.
    Abs,
}

/// `true` if the symmetric 4×4 `m` is positive definite by an `LDLᵀ` factorization whose
/// pivots all exceed `1e-12 · max diagonal` (a conservative test: a singular PSD matrix fails
/// it and is sent to the eigen-decomposition, whose clamping then changes it only by rounding).
fn ldlt_positive(m: &[[f64; 4]; 4]) -> bool {
    let scale = m[0][0].max(m[1][1]).max(m[2][2]).max(m[3][3]);
    if scale.is_nan() || scale <= 0.0 {
        return false;
    }
    let tol = 1e-12 * scale;
    let mut a = *m;
    for k in 0..4 {
        let d = a[k][k];
        if d.is_nan() || d <= tol {
            return false;
        }
        for i in k + 1..4 {
            let l = a[i][k] / d;
            for j in k + 1..=i {
                a[i][j] -= l * a[j][k];
            }
        }
    }
    true
}

/// Eigen-decomposition of a symmetric 4×4 matrix by cyclic Jacobi rotations: returns the
/// eigenvalues `λ` and the eigenvectors as the columns of `Q` (`m = Q diag(λ) Qᵀ` to rounding).
pub fn sym4_eigen(m: &[[f64; 4]; 4]) -> ([f64; 4], [[f64; 4]; 4]) {
    let mut a = *m;
    let mut q = [[0.0; 4]; 4];
    for (i, row) in q.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    let norm2: f64 = a.iter().flatten().map(|v| v * v).sum();
    for _sweep in 0..16 {
        let mut off = 0.0;
        for p in 0..4 {
            for r in p + 1..4 {
                off += a[p][r] * a[p][r];
            }
        }
        if off.is_nan() || off <= 1e-30 * norm2 {
            break;
        }
        for p in 0..3 {
            for r in p + 1..4 {
                let apr = a[p][r];
                if apr == 0.0 {
                    continue;
                }
                // rotation angle zeroing a[p][r]: t = tan θ, the smaller root of
                // t² + 2θ̃ t − 1 = 0 with θ̃ = (a_rr − a_pp)/(2 a_pr)
                let theta = (a[r][r] - a[p][p]) / (2.0 * apr);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..4 {
                    let akp = a[k][p];
                    let akr = a[k][r];
                    a[k][p] = c * akp - s * akr;
                    a[k][r] = s * akp + c * akr;
                }
                for k in 0..4 {
                    let apk = a[p][k];
                    let ark = a[r][k];
                    a[p][k] = c * apk - s * ark;
                    a[r][k] = s * apk + c * ark;
                }
                for row in q.iter_mut() {
                    let qp = row[p];
                    let qr = row[r];
                    row[p] = c * qp - s * qr;
                    row[r] = s * qp + c * qr;
                }
            }
        }
    }
    ([a[0][0], a[1][1], a[2][2], a[3][3]], q)
}

/// Projects the symmetric 4×4 `m` in place ([`PsdProjection`]); returns `false` (and leaves
/// `m` untouched) when `m` is already positive definite by the `LDLᵀ` test.
pub fn project_psd4(m: &mut [[f64; 4]; 4], mode: PsdProjection) -> bool {
    if ldlt_positive(m) {
        return false;
    }
    let (lam, q) = sym4_eigen(m);
    let lam = lam.map(|l| match mode {
        PsdProjection::Clamp => l.max(0.0),
        PsdProjection::Abs => l.abs(),
    });
    for i in 0..4 {
        for j in i..4 {
            let mut acc = 0.0;
            for k in 0..4 {
                acc += q[i][k] * lam[k] * q[j][k];
            }
            m[i][j] = acc;
            m[j][i] = acc;
        }
    }
    true
}

impl QuadFunctional {
    /// The PSD model Hessian (module docs) at `x`, written into `h` (which must come from
    /// [`hessian_pattern`](crate::Hessian::hessian_pattern)); returns the number of triangle
    /// terms whose leg Hessian was projected.
    ///
    /// # Panics
    /// As [`Hessian::hessian`](crate::Hessian::hessian): if `x` or `h` has the wrong size.
    pub fn hessian_psd(&self, x: &[f64], h: &mut Csr, mode: PsdProjection) -> usize {
        self.check_hessian_args(x, h);
        with_plan!(self, k, t => psd_assemble(self, k, t, x, h, mode))
    }
}

/// The assembly of [`QuadFunctional::hessian_psd`] with the kernel `k` of the fast path's plan
/// (the fused or general kernel chosen for the expression).
fn psd_assemble<KK: TriKernel>(
    f: &QuadFunctional,
    kernel: &KK,
    terms: Terms,
    x: &[f64],
    h: &mut Csr,
    mode: PsdProjection,
) -> usize {
    let (lo, hi) = pair_range(terms);
    let projected = f.topo.assemble_cell_hessians(x, h, true, |c, p| {
        let mut lh = [[0.0; 8]; 8];
        let mut count = 0.0;
        for q in lo..hi {
            let (a, b, s) = scalars(p, c, q);
            let d = kernel.eval(&s, Order::Hessian);
            let mut hu = leg_hessian(a, b, &d);
            if project_psd4(&mut hu, mode) {
                count += 1.0;
            }
            scatter_leg_hessian(&mut lh, LEGS[q], &hu);
        }
        (lh, count)
    });
    projected as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mat(rows: [[f64; 4]; 4]) -> [[f64; 4]; 4] {
        rows
    }

    fn quad_form(m: &[[f64; 4]; 4], v: &[f64; 4]) -> f64 {
        let mut s = 0.0;
        for i in 0..4 {
            for j in 0..4 {
                s += v[i] * m[i][j] * v[j];
            }
        }
        s
    }

    #[test]
    fn eigen_reconstructs_and_orthogonal() {
        let m = mat([
            [4.0, 1.0, -2.0, 0.5],
            [1.0, -3.0, 0.0, 2.0],
            [-2.0, 0.0, 1.0, -1.0],
            [0.5, 2.0, -1.0, 0.0],
        ]);
        let (lam, q) = sym4_eigen(&m);
        // trace is invariant: 4 − 3 + 1 + 0 = 2
        assert!((lam.iter().sum::<f64>() - 2.0).abs() < 1e-12);
        for i in 0..4 {
            for j in 0..4 {
                let r: f64 = (0..4).map(|k| q[i][k] * lam[k] * q[j][k]).sum();
                assert!((r - m[i][j]).abs() < 1e-12, "{i},{j}");
                let o: f64 = (0..4).map(|k| q[k][i] * q[k][j]).sum();
                assert!((o - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn f_ao_leg_hessian_projection_by_hand() {
        // F_AO = ½|a|²|b|² at a = (1, 0), b = (0, 2): H_u = [[|b|² I, 2abᵀ], [2baᵀ, |a|² I]]
        // = rows (4,0,0,0), (0,4,0,0)+..., coupling 2·a_x·b_y = 4 at (aₓ, b_y).
        // Eigen: a_y ↦ 4, bₓ ↦ 1, and on (aₓ, b_y): [[4, 4], [4, 1]] with λ = (5 ± √73)/2.
        let mut m = mat([
            [4.0, 0.0, 0.0, 4.0],
            [0.0, 4.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [4.0, 0.0, 0.0, 1.0],
        ]);
        assert!(project_psd4(&mut m, PsdProjection::Clamp));
        // clamped: λ₊ = (5 + √73)/2 with eigenvector ∝ (4, λ₊ − 4) on (aₓ, b_y)
        let lp = (5.0 + 73f64.sqrt()) / 2.0;
        let (vx, vy) = (4.0, lp - 4.0);
        let nn = vx * vx + vy * vy;
        assert!((m[0][0] - lp * vx * vx / nn).abs() < 1e-12);
        assert!((m[0][3] - lp * vx * vy / nn).abs() < 1e-12);
        assert!((m[3][3] - lp * vy * vy / nn).abs() < 1e-12);
        assert!((m[1][1] - 4.0).abs() < 1e-12 && (m[2][2] - 1.0).abs() < 1e-12);
        let (lam, _) = sym4_eigen(&m);
        assert!(lam.iter().all(|&l| l > -1e-12));
        // Abs: trace = 4 + 1 + |λ₊| + |λ₋| = 5 + √73
        let mut m2 = mat([
            [4.0, 0.0, 0.0, 4.0],
            [0.0, 4.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [4.0, 0.0, 0.0, 1.0],
        ]);
        assert!(project_psd4(&mut m2, PsdProjection::Abs));
        let tr = m2[0][0] + m2[1][1] + m2[2][2] + m2[3][3];
        assert!((tr - (5.0 + 73f64.sqrt())).abs() < 1e-12);
    }

    #[test]
    fn positive_definite_is_untouched() {
        let m0 = mat([
            [4.0, 1.0, 0.0, 0.0],
            [1.0, 3.0, 0.5, 0.0],
            [0.0, 0.5, 2.0, 0.1],
            [0.0, 0.0, 0.1, 1.0],
        ]);
        let mut m = m0;
        assert!(!project_psd4(&mut m, PsdProjection::Clamp));
        assert_eq!(m, m0);
        // a random-ish vector has a non-negative quadratic form
        assert!(quad_form(&m, &[0.3, -1.0, 2.0, 0.7]) > 0.0);
    }
}
