//! 2D functionals on quad meshes: [`QuadTopology`] (connectivity, free-variable map, fixed
//! coordinates) and [`QuadFunctional`] (a topology plus a [`KernelExpr`]), which implements
//! [`Problem`].
//!
//! # The generic derivative path
//! For a leg pair `a = X_{n₁} − X_{n₀}`, `b = X_{n₃} − X_{n₂}` (corner triangle at `P = v_k`:
//! `n₀ = n₂ = k`, `n₁ = k+1`, `n₃ = k−1`) let `u = (aₓ, a_y, bₓ, b_y)` and
//! `s = (α, la, lb, o) = (aₓb_y − a_ybₓ, |a|², |b|², a·b)`. Then
//!
//! * `∇ᵤα = (b_y, −bₓ, −a_y, aₓ)` (i.e. `∂α/∂a = J₂b`, `∂α/∂b = −J₂a`, `J₂w = (w_y, −w_x)`),
//!   `∇ᵤla = (2a, 0)`, `∇ᵤlb = (0, 2b)`, `∇ᵤo = (b, a)`;
//! * `∇²ᵤα` has `+1` at `(aₓ, b_y)` and `−1` at `(a_y, bₓ)`, `∇²ᵤla = 2I_a`, `∇²ᵤlb = 2I_b`,
//!   `∇²ᵤo` has `1` at `(aₓ, bₓ)` and `(a_y, b_y)` (all constant);
//! * `∇ᵤf = Σₛ fₛ ∇ᵤs`, `∇²ᵤf = Jᵀ (∂²f/∂s²) J + Σₛ fₛ ∇²ᵤs` with `J = ∂s/∂u`;
//! * node derivatives follow from `a = X_{n₁} − X_{n₀}`, `b = X_{n₃} − X_{n₂}`: `n₁` receives
//!   `+∂f/∂a`, `n₀` receives `−∂f/∂a` (and likewise for `b`), and the Hessian block of nodes
//!   `(i, j)` is `Σ σᵢσⱼ ∂²f/∂Lᵢ∂Lⱼ` over the legs `Lᵢ ∋ i`, `Lⱼ ∋ j` with signs `σ = ±1`.
//!
//! This one exact path serves every kernel (checked against finite differences in the tests).
//!
//! # Two implementations of the same formulas
//! [`Problem`] for [`QuadFunctional`] (every capability trait) runs the fast evaluator of the private `lanes` submodule
//! (the four corners of a cell as SIMD lanes, per-cell first-contribution flags and CSR slot
//! tables, AVX2 dispatch; its docs give the node-block formulas `H_PP = A + B + Bᵀ + C`,
//! `H_PQ = −(A + Bᵀ)`, `H_PR = −(B + C)`, `H_QR = B` of a corner with leg blocks
//! `A = H_aa`, `B = H_ab`, `C = H_bb`). The per-triangle path above is kept in a test-only
//! submodule (`reference`) as the oracle: the tests check that the two agree to rounding for
//! every kind of expression. The kernel the fast path runs is chosen once per expression
//! (private `plan` submodule): `w₁F_AO + w₂H_ω` ([Méndez 2023, (6.8)]) runs a fused, monomorphized
//! two-leaf kernel, anything else the expression's own evaluation (one `match` per node, cell
//! and term).

use std::sync::Arc;

use glam::DVec2;

use crate::assembly::SyncPtr;
use crate::csr::Csr;
use crate::kernel::{KernelExpr, Order, Partials, Terms, TriKernel, TriScalars};
#[cfg(doc)]
use crate::problem::Problem;
use crate::problem::{
    Cost, ElementMeasures, Gradient, Hessian, LocalModel, PointwiseModel, Variables,
};

mod lanes;
mod plan;
mod topology;

use plan::Plan;
pub use topology::{AlphaSummary, QuadTopology};

/// Leg nodes `(n₀, n₁, n₂, n₃)` of corner `k` (`a = X_{n₁} − X_{n₀}`, `b = X_{n₃} − X_{n₂}`) and,
/// at index 4, of the diagonal pair.
const LEGS: [[usize; 4]; 5] = [
    [0, 1, 0, 3],
    [1, 2, 1, 0],
    [2, 3, 2, 1],
    [3, 0, 3, 2],
    [0, 2, 1, 3],
];

