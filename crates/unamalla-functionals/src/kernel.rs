//! Per-triangle kernels of the 2D functionals and their weighted sums.
//!
//! Every 2D functional of this crate is a sum of terms `f(α, |a|², |b|², o)` over **leg pairs**
//! `(a, b)` of the cells:
//!
//! * the four **corner triangles** of a counter-clockwise quad `[v₀, v₁, v₂, v₃]`: at corner `k`
//!   the corner is `P = v_k`, `Q = v_{k+1}`, `R = v_{k−1}` (indices mod 4), `a = Q − P`,
//!   `b = R − P` ([Méndez 2023, §6.4.2, Fig 6.12]; [González Flores, (2.53), Fig 2.19]);
//! * the **diagonal pair** `a = v₂ − v₀`, `b = v₃ − v₁` (only for the Castillo cell area:
//!   `det(a, b) = 2·area(cell)`), tagged with [`DIAGONAL`].
//!
//! with `α = det(a, b)` (doubled signed area), `la = |a|²`, `lb = |b|²` (so `l = la + lb`) and
//! `o = a·b`. A kernel returns the value and the partial derivatives with respect to
//! `s = (α, la, lb, o)` ([`Partials`]); [`crate::quad`] turns them into exact gradients and
//! Hessians in the node coordinates by the chain rule (the formulas are in [`crate::quad`]).
//!
//! For corner `k`, the leg `a` is the cell's ξ-edge when `k` is even and its η-edge when `k` is
//! odd (`v₀→v₁` is the ξ direction of the cell), which is how the weighted length and the
//! non-uniform Winslow weights tell the two families of lines apart.
//!
//! # The three layers
//! * [`TriKernel`]: one term `f(α, la, lb, o)` with its partials `∂f/∂s`, `∂²f/∂s²` (and the
//!   same on the four corner lanes of a cell, [`CornerLanes`]). Implemented by every leaf
//!   kernel and by user kernels (e.g. [`GenericArea`]).
//! * The **leaf kernels** ([`leaves`]: [`Length`], [`HOmega`], …) and the enum [`Leaf`] of
//!   all of them. The leaf list is written once, in the `leaves!` invocation of [`expr`]; the
//!   enum, its conversions and its dispatch are generated from it.
//! * [`KernelExpr`]: the one representation of a functional's per-pair term: a leaf, a
//!   weighted sum `Σᵢ wᵢ·Eᵢ` or a cell-weighted expression `c(cell)·E`, built flat by its
//!   methods (sums, convex combinations, normalizations, per-cell weights). The evaluator of
//!   [`crate::quad`] inspects the expression once and picks a fused kernel for the sums it
//!   knows (today `w₁F_AO + w₂H_ω`, [Méndez 2023, (6.8)]), the general recursive one otherwise.

/// Index of α in [`Partials`] arrays.
pub const S_ALPHA: usize = 0;
/// Index of `la = |a|²`.
pub const S_LA: usize = 1;
/// Index of `lb = |b|²`.
pub const S_LB: usize = 2;
/// Index of `o = a·b`.
pub const S_O: usize = 3;
/// `corner` tag of the diagonal leg pair of a cell.
pub const DIAGONAL: u8 = 4;

/// The scalar inputs of one term.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriScalars {
    /// `α = det(a, b)`.
    pub alpha: f64,
    /// `|a|²`.
    pub la: f64,
    /// `|b|²`.
    pub lb: f64,
    /// `a·b`.
    pub o: f64,
    /// Cell id.
    pub cell: usize,
    /// Corner `0..4`, or [`DIAGONAL`].
    pub corner: u8,
}

/// How many derivatives a kernel must compute.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Order {
    /// The value only.
    Value,
    /// Value and first partials.
    Gradient,
    /// Value, first and second partials.
    Hessian,
}

/// Value and partial derivatives of a term with respect to `s = (α, la, lb, o)`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Partials {
    /// The value.
    pub v: f64,
    /// `∂f/∂s_i`.
    pub g: [f64; 4],
    /// `∂²f/∂s_i∂s_j` (symmetric).
    pub h: [[f64; 4]; 4],
}

impl Partials {
    /// `self += w·other`.
    #[inline(always)]
    pub fn add_scaled(&mut self, w: f64, o: &Partials, order: Order) {
        self.v += w * o.v;
        if order != Order::Value {
            for i in 0..4 {
                self.g[i] += w * o.g[i];
            }
        }
        if order == Order::Hessian {
            for i in 0..4 {
                for j in 0..4 {
                    self.h[i][j] += w * o.h[i][j];
                }
            }
        }
    }
    /// `self *= w`.
    #[inline(always)]
    pub fn scale(&mut self, w: f64, order: Order) {
        let z = *self;
        *self = Partials::default();
        self.add_scaled(w, &z, order);
    }
}

