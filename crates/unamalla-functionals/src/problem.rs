//! The optimization-facing interface, split into small capability traits (the problem/solver
//! separation of argmin, whose `CostFunction`, `Gradient` and `Hessian` are separate traits): a
//! solver asks for exactly what it uses, and a wrapper that changes one capability implements
//! only that one.
//!
//! | trait | methods | used by |
//! |---|---|---|
//! | [`Variables`] | `dim`, `num_vars`, `free_nodes`, `var_of` | everything (sizes, the node ↔ variable map) |
//! | [`Cost`] | `value` = `F(x)` | argmin's cost, evaluation |
//! | [`Gradient`] | `value_grad` = `(F(x), ∇F(x))` | every solver |
//! | [`Hessian`] | `hessian_pattern`, `hessian` = `∇²F(x)`, `hess_vec` = `∇²F(x)·v` | truncated Newton (its quadratic model), the node colouring of pointwise Newton |
//! | [`PointwiseModel`] | `local`, `local_value`: `F` restricted to one node | pointwise Newton |
//! | [`ElementMeasures`] | `num_elements`, `element_measures`, `element_nodes` | the convexity safeguard and its statistics |
//!
//! [`Problem`] is all of them (a blanket implementation: any type with the six capabilities is a
//! `Problem`), for the code that needs everything — the solver entry points, which choose the
//! method at run time. Shared references forward every capability (`&P` is a problem when `P`
//! is).
//!
//! # Replacing one capability
//! [`WithHessian`] and [`WithMeasures`] take every capability from an inner problem except the
//! one they replace: the PSD-projected model Hessian of truncated Newton
//! (`unamalla_optim::psd_model::PsdModel`) implements only [`Hessian`] over a borrowed
//! functional, and `WithHessian::new(&f, model)` is the problem the solver sees. The adaptor
//! (rather than a second Hessian argument of the solvers) keeps one problem per run: the
//! solvers, the session and the drivers see the same type whatever is replaced, and the
//! replacement can be any capability without a new solver signature.
//!
//! ```
//! use std::sync::Arc;
//! use unamalla_functionals::prelude::*;
//! use unamalla_functionals::{Csr, Length, QuadFunctional, QuadTopology, WithHessian};
//! use unamalla_mesh::{DVec2, StructuredGrid2};
//!
//! /// `2·I`: a constant model Hessian with the functional's sparsity pattern.
//! struct TwiceIdentity<'a>(&'a QuadFunctional);
//! impl Hessian for TwiceIdentity<'_> {
//!     fn hessian_pattern(&self) -> Csr {
//!         self.0.hessian_pattern()
//!     }
//!     fn hessian(&self, _x: &[f64], h: &mut Csr) {
//!         for r in 0..h.nrows {
//!             for k in h.row_offsets[r]..h.row_offsets[r + 1] {
//!                 h.values[k] = if h.col_indices[k] as usize == r { 2.0 } else { 0.0 };
//!             }
//!         }
//!     }
//!     fn hess_vec(&self, _x: &[f64], v: &[f64], out: &mut [f64]) {
//!         out.iter_mut().zip(v).for_each(|(o, v)| *o = 2.0 * v);
//!     }
//! }
//!
//! let g = StructuredGrid2::from_fn(3, 3, |i, j| DVec2::new(i as f64, j as f64)).unwrap();
//! let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
//! let f = QuadFunctional::new(topo.clone(), Length);
//! let p = WithHessian::new(&f, TwiceIdentity(&f));
//! let x = topo.initial_x();
//! assert_eq!(p.value(&x), f.value(&x)); // the inner functional's value ...
//! let mut h = p.hessian_pattern();
//! p.hessian(&x, &mut h); // ... and the replaced Hessian
//! assert_eq!(h.values.iter().sum::<f64>(), 2.0 * p.num_vars() as f64);
//! ```

use crate::csr::Csr;