/// Leg Hessian `H_u = Jᵀ (∂²f/∂s²) J + Σ_s f_s ∇²_u s`, `u = (aₓ, a_y, bₓ, b_y)` (module docs).
#[inline(always)]
/// Adds the Hessian `hu` with respect to the legs `u = (a, b)` of the corner triangle with leg
/// nodes `l` (`a = X_{l₁} − X_{l₀}`, `b = X_{l₃} − X_{l₂}`, cell-local node ids) into the cell's
/// 8 × 8 node Hessian `h` (chain rule with the ±1 leg Jacobian).
pub(crate) fn scatter_leg_hessian(h: &mut [[f64; 8]; 8], l: [usize; 4], hu: &[[f64; 4]; 4]) {
    // (node, sign, leg)
    let ends = [
        (l[1], 1.0, 0usize),
        (l[0], -1.0, 0),
        (l[3], 1.0, 1),
        (l[2], -1.0, 1),
    ];
    for &(ni, si, li) in &ends {
        for &(nj, sj, lj) in &ends {
            let sg = si * sj;
            for dx in 0..2 {
                for dy in 0..2 {
                    h[2 * ni + dx][2 * nj + dy] += sg * hu[2 * li + dx][2 * lj + dy];
                }
            }
        }
    }
}

fn leg_hessian(a: DVec2, b: DVec2, d: &Partials) -> [[f64; 4]; 4] {
    // J = ∂s/∂u, u = (ax, ay, bx, by)
    let j = [
        [b.y, -b.x, -a.y, a.x],
        [2.0 * a.x, 2.0 * a.y, 0.0, 0.0],
        [0.0, 0.0, 2.0 * b.x, 2.0 * b.y],
        [b.x, b.y, a.x, a.y],
    ];
    let mut hj = [[0.0; 4]; 4]; // (∂²f/∂s²) J
    for si in 0..4 {
        for ui in 0..4 {
            let mut acc = 0.0;
            for tt in 0..4 {
                acc += d.h[si][tt] * j[tt][ui];
            }
            hj[si][ui] = acc;
        }
    }
    let mut hu = [[0.0; 4]; 4];
    for ui in 0..4 {
        for uj in 0..4 {
            let mut acc = 0.0;
            for si in 0..4 {
                acc += j[si][ui] * hj[si][uj];
            }
            hu[ui][uj] = acc;
        }
    }
    let (ga_, gla, glb, go) = (d.g[0], d.g[1], d.g[2], d.g[3]);
    hu[0][3] += ga_;
    hu[3][0] += ga_;
    hu[1][2] -= ga_;
    hu[2][1] -= ga_;
    hu[0][0] += 2.0 * gla;
    hu[1][1] += 2.0 * gla;
    hu[2][2] += 2.0 * glb;
    hu[3][3] += 2.0 * glb;
    hu[0][2] += go;
    hu[2][0] += go;
    hu[1][3] += go;
    hu[3][1] += go;
    hu
}

#[inline(always)]
fn scalars(p: &[DVec2; 4], c: usize, k: usize) -> (DVec2, DVec2, TriScalars) {
    let l = LEGS[k];
    let a = p[l[1]] - p[l[0]];
    let b = p[l[3]] - p[l[2]];
    (
        a,
        b,
        TriScalars {
            alpha: a.perp_dot(b),
            la: a.length_squared(),
            lb: b.length_squared(),
            o: a.dot(b),
            cell: c,
            corner: k as u8,
        },
    )
}

/// Node-only local model of cell node `node`: for each of its cells, the corner triangles
/// (and the diagonal pair) that involve it contribute their gradient and the node's 2 × 2
/// block of their leg Hessian ([`node_block`]: the block that [`scatter_leg_hessian`] would
/// add at `(i, i)`, without the 4 × 4 leg Hessian or the cell's 8 × 8 matrix).
fn node_model<K: TriKernel>(
    k: &K,
    t: Terms,
    topo: &QuadTopology,
    x: &[f64],
    node: usize,
) -> Option<LocalModel> {
    let mut m = LocalModel {
        value: 0.0,
        grad: [0.0; 3],
        hess: [[0.0; 3]; 3],
        dim: 2,
    };
    for_each_node_pair(t, topo, x, node, |p, c, q, i| {
        let l = LEGS[q];
        let sign = |to: usize, from: usize| {
            f64::from(u8::from(l[to] == i)) - f64::from(u8::from(l[from] == i))
        };
        let (sa, sb) = (sign(1, 0), sign(3, 2));
        let (a, b, s) = scalars(p, c, q);
        let d = k.eval(&s, Order::Hessian);
        m.value += d.v;
        let (ga, gb) = leg_grads(a, b, &d.g);
        let gi = sa * ga + sb * gb;
        m.grad[0] += gi.x;
        m.grad[1] += gi.y;
        let h = node_block(a, b, sa, sb, &d);
        for dx in 0..2 {
            for dy in 0..2 {
                m.hess[dx][dy] += h[dx][dy];
            }
        }
    })?;
    Some(m)
}

