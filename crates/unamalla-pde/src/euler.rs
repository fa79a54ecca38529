//! A first-order finite-volume solver of the 3D Euler equations on a structured hexahedral
//! grid — the smallest faithful version of the application of Cortés Aguirre (2012, *Mallas
//! hexaédricas estructuradas…*, chapter 5): a pressure blast in a closed sphere or ellipsoid
//! meshed by the hexahedral product, run there with CLAWPACK 4.3.
//!
//! # Equations
//! For a polytropic gas (`γ` = [`EulerOptions::gamma`], 1.4 in the source),
//!
//! ```text
//! ∂ₜq + ∇·f(q) = 0,   q = (ρ, ρu, ρv, ρw, E),   E = p/(γ − 1) + ½ρ|u|²,
//! f(q)·n = (ρ u_n, ρu u_n + p n_x, ρv u_n + p n_y, ρw u_n + p n_z, (E + p) u_n),  u_n = u·n.
//! ```
//!
//! # Scheme
//! Cell averages on the hexahedra; each face `f` between cells `L` and `R` carries the
//! **Rusanov** (local Lax–Friedrichs) flux (Rusanov 1961; Toro 2009, *Riemann Solvers and
//! Numerical Methods for Fluid Dynamics*, 3rd ed., §10.5.1, eq. (10.55))
//!
//! `F_f = |S_f|·(½(f(q_L) + f(q_R))·n̂ − ½ s (q_R − q_L))`,  `s = max(|u_n| + c)` over L and R,
//!
//! with `S_f = ½ (x₃ − x₁) × (x₄ − x₂)` the vector area of the (bilinear) face — the exact
//! vector area of the face's boundary loop, so the six face areas of every cell sum to zero and
//! a uniform state is preserved to rounding (free-stream preservation). Volumes are
//! `V = ⅓ Σ_f c_f·S_f` (divergence theorem with the face centroids `c_f`). **Solid walls**: the
//! outside state of a boundary face is the mirror state (same `ρ`, `p`; `u − 2(u·n̂)n̂`), so no
//! mass or energy crosses a wall. Forward Euler in time, `Δt = CFL · min_c V_c / Σ_{f∋c} s_f
//! |S_f|` (the positivity bound of the Rusanov scheme for CFL ≤ 1). First order in space and
//! time: the source's CLAWPACK runs add limited second-order corrections, which this version
//! leaves out (docs/results.md, feature table).
//!
//! Determinism: face fluxes are computed in parallel, and each cell sums its six faces in a
//! fixed order, so the result does not depend on the thread count.

use rayon::prelude::*;
use unamalla_mesh::{DVec3, StructuredGrid3};

/// Errors of the Euler solver.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EulerError {
    /// A cell has a non-positive volume (a folded or degenerate hexahedron).
    #[error("cell {cell} has volume {volume:.3e} ≤ 0: the grid is folded")]
    FoldedCell {
        /// The cell (`i + (m−1)(j + (n−1)k)`).
        cell: usize,
        /// Its volume.
        volume: f64,
    },
    /// An option is out of range.
    #[error("option {name} = {value}: {reason}")]
    InvalidOption {
        /// The option.
        name: &'static str,
        /// Its value.
        value: f64,
        /// Why.
        reason: &'static str,
    },
    /// A state has non-positive density or pressure, or is not finite.
    #[error("cell {cell}: density {rho:.3e}, pressure {p:.3e} at step {step} (t = {time:.4e}): not a physical state")]
    Unphysical {
        /// The cell.
        cell: usize,
        /// Its density.
        rho: f64,
        /// Its pressure.
        p: f64,
        /// The step (0 = the initial state).
        step: usize,
        /// The time.
        time: f64,
    },
}

