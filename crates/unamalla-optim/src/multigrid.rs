//! Smoothed-aggregation algebraic multigrid: a symmetric V-cycle used as the preconditioner of
//! the inner CG of truncated Newton ([`Preconditioner::Multigrid`](crate::Preconditioner)).
//!
//! # Why
//! The Hessians of the smoothing functionals ([Méndez 2023, (6.8)], the area/length/Winslow kernels
//! of [González Flores, Ch. 2–3]) are discrete second-order elliptic operators ("Laplacian-like"):
//! their condition number grows like `h⁻²`, so CG preconditioned by the node-block diagonal needs
//! `O(√κ) = O(n)` iterations on an `n × n` grid (measured: the 200-iteration cap is hit from 300²
//! on; see `docs/benchmarks.md`). A multigrid V-cycle is a preconditioner whose quality does not
//! depend on `h`, so CG needs a bounded number of iterations per Newton step.
//!
//! # Algorithm (Vaněk, Mandel, Brezina 1996, "Algebraic multigrid by smoothed aggregation")
//! Unknowns are grouped by node (`dim` coordinates per node, interleaved as in the Hessians of
//! `unamalla-functionals`). On each level with operator `A`:
//! 1. **Aggregation** of the node graph of `A` (strong neighbours: `‖A_ij‖_F ≥ θ·√(‖A_ii‖_F‖A_jj‖_F)`,
//!    θ = [`MultigridOptions::strength`]): phase 1 makes an aggregate of every node whose strong
//!    neighbours are all free, together with them; phase 2 joins each left-over node to a
//!    neighbouring aggregate; phase 3 groups what is still left. On the 9-point node graph of a
//!    structured quad grid this gives 3 × 3 aggregates (coarsening ≈ 9×).
//! 2. **Tentative prolongation** `P̂`: the near-null space is the `dim` translations, so
//!    `P̂[(v, c), (a, c)] = 1` when node `v` is in aggregate `a` (component `c`).
//! 3. **Smoothed prolongation** `P = (I − ω D⁻¹A) P̂` with `D` the node-block diagonal of `A` and
//!    `ω = 4/(3ρ̂)`, `ρ̂ ≥ ρ(D⁻¹A)` (Gershgorin bound of the rows of `D⁻¹A`).
//! 4. **Galerkin coarse operator** `A_c = Pᵀ A P` (sparse products written here; `A_c` is SPD
//!    when `A` is, since `P` has full column rank).
//!
//! Coarsening stops at [`MultigridOptions::coarse_size`] unknowns, where the coarsest operator
//! is factored by a dense Cholesky decomposition (nalgebra's `Cholesky`, with a small diagonal
//! shift if it is not numerically positive definite).
//!
//! **V-cycle** `z = M⁻¹ r` (`ν` = [`MultigridOptions::sweeps`]): `ν` damped block-Jacobi sweeps
//! `x ← x + ω_s D⁻¹(b − A x)` from `x = 0`, restriction `b_c = Pᵀ(b − A x)`, recursive coarse
//! correction `x ← x + P x_c`, `ν` more sweeps. The Jacobi sweep is symmetric in the `A`
//! inner product and the same number of sweeps is done before and after, so `M⁻¹` is
//! symmetric; with `ω_s ρ(D⁻¹A) < 2` (here `ω_s = 4/(3ρ̂) ≤ 4/3 ρ/ρ̂`) every sweep is an
//! `A`-norm contraction, hence `M⁻¹` is positive definite when `A` is (Hackbusch, Multi-Grid
//! Methods, §10.7). The smoother uses the block-Jacobi inverse of
//! [`PrecondApply`], which falls back to `|diag|` on node blocks that are not positive definite.
//!
//! Setup cost per Hessian is two sparse products per level (`A·P` and `Pᵀ·(AP)`), dominated by
//! the finest level (≈ 2–4 fine matrix-vector products); one V-cycle costs ≈ `2ν + 2` fine
//! matrix-vector products.

use nalgebra::{Cholesky, DMatrix, DVectorViewMut, Dyn};
use rayon::prelude::*;
use unamalla_functionals::Csr;

