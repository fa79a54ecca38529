//! The built-in logically hexahedral regions (after the test regions of [Cortés Aguirre 2012,
//! §3.4.1, Table 3.1], the box of its chapter 4 and the ellipsoid of §2.1.1; the references are
//! listed in `docs/references.md` of the repository) and their initial meshes: the radial map of
//! the cube onto the ball and the ellipsoid, extrusion of a plan-view grid between two surfaces,
//! six analytic face grids filled by 3D TFI, and the Shepard surface of the reservoir stand-in.

use std::f64::consts::PI;
use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};
use unamalla_mesh::hexgen::{
    cube_to_ball, ellipsoid_grid, extrude_grid, Anchor, Extrusion, FaceGrid, HexGenError,
    HexRegion, NodalFunction, Plane, Shepard, ShepardKind,
};
use unamalla_mesh::{DVec2, DVec3, StructuredGrid2, StructuredGrid3};

use crate::{HexError, Perturbation};

/// The built-in logically hexahedral regions (after [Cortés Aguirre 2012, §3.4.1, Table 3.1]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum HexCase {
    /// "Esfera": the radial map of `[−1, 1]³` onto the unit ball (every node mapped). Thesis
    /// size 20³, perturbed to 22 non-convex cells.
    Sphere,
    /// "Elipsoide": the same map scaled to semi-axes `(0.5, 1, 0.5)`. Thesis size 20³, 45
    /// non-convex cells at the start.
    Ellipsoid,
    /// The chapter 4 box: `x, y ∈ [−4, 4]`, bottom `z = −5 − sin(0.5x + 0.5y)`, top
    /// `z = 5 + cos(0.5x + 0.5y)`, vertical sides; uniform `(x, y)` grid extruded with equal
    /// layers between bottom and top. Thesis size 5³, no perturbation (it is the convex
    /// harmonic mesh whose cells are not planar).
    Box,
    /// "Pico"-like: `[0, 2]² × [0, 2.5]`, five planar faces (bottom `z = 0`, vertical sides),
    /// top = the plane `z = 1.5` plus the trigonometric peak
    /// `cos²(π r/(2·0.6))` (`r` = distance to `(1, 1)`, zero for `r ≥ 0.6`), peak height 2.5;
    /// six face grids and 3D TFI. Thesis sizes 10³ (80 non-convex at the start) and 21³ (188).
    Pico,
    /// "Cosin"-like: `[0, 2]² × [0, 2.5]`, vertical planar sides, bottom
    /// `z = 0.125(1 + sin(πx + πy))`, top `z = 2.25 + 0.25 cos(πx) sin(πy)` (combinations of
    /// cos and sin); six face grids and 3D TFI. Thesis size 10-10-15, 17 non-convex.
    Cosin,
    /// "Shell"-like: a disc of radius 10.74 (2D radial square → disc grid), flat base
    /// `z = −1`, paraboloid top `z = 9.97 − 0.0856 r²` (≈ 0.1 at the rim); equal layers.
    /// Thesis size 20-20-10, 100 non-convex.
    Shell,
    /// "Parabs"-like: two paraboloids over the disc of radius 10, bottom `z = 0.5 + 0.5 r²`,
    /// top `z = 135.39 − 0.5 r²`; equal layers. Thesis size 20-20-10, 30 non-convex.
    Parabs,
    /// "Elipsoideg" (Cortés Aguirre 2012, Table 3.1: the degenerate ellipsoid from the radial
    /// map of `[−1, 1]³` with a **planar top**, initial mesh by TFI, domain
    /// `[−0.5, 0.5] × [−1, 1] × [−0.5, 0.2887]`, size 10-10-13, 58 non-convex cells at the
    /// start). The thesis gives the domain and the construction, not the flattening; ours
    /// (our reconstruction, matching that domain exactly): the six cube faces are mapped by the
    /// scaled ball map of [`HexCase::Ellipsoid`] (semi-axes 0.5, 1, 0.5), then the height of
    /// each boundary node is multiplied by `1 + (ρ − 1)·w`, with `ρ(x, y) = √(1 + x² + y²)/√3`
    /// of the node's cube coordinates (this puts the whole top face at `z = 0.5/√3 = 0.2887`,
    /// the height of the mapped top corners) and `w = ((z_cube + 1)/2)²` (0 on the bottom
    /// face); interior by 3D TFI of the six faces.
    Elipsoideg,
    /// "Yacimiento1"-like reservoir (Table 3.1: "reservoir top copied vertically", domain
    /// `[27.51, 98.86] × [16.9, 95.68] × [69.01, 82.57]`, size 35-25-5, 30 non-convex at the
    /// start; the field data are not in the thesis). Built as the thesis's §2.2.3 / App. B
    /// "case 2" does, with stand-in data: a 2D structured mesh of a curved four-sided contour
    /// filling that `(x, y)` box ([`yacimiento_plan`]) is projected onto a **Shepard
    /// surface** ([`unamalla_mesh::hexgen::Shepard`], modified method, 13 neighbours, linear
    /// nodal functions; Renka 1988) interpolating 40 synthetic top picks
    /// ([`yacimiento_data`]: an anticline `z = 82.57 − 3.5·u² − 2.5·v²` sampled at Halton
    /// points), and **extruded** downwards with the layer thicknesses `1.5, 2, 2, 2`
    /// ([`Extrusion::Layers`], anchor top).
    Yacimiento,
    /// "Sydney"-like (Table 3.1: flat circular base, the top "formed by modifying the base with
    /// two paraboloids in opposite senses", initial mesh by interpolating top and base,
    /// `x, y ∈ [−10.74, 10.74]`, `z ∈ [−1, 11.24]`, size 20-20-15, 103 non-convex at the
    /// start; the paraboloids are not given). Ours: the disc of radius `R = 10.74`, base
    /// `z = −1`, top `11.24 − a r²` for `r ≤ R/2` and `a (R − r)² − 0.9` beyond (the inverse
    /// paraboloid; `C¹` at `R/2`, which fixes `a = 12.14/(2 (R/2)²)`), equal layers.
    Sydney,
}