/// Which leg pairs a kernel uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Terms {
    /// The four corner triangles of each cell.
    pub corners: bool,
    /// The diagonal pair of each cell.
    pub diagonal: bool,
}

impl Terms {
    /// Union of two term sets.
    pub fn or(self, o: Terms) -> Terms {
        Terms {
            corners: self.corners || o.corners,
            diagonal: self.diagonal || o.diagonal,
        }
    }
}

pub(crate) const CORNERS: Terms = Terms {
    corners: true,
    diagonal: false,
};

/// `true` if kernel `k` must be evaluated on the pair described by `s`.
#[inline(always)]
pub(crate) fn wants<K: TriKernel + ?Sized>(k: &K, s: &TriScalars) -> bool {
    let t = k.terms();
    if s.corner == DIAGONAL {
        t.diagonal
    } else {
        t.corners
    }
}

/// A per-term function `f(α, la, lb, o)` (see the module docs).
pub trait TriKernel: Send + Sync {
    /// Value and partials up to `order`. Entries beyond `order` may be left zero. It is called
    /// on corner triangles only if [`terms`](Self::terms)`.corners` and with
    /// `s.corner == DIAGONAL` only if `terms().diagonal` (the evaluator and the combinators
    /// guarantee this).
    fn eval(&self, s: &TriScalars, order: Order) -> Partials;
    /// Which leg pairs this kernel uses (corner triangles by default).
    fn terms(&self) -> Terms {
        CORNERS
    }
    /// Value only (hot path of [`Cost::value`](crate::Cost::value); defaults to
    /// [`eval`](Self::eval) with [`Order::Value`]).
    #[inline(always)]
    fn value(&self, s: &TriScalars) -> f64 {
        self.eval(s, Order::Value).v
    }
    /// Value and first partials (hot path of
    /// [`Gradient::value_grad`](crate::Gradient::value_grad); defaults to [`eval`](Self::eval)
    /// with [`Order::Gradient`]). Combinators override it so that no second-derivative storage
    /// is touched.
    #[inline(always)]
    fn value_grad(&self, s: &TriScalars) -> (f64, [f64; 4]) {
        let p = self.eval(s, Order::Gradient);
        (p.v, p.g)
    }
    /// Values of the four corner terms of one cell (lane `k` = corner `k`): the hot path of the
    /// fast 2D evaluator ([`crate::quad`]). The default calls [`value`](Self::value) per lane;
    /// after inlining, the four lanes are independent and the compiler vectorizes them.
    #[inline(always)]
    fn corners_value(&self, s: &CornerLanes) -> [f64; 4] {
        [
            self.value(&s.lane(0)),
            self.value(&s.lane(1)),
            self.value(&s.lane(2)),
            self.value(&s.lane(3)),
        ]
    }
    /// Values and first partials of the four corner terms of one cell ([`LaneGrad`]). The
    /// default calls [`value_grad`](Self::value_grad) per lane; combinators combine lane-wise
    /// so that a monomorphized sum is one straight-line, vectorizable computation.
    #[inline(always)]
    fn corners_value_grad(&self, s: &CornerLanes) -> LaneGrad {
        let mut out = LaneGrad::default();
        for k in 0..4 {
            let (v, g) = self.value_grad(&s.lane(k));
            out.v[k] = v;
            for i in 0..4 {
                out.g[i][k] = g[i];
            }
        }
        out
    }
    /// Values, first and second partials of the four corner terms of one cell
    /// ([`LanePartials`]); the default calls [`eval`](Self::eval) with [`Order::Hessian`] per
    /// lane.
    #[inline(always)]
    fn corners_hessian(&self, s: &CornerLanes) -> LanePartials {
        let mut out = LanePartials::default();
        for k in 0..4 {
            let p = self.eval(&s.lane(k), Order::Hessian);
            out.v[k] = p.v;
            for i in 0..4 {
                out.g[i][k] = p.g[i];
                for j in 0..4 {
                    out.h[i][j][k] = p.h[i][j];
                }
            }
        }
        out
    }
    /// Which second partials `∂²f/∂sᵢ∂sⱼ` (`s = (α, la, lb, o)`) may be non-zero. The fast
    /// Hessian path skips the others; for a typed kernel the answer is a constant, so the
    /// skipped products are removed at compile time. The default (all `true`) is always correct;
    /// an override must only clear entries that [`eval`](Self::eval) leaves at zero.
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        [[true; 4]; 4]
    }
}

/// The scalars of the four corner triangles of one cell, one **lane** per corner (lane `k` is
/// corner `k`: `a = v_{k+1} − v_k`, `b = v_{k−1} − v_k`), in structure-of-arrays form so that the
/// per-corner arithmetic of a kernel runs on all four corners at once (SIMD).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CornerLanes {
    /// `α` per corner.
    pub alpha: [f64; 4],
    /// `|a|²` per corner.
    pub la: [f64; 4],
    /// `|b|²` per corner.
    pub lb: [f64; 4],
    /// `a·b` per corner.
    pub o: [f64; 4],
    /// Cell id.
    pub cell: usize,
}