use crate::linalg::{PrecondApply, Preconditioner};

/// Options of the multigrid hierarchy.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct MultigridOptions {
    /// Stop coarsening when a level has at most this many unknowns (solved directly).
    pub coarse_size: usize,
    /// Maximum number of levels (including the finest).
    pub max_levels: usize,
    /// Smoothing sweeps before and after the coarse correction (`ν`).
    pub sweeps: usize,
    /// Strength-of-connection threshold θ of the aggregation (0 = every neighbour is strong).
    pub strength: f64,
}

impl Default for MultigridOptions {
    fn default() -> Self {
        Self {
            coarse_size: 600,
            max_levels: 12,
            sweeps: 1,
            strength: 0.0,
        }
    }
}

impl MultigridOptions {
    /// Sets [`coarse_size`](Self::coarse_size).
    #[must_use]
    pub fn coarse_size(mut self, coarse_size: usize) -> Self {
        self.coarse_size = coarse_size;
        self
    }

    /// Sets [`max_levels`](Self::max_levels): maximum number of levels (including the finest).
    #[must_use]
    pub fn max_levels(mut self, max_levels: usize) -> Self {
        self.max_levels = max_levels;
        self
    }

    /// Sets [`sweeps`](Self::sweeps): smoothing sweeps before and after the coarse correction
    /// (`ν`).
    #[must_use]
    pub fn sweeps(mut self, sweeps: usize) -> Self {
        self.sweeps = sweeps;
        self
    }

    /// Sets [`strength`](Self::strength).
    #[must_use]
    pub fn strength(mut self, strength: f64) -> Self {
        self.strength = strength;
        self
    }
}

/// One level above the coarsest: its operator (not stored for the finest level, which the
/// caller passes to [`Multigrid::apply`]), its smoother and the transfer to the next level.
#[derive(Debug, Clone)]
struct Level {
    /// Operator of this level (empty for level 0).
    a: Csr,
    /// Block-Jacobi inverse of this level's node blocks.
    smoother: PrecondApply,
    /// Damping of the Jacobi sweeps.
    omega: f64,
    /// Prolongation from the next level.
    p: Csr,
    /// Restriction `Pᵀ`.
    r: Csr,
}

/// A smoothed-aggregation multigrid hierarchy for one symmetric matrix (see the module docs).
///
/// ```
/// use unamalla_functionals::Csr;
/// use unamalla_optim::multigrid::{Multigrid, MultigridOptions};
///
/// // 1D Laplacian tridiag(−1, 2, −1) with 2000 unknowns (dim = 1)
/// let n = 2000;
/// let (mut ro, mut ci, mut v) = (vec![0], Vec::new(), Vec::new());
/// for i in 0..n {
///     if i > 0 { ci.push(i as u32 - 1); v.push(-1.0); }
///     ci.push(i as u32); v.push(2.0);
///     if i + 1 < n { ci.push(i as u32 + 1); v.push(-1.0); }
///     ro.push(ci.len());
/// }
/// let a = Csr { nrows: n, ncols: n, row_offsets: ro, col_indices: ci, values: v };
/// let mg = Multigrid::build(&a, 1, &MultigridOptions::default());
/// assert!(mg.num_levels() >= 2);
/// let r = vec![1.0; n];
/// let mut z = vec![0.0; n];
/// mg.apply(&a, &r, &mut z); // z = M⁻¹ r, one symmetric V-cycle
/// assert!(r.iter().zip(&z).map(|(r, z)| r * z).sum::<f64>() > 0.0);
/// ```
#[derive(Debug, Clone)]
pub struct Multigrid {
    dim: usize,
    sweeps: usize,
    levels: Vec<Level>,
    /// Coarsest operator (level `levels.len()`), kept for diagnostics.
    coarse_n: usize,
    /// Cholesky factorization of the coarsest operator (`coarse_n × coarse_n`).
    chol: Cholesky<f64, Dyn>,
    /// Unknowns per level (finest first).
    sizes: Vec<usize>,
    /// Stored entries per level (finest first).
    nnzs: Vec<usize>,
}