/// Value, gradient and Hessian of a functional restricted to one free node (the other nodes held at
/// their current positions): the model used by pointwise Newton ([González Flores, §B.5.2], after
/// García). Only the first `dim` entries of `grad` and the leading `dim × dim` block of `hess` are
/// meaningful (2 for quad meshes, 3 for hex meshes); the rest is zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalModel {
    /// Sum of the terms that involve the node (its incident triangles / tetrahedra / faces).
    pub value: f64,
    /// Gradient with respect to the node's coordinates.
    pub grad: [f64; 3],
    /// Hessian with respect to the node's coordinates.
    pub hess: [[f64; 3]; 3],
    /// 2 or 3.
    pub dim: usize,
}

/// The variables of a discrete functional: the free-node coordinates.
///
/// The variable vector is `x = [x₀, y₀, x₁, y₁, …]` (2D) or `[x₀, y₀, z₀, …]` (3D), ordered by
/// increasing mesh node id of the free nodes ([`free_nodes`](Self::free_nodes)); fixed node
/// coordinates are data stored in the problem. Every slice argument of the other capability
/// traits (`x`, `g`, `v`, `out`) has [`num_vars`](Self::num_vars) entries.
pub trait Variables: Send + Sync {
    /// Space dimension (2 or 3).
    fn dim(&self) -> usize;
    /// Number of variables `dim · num_free_nodes`.
    fn num_vars(&self) -> usize;
    /// Mesh node ids of the free nodes (variable node `j` is `free_nodes()[j]`).
    fn free_nodes(&self) -> &[usize];
    /// Variable-node index of a mesh node, `None` if it is fixed or out of range.
    fn var_of(&self, node: usize) -> Option<usize>;
}

/// The value `F(x)` of a functional of the [`Variables`] (argmin's `CostFunction`).
///
/// Evaluations are parallel (rayon) and deterministic in the implementations of this crate: the
/// result is bit-identical for any number of threads.
///
/// # Panics
/// If `x` has the wrong length (a programming error, not a user-input error).
pub trait Cost: Send + Sync {
    /// The value `F(x)`.
    fn value(&self, x: &[f64]) -> f64;
}

/// The gradient `∇F(x)` (argmin's `Gradient`), evaluated together with the value because the
/// two share every intermediate quantity.
///
/// # Panics
/// If `x` or `g` has the wrong length.
pub trait Gradient: Send + Sync {
    /// The value `F(x)` (the same number as [`Cost::value`]), and `∇F(x)` written to `g`
    /// (overwritten).
    fn value_grad(&self, x: &[f64], g: &mut [f64]) -> f64;
}

/// Second derivatives `∇²F(x)` (argmin's `Hessian`): a sparse matrix refreshed in place, and a
/// matrix-free product. The matrix need not be the exact Hessian: a solver uses it as the
/// curvature of its quadratic model `m(z) = F + ∇Fᵀz + ½ zᵀHz`, so an implementation may
/// supply a model Hessian (e.g. a positive semidefinite projection) and keep the same
/// minimizer, because [`Gradient`] stays exact.
///
/// # Panics
/// If a slice has the wrong length or `h` does not come from
/// [`hessian_pattern`](Self::hessian_pattern).
pub trait Hessian: Send + Sync {
    /// A matrix with the sparsity pattern of the mesh connectivity (the variables of nodes that
    /// share a cell) and zero values (built once; refresh it with [`hessian`](Self::hessian)).
    fn hessian_pattern(&self) -> Csr;
    /// Refreshes the values of `h` (which must come from [`hessian_pattern`](Self::hessian_pattern))
    /// with the Hessian at `x`.
    fn hessian(&self, x: &[f64], h: &mut Csr);
    /// `out = ∇²F(x) v`, matrix-free (for repeated products at one `x`, assembling with
    /// [`hessian`](Self::hessian) and using [`Csr::mul_vec`] is cheaper).
    fn hess_vec(&self, x: &[f64], v: &[f64], out: &mut [f64]);
}

