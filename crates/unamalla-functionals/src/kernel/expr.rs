//! [`KernelExpr`], the one representation of a 2D functional: a weighted sum of (possibly
//! cell-weighted) leaf kernels, and [`Leaf`], the enum of the leaf kernels.
//!
//! # The expression
//! `F = Σ_q E(q)` over the leg pairs `q` of the mesh, where the per-pair term `E` is
//!
//! * a leaf, `E = f(α, la, lb, o)` ([`KernelExpr::Leaf`]);
//! * a weighted sum `E = Σᵢ wᵢ·Eᵢ` ([`KernelExpr::Sum`]), evaluated as written: an accumulator
//!   starting at 0 receives `wᵢ·Eᵢ` in order;
//! * a cell-weighted expression `E = c(cell)·E₁` ([`KernelExpr::CellWeighted`], the boundary
//!   density `w` of [Méndez 2023, (6.9)]; a cell past the end of the weights has weight 1).
//!
//! A leaf that uses the diagonal pair ([`CastilloArea`]) is evaluated on the diagonal pair only,
//! all others on the four corner triangles ([`TriKernel::terms`]); a sum skips the parts that do
//! not use the pair at hand.
//!
//! Building: [`KernelExpr::from`] a leaf (every leaf struct converts, as does a [`Leaf`]),
//! [`KernelExpr::custom`] for a user [`TriKernel`], then [`weighted_sum`](KernelExpr::weighted_sum),
//! [`convex`](KernelExpr::convex), [`scaled`](KernelExpr::scaled),
//! [`normalized`](KernelExpr::normalized) and [`cell_weighted`](KernelExpr::cell_weighted).
//! These keep the expression flat: a sum that becomes a part of another sum is multiplied out
//! (`a·(b·f + c·g)` is stored as `(a·b)·f + (a·c)·g`, equal up to rounding and cheaper).
//! [`nested_sum`](KernelExpr::nested_sum) keeps a grouping as written when the evaluation order
//! matters.
//!
//! # The leaf list
//! The `leaves!` invocation below is the only place where the leaf kernels are enumerated: it
//! generates [`Leaf`], the conversions `From<leaf> for Leaf` and `for KernelExpr`, `Debug`,
//! and the [`TriKernel`] dispatch of [`Leaf`]. Adding a leaf is one struct in
//! [`leaves`](super::leaves) and one line here (plus, if it has a special ideal value, one arm
//! of [`Leaf::ideal_term`]).

use std::sync::Arc;

#[cfg(doc)]
use super::leaves::GenericArea;
use super::leaves::{
    check_finite, Area, AreaOrthogonality, CastilloArea, HOmega, IvanenkoConvex, KArea,
    KSmoothness, Length, Orthogonality, RegularizedInverseArea, RegularizedSmoothness, SOmegaEps,
    Smoothness, WeightedLength, A4P, SP_NONE,
};
use super::{
    axpy4, axpy_lanes, sparsity_or, wants, CornerLanes, LaneGrad, LanePartials, Order, Partials,
    Terms, TriKernel, TriScalars,
};
use crate::error::FunctionalError;

