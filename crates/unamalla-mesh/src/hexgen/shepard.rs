//! Shepard interpolation of scattered `(x, y, z)` data, for top and base surfaces
//! ([Cortés Aguirre 2012, §2.2.3, Fig. 2.13]: a function `f(x, y)` or scattered observations,
//! interpolated with Shepard's method as in [Renka 1988]; the references are listed in
//! `docs/references.md` of the repository).
//!
//! With data `(x_k, f_k)`, `k = 1..N`, and `d_k = ‖x − x_k‖`:
//!
//! * **Global** (Shepard 1968): `F(x) = Σ w_k f_k / Σ w_k`, `w_k = d_k^{−q}` (`q > 0`,
//!   usually 2); `F(x_k) = f_k`.
//! * **Modified** (Franke–Little weights, as in Renka's 1988 algorithm):
//!   `F(x) = Σ W_k Q_k(x) / Σ W_k`, `W_k = [(R_k − d_k)₊ / (R_k d_k)]²`, where `R_k` is the
//!   radius of the smallest disc about `x_k` holding `n_w` other data points (times
//!   `1 + 10⁻⁹`, so the farthest of them has a positive weight), and the nodal function
//!   `Q_k` is either the constant `f_k` ([`NodalFunction::Constant`]) or the plane
//!   `f_k + g_k·(x − x_k)` whose gradient `g_k` is the weighted least-squares fit to the
//!   `n_w` nearest neighbours with Renka's weights ([`NodalFunction::Linear`]; Renka uses
//!   quadratics, a documented simplification). If no disc covers `x` (all `W_k = 0`), the global weights with `q = 2` are used.
//!
//! Both forms interpolate the data (`W_k → ∞` as `x → x_k`) and reproduce constants; the
//! linear form also reproduces planes exactly (every `Q_k` is then the plane itself).
//! Evaluation is a direct `O(N)` loop per point: the thesis's data sets are small.

use glam::DVec2;

use super::error::HexGenError;

/// Nodal functions of the modified method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum NodalFunction {
    /// `Q_k = f_k`.
    Constant,
    /// `Q_k = f_k + g_k·(x − x_k)` (least-squares gradient).
    Linear,
}

/// Which Shepard method.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum ShepardKind {
    /// `w_k = d_k^{−power}` over all data.
    Global {
        /// The exponent `q > 0`.
        power: f64,
    },
    /// Local Franke–Little weights over `neighbors` nearest points.
    Modified {
        /// `n_w ≥ 1` (Renka suggests 19 for QSHEP2D; fewer for small data sets).
        neighbors: usize,
        /// The nodal functions.
        nodal: NodalFunction,
    },
}

/// A Shepard interpolant of scattered data `z = f(x, y)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Shepard {
    xy: Vec<DVec2>,
    z: Vec<f64>,
    kind: ShepardKind,
    radius: Vec<f64>,
    grad: Vec<DVec2>,
}