/// The 2 × 2 block of a leg pair's Hessian for a node that moves both legs by `s_a·δx`,
/// `s_b·δx` (`s_a`, `s_b` ∈ {−1, 0, 1}: `+1` at a leg's head, `−1` at its tail):
/// `Pᵀ·H_u·P` with `P = [s_a I; s_b I]`. With `J_n = ∂s/∂x` (rows α, |a|², |b|², a·b:
/// `s_a(b_y, −b_x) + s_b(−a_y, a_x)`, `2s_a a`, `2s_b b`, `s_a b + s_b a`) it is
/// `J_nᵀ·(∂²f/∂s²)·J_n + 2(f_{|a|²} s_a² + f_{|b|²} s_b² + f_{a·b} s_a s_b)·I` — the second
/// derivative of α contributes `s_a s_b·(A + Aᵀ) = 0` (A the rotation block).
#[inline(always)]
fn node_block(a: DVec2, b: DVec2, sa: f64, sb: f64, d: &Partials) -> [[f64; 2]; 2] {
    let j = [
        sa * DVec2::new(b.y, -b.x) + sb * DVec2::new(-a.y, a.x),
        (2.0 * sa) * a,
        (2.0 * sb) * b,
        sa * b + sb * a,
    ];
    let mut hj = [DVec2::ZERO; 4]; // (∂²f/∂s²)·J_n, row by row
    for (r, row) in hj.iter_mut().enumerate() {
        for (t, jt) in j.iter().enumerate() {
            *row += d.h[r][t] * *jt;
        }
    }
    let diag = 2.0 * (d.g[1] * sa * sa + d.g[2] * sb * sb + d.g[3] * sa * sb);
    let mut out = [[0.0; 2]; 2];
    for (r, jr) in j.iter().enumerate() {
        out[0][0] += jr.x * hj[r].x;
        out[0][1] += jr.x * hj[r].y;
        out[1][0] += jr.y * hj[r].x;
        out[1][1] += jr.y * hj[r].y;
    }
    out[0][0] += diag;
    out[1][1] += diag;
    out
}

/// The value of [`node_model`] alone (value-only kernel evaluations).
fn node_value<K: TriKernel>(
    k: &K,
    t: Terms,
    topo: &QuadTopology,
    x: &[f64],
    node: usize,
) -> Option<f64> {
    let mut v = 0.0;
    for_each_node_pair(t, topo, x, node, |p, c, q, _| {
        v += k.value(&scalars(p, c, q).2);
    })?;
    Some(v)
}

/// Calls `f(cell points, cell, leg pair, local index of the node)` for every leg pair (in
/// `pair_range(t)`) of every cell around mesh node `node` whose triangle involves the node
/// ([`node_pairs`]); `None` if the incidence table is inconsistent.
#[inline(always)]
fn for_each_node_pair(
    t: Terms,
    topo: &QuadTopology,
    x: &[f64],
    node: usize,
    mut f: impl FnMut(&[DVec2; 4], usize, usize, usize),
) -> Option<()> {
    let asm = &topo.asm;
    let (lo, hi) = pair_range(t);
    for &c in &asm.inc[asm.inc_offsets[node]..asm.inc_offsets[node + 1]] {
        let c = c as usize;
        let i = asm.cells[c].iter().position(|&v| v as usize == node)?;
        let (p, _) = topo.cell_points(x, c);
        for q in node_pairs(i, lo, hi) {
            f(&p, c, q, i);
        }
    }
    Some(())
}

/// The leg pairs in `lo..hi` ([`pair_range`]) whose triangle involves cell node `i`: every
/// corner triangle except the one at the opposite corner `i + 2`, and the diagonal pair.
#[inline(always)]
fn node_pairs(i: usize, lo: usize, hi: usize) -> impl Iterator<Item = usize> {
    (lo..hi).filter(move |&q| !(q < 4 && q == (i + 2) & 3))
}

#[inline(always)]
fn pair_range(t: Terms) -> (usize, usize) {
    match (t.corners, t.diagonal) {
        (true, true) => (0, 5),
        (true, false) => (0, 4),
        (false, true) => (4, 5),
        (false, false) => (0, 0),
    }
}