/// Generates [`Leaf`] and everything that lists its variants from one list of leaf types.
macro_rules! leaves {
    ($($name:ident),* $(,)?) => {
        /// One leaf kernel: any of the kernels of [`leaves`](super::leaves), or a user kernel.
        /// Every leaf struct converts into it (`Leaf::from(HOmega::new(ω)?)`).
        #[derive(Clone)]
        #[non_exhaustive]
        pub enum Leaf {
            $(
                #[doc = concat!("[`", stringify!($name), "`].")]
                $name($name),
            )*
            /// Any user kernel, e.g. a [`GenericArea`].
            Custom(Arc<dyn TriKernel>),
        }

        impl std::fmt::Debug for Leaf {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                match self {
                    $(Leaf::$name(k) => write!(f, "{k:?}"),)*
                    Leaf::Custom(_) => f.write_str("Custom(<kernel>)"),
                }
            }
        }

        $(
            impl From<$name> for Leaf {
                fn from(k: $name) -> Leaf {
                    Leaf::$name(k)
                }
            }
            impl From<$name> for KernelExpr {
                fn from(k: $name) -> KernelExpr {
                    KernelExpr::leaf(Leaf::$name(k))
                }
            }
        )*

        impl TriKernel for Leaf {
            #[inline]
            fn eval(&self, s: &TriScalars, order: Order) -> Partials {
                match self {
                    $(Leaf::$name(k) => k.eval(s, order),)*
                    Leaf::Custom(k) => k.eval(s, order),
                }
            }
            #[inline]
            fn terms(&self) -> Terms {
                match self {
                    $(Leaf::$name(k) => k.terms(),)*
                    Leaf::Custom(k) => k.terms(),
                }
            }
            #[inline]
            fn value(&self, s: &TriScalars) -> f64 {
                match self {
                    $(Leaf::$name(k) => k.value(s),)*
                    Leaf::Custom(k) => k.value(s),
                }
            }
            #[inline]
            fn value_grad(&self, s: &TriScalars) -> (f64, [f64; 4]) {
                match self {
                    $(Leaf::$name(k) => k.value_grad(s),)*
                    Leaf::Custom(k) => k.value_grad(s),
                }
            }
            #[inline]
            fn corners_value(&self, s: &CornerLanes) -> [f64; 4] {
                match self {
                    $(Leaf::$name(k) => k.corners_value(s),)*
                    Leaf::Custom(k) => k.corners_value(s),
                }
            }
            #[inline]
            fn corners_value_grad(&self, s: &CornerLanes) -> LaneGrad {
                match self {
                    $(Leaf::$name(k) => k.corners_value_grad(s),)*
                    Leaf::Custom(k) => k.corners_value_grad(s),
                }
            }
            #[inline]
            fn corners_hessian(&self, s: &CornerLanes) -> LanePartials {
                match self {
                    $(Leaf::$name(k) => k.corners_hessian(s),)*
                    Leaf::Custom(k) => k.corners_hessian(s),
                }
            }
            #[inline]
            fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
                match self {
                    $(Leaf::$name(k) => k.hessian_sparsity(),)*
                    Leaf::Custom(k) => k.hessian_sparsity(),
                }
            }
        }
    };
}

// The leaf list (the only one; see the module docs).
leaves!(
    Length,
    WeightedLength,
    Area,
    CastilloArea,
    A4P,
    Orthogonality,
    AreaOrthogonality,
    Smoothness,
    RegularizedSmoothness,
    RegularizedInverseArea,
    KSmoothness,
    KArea,
    SOmegaEps,
    HOmega,
    IvanenkoConvex,
);

impl Leaf {
    /// A user kernel (e.g. a [`GenericArea`]).
    pub fn custom<K: TriKernel + 'static>(k: K) -> Leaf {
        Leaf::Custom(Arc::new(k))
    }

    /// The value of one corner-triangle term on the **ideal** triangle of a mesh with mean `ᾱ`
    /// (right isosceles with legs `√ᾱ`: `α = ᾱ`, `la = lb = ᾱ`, `o = 0`), used as the
    /// normalization constant per triangle ([González Flores, §5.1]; [Méndez 2023, Obs 6.8]). For
    /// functionals whose ideal value is 0 (orthogonality, A4P) the conventional scale `ᾱ²`
    /// resp. `ᾱ⁴` is returned. `None` for a custom kernel (no natural scale).
    pub fn ideal_term(&self, alpha_bar: f64) -> Option<f64> {
        let s = TriScalars {
            alpha: alpha_bar,
            la: alpha_bar,
            lb: alpha_bar,
            o: 0.0,
            cell: 0,
            corner: 0,
        };
        match self {
            Leaf::Orthogonality(_) => Some(alpha_bar * alpha_bar),
            Leaf::A4P(_) => Some(alpha_bar.powi(4)),
            // one cell (4 corner triangles) has area ᾱ: Castillo per cell ᾱ², i.e. ᾱ²/4 per
            // corner triangle
            Leaf::CastilloArea(_) => Some(0.25 * alpha_bar * alpha_bar),
            Leaf::Custom(_) => None,
            other => Some(other.eval(&s, Order::Value).v),
        }
    }
}

/// A 2D functional's per-pair term (module docs): a leaf, a weighted sum, or a cell-weighted
/// expression. This is what [`QuadFunctional`](crate::QuadFunctional) evaluates; its
/// [`TriKernel`] implementation is the definition (the evaluator of [`crate::quad`] runs the
/// same arithmetic, with fused kernels for the sums it knows).
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum KernelExpr {
    /// One leaf kernel.
    Leaf(Leaf),
    /// `Σ wᵢ Eᵢ`.
    Sum(Vec<(f64, KernelExpr)>),
    /// `c(cell) · E` with one weight per cell.
    CellWeighted(Arc<[f64]>, Box<KernelExpr>),
}

impl From<Leaf> for KernelExpr {
    fn from(l: Leaf) -> KernelExpr {
        KernelExpr::Leaf(l)
    }
}

impl KernelExpr {
    /// One leaf.
    pub fn leaf(leaf: impl Into<Leaf>) -> KernelExpr {
        KernelExpr::Leaf(leaf.into())
    }