fn empty_csr() -> Csr {
    Csr {
        nrows: 0,
        ncols: 0,
        row_offsets: vec![0],
        col_indices: Vec::new(),
        values: Vec::new(),
    }
}

impl Multigrid {
    /// Builds the hierarchy of the symmetric matrix `a` whose unknowns are node blocks of size
    /// `dim` (`a.nrows` must be a multiple of `dim`; otherwise `dim = 1` is used).
    pub fn build(a: &Csr, dim: usize, opts: &MultigridOptions) -> Self {
        let dim = if dim == 0 || !a.nrows.is_multiple_of(dim) {
            1
        } else {
            dim
        };
        let mut levels: Vec<Level> = Vec::new();
        let mut sizes = vec![a.nrows];
        let mut nnzs = vec![a.nnz()];
        let mut cur: Option<Csr> = None;
        loop {
            let op: &Csr = cur.as_ref().unwrap_or(a);
            let n = op.nrows;
            if n <= opts.coarse_size.max(dim) || levels.len() + 1 >= opts.max_levels.max(1) {
                break;
            }
            let mut smoother = PrecondApply::default();
            smoother.build(Preconditioner::BlockJacobi, op, dim);
            let rho = dinv_a_bound(op, &smoother, dim);
            let omega = 4.0 / (3.0 * rho);
            let (agg, nagg) = aggregate(op, dim, opts.strength);
            if nagg == 0 || nagg * dim * 10 > n * 9 {
                // coarsening stalled: solve this level directly
                break;
            }
            let p = smoothed_prolongation(op, &smoother, dim, &agg, nagg, omega);
            let r = transpose(&p);
            let ap = spgemm(op, &p);
            let ac = spgemm(&r, &ap);
            sizes.push(ac.nrows);
            nnzs.push(ac.nnz());
            let a_store = cur.take().unwrap_or_else(empty_csr);
            levels.push(Level {
                a: a_store,
                smoother,
                omega,
                p,
                r,
            });
            cur = Some(ac);
        }
        let coarse = cur.as_ref().unwrap_or(a);
        let coarse_n = coarse.nrows;
        let chol = dense_cholesky_shifted(coarse);
        Self {
            dim,
            sweeps: opts.sweeps,
            levels,
            coarse_n,
            chol,
            sizes,
            nnzs,
        }
    }

    /// Refreshes the finest level's smoother (block-Jacobi of `a`) and keeps the coarse levels:
    /// a lagged hierarchy for a matrix with the pattern of the one it was built from and
    /// nearby values (the next Newton iterate's Hessian). The V-cycle stays symmetric; it is
    /// positive definite while `ω_s ρ(D⁻¹A) < 2`, checked here by the Gershgorin bound (the
    /// damping is recomputed). Returns false (and changes nothing) if the size differs.
    pub fn refresh_finest(&mut self, a: &Csr) -> bool {
        if a.nrows != self.sizes[0] {
            return false;
        }
        if let Some(l0) = self.levels.first_mut() {
            l0.smoother.build(Preconditioner::BlockJacobi, a, self.dim);
            let rho = dinv_a_bound(a, &l0.smoother, self.dim);
            l0.omega = 4.0 / (3.0 * rho);
        } else {
            self.chol = dense_cholesky_shifted(a);
        }
        true
    }

    /// Number of levels (1 = the matrix is solved directly).
    pub fn num_levels(&self) -> usize {
        self.levels.len() + 1
    }

    /// Unknowns per level, finest first.
    pub fn level_sizes(&self) -> &[usize] {
        &self.sizes
    }

    /// Operator complexity `Σ nnz(A_l) / nnz(A_0)`.
    pub fn operator_complexity(&self) -> f64 {
        let total: usize = self.nnzs.iter().sum();
        total as f64 / self.nnzs.first().copied().unwrap_or(1).max(1) as f64
    }

