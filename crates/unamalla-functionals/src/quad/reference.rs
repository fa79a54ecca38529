//! The straightforward per-triangle path, kept as the tests' reference for the fast evaluator
//! (test builds only; the fast path's tests are in [`fast_path`]).
//!
//! Each corner (and diagonal) pair is evaluated on its own with the formulas of the
//! [`quad`](super) module docs, accumulated per cell with zeroing and adding (no lanes, no
//! first-contribution stores, neighbour positions by binary search), with the expression's own
//! evaluation ([`ExprKernel`], never the fused plan). The two paths agree to rounding.

use glam::DVec2;
use rayon::prelude::*;

use super::plan::{ExprKernel, Plan};
use super::{cell_hess, leg_grads, scalars, QuadFunctional, LEGS};
use crate::assembly::{SyncPtr, FIXED};
use crate::csr::Csr;
use crate::kernel::{Terms, TriKernel, TriScalars};

mod fast_path;

impl QuadFunctional {
    /// The value with a single-threaded loop (same chunked summation as [`Cost::value`](crate::Cost::value), so
    /// the results are identical); useful as a reference.
    pub(crate) fn value_serial(&self, x: &[f64]) -> f64 {
        assert_eq!(
            x.len(),
            self.topo.num_vars(),
            "value: x has the wrong length"
        );
        with_plan!(self, k, t => self.topo.asm.run_serial_chunks(|s, e| {
            super::lanes::value_chunk(&self.topo, k, t, x, s, e)
        }))
    }

    /// Reference value: the per-triangle path with the kernel as given (no lanes, no
    /// flattening). Equal to [`Cost::value`](crate::Cost::value) up to rounding.
    pub(crate) fn value_reference(&self, x: &[f64]) -> f64 {
        let reference = ExprKernel::new(&self.kernel);
        assert_eq!(
            x.len(),
            self.topo.num_vars(),
            "value: x has the wrong length"
        );
        self.topo.asm.run_value(|c| {
            let (p, _) = self.topo.cell_points(x, c);
            cell_value(&reference, self.terms, &p, c)
        })
    }

    /// Reference value and gradient (per-triangle path, zero then add). Equal to
    /// [`Gradient::value_grad`](crate::Gradient::value_grad) up to rounding.
    pub(crate) fn value_grad_reference(&self, x: &[f64], g: &mut [f64]) -> f64 {
        let reference = ExprKernel::new(&self.kernel);
        assert_eq!(
            x.len(),
            self.topo.num_vars(),
            "value_grad: x has the wrong length"
        );
        assert_eq!(
            g.len(),
            self.topo.num_vars(),
            "value_grad: g has the wrong length"
        );
        crate::csr::par_zero(g);
        let gp = SyncPtr::new(g);
        self.topo.asm.run_colored(|c| {
            let (p, vars) = self.topo.cell_points(x, c);
            let mut lg = [DVec2::ZERO; 4];
            let v = cell_grad(&reference, self.terms, &p, c, &mut lg);
            for i in 0..4 {
                let j = vars[i];
                if j != FIXED {
                    let j = 2 * j as usize;
                    // SAFETY: node of this cell; see `assembly` (colouring).
                    unsafe {
                        gp.add(j, lg[i].x);
                        gp.add(j + 1, lg[i].y);
                    }
                }
            }
            v
        })
    }

    /// Reference Hessian refresh (per-triangle 8×8 cell matrices, zero then add, neighbour
    /// positions found by binary search). Equal to [`Hessian::hessian`](crate::Hessian::hessian) up to rounding.
    ///
    /// # Panics
    /// As [`Hessian::hessian`](crate::Hessian::hessian).
    pub(crate) fn hessian_reference(&self, x: &[f64], h: &mut Csr) {
        self.check_hessian_args(x, h);
        self.hessian_per_triangle(&ExprKernel::new(&self.kernel), self.terms, x, h);
    }