#[inline(always)]
fn leg_grads(a: DVec2, b: DVec2, d: &[f64; 4]) -> (DVec2, DVec2) {
    let ga = d[0] * DVec2::new(b.y, -b.x) + (2.0 * d[1]) * a + d[3] * b;
    let gb = d[0] * DVec2::new(-a.y, a.x) + (2.0 * d[2]) * b + d[3] * a;
    (ga, gb)
}

/// Value, gradient and 8×8 Hessian of the terms of cell `c`.
#[inline(always)]
fn cell_hess<K: TriKernel>(
    k: &K,
    t: Terms,
    p: &[DVec2; 4],
    c: usize,
    g: &mut [DVec2; 4],
    h: &mut [[f64; 8]; 8],
) -> f64 {
    let (lo, hi) = pair_range(t);
    let mut v = 0.0;
    for q in lo..hi {
        let (a, b, s) = scalars(p, c, q);
        let d = k.eval(&s, Order::Hessian);
        v += d.v;
        let (ga, gb) = leg_grads(a, b, &d.g);
        let l = LEGS[q];
        g[l[1]] += ga;
        g[l[0]] -= ga;
        g[l[3]] += gb;
        g[l[2]] -= gb;
        scatter_leg_hessian(h, LEGS[q], &leg_hessian(a, b, &d));
    }
    v
}

/// Runs `$body` with `$k` bound to the kernel the fast path uses (monomorphized per plan) and
/// `$t` to the leg pairs it needs.
macro_rules! with_plan {
    ($self:expr, $k:ident, $t:ident => $body:expr) => {
        match &$self.plan {
            Plan::AoHOmega(kk) => {
                let $k = kk;
                let $t = kk.terms();
                $body
            }
            Plan::General(kk) => {
                let $k = kk;
                let $t = $self.terms;
                $body
            }
        }
    };
}

// After `with_plan!` (textual macro scope): the PSD-projected model Hessian.
pub mod psd;
#[cfg(test)]
mod reference;

/// A 2D functional: a [`QuadTopology`] (shared, cheap to clone) and a [`KernelExpr`].
///
/// Every capability of [`Problem`] is implemented by the fast evaluator (module `lanes`: four
/// corner lanes per cell, precomputed index and slot tables, AVX2 when available), running the
/// plan chosen for the expression (module `plan`: a fused kernel for the sums it knows, a loop
/// over the terms otherwise).
#[derive(Debug, Clone)]
pub struct QuadFunctional {
    topo: Arc<QuadTopology>,
    kernel: KernelExpr,
    terms: Terms,
    plan: Plan,
}

impl QuadFunctional {
    /// The functional `Σ kernel` over the leg pairs of the topology (`kernel`: a
    /// [`KernelExpr`], or anything that converts into one, e.g. a leaf kernel).
    pub fn new(topo: Arc<QuadTopology>, kernel: impl Into<KernelExpr>) -> Self {
        let kernel = kernel.into();
        let terms = kernel.terms();
        let plan = Plan::for_expr(&kernel);
        Self {
            topo,
            kernel,
            terms,
            plan,
        }
    }
    /// The topology.
    pub fn topology(&self) -> &Arc<QuadTopology> {
        &self.topo
    }
    /// The kernel expression.
    pub fn kernel(&self) -> &KernelExpr {
        &self.kernel
    }
    /// Replaces the kernel (e.g. a new ω or k during a continuation), keeping the topology.
    pub fn set_kernel(&mut self, kernel: impl Into<KernelExpr>) {
        let kernel = kernel.into();
        self.terms = kernel.terms();
        self.plan = Plan::for_expr(&kernel);
        self.kernel = kernel;
    }
    fn check_hessian_args(&self, x: &[f64], h: &Csr) {
        assert_eq!(
            x.len(),
            self.topo.num_vars(),
            "hessian: x has the wrong length"
        );
        assert_eq!(
            h.nrows,
            self.topo.num_vars(),
            "hessian: matrix has the wrong size"
        );
        assert!(
            self.topo.asm.matches_pattern(2, h),
            "hessian: matrix does not come from hessian_pattern"
        );
    }

    /// The per-triangle Hessian assembly with the plan's kernel (the fallback of
    /// [`Hessian::hessian`] when the slot tables cannot be built).
    fn hessian_generic(&self, x: &[f64], h: &mut Csr) {
        with_plan!(self, k, t => self.hessian_per_triangle(k, t, x, h))
    }

    fn hessian_per_triangle<KK: TriKernel>(&self, k: &KK, t: Terms, x: &[f64], h: &mut Csr) {
        self.topo.assemble_cell_hessians(x, h, false, |c, p| {
            let mut lg = [DVec2::ZERO; 4];
            let mut lh = [[0.0; 8]; 8];
            cell_hess(k, t, p, c, &mut lg, &mut lh);
            (lh, 0.0)
        });
    }
}

