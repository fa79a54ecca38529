//! Generators of structured hexahedral meshes on logically hexahedral regions
//! ([Cortés Aguirre 2012, Ch. 2–3, Appendix A]; the references are listed in
//! `docs/references.md` of the repository; the section numbers below are the thesis's).
//!
//! * [`region`]: a region from six structured face grids with compatibility checks
//!   (opposite faces of equal size, shared edges coincident; Def. 6), and its initial mesh by
//!   3D TFI ([`tfi3`](crate::tfi3), §2.2.1);
//! * [`radial`]: the radial map `x ↦ x·‖x‖∞/‖x‖₂` of the cube onto the ball and, scaled, onto
//!   an ellipsoid (§2.1.1; the thesis does not print the formula, ours is in the module);
//! * [`extrude`]: a 2D mesh projected onto a plane or `z = f(x, y)` and extruded with a list
//!   of layer thicknesses, or interpolated between a base and a top surface (§2.2.2);
//! * [`shepard`]: Shepard interpolation of scattered `(x, y, z)` data for those surfaces
//!   (§2.2.3);
//! * [`perturb`]: seeded random interior perturbation (folded starts);
//! * [`classify`]: corner / edge / face / interior cells and the admissibility check
//!   (fixed tetrahedra positive, §3.3 Def. 11);
//! * [`counting`]: appendix A (variables vs planarity constraints, Theorems A.1–A.4).
//!
//! The quality measures of the resulting meshes (10-tetrahedra convexity test, face
//! planarity `|cos|`, Verdict metrics) are in [`crate::quality`]; the optimisation
//! (Algorithms A and B) is in `unamalla-optim`; the hexahedral product built on both (built-in
//! regions, face-grid files, runs, reports) is the crate `unamalla-hex`.

pub mod classify;
pub mod counting;
pub mod error;
pub mod extrude;
pub mod perturb;
pub mod radial;
pub mod region;
pub mod shepard;

pub use classify::{
    admissibility, class_counts, classify_cells, Admissibility, CellClass, ClassCounts,
    FixedTetViolation,
};
pub use counting::{planarity_counts, PlanarityCounts};
pub use error::HexGenError;
pub use extrude::{extrude_grid, extrude_mesh, Anchor, Extrusion, HeightField, Plane};
pub use perturb::{
    perturb_interior, perturb_until_nonconvex, shortest_edges, SplitMix64, HEX_EDGES,
};
pub use radial::{ball_grid, cube_to_ball, ellipsoid_grid};
pub use region::{FaceGrid, HexFaceId, HexRegion, EDGE_TOLERANCE};
pub use shepard::{NodalFunction, Shepard, ShepardKind};
