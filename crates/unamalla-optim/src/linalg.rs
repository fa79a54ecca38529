//! Dense vector kernels (parallel above a size threshold) and the CG preconditioners.

use rayon::prelude::*;
use unamalla_functionals::Csr;

use crate::multigrid::{Multigrid, MultigridOptions};

const PAR: usize = 1 << 15;

/// `xᵀy`. Deterministic at any thread count: above the parallel threshold the partial sums
/// of fixed 8192-element chunks are collected in chunk order and added serially (rayon's own
/// `sum` groups the partials by its work splitting, which depends on the thread count; see
/// rayon-rs/rayon#663), and a serial call adds the same partials in the same order.
pub fn dot(x: &[f64], y: &[f64]) -> f64 {
    let partials: Vec<f64> = if x.len() >= PAR {
        x.par_chunks(CHUNK)
            .zip(y.par_chunks(CHUNK))
            .map(|(a, b)| dot_serial(a, b))
            .collect()
    } else {
        return dot_serial(x, y);
    };
    partials.iter().sum()
}

/// The fixed chunk of the parallel reductions (never derived from the thread count).
const CHUNK: usize = 8192;

fn dot_serial(x: &[f64], y: &[f64]) -> f64 {
    let mut s = [0.0; 4];
    let n = x.len() / 4 * 4;
    for i in (0..n).step_by(4) {
        for k in 0..4 {
            s[k] += x[i + k] * y[i + k];
        }
    }
    let mut t = (s[0] + s[1]) + (s[2] + s[3]);
    for i in n..x.len() {
        t += x[i] * y[i];
    }
    t
}

/// `‖x‖₂`.
pub fn norm(x: &[f64]) -> f64 {
    dot(x, x).sqrt()
}

/// `y ← y + a·x`.
pub fn axpy(a: f64, x: &[f64], y: &mut [f64]) {
    if y.len() >= PAR {
        y.par_chunks_mut(8192)
            .zip(x.par_chunks(8192))
            .for_each(|(yy, xx)| yy.iter_mut().zip(xx).for_each(|(y, x)| *y += a * x));
    } else {
        y.iter_mut().zip(x).for_each(|(y, x)| *y += a * x);
    }
}

/// `z ← x + a·y`.
pub fn add_scaled(x: &[f64], a: f64, y: &[f64], z: &mut [f64]) {
    if z.len() >= PAR {
        z.par_chunks_mut(8192)
            .zip(x.par_chunks(8192).zip(y.par_chunks(8192)))
            .for_each(|(zz, (xx, yy))| {
                for i in 0..zz.len() {
                    zz[i] = xx[i] + a * yy[i];
                }
            });
    } else {
        for i in 0..z.len() {
            z[i] = x[i] + a * y[i];
        }
    }
}

/// `y ← a·y + x`.
pub fn scale_add(a: f64, y: &mut [f64], x: &[f64]) {
    if y.len() >= PAR {
        y.par_chunks_mut(8192)
            .zip(x.par_chunks(8192))
            .for_each(|(yy, xx)| yy.iter_mut().zip(xx).for_each(|(y, x)| *y = a * *y + x));
    } else {
        y.iter_mut().zip(x).for_each(|(y, x)| *y = a * *y + x);
    }
}

/// The preconditioner of the inner CG of truncated Newton.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub enum Preconditioner {
    /// None (plain CG, as argmin's `NewtonCG`).
    None,
    /// Jacobi: `M = diag(|H_ii|)`.
    Jacobi,
    /// Block-Jacobi: `M` = the `dim × dim` diagonal node blocks of `H` (falls back to
    /// `diag(|H_ii|)` on a block that is not positive definite).
    #[default]
    BlockJacobi,
    /// One symmetric V-cycle of smoothed-aggregation algebraic multigrid
    /// ([`Multigrid`], default [`MultigridOptions`]) built from
    /// the assembled Hessian; its iteration count does not grow with the grid size.
    Multigrid,
}

impl Preconditioner {
    /// All preconditioners.
    pub const ALL: [Preconditioner; 4] = [
        Preconditioner::None,
        Preconditioner::Jacobi,
        Preconditioner::BlockJacobi,
        Preconditioner::Multigrid,
    ];
    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Preconditioner::None => "none",
            Preconditioner::Jacobi => "jacobi",
            Preconditioner::BlockJacobi => "block-jacobi",
            Preconditioner::Multigrid => "multigrid",
        }
    }
}

