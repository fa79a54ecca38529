//! # unamalla-hex
//!
//! Structured hexahedral meshes on logically hexahedral regions (seed 004): built-in test
//! regions, initial meshes, Algorithm A (convex harmonic) and Algorithm B (planar faces), the
//! run report and the output files.
//!
//! # Pipeline (seed 004 digest §0)
//! 1. **Region and initial mesh** ([`HexCase::initial_grid`], [`read_face_dir`]): six face
//!    grids + 3D TFI, the radial cube → ball/ellipsoid map, or extrusion of a 2D grid between
//!    two surfaces (generators in [`unamalla_mesh::hexgen`]);
//! 2. **perturbation** ([`Perturbation`]): seeded random moves of the interior nodes until the
//!    start has at least the thesis's number of non-convex cells (Tables 3.1–3.2 "NC0"), or
//!    with a given amplitude;
//! 3. **admissibility** (Def. 11): every fixed tetrahedron positive, else
//!    [`HexError::Inadmissible`];
//! 4. **Algorithm A** ([`unamalla_optim::drivers::omega_continuation_hex`], §3.4): minimise
//!    `H_ω` over the 10 tetrahedra of each cell, halving `ω` until the mesh is ε-convex
//!    (`V > ε·v̄`, ε = 10⁻⁴ as for Tables 3.1–3.2), then one refinement run;
//! 5. **Algorithm B** ([`unamalla_optim::drivers::coplanarity_continuation`], §4.2), if asked
//!    and A reached convexity: `H_ω + C·Σk²` over the faces of the interior cells,
//!    `C = 1/(2μ)`, `μ = 500, 50, …` until every interior face has `|cos| ≤ 10⁻³` (or
//!    `μ ≤ 10⁻¹²`; the thesis's `μ₀ = 0.1` schedule without the planarity stop is
//!    [`CoplanarityOptions::thesis`]; the choice is explained on
//!    [`coplanarity_continuation`]); the convexity safeguard keeps the mesh convex;
//! 6. **report** ([`HexRunReport`], §9 and App. B "information panel"): non-convex cells
//!    (10-tetrahedra test with ε), non-hexahedral interior cells (some face with
//!    `|cos| ≥ 10⁻²`, criterion 2 of §4.1), max `|cos|`, min/max tetrahedron volume, Verdict
//!    scaled Jacobian min/p5, iterations, time, and the histograms of App. B.6 (tetrahedron
//!    volume sign, face planarity, edge lengths) as data and as an SVG plot
//!    ([`histograms_svg`]).
//!
//! # Built-in regions ([`HexCase`], digest §10)
//! `sphere` and `ellipsoid` (semi-axes 0.5, 1, 0.5) and the chapter 4 `box` are the thesis's
//! exactly reconstructible regions. `pico`, `cosin`, `shell` and `parabs` are **analytic
//! stand-ins** with the thesis's bounding boxes: the thesis does not give their surfaces
//! (digest §10, "Approx"); each variant's documentation gives the formula used.
//!
//! ```
//! use unamalla_hex::{run_hex, HexCase, HexRunOptions, Perturbation};
//! use unamalla_optim::NullObserver;
//!
//! let mut grid = HexCase::Sphere.initial_grid((8, 8, 8)).unwrap();
//! let (amp, nc0) = Perturbation::AtLeast { cells: 5 }.apply(&mut grid, 1).unwrap();
//! assert!(nc0 >= 5 && amp > 0.0);
//! let rep = run_hex(&mut grid, &HexRunOptions::default(), &mut NullObserver).unwrap();
//! assert_eq!(rep.start.non_convex_cells, nc0);
//! assert_eq!(rep.non_convex_cells, 0); // Algorithm A made it convex
//! ```

#![warn(missing_docs)]
// user input (case names, face-grid files, options) reaches every function: no unwrap/expect
// outside tests (issue #14)
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

use std::f64::consts::PI;
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::Arc;
use std::time::Instant;

use serde::{Deserialize, Serialize};
use unamalla_functionals::{FunctionalError, HexTopology, Scaling3};
use unamalla_io::IoError;
use unamalla_mesh::hexgen::{
    admissibility, class_counts, classify_cells, cube_to_ball, ellipsoid_grid, extrude_grid,
    perturb_interior, perturb_until_nonconvex, planarity_counts, Anchor, CellClass, ClassCounts,
    Extrusion, FaceGrid, HexFaceId, HexGenError, HexRegion, NodalFunction, PlanarityCounts, Plane,
    Shepard, ShepardKind,
};
use unamalla_mesh::quality::{hex_metrics_per_cell, HexMetrics, MetricSummary};
use unamalla_mesh::svg::{Style, SvgCanvas};
use unamalla_mesh::{
    DVec2, DVec3, HasHexCells, HasNodes, HexMesh, StructuredGrid2, StructuredGrid3,
};
use unamalla_optim::drivers::{
    coplanarity_continuation, omega_continuation_hex, CoplanarityOptions, OmegaOptions,
};
use unamalla_optim::monitor::Session;
use unamalla_optim::{Observer, OptimError, SmoothReport, SolverOptions};