    /// Node block size used.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// `z = M⁻¹ r`: one symmetric V-cycle for the finest operator `a` (the matrix the hierarchy
    /// was built from, or one with the same pattern and similar values).
    ///
    /// # Panics
    /// If `a`, `r` and `z` do not have the size of the finest level.
    pub fn apply(&self, a: &Csr, r: &[f64], z: &mut [f64]) {
        assert_eq!(
            r.len(),
            self.sizes[0],
            "Multigrid::apply: r has the wrong length"
        );
        assert_eq!(
            z.len(),
            self.sizes[0],
            "Multigrid::apply: z has the wrong length"
        );
        self.vcycle(0, a, r, z);
    }

    fn vcycle(&self, l: usize, a_fine: &Csr, b: &[f64], x: &mut [f64]) {
        if l == self.levels.len() {
            x.copy_from_slice(b);
            self.chol
                .solve_mut(&mut DVectorViewMut::from_slice(x, self.coarse_n));
            return;
        }
        let lev = &self.levels[l];
        let a = if l == 0 { a_fine } else { &lev.a };
        let n = b.len();
        let mut res = vec![0.0; n];
        let mut t = vec![0.0; n];
        // pre-smoothing from x = 0: the first sweep is x = ω D⁻¹ b
        lev.smoother.apply(b, x);
        x.par_iter_mut().for_each(|v| *v *= lev.omega);
        for _ in 1..self.sweeps_of() {
            jacobi_sweep(a, &lev.smoother, lev.omega, b, x, &mut res, &mut t);
        }
        // coarse correction
        residual(a, b, x, &mut res);
        let nc = lev.p.ncols;
        let mut bc = vec![0.0; nc];
        lev.r.mul_vec(&res, &mut bc);
        let mut xc = vec![0.0; nc];
        self.vcycle(l + 1, a_fine, &bc, &mut xc);
        lev.p.mul_vec(&xc, &mut t);
        x.par_iter_mut()
            .zip(t.par_iter())
            .for_each(|(x, t)| *x += t);
        for _ in 0..self.sweeps_of() {
            jacobi_sweep(a, &lev.smoother, lev.omega, b, x, &mut res, &mut t);
        }
    }

    fn sweeps_of(&self) -> usize {
        self.sweeps.max(1)
    }
}

/// `res = b − A x`.
fn residual(a: &Csr, b: &[f64], x: &[f64], res: &mut [f64]) {
    a.mul_vec(x, res);
    res.par_iter_mut()
        .zip(b.par_iter())
        .for_each(|(r, b)| *r = b - *r);
}

/// One damped block-Jacobi sweep `x ← x + ω D⁻¹ (b − A x)`.
fn jacobi_sweep(
    a: &Csr,
    d: &PrecondApply,
    omega: f64,
    b: &[f64],
    x: &mut [f64],
    res: &mut [f64],
    t: &mut [f64],
) {
    residual(a, b, x, res);
    d.apply(res, t);
    x.par_iter_mut()
        .zip(t.par_iter())
        .for_each(|(x, t)| *x += omega * t);
}

/// Gershgorin bound of `ρ(D⁻¹A)`: the largest absolute row sum of `D⁻¹A` (node-block `D`).
fn dinv_a_bound(a: &Csr, d: &PrecondApply, dim: usize) -> f64 {
    let nb = a.nrows / dim;
    let m = (0..nb)
        .into_par_iter()
        .with_min_len(1024)
        .map(|b| {
            let inv = d.block(b);
            let mut best = 0.0f64;
            for i in 0..dim {
                // row i of D⁻¹A = Σ_k inv[i][k] · row (b·dim + k) of A
                let mut s = 0.0;
                // rows of a node block share their column pattern (block pattern); fall back
                // to summing the absolute values row by row otherwise
                let r0 = b * dim;
                let (s0, e0) = (a.row_offsets[r0], a.row_offsets[r0 + 1]);
                let same = (1..dim).all(|k| {
                    let (sk, ek) = (a.row_offsets[r0 + k], a.row_offsets[r0 + k + 1]);
                    ek - sk == e0 - s0 && a.col_indices[sk..ek] == a.col_indices[s0..e0]
                });
                if same {
                    for e in 0..(e0 - s0) {
                        let mut v = 0.0;
                        for k in 0..dim {
                            v += inv[i * dim + k] * a.values[a.row_offsets[r0 + k] + e];
                        }
                        s += v.abs();
                    }
                } else {
                    for k in 0..dim {
                        let (sk, ek) = (a.row_offsets[r0 + k], a.row_offsets[r0 + k + 1]);
                        let vs: f64 = a.values[sk..ek].iter().map(|v| v.abs()).sum();
                        s += inv[i * dim + k].abs() * vs;
                    }
                }
                best = best.max(s);
            }
            best
        })
        .reduce(|| 0.0, f64::max);
    if m.is_finite() && m > 0.0 {
        m
    } else {
        2.0
    }
}