impl std::str::FromStr for Preconditioner {
    type Err = crate::OptimError;
    fn from_str(s: &str) -> Result<Self, crate::OptimError> {
        Preconditioner::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| crate::OptimError::UnknownName {
                what: "preconditioner",
                name: s.to_string(),
                expected: "none, jacobi, block-jacobi, multigrid",
            })
    }
}

/// An applied preconditioner: `M⁻¹` stored per node block (`dim²` entries per node), and for
/// [`Preconditioner::Multigrid`] the multigrid hierarchy (its node-block inverses are kept too:
/// [`apply`](Self::apply) without the matrix falls back to block-Jacobi).
#[derive(Debug, Clone, Default)]
pub struct PrecondApply {
    dim: usize,
    inv: Vec<f64>,
    kind: Option<Preconditioner>,
    mg: Option<Box<Multigrid>>,
}

impl PrecondApply {
    /// Rebuilds `M⁻¹` from the assembled Hessian `h` (node blocks of size `dim`).
    pub fn build(&mut self, kind: Preconditioner, h: &Csr, dim: usize) {
        self.kind = Some(kind);
        self.dim = dim;
        let n = h.nrows;
        let nb = n / dim;
        let d2 = dim * dim;
        self.inv.resize(nb * d2, 0.0);
        let floor = {
            let mut m = 0.0f64;
            for r in 0..n {
                m = m.max(h.get(r, r).abs());
            }
            (m * 1e-12).max(f64::MIN_POSITIVE)
        };
        let jac = |r: usize| 1.0 / h.get(r, r).abs().max(floor);
        if kind == Preconditioner::Multigrid {
            self.build(Preconditioner::BlockJacobi, h, dim);
            self.kind = Some(kind);
            self.mg = Some(Box::new(Multigrid::build(
                h,
                dim,
                &MultigridOptions::default(),
            )));
            return;
        }
        self.mg = None;
        match kind {
            Preconditioner::None | Preconditioner::Multigrid => {}
            Preconditioner::Jacobi => {
                self.inv.par_chunks_mut(d2).enumerate().for_each(|(b, m)| {
                    m.iter_mut().for_each(|v| *v = 0.0);
                    for a in 0..dim {
                        m[a * dim + a] = jac(b * dim + a);
                    }
                });
            }
            Preconditioner::BlockJacobi => {
                self.inv.par_chunks_mut(d2).enumerate().for_each(|(b, m)| {
                    let mut blk = [[0.0; 3]; 3];
                    for (a, row) in blk.iter_mut().enumerate().take(dim) {
                        let r = b * dim + a;
                        let (s, e) = (h.row_offsets[r], h.row_offsets[r + 1]);
                        for k in s..e {
                            let c = h.col_indices[k] as usize;
                            if c / dim == b {
                                row[c - b * dim] = h.values[k];
                            }
                        }
                    }
                    let ok = match dim {
                        2 => {
                            let (p, q, r) = (blk[0][0], 0.5 * (blk[0][1] + blk[1][0]), blk[1][1]);
                            let det = p * r - q * q;
                            if p > 0.0 && det > 1e-14 * p * r {
                                m[0] = r / det;
                                m[1] = -q / det;
                                m[2] = -q / det;
                                m[3] = p / det;
                                true
                            } else {
                                false
                            }
                        }
                        3 => match inv3_spd(&blk) {
                            Some(inv) => {
                                for a in 0..3 {
                                    for c in 0..3 {
                                        m[a * 3 + c] = inv[a][c];
                                    }
                                }
                                true
                            }
                            None => false,
                        },
                        _ => false,
                    };
                    if !ok {
                        m.iter_mut().for_each(|v| *v = 0.0);
                        for a in 0..dim {
                            m[a * dim + a] = 1.0 / blk[a][a].abs().max(floor);
                        }
                    }
                });
            }
        }
    }

    /// The inverse of node block `b` (`dim²` entries, row-major; all zeros for
    /// [`Preconditioner::None`]).
    pub fn block(&self, b: usize) -> &[f64] {
        let d2 = self.dim * self.dim;
        self.inv.get(b * d2..(b + 1) * d2).unwrap_or(&[])
    }