/// The functional restricted to one free node, the other nodes held at their positions in `x`:
/// `F_v(p) = Σ_{T ∋ v} f_T(x with node v at p)`, the sum of the terms that involve node `v`,
/// with its gradient and Hessian in the node's `dim` coordinates ([`LocalModel`]). Pointwise
/// Newton ([González Flores, §B.5.2]) solves `∇²F_v d = −∇F_v` per node and tests the step with
/// [`local_value`](Self::local_value).
pub trait PointwiseModel: Send + Sync {
    /// The local model of mesh node `node`; `None` if the node is fixed or out of range.
    fn local(&self, x: &[f64], node: usize) -> Option<LocalModel>;
    /// Only the value of [`local`](Self::local) (the part of F that depends on `node`): what the
    /// pointwise solver's line search needs for each trial position. The default computes the
    /// whole local model; implementations override it with a value-only evaluation.
    fn local_value(&self, x: &[f64], node: usize) -> Option<f64> {
        self.local(x, node).map(|m| m.value)
    }
}

/// Per-element convexity measures: what the solvers' safeguard keeps above a threshold (a convex
/// start stays convex) and what the convexity statistics report.
///
/// In 2D the measure of the corner triangle at vertex `P` of a cell is
/// `α = (Q − P) × (R − P)` (twice its signed area; `Q`, `R` the neighbours of `P` in the cell),
/// numbered `4·cell + corner`; in 3D the Jacobian determinant of each of the ten tetrahedra of a
/// hexahedron, numbered `10·cell + tet`.
pub trait ElementMeasures: Send + Sync {
    /// Number of elements measured by [`element_measures`](Self::element_measures)
    /// (corner triangles in 2D, tetrahedra in 3D).
    fn num_elements(&self) -> usize;
    /// The convexity measures at `x`, written to `out` ([`num_elements`](Self::num_elements)
    /// entries).
    fn element_measures(&self, x: &[f64], out: &mut [f64]);
    /// Appends to `out` the mesh nodes whose positions element `e`'s measure depends on (a
    /// superset is allowed: the implementations give the nodes of the element's cell). The
    /// default appends nothing; the solvers' safeguard then cannot tell which nodes block a
    /// step and shortens the whole step instead of holding those nodes back.
    fn element_nodes(&self, e: usize, out: &mut Vec<usize>) {
        let _ = (e, out);
    }
}

/// A discrete functional of the free-node coordinates with every capability: [`Variables`],
/// [`Cost`], [`Gradient`], [`Hessian`], [`PointwiseModel`] and [`ElementMeasures`] (see the
/// [module docs](self)). Implemented for every type that has them all; write `P: Problem` where
/// a function needs everything, and the single capability traits where it does not.
pub trait Problem:
    Variables + Cost + Gradient + Hessian + PointwiseModel + ElementMeasures
{
}

impl<T> Problem for T where
    T: Variables + Cost + Gradient + Hessian + PointwiseModel + ElementMeasures + ?Sized
{
}

impl<T: Variables + ?Sized> Variables for &T {
    fn dim(&self) -> usize {
        (**self).dim()
    }
    fn num_vars(&self) -> usize {
        (**self).num_vars()
    }
    fn free_nodes(&self) -> &[usize] {
        (**self).free_nodes()
    }
    fn var_of(&self, node: usize) -> Option<usize> {
        (**self).var_of(node)
    }
}

impl<T: Cost + ?Sized> Cost for &T {
    fn value(&self, x: &[f64]) -> f64 {
        (**self).value(x)
    }
}

impl<T: Gradient + ?Sized> Gradient for &T {
    fn value_grad(&self, x: &[f64], g: &mut [f64]) -> f64 {
        (**self).value_grad(x, g)
    }
}

impl<T: Hessian + ?Sized> Hessian for &T {
    fn hessian_pattern(&self) -> Csr {
        (**self).hessian_pattern()
    }
    fn hessian(&self, x: &[f64], h: &mut Csr) {
        (**self).hessian(x, h)
    }
    fn hess_vec(&self, x: &[f64], v: &[f64], out: &mut [f64]) {
        (**self).hess_vec(x, v, out)
    }
}

