//! Dense Jacobian sampling, as in [Abelló et al., §3, Table 1]: `det J` at `N_ξ × N_η`
//! equispaced parameters `ξ_a = a/(N_ξ−1)`, `η_b = b/(N_η−1)` (the boundary of `U` included —
//! the paper does not say whether its 10⁴ × 10⁴ sample did), in parallel (rayon, one task per
//! row of `η`), returning the minimum and maximum with their locations, the mean and the number
//! of non-positive samples.
//!
//! Each sample costs one cubic Horner evaluation: per row and patch the power-basis coefficients
//! of `det J` ([`crate::map::Patch::jac_power`]) are contracted with `1, v, v², v³` once, so a
//! 10⁸-point sample is a few hundred million multiply-adds. The mean of `det J` over `U`
//! approximates `area(Ω)` for an injective map (`∫_U det J = area(Ω)`), so
//! `min/mean` is the scale-free number to compare across regions.

use rayon::prelude::*;

use crate::error::BsplineError;
use crate::map::TensorMap;

/// Result of [`sample_det_j`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct JacobianSample {
    /// Samples along ξ.
    pub n_xi: usize,
    /// Samples along η.
    pub n_eta: usize,
    /// Minimum `det J`.
    pub min: f64,
    /// Where: `(ξ, η)`.
    pub argmin: (f64, f64),
    /// Maximum `det J`.
    pub max: f64,
    /// Where.
    pub argmax: (f64, f64),
    /// Mean over the samples (≈ area of the image for an injective map).
    pub mean: f64,
    /// Samples with `det J ≤ 0`.
    pub nonpositive: u64,
}

impl JacobianSample {
    /// `min/mean`, scale free.
    pub fn min_over_mean(&self) -> f64 {
        self.min / self.mean
    }
}

#[derive(Clone, Copy)]
struct Acc {
    min: f64,
    amin: (usize, usize),
    max: f64,
    amax: (usize, usize),
    sum: f64,
    nonpos: u64,
}

impl Acc {
    fn empty() -> Self {
        Acc {
            min: f64::INFINITY,
            amin: (0, 0),
            max: f64::NEG_INFINITY,
            amax: (0, 0),
            sum: 0.0,
            nonpos: 0,
        }
    }
    fn merge(self, o: Acc) -> Acc {
        // ties broken by the smaller (row, column) so the result does not depend on scheduling
        let (min, amin) = if o.min < self.min
            || (o.min == self.min && (o.amin.1, o.amin.0) < (self.amin.1, self.amin.0))
        {
            (o.min, o.amin)
        } else {
            (self.min, self.amin)
        };
        let (max, amax) = if o.max > self.max
            || (o.max == self.max && (o.amax.1, o.amax.0) < (self.amax.1, self.amax.0))
        {
            (o.max, o.amax)
        } else {
            (self.max, self.amax)
        };
        Acc {
            min,
            amin,
            max,
            amax,
            sum: self.sum + o.sum,
            nonpos: self.nonpos + o.nonpos,
        }
    }
}

/// Samples `det J` on `n_xi × n_eta ≥ 2 × 2` equispaced parameters (module docs).
pub fn sample_det_j(
    map: &TensorMap,
    n_xi: usize,
    n_eta: usize,
) -> Result<JacobianSample, BsplineError> {
    if n_xi < 2 || n_eta < 2 {
        return Err(BsplineError::InvalidOption {
            name: "samples",
            value: n_xi.min(n_eta) as f64,
            reason: "at least 2 samples per direction",
        });
    }
    let (npx, _) = map.num_patches();
    let e = 2 * map.degree().degree() - 1;
    // column → (patch column, local u), computed once
    let cols: Vec<(u32, f64)> = (0..n_xi)
        .map(|a| {
            let xi = a as f64 / (n_xi - 1) as f64;
            let (px, _, u, _) = map.locate(xi, 0.0);
            (px as u32, u)
        })
        .collect();
    let acc = (0..n_eta)
        .into_par_iter()
        .map(|b| {
            let eta = b as f64 / (n_eta - 1) as f64;
            let (_, py, _, v) = map.locate(0.0, eta);
            // per patch of this row: cubic coefficients in u
            let mut q = vec![[0.0f64; 4]; npx];
            for (px, qp) in q.iter_mut().enumerate() {
                let p = &map.patch(px, py).jac_power;
                for a in 0..=e {
                    let mut s = 0.0;
                    for bb in (0..=e).rev() {
                        s = s * v + p[a][bb];
                    }
                    qp[a] = s;
                }
            }
            let mut acc = Acc::empty();
            for (a, &(px, u)) in cols.iter().enumerate() {
                let c = &q[px as usize];
                let d = ((c[3] * u + c[2]) * u + c[1]) * u + c[0];
                acc.sum += d;
                if d <= 0.0 || d.is_nan() {
                    acc.nonpos += 1;
                }
                if d < acc.min || d.is_nan() {
                    acc.min = if d.is_nan() { f64::NEG_INFINITY } else { d };
                    acc.amin = (a, b);
                }
                if d > acc.max {
                    acc.max = d;
                    acc.amax = (a, b);
                }
            }
            acc
        })
        .reduce(Acc::empty, Acc::merge);
    let at = |(a, b): (usize, usize)| (a as f64 / (n_xi - 1) as f64, b as f64 / (n_eta - 1) as f64);
    Ok(JacobianSample {
        n_xi,
        n_eta,
        min: acc.min,
        argmin: at(acc.amin),
        max: acc.max,
        argmax: at(acc.amax),
        mean: acc.sum / (n_xi as f64 * n_eta as f64),
        nonpositive: acc.nonpos,
    })
}

/// `det J` on an `n_xi × n_eta` parameter grid, `η`-major (`b·n_xi + a`), for export.
pub fn det_j_grid(map: &TensorMap, n_xi: usize, n_eta: usize) -> Vec<f64> {
    let nx = n_xi.max(2);
    let ny = n_eta.max(2);
    (0..ny)
        .into_par_iter()
        .flat_map_iter(|b| {
            let eta = b as f64 / (ny - 1) as f64;
            (0..nx).map(move |a| map.det_j_bernstein(a as f64 / (nx - 1) as f64, eta))
        })
        .collect()
}
