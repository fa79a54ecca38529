//! The 9-node logical neighbourhoods and the transformed 9-point stencil (formulas in the
//! crate docs of [`unamalla_pde`](crate)).
//!
//! Patch slot `k = 3·(δj + 1) + (δi + 1)` holds the node at logical offset `(δi, δj)`:
//!
//! ```text
//! 6 7 8      (−1,+1) (0,+1) (+1,+1)
//! 3 4 5      (−1, 0) (0, 0) (+1, 0)
//! 0 1 2      (−1,−1) (0,−1) (+1,−1)
//! ```

use unamalla_mesh::{DVec2, HasQuadCells};

use super::{Equation, PdeError};

/// One equation of the system: `Σ_t w[t]·U[cols[t]] = rhs`, `cols` are node ids.
#[derive(Debug, Clone)]
pub(crate) struct Row {
    /// The centre node (the unknown of this row).
    pub node: usize,
    /// The 9 nodes of the patch.
    pub cols: [usize; 9],
    /// Their weights.
    pub w: [f64; 9],
    /// The sum of the weights whose column is the centre node.
    pub diag: f64,
    /// `g` at the node.
    pub rhs: f64,
}

impl Row {
    /// `Σ_{cols[t] ≠ node} w[t]·u[cols[t]]`.
    #[inline]
    pub fn off_diagonal(&self, u: &[f64]) -> f64 {
        let mut s = 0.0;
        for t in 0..9 {
            let c = self.cols[t];
            if c != self.node {
                s += self.w[t] * u[c];
            }
        }
        s
    }
}

/// The patches of the interior nodes of an `m × n` structured grid (node `j·m + i`).
pub(crate) fn grid_patches(m: usize, n: usize) -> Vec<(usize, [usize; 9])> {
    let mut out = Vec::with_capacity(m.saturating_sub(2) * n.saturating_sub(2));
    for j in 1..n.saturating_sub(1) {
        for i in 1..m.saturating_sub(1) {
            let mut p = [0usize; 9];
            for dj in 0..3 {
                for di in 0..3 {
                    p[3 * dj + di] = (j + dj - 1) * m + (i + di - 1);
                }
            }
            out.push((j * m + i, p));
        }
    }
    out
}

/// The patches of the interior nodes of a conformal quad mesh: the four cells around a node,
/// chained counter-clockwise, give its edge neighbours `N₀..N₃` and diagonal neighbours; `N₀`
/// is put at `(+1, 0)`, `N₁` at `(0, +1)`, … (any of the 8 frames gives the same stencil).
pub(crate) fn quad_patches<M: HasQuadCells + ?Sized>(
    mesh: &M,
    boundary: &[bool],
) -> Result<Vec<(usize, [usize; 9])>, PdeError> {
    let nn = mesh.num_nodes();
    // (e1, diagonal, e2) of every cell corner, grouped by node (CSR)
    let mut count = vec![0usize; nn + 1];
    for c in 0..mesh.num_quads() {
        for v in mesh.quad(c) {
            count[v + 1] += 1;
        }
    }
    for k in 0..nn {
        count[k + 1] += count[k];
    }
    let mut fill = count.clone();
    let mut corners = vec![[0usize; 3]; count[nn]];
    for c in 0..mesh.num_quads() {
        let q = mesh.quad(c);
        for k in 0..4 {
            let v = q[k];
            corners[fill[v]] = [q[(k + 1) % 4], q[(k + 2) % 4], q[(k + 3) % 4]];
            fill[v] += 1;
        }
    }
    let mut out = Vec::new();
    for p in 0..nn {
        if boundary[p] {
            continue;
        }
        let around = &corners[count[p]..count[p + 1]];
        if around.is_empty() {
            // a node of no cell: not part of the mesh, nothing to solve for
            continue;
        }
        if around.len() != 4 {
            return Err(PdeError::IrregularNode {
                node: p,
                cells: around.len(),
            });
        }
        // chain: N0 = e1 of the first corner, then the corner whose e1 is the previous e2
        let mut edge = [0usize; 4];
        let mut diag = [0usize; 4];
        let mut cur = around[0];
        for s in 0..4 {
            edge[s] = cur[0];
            diag[s] = cur[1];
            if s < 3 {
                cur = *around
                    .iter()
                    .find(|c| c[0] == cur[2])
                    .ok_or(PdeError::IrregularNode {
                        node: p,
                        cells: around.len(),
                    })?;
            } else if cur[2] != edge[0] {
                return Err(PdeError::IrregularNode {
                    node: p,
                    cells: around.len(),
                });
            }
        }
        // N0 (+1,0)=5, N1 (0,+1)=7, N2 (−1,0)=3, N3 (0,−1)=1;
        // D01 (+1,+1)=8, D12 (−1,+1)=6, D23 (−1,−1)=0, D30 (+1,−1)=2
        let patch = [
            diag[2], edge[3], diag[3], edge[2], p, edge[0], diag[1], edge[1], diag[0],
        ];
        out.push((p, patch));
    }
    Ok(out)
}