impl CornerLanes {
    /// The scalars of corner `k` (`k < 4`).
    #[inline(always)]
    pub fn lane(&self, k: usize) -> TriScalars {
        TriScalars {
            alpha: self.alpha[k],
            la: self.la[k],
            lb: self.lb[k],
            o: self.o[k],
            cell: self.cell,
            corner: k as u8,
        }
    }
}

/// Values and first partials of the four corner terms of a cell: `v[k]` and `g[s][k]` =
/// `∂f/∂s` of corner `k`, `s` indexed as in [`Partials`] (`α`, `la`, `lb`, `o`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LaneGrad {
    /// Value per corner.
    pub v: [f64; 4],
    /// `g[s][k] = ∂f_k/∂s`.
    pub g: [[f64; 4]; 4],
}

impl LaneGrad {
    /// `self += w·o`, lane-wise.
    #[inline(always)]
    pub fn add_scaled(&mut self, w: f64, o: &LaneGrad) {
        for k in 0..4 {
            self.v[k] += w * o.v[k];
        }
        for i in 0..4 {
            for k in 0..4 {
                self.g[i][k] += w * o.g[i][k];
            }
        }
    }
    /// `self += w_k·o` with one weight per lane.
    #[inline(always)]
    pub fn add_scaled_lanes(&mut self, w: &[f64; 4], o: &LaneGrad) {
        for k in 0..4 {
            self.v[k] += w[k] * o.v[k];
        }
        for i in 0..4 {
            for k in 0..4 {
                self.g[i][k] += w[k] * o.g[i][k];
            }
        }
    }
}

/// Values, first and second partials of the four corner terms of a cell: `h[s][t][k]` =
/// `∂²f_k/∂s∂t`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LanePartials {
    /// Value per corner.
    pub v: [f64; 4],
    /// `g[s][k] = ∂f_k/∂s`.
    pub g: [[f64; 4]; 4],
    /// `h[s][t][k] = ∂²f_k/∂s∂t` (symmetric in `s`, `t`).
    pub h: [[[f64; 4]; 4]; 4],
}

impl LanePartials {
    /// `self += w·o`, lane-wise.
    #[inline(always)]
    pub fn add_scaled(&mut self, w: f64, o: &LanePartials) {
        self.add_scaled_masked(w, o, &[[true; 4]; 4]);
    }
    /// `self += w·o` on the second partials marked in `mask` only (the others of `o` must be
    /// zero, e.g. `mask` = the [`TriKernel::hessian_sparsity`] of the kernel that produced
    /// `o`; for a typed kernel the mask is a constant and the skipped products vanish at
    /// compile time).
    #[inline(always)]
    pub fn add_scaled_masked(&mut self, w: f64, o: &LanePartials, mask: &[[bool; 4]; 4]) {
        for k in 0..4 {
            self.v[k] += w * o.v[k];
        }
        for i in 0..4 {
            for k in 0..4 {
                self.g[i][k] += w * o.g[i][k];
            }
            for j in 0..4 {
                if mask[i][j] {
                    for k in 0..4 {
                        self.h[i][j][k] += w * o.h[i][j][k];
                    }
                }
            }
        }
    }
}

#[inline(always)]
pub(crate) fn axpy_lanes(acc: &mut [f64; 4], w: f64, o: [f64; 4]) {
    for k in 0..4 {
        acc[k] += w * o[k];
    }
}

/// Sparsity of `∂²f/∂s²` with the given `(i, j)` entries (and their transposes) non-zero.
pub(crate) const fn sparsity(entries: &[(usize, usize)]) -> [[bool; 4]; 4] {
    let mut m = [[false; 4]; 4];
    let mut k = 0;
    while k < entries.len() {
        let (i, j) = entries[k];
        m[i][j] = true;
        m[j][i] = true;
        k += 1;
    }
    m
}

/// Entry-wise `a ∨ b` of two sparsity patterns.
#[inline(always)]
pub(crate) fn sparsity_or(a: [[bool; 4]; 4], b: [[bool; 4]; 4]) -> [[bool; 4]; 4] {
    let mut m = a;
    for i in 0..4 {
        for j in 0..4 {
            m[i][j] |= b[i][j];
        }
    }
    m
}

#[inline(always)]
pub(crate) fn axpy4(acc: &mut (f64, [f64; 4]), w: f64, o: (f64, [f64; 4])) {
    acc.0 += w * o.0;
    for i in 0..4 {
        acc.1[i] += w * o.1[i];
    }
}

pub mod expr;
pub mod leaves;

pub use expr::{KernelExpr, Leaf};
pub use leaves::*;
