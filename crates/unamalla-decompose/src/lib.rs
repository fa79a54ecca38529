//! # unamalla-decompose
//!
//! Stage 2 and 3a of the pipeline ([Méndez 2023, Ch. 4, §5.1, §5.1.1]; the references are listed
//! in `docs/references.md` of the repository):
//! decompose a planar region with holes into **admissible blocks** by straight **cuts**, and
//! choose **four corners** per block, so that every block can be meshed by a structured grid
//! and neighbouring grids match along whole cuts (no interior singularities).
//!
//! ```no_run
//! # use unamalla_mesh::Region;
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let region: Region = todo!();
//! use unamalla_decompose::{decompose, DecomposeOptions, Decomposition};
//! let d = decompose(&region, &DecomposeOptions::default())?;
//! let json = d.to_json();                         // save (documented in [`file`])
//! let again = Decomposition::from_json(&json, &region)?; // load + validate
//! let svg = d.to_svg(&region);
//! for block in &d.blocks {
//!     for side in block.side_curves() {           // bottom, right, top, left
//!         for q in side { /* q.points, q.kind: Boundary { ring } | Cut { cut, neighbour } */ }
//!     }
//! }
//! # Ok(()) }
//! ```
//!
//! ## What a decomposition is
//!
//! A [`Decomposition`] has [`Block`]s and [`Cut`]s. A cut is a straight segment between two
//! boundary points whose open interior lies in the open region (tested exactly with `orient2d`).
//! Each block is a simple counter-clockwise ring; `edges[i]` says whether ring edge `i` is original
//! boundary (and of which region ring) or a whole cut (which cut, which neighbour). Cut endpoints
//! are vertices of both adjacent blocks and every cut is exactly one edge of each of its two
//! blocks. `corners` are four ring indices in counter-clockwise order (bottom, right, top, left
//! sides). [`Block::side_curves`] splits each side into the curves Q_j the compatibility ILP needs
//! ([Méndez 2023, §5.1]). The binary tree T and the adjacency graph 𝒢 (one independent cycle per
//! hole, [`Decomposition::graph_cycles`]) are available ([Méndez 2023, §4.3]).
//! [`Decomposition::validate`] proves the tiling: cuts inside and disjoint, each cut an edge of
//! exactly two blocks in opposite directions, every boundary edge covered exactly once in its own
//! direction, areas adding up — which together imply that the blocks cover the region without
//! overlap (the boundary chains of the blocks add up to the region's boundary).
//!
//! ## The algorithm (automatic; the thesis was interactive)
//!
//! [Méndez 2023, Algorithm 1] (§4.2.1) with **exclusive branches** (the thesis prints three
//! sequential `if`s; after a split the piece is no longer a leaf): for a piece
//!
//! 1. **with holes → Algorithm 2** (hole removal): the shortest admissible bridges between a
//!    hole and the outer ring (vertex → vertex or vertex → foot of the perpendicular on an edge)
//!    are ranked by `ℓ/ℓ_min + w_a·ḡ` and the best one that admits a second cut is taken
//!    (this picks the hole nearest to the outer boundary and the closest point pair). The hole
//!    is joined to the outer ring (a weakly simple ring) and a second cut from the hole to the
//!    outer part splits the piece in two. The second cut minimises
//!    `w_h·4(f − ½)² + ℓ/(ℓ₁ + per(H)/π) + w_a·ḡ` where `f` is the fraction of the hole's
//!    perimeter on one side (so the hole is split in halves, the thesis's "q₂ far from q₁"),
//!    ℓ₁ the first cut's length. Remaining holes go to the child that contains them.
//! 2. **not approximately convex → Algorithm 3** (concavity cut): the start p is one of the
//!    `K` (default 10) reflex vertices with the largest point concavity κ₃(p) (deepest in their
//!    pockets); q ranges over all vertices, the feet of the perpendiculars from p on every edge,
//!    and the first boundary hits of the rays extending p's two edges and bisecting its angle.
//!    Each admissible candidate is scored by the expected mesh quality of the children:
//!
//!    ```text
//!    S = ½·max(B₁, B₂) + ¼·(B₁ + B₂) + w_a·ḡ + w_l·ℓ/√A
//!    B(P) = F*(P)             if P is approximately convex (it will be a block)
//!    B(P) = 1 + κ₂(P) + κ₃(P)  otherwise (it will be cut again; worse the less convex)
//!    ḡ = ¼ Σ g(α) over the four new angles at the cut ends
//!    g(α) = ((α − 90°)/90°)² for α ≤ 180°,  1 + (α − 180°)/90° for reflex α
//!    ```
//!
//!    with F*(P) the best corner score of the child (module [`corners`]: corner angles near 90°,
//!    balanced opposite sides, straight sides), A the piece's area, ℓ the cut length. The
//!    children count equally whatever their area (an area-weighted mean let long thin wedges
//!    through as long as the big child stayed non-convex); defaults
//!    w_a = 0.5, w_l = 0.1, w_h = 1.5. The best S wins (the thesis's "q minimising the children's
//!    concavity", extended by the quality terms). Candidates are pre-ranked by the cheap terms
//!    (w_a·ḡ + w_l·ℓ/√A); the first 60 admissible ones get the full score.
//! 3. **more than three sides and a critical angle (< θ₋ = 40°) → Algorithm 4**: a triangle
//!    p v q with p, q on the two edges at v at the same distance d = ½·min(edge lengths) (halved
//!    up to four times until pq is a valid cut) is cut off and left as a leaf; the triangle
//!    angles are θ and (180° − θ)/2, the remainder gets 90° + θ/2 at p and q. The triangle must
//!    have at least `min_triangle_fraction` (10⁻⁵) of the region's area — smaller than the
//!    negligible area on purpose (a critical corner left in a block is worse than a
//!    small triangle block; the thesis's Obs 4.5 only warns against small triangles).
//!
//! **Validity rules** (§4.2.3): cuts are disjoint (they never cross piece boundaries and end only
//! at vertices or inside original-boundary edges, never inside another cut); no new angle at a
//! cut end is below θ₋, and a concavity cut must resolve its reflex start vertex (both new
//! angles there ≤ 180°, which prevents fans of cuts from one vertex). Only when no candidate
//! passes are relaxed tiers tried: θ₋ without the resolve rule, then ½θ₋, then ⅕θ₋. No piece may
//! be smaller than `min_area_fraction` (2·10⁻⁴) of the region's area (the last tier accepts a
//! tenth of that, so that a non-convex piece is not left uncut for want of room). Approximate convexity is
//! criteria 1–4 with the thesis defaults τ₁⁻ = 0.1, τ₂⁻ = 0.45, τ₃⁻ = 0.1 (τ₄⁻ unused)
//! (module [`concavity`](mod@concavity)) plus, beyond the thesis, the **spike criterion**: no
//! interior angle above θ₊ = 350° (the tip of a sliver island or of a thin spit of the
//! exterior changes κ₁–κ₃ too little to be noticed, but a block side cannot pass it: its two
//! cells there would need angles of ≈ 179° each — the fold once seen on the gulf-of-mexico
//! region). Such tips
//! are tried first as starts of the concavity cut, whose bisector candidate leaves two angles
//! ≤ 180° (tested: `tests/known_answers.rs`, `a_spike_tip_gets_a_cut_so_no_block_keeps_it`).
//! All rankings are geometric; ties are broken by
//! coordinates, so the result does not depend on where a ring's numbering starts (tested).
//!
//! **Cleanup (merge) pass** (beyond the thesis): greedy splitting can leave cuts that are not
//! needed (a strip cut off a block that was already convex). Afterwards, two blocks sharing
//! exactly one cut are merged when their union is approximately convex, has no critical angle
//! and its corner score is no worse than the worse of the two (F*(A ∪ B) ≤ max(F*(A), F*(B)) +
//! 0.02) — or, for a triangle bounded by cuts only, whenever the union is admissible; best gains
//! first, repeated until nothing merges. User cuts from a file are never
//! merged away. The tree T keeps the split history; its leaves point to the block containing
//! them.
//!
//! **Corner repair** (beyond the thesis, module `builder::repair`): after the merge pass, a block with
//! fewer than four *usable* corners (interior angle < 170°), a critical angle or a non-convex
//! shape is split by one more cut into two good blocks, or merged with a neighbour (and the
//! union re-split), so that the shared cut meets the boundary at a better angle; failing that,
//! the block alone or with one neighbour is re-split by **two** cuts into three good blocks, or
//! its union with two neighbours into two or three (a good neighbour's corner score may get at
//! most 0.05 worse). With this step every block of every bundled region is admissible at the
//! mesher's defaults (`tests/fixtures.rs`, `pipeline_regions_meet_the_corner_rules`). Note the
//! counting bound behind it: a straight cut adds at most two usable corners at each end, and one
//! block, so a region (or a union of blocks) with fewer than four usable vertices can never be
//! cut into blocks with four usable corners each — a triangle stays a triangle block.
//!
//! **No corner inside a cut** (fourth step of the repair): a block that would still
//! need a point inside a cut for the triangle-block rule (bounded by cuts where its corners
//! must go, fewer than four usable vertices) is split or merged and re-split with a relaxed
//! acceptance (a critical angle or a non-convex block is accepted, a cut joint is not).
//! [`Decomposition::cut_joints`] lists block vertices off the region boundary (empty for
//! every fixture region, tested).
//!
//! **Triangle-block rule and split cuts.** Blocks with three vertices or fewer than four
//! corner-like vertices get the triangle-block rule, inserting on original boundary edges only
//! when possible; otherwise a block with four non-reflex vertices takes its corners among them
//! (accepting a nearly straight or sharp corner), and a three-vertex block keeps its critical
//! vertex as a corner and gets its fourth corner at the midpoint of a boundary edge. Only a
//! three-vertex block bounded by cuts alone gets a cut split in two (both neighbours get the vertex);
//! such a joint is the only place where a cut endpoint may lie off the region boundary, and it
//! is an interior mesh node of valence 3 (a singularity) — it does not occur in the fixture
//! decompositions of `docs/results.md (section "Decomposition results")` unless the table says so.
//!
//! **Corners** ([`corners`], [Méndez 2023, §5.1.1]): the best 4-tuple of vertices with an
//! interior angle below 170° (never a straight or reflex vertex) by
//! `F = ¼Σg(θ) + w_bal·balance + w_turn·straightness`; triangles get the triangle-block rule:
//! their three vertices and the midpoint of the longest side. The thesis's rule (Figs 5.3–5.4)
//! instead blunts each critical vertex: two points inserted on its two edges at the same
//! distance become corners (180° by construction) and the vertex lies inside the short side
//! between them, so its mesh node is shared by two cells of about half its angle each — a 36°
//! coastal tip gave two 18° cells that failed OpenFOAM's skewness test. Keeping the sharp
//! vertex as a corner gives one cell with its whole angle; on the 34 development regions it
//! raised the smallest scaled Jacobian on 29 of the 34 changed meshes at 5,000 and 20,000 cells
//! at the same μ ≥ 0.8 share to ±0.5 points except one mesh (docs/results.md, "Sharp tips as
//! corners"). [`DecomposeOptions::blunt_critical_tips`] restores the thesis's rule.
//!
//! ## Layouts: the concavity layout and the chord layout
//!
//! [`Layout::Concavity`] is the algorithm above alone. On long gulfs, elongated islands and
//! ragged coasts it places long shore-to-shore cuts and cuts *along* elongated parts (sliver
//! blocks), and leaves narrow arms inside large blocks. [`Layout::Chords`] (module
//! [`chords`], the default of [`decompose`]) first places cuts chosen from the shape's
//! **chordal axis** (Prasad, "Morphological analysis of shapes", CNLS Newsletter 139, 1997):
//! the boundary is sampled (at the cell size, at most a sixteenth of each ring), the samples
//! are triangulated by a constrained Delaunay triangulation (`spade`), and every interior
//! edge of it — a chord, a boundary-to-boundary segment inside the region; no two cross — is a
//! candidate cut:
//!
//! 1. **hole bridges**: a minimum spanning tree of the rings over their cheapest chords
//!    (cost `ℓ·(1 + ḡ)`), closed into cycles by further chords so that no bridge has one block
//!    on both sides (a second chord of the same hole must leave ≥ ¼ of its perimeter on each
//!    side); this is what lets a sea with 500 islands decompose
//!    (`tests/categories.rs` of `unamalla-core`), where Algorithm 2 gives up on a hole;
//! 2. **transverse cuts**: in each simply connected piece, the chord maximising
//!    `min(A₁, A₂)/w²·(1 − ½ḡ)` (w its length, A₁, A₂ the areas on its sides — subtree sums of
//!    the dual tree) is cut while the score reaches the aspect threshold T
//!    ([`DecomposeOptions::chord_aspect`]): the score is high at **necks** and at the middle of
//!    long **channels** and elongated islands (which become chains of blocks at most ≈ 2T
//!    widths long) and low at small capes (a half disc at its base scores π/8);
//! 3. Algorithm 1 on every piece; then **arm cuts**: a block that still has a part
//!    [`ARM_SCORE`] chord widths beyond a chord between two boundary points gets that chord as
//!    a layout cut and the decomposition is redone (two rounds at most).
//!
//! Cut ends keep at least [`chords::MIN_END_ANGLE_DEG`] to the boundary and `max(s, w/2)` from
//! other layout cut ends (no fans). The layout cuts are never merged away. Neither layout
//! wins everywhere (measured on the 34 development regions with the quality predictor of
//! `unamalla_core::predict`): the mesher builds the concavity layout and chord layouts at
//! T = 0.35, 0.75, 1.5 and meshes the one with the best predicted quality
//! (`unamalla_core::pipeline::choose_layout`).
//!
//! ## Submapping (Ruiz-Gironés & Sarrate)
//!
//! Module [`submap`] is the second strategy: vertex classification by turning angles with the ILP
//! repair [Ruiz-Gironés & Sarrate, (6), (8)], virtual edges for holes from a constrained Delaunay
//! triangulation, interval assignment ILP [Ruiz-Gironés & Sarrate, (3)], the integer
//! computational space and cuts from Corner/Reversal nodes until
//! every piece is a computational rectangle ([`submap::submap`]); the pieces can be TFI'd and merged
//! ([`submap::Submapping::block_mesh`]) or viewed as a [`Decomposition`]
//! ([`submap::Submapping::to_decomposition`]).
//!
//! ## Files and pictures
//!
//! The decomposition file (module [`file`](mod@file)) saves any result and overrides any part of it
//! (cuts only, cuts + continue automatically, or complete blocks with corners); loading
//! validates with errors naming the block, cut, ring or vertex ([`DecomposeError`]).
//! [`Decomposition::to_svg`] draws blocks, cuts, corners and ids.

#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

mod auto;
mod builder;
pub mod chords;
pub mod concavity;
pub mod corners;
pub mod corners_diametral;
pub mod curves;
mod decomposition;
pub mod error;
pub mod file;
mod geom;
mod piece;
mod render;
pub mod submap;

pub use auto::{
    chord_layout, chord_layout_cuts, decompose, layout_from_cuts, split_chord, CutWeights,
    DecomposeOptions, Layout, ARM_SCORE,
};
pub use concavity::{concavity, critical_angles, is_admissible, Concavity, Pocket, Tolerances};
pub use corners::{select_corners, CornerWeights};
pub use corners_diametral::CornerChoice;
pub use curves::BlockCurves;
pub use decomposition::{Block, Cut, Decomposition, EdgeKind, SideCurve, Step, TreeNode};
pub use error::DecomposeError;