/// Errors of the hexahedral pipeline.
#[derive(Debug, thiserror::Error)]
pub enum HexError {
    /// A generator or region check failed.
    #[error(transparent)]
    Gen(#[from] HexGenError),
    /// The optimiser failed.
    #[error(transparent)]
    Optim(#[from] OptimError),
    /// The functional could not be set up.
    #[error(transparent)]
    Functional(#[from] FunctionalError),
    /// Writing an output file failed.
    #[error(transparent)]
    Io(#[from] IoError),
    /// A face-grid file could not be read or parsed.
    #[error("{}: line {line}: {reason}", path.display())]
    FaceFile {
        /// The file.
        path: PathBuf,
        /// 1-based line number (0 when the file could not be opened).
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// The case name is not a built-in region.
    #[error("unknown hex case '{0}'; built-in cases: sphere, ellipsoid, box, pico, cosin, shell, parabs, elipsoideg, yacimiento, sydney (or a directory of six face grids)")]
    UnknownCase(String),
    /// Some fixed tetrahedron has `V ≤ 0` (Def. 11): no interior node can repair it.
    #[error("the region is not admissible: fixed tetrahedron {tet} of cell {cell} has V = {v:e} ≤ 0 ({count} such tetrahedra)")]
    Inadmissible {
        /// First offending cell.
        cell: usize,
        /// Its tetrahedron (row of the 10-tetrahedra table).
        tet: usize,
        /// Its `V`.
        v: f64,
        /// Number of offending tetrahedra.
        count: usize,
    },
}

/// The built-in logically hexahedral regions (digest §10).
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

/// Reads a region given as a directory of six face grids `i_min.txt`, `i_max.txt`,
/// `j_min.txt`, `j_max.txt`, `k_min.txt`, `k_max.txt` and returns it validated
/// ([`HexRegion::from_face_grids`]).
///
/// Each file: optional `#` comment lines, a line `a b` (points along the face's first and
/// second directions: `(j, k)` on the `i` faces, `(i, k)` on the `j` faces, `(i, j)` on the
/// `k` faces), then `a·b` lines `x y z`, first direction fastest (the layout of
/// [`unamalla_mesh::HexFaces`]).
pub fn read_face_dir(dir: &Path) -> Result<HexRegion, HexError> {
    let mut grids = Vec::with_capacity(6);
    for id in HexFaceId::ALL {
        let path = dir.join(format!("{}.txt", id.name()));
        let text = std::fs::read_to_string(&path).map_err(|e| HexError::FaceFile {
            path: path.clone(),
            line: 0,
            reason: e.to_string(),
        })?;
        grids.push(parse_face_grid(&path, &text)?);
    }
    let faces: [FaceGrid; 6] = grids.try_into().map_err(|_| HexError::FaceFile {
        path: dir.to_path_buf(),
        line: 0,
        reason: "expected six face grids".into(),
    })?;
    Ok(HexRegion::from_face_grids(faces)?)
}

/// Parses one face-grid file (see [`read_face_dir`]); `path` is only used in errors.
pub fn parse_face_grid(path: &Path, text: &str) -> Result<FaceGrid, HexError> {
    let err = |line: usize, reason: String| HexError::FaceFile {
        path: path.to_path_buf(),
        line,
        reason,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(k, l)| (k + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let (ln, head) = lines
        .next()
        .ok_or_else(|| err(0, "empty file; expected a line 'a b'".into()))?;
    let dims: Vec<usize> = head
        .split_whitespace()
        .map(|t| t.parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| err(ln, format!("expected two point counts 'a b', got '{head}'")))?;
    let [a, b] = <[usize; 2]>::try_from(dims)
        .map_err(|_| err(ln, format!("expected two point counts 'a b', got '{head}'")))?;
    if a < 2 || b < 2 {
        return Err(err(
            ln,
            format!("a face grid needs at least 2 × 2 points, got {a} × {b}"),
        ));
    }
    let mut points = Vec::with_capacity(a.saturating_mul(b).min(1 << 24));
    for (ln, l) in lines {
        let v: Vec<f64> = l
            .split_whitespace()
            .map(|t| t.parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| err(ln, format!("expected 'x y z', got '{l}'")))?;
        let [x, y, z] = <[f64; 3]>::try_from(v)
            .map_err(|_| err(ln, format!("expected three coordinates 'x y z', got '{l}'")))?;
        points.push(DVec3::new(x, y, z));
    }
    if points.len() != a * b {
        return Err(err(
            0,
            format!(
                "{a} × {b} face needs {} points, found {}",
                a * b,
                points.len()
            ),
        ));
    }
    Ok(FaceGrid { a, b, points })
}

/// Writes the six faces of a region in the format of [`read_face_dir`] (atomically).
pub fn write_face_dir(region: &HexRegion, dir: &Path) -> Result<(), HexError> {
    let (m, n, p) = region.dims();
    for id in HexFaceId::ALL {
        let (a, b) = match id {
            HexFaceId::IMin | HexFaceId::IMax => (n, p),
            HexFaceId::JMin | HexFaceId::JMax => (m, p),
            HexFaceId::KMin | HexFaceId::KMax => (m, n),
        };
        let pts = region.face(id);
        let path = dir.join(format!("{}.txt", id.name()));
        unamalla_io::atomic_write(&path, |w| {
            writeln!(w, "# face {} of a {m} x {n} x {p} region", id.thesis_name())?;
            writeln!(w, "{a} {b}")?;
            for q in pts {
                writeln!(w, "{} {} {}", q.x, q.y, q.z)?;
            }
            Ok(())
        })?;
    }
    Ok(())
}

/// How the start is perturbed ([`perturb_interior`]: each free node moves by
/// `s·h_v·u`, `h_v` its shortest edge, `u` uniform in the unit ball).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Perturbation {
    /// No perturbation.
    None,
    /// A fixed amplitude `s`.
    Amplitude(f64),
    /// The smallest amplitude `0.02·1.1^t` (t = 0, 1, …, ≤ 80 tries) giving at least this
    /// many non-convex cells.
    AtLeast {
        /// Target number of non-convex cells.
        cells: usize,
    },
}

impl Perturbation {
    /// Applies the perturbation with `seed`; returns `(amplitude used, non-convex cells)`.
    pub fn apply(&self, grid: &mut StructuredGrid3, seed: u64) -> Result<(f64, usize), HexError> {
        match *self {
            Perturbation::None => {
                Ok((0.0, unamalla_mesh::quality::hex_non_convex_count(grid, 0.0)))
            }
            Perturbation::Amplitude(s) => {
                perturb_interior(grid, s, seed)?;
                Ok((s, unamalla_mesh::quality::hex_non_convex_count(grid, 0.0)))
            }
            Perturbation::AtLeast { cells } => {
                Ok(perturb_until_nonconvex(grid, cells, 0.02, seed, 80)?)
            }
        }
    }
}

/// Which algorithms to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum HexAlgorithm {
    /// Algorithm A only.
    A,
    /// Algorithm A, then Algorithm B.
    #[default]
    AB,
}

/// The tetrahedron Jacobian scaling (digest §3.2 "Scaling", erratum 6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum HexScaling {
    /// Raw vertex differences, as printed in the thesis.
    Index,
    /// Unit-parametric (`r_ξ ≈ (m−1)(r₂ − r₁)`), which fits the thesis's reported values.
    #[default]
    Parametric,
}

/// Options of [`run_hex`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HexRunOptions {
    /// A or A + B.
    pub algorithm: HexAlgorithm,
    /// Jacobian scaling of `H_ω`.
    pub scaling: HexScaling,
    /// Algorithm A (ε = 10⁻⁴ of Tables 3.1–3.2; ω₀ = 0.1 relative to the mean tetrahedron
    /// Jacobian; the thesis's absolute ω₀ = 200 has no scale-free meaning).
    pub omega: OmegaOptions,
    /// Algorithm B (`μ₀ = 500`, `μ ← 0.1μ` while `μ > 10⁻¹²` and some interior face has
    /// `|cos| > 10⁻³`, ≤ 50 iterations per step; `ε_n = 10⁻²`).
    pub coplanarity: CoplanarityOptions,
    /// Planarity tolerance on `|cos|` for "non-hexahedral" cells (criterion 2: 10⁻²).
    pub planarity_tol: f64,
    /// Tolerance `ε_v` of the volume criterion (criterion 1 of Cortés Aguirre 2012 §4.1,
    /// eq. (4.1): a face is planar iff the tetrahedron on its four vertices has
    /// `|V_l| < ε_v`; thesis value 10⁻⁶). Reported beside criterion 2 (Table 4.1), never
    /// used to steer Algorithm B.
    #[serde(default = "default_volume_tol")]
    pub planarity_volume_tol: f64,
    /// Bins of the edge-length histogram.
    pub histogram_bins: usize,
}

impl Default for HexRunOptions {
    fn default() -> Self {
        let solver = SolverOptions {
            max_iter: 100,
            ftol: 1e-8,
            gtol: 1e-4,
            ..SolverOptions::default()
        };
        Self {
            algorithm: HexAlgorithm::AB,
            scaling: HexScaling::Parametric,
            omega: OmegaOptions {
                eps: 1e-4,
                // ω₀ = 0.1·(mean tetrahedron Jacobian): on the perturbed sphere 20³ this took
                // 11 iterations and left 1892 non-hexahedral interior cells, against 14 and
                // 2216 with ω₀ = v̄ (measured; docs/results.md)
                omega0_rel: 0.1,
                solver: solver.clone(),
                ..OmegaOptions::default()
            },
            coplanarity: CoplanarityOptions {
                solver: SolverOptions {
                    max_iter: 50,
                    ..solver
                },
                ..CoplanarityOptions::default()
            },
            planarity_tol: 1e-2,
            planarity_volume_tol: default_volume_tol(),
            histogram_bins: 20,
        }
    }
}

fn default_volume_tol() -> f64 {
    1e-6
}

/// Mesh measures at one stage of a run (digest §9; App. B information panel).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HexMeasures {
    /// Cells failing the 10-tetrahedra test `V > ε·v̄` (ε of Algorithm A, `v̄` the mean of all
    /// tetrahedron values `V = 6·volume`).
    pub non_convex_cells: usize,
    /// The ε of that test.
    pub eps: f64,
    /// Interior cells with some face `|cos| ≥` the planarity tolerance (non-hexahedral).
    pub non_hex_interior_cells: usize,
    /// Faces of interior cells (counted once per cell) with `|cos| ≥` tolerance.
    pub non_planar_interior_faces: usize,
    /// Largest face `|cos|` over the interior cells (0 without interior cells).
    pub max_abs_cos: f64,
    /// Interior cells with some face whose tetrahedron volume is `|V_l| ≥ ε_v`
    /// (criterion 1 of §4.1, Table 4.1's "non-hex" column; `HexRunOptions::planarity_volume_tol`).
    #[serde(default)]
    pub non_hex_interior_cells_volume: usize,
    /// Largest face tetrahedron volume `|V_l|` over the interior cells (Table 4.1's "max Vol").
    #[serde(default)]
    pub max_face_volume: f64,
    /// Smallest face `|cos|` over the interior cells.
    pub min_abs_cos: f64,
    /// Largest face `|cos|` over all cells.
    pub max_abs_cos_all: f64,
    /// Smallest tetrahedron signed volume (of the 10 per cell).
    pub min_tet_volume: f64,
    /// Largest tetrahedron signed volume.
    pub max_tet_volume: f64,
    /// Verdict hex scaled Jacobian: minimum over the cells.
    pub min_scaled_jacobian: f64,
    /// Verdict hex scaled Jacobian: 5th percentile.
    pub p5_scaled_jacobian: f64,
}

/// Iterations and time of one algorithm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhaseStats {
    /// Solver iterations (all continuation steps and the refinement).
    pub iterations: usize,
    /// Continuation steps (ω values for A, μ values for B).
    pub continuation_steps: usize,
    /// Wall time of the algorithm in seconds.
    pub seconds: f64,
    /// The final status message (UNAMALLA wording).
    pub status: String,
    /// Final `ω` (absolute).
    pub omega: Option<f64>,
    /// Final `μ` (Algorithm B).
    pub mu: Option<f64>,
    /// Final functional value.
    pub f: f64,
    /// Final gradient norm.
    pub gnorm: f64,
}

/// A histogram over `[lo, hi]` in equal bins (the last bin closed).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Histogram {
    /// Bin edges (`bins + 1` values).
    pub edges: Vec<f64>,
    /// Counts per bin.
    pub counts: Vec<usize>,
}