/// Assembles the rows (crate docs of [`unamalla_pde`](crate)). The equation is multiplied by −1 when
/// `a < 0` so that the diagonal is negative and the weights have one sign convention; the
/// solution is unchanged.
pub(crate) fn assemble(
    nodes: &[DVec2],
    patches: &[(usize, [usize; 9])],
    eq: &Equation,
    g: &[f64],
) -> Result<Vec<Row>, PdeError> {
    let s = if eq.a < 0.0 { -1.0 } else { 1.0 };
    let (a, b, c, d) = (s * eq.a, s * eq.b, s * eq.c, s * eq.d);
    let mut rows = Vec::with_capacity(patches.len());
    for (r, &(node, cols)) in patches.iter().enumerate() {
        let x: [DVec2; 9] = std::array::from_fn(|t| nodes[cols[t]]);
        let x_xi = 0.5 * (x[5] - x[3]);
        let x_eta = 0.5 * (x[7] - x[1]);
        let x_xixi = x[5] - 2.0 * x[4] + x[3];
        let x_etaeta = x[7] - 2.0 * x[4] + x[1];
        let x_xieta = 0.25 * (x[8] - x[2] - x[6] + x[0]);
        let jac = x_xi.x * x_eta.y - x_eta.x * x_xi.y;
        if jac.is_nan() || jac <= 0.0 {
            return Err(PdeError::DegenerateMetric {
                node,
                jacobian: jac,
            });
        }
        // inverse metrics
        let (xi_x, xi_y) = (x_eta.y / jac, -x_eta.x / jac);
        let (eta_x, eta_y) = (-x_xi.y / jac, x_xi.x / jac);
        let a11 = a * xi_x * xi_x + 2.0 * b * xi_x * xi_y + c * xi_y * xi_y;
        let a12 = a * xi_x * eta_x + b * (xi_x * eta_y + xi_y * eta_x) + c * xi_y * eta_y;
        let a22 = a * eta_x * eta_x + 2.0 * b * eta_x * eta_y + c * eta_y * eta_y;
        // P = Lξ, Q = Lη from L x = L y = 0
        let rr = a11 * x_xixi + 2.0 * a12 * x_xieta + a22 * x_etaeta;
        let p = -(x_eta.y * rr.x - x_eta.x * rr.y) / jac;
        let q = -(x_xi.x * rr.y - x_xi.y * rr.x) / jac;
        let mut w = [0.0; 9];
        w[3] += a11 - 0.5 * p;
        w[5] += a11 + 0.5 * p;
        w[1] += a22 - 0.5 * q;
        w[7] += a22 + 0.5 * q;
        w[4] += -2.0 * (a11 + a22) + d;
        let h = 0.5 * a12;
        w[8] += h;
        w[0] += h;
        w[2] -= h;
        w[6] -= h;
        let diag: f64 = (0..9).filter(|&t| cols[t] == node).map(|t| w[t]).sum();
        if !diag.is_finite() || diag == 0.0 || w.iter().any(|v| !v.is_finite()) {
            return Err(PdeError::DegenerateMetric {
                node,
                jacobian: jac,
            });
        }
        rows.push(Row {
            node,
            cols,
            w,
            diag,
            rhs: s * g[r],
        });
    }
    Ok(rows)
}

/// `max_i |r_i / A_ii|` with `r = g − A U`.
pub(crate) fn residual(rows: &[Row], u: &[f64]) -> f64 {
    rows.iter()
        .map(|r| ((r.rhs - r.off_diagonal(u) - r.diag * u[r.node]) / r.diag).abs())
        .fold(0.0, f64::max)
}
