//! A plain compressed-sparse-row matrix used for the Hessians.
//!
//! Why not `nalgebra_sparse::CsrMatrix` as the solvers' matrix: the optimizer refreshes the
//! *values* of a fixed pattern in place, from many threads at once, at positions computed from
//! the mesh connectivity (`row_offsets[r] + dim·k + c'`, see [`Csr::block_index`]). Keeping the
//! three arrays as public fields makes that direct and keeps the column indices at 32 bits (a
//! 1000 × 1000 quad grid has 36 M Hessian entries). Interoperation is kept, not dropped: with the
//! default feature `nalgebra-sparse` (a dependency of this crate) [`Csr::to_nalgebra_sparse`]
//! converts and [`Csr::copy_values_into`] refreshes an existing `CsrMatrix` of the same pattern
//! (module `nalgebra_sparse_conv`).
//!
//! Measured (`cargo bench -p unamalla-functionals --bench csr_nalgebra`, Winslow's functional on
//! a perturbed grid, 2026-12-03, load average 1.6): the product `H·v` takes 0.31 ms / 3.44 ms on
//! 100² / 300² cells with ours (parallel over rows) against 1.00 ms / 10.6 ms with
//! `&CsrMatrix * &DVector`; on one thread (`RAYON_NUM_THREADS=1`) 1.01 / 6.89 ms against
//! 1.02 / 9.22 ms. Keeping a `CsrMatrix` up to date costs a copy of the values after each refresh
//! (refresh 1.94 ms → 3.43 ms at 100², 17.3 → 33.2 ms at 300²), a fresh conversion more
//! (6.54 ms, 64.9 ms).

use rayon::prelude::*;

/// Sets every entry of `v` to zero, in parallel (the start of every scatter-add assembly of
/// a gradient or of Hessian values).
pub(crate) fn par_zero(v: &mut [f64]) {
    v.par_iter_mut().with_min_len(4096).for_each(|v| *v = 0.0);
}

/// A sparse matrix in compressed-sparse-row form with **both** triangles stored (the Hessians
/// are symmetric; storing both makes products and row access trivial).
///
/// * `row_offsets` has `nrows + 1` entries; row `r` occupies `row_offsets[r]..row_offsets[r+1]`
///   of `col_indices` and `values`;
/// * `col_indices` are sorted increasingly inside each row;
/// * for the Hessians of this crate the variables are the free-node coordinates interleaved
///   (`x = [x₀, y₀, x₁, y₁, …]` in 2D, `[x₀, y₀, z₀, …]` in 3D), and every pair of
///   neighbouring free nodes contributes a dense `dim × dim` block, so the pattern is a block
///   pattern stored entry-wise.
#[derive(Debug, Clone, PartialEq)]
pub struct Csr {
    /// Number of rows.
    pub nrows: usize,
    /// Number of columns.
    pub ncols: usize,
    /// Start of each row in `col_indices` / `values` (`nrows + 1` entries).
    pub row_offsets: Vec<usize>,
    /// Column of each stored entry.
    pub col_indices: Vec<u32>,
    /// Value of each stored entry.
    pub values: Vec<f64>,
}

impl Csr {
    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    /// The entry `(r, c)`, or 0 if it is not stored (or out of range).
    pub fn get(&self, r: usize, c: usize) -> f64 {
        if r >= self.nrows {
            return 0.0;
        }
        let (s, e) = (self.row_offsets[r], self.row_offsets[r + 1]);
        match self.col_indices[s..e].binary_search(&(c as u32)) {
            Ok(k) => self.values[s + k],
            Err(_) => 0.0,
        }
    }

    /// `out = A v`, computed row by row in parallel (each row is summed sequentially, so the
    /// result does not depend on the number of threads).
    ///
    /// # Panics
    /// If `v.len() != ncols` or `out.len() != nrows`.
    pub fn mul_vec(&self, v: &[f64], out: &mut [f64]) {
        assert_eq!(v.len(), self.ncols, "Csr::mul_vec: v has the wrong length");
        assert_eq!(
            out.len(),
            self.nrows,
            "Csr::mul_vec: out has the wrong length"
        );
        out.par_iter_mut()
            .with_min_len(1024)
            .enumerate()
            .for_each(|(r, o)| {
                let (s, e) = (self.row_offsets[r], self.row_offsets[r + 1]);
                let mut acc = 0.0;
                for k in s..e {
                    acc += self.values[k] * v[self.col_indices[k] as usize];
                }
                *o = acc;
            });
    }

    /// The diagonal entries (0 where not stored).
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.nrows).map(|r| self.get(r, r)).collect()
    }

    /// A dense copy (row-major), for tests and small problems.
    pub fn to_dense(&self) -> Vec<Vec<f64>> {
        let mut d = vec![vec![0.0; self.ncols]; self.nrows];
        for (r, row) in d.iter_mut().enumerate() {
            for k in self.row_offsets[r]..self.row_offsets[r + 1] {
                row[self.col_indices[k] as usize] = self.values[k];
            }
        }
        d
    }

    /// Index into `values` of entry `(dim·a + ra, dim·b + rb)` of a block pattern built by this
    /// crate, where `k` is the position of node-variable `b` in the sorted neighbour list of
    /// node-variable `a` (every node row lists the same neighbours, each as `dim` columns).
    #[inline]
    pub fn block_index(&self, dim: usize, a: usize, k: usize, ra: usize, rb: usize) -> usize {
        self.row_offsets[dim * a + ra] + dim * k + rb
    }

    /// Builds the block pattern (zero values) from sorted neighbour lists of node variables.
    pub(crate) fn from_block_pattern(dim: usize, nbr_offsets: &[usize], nbr: &[u32]) -> Csr {
        let nfree = nbr_offsets.len() - 1;
        let nrows = dim * nfree;
        let mut row_offsets = Vec::with_capacity(nrows + 1);
        row_offsets.push(0);
        let mut col_indices = Vec::with_capacity(dim * dim * nbr.len());
        for a in 0..nfree {
            let list = &nbr[nbr_offsets[a]..nbr_offsets[a + 1]];
            for _ in 0..dim {
                for &b in list {
                    for rb in 0..dim {
                        col_indices.push(b * dim as u32 + rb as u32);
                    }
                }
                row_offsets.push(col_indices.len());
            }
        }
        let nnz = col_indices.len();
        Csr {
            nrows,
            ncols: nrows,
            row_offsets,
            col_indices,
            values: vec![0.0; nnz],
        }
    }
}