/// Options of [`EulerSolver::run`]. Build them from [`EulerOptions::default`] or
/// [`EulerOptions::until`] and the setters; new options may be added in minor releases.
///
/// ```
/// use unamalla_pde::euler::EulerOptions;
///
/// let opts = EulerOptions::until(0.5).gamma(1.3).cfl(0.5).max_steps(40);
/// assert_eq!((opts.end_time, opts.gamma, opts.cfl, opts.max_steps), (0.5, 1.3, 0.5, 40));
/// assert_eq!(EulerOptions::default().end_time(0.2).end_time, 0.2);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct EulerOptions {
    /// Ratio of specific heats `γ` (1.4).
    pub gamma: f64,
    /// Courant number (0.8; at most 1).
    pub cfl: f64,
    /// End time.
    pub end_time: f64,
    /// Steps at most (the run stops there even before `end_time`).
    pub max_steps: usize,
}

impl Default for EulerOptions {
    fn default() -> Self {
        Self {
            gamma: 1.4,
            cfl: 0.8,
            end_time: 0.1,
            max_steps: 100_000,
        }
    }
}

impl EulerOptions {
    /// The default options with the end time `t`.
    pub fn until(t: f64) -> Self {
        Self {
            end_time: t,
            ..Self::default()
        }
    }

    /// Sets [`gamma`](Self::gamma): ratio of specific heats `γ` (1.4).
    #[must_use]
    pub fn gamma(mut self, gamma: f64) -> Self {
        self.gamma = gamma;
        self
    }

    /// Sets [`cfl`](Self::cfl): Courant number (0.8; at most 1).
    #[must_use]
    pub fn cfl(mut self, cfl: f64) -> Self {
        self.cfl = cfl;
        self
    }

    /// Sets [`end_time`](Self::end_time): end time.
    #[must_use]
    pub fn end_time(mut self, end_time: f64) -> Self {
        self.end_time = end_time;
        self
    }

    /// Sets [`max_steps`](Self::max_steps): steps at most (the run stops there even before
    /// `end_time`).
    #[must_use]
    pub fn max_steps(mut self, max_steps: usize) -> Self {
        self.max_steps = max_steps;
        self
    }
}

/// What a run did.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct EulerReport {
    /// Steps taken.
    pub steps: usize,
    /// Time reached.
    pub time: f64,
    /// Total mass `Σ ρ V` at the start and at the end.
    pub mass: [f64; 2],
    /// Total energy `Σ E V` at the start and at the end.
    pub energy: [f64; 2],
    /// Smallest density and pressure at the end.
    pub min_rho_p: [f64; 2],
    /// Largest pressure at the end.
    pub max_p: f64,
}

/// Conserved state of one cell: `(ρ, ρu, ρv, ρw, E)`.
pub type State = [f64; 5];

/// A face: its owner cell, the cell across it (`None` on the wall) and its vector area,
/// pointing out of the owner.
#[derive(Debug, Clone, Copy)]
struct Face {
    owner: usize,
    other: Option<usize>,
    area: DVec3,
}

/// The finite-volume geometry of a hexahedral grid (module documentation).
#[derive(Debug, Clone)]
pub struct EulerSolver {
    volumes: Vec<f64>,
    centroids: Vec<DVec3>,
    faces: Vec<Face>,
    /// The six faces of every cell with the sign of its outward area (`+1` owner, `−1`).
    cell_faces: Vec<[(usize, f64); 6]>,
}

/// Local faces of a VTK hexahedron with outward normals (`unamalla_mesh::HEX_FACES`) and the
/// structured neighbour across each: bottom `k−`, top `k+`, front `j−`, right `i+`, back `j+`,
/// left `i−`.
const NEIGHBOUR: [(i64, i64, i64); 6] = [
    (0, 0, -1),
    (0, 0, 1),
    (0, -1, 0),
    (1, 0, 0),
    (0, 1, 0),
    (-1, 0, 0),
];