    /// A user kernel `k` (e.g. a [`GenericArea`]).
    pub fn custom<K: TriKernel + 'static>(k: K) -> KernelExpr {
        KernelExpr::Leaf(Leaf::custom(k))
    }

    /// `Σ wᵢ Eᵢ`, kept flat: a part that is itself a sum `Σ w_ij E_ij` contributes its parts
    /// with weights `wᵢ·w_ij`.
    pub fn weighted_sum(parts: impl IntoIterator<Item = (f64, KernelExpr)>) -> KernelExpr {
        let mut out = Vec::new();
        for (w, e) in parts {
            match e {
                KernelExpr::Sum(inner) => {
                    out.extend(inner.into_iter().map(|(wi, k)| (w * wi, k)));
                }
                other => out.push((w, other)),
            }
        }
        KernelExpr::Sum(out)
    }

    /// `Σ wᵢ Eᵢ` with the parts as given (no multiplying out): each part is evaluated on its
    /// own, then weighted.
    pub fn nested_sum(parts: impl IntoIterator<Item = (f64, KernelExpr)>) -> KernelExpr {
        KernelExpr::Sum(parts.into_iter().collect())
    }

    /// `σ·a + (1−σ)·b` (σ is the weight of the first functional, as in
    /// [González Flores, Table 5.1, Table 5.2, (5.19)–(5.20)], although its (5.12) states the
    /// opposite; [Méndez 2023, (6.8)] is `convex(1−σ, F_AO, H_ω)`), kept flat as
    /// [`weighted_sum`](Self::weighted_sum).
    pub fn convex(sigma: f64, a: KernelExpr, b: KernelExpr) -> Result<KernelExpr, FunctionalError> {
        if !(0.0..=1.0).contains(&sigma) {
            return Err(FunctionalError::InvalidParameter {
                name: "sigma",
                value: sigma,
                reason: "a convex combination needs 0 ≤ σ ≤ 1".into(),
            });
        }
        Ok(KernelExpr::weighted_sum([(sigma, a), (1.0 - sigma, b)]))
    }

    /// `factor · self`, kept flat as [`weighted_sum`](Self::weighted_sum).
    pub fn scaled(self, factor: f64) -> KernelExpr {
        KernelExpr::weighted_sum([(factor, self)])
    }

    /// Applies one finite weight per cell, in cell order (see
    /// [`QuadTopology::boundary_density`](crate::QuadTopology::boundary_density)).
    pub fn cell_weighted(self, weights: Vec<f64>) -> Result<KernelExpr, FunctionalError> {
        for &w in &weights {
            check_finite("weight", w)?;
        }
        Ok(KernelExpr::CellWeighted(weights.into(), Box::new(self)))
    }

    /// The value of one corner-triangle term on the **ideal** triangle of a mesh with mean `ᾱ`:
    /// [`Leaf::ideal_term`] for a leaf, `Σ wᵢ·ideal_term(Eᵢ)` for a sum, `None` for
    /// cell-weighted expressions and custom kernels (no natural scale).
    pub fn ideal_term(&self, alpha_bar: f64) -> Option<f64> {
        match self {
            KernelExpr::Leaf(l) => l.ideal_term(alpha_bar),
            KernelExpr::Sum(v) => {
                let mut t = 0.0;
                for (w, k) in v {
                    t += w * k.ideal_term(alpha_bar)?;
                }
                Some(t)
            }
            KernelExpr::CellWeighted(..) => None,
        }
    }

    /// The normalized functional `F / (N·ideal_term(ᾱ))` for `N` corner triangles, so that it is
    /// 1 on the ideal grid ([González Flores, §5.1]: e.g. area `Σα²/(Nᾱ²)`, length `Σl/(2Nᾱ)`,
    /// k-smoothness `Σ(l+2k)/(k+α)/(2N)`, k-area `(k+ᾱ)/N·Σ1/(k+α)`).
    pub fn normalized(
        self,
        num_triangles: usize,
        alpha_bar: f64,
    ) -> Result<KernelExpr, FunctionalError> {
        let t = self
            .ideal_term(alpha_bar)
            .ok_or_else(|| FunctionalError::InvalidParameter {
                name: "normalization",
                value: f64::NAN,
                reason: "this kernel has no ideal value".into(),
            })?;
        let k = t * num_triangles as f64;
        if !(k.is_finite() && k > 0.0) {
            return Err(FunctionalError::InvalidParameter {
                name: "normalization",
                value: k,
                reason: "the ideal value must be finite and > 0".into(),
            });
        }
        Ok(self.scaled(1.0 / k))
    }
}