impl Histogram {
    fn equal(values: &[f64], bins: usize) -> Self {
        let bins = bins.max(1);
        let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if !(lo.is_finite() && hi.is_finite()) {
            return Self {
                edges: vec![0.0, 1.0],
                counts: vec![0],
            };
        }
        let w = (hi - lo) / bins as f64;
        let edges = (0..=bins).map(|k| lo + w * k as f64).collect();
        let mut counts = vec![0; bins];
        for &v in values {
            let k = if w > 0.0 {
                (((v - lo) / w) as usize).min(bins - 1)
            } else {
                0
            };
            counts[k] += 1;
        }
        Self { edges, counts }
    }
}

/// The histograms of App. B.6 as data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HexHistograms {
    /// Tetrahedra (10 per cell) with `V > 0`.
    pub tets_positive: usize,
    /// Tetrahedra with `V = 0`.
    pub tets_zero: usize,
    /// Tetrahedra with `V < 0`.
    pub tets_negative: usize,
    /// Interior-cell faces (6 per cell) by `|cos|` decade: bin `k` holds
    /// `10^{k−7} ≤ |cos| < 10^{k−6}` for `k = 1..6`, bin 0 `|cos| < 10⁻⁶`, bin 7 `|cos| ≥ 0.1`.
    pub face_cos_decades: Vec<usize>,
    /// Decade labels of `face_cos_decades`.
    pub face_cos_labels: Vec<String>,
    /// Interior-cell faces with `|cos| <` tolerance.
    pub faces_planar: usize,
    /// Interior-cell faces with `|cos| ≥` tolerance.
    pub faces_non_planar: usize,
    /// Lengths of all mesh edges (each once).
    pub edge_lengths: Histogram,
    /// App. B.6 histogram (1): per interior-cell face (6 per cell), the smallest height of the
    /// tetrahedron on its four vertices ([`unamalla_mesh::quality::face_height_area`]); 0 for
    /// a planar face.
    #[serde(default)]
    pub face_min_heights: Histogram,
    /// App. B.6 histogram (1): per interior-cell face, the smallest triangle area of that
    /// tetrahedron.
    #[serde(default)]
    pub face_min_areas: Histogram,
}

