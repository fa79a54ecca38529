//! # unamalla-hex
//!
//! Structured hexahedral meshes on logically hexahedral regions ([Cortés Aguirre 2012]; the
//! references are listed in `docs/references.md` of the repository): built-in test regions, initial
//! meshes, Algorithm A (convex harmonic) and Algorithm B (planar faces), the run report and the
//! output files.
//!
//! # Pipeline (section, table and definition numbers are the thesis's)
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
//!    [`CoplanarityOptions::thesis`](unamalla_optim::drivers::CoplanarityOptions::thesis); the
//!    choice is explained on
//!    [`coplanarity_continuation`](unamalla_optim::drivers::coplanarity_continuation)); the
//!    convexity safeguard keeps the mesh convex;
//! 6. **report** ([`HexRunReport`], the measures of §3.2.1 and §4.1 and the information panel
//!    of §B.3): non-convex cells
//!    (10-tetrahedra test with ε), non-hexahedral interior cells (some face with
//!    `|cos| ≥ 10⁻²`, criterion 2 of §4.1), max `|cos|`, min/max tetrahedron volume, Verdict
//!    scaled Jacobian min/p5, iterations, time, and the histograms of App. B.6 (tetrahedron
//!    volume sign, face planarity, edge lengths) as data and as an SVG plot
//!    ([`histograms_svg`]).
//!
//! # Built-in regions ([`HexCase`], [Cortés Aguirre 2012, §3.4.1, Table 3.1])
//! `sphere` and `ellipsoid` (semi-axes 0.5, 1, 0.5) and the chapter 4 `box` are the thesis's
//! exactly reconstructible regions. `pico`, `cosin`, `shell` and `parabs` are **analytic
//! stand-ins** with the thesis's bounding boxes: the thesis does not give their surfaces
//! (§3.4.1 describes them in words and gives their domains); each variant's documentation gives
//! the formula used.
//! `elipsoideg`, `yacimiento` and `sydney` (Cortés Aguirre 2012, Table 3.1) are
//! reconstructions too: the thesis gives their domains and constructions, not every surface or
//! datum, and each variant's documentation says what is ours.
//!
//! # Layout
//! | file | holds |
//! |---|---|
//! | `cases.rs` | [`HexCase`]: the built-in regions and their initial meshes |
//! | `face_grid.rs` | the face-grid text format: [`read_face_dir`], [`parse_face_grid`], [`write_face_dir`] |
//! | `run.rs` | [`Perturbation`], [`HexRunOptions`], [`run_hex`] (admissibility, Algorithms A and B) |
//! | `report.rs` | [`HexRunReport`]: stage measures, phase statistics, histograms as data |
//! | `output.rs` | [`write_outputs`] (VTK, `report.json`) and [`histograms_svg`] |
//! | `error.rs` | [`HexError`] |
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
// outside tests (docs/reliability.md, section 3)
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

mod cases;
mod error;
mod face_grid;
mod output;
mod report;
mod run;

pub use cases::{yacimiento_data, yacimiento_plan, HexCase};
pub use error::HexError;
pub use face_grid::{parse_face_grid, read_face_dir, write_face_dir};
pub use output::{histograms_svg, write_outputs, HexOutputFiles};
pub use report::{HexHistograms, HexMeasures, HexRunReport, Histogram, PhaseStats};
pub use run::{run_hex, HexAlgorithm, HexRunOptions, HexScaling, Perturbation};
