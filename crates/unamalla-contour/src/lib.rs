//! # unamalla-contour
//!
//! Step 1 of the unamalla pipeline: **contour approximation** — simplification and noise
//! reduction of the rings of a planar region with holes ([Méndez 2023, Ch. 3]; the references
//! are listed in `docs/references.md` of the repository). Real regions arrive with thousands of noisy vertices;
//! this crate returns polygons that keep the shape with far fewer points, so that
//! decomposition and meshing are well conditioned.
//!
//! ```
//! use unamalla_contour::{simplify_region, Method, SimplifyOptions, Preset};
//! use unamalla_mesh::{DVec2, Region};
//!
//! // a square whose sides carry collinear points: all of them go, the corners stay
//! let mut ring = Vec::new();
//! for k in 0..10 { ring.push(DVec2::new(k as f64, 0.0)); }
//! for k in 0..10 { ring.push(DVec2::new(10.0, k as f64)); }
//! for k in 0..10 { ring.push(DVec2::new(10.0 - k as f64, 10.0)); }
//! for k in 0..10 { ring.push(DVec2::new(0.0, 10.0 - k as f64)); }
//! let region = Region::new(ring, vec![]).unwrap();
//! let opts = SimplifyOptions::new("modified-areas".parse().unwrap(), Preset::Clean);
//! let res = simplify_region(&region, &opts).unwrap();
//! assert_eq!(res.region.outer().len(), 4);
//! assert_eq!(res.relative_area_change, 0.0);
//! ```
//!
//! ## Formulas and sources
//!
//! For vertex `v_i` with neighbours `v_{i−1}`, `v_{i+1}` (cyclic) the triangle
//! `T_i = (v_{i−1}, v_i, v_{i+1})` has doubled area `α_i`, interior angle `θ_i` at `v_i`,
//! inradius `r_i`, circumradius `R_i`, side lengths `ℓ₁, ℓ₂, ℓ₃` (see [`criteria`]).
//!
//! | method | rule | source |
//! |---|---|---|
//! | scaled Visvalingam | remove argmin `a_i` while `a_i < ε · ā`, one per step, `ā` of the input ring | [Méndez 2023, §3.1.1], Obs 3.1 |
//! | areas | remove all `v_i` with `ζ_i / ā < 2ε`, `ζ_i = α_i |sin θ_i|`; repeat | §3.3.1, eqs. (3.3)–(3.5) |
//! | radii | remove all `v_i` with `r_i / R_i < ρ`; repeat | §3.3.2 |
//! | modified areas | remove `j = argmin ζ_i` while `ζ_j < ᾱ ε`, `ᾱ` of the input ring | §3.3.4, eq. (3.6) |
//! | modified radii | same with `ρ_i = 2 r_i R_i |sin θ_i| = ℓ₁ℓ₂ℓ₃/(ℓ₁+ℓ₂+ℓ₃) · |sin θ_i|` | §3.3.4, eqs. (3.7), (3.8) (the thesis prints `sin`; we use `|sin θ_i|`) |
//! | minimum-perimeter polygon | `min Σ|u_{i+1} − u_i|` s.t. `‖u_i − v_i‖_∞ ≤ p₀ δ` | §3.2.2, eq. (3.2) (convex but not smooth, not quadratic as the thesis says); [`mpp`] |
//! | three-step | areas (ε = 1e-4) → MPP (δ) → radii (ρ) | §3.3.3 (Example 3.5's "ρ = 10⁻³" is the MPP factor δ) |
//! | modified three-step | modified areas (ε = 0.1) → MPP (δ) → modified areas (ε) | §3.3.4 |
//! | noise detection | sorted profile `log10(a_σ(i)/a_σ(1))` + jump detector | §3.2.1, eq. (3.1) (normalized by the largest area; the chapter summary's "average" only shifts the log profile); [`noise`] |
//!
//! `ā`/`ᾱ` is the mean triangle **area** `(1/n) Σ |α_i|/2`. The batch criteria (areas,
//! radii) evaluate every vertex of the current ring, delete all that satisfy the criterion, and
//! repeat until a pass deletes nothing (Obs 3.3), recomputing `ā` each pass. The sequential
//! methods (Visvalingam, modified areas/radii) take the vertex of smallest key (ties: lowest
//! index) from a priority queue — the initial keys sorted once plus an indexed 4-ary heap of
//! recomputed keys — and recompute only the two neighbours of a removed vertex: O(n log n). In the
//! modified three-step method both removal steps use `ᾱ` of the **input** ring, the "initial
//! polygon" of (3.6). Rings are simplified separately, outer ring first, then each hole
//! (Obs 3.3, Obs 3.5). Default thresholds: [`Method`] (table there).
//!
//! ## Topology safety
//!
//! Beyond the thesis, no method returns a ring that self-intersects or touches another ring:
//! a vertex `b` (neighbours `a`, `c`) is removed only if no other live vertex of **any** ring
//! lies in the closed triangle `abc` (`orient2d` with an inlined floating-point filter and the
//! exact predicate as fallback), queried in a flat hashed bucket grid of the live vertices of
//! all rings; a removal that fails the test is skipped (and retried in a few later
//! rounds, when other removals may have emptied the triangle). Given valid rings the test
//! guarantees that the new edge `ac` crosses nothing and that no ring or vertex changes side
//! (argument in the `removal` module). After the
//! MPP step, vertices of edges that came to intersect are restored to their input positions
//! until the rings are valid again (checked with [`unamalla_mesh::Region::new`]). The output
//! rings are therefore valid by construction, and the result region is built with
//! [`unamalla_mesh::Region::from_simple_rings`], which runs only the O(n) checks (finite, no
//! repeated points, non-zero area) and skips the O(n log n) re-validation (≈ 8 % of the time on
//! the 100,000-vertex benchmark); debug
//! builds — every test — also validate it with [`unamalla_mesh::Region::new`] and assert that
//! both agree.
//!
//! Every result reports per-ring vertex counts, the relative area change and the Hausdorff
//! distance to the input, see [`SimplifyResult`]: for the vertex-removal methods the per-edge
//! chain scan of [`subset_hausdorff`] (O(n), exact whenever its certificate holds, otherwise
//! the sampled value), for the methods that move points the sampled [`hausdorff`]. Holes can be
//! dropped below an area threshold first ([`HoleFilter`]).

// No unwrap/expect in library code: user input must give an error, never a panic (see
// docs/reliability.md). Tests may use them; a local `#[allow]` needs a comment naming the invariant.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

pub mod criteria;
mod error;
pub mod mpp;
mod necks;
pub mod noise;
mod overlay;
mod removal;
mod simplify;

pub use error::ContourError;
pub use mpp::{minimum_perimeter_polygon, MppOptions, MppResult};
pub use necks::{cut_narrow_necks, NeckCut, NeckKind, NeckOptions};
pub use noise::{detect_noise, detect_noise_region, log_area_profile, NoiseReport};
pub use overlay::overlay_svg;
pub use simplify::{
    hausdorff, hole_width, remove_features_below, simplify_region, subset_hausdorff, DroppedHole,
    HoleFilter, Method, Preset, RingReport, SimplifyOptions, SimplifyResult, SubsetHausdorff,
};