/// The report of [`run_hex`], written as `report.json`. The flat fields describe the final
/// mesh; `start`, `after_a`, `after_b` each stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HexRunReport {
    /// Region name (built-in case or directory).
    pub case: String,
    /// Nodes per direction.
    pub dims: (usize, usize, usize),
    /// Number of cells.
    pub cells: usize,
    /// Number of interior cells (no boundary node).
    pub interior_cells: usize,
    /// Final non-convex cells.
    pub non_convex_cells: usize,
    /// Final non-hexahedral interior cells.
    pub non_hex_interior_cells: usize,
    /// Final max face `|cos|` over the interior cells.
    pub max_abs_cos: f64,
    /// Final smallest tetrahedron volume.
    pub min_tet_volume: f64,
    /// Final largest tetrahedron volume.
    pub max_tet_volume: f64,
    /// Final minimum Verdict scaled Jacobian.
    pub min_scaled_jacobian: f64,
    /// Final 5th percentile of the scaled Jacobian.
    pub p5_scaled_jacobian: f64,
    /// Iterations of A and B together.
    pub iterations: usize,
    /// Wall time of A and B together, seconds.
    pub seconds: f64,
    /// Perturbation amplitude applied before the run (0 if none; informational, set by the
    /// caller).
    pub perturbation: f64,
    /// Seed of the perturbation.
    pub seed: u64,
    /// Corner / edge / face / interior cell counts.
    pub classes: ClassCounts,
    /// Number of fixed tetrahedra and the smallest `V` among them (admissibility, Def. 11).
    pub fixed_tets: (usize, f64),
    /// Appendix A counts (sizes ≥ 4 only).
    pub counting: Option<PlanarityCounts>,
    /// The start.
    pub start: HexMeasures,
    /// After Algorithm A.
    pub after_a: Option<HexMeasures>,
    /// After Algorithm B.
    pub after_b: Option<HexMeasures>,
    /// Algorithm A.
    pub algorithm_a: Option<PhaseStats>,
    /// Algorithm B (absent if not asked or A did not reach convexity).
    pub algorithm_b: Option<PhaseStats>,
    /// Histograms of the final mesh.
    pub histograms: HexHistograms,
    /// The harmonic energy of the final mesh under the readings of the thesis's
    /// normalisation ([`unamalla_functionals::energy_variants`], same Jacobian scaling as the
    /// run): `printed` is (3.27) at `ω → 0`, the value Algorithm A's `f` tends to;
    /// `per_decomposition = 2·printed` is the reading that matches the thesis's sphere
    /// (§3.4.3, `f = 2.26543`; see the "energy values" section of `docs/results.md`).
    #[serde(default)]
    pub energy: Option<unamalla_functionals::EnergyVariants>,
    /// Options used.
    pub options: HexRunOptions,
}

impl HexRunReport {
    /// Pretty JSON.
    pub fn to_json(&self) -> String {
        // plain numbers (all finite), strings, vectors: cannot fail
        serde_json::to_string_pretty(self).unwrap_or_default()
    }
}

/// Per-cell metrics and the stage measures of a grid.
fn measure(
    grid: &StructuredGrid3,
    classes: &[CellClass],
    eps: f64,
    tol: f64,
    vol_tol: f64,
) -> (HexMeasures, Vec<HexMetrics>) {
    let per_cell = hex_metrics_per_cell(grid);
    let n = per_cell.len().max(1);
    let vbar = per_cell
        .iter()
        .map(|c| c.tet_dets.iter().sum::<f64>())
        .sum::<f64>()
        / (10 * n) as f64;
    let thr = eps * vbar;
    let mut m = HexMeasures {
        non_convex_cells: 0,
        eps,
        non_hex_interior_cells: 0,
        non_planar_interior_faces: 0,
        max_abs_cos: 0.0,
        non_hex_interior_cells_volume: 0,
        max_face_volume: 0.0,
        min_abs_cos: 0.0,
        max_abs_cos_all: 0.0,
        min_tet_volume: f64::INFINITY,
        max_tet_volume: f64::NEG_INFINITY,
        min_scaled_jacobian: 0.0,
        p5_scaled_jacobian: 0.0,
    };
    let mut min_cos = f64::INFINITY;
    for (c, cm) in per_cell.iter().enumerate() {
        if !cm.tet_dets.iter().all(|&v| v > thr) {
            m.non_convex_cells += 1;
        }
        for &v in &cm.tet_dets {
            m.min_tet_volume = m.min_tet_volume.min(v / 6.0);
            m.max_tet_volume = m.max_tet_volume.max(v / 6.0);
        }
        m.max_abs_cos_all = m.max_abs_cos_all.max(cm.max_face_cos());
        if classes[c] == CellClass::Interior {
            let bad = cm.face_cos.iter().filter(|&&k| k >= tol).count();
            m.non_planar_interior_faces += bad;
            m.non_hex_interior_cells += (bad > 0) as usize;
            for &k in &cm.face_cos {
                m.max_abs_cos = m.max_abs_cos.max(k);
                min_cos = min_cos.min(k);
            }
            m.non_hex_interior_cells_volume += cm.face_vol.iter().any(|&v| v >= vol_tol) as usize;
            m.max_face_volume = cm.face_vol.iter().fold(m.max_face_volume, |a, &v| a.max(v));
        }
    }
    if min_cos.is_finite() {
        m.min_abs_cos = min_cos;
    }
    if per_cell.is_empty() {
        (m.min_tet_volume, m.max_tet_volume) = (0.0, 0.0);
    }
    let sj: Vec<f64> = per_cell.iter().map(|c| c.scaled_jacobian).collect();
    if let Some(s) = MetricSummary::new("scaled_jacobian", &sj) {
        m.min_scaled_jacobian = s.min;
        m.p5_scaled_jacobian = s.p5;
    }
    (m, per_cell)
}

