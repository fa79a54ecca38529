//! The optimization-facing interface: a [`Problem`] is a smooth function of the free-node
//! coordinates with exact derivatives (argmin-style problem/solver separation: the optimizer
//! crate only sees this trait).

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

/// A discrete functional of the free-node coordinates.
///
/// The variable vector is `x = [x₀, y₀, x₁, y₁, …]` (2D) or `[x₀, y₀, z₀, …]` (3D), ordered by
/// increasing mesh node id of the free nodes ([`free_nodes`](Self::free_nodes)); fixed node
/// coordinates are data stored in the problem. All evaluations are parallel (rayon) and
/// deterministic: the result is bit-identical for any number of threads.
///
/// # Panics
/// The evaluation methods panic if a slice has the wrong length (a programming error, not a
/// user-input error): `x`, `g`, `v`, `out` must have [`num_vars`](Self::num_vars) entries.
pub trait Problem: Send + Sync {
    /// Space dimension (2 or 3).
    fn dim(&self) -> usize;
    /// Number of variables `dim · num_free_nodes`.
    fn num_vars(&self) -> usize;
    /// Mesh node ids of the free nodes (variable node `j` is `free_nodes()[j]`).
    fn free_nodes(&self) -> &[usize];
    /// Variable-node index of a mesh node, `None` if it is fixed or out of range.
    fn var_of(&self, node: usize) -> Option<usize>;
    /// The value `F(x)`.
    fn value(&self, x: &[f64]) -> f64;
    /// The value, and the gradient written to `g` (overwritten).
    fn value_grad(&self, x: &[f64], g: &mut [f64]) -> f64;
    /// A Hessian with the sparsity pattern of the mesh connectivity and zero values (built once;
    /// refresh it with [`hessian`](Self::hessian)).
    fn hessian_pattern(&self) -> Csr;
    /// Refreshes the values of `h` (which must come from [`hessian_pattern`](Self::hessian_pattern))
    /// with the exact Hessian at `x`.
    fn hessian(&self, x: &[f64], h: &mut Csr);
    /// `out = ∇²F(x) v`, matrix-free (exact; for repeated products at one `x`, assembling with
    /// [`hessian`](Self::hessian) and using [`Csr::mul_vec`] is cheaper).
    fn hess_vec(&self, x: &[f64], v: &[f64], out: &mut [f64]);
    /// The local model of mesh node `node`; `None` if the node is fixed or out of range.
    fn local(&self, x: &[f64], node: usize) -> Option<LocalModel>;
    /// Only the value of [`local`](Self::local) (the part of F that depends on `node`): what the
    /// pointwise solver's line search needs for each trial position. The default computes the
    /// whole local model; implementations override it with a value-only evaluation.
    fn local_value(&self, x: &[f64], node: usize) -> Option<f64> {
        self.local(x, node).map(|m| m.value)
    }
    /// Number of elements measured by [`element_measures`](Self::element_measures)
    /// (corner triangles in 2D, tetrahedra in 3D).
    fn num_elements(&self) -> usize;
    /// The convexity measures at `x`: α of every corner triangle (2D, `4·cell + corner`) or
    /// the Jacobian determinant of every tetrahedron (3D, `10·cell + tet`).
    fn element_measures(&self, x: &[f64], out: &mut [f64]);
    /// Appends to `out` the mesh nodes whose positions element `e`'s measure depends on (a
    /// superset is allowed: the implementations give the nodes of the element's cell). The
    /// default appends nothing; the solvers' safeguard then cannot tell which nodes block a
    /// step and shortens the whole step instead of holding those nodes back.
    fn element_nodes(&self, e: usize, out: &mut Vec<usize>) {
        let _ = (e, out);
    }
}