/// Greedy aggregation of the node graph of `a` (see the module docs). Returns the aggregate of
/// every node and the number of aggregates.
fn aggregate(a: &Csr, dim: usize, theta: f64) -> (Vec<u32>, usize) {
    let nb = a.nrows / dim;
    // strong node neighbours, from the first row of each node block
    let block_norm = |r0: usize, cb: usize| -> f64 {
        let mut s = 0.0;
        for k in 0..dim {
            for c in 0..dim {
                let v = a.get(r0 + k, cb * dim + c);
                s += v * v;
            }
        }
        s.sqrt()
    };
    let diag: Vec<f64> = if theta > 0.0 {
        (0..nb)
            .into_par_iter()
            .map(|b| block_norm(b * dim, b))
            .collect()
    } else {
        Vec::new()
    };
    let nbrs: Vec<Vec<u32>> = (0..nb)
        .into_par_iter()
        .with_min_len(1024)
        .map(|b| {
            let r0 = b * dim;
            let mut out: Vec<u32> = Vec::with_capacity(12);
            let mut last = u32::MAX;
            for k in a.row_offsets[r0]..a.row_offsets[r0 + 1] {
                let cb = (a.col_indices[k] as usize / dim) as u32;
                if cb == last || cb as usize == b {
                    last = cb;
                    continue;
                }
                last = cb;
                if theta > 0.0 {
                    let s = block_norm(r0, cb as usize);
                    if s < theta * (diag[b] * diag[cb as usize]).sqrt() {
                        continue;
                    }
                }
                out.push(cb);
            }
            out
        })
        .collect();
    const NONE: u32 = u32::MAX;
    let mut agg = vec![NONE; nb];
    let mut count = 0u32;
    // phase 1: root nodes whose strong neighbours are all unaggregated
    for v in 0..nb {
        if agg[v] != NONE {
            continue;
        }
        if nbrs[v].iter().all(|&u| agg[u as usize] == NONE) {
            agg[v] = count;
            for &u in &nbrs[v] {
                agg[u as usize] = count;
            }
            count += 1;
        }
    }
    // phase 2: join a neighbouring aggregate (decided on the phase-1 state)
    let phase1 = agg.clone();
    for v in 0..nb {
        if agg[v] == NONE {
            if let Some(&u) = nbrs[v].iter().find(|&&u| phase1[u as usize] != NONE) {
                agg[v] = phase1[u as usize];
            }
        }
    }
    // phase 3: what is left forms aggregates with its unaggregated neighbours
    for v in 0..nb {
        if agg[v] == NONE {
            agg[v] = count;
            for &u in &nbrs[v] {
                if agg[u as usize] == NONE {
                    agg[u as usize] = count;
                }
            }
            count += 1;
        }
    }
    (agg, count as usize)
}