impl Variables for QuadFunctional {
    fn dim(&self) -> usize {
        2
    }
    fn num_vars(&self) -> usize {
        self.topo.num_vars()
    }
    fn free_nodes(&self) -> &[usize] {
        self.topo.free_nodes()
    }
    fn var_of(&self, node: usize) -> Option<usize> {
        self.topo.var_of(node)
    }
}

impl Cost for QuadFunctional {
    fn value(&self, x: &[f64]) -> f64 {
        assert_eq!(
            x.len(),
            self.topo.num_vars(),
            "value: x has the wrong length"
        );
        with_plan!(self, k, t => self.topo.asm.run_value_chunks(|s, e| {
            lanes::value_chunk(&self.topo, k, t, x, s, e)
        }))
    }
}

impl Gradient for QuadFunctional {
    fn value_grad(&self, x: &[f64], g: &mut [f64]) -> f64 {
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
        self.topo.zero_isolated(g);
        let gp = SyncPtr::new(g);
        with_plan!(self, k, t => self.topo.asm.run_colored_chunks(|s, e| {
            lanes::grad_chunk(&self.topo, k, t, x, gp, s, e)
        }))
    }
}

impl Hessian for QuadFunctional {
    fn hessian_pattern(&self) -> Csr {
        self.topo.hessian_pattern()
    }

    fn hessian(&self, x: &[f64], h: &mut Csr) {
        self.check_hessian_args(x, h);
        let Some(slots) = self.topo.hessian_slots() else {
            self.hessian_generic(x, h);
            return;
        };
        let Csr {
            row_offsets,
            values,
            ..
        } = h;
        let hp = SyncPtr::new(values);
        let ro: &[usize] = row_offsets;
        with_plan!(self, k, t => self.topo.asm.run_colored_chunks(|s, e| {
            lanes::hess_chunk(&self.topo, k, t, x, slots, ro, hp, s, e);
            0.0
        }));
    }

    fn hess_vec(&self, x: &[f64], v: &[f64], out: &mut [f64]) {
        let n = self.topo.num_vars();
        assert_eq!(x.len(), n, "hess_vec: x has the wrong length");
        assert_eq!(v.len(), n, "hess_vec: v has the wrong length");
        assert_eq!(out.len(), n, "hess_vec: out has the wrong length");
        self.topo.zero_isolated(out);
        let op = SyncPtr::new(out);
        with_plan!(self, k, t => self.topo.asm.run_colored_chunks(|s, e| {
            lanes::hess_vec_chunk(&self.topo, k, t, x, v, op, s, e);
            0.0
        }));
    }
}

impl PointwiseModel for QuadFunctional {
    /// Node-only local model (the node's 2 × 2 block of its leg pairs' Hessians, no 8 × 8 cell
    /// matrix), with the kernel of the fast evaluator's plan.
    fn local(&self, x: &[f64], node: usize) -> Option<LocalModel> {
        self.topo.var_of(node)?;
        assert_eq!(
            x.len(),
            self.topo.num_vars(),
            "local: x has the wrong length"
        );
        with_plan!(self, k, t => node_model(k, t, &self.topo, x, node))
    }

    fn local_value(&self, x: &[f64], node: usize) -> Option<f64> {
        self.topo.var_of(node)?;
        with_plan!(self, k, t => node_value(k, t, &self.topo, x, node))
    }
}

impl ElementMeasures for QuadFunctional {
    fn num_elements(&self) -> usize {
        self.topo.num_triangles()
    }

    fn element_measures(&self, x: &[f64], out: &mut [f64]) {
        self.topo.alphas(x, out)
    }
    fn element_nodes(&self, e: usize, out: &mut Vec<usize>) {
        out.extend_from_slice(&self.topo.cell(e / 4));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::DIAGONAL;

    #[test]
    fn diagonal_pair_gives_twice_the_cell_area() {
        let p = [
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(2.0, 3.0),
            DVec2::new(0.0, 3.0),
        ];
        let (_, _, s) = scalars(&p, 0, DIAGONAL as usize);
        assert!((s.alpha - 12.0).abs() < 1e-12);
        let (_, _, s0) = scalars(&p, 0, 0);
        assert!((s0.alpha - 6.0).abs() < 1e-12);
        assert!((s0.la - 4.0).abs() < 1e-12 && (s0.lb - 9.0).abs() < 1e-12);
    }
}