fn histograms(
    grid: &StructuredGrid3,
    classes: &[CellClass],
    per_cell: &[HexMetrics],
    tol: f64,
    bins: usize,
) -> HexHistograms {
    let (mut pos, mut zero, mut neg) = (0, 0, 0);
    let mut dec = [0usize; 8];
    let (mut planar, mut non_planar) = (0, 0);
    let (mut heights, mut areas) = (Vec::new(), Vec::new());
    for (c, cm) in per_cell.iter().enumerate() {
        for &v in &cm.tet_dets {
            if v > 0.0 {
                pos += 1;
            } else if v < 0.0 {
                neg += 1;
            } else {
                zero += 1;
            }
        }
        if classes[c] == CellClass::Interior {
            let h = grid.hex_points(c);
            for f in unamalla_mesh::quality::PLANARITY_FACES {
                let (fh, fa) =
                    unamalla_mesh::quality::face_height_area([h[f[0]], h[f[1]], h[f[2]], h[f[3]]]);
                heights.push(fh);
                areas.push(fa);
            }
            for &k in &cm.face_cos {
                let b = if k <= 0.0 {
                    0
                } else {
                    ((k.log10() + 7.0).floor().max(0.0) as usize).min(7)
                };
                dec[b] += 1;
                if k < tol {
                    planar += 1;
                } else {
                    non_planar += 1;
                }
            }
        }
    }
    let labels: Vec<String> = ["<1e-6", "1e-6", "1e-5", "1e-4", "1e-3", "1e-2", ">=1e-1"]
        .iter()
        .map(|l| l.to_string())
        .collect();
    // merge bins 6 and 7 (|cos| ≥ 0.1) into the last label
    let mut d7 = dec[..6].to_vec();
    d7.push(dec[6] + dec[7]);
    let (m, n, p) = grid.dims();
    let mut lens = Vec::with_capacity(3 * m * n * p);
    for k in 0..p {
        for j in 0..n {
            for i in 0..m {
                let q = grid.node(i, j, k);
                if i + 1 < m {
                    lens.push(q.distance(grid.node(i + 1, j, k)));
                }
                if j + 1 < n {
                    lens.push(q.distance(grid.node(i, j + 1, k)));
                }
                if k + 1 < p {
                    lens.push(q.distance(grid.node(i, j, k + 1)));
                }
            }
        }
    }
    HexHistograms {
        tets_positive: pos,
        tets_zero: zero,
        tets_negative: neg,
        face_cos_decades: d7,
        face_cos_labels: labels,
        faces_planar: planar,
        faces_non_planar: non_planar,
        edge_lengths: Histogram::equal(&lens, bins),
        face_min_heights: Histogram::equal(&heights, bins),
        face_min_areas: Histogram::equal(&areas, bins),
    }
}

fn phase(rep: &SmoothReport, iterations: usize, seconds: f64) -> PhaseStats {
    PhaseStats {
        iterations,
        continuation_steps: rep.continuation_steps,
        seconds,
        status: rep.status.to_string(),
        omega: rep.omega,
        mu: rep.mu,
        f: rep.f,
        gnorm: rep.gnorm,
    }
}

/// Runs Algorithm A (and B if asked and A reached convexity) on `grid` in place, with the
/// boundary nodes fixed, and returns the report. The start must be admissible.
pub fn run_hex(
    grid: &mut StructuredGrid3,
    opts: &HexRunOptions,
    observer: &mut dyn Observer,
) -> Result<HexRunReport, HexError> {
    let dims = grid.dims();
    let classes = classify_cells(grid);
    let adm = admissibility(grid);
    if let Some(v) = adm.violations.first() {
        return Err(HexError::Inadmissible {
            cell: v.cell,
            tet: v.tet,
            v: v.v,
            count: adm.violations.len(),
        });
    }
    let eps = opts.omega.eps;
    let tol = opts.planarity_tol;
    let vol_tol = opts.planarity_volume_tol;
    let (start, _) = measure(grid, &classes, eps, tol, vol_tol);
    let scaling = match opts.scaling {
        HexScaling::Index => Scaling3::Index,
        HexScaling::Parametric => Scaling3::Parametric {
            m: dims.0,
            n: dims.1,
            p: dims.2,
        },
    };
    let topo = Arc::new(HexTopology::from_mesh(&*grid)?);
    let mut x = topo.initial_x();
    let probe = unamalla_functionals::HexFunctional::h_omega(topo.clone(), 1.0, scaling)?;
    let mut session = Session::new(&probe, &x, observer);
    let t0 = Instant::now();
    let ra = omega_continuation_hex(&topo, scaling, &mut x, &opts.omega, &mut session)?;
    let ta = t0.elapsed().as_secs_f64();
    let it_a = ra.iterations();
    topo.scatter(&x, grid.nodes_mut());
    let (after_a, _) = measure(grid, &classes, eps, tol, vol_tol);
    let mut algorithm_b = None;
    let mut after_b = None;
    let mut seconds = ta;
    let mut iterations = it_a;
    if opts.algorithm == HexAlgorithm::AB && ra.convex && ra.status.convex() == Some(true) {
        let t1 = Instant::now();
        let rb = coplanarity_continuation(&topo, scaling, &mut x, &opts.coplanarity, &mut session)?;
        let tb = t1.elapsed().as_secs_f64();
        let it_b = rb.iterations().saturating_sub(it_a);
        topo.scatter(&x, grid.nodes_mut());
        after_b = Some(measure(grid, &classes, eps, tol, vol_tol).0);
        algorithm_b = Some(phase(&rb, it_b, tb));
        seconds += tb;
        iterations += it_b;
    }
    let (fin, per_cell) = measure(grid, &classes, eps, tol, vol_tol);
    let hist = histograms(grid, &classes, &per_cell, tol, opts.histogram_bins);
    let cells: Vec<[DVec3; 8]> = (0..grid.num_hexes()).map(|c| grid.hex_points(c)).collect();
    let energy = unamalla_functionals::energy_variants(&cells, scaling).ok();
    Ok(HexRunReport {
        case: String::new(),
        dims,
        cells: grid.num_cells(),
        interior_cells: classes
            .iter()
            .filter(|c| **c == CellClass::Interior)
            .count(),
        non_convex_cells: fin.non_convex_cells,
        non_hex_interior_cells: fin.non_hex_interior_cells,
        max_abs_cos: fin.max_abs_cos,
        min_tet_volume: fin.min_tet_volume,
        max_tet_volume: fin.max_tet_volume,
        min_scaled_jacobian: fin.min_scaled_jacobian,
        p5_scaled_jacobian: fin.p5_scaled_jacobian,
        iterations,
        seconds,
        perturbation: 0.0,
        seed: 0,
        classes: class_counts(&classes),
        fixed_tets: (
            adm.fixed_tets,
            if adm.fixed_tets > 0 {
                adm.min_fixed_v
            } else {
                0.0
            },
        ),
        counting: planarity_counts(dims.0, dims.1, dims.2).ok(),
        start,
        after_a: Some(after_a),
        after_b,
        algorithm_a: Some(phase(&ra, it_a, ta)),
        algorithm_b,
        histograms: hist,
        energy,
        options: opts.clone(),
    })
}