impl EulerSolver {
    /// The geometry of `grid`'s `(m−1)(n−1)(p−1)` cells (index `i + (m−1)(j + (n−1)k)`).
    /// Errors: a cell of non-positive volume (after orienting the grid by its total volume).
    pub fn new(grid: &StructuredGrid3) -> Result<Self, EulerError> {
        let (gm, gn, gp) = grid.dims();
        let (w, h, d) = (gm - 1, gn - 1, gp - 1);
        let nc = w * h * d;
        let x = unamalla_mesh::HasNodes::nodes(grid);
        let id = |i: usize, j: usize, k: usize| i + w * (j + h * k);
        let face_area = |c: [usize; 8], f: usize| -> (DVec3, DVec3) {
            let q = unamalla_mesh::HEX_FACES[f].map(|l| x[c[l]]);
            (
                0.5 * (q[2] - q[0]).cross(q[3] - q[1]),
                0.25 * (q[0] + q[1] + q[2] + q[3]),
            )
        };
        // orientation: the grid may be left-handed (all volumes negative)
        let mut total = 0.0;
        let mut raw = vec![0.0; nc];
        let mut centroids = vec![DVec3::ZERO; nc];
        for k in 0..d {
            for j in 0..h {
                for i in 0..w {
                    let c = grid.cell(i, j, k);
                    let v: f64 = (0..6)
                        .map(|f| {
                            let (s, m) = face_area(c, f);
                            m.dot(s) / 3.0
                        })
                        .sum();
                    raw[id(i, j, k)] = v;
                    total += v;
                    centroids[id(i, j, k)] = c.iter().map(|&n| x[n]).sum::<DVec3>() / 8.0;
                }
            }
        }
        let sign = if total < 0.0 { -1.0 } else { 1.0 };
        let volumes: Vec<f64> = raw.iter().map(|v| v * sign).collect();
        if let Some(cell) = volumes.iter().position(|&v| v.is_nan() || v <= 0.0) {
            return Err(EulerError::FoldedCell {
                cell,
                volume: volumes[cell],
            });
        }
        let mut faces = Vec::with_capacity(3 * nc + 2 * (w * h + h * d + w * d));
        let mut cell_faces = vec![[(0usize, 0.0f64); 6]; nc];
        let mut owned: Vec<[Option<usize>; 6]> = vec![[None; 6]; nc];
        for k in 0..d {
            for j in 0..h {
                for i in 0..w {
                    let c = id(i, j, k);
                    let nodes = grid.cell(i, j, k);
                    for (f, &(di, dj, dk)) in NEIGHBOUR.iter().enumerate() {
                        let (ni, nj, nk) = (i as i64 + di, j as i64 + dj, k as i64 + dk);
                        let inside = (0..w as i64).contains(&ni)
                            && (0..h as i64).contains(&nj)
                            && (0..d as i64).contains(&nk);
                        let other = inside.then(|| id(ni as usize, nj as usize, nk as usize));
                        match other {
                            Some(o) if o < c => {
                                // made by the other cell: its face opposite to this one
                                let opposite = [1, 0, 4, 5, 2, 3][f];
                                let fid = owned[o][opposite].unwrap_or_else(|| unreachable!());
                                cell_faces[c][f] = (fid, -1.0);
                            }
                            _ => {
                                let (s, _) = face_area(nodes, f);
                                faces.push(Face {
                                    owner: c,
                                    other,
                                    area: s * sign,
                                });
                                owned[c][f] = Some(faces.len() - 1);
                                cell_faces[c][f] = (faces.len() - 1, 1.0);
                            }
                        }
                    }
                }
            }
        }
        Ok(Self {
            volumes,
            centroids,
            faces,
            cell_faces,
        })
    }

    /// Cell volumes.
    pub fn volumes(&self) -> &[f64] {
        &self.volumes
    }

    /// Cell centroids (mean of the eight corners).
    pub fn centroids(&self) -> &[DVec3] {
        &self.centroids
    }

    /// The conserved states of primitive values `(ρ, u, p)` given per cell centroid.
    pub fn initial_state(&self, gamma: f64, f: impl Fn(DVec3) -> (f64, DVec3, f64)) -> Vec<State> {
        self.centroids
            .iter()
            .map(|&c| {
                let (rho, u, p) = f(c);
                conserved(gamma, rho, u, p)
            })
            .collect()
    }

    /// Pressure of every cell.
    pub fn pressure(&self, gamma: f64, q: &[State]) -> Vec<f64> {
        q.iter().map(|s| primitive(gamma, s).2).collect()
    }