impl Shepard {
    /// Builds the interpolant from points `(x, y, z)`. Errors on an empty or non-finite data
    /// set, on repeated `(x, y)` locations, and on invalid parameters.
    ///
    /// ```
    /// use unamalla_mesh::hexgen::{Shepard, ShepardKind, NodalFunction};
    /// let data = [[0.0, 0.0, 1.0], [1.0, 0.0, 2.0], [0.0, 1.0, 3.0], [1.0, 1.0, 4.0], [0.5, 0.4, 2.3]];
    /// let s = Shepard::new(&data, ShepardKind::Modified { neighbors: 4, nodal: NodalFunction::Linear }).unwrap();
    /// // z = 1 + x + 2y is reproduced exactly by linear nodal functions
    /// assert!((s.eval(0.3, 0.7) - (1.0 + 0.3 + 1.4)).abs() < 1e-12);
    /// assert_eq!(s.eval(1.0, 0.0), 2.0);
    /// ```
    pub fn new(points: &[[f64; 3]], kind: ShepardKind) -> Result<Self, HexGenError> {
        if points.is_empty() {
            return Err(HexGenError::Data("no data points".into()));
        }
        if let Some(ix) = points.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(HexGenError::NonFinite {
                what: "scattered data",
                index: ix,
            });
        }
        let xy: Vec<DVec2> = points.iter().map(|p| DVec2::new(p[0], p[1])).collect();
        let z: Vec<f64> = points.iter().map(|p| p[2]).collect();
        {
            let mut order: Vec<usize> = (0..xy.len()).collect();
            order.sort_by(|&a, &b| {
                xy[a]
                    .x
                    .total_cmp(&xy[b].x)
                    .then(xy[a].y.total_cmp(&xy[b].y))
            });
            for w in order.windows(2) {
                if xy[w[0]] == xy[w[1]] {
                    return Err(HexGenError::Data(format!(
                        "points {} and {} have the same (x, y) = ({}, {})",
                        w[0].min(w[1]),
                        w[0].max(w[1]),
                        xy[w[0]].x,
                        xy[w[0]].y
                    )));
                }
            }
        }
        let mut radius = Vec::new();
        let mut grad = Vec::new();
        match kind {
            ShepardKind::Global { power } => {
                if !(power.is_finite() && power > 0.0) {
                    return Err(HexGenError::InvalidParameter {
                        name: "power",
                        value: power,
                        reason: "the Shepard exponent must be finite and > 0",
                    });
                }
            }
            ShepardKind::Modified { neighbors, nodal } => {
                if neighbors == 0 {
                    return Err(HexGenError::InvalidParameter {
                        name: "neighbors",
                        value: 0.0,
                        reason: "the modified method needs at least one neighbour",
                    });
                }
                let nw = neighbors.min(xy.len().saturating_sub(1));
                for k in 0..xy.len() {
                    let mut d: Vec<(f64, usize)> = (0..xy.len())
                        .filter(|&j| j != k)
                        .map(|j| (xy[j].distance(xy[k]), j))
                        .collect();
                    d.sort_by(|a, b| a.0.total_cmp(&b.0));
                    d.truncate(nw);
                    let r = d.last().map_or(f64::INFINITY, |x| x.0 * (1.0 + 1e-9));
                    radius.push(r);
                    let g = match nodal {
                        NodalFunction::Constant => DVec2::ZERO,
                        NodalFunction::Linear => {
                            // weighted normal equations A g = b, A = Σ w e eᵀ, b = Σ w e Δf
                            let (mut a11, mut a12, mut a22, mut b1, mut b2) =
                                (0.0, 0.0, 0.0, 0.0, 0.0);
                            for &(dj, j) in &d {
                                let w = ((r - dj).max(0.0) / (r * dj)).powi(2);
                                let e = xy[j] - xy[k];
                                let df = z[j] - z[k];
                                a11 += w * e.x * e.x;
                                a12 += w * e.x * e.y;
                                a22 += w * e.y * e.y;
                                b1 += w * e.x * df;
                                b2 += w * e.y * df;
                            }
                            let det = a11 * a22 - a12 * a12;
                            // collinear or too few neighbours: no reliable gradient
                            if det > 1e-12 * (a11 + a22).powi(2) && det > 0.0 {
                                DVec2::new((a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det)
                            } else {
                                DVec2::ZERO
                            }
                        }
                    };
                    grad.push(g);
                }
            }
        }
        Ok(Self {
            xy,
            z,
            kind,
            radius,
            grad,
        })
    }

    /// Number of data points.
    pub fn len(&self) -> usize {
        self.z.len()
    }

    /// `true` if there is no data (never, for a constructed interpolant).
    pub fn is_empty(&self) -> bool {
        self.z.is_empty()
    }