impl<T: PointwiseModel + ?Sized> PointwiseModel for &T {
    fn local(&self, x: &[f64], node: usize) -> Option<LocalModel> {
        (**self).local(x, node)
    }
    fn local_value(&self, x: &[f64], node: usize) -> Option<f64> {
        (**self).local_value(x, node)
    }
}

impl<T: ElementMeasures + ?Sized> ElementMeasures for &T {
    fn num_elements(&self) -> usize {
        (**self).num_elements()
    }
    fn element_measures(&self, x: &[f64], out: &mut [f64]) {
        (**self).element_measures(x, out)
    }
    fn element_nodes(&self, e: usize, out: &mut Vec<usize>) {
        (**self).element_nodes(e, out)
    }
}

/// Forwards the capabilities listed to the field `inner` of an adaptor.
macro_rules! forward_to_inner {
    ($ty:ident<$p:ident, $r:ident>: $($cap:ident),*) => {
        $(forward_to_inner!(@one $ty, $p, $r, $cap);)*
    };
    (@one $ty:ident, $p:ident, $r:ident, Variables) => {
        impl<$p: Variables, $r: Send + Sync> Variables for $ty<$p, $r> {
            fn dim(&self) -> usize {
                self.inner.dim()
            }
            fn num_vars(&self) -> usize {
                self.inner.num_vars()
            }
            fn free_nodes(&self) -> &[usize] {
                self.inner.free_nodes()
            }
            fn var_of(&self, node: usize) -> Option<usize> {
                self.inner.var_of(node)
            }
        }
    };
    (@one $ty:ident, $p:ident, $r:ident, Cost) => {
        impl<$p: Cost, $r: Send + Sync> Cost for $ty<$p, $r> {
            fn value(&self, x: &[f64]) -> f64 {
                self.inner.value(x)
            }
        }
    };
    (@one $ty:ident, $p:ident, $r:ident, Gradient) => {
        impl<$p: Gradient, $r: Send + Sync> Gradient for $ty<$p, $r> {
            fn value_grad(&self, x: &[f64], g: &mut [f64]) -> f64 {
                self.inner.value_grad(x, g)
            }
        }
    };
    (@one $ty:ident, $p:ident, $r:ident, Hessian) => {
        impl<$p: Hessian, $r: Send + Sync> Hessian for $ty<$p, $r> {
            fn hessian_pattern(&self) -> Csr {
                self.inner.hessian_pattern()
            }
            fn hessian(&self, x: &[f64], h: &mut Csr) {
                self.inner.hessian(x, h)
            }
            fn hess_vec(&self, x: &[f64], v: &[f64], out: &mut [f64]) {
                self.inner.hess_vec(x, v, out)
            }
        }
    };
    (@one $ty:ident, $p:ident, $r:ident, PointwiseModel) => {
        impl<$p: PointwiseModel, $r: Send + Sync> PointwiseModel for $ty<$p, $r> {
            fn local(&self, x: &[f64], node: usize) -> Option<LocalModel> {
                self.inner.local(x, node)
            }
            fn local_value(&self, x: &[f64], node: usize) -> Option<f64> {
                self.inner.local_value(x, node)
            }
        }
    };
    (@one $ty:ident, $p:ident, $r:ident, ElementMeasures) => {
        impl<$p: ElementMeasures, $r: Send + Sync> ElementMeasures for $ty<$p, $r> {
            fn num_elements(&self) -> usize {
                self.inner.num_elements()
            }
            fn element_measures(&self, x: &[f64], out: &mut [f64]) {
                self.inner.element_measures(x, out)
            }
            fn element_nodes(&self, e: usize, out: &mut Vec<usize>) {
                self.inner.element_nodes(e, out)
            }
        }
    };
}

/// `inner` with its [`Hessian`] replaced by `hessian`: every other capability is `inner`'s.
/// With `inner` a [`Problem`] and `hessian` a [`Hessian`], the adaptor is a [`Problem`] whose
/// value and gradient — hence whose minimizers and every stopping test — are `inner`'s, while
/// truncated Newton builds its quadratic model on `hessian` (see the [module docs](self)).
/// `P` is usually a reference (`WithHessian::new(&f, model)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WithHessian<P, H> {
    /// The problem that supplies every capability but the Hessian.
    pub inner: P,
    /// The Hessian.
    pub hessian: H,
}