/// An SVG with three bar charts of the histograms (App. B.6): tetrahedron volume sign,
/// interior-face planarity by `|cos|` decade (bars at or above the tolerance in red), and
/// edge lengths.
pub fn histograms_svg(h: &HexHistograms, title: &str) -> String {
    // world units: three panels of 10 × 6 side by side, y up
    let mut c = SvgCanvas::new(DVec2::new(0.0, -1.5), DVec2::new(33.0, 8.0), 990.0);
    c.text(DVec2::new(16.5, 7.5), title, 16.0, "#000000");
    let panel = |c: &mut SvgCanvas, x0: f64, name: &str, bars: &[(String, usize, &str)]| {
        let maxc = bars.iter().map(|b| b.1).max().unwrap_or(0).max(1) as f64;
        let w = 10.0 / bars.len().max(1) as f64;
        c.polyline(
            &[
                DVec2::new(x0, 6.0),
                DVec2::new(x0, 0.0),
                DVec2::new(x0 + 10.0, 0.0),
            ],
            &Style::stroke("#000000", 1.0),
        );
        c.text(DVec2::new(x0 + 5.0, 6.6), name, 13.0, "#000000");
        for (k, (label, count, color)) in bars.iter().enumerate() {
            let hgt = 5.5 * *count as f64 / maxc;
            let xl = x0 + k as f64 * w + 0.1 * w;
            let xr = x0 + (k + 1) as f64 * w - 0.1 * w;
            if *count > 0 {
                c.polygon(
                    &[
                        DVec2::new(xl, 0.0),
                        DVec2::new(xr, 0.0),
                        DVec2::new(xr, hgt),
                        DVec2::new(xl, hgt),
                    ],
                    &Style::fill(color),
                );
            }
            c.text(
                DVec2::new(0.5 * (xl + xr), hgt + 0.3),
                &count.to_string(),
                9.0,
                "#333333",
            );
            c.text(DVec2::new(0.5 * (xl + xr), -0.5), label, 9.0, "#333333");
        }
    };
    panel(
        &mut c,
        0.5,
        "tetrahedra: sign of V",
        &[
            ("V>0".into(), h.tets_positive, "#1f77b4"),
            ("V=0".into(), h.tets_zero, "#ff7f0e"),
            ("V<0".into(), h.tets_negative, "#d62728"),
        ],
    );
    let dec: Vec<(String, usize, &str)> = h
        .face_cos_decades
        .iter()
        .zip(&h.face_cos_labels)
        .enumerate()
        .map(|(k, (n, l))| (l.clone(), *n, if k >= 5 { "#d62728" } else { "#1f77b4" }))
        .collect();
    panel(&mut c, 11.5, "interior faces: |cos| decade", &dec);
    let el = &h.edge_lengths;
    let bars: Vec<(String, usize, &str)> = el
        .counts
        .iter()
        .enumerate()
        .map(|(k, n)| {
            let label = if k == 0 || k + 1 == el.counts.len() {
                format!("{:.3}", el.edges[k.min(el.edges.len() - 1)])
            } else {
                String::new()
            };
            (label, *n, "#2ca02c")
        })
        .collect();
    panel(&mut c, 22.5, "edge lengths", &bars);
    c.finish()
}

/// Files written by [`write_outputs`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HexOutputFiles {
    /// `mesh.vts` (structured grid with per-cell quality).
    pub vts: PathBuf,
    /// `mesh.vtu` (unstructured hexahedra with per-cell quality).
    pub vtu: PathBuf,
    /// `report.json`.
    pub report: PathBuf,
    /// `histograms.svg`.
    pub svg: PathBuf,
}