    /// Like [`build`](Self::build), but for [`Preconditioner::Multigrid`] with an existing
    /// hierarchy of the same size and `rebuild_coarse == false`, only the node-block inverses
    /// and the finest smoother are refreshed from `h` and the coarse levels are kept (lagged
    /// from an earlier Hessian; the setup of the coarse levels costs several Hessian
    /// refreshes on large grids).
    pub fn update(&mut self, kind: Preconditioner, h: &Csr, dim: usize, rebuild_coarse: bool) {
        if kind == Preconditioner::Multigrid && !rebuild_coarse {
            if let Some(mut mg) = self.mg.take() {
                if mg.refresh_finest(h) {
                    self.build(Preconditioner::BlockJacobi, h, dim);
                    self.kind = Some(kind);
                    self.mg = Some(mg);
                    return;
                }
            }
        }
        self.build(kind, h, dim);
    }

    /// The multigrid hierarchy, if the preconditioner is [`Preconditioner::Multigrid`].
    pub fn multigrid(&self) -> Option<&Multigrid> {
        self.mg.as_deref()
    }

    /// `z = M⁻¹ r` where `a` is the matrix the preconditioner was built from (needed by the
    /// multigrid V-cycle; the other kinds ignore it).
    pub fn apply_with(&self, a: &Csr, r: &[f64], z: &mut [f64]) {
        match &self.mg {
            Some(mg) if a.nrows == r.len() => mg.apply(a, r, z),
            _ => self.apply(r, z),
        }
    }

    /// `z = M⁻¹ r` (for [`Preconditioner::Multigrid`]: the block-Jacobi part only; use
    /// [`apply_with`](Self::apply_with)).
    pub fn apply(&self, r: &[f64], z: &mut [f64]) {
        match self.kind {
            None | Some(Preconditioner::None) => z.copy_from_slice(r),
            Some(_) => {
                let d = self.dim;
                let d2 = d * d;
                z.par_chunks_mut(d * 1024)
                    .zip(r.par_chunks(d * 1024))
                    .enumerate()
                    .for_each(|(ch, (zz, rr))| {
                        let b0 = ch * 1024;
                        for (lb, (zb, rb)) in zz.chunks_mut(d).zip(rr.chunks(d)).enumerate() {
                            let m = &self.inv[(b0 + lb) * d2..(b0 + lb + 1) * d2];
                            for a in 0..d {
                                let mut acc = 0.0;
                                for c in 0..d {
                                    acc += m[a * d + c] * rb[c];
                                }
                                zb[a] = acc;
                            }
                        }
                    });
            }
        }
    }
}

/// Inverse of a symmetric 3×3 matrix if it is positive definite (Cholesky test).
pub(crate) fn inv3_spd(a: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let s = |i: usize, j: usize| 0.5 * (a[i][j] + a[j][i]);
    let l00 = s(0, 0);
    if l00 <= 0.0 {
        return None;
    }
    let m1 = s(0, 0) * s(1, 1) - s(0, 1) * s(0, 1);
    let det = s(0, 0) * (s(1, 1) * s(2, 2) - s(1, 2) * s(1, 2))
        - s(0, 1) * (s(0, 1) * s(2, 2) - s(1, 2) * s(0, 2))
        + s(0, 2) * (s(0, 1) * s(1, 2) - s(1, 1) * s(0, 2));
    let scale = s(0, 0) * s(1, 1) * s(2, 2);
    if m1 <= 1e-14 * s(0, 0) * s(1, 1) || det <= 1e-14 * scale {
        return None;
    }
    let c = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        s(r0, c0) * s(r1, c1) - s(r0, c1) * s(r1, c0)
    };
    let mut inv = [[0.0; 3]; 3];
    for (i, row) in inv.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = c(j, i) / det;
        }
    }
    Some(inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The parallel dot product is bit-identical in pools of 1, 2, 3 and 4 threads and equals
    /// the serial sum of the fixed chunks' partials in chunk order. Magnitudes spread over
    /// twelve decades make the sum sensitive to its grouping (rayon's own `sum` over the
    /// chunk partials gave thread-count dependent last bits).
    #[test]
    fn dot_is_bit_identical_at_any_thread_count() {
        let n = 40 * CHUNK + 123;
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let x: Vec<f64> = (0..n)
            .map(|_| (next() - 0.5) * 10f64.powf(12.0 * next() - 6.0))
            .collect();
        let y: Vec<f64> = (0..n).map(|_| next() - 0.3).collect();
        let expected: f64 = x
            .chunks(CHUNK)
            .zip(y.chunks(CHUNK))
            .map(|(a, b)| dot_serial(a, b))
            .fold(0.0, |s, p| s + p);
        for threads in 1..=4 {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for _ in 0..5 {
                let d = pool.install(|| dot(&x, &y));
                assert_eq!(d.to_bits(), expected.to_bits(), "{threads} threads");
            }
        }
    }
}