    /// Reference matrix-free Hessian-vector product (per-triangle 8×8 cell matrices). Equal to
    /// [`Hessian::hess_vec`](crate::Hessian::hess_vec) up to rounding.
    pub(crate) fn hess_vec_reference(&self, x: &[f64], v: &[f64], out: &mut [f64]) {
        let reference = ExprKernel::new(&self.kernel);
        let n = self.topo.num_vars();
        assert_eq!(x.len(), n, "hess_vec: x has the wrong length");
        assert_eq!(v.len(), n, "hess_vec: v has the wrong length");
        assert_eq!(out.len(), n, "hess_vec: out has the wrong length");
        out.par_iter_mut().with_min_len(4096).for_each(|o| *o = 0.0);
        let op = SyncPtr::new(out);
        self.topo.asm.run_colored(|c| {
            let (p, vars) = self.topo.cell_points(x, c);
            let mut lg = [DVec2::ZERO; 4];
            let mut lh = [[0.0; 8]; 8];
            cell_hess(&reference, self.terms, &p, c, &mut lg, &mut lh);
            let mut lv = [0.0; 8];
            for i in 0..4 {
                if vars[i] != FIXED {
                    let j = 2 * vars[i] as usize;
                    lv[2 * i] = v[j];
                    lv[2 * i + 1] = v[j + 1];
                }
            }
            for i in 0..4 {
                if vars[i] == FIXED {
                    continue;
                }
                let j = 2 * vars[i] as usize;
                for dx in 0..2 {
                    let mut acc = 0.0;
                    for (col, &vv) in lv.iter().enumerate() {
                        acc += lh[2 * i + dx][col] * vv;
                    }
                    // SAFETY: node of this cell; see `assembly` (colouring).
                    unsafe { op.add(j + dx, acc) };
                }
            }
            0.0
        });
    }
}

/// Corner-triangle scalars from the cell edges `e_k = v_{k+1} − v_k`: at corner `k`,
/// `a = e_k`, `b = −e_{k−1}` (bitwise identical to `v_{k−1} − v_k`).
#[inline(always)]
fn corner_from_edges(
    e: &[DVec2; 4],
    l2: &[f64; 4],
    c: usize,
    k: usize,
) -> (DVec2, DVec2, TriScalars) {
    let km = (k + 3) & 3;
    let a = e[k];
    let b = -e[km];
    (
        a,
        b,
        TriScalars {
            alpha: a.perp_dot(b),
            la: l2[k],
            lb: l2[km],
            o: a.dot(b),
            cell: c,
            corner: k as u8,
        },
    )
}

#[inline(always)]
fn edges(p: &[DVec2; 4]) -> ([DVec2; 4], [f64; 4]) {
    let e = [p[1] - p[0], p[2] - p[1], p[3] - p[2], p[0] - p[3]];
    (e, e.map(|v| v.length_squared()))
}

#[inline(always)]
fn cell_value<K: TriKernel>(k: &K, t: Terms, p: &[DVec2; 4], c: usize) -> f64 {
    let mut v = 0.0;
    if t.corners {
        let (e, l2) = edges(p);
        for q in 0..4 {
            let (_, _, s) = corner_from_edges(&e, &l2, c, q);
            v += k.value(&s);
        }
    }
    if t.diagonal {
        let (_, _, s) = scalars(p, c, 4);
        v += k.value(&s);
    }
    v
}

/// Value and gradient of the terms of cell `c` (corner terms accumulated per edge, then per
/// node: `e_k = v_{k+1} − v_k` gives `+∂f/∂e_k` to `v_{k+1}` and `−∂f/∂e_k` to `v_k`).
#[inline(always)]
fn cell_grad<K: TriKernel>(k: &K, t: Terms, p: &[DVec2; 4], c: usize, g: &mut [DVec2; 4]) -> f64 {
    let mut v = 0.0;
    if t.corners {
        let (e, l2) = edges(p);
        let mut ge = [DVec2::ZERO; 4];
        for q in 0..4 {
            let (a, b, s) = corner_from_edges(&e, &l2, c, q);
            let (val, dg) = k.value_grad(&s);
            v += val;
            let (ga, gb) = leg_grads(a, b, &dg);
            ge[q] += ga;
            ge[(q + 3) & 3] -= gb;
        }
        for q in 0..4 {
            g[(q + 1) & 3] += ge[q];
            g[q] -= ge[q];
        }
    }
    if t.diagonal {
        let (a, b, s) = scalars(p, c, 4);
        let (val, dg) = k.value_grad(&s);
        v += val;
        let (ga, gb) = leg_grads(a, b, &dg);
        let l = LEGS[4];
        g[l[1]] += ga;
        g[l[0]] -= ga;
        g[l[3]] += gb;
        g[l[2]] -= gb;
    }
    v
}
