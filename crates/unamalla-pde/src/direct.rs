//! The direct solver: sparse LU of the 9-point system over the interior unknowns
//! (`faer`, cargo feature `direct`; crate docs of [`unamalla_pde`](crate) say why `faer`).

use super::stencil::Row;
use super::PdeError;

/// Solves for the interior values in place (`u` holds the Dirichlet data on the boundary).
#[cfg(feature = "direct")]
pub(crate) fn solve(rows: &[Row], u: &mut [f64]) -> Result<(), PdeError> {
    use faer::sparse::{SparseColMat, Triplet};

    let mut unknown = vec![usize::MAX; u.len()];
    for (k, r) in rows.iter().enumerate() {
        unknown[r.node] = k;
    }
    let n = rows.len();
    let mut trip = Vec::with_capacity(9 * n);
    let mut b = faer::Mat::<f64>::zeros(n, 1);
    for (k, r) in rows.iter().enumerate() {
        let mut rhs = r.rhs;
        for t in 0..9 {
            let c = r.cols[t];
            match unknown[c] {
                usize::MAX => rhs -= r.w[t] * u[c],
                col => trip.push(Triplet::new(k, col, r.w[t])),
            }
        }
        b[(k, 0)] = rhs;
    }
    // duplicate entries (a node twice in a patch) are summed by the constructor
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &trip)
        .map_err(|e| PdeError::Singular(format!("building the sparse matrix: {e:?}")))?;
    let lu = a
        .sp_lu()
        .map_err(|e| PdeError::Singular(format!("sparse LU: {e}")))?;
    let x = {
        use faer::prelude::Solve;
        lu.solve(&b)
    };
    for (k, r) in rows.iter().enumerate() {
        let v = x[(k, 0)];
        if !v.is_finite() {
            return Err(PdeError::Singular(format!(
                "the solution is not finite at node {} (singular system?)",
                r.node
            )));
        }
        u[r.node] = v;
    }
    // a numerically singular matrix gives a finite but wrong answer: check the residual
    let res = super::stencil::residual(rows, u);
    let scale = u.iter().map(|v| v.abs()).fold(1.0, f64::max);
    if res > 1e-6 * scale {
        return Err(PdeError::Singular(format!(
            "the LU solution has residual {res:.3e} (relative to max |U| = {scale:.3e}); the system is (nearly) singular"
        )));
    }
    Ok(())
}

/// Without the `direct` feature: an error.
#[cfg(not(feature = "direct"))]
pub(crate) fn solve(_rows: &[Row], _u: &mut [f64]) -> Result<(), PdeError> {
    Err(PdeError::DirectUnavailable)
}