impl HexCase {
    /// All built-in cases.
    pub const ALL: [HexCase; 10] = [
        HexCase::Sphere,
        HexCase::Ellipsoid,
        HexCase::Box,
        HexCase::Pico,
        HexCase::Cosin,
        HexCase::Shell,
        HexCase::Parabs,
        HexCase::Elipsoideg,
        HexCase::Yacimiento,
        HexCase::Sydney,
    ];

    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            HexCase::Sphere => "sphere",
            HexCase::Ellipsoid => "ellipsoid",
            HexCase::Box => "box",
            HexCase::Pico => "pico",
            HexCase::Cosin => "cosin",
            HexCase::Shell => "shell",
            HexCase::Parabs => "parabs",
            HexCase::Elipsoideg => "elipsoideg",
            HexCase::Yacimiento => "yacimiento",
            HexCase::Sydney => "sydney",
        }
    }

    /// The thesis's size for this region (nodes per direction).
    pub fn default_size(self) -> (usize, usize, usize) {
        match self {
            HexCase::Sphere | HexCase::Ellipsoid => (20, 20, 20),
            HexCase::Box => (5, 5, 5),
            HexCase::Pico => (10, 10, 10),
            HexCase::Cosin => (10, 10, 15),
            HexCase::Shell | HexCase::Parabs => (20, 20, 10),
            HexCase::Elipsoideg => (10, 10, 13),
            HexCase::Yacimiento => (35, 25, 5),
            HexCase::Sydney => (20, 20, 15),
        }
    }

    /// The default perturbation: at least the thesis's number of non-convex cells at the
    /// start ("NC0" of Tables 3.1–3.2; Pico 21³ has 188), none for the box.
    pub fn default_perturbation(self, dims: (usize, usize, usize)) -> Perturbation {
        let cells = match self {
            HexCase::Sphere => 22,
            HexCase::Ellipsoid => 45,
            HexCase::Box => return Perturbation::None,
            HexCase::Pico if dims.0 >= 21 => 188,
            HexCase::Pico => 80,
            HexCase::Cosin => 17,
            HexCase::Shell => 100,
            HexCase::Parabs => 30,
            HexCase::Elipsoideg => 58,
            HexCase::Yacimiento => 30,
            HexCase::Sydney => 103,
        };
        Perturbation::AtLeast { cells }
    }

    /// The unperturbed initial mesh of size `dims` (nodes per direction, each ≥ 2).
    pub fn initial_grid(self, dims: (usize, usize, usize)) -> Result<StructuredGrid3, HexError> {
        let (m, n, p) = dims;
        if m < 2 || n < 2 || p < 2 {
            return Err(HexGenError::TooSmall {
                dims,
                reason: "a hexahedral mesh needs at least 2 nodes per direction",
            }
            .into());
        }
        let u = |i: usize, k: usize| i as f64 / (k - 1) as f64;
        match self {
            HexCase::Sphere => Ok(ellipsoid_grid(dims, DVec3::ONE, DVec3::ZERO)?),
            HexCase::Ellipsoid => Ok(ellipsoid_grid(
                dims,
                DVec3::new(0.5, 1.0, 0.5),
                DVec3::ZERO,
            )?),
            HexCase::Box => {
                let g2 = StructuredGrid2::from_fn(m, n, |i, j| {
                    DVec2::new(-4.0 + 8.0 * u(i, m), -4.0 + 8.0 * u(j, n))
                })
                .map_err(HexGenError::from)?;
                let base = |x: f64, y: f64| -5.0 - (0.5 * x + 0.5 * y).sin();
                let top = |x: f64, y: f64| 5.0 + (0.5 * x + 0.5 * y).cos();
                Ok(extrude_grid(
                    &g2,
                    &Extrusion::uniform_between(&base, &top, p),
                )?)
            }
            HexCase::Pico => {
                let top = |x: f64, y: f64| {
                    let r = DVec2::new(x - 1.0, y - 1.0).length();
                    let peak = if r < 0.6 {
                        (PI * r / 1.2).cos().powi(2)
                    } else {
                        0.0
                    };
                    1.5 + peak
                };
                tfi_between(dims, [0.0, 2.0, 0.0, 2.0], &|_, _| 0.0, &top)
            }
            HexCase::Cosin => {
                let base = |x: f64, y: f64| 0.125 * (1.0 + (PI * x + PI * y).sin());
                let top = |x: f64, y: f64| 2.25 + 0.25 * (PI * x).cos() * (PI * y).sin();
                tfi_between(dims, [0.0, 2.0, 0.0, 2.0], &base, &top)
            }
            HexCase::Shell => {
                let g2 = disc_grid(m, n, 10.74)?;
                let base = Plane::horizontal(-1.0);
                let top = |x: f64, y: f64| 9.97 - 0.0856 * (x * x + y * y);
                Ok(extrude_grid(
                    &g2,
                    &Extrusion::uniform_between(&base, &top, p),
                )?)
            }
            HexCase::Parabs => {
                let g2 = disc_grid(m, n, 10.0)?;
                let base = |x: f64, y: f64| 0.5 + 0.5 * (x * x + y * y);
                let top = |x: f64, y: f64| 135.39 - 0.5 * (x * x + y * y);
                Ok(extrude_grid(
                    &g2,
                    &Extrusion::uniform_between(&base, &top, p),
                )?)
            }
            HexCase::Sydney => {
                let big_r = 10.74;
                let g2 = disc_grid(m, n, big_r)?;
                let base = Plane::horizontal(-1.0);
                let top = |x: f64, y: f64| sydney_top(DVec2::new(x, y).length());
                Ok(extrude_grid(
                    &g2,
                    &Extrusion::uniform_between(&base, &top, p),
                )?)
            }
            HexCase::Elipsoideg => {
                let axes = DVec3::new(0.5, 1.0, 0.5);
                let t = |i: usize, k: usize| -1.0 + 2.0 * u(i, k);
                let at = |i: usize, j: usize, k: usize| {
                    let q = DVec3::new(t(i, m), t(j, n), t(k, p));
                    let mut b = cube_to_ball(q);
                    let rho = (1.0 + q.x * q.x + q.y * q.y).sqrt() / 3f64.sqrt();
                    let w = (0.5 * (q.z + 1.0)).powi(2);
                    b.z *= 1.0 + (rho - 1.0) * w;
                    b * axes
                };
                tfi_of_faces(dims, &at)
            }
            HexCase::Yacimiento => {
                let plan = yacimiento_plan(m, n)?;
                let top = Shepard::new(
                    &yacimiento_data(),
                    ShepardKind::Modified {
                        neighbors: 13,
                        nodal: NodalFunction::Linear,
                    },
                )?;
                // thesis thicknesses are not given; 1.5, 2, 2, 2 for the 5 node layers,
                // repeated (scaled to the same total 7.5) for other p
                let thicknesses = if p == 5 {
                    vec![1.5, 2.0, 2.0, 2.0]
                } else {
                    vec![7.5 / (p - 1) as f64; p - 1]
                };
                Ok(extrude_grid(
                    &plan,
                    &Extrusion::Layers {
                        surface: &top,
                        anchor: Anchor::Top,
                        thicknesses,
                    },
                )?)
            }
        }
    }
}