impl TriKernel for KernelExpr {
    #[inline]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        match self {
            KernelExpr::Leaf(l) => l.hessian_sparsity(),
            KernelExpr::Sum(v) => v
                .iter()
                .fold(SP_NONE, |m, (_, k)| sparsity_or(m, k.hessian_sparsity())),
            KernelExpr::CellWeighted(_, k) => k.hessian_sparsity(),
        }
    }
    #[inline]
    fn terms(&self) -> Terms {
        match self {
            KernelExpr::Leaf(l) => l.terms(),
            KernelExpr::Sum(v) => v.iter().fold(
                Terms {
                    corners: false,
                    diagonal: false,
                },
                |t, (_, k)| t.or(k.terms()),
            ),
            KernelExpr::CellWeighted(_, k) => k.terms(),
        }
    }
    #[inline]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        match self {
            KernelExpr::Leaf(l) => l.eval(s, order),
            KernelExpr::Sum(v) => {
                let mut p = Partials::default();
                for (w, k) in v {
                    if wants(k, s) {
                        let q = k.eval(s, order);
                        p.add_scaled(*w, &q, order);
                    }
                }
                p
            }
            KernelExpr::CellWeighted(w, k) => {
                let mut p = k.eval(s, order);
                p.scale(cell_weight(w, s.cell), order);
                p
            }
        }
    }
    #[inline]
    fn value(&self, s: &TriScalars) -> f64 {
        match self {
            KernelExpr::Leaf(l) => l.value(s),
            KernelExpr::Sum(v) => {
                let mut acc = 0.0;
                for (w, k) in v {
                    if wants(k, s) {
                        acc += w * k.value(s);
                    }
                }
                acc
            }
            KernelExpr::CellWeighted(w, k) => cell_weight(w, s.cell) * k.value(s),
        }
    }
    #[inline]
    fn value_grad(&self, s: &TriScalars) -> (f64, [f64; 4]) {
        match self {
            KernelExpr::Leaf(l) => l.value_grad(s),
            KernelExpr::Sum(v) => {
                let mut acc = (0.0, [0.0; 4]);
                for (w, k) in v {
                    if wants(k, s) {
                        axpy4(&mut acc, *w, k.value_grad(s));
                    }
                }
                acc
            }
            KernelExpr::CellWeighted(w, k) => {
                let mut acc = (0.0, [0.0; 4]);
                axpy4(&mut acc, cell_weight(w, s.cell), k.value_grad(s));
                acc
            }
        }
    }
    #[inline]
    fn corners_value(&self, s: &CornerLanes) -> [f64; 4] {
        match self {
            KernelExpr::Leaf(l) => l.corners_value(s),
            KernelExpr::Sum(v) => {
                let mut acc = [0.0; 4];
                for (w, k) in v {
                    if k.terms().corners {
                        axpy_lanes(&mut acc, *w, k.corners_value(s));
                    }
                }
                acc
            }
            KernelExpr::CellWeighted(w, k) => {
                let mut acc = [0.0; 4];
                axpy_lanes(&mut acc, cell_weight(w, s.cell), k.corners_value(s));
                acc
            }
        }
    }
    #[inline]
    fn corners_value_grad(&self, s: &CornerLanes) -> LaneGrad {
        match self {
            KernelExpr::Leaf(l) => l.corners_value_grad(s),
            KernelExpr::Sum(v) => {
                let mut acc = LaneGrad::default();
                for (w, k) in v {
                    if k.terms().corners {
                        acc.add_scaled(*w, &k.corners_value_grad(s));
                    }
                }
                acc
            }
            KernelExpr::CellWeighted(w, k) => {
                let mut acc = LaneGrad::default();
                acc.add_scaled(cell_weight(w, s.cell), &k.corners_value_grad(s));
                acc
            }
        }
    }
    #[inline]
    fn corners_hessian(&self, s: &CornerLanes) -> LanePartials {
        match self {
            KernelExpr::Leaf(l) => l.corners_hessian(s),
            KernelExpr::Sum(v) => {
                let mut acc = LanePartials::default();
                for (w, k) in v {
                    if k.terms().corners {
                        let m = k.hessian_sparsity();
                        acc.add_scaled_masked(*w, &k.corners_hessian(s), &m);
                    }
                }
                acc
            }
            KernelExpr::CellWeighted(w, k) => {
                let mut acc = LanePartials::default();
                let m = k.hessian_sparsity();
                acc.add_scaled_masked(cell_weight(w, s.cell), &k.corners_hessian(s), &m);
                acc
            }
        }
    }
}

/// The weight of cell `c` (1 past the end).
#[inline(always)]
fn cell_weight(w: &[f64], c: usize) -> f64 {
    w.get(c).copied().unwrap_or(1.0)
}
