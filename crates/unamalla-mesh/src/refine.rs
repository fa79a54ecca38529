//! Uniform refinement of structured grids ([González Flores, §6.1.7], requirement RF11).
//!
//! `m′` new coordinate lines are inserted between every two consecutive `i`-lines and `n′`
//! between every two consecutive `j`-lines by bilinear interpolation inside each cell, so an
//! `m × n` grid becomes `((m−1)(m′+1)+1) × ((n−1)(n′+1)+1)`. Every original node is kept at the
//! same place (at index `(i(m′+1), j(n′+1))`) and every new node lies inside (or on an edge of)
//! its original cell, so a convex grid stays convex: each refined cell is a bilinear image of a
//! rectangle inside a convex quadrilateral.

use crate::error::MeshError;
use crate::grid::StructuredGrid2;

impl StructuredGrid2 {
    /// Inserts `mi` lines between consecutive `i`-lines and `nj` between consecutive `j`-lines
    /// (bilinear interpolation in each cell). `refined(0, 0)` is a copy.
    pub fn refined(&self, mi: usize, nj: usize) -> Result<StructuredGrid2, MeshError> {
        let (m, n) = (self.m(), self.n());
        let (sx, sy) = (mi + 1, nj + 1);
        let new_m = (m - 1)
            .checked_mul(sx)
            .and_then(|v| v.checked_add(1))
            .ok_or_else(|| MeshError::InvalidSize("refined grid too large".into()))?;
        let new_n = (n - 1)
            .checked_mul(sy)
            .and_then(|v| v.checked_add(1))
            .ok_or_else(|| MeshError::InvalidSize("refined grid too large".into()))?;
        if new_m.checked_mul(new_n).is_none_or(|t| t > 1 << 31) {
            return Err(MeshError::InvalidSize(format!(
                "refined grid {new_m} × {new_n} is too large"
            )));
        }
        StructuredGrid2::from_fn(new_m, new_n, |a, b| {
            let (i, u) = ((a / sx).min(m - 2), a as f64 / sx as f64);
            let (j, v) = ((b / sy).min(n - 2), b as f64 / sy as f64);
            let (u, v) = (u - i as f64, v - j as f64);
            let p00 = self.node(i, j);
            let p10 = self.node(i + 1, j);
            let p01 = self.node(i, j + 1);
            let p11 = self.node(i + 1, j + 1);
            (1.0 - u) * (1.0 - v) * p00 + u * (1.0 - v) * p10 + (1.0 - u) * v * p01 + u * v * p11
        })
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec2;

    use super::*;

    #[test]
    fn refining_keeps_old_nodes_and_sizes() {
        let g = StructuredGrid2::from_fn(3, 4, |i, j| {
            DVec2::new(i as f64 + 0.1 * (j * j) as f64, j as f64)
        })
        .unwrap();
        let r = g.refined(2, 1).unwrap();
        assert_eq!((r.m(), r.n()), (2 * 3 + 1, 3 * 2 + 1));
        for j in 0..4 {
            for i in 0..3 {
                assert_eq!(r.node(3 * i, 2 * j), g.node(i, j));
            }
        }
        // the midpoint of edge (0,0)-(1,0) along j is inserted exactly
        assert_eq!(r.node(0, 1), 0.5 * (g.node(0, 0) + g.node(0, 1)));
        assert_eq!(g.refined(0, 0).unwrap(), g);
    }

    #[test]
    fn refining_an_affine_grid_gives_the_finer_affine_grid() {
        let f = |x: f64, y: f64| DVec2::new(2.0 * x + 0.5 * y + 1.0, -x + 3.0 * y);
        let g = StructuredGrid2::from_fn(4, 3, |i, j| f(i as f64, j as f64)).unwrap();
        let r = g.refined(3, 4).unwrap();
        for b in 0..r.n() {
            for a in 0..r.m() {
                let want = f(a as f64 / 4.0, b as f64 / 5.0);
                assert!(r.node(a, b).distance(want) < 1e-12);
            }
        }
    }
}