    /// Advances `q` to [`EulerOptions::end_time`] (or [`EulerOptions::max_steps`]).
    pub fn run(&self, q: &mut [State], opts: &EulerOptions) -> Result<EulerReport, EulerError> {
        if !(opts.gamma > 1.0 && opts.gamma.is_finite()) {
            return Err(EulerError::InvalidOption {
                name: "gamma",
                value: opts.gamma,
                reason: "γ must be > 1",
            });
        }
        if !(opts.cfl > 0.0 && opts.cfl <= 1.0) {
            return Err(EulerError::InvalidOption {
                name: "cfl",
                value: opts.cfl,
                reason: "the Courant number must lie in (0, 1]",
            });
        }
        if !(opts.end_time >= 0.0 && opts.end_time.is_finite()) {
            return Err(EulerError::InvalidOption {
                name: "end_time",
                value: opts.end_time,
                reason: "the end time must be finite and ≥ 0",
            });
        }
        let g = opts.gamma;
        self.check(g, q, 0, 0.0)?;
        let totals = |q: &[State]| {
            let mass: f64 = q.iter().zip(&self.volumes).map(|(s, v)| s[0] * v).sum();
            let energy: f64 = q.iter().zip(&self.volumes).map(|(s, v)| s[4] * v).sum();
            (mass, energy)
        };
        let (m0, e0) = totals(q);
        let mut t = 0.0;
        let mut steps = 0;
        let mut flux = vec![([0.0; 5], 0.0); self.faces.len()];
        while t < opts.end_time && steps < opts.max_steps {
            // fluxes and spectral radii per face
            flux.par_iter_mut()
                .zip(&self.faces)
                .for_each(|(out, f)| *out = face_flux(g, f, q));
            // Δt from the cells' Σ s|S|
            let dt_cells: f64 = (0..q.len())
                .into_par_iter()
                .map(|c| {
                    let rate: f64 = self.cell_faces[c].iter().map(|&(fid, _)| flux[fid].1).sum();
                    self.volumes[c] / rate.max(f64::MIN_POSITIVE)
                })
                .reduce(|| f64::INFINITY, f64::min);
            let dt = (opts.cfl * dt_cells).min(opts.end_time - t);
            q.par_iter_mut().enumerate().for_each(|(c, s)| {
                let mut net = [0.0; 5];
                for &(fid, sign) in &self.cell_faces[c] {
                    for (n, v) in net.iter_mut().zip(&flux[fid].0) {
                        *n += sign * v;
                    }
                }
                let k = dt / self.volumes[c];
                for (s, n) in s.iter_mut().zip(&net) {
                    *s -= k * n;
                }
            });
            t += dt;
            steps += 1;
            self.check(g, q, steps, t)?;
        }
        let (m1, e1) = totals(q);
        let (mut rmin, mut pmin, mut pmax) = (f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY);
        for s in q.iter() {
            let (rho, _, p) = primitive(g, s);
            rmin = rmin.min(rho);
            pmin = pmin.min(p);
            pmax = pmax.max(p);
        }
        Ok(EulerReport {
            steps,
            time: t,
            mass: [m0, m1],
            energy: [e0, e1],
            min_rho_p: [rmin, pmin],
            max_p: pmax,
        })
    }

    fn check(&self, g: f64, q: &[State], step: usize, time: f64) -> Result<(), EulerError> {
        for (cell, s) in q.iter().enumerate() {
            let (rho, _, p) = primitive(g, s);
            if !(rho > 0.0 && p > 0.0 && rho.is_finite() && p.is_finite()) {
                return Err(EulerError::Unphysical {
                    cell,
                    rho,
                    p,
                    step,
                    time,
                });
            }
        }
        Ok(())
    }
}

/// `(ρ, u, p)` → `(ρ, ρu, E)`.
pub fn conserved(gamma: f64, rho: f64, u: DVec3, p: f64) -> State {
    [
        rho,
        rho * u.x,
        rho * u.y,
        rho * u.z,
        p / (gamma - 1.0) + 0.5 * rho * u.length_squared(),
    ]
}

/// `(ρ, ρu, E)` → `(ρ, u, p)`.
pub fn primitive(gamma: f64, s: &State) -> (f64, DVec3, f64) {
    let rho = s[0];
    let u = DVec3::new(s[1], s[2], s[3]) / rho;
    let p = (gamma - 1.0) * (s[4] - 0.5 * rho * u.length_squared());
    (rho, u, p)
}