/// `P = (I − ω D⁻¹A) P̂` with the tentative `P̂` of the aggregates (module docs, step 3).
fn smoothed_prolongation(
    a: &Csr,
    d: &PrecondApply,
    dim: usize,
    agg: &[u32],
    nagg: usize,
    omega: f64,
) -> Csr {
    let nb = a.nrows / dim;
    let rows: Vec<(Vec<u32>, Vec<f64>)> = (0..nb)
        .into_par_iter()
        .with_min_len(512)
        .map(|b| {
            // the coarse columns touched by the node block's rows: (A P̂)[(b,k), (g,c)] =
            // Σ_{columns (u,c) of row (b,k) with agg[u] = g} A
            let mut cols: Vec<u32> = Vec::with_capacity(8);
            for k in 0..dim {
                let r = b * dim + k;
                for e in a.row_offsets[r]..a.row_offsets[r + 1] {
                    let g = agg[a.col_indices[e] as usize / dim];
                    if !cols.contains(&g) {
                        cols.push(g);
                    }
                }
            }
            let own = agg[b];
            if !cols.contains(&own) {
                cols.push(own);
            }
            cols.sort_unstable();
            let m = cols.len();
            // ap[k][j·dim + c]
            let mut ap = vec![0.0; dim * m * dim];
            for k in 0..dim {
                let r = b * dim + k;
                for e in a.row_offsets[r]..a.row_offsets[r + 1] {
                    let col = a.col_indices[e] as usize;
                    let (u, c) = (col / dim, col % dim);
                    let j = cols.iter().position(|&g| g == agg[u]).unwrap_or(0);
                    ap[k * m * dim + j * dim + c] += a.values[e];
                }
            }
            let inv = d.block(b);
            let jo = cols.iter().position(|&g| g == own).unwrap_or(0);
            let mut out_c = Vec::with_capacity(dim * m * dim);
            let mut out_v = Vec::with_capacity(dim * m * dim);
            for i in 0..dim {
                for j in 0..m {
                    for c in 0..dim {
                        let mut v = 0.0;
                        for k in 0..dim {
                            v += inv[i * dim + k] * ap[k * m * dim + j * dim + c];
                        }
                        let mut p = -omega * v;
                        if j == jo && c == i {
                            p += 1.0;
                        }
                        out_c.push(cols[j] * dim as u32 + c as u32);
                        out_v.push(p);
                    }
                }
            }
            (out_c, out_v)
        })
        .collect();
    // rows of node b are stored consecutively in (cols, vals), dim rows of m·dim entries each
    let mut row_offsets = Vec::with_capacity(a.nrows + 1);
    row_offsets.push(0);
    let total: usize = rows.iter().map(|r| r.0.len()).sum();
    let mut col_indices = Vec::with_capacity(total);
    let mut values = Vec::with_capacity(total);
    for (c, v) in rows {
        let per = c.len() / dim;
        for i in 0..dim {
            col_indices.extend_from_slice(&c[i * per..(i + 1) * per]);
            values.extend_from_slice(&v[i * per..(i + 1) * per]);
            row_offsets.push(col_indices.len());
        }
    }
    Csr {
        nrows: a.nrows,
        ncols: nagg * dim,
        row_offsets,
        col_indices,
        values,
    }
}

/// `Aᵀ` (counting sort by column; rows of the result are sorted).
pub(crate) fn transpose(a: &Csr) -> Csr {
    let mut cnt = vec![0usize; a.ncols + 1];
    for &c in &a.col_indices {
        cnt[c as usize + 1] += 1;
    }
    for i in 0..a.ncols {
        cnt[i + 1] += cnt[i];
    }
    let mut fill = cnt.clone();
    let mut col_indices = vec![0u32; a.nnz()];
    let mut values = vec![0.0; a.nnz()];
    for r in 0..a.nrows {
        for e in a.row_offsets[r]..a.row_offsets[r + 1] {
            let c = a.col_indices[e] as usize;
            col_indices[fill[c]] = r as u32;
            values[fill[c]] = a.values[e];
            fill[c] += 1;
        }
    }
    Csr {
        nrows: a.ncols,
        ncols: a.nrows,
        row_offsets: cnt,
        col_indices,
        values,
    }
}