    /// The interpolated value at `(x, y)`.
    pub fn eval(&self, x: f64, y: f64) -> f64 {
        let q = DVec2::new(x, y);
        let global = |power: f64| -> f64 {
            let (mut sw, mut swf) = (0.0, 0.0);
            for (k, p) in self.xy.iter().enumerate() {
                let d = p.distance(q);
                if d == 0.0 {
                    return self.z[k];
                }
                let w = d.powf(-power);
                sw += w;
                swf += w * self.z[k];
            }
            swf / sw
        };
        match self.kind {
            ShepardKind::Global { power } => global(power),
            ShepardKind::Modified { .. } => {
                let (mut sw, mut swf) = (0.0, 0.0);
                for (k, p) in self.xy.iter().enumerate() {
                    let d = p.distance(q);
                    if d == 0.0 {
                        return self.z[k];
                    }
                    let r = self.radius[k];
                    if d >= r {
                        continue;
                    }
                    let w = ((r - d) / (r * d)).powi(2);
                    sw += w;
                    swf += w * (self.z[k] + self.grad[k].dot(q - *p));
                }
                if sw > 0.0 {
                    swf / sw
                } else {
                    global(2.0)
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn data(f: impl Fn(f64, f64) -> f64) -> Vec<[f64; 3]> {
        // a jittered 6 × 6 lattice on [0, 1]²
        let mut v = Vec::new();
        for j in 0..6 {
            for i in 0..6 {
                let x = i as f64 / 5.0 + 0.03 * ((i * 7 + j * 3) % 5) as f64 / 5.0;
                let y = j as f64 / 5.0 + 0.02 * ((i * 2 + j * 5) % 7) as f64 / 7.0;
                v.push([x, y, f(x, y)]);
            }
        }
        v
    }

    #[test]
    fn every_method_interpolates_the_data() {
        let d = data(|x, y| (3.0 * x).sin() + y * y);
        for kind in [
            ShepardKind::Global { power: 2.0 },
            ShepardKind::Modified {
                neighbors: 8,
                nodal: NodalFunction::Constant,
            },
            ShepardKind::Modified {
                neighbors: 8,
                nodal: NodalFunction::Linear,
            },
        ] {
            let s = Shepard::new(&d, kind).unwrap();
            for p in &d {
                assert_eq!(s.eval(p[0], p[1]), p[2]);
            }
        }
    }

    #[test]
    fn linear_nodal_functions_reproduce_planes_and_constants_are_kept() {
        let plane = |x: f64, y: f64| 2.0 - 0.5 * x + 3.0 * y;
        let s = Shepard::new(
            &data(plane),
            ShepardKind::Modified {
                neighbors: 8,
                nodal: NodalFunction::Linear,
            },
        )
        .unwrap();
        let g = Shepard::new(&data(|_, _| 4.5), ShepardKind::Global { power: 2.0 }).unwrap();
        for (x, y) in [(0.11, 0.52), (0.9, 0.05), (0.5, 0.5), (1.3, -0.2)] {
            assert!((s.eval(x, y) - plane(x, y)).abs() < 1e-10, "{x} {y}");
            assert!((g.eval(x, y) - 4.5).abs() < 1e-12);
        }
    }

    #[test]
    fn bad_data_is_rejected_by_name() {
        assert!(matches!(
            Shepard::new(&[], ShepardKind::Global { power: 2.0 }),
            Err(HexGenError::Data(_))
        ));
        let e = Shepard::new(
            &[[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 0.0, 2.0]],
            ShepardKind::Global { power: 2.0 },
        )
        .unwrap_err();
        assert!(e.to_string().contains("points 0 and 2"), "{e}");
        let e =
            Shepard::new(&[[0.0, f64::NAN, 1.0]], ShepardKind::Global { power: 2.0 }).unwrap_err();
        assert_eq!(
            e,
            HexGenError::NonFinite {
                what: "scattered data",
                index: 0
            }
        );
        assert!(Shepard::new(&[[0.0, 0.0, 1.0]], ShepardKind::Global { power: -1.0 }).is_err());
    }

    proptest! {
        #[test]
        fn values_stay_within_the_data_range_for_constant_nodal_functions(
            x in -0.5f64..1.5, y in -0.5f64..1.5
        ) {
            // convex combination of the f_k: min f ≤ F ≤ max f
            let d = data(|x, y| x * y - x);
            let (lo, hi) = d.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p[2]), b.max(p[2])));
            for kind in [
                ShepardKind::Global { power: 2.0 },
                ShepardKind::Modified { neighbors: 6, nodal: NodalFunction::Constant },
            ] {
                let v = Shepard::new(&d, kind).unwrap().eval(x, y);
                prop_assert!(v >= lo - 1e-12 && v <= hi + 1e-12);
            }
        }
    }
}