impl<P, H> WithHessian<P, H> {
    /// `inner` with the Hessian `hessian`.
    pub fn new(inner: P, hessian: H) -> Self {
        Self { inner, hessian }
    }
}

forward_to_inner!(WithHessian<P, H>: Variables, Cost, Gradient, PointwiseModel, ElementMeasures);

impl<P: Send + Sync, H: Hessian> Hessian for WithHessian<P, H> {
    fn hessian_pattern(&self) -> Csr {
        self.hessian.hessian_pattern()
    }
    fn hessian(&self, x: &[f64], h: &mut Csr) {
        self.hessian.hessian(x, h)
    }
    fn hess_vec(&self, x: &[f64], v: &[f64], out: &mut [f64]) {
        self.hessian.hess_vec(x, v, out)
    }
}

/// `inner` with its [`ElementMeasures`] replaced by `measures`: every other capability is
/// `inner`'s. The solvers' safeguard then keeps `measures` above its threshold instead of
/// `inner`'s measures (a different quality measure, or the same measures without
/// [`element_nodes`](ElementMeasures::element_nodes)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WithMeasures<P, M> {
    /// The problem that supplies every capability but the element measures.
    pub inner: P,
    /// The element measures.
    pub measures: M,
}

impl<P, M> WithMeasures<P, M> {
    /// `inner` with the element measures `measures`.
    pub fn new(inner: P, measures: M) -> Self {
        Self { inner, measures }
    }
}

forward_to_inner!(WithMeasures<P, M>: Variables, Cost, Gradient, Hessian, PointwiseModel);

impl<P: Send + Sync, M: ElementMeasures> ElementMeasures for WithMeasures<P, M> {
    fn num_elements(&self) -> usize {
        self.measures.num_elements()
    }
    fn element_measures(&self, x: &[f64], out: &mut [f64]) {
        self.measures.element_measures(x, out)
    }
    fn element_nodes(&self, e: usize, out: &mut Vec<usize>) {
        self.measures.element_nodes(e, out)
    }
}

/// The capability traits and [`Problem`], for `use unamalla_functionals::prelude::*` (a method
/// call such as `f.value(&x)` on a concrete functional needs its trait in scope).
pub mod prelude {
    pub use super::{Cost, ElementMeasures, Gradient, Hessian, PointwiseModel, Problem, Variables};
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `F(x) = Σ cᵢ xᵢ²` on one 2D node (`c = (1, 3)`): `∇F = 2c∘x`, `∇²F = diag(2c)`; its one
    /// "element" measures `x₀ + x₁`.
    struct Diag;
    impl Variables for Diag {
        fn dim(&self) -> usize {
            2
        }
        fn num_vars(&self) -> usize {
            2
        }
        fn free_nodes(&self) -> &[usize] {
            &[7]
        }
        fn var_of(&self, node: usize) -> Option<usize> {
            (node == 7).then_some(0)
        }
    }
    impl Cost for Diag {
        fn value(&self, x: &[f64]) -> f64 {
            x[0] * x[0] + 3.0 * x[1] * x[1]
        }
    }
    impl Gradient for Diag {
        fn value_grad(&self, x: &[f64], g: &mut [f64]) -> f64 {
            g[0] = 2.0 * x[0];
            g[1] = 6.0 * x[1];
            self.value(x)
        }
    }
    impl Hessian for Diag {
        fn hessian_pattern(&self) -> Csr {
            Csr {
                nrows: 2,
                ncols: 2,
                row_offsets: vec![0, 1, 2],
                col_indices: vec![0, 1],
                values: vec![0.0; 2],
            }
        }
        fn hessian(&self, _x: &[f64], h: &mut Csr) {
            h.values.copy_from_slice(&[2.0, 6.0]);
        }
        fn hess_vec(&self, _x: &[f64], v: &[f64], out: &mut [f64]) {
            out[0] = 2.0 * v[0];
            out[1] = 6.0 * v[1];
        }
    }
    impl PointwiseModel for Diag {
        fn local(&self, x: &[f64], node: usize) -> Option<LocalModel> {
            (node == 7).then(|| LocalModel {
                value: self.value(x),
                grad: [2.0 * x[0], 6.0 * x[1], 0.0],
                hess: [[2.0, 0.0, 0.0], [0.0, 6.0, 0.0], [0.0; 3]],
                dim: 2,
            })
        }
    }
    impl ElementMeasures for Diag {
        fn num_elements(&self) -> usize {
            1
        }
        fn element_measures(&self, x: &[f64], out: &mut [f64]) {
            out[0] = x[0] + x[1];
        }
        fn element_nodes(&self, _e: usize, out: &mut Vec<usize>) {
            out.push(7);
        }
    }

