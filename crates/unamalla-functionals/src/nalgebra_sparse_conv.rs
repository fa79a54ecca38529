//! Conversions between the Hessian matrix [`Csr`] and [`nalgebra_sparse::CsrMatrix`] (feature
//! `nalgebra-sparse`, on by default).
//!
//! Both are compressed-sparse-row matrices with sorted column indices, so a conversion is a copy
//! of the three arrays (column indices widened from `u32` to `usize` or narrowed back). With a
//! `CsrMatrix` the whole of nalgebra-sparse applies to our Hessians: products with
//! `nalgebra::DVector`, conversion to `CscMatrix` and its sparse Cholesky factorization
//! (`nalgebra_sparse::factorization::CscCholesky`; the method: Davis 2006, *Direct Methods for
//! Sparse Linear Systems*, ch. 4), Matrix Market output.
//!
//! Why the solvers keep [`Csr`] (measured in docs/benchmarks.md, "nalgebra-sparse"): the
//! Hessian values are refreshed in place from many threads at positions precomputed from the
//! mesh (`Csr::block_index`), with 32-bit column indices (half the index memory of `usize`);
//! after [`to_nalgebra_sparse`](Csr::to_nalgebra_sparse) once, later refreshes can be copied into
//! the same `CsrMatrix` with [`copy_values_into`](Csr::copy_values_into) without rebuilding its
//! pattern.

use nalgebra_sparse::CsrMatrix;

use crate::csr::Csr;

/// Errors of the conversions.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum CsrConversionError {
    /// The arrays of a [`Csr`] do not form a valid CSR matrix (a `Csr`'s fields are public, so
    /// a caller can break its invariants).
    #[error("not a valid CSR matrix: {0}")]
    InvalidFormat(String),
    /// A column index does not fit the 32 bits of [`Csr::col_indices`].
    #[error("column index {0} does not fit in 32 bits")]
    ColumnTooLarge(usize),
    /// The `CsrMatrix` given to [`Csr::copy_values_into`] has another sparsity pattern.
    #[error("the target matrix has another sparsity pattern")]
    PatternMismatch,
}

impl Csr {
    /// A `nalgebra_sparse::CsrMatrix` with the same entries (a copy).
    ///
    /// # Errors
    /// [`CsrConversionError::InvalidFormat`] if the offsets, column indices and values do not
    /// form a valid CSR matrix (wrong lengths, unsorted or duplicate columns in a row, a column
    /// out of range).
    pub fn to_nalgebra_sparse(&self) -> Result<CsrMatrix<f64>, CsrConversionError> {
        CsrMatrix::try_from_csr_data(
            self.nrows,
            self.ncols,
            self.row_offsets.clone(),
            self.col_indices.iter().map(|&c| c as usize).collect(),
            self.values.clone(),
        )
        .map_err(|e| CsrConversionError::InvalidFormat(e.to_string()))
    }

    /// A [`Csr`] with the same entries as `m` (a copy).
    ///
    /// # Errors
    /// [`CsrConversionError::ColumnTooLarge`] if a column index exceeds `u32::MAX`.
    pub fn from_nalgebra_sparse(m: &CsrMatrix<f64>) -> Result<Csr, CsrConversionError> {
        let (offsets, cols, values) = m.csr_data();
        let col_indices = cols
            .iter()
            .map(|&c| u32::try_from(c).map_err(|_| CsrConversionError::ColumnTooLarge(c)))
            .collect::<Result<Vec<u32>, _>>()?;
        Ok(Csr {
            nrows: m.nrows(),
            ncols: m.ncols(),
            row_offsets: offsets.to_vec(),
            col_indices,
            values: values.to_vec(),
        })
    }

    /// Copies the values of `self` into `m`, which must have the same sparsity pattern (e.g.
    /// made by [`to_nalgebra_sparse`](Self::to_nalgebra_sparse) from an earlier refresh of the
    /// same Hessian): the refresh of a `CsrMatrix` without rebuilding its pattern.
    ///
    /// # Errors
    /// [`CsrConversionError::PatternMismatch`] if the patterns differ.
    pub fn copy_values_into(&self, m: &mut CsrMatrix<f64>) -> Result<(), CsrConversionError> {
        let (offsets, cols, values) = m.csr_data_mut();
        let same = same_pattern(self, offsets, cols, values.len());
        if !same {
            return Err(CsrConversionError::PatternMismatch);
        }
        values.copy_from_slice(&self.values);
        Ok(())
    }
}

fn same_pattern(a: &Csr, offsets: &[usize], cols: &[usize], nnz: usize) -> bool {
    a.row_offsets == offsets
        && a.values.len() == nnz
        && a.col_indices.len() == cols.len()
        && a.col_indices
            .iter()
            .zip(cols)
            .all(|(&c, &d)| c as usize == d)
}

impl TryFrom<&Csr> for CsrMatrix<f64> {
    type Error = CsrConversionError;
    fn try_from(a: &Csr) -> Result<Self, CsrConversionError> {
        a.to_nalgebra_sparse()
    }
}

impl TryFrom<&CsrMatrix<f64>> for Csr {
    type Error = CsrConversionError;
    fn try_from(m: &CsrMatrix<f64>) -> Result<Self, CsrConversionError> {
        Csr::from_nalgebra_sparse(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `[[2, −1, 0], [−1, 2, −1], [0, −1, 2]]`, entered by hand.
    fn tridiag() -> Csr {
        Csr {
            nrows: 3,
            ncols: 3,
            row_offsets: vec![0, 2, 5, 7],
            col_indices: vec![0, 1, 0, 1, 2, 1, 2],
            values: vec![2.0, -1.0, -1.0, 2.0, -1.0, -1.0, 2.0],
        }
    }

    #[test]
    fn round_trip_and_entries() {
        let a = tridiag();
        let m = a.to_nalgebra_sparse().unwrap();
        assert_eq!(m.nnz(), 7);
        // entry (1, 2) = −1, (0, 2) not stored
        assert_eq!(m.get_entry(1, 2).unwrap().into_value(), -1.0);
        assert_eq!(m.get_entry(0, 2).unwrap().into_value(), 0.0);
        assert_eq!(Csr::from_nalgebra_sparse(&m).unwrap(), a);
        assert_eq!(Csr::try_from(&CsrMatrix::try_from(&a).unwrap()).unwrap(), a);
    }

    #[test]
    fn invalid_arrays_and_patterns_are_errors() {
        let mut a = tridiag();
        a.col_indices.swap(0, 1); // row 0 unsorted
        assert!(matches!(
            a.to_nalgebra_sparse(),
            Err(CsrConversionError::InvalidFormat(_))
        ));
        let mut m = tridiag().to_nalgebra_sparse().unwrap();
        let mut b = tridiag();
        b.values[3] = 5.0;
        b.copy_values_into(&mut m).unwrap();
        assert_eq!(m.get_entry(1, 1).unwrap().into_value(), 5.0);
        let diag = Csr {
            nrows: 3,
            ncols: 3,
            row_offsets: vec![0, 1, 2, 3],
            col_indices: vec![0, 1, 2],
            values: vec![1.0; 3],
        };
        assert_eq!(
            diag.copy_values_into(&mut m),
            Err(CsrConversionError::PatternMismatch)
        );
    }
}