impl fmt::Display for HexCase {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for HexCase {
    type Err = HexError;
    fn from_str(s: &str) -> Result<Self, HexError> {
        let l = s.to_ascii_lowercase();
        let alias = match l.as_str() {
            "esfera" | "ball" => "sphere",
            "elipsoide" => "ellipsoid",
            "ch4" | "chapter4" => "box",
            "yacimiento1" | "yac1" | "reservoir" => "yacimiento",
            other => other,
        };
        HexCase::ALL
            .into_iter()
            .find(|c| c.name() == alias)
            .ok_or_else(|| HexError::UnknownCase(s.to_string()))
    }
}

/// The plan-view mesh of the [`HexCase::Yacimiento`] stand-in: an `m × n` TFI-like grid of a
/// four-sided contour with gently curved sides spanning `[27.51, 98.86] × [16.9, 95.68]` (the
/// thesis's Yacimiento1 box): `x = x0 + Lx·(s + 0.03 sin(πs) sin(2πt))`,
/// `y = y0 + Ly·(t + 0.04 sin(2πs) sin(πt))`, `(s, t)` uniform in `[0, 1]²` (sides bulge
/// inward/outward by ≤ 4 % of the box; the corners and the box are the thesis's).
pub fn yacimiento_plan(m: usize, n: usize) -> Result<StructuredGrid2, HexError> {
    let (x0, lx, y0, ly) = (27.51, 98.86 - 27.51, 16.9, 95.68 - 16.9);
    Ok(StructuredGrid2::from_fn(m, n, |i, j| {
        let s = i as f64 / (m - 1) as f64;
        let t = j as f64 / (n - 1) as f64;
        DVec2::new(
            x0 + lx * (s + 0.03 * (PI * s).sin() * (2.0 * PI * t).sin()),
            y0 + ly * (t + 0.04 * (2.0 * PI * s).sin() * (PI * t).sin()),
        )
    })
    .map_err(HexGenError::from)?)
}

/// The 40 synthetic "top of reservoir" picks of [`HexCase::Yacimiento`] (stand-ins for the
/// field data the thesis does not give): Halton points (bases 2 and 3, indices 1..=40) of the
/// box `[27.51, 98.86] × [16.9, 95.68]` widened by 5 % on each side, each with
/// `z = 82.57 − 3.5·u² − 2.5·v² + 0.3·sin(3u)·cos(2v)`, `u, v ∈ [−1, 1]` the box coordinates
/// of the pick (an anticline with its crest at the thesis's `z_max = 82.57`).
pub fn yacimiento_data() -> Vec<[f64; 3]> {
    fn halton(mut i: usize, b: usize) -> f64 {
        let (mut f, mut r) = (1.0, 0.0);
        while i > 0 {
            f /= b as f64;
            r += f * (i % b) as f64;
            i /= b;
        }
        r
    }
    let (x0, lx, y0, ly) = (27.51, 98.86 - 27.51, 16.9, 95.68 - 16.9);
    (1..=40)
        .map(|i| {
            // stretch [0, 1] to [−0.05, 1.05] so the picks cover the corners of the box
            let s = -0.05 + 1.1 * halton(i, 2);
            let t = -0.05 + 1.1 * halton(i, 3);
            let (u, v) = (2.0 * s - 1.0, 2.0 * t - 1.0);
            let z = 82.57 - 3.5 * u * u - 2.5 * v * v + 0.3 * (3.0 * u).sin() * (2.0 * v).cos();
            [x0 + lx * s, y0 + ly * t, z]
        })
        .collect()
}

/// The top of [`HexCase::Sydney`] at distance `r` from the axis.
fn sydney_top(r: f64) -> f64 {
    let big_r = 10.74;
    let r1 = big_r / 2.0;
    let a = 12.14 / (2.0 * r1 * r1);
    if r <= r1 {
        11.24 - a * r * r
    } else {
        a * (big_r - r).powi(2) - 0.9
    }
}

/// The 2D radial map of the square `[−1, 1]²` onto the disc of radius `r`
/// (`x ↦ r·x·‖x‖∞/‖x‖₂`, the 2D analogue of the ball map).
fn disc_grid(m: usize, n: usize, r: f64) -> Result<StructuredGrid2, HexError> {
    let t = |i: usize, k: usize| -1.0 + 2.0 * i as f64 / (k - 1) as f64;
    Ok(StructuredGrid2::from_fn(m, n, |i, j| {
        let q = DVec2::new(t(i, m), t(j, n));
        let l = q.length();
        if l > 0.0 {
            q * (r * q.abs().max_element() / l)
        } else {
            DVec2::ZERO
        }
    })
    .map_err(HexGenError::from)?)
}

/// Six face grids of the box `[x0, x1] × [y0, y1]` between `z = base(x, y)` and
/// `z = top(x, y)` (vertical planar sides, uniform spacing), validated as a [`HexRegion`] and
/// filled by 3D TFI.
fn tfi_between(
    dims: (usize, usize, usize),
    bb: [f64; 4],
    base: &dyn Fn(f64, f64) -> f64,
    top: &dyn Fn(f64, f64) -> f64,
) -> Result<StructuredGrid3, HexError> {
    let (m, n, p) = dims;
    let x = |i: usize| bb[0] + (bb[1] - bb[0]) * i as f64 / (m - 1) as f64;
    let y = |j: usize| bb[2] + (bb[3] - bb[2]) * j as f64 / (n - 1) as f64;
    let at = |i: usize, j: usize, k: usize| {
        let (xx, yy) = (x(i), y(j));
        let t = k as f64 / (p - 1) as f64;
        DVec3::new(xx, yy, (1.0 - t) * base(xx, yy) + t * top(xx, yy))
    };
    tfi_of_faces(dims, &at)
}

/// The six face grids of the boundary nodes `at(i, j, k)` of an `m × n × p` grid, validated as
/// a [`HexRegion`] and filled by 3D TFI (§2.2.1).
fn tfi_of_faces(
    dims: (usize, usize, usize),
    at: &dyn Fn(usize, usize, usize) -> DVec3,
) -> Result<StructuredGrid3, HexError> {
    let (m, n, p) = dims;
    let faces = [
        FaceGrid::from_fn(n, p, |j, k| at(0, j, k)),
        FaceGrid::from_fn(n, p, |j, k| at(m - 1, j, k)),
        FaceGrid::from_fn(m, p, |i, k| at(i, 0, k)),
        FaceGrid::from_fn(m, p, |i, k| at(i, n - 1, k)),
        FaceGrid::from_fn(m, n, |i, j| at(i, j, 0)),
        FaceGrid::from_fn(m, n, |i, j| at(i, j, p - 1)),
    ];
    Ok(HexRegion::from_face_grids(faces)?.tfi()?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use unamalla_mesh::hexgen::{admissibility, classify_cells};

    #[test]
    fn generators_put_the_boundary_on_the_surfaces() {
        // sphere: boundary nodes at radius 1
        let g = HexCase::Sphere.initial_grid((9, 9, 9)).unwrap();
        for k in 0..9 {
            for j in 0..9 {
                for i in 0..9 {
                    if g.is_boundary(i, j, k) {
                        assert!((g.node(i, j, k).length() - 1.0).abs() < 1e-14);
                    }
                }
            }
        }
        // box: bottom and top on −5 − sin, 5 + cos; sides at ±4
        let g = HexCase::Box.initial_grid((5, 5, 5)).unwrap();
        for j in 0..5 {
            for i in 0..5 {
                let b = g.node(i, j, 0);
                let t = g.node(i, j, 4);
                assert!((b.z - (-5.0 - (0.5 * b.x + 0.5 * b.y).sin())).abs() < 1e-12);
                assert!((t.z - (5.0 + (0.5 * t.x + 0.5 * t.y).cos())).abs() < 1e-12);
            }
        }
        assert_eq!(g.node(0, 0, 2).x, -4.0);
        assert_eq!(g.node(4, 4, 2).y, 4.0);
        // pico: peak height 2.5 at (1, 1) (odd size puts a node there), plane 1.5 far away
        let g = HexCase::Pico.initial_grid((11, 11, 5)).unwrap();
        assert!((g.node(5, 5, 4) - DVec3::new(1.0, 1.0, 2.5)).length() < 1e-12);
        assert!((g.node(0, 0, 4).z - 1.5).abs() < 1e-12);
        // shell / parabs: rim nodes at the disc radius, bases as defined
        let g = HexCase::Shell.initial_grid((12, 12, 4)).unwrap();
        let q = g.node(11, 4, 0);
        assert!((DVec2::new(q.x, q.y).length() - 10.74).abs() < 1e-12 && q.z == -1.0);
        let g = HexCase::Parabs.initial_grid((12, 12, 4)).unwrap();
        let q = g.node(3, 0, 3);
        let r2 = q.x * q.x + q.y * q.y;
        assert!((q.z - (135.39 - 0.5 * r2)).abs() < 1e-9);
        // sydney: the two paraboloids meet C¹ at R/2 (a = 12.14/(2·5.37²)); the thesis's z range
        let a = 12.14 / (2.0 * 5.37 * 5.37);
        assert!((sydney_top(5.37) - (11.24 - a * 5.37 * 5.37)).abs() < 1e-12);
        assert!((sydney_top(5.37) - (a * 5.37 * 5.37 - 0.9)).abs() < 1e-12);
        let d = 1e-6;
        let slope = |r: f64| (sydney_top(r + d) - sydney_top(r - d)) / (2.0 * d);
        assert!((slope(5.37) + 2.0 * a * 5.37).abs() < 1e-6);
        assert_eq!(sydney_top(0.0), 11.24);
        assert!((sydney_top(10.74) + 0.9).abs() < 1e-12);
        let g = HexCase::Sydney.initial_grid((11, 11, 6)).unwrap();
        assert_eq!(g.node(5, 5, 5).z, 11.24);
        assert_eq!(g.node(0, 3, 0).z, -1.0);
    }
    #[test]
    fn every_case_is_admissible_at_its_default_size_and_names_parse() {
        for case in HexCase::ALL {
            let g = case.initial_grid(case.default_size()).unwrap();
            let a = admissibility(&g);
            assert!(a.is_admissible(), "{case}: {:?}", a.violations.first());
            assert_eq!(case.name().parse::<HexCase>().unwrap(), case);
            assert_eq!(classify_cells(&g).len(), g.num_cells());
        }
        assert!(matches!(
            "bogus".parse::<HexCase>(),
            Err(HexError::UnknownCase(_))
        ));
        assert_eq!("Esfera".parse::<HexCase>().unwrap(), HexCase::Sphere);
    }
    /// Elipsoideg (Table 3.1): the thesis's domain `[−0.5, 0.5] × [−1, 1] × [−0.5, 0.5/√3]`
    /// and a planar top face.
    #[test]
    fn elipsoideg_has_the_thesis_domain_and_a_flat_top() {
        let (m, n, p) = HexCase::Elipsoideg.default_size();
        assert_eq!((m, n, p), (10, 10, 13));
        let g = HexCase::Elipsoideg.initial_grid((m, n, p)).unwrap();
        let zc = 0.5 / 3f64.sqrt();
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for k in 0..p {
            for j in 0..n {
                for i in 0..m {
                    if g.is_boundary(i, j, k) {
                        lo = lo.min(g.node(i, j, k));
                        hi = hi.max(g.node(i, j, k));
                    }
                }
            }
        }
        // p = 13 puts a node layer on the equator (cube z = 0), where x and y reach 0.5 and 1;
        // n = m = 10 have no node at the cube's x = 0 or y = 0, hence the 2 % slack there; the
        // lowest nodes are the bottom face's (±1/9, ±1/9, −1): z = −0.5/√(1 + 2/81)
        let zlo = -0.5 / (1.0 + 2.0 / 81.0f64).sqrt();
        assert!(
            (lo.z - zlo).abs() < 1e-12 && (hi.z - zc).abs() < 1e-12,
            "{lo} {hi}"
        );
        assert!(
            (hi.x - 0.5).abs() < 0.02 && (hi.y - 1.0).abs() < 0.02,
            "{hi}"
        );
        for j in 0..n {
            for i in 0..m {
                assert!((g.node(i, j, p - 1).z - zc).abs() < 1e-12);
            }
        }
        // the bottom face is the unflattened ellipsoid
        let b = g.node(3, 6, 0);
        let r = (b.x / 0.5).powi(2) + b.y.powi(2) + (b.z / 0.5).powi(2);
        assert!((r - 1.0).abs() < 1e-12);
    }
    /// Yacimiento (Table 3.1, §2.2.3): the top is the Shepard surface of the picks, the layers
    /// are vertical copies 1.5, 2, 2, 2 below it.
    #[test]
    fn yacimiento_is_a_shepard_top_with_vertical_copies() {
        let dims = HexCase::Yacimiento.default_size();
        assert_eq!(dims, (35, 25, 5));
        let g = HexCase::Yacimiento.initial_grid(dims).unwrap();
        let data = yacimiento_data();
        assert_eq!(data.len(), 40);
        let top = Shepard::new(
            &data,
            ShepardKind::Modified {
                neighbors: 13,
                nodal: NodalFunction::Linear,
            },
        )
        .unwrap();
        // Shepard interpolates its data
        for d in &data {
            assert!((top.eval(d[0], d[1]) - d[2]).abs() < 1e-9);
        }
        let plan = yacimiento_plan(35, 25).unwrap();
        for (i, j) in [(0, 0), (34, 24), (17, 12), (5, 20)] {
            let q = plan.node(i, j);
            let t = g.node(i, j, 4);
            assert!((t.x - q.x).abs() < 1e-12 && (t.y - q.y).abs() < 1e-12);
            assert!((t.z - top.eval(q.x, q.y)).abs() < 1e-12);
            for (k, below) in [(3, 2.0), (2, 4.0), (1, 6.0), (0, 7.5)] {
                let c = g.node(i, j, k);
                assert!((t.z - c.z - below).abs() < 1e-12 && c.x == t.x && c.y == t.y);
            }
        }
        // the plan's corners are the thesis's box corners
        assert_eq!(plan.node(0, 0), DVec2::new(27.51, 16.9));
        assert!((plan.node(34, 24) - DVec2::new(98.86, 95.68)).length() < 1e-12);
    }
}