/// The physical flux `f(q)·n̂` and `|u_n| + c`.
fn normal_flux(gamma: f64, s: &State, n: DVec3) -> (State, f64) {
    let (rho, u, p) = primitive(gamma, s);
    let un = u.dot(n);
    let c = (gamma * p / rho).max(0.0).sqrt();
    (
        [
            rho * un,
            s[1] * un + p * n.x,
            s[2] * un + p * n.y,
            s[3] * un + p * n.z,
            (s[4] + p) * un,
        ],
        un.abs() + c,
    )
}

/// The Rusanov flux through face `f` (times its area) and `s·|S|`.
fn face_flux(gamma: f64, f: &Face, q: &[State]) -> (State, f64) {
    let a = f.area.length();
    if a == 0.0 {
        return ([0.0; 5], 0.0);
    }
    let n = f.area / a;
    let l = q[f.owner];
    let r = match f.other {
        Some(o) => q[o],
        None => {
            // the mirror state across a solid wall
            let (rho, u, p) = primitive(gamma, &l);
            conserved(gamma, rho, u - 2.0 * u.dot(n) * n, p)
        }
    };
    let (fl, sl) = normal_flux(gamma, &l, n);
    let (fr, sr) = normal_flux(gamma, &r, n);
    let s = sl.max(sr);
    let mut out = [0.0; 5];
    for k in 0..5 {
        out[k] = a * (0.5 * (fl[k] + fr[k]) - 0.5 * s * (r[k] - l[k]));
    }
    (out, s * a)
}

#[cfg(test)]
mod tests {
    use super::*;
    use unamalla_mesh::hexgen::ellipsoid_grid;

    /// A uniform gas at rest in a closed ball stays at rest: the six face areas of every cell
    /// sum to zero, so the pressure forces cancel exactly (up to rounding).
    #[test]
    fn a_gas_at_rest_stays_at_rest() {
        let g = ellipsoid_grid((9, 9, 9), DVec3::ONE, DVec3::ZERO).unwrap();
        let s = EulerSolver::new(&g).unwrap();
        let mut q = s.initial_state(1.4, |_| (1.0, DVec3::ZERO, 1.0));
        let r = s.run(&mut q, &EulerOptions::until(0.2)).unwrap();
        assert!(r.steps > 5);
        for st in &q {
            let (rho, u, p) = primitive(1.4, st);
            assert!(
                (rho - 1.0).abs() < 1e-12 && (p - 1.0).abs() < 1e-12,
                "{rho} {p}"
            );
            assert!(u.length() < 1e-12, "{u}");
        }
    }

    /// The cell volumes of the ball add up to the volume of the polyhedral ball (the mapped
    /// cube): between the inscribed and the true ball volume 4π/3.
    #[test]
    fn volumes_add_up() {
        let g = ellipsoid_grid((13, 13, 13), DVec3::ONE, DVec3::ZERO).unwrap();
        let s = EulerSolver::new(&g).unwrap();
        let v: f64 = s.volumes().iter().sum();
        let ball = 4.0 / 3.0 * std::f64::consts::PI;
        assert!(v < ball && v > 0.95 * ball, "{v} vs {ball}");
    }

    #[test]
    fn bad_options_are_errors() {
        let g = ellipsoid_grid((5, 5, 5), DVec3::ONE, DVec3::ZERO).unwrap();
        let s = EulerSolver::new(&g).unwrap();
        let mut q = s.initial_state(1.4, |_| (1.0, DVec3::ZERO, 1.0));
        for o in [
            EulerOptions {
                cfl: 1.5,
                ..EulerOptions::default()
            },
            EulerOptions {
                gamma: 1.0,
                ..EulerOptions::default()
            },
        ] {
            assert!(matches!(
                s.run(&mut q, &o),
                Err(EulerError::InvalidOption { .. })
            ));
        }
        let mut bad = s.initial_state(1.4, |_| (-1.0, DVec3::ZERO, 1.0));
        assert!(matches!(
            s.run(&mut bad, &EulerOptions::default()),
            Err(EulerError::Unphysical { step: 0, .. })
        ));
    }
}