    /// The identity as a model Hessian, and `−x₀` as the only measure (no node list).
    struct Unit;
    impl Hessian for Unit {
        fn hessian_pattern(&self) -> Csr {
            Diag.hessian_pattern()
        }
        fn hessian(&self, _x: &[f64], h: &mut Csr) {
            h.values.copy_from_slice(&[1.0, 1.0]);
        }
        fn hess_vec(&self, _x: &[f64], v: &[f64], out: &mut [f64]) {
            out.copy_from_slice(v);
        }
    }
    impl ElementMeasures for Unit {
        fn num_elements(&self) -> usize {
            1
        }
        fn element_measures(&self, x: &[f64], out: &mut [f64]) {
            out[0] = -x[0];
        }
    }

    fn needs_all<P: Problem + ?Sized>(p: &P, x: &[f64]) -> (f64, [f64; 2], Vec<f64>, Vec<f64>) {
        let mut g = [0.0; 2];
        let f = p.value_grad(x, &mut g);
        assert_eq!(f, p.value(x));
        let mut h = p.hessian_pattern();
        p.hessian(x, &mut h);
        let mut m = vec![0.0; p.num_elements()];
        p.element_measures(x, &mut m);
        (f, g, h.values, m)
    }

    #[test]
    fn adaptors_replace_one_capability_and_forward_the_others() {
        let x = [2.0, -1.0];
        // F = 4 + 3 = 7, ∇F = (4, −6), ∇²F = diag(2, 6), measure x₀ + x₁ = 1
        assert_eq!(
            needs_all(&Diag, &x),
            (7.0, [4.0, -6.0], vec![2.0, 6.0], vec![1.0])
        );
        let wh = WithHessian::new(&Diag, Unit);
        assert_eq!(
            needs_all(&wh, &x),
            (7.0, [4.0, -6.0], vec![1.0, 1.0], vec![1.0])
        );
        let mut out = [0.0; 2];
        wh.hess_vec(&x, &[3.0, 5.0], &mut out);
        assert_eq!(out, [3.0, 5.0]);
        assert_eq!(wh.local_value(&x, 7), Some(7.0));
        assert_eq!(wh.local(&x, 3), None);
        let (mut nodes, mut none) = (Vec::new(), Vec::new());
        wh.element_nodes(0, &mut nodes);
        assert_eq!(nodes, [7]);
        let wm = WithMeasures::new(Diag, Unit);
        assert_eq!(
            needs_all(&wm, &x),
            (7.0, [4.0, -6.0], vec![2.0, 6.0], vec![-2.0])
        );
        wm.element_nodes(0, &mut none);
        assert!(none.is_empty(), "the replacement's default node list");
        assert_eq!(
            (wm.dim(), wm.num_vars(), wm.free_nodes(), wm.var_of(7)),
            (2, 2, &[7][..], Some(0))
        );
        // through a trait object, as the drivers' probes are passed
        let dynamic: &dyn Problem = &wm;
        assert_eq!(needs_all(dynamic, &x).3, vec![-2.0]);
    }
}