/// `C = A·B` (Gustavson's row-by-row product with a dense marker per chunk of rows; rows of
/// `C` are sorted).
pub(crate) fn spgemm(a: &Csr, b: &Csr) -> Csr {
    let nrows = a.nrows;
    let ncols = b.ncols;
    let nchunks = (rayon::current_num_threads() * 4).max(1).min(nrows.max(1));
    let chunk = nrows.div_ceil(nchunks).max(1);
    let parts: Vec<(Vec<usize>, Vec<u32>, Vec<f64>)> = (0..nrows.div_ceil(chunk))
        .into_par_iter()
        .map(|ch| {
            let r0 = ch * chunk;
            let r1 = (r0 + chunk).min(nrows);
            let mut pos = vec![usize::MAX; ncols];
            let mut lens = Vec::with_capacity(r1 - r0);
            let mut cols: Vec<u32> = Vec::new();
            let mut vals: Vec<f64> = Vec::new();
            let mut row_c: Vec<u32> = Vec::new();
            let mut row_v: Vec<f64> = Vec::new();
            for r in r0..r1 {
                row_c.clear();
                row_v.clear();
                for e in a.row_offsets[r]..a.row_offsets[r + 1] {
                    let k = a.col_indices[e] as usize;
                    let av = a.values[e];
                    for f in b.row_offsets[k]..b.row_offsets[k + 1] {
                        let c = b.col_indices[f] as usize;
                        if pos[c] == usize::MAX {
                            pos[c] = row_c.len();
                            row_c.push(c as u32);
                            row_v.push(av * b.values[f]);
                        } else {
                            row_v[pos[c]] += av * b.values[f];
                        }
                    }
                }
                let mut idx: Vec<usize> = (0..row_c.len()).collect();
                idx.sort_unstable_by_key(|&i| row_c[i]);
                for &i in &idx {
                    cols.push(row_c[i]);
                    vals.push(row_v[i]);
                    pos[row_c[i] as usize] = usize::MAX;
                }
                lens.push(row_c.len());
            }
            (lens, cols, vals)
        })
        .collect();
    let total: usize = parts.iter().map(|p| p.1.len()).sum();
    let mut row_offsets = Vec::with_capacity(nrows + 1);
    row_offsets.push(0);
    let mut col_indices = Vec::with_capacity(total);
    let mut values = Vec::with_capacity(total);
    let mut off = 0;
    for (lens, c, v) in parts {
        for l in lens {
            off += l;
            row_offsets.push(off);
        }
        col_indices.extend_from_slice(&c);
        values.extend_from_slice(&v);
    }
    Csr {
        nrows,
        ncols,
        row_offsets,
        col_indices,
        values,
    }
}

/// Dense Cholesky factorization (nalgebra's `Cholesky`, `A = L Lᵀ`) of the symmetric part of
/// `a`; if `a` is not numerically positive definite, a diagonal shift `δ·max|a_ii|` (δ = 1e-12,
/// ×10 until the factorization succeeds) is added, so the coarse solve is always SPD.
fn dense_cholesky_shifted(a: &Csr) -> Cholesky<f64, Dyn> {
    let n = a.nrows;
    let mut dense = DMatrix::<f64>::zeros(n, n);
    for r in 0..n {
        for e in a.row_offsets[r]..a.row_offsets[r + 1] {
            let c = a.col_indices[e] as usize;
            dense[(r, c)] += 0.5 * a.values[e];
            dense[(c, r)] += 0.5 * a.values[e];
        }
    }
    let dmax = (0..n)
        .map(|i| dense[(i, i)].abs())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let mut shift = 0.0;
    loop {
        let mut m = dense.clone();
        for i in 0..n {
            m[(i, i)] += shift;
        }
        // `Cholesky::new` returns None when a pivot is not > 0 (or is NaN)
        if let Some(c) = m.cholesky() {
            return c;
        }
        shift = if shift == 0.0 {
            1e-12 * dmax
        } else {
            shift * 10.0
        };
        if shift > 1e3 * dmax {
            // hopeless (NaN entries): the factor of the largest diagonal entry times I
            let scaled = DMatrix::<f64>::from_diagonal_element(n, n, dmax);
            return Cholesky::new_unchecked(scaled);
        }
    }
}

#[cfg(test)]
mod tests;