/// Writes `mesh.vts`, `mesh.vtu` (both with the per-cell Verdict metrics, `min_tet_det`,
/// `convex_10tet`, `max_face_cos` and the cell class 0 corner / 1 edge / 2 face /
/// 3 interior / 4 other), `report.json` and `histograms.svg` into `dir` (created if
/// missing). Every file is written atomically.
pub fn write_outputs(
    dir: &Path,
    grid: &StructuredGrid3,
    report: &HexRunReport,
) -> Result<HexOutputFiles, HexError> {
    std::fs::create_dir_all(dir).map_err(|e| HexError::FaceFile {
        path: dir.to_path_buf(),
        line: 0,
        reason: format!("cannot create the output directory: {e}"),
    })?;
    let mut cols = unamalla_mesh::quality::hex_cell_metrics(grid);
    let cls: Vec<f64> = classify_cells(grid)
        .iter()
        .map(|c| match c {
            CellClass::Corner => 0.0,
            CellClass::Edge => 1.0,
            CellClass::Face => 2.0,
            CellClass::Interior => 3.0,
            CellClass::Other(_) => 4.0,
        })
        .collect();
    cols.push(("cell_class", cls));
    let data: Vec<(&str, &[f64])> = cols.iter().map(|(k, v)| (*k, v.as_slice())).collect();
    let files = HexOutputFiles {
        vts: dir.join("mesh.vts"),
        vtu: dir.join("mesh.vtu"),
        report: dir.join("report.json"),
        svg: dir.join("histograms.svg"),
    };
    unamalla_io::write_vts3(&files.vts, grid, &data)?;
    unamalla_io::write_vtu_hexes(&files.vtu, &HexMesh::from_grid(grid), &data)?;
    let json = report.to_json();
    unamalla_io::atomic_write(&files.report, |w| w.write_all(json.as_bytes()))?;
    let title = format!(
        "{} {}x{}x{}: non-convex {}, non-hex interior {}, max |cos| {:.2e}",
        report.case,
        report.dims.0,
        report.dims.1,
        report.dims.2,
        report.non_convex_cells,
        report.non_hex_interior_cells,
        report.max_abs_cos
    );
    let svg = histograms_svg(&report.histograms, &title);
    unamalla_io::atomic_write(&files.svg, |w| w.write_all(svg.as_bytes()))?;
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;
    use unamalla_mesh::hexgen::{admissibility, classify_cells};
    use unamalla_mesh::HasHexCells;
    use unamalla_optim::NullObserver;

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

    #[test]
    fn face_files_round_trip_and_bad_files_name_the_line() {
        let g = HexCase::Cosin.initial_grid((4, 5, 6)).unwrap();
        let r = HexRegion::of_grid(&g);
        let dir = std::env::temp_dir().join(format!("unamalla-hexfaces-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write_face_dir(&r, &dir).unwrap();
        let back = read_face_dir(&dir).unwrap();
        assert_eq!(back.dims(), (4, 5, 6));
        let t = back.tfi().unwrap();
        assert!(t
            .nodes()
            .iter()
            .zip(g.nodes())
            .all(|(a, b)| a.distance(*b) < 1e-9));
        let e = parse_face_grid(Path::new("f.txt"), "# c\n2 2\n0 0 0\n1 0 x\n").unwrap_err();
        assert!(e.to_string().contains("f.txt: line 4"), "{e}");
        let e = parse_face_grid(Path::new("f.txt"), "2 2\n0 0 0\n").unwrap_err();
        assert!(e.to_string().contains("needs 4 points, found 1"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn histograms_count_every_tet_face_and_edge() {
        let mut g = HexCase::Box.initial_grid((5, 5, 5)).unwrap();
        let opts = HexRunOptions {
            algorithm: HexAlgorithm::A,
            ..HexRunOptions::default()
        };
        let r = run_hex(&mut g, &opts, &mut NullObserver).unwrap();
        let h = &r.histograms;
        assert_eq!(h.tets_positive + h.tets_zero + h.tets_negative, 10 * 64);
        // interior cells of 5³: 2³ = 8, 6 faces each
        assert_eq!(r.interior_cells, 8);
        assert_eq!(h.faces_planar + h.faces_non_planar, 48);
        assert_eq!(h.face_cos_decades.iter().sum::<usize>(), 48);
        // edges of a 5³ grid: 3·4·5·5
        assert_eq!(h.edge_lengths.counts.iter().sum::<usize>(), 300);
        let svg = histograms_svg(h, "box");
        assert!(svg.starts_with("<svg") && svg.contains("edge lengths"));
    }

    #[test]
    fn algorithm_a_turns_the_perturbed_sphere_20_convex() {
        // the thesis's Esfera: 20³, perturbed to ≥ 22 non-convex cells (digest §3.4.3)
        let case = HexCase::Sphere;
        let dims = case.default_size();
        let mut g = case.initial_grid(dims).unwrap();
        let (_, nc0) = case.default_perturbation(dims).apply(&mut g, 1).unwrap();
        assert!(nc0 >= 22, "{nc0}");
        let opts = HexRunOptions {
            algorithm: HexAlgorithm::A,
            ..HexRunOptions::default()
        };
        let r = run_hex(&mut g, &opts, &mut NullObserver).unwrap();
        assert!(r.start.non_convex_cells >= 22);
        assert_eq!(r.non_convex_cells, 0);
        assert!(r.min_tet_volume > 0.0);
        assert!(r.after_b.is_none());
        // the energy values (Cortés Aguirre 2012 §3.4.3: the sphere starts at f = 0.0261538
        // with ω = 200 and ends "harmonic and convex" at ω = 10⁻⁸ with f = 2.26543)
        let e = r.energy.expect("energy of the final mesh");
        let fa = r.algorithm_a.as_ref().expect("A ran").f;
        assert_eq!(e.non_positive, 0);
        // E ≥ 1 per tetrahedron (AM–GM), and A's f is H_ω at its last ω, below the energy
        // (the tangent continuation lies under 1/V): the two numbers must not be confused
        assert!(e.printed > 1.0 && fa < e.printed, "{fa} {e:?}");
        assert!((e.per_decomposition - 2.0 * e.printed).abs() < 1e-12);
        // E is scale-free and the parametric factors are equal for m = n = p: the Jacobian
        // scaling cannot explain a different value on the sphere
        let cells: Vec<[DVec3; 8]> = (0..g.num_hexes()).map(|c| g.hex_points(c)).collect();
        let idx = unamalla_functionals::energy_variants(&cells, Scaling3::Index).unwrap();
        assert!((idx.printed - e.printed).abs() < 1e-9 * e.printed);
        // none of the readings of the normalisation reaches the thesis's value (docs/results.md,
        // "energy values": the closest, volume weights and the per-decomposition sum, are 8–10 %
        // above it, the printed (3.27) 45 % below)
        let thesis = 2.26543;
        for v in [
            e.printed,
            e.per_decomposition,
            e.volume_weighted,
            e.interior_raw,
        ] {
            assert!((v - thesis).abs() > 0.05 * thesis, "{v} vs {thesis}");
        }
        // the thesis's start value is below what (3.27) allows at ω = 200 with parametric
        // scaling: λ ≥ V per tetrahedron (Hadamard + AM–GM), so
        // H_200 ≥ (1/10N_c) Σ V(2ω − V)/ω², V = (m−1)³·(the thesis's tet Jacobian)
        let mut g0 = case.initial_grid(dims).unwrap();
        case.default_perturbation(dims).apply(&mut g0, 1).unwrap();
        let scale = 19f64.powi(3);
        let (w, mut bound) = (200.0, 0.0);
        for c in 0..g0.num_hexes() {
            for v in unamalla_mesh::quality::hex_tet_jacobians(&g0.hex_points(c)) {
                let v = v * scale;
                bound += v * (2.0 * w - v) / (w * w);
            }
        }
        bound /= 10.0 * g0.num_hexes() as f64;
        assert!(bound > 1.5 * 0.0261538, "bound {bound}");
        // boundary nodes did not move: still on the unit sphere
        for k in [0, 19] {
            for j in 0..20 {
                for i in 0..20 {
                    assert!((g.node(i, j, k).length() - 1.0).abs() < 1e-14);
                }
            }
        }
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

    #[test]
    fn the_ellipsoid_20_start_has_at_least_20_non_convex_cells() {
        let case = HexCase::Ellipsoid;
        let dims = case.default_size();
        let mut g = case.initial_grid(dims).unwrap();
        let (amp, nc0) = case.default_perturbation(dims).apply(&mut g, 1).unwrap();
        assert!(nc0 >= 45 && amp > 0.0, "{amp} {nc0}");
        assert!(admissibility(&g).is_admissible());
    }

    #[test]
    fn algorithm_b_makes_every_interior_face_of_the_box_planar() {
        // chapter 4: the 5³ harmonic convex mesh has non-planar cells; B fixes the interior ones
        let mut g = HexCase::Box.initial_grid((5, 5, 5)).unwrap();
        let r = run_hex(&mut g, &HexRunOptions::default(), &mut NullObserver).unwrap();
        let a = r.after_a.as_ref().unwrap();
        assert_eq!(a.non_convex_cells, 0);
        assert_eq!(
            a.non_hex_interior_cells, 8,
            "A alone leaves the interior cells non-planar"
        );
        assert!(r.algorithm_b.is_some());
        assert_eq!(r.non_convex_cells, 0);
        assert_eq!(r.non_hex_interior_cells, 0);
        // every face of every interior cell, checked directly
        let cls = classify_cells(&g);
        for (c, cl) in cls.iter().enumerate() {
            if *cl == CellClass::Interior {
                let h = g.hex_points(c);
                assert!(
                    unamalla_mesh::quality::max_face_cosine(&h) < 1e-2,
                    "cell {c}"
                );
            }
        }
        assert!(r.max_abs_cos < 1e-2);
    }

    #[test]
    fn default_b_schedule_stops_once_planar_and_beats_the_thesis_schedule() {
        // Pico-like 10³ (seed 1): the default schedule (μ₀ = 500, planarity stop at
        // |cos| ≤ 10⁻³) must end with every interior face planar and convex, and stop after
        // at most 6 μ steps (measured: 5, μ = 500 … 0.05), while the thesis's schedule always
        // runs its 12 steps (0.1 → 10⁻¹²: floating-point 0.1¹² is just above 10⁻¹²).
        let dims = (10, 10, 10);
        let run = |co: CoplanarityOptions| {
            let mut g = HexCase::Pico.initial_grid(dims).unwrap();
            HexCase::Pico
                .default_perturbation(dims)
                .apply(&mut g, 1)
                .unwrap();
            let mut o = HexRunOptions::default();
            o.coplanarity = CoplanarityOptions {
                solver: o.coplanarity.solver.clone(),
                ..co
            };
            run_hex(&mut g, &o, &mut NullObserver).unwrap()
        };
        let d = run(HexRunOptions::default().coplanarity);
        let b = d.algorithm_b.as_ref().unwrap();
        assert_eq!(d.non_convex_cells, 0);
        assert_eq!(d.non_hex_interior_cells, 0);
        assert!(d.max_abs_cos <= 1e-3, "max|cos| {}", d.max_abs_cos);
        assert!(b.continuation_steps <= 6, "{} steps", b.continuation_steps);
        // the run says why it ended (it used to read "STOP by MAXITER condition")
        assert_eq!(b.status, "Convex grid, STOP by PLANARITY condition");
        let t = run(CoplanarityOptions::thesis());
        assert_ne!(
            t.algorithm_b.as_ref().unwrap().status,
            "Convex grid, STOP by PLANARITY condition"
        );
        assert_eq!(t.algorithm_b.as_ref().unwrap().continuation_steps, 12);
        assert!(b.iterations < t.algorithm_b.as_ref().unwrap().iterations);
    }

    /// Issue #10 regression: the Pico-like 21³ case (seed 1) stalled with the thesis's
    /// schedule (every μ step at its 50-iteration limit, 12 non-hexahedral and 16
    /// non-ε-convex cells left); the default schedule must finish it (measured: 172 B
    /// iterations, 6 μ steps). ≈ 1 min: `cargo test -p unamalla-core --release --lib hex --
    /// --ignored pico_21`.
    #[test]
    #[ignore]
    fn default_b_schedule_finishes_pico_21() {
        let dims = (21, 21, 21);
        let mut g = HexCase::Pico.initial_grid(dims).unwrap();
        HexCase::Pico
            .default_perturbation(dims)
            .apply(&mut g, 1)
            .unwrap();
        let r = run_hex(&mut g, &HexRunOptions::default(), &mut NullObserver).unwrap();
        assert_eq!(r.non_convex_cells, 0);
        assert_eq!(r.non_hex_interior_cells, 0);
    }

    /// Slow under load: `cargo test -p unamalla-core --release --lib hex -- --ignored`.
    /// Every built-in case at its thesis size (Pico at 10³; Pico 21³ is
    /// `default_b_schedule_finishes_pico_21`) ends convex and, with the default B schedule,
    /// with every interior face planar — except `sydney`, a known failure (Algorithm A
    /// stops at once with 114 non-convex cells: its rim layers are 0.007 thick against 0.9 at
    /// the centre; docs/results.md).
    #[test]
    #[ignore]
    fn every_case_at_its_thesis_size_ends_convex() {
        for case in HexCase::ALL.into_iter().filter(|c| *c != HexCase::Sydney) {
            let dims = case.default_size();
            let mut g = case.initial_grid(dims).unwrap();
            case.default_perturbation(dims).apply(&mut g, 1).unwrap();
            let r = run_hex(&mut g, &HexRunOptions::default(), &mut NullObserver).unwrap();
            assert_eq!(r.non_convex_cells, 0, "{case}");
            assert_eq!(r.non_hex_interior_cells, 0, "{case}");
        }
    }
}
