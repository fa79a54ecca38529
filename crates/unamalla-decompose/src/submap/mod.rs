//! # Submapping ([Ruiz-Gironés & Sarrate], multiply connected surfaces)
//!
//! The references are listed in `docs/references.md` of the repository; the paper is cited by its
//! equations `(1)`–`(8)` and figures.
//!
//! A second decomposition strategy next to the cut decomposition of [Méndez 2023, Ch. 4]: the
//! region is split into pieces that are **rectangles in a computational (index) space**, each piece
//! is filled by TFI and the pieces are conformal by construction. It applies to regions whose
//! angles are close to multiples of 90° (mechanical parts, rectilinear plates with holes); fuzzy
//! angles are repaired by the vertex-classification ILP. The six steps the paper lists for
//! submapping plus its conversion of multiply connected domains (the overall strategy of its
//! section "Dominios no simplemente conexos") are:
//!
//! 1. **Vertex classification** ([`classify_region`], [Ruiz-Gironés & Sarrate, Fig 3]). The turning
//!    angle at vertex `i` of a ring traversed with the domain on the left (outer ring CCW, holes
//!    CW; the paper never states the orientation, it is the one its angle values and (7) imply) is
//!    `θ_i = atan2(t_in × t_out, t_in · t_out) ∈ [−π, π)` (exactly antiparallel tangents give `−π`,
//!    a Reversal), `α_i = θ_i/(π/2)` and the initial label is `round(α_i)` clamped to `{−2,…,1}` =
//!    {Reversal, Corner, Side, End}.
//! 2. **Necessary condition** `E − C − 2R = 4(1 − H)` ([Ruiz-Gironés & Sarrate, (1), (7)]). When it
//!    fails, the labels are recomputed by the ILP [Ruiz-Gironés & Sarrate, (6), (8)] of
//!    `unamalla-compat-ilp`, reading the paper's "initially detected classification" `ā_i` as the
//!    real `α_i` with `ρ_i = ω_i = 1` (the paper gives no weights). [`SumMode::PerLoop`] (default)
//!    imposes `Σ_outer α = 4` and `Σ_hole α = −4` separately — a stricter variant than the paper's,
//!    which constrains only the global sum; we offer it because a hole labelled with `Σ = −6`
//!    forces a "twisted" computational image (Fig 11) that the cut search cannot handle;
//!    [`SumMode::Global`] is the paper's (8).
//! 3. **Virtual edges** ([Ruiz-Gironés & Sarrate, Fig 8, Fig 10]): the rings are discretized at the
//!    target size `h`, a constrained Delaunay triangulation of those points (plus the feet of the
//!    perpendiculars from hole vertices onto the other rings' edges, so that exactly axis-aligned
//!    return segments exist; all points lie on the boundary, no interior Steiner points, as in the
//!    paper) gives the candidate edges, and among the edges joining the current outer loop to an
//!    unconnected hole the one with the **best angles** wins. The paper does not quantify "best";
//!    our measure: the four junction turning angles `θ` it creates are scored by
//!    `dev(θ) = |θ − (π/2)·round(θ/(π/2))|`, ranked by `max dev`, then `Σ dev`, then the edge
//!    length (the paper's tie-break), then coordinates. Loop surgery:
//!    `outer…A → (A→B) → hole from B around to B → (B→A) → A…outer`. The junction vertices are
//!    classified by the angle rule and (1) is rechecked on the merged loop; if it fails, ILP (6)
//!    runs on the merged loop with the ring labels pinned (weight 1000) and the junction labels
//!    free (the paper does not say how the junction vertices are classified; this rule is ours).
//! 4. **Edge classification** ([Ruiz-Gironés & Sarrate, Fig 4]): the loop's edges are the maximal
//!    runs between non-Side vertices (a polyline between two non-Side vertices is one "curve";
//!    virtual-edge ends always break). Directions in `Z_4` (0 = +i, 1 = +j, 2 = −i, 3 = −j): the
//!    first edge is `+i` and `d_{k+1} = d_k + α_{v_k} (mod 4)`; the walk must close
//!    (`Σ α ≡ 0 mod 4`, and `Σ α = 4`).
//! 5. **Interval assignment** ILP [Ruiz-Gironés & Sarrate, (3)]: `min Σ n_e/l(e) + M`,
//!    `Σ_{I+} n = Σ_{I−} n`, `Σ_{J+} n = Σ_{J−} n`, `N_e M ≥ n_e`,
//!    `n_e ≥ N_e = max(1, round(l(e)/h))`, with `n_{e'} = n_{e''}` for the two copies of a virtual
//!    edge (the paper does not say how `N_e` follows from `h`; the equality is its "generated nodes
//!    coincide"). Nodes are placed uniformly in arc length on each edge (the paper does not say
//!    where; our choice); Side vertices that turn by more than
//!    [`SubmapOptions::keep_vertex_angle_deg`] are kept as nodes (the edge's `N_e` is raised to the
//!    number of its pieces and the intervals are spread over them in proportion to length).
//! 6. **Computational space** ([Ruiz-Gironés & Sarrate, Fig 2, Fig 5]): every node gets an integer
//!    position, the walk `p_{end} = p_{start} + n_e·dir(e)` must return to the origin, and the loop
//!    must be weakly simple (where a position is visited twice the interior angles of the visits
//!    must not overlap). ILP (3) balances only the global sums (2), so it can stretch an edge such
//!    that a hole crosses the outer boundary in computational space (a case the paper does not
//!    treat; compare its Fig 11, a virtual edge traversed twice in the same direction); the virtual
//!    edges of such an attempt are then banned and the next best ones tried
//!    ([`SubmapOptions::max_attempts`]), otherwise [`SubmapError::Overlap`] is returned.
//! 7. **Cuts** ([Ruiz-Gironés & Sarrate, Fig 6]): from every concave node (interior angle 270° =
//!    Corner or 360° = Reversal) rays along the axis directions strictly inside its interior angle
//!    (2 for a Corner, 3 for a Reversal) are cast in computational space; a ray ends at the first
//!    boundary node it reaches from the inside. The **globally shortest** cut of the piece, ties by
//!    physical length then node order, splits the piece (the paper takes the shortest cut line but
//!    does not say whether per node or per piece, nor how ties are broken); cut nodes are placed by
//!    linear interpolation between the physical end points (ours; the paper does not say) and are
//!    free during smoothing. Recursion stops when no concave node is left: the piece has exactly
//!    four End nodes and is an `a × b` computational rectangle with equal counts on opposite sides.
//! 8. **TFI** per piece ([`Submapping::grids`], discrete Coons TFI of `unamalla-mesh`; the paper
//!    gives no TFI formula) and merge ([`Submapping::block_mesh`]). Cut and virtual-edge nodes
//!    become interior nodes of the merged mesh, so a smoother moves them (the paper's second
//!    observation on virtual edges: a smoother removes the imperfections they introduce).
//!
//! Interior angles in computational space: for a boundary occurrence with incoming direction
//! `d_in` and outgoing `d_out` (codes in `Z_4`), `s = (d_in + 2 − d_out) mod 4` (0 read as 4) is the
//! interior angle in quarter turns (1 End, 2 Side, 3 Corner, 4 Reversal); a direction `v` points
//! strictly into the piece iff `0 < (v − d_out) mod 4 < s`.
//!
//! ```
//! use unamalla_decompose::submap::{submap, SubmapOptions};
//! use unamalla_mesh::{DVec2, Region};
//!
//! // L-shape (`shapes::l_shape`): E = 5, C = 1; one cut splits it into two rectangles
//! let pts = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)];
//! let region = Region::new(pts.iter().map(|&(x, y)| DVec2::new(x, y)).collect(), vec![])?;
//! let s = submap(&region, &SubmapOptions::new(0.5))?;
//! assert_eq!(s.classification.counts.condition_value(), 4);
//! assert_eq!(s.pieces.len(), 2);
//! assert_eq!(s.cuts[0].length, 2); // a unit-length cut with h = 0.5
//! let mesh = s.block_mesh()?;
//! assert_eq!(unamalla_mesh::HasQuadCells::num_quads(&mesh), 12); // 3 unit squares × 4
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod classify;
mod comp;
mod cuts;
mod output;
pub mod shapes;
mod virtual_edges;
pub mod white;

use unamalla_compat_ilp::{CompatError, Direction, VertexKind};
use unamalla_mesh::{DVec2, MeshError, Region};

pub use classify::{classify_region, max_right_angle_deviation, prefers_submap, turning_angle};
pub use white::{white_submap, WhiteStep, WhiteSubmapping};

/// How the necessary condition is imposed when the vertex labels are repaired.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SumMode {
    /// `Σ α = 4` on the outer ring and `Σ α = −4` on every hole (default; stricter than the
    /// paper's (8), which constrains only the global sum).
    #[default]
    PerLoop,
    /// The paper's (8): only the global sum `Σ α = 4(1 − H)` is imposed.
    Global,
}

/// Options of [`submap`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct SubmapOptions {
    /// Target element size `h` (region units): `N_e = max(1, round(l(e)/h))` and the CDT spacing.
    pub target_size: f64,
    /// Per-loop or global sums in the vertex-classification ILP.
    pub sum_mode: SumMode,
    /// Include the `M = max n_e/N_e` term in ILP (3) (objective f_2 of Example 2; `false` gives f_1).
    pub include_max_term: bool,
    /// Side vertices whose turning angle exceeds this (degrees) stay mesh nodes.
    pub keep_vertex_angle_deg: f64,
    /// Safety limit on the number of pieces.
    pub max_pieces: usize,
    /// How many sets of virtual edges may be tried (see [`Submapping::attempts`]).
    pub max_attempts: usize,
}

impl SubmapOptions {
    /// Defaults for target size `h`: per-loop sums, objective f_2, Side vertices turning more than
    /// 10° kept as nodes, at most 10 000 pieces, at most 4 choices of virtual edges.
    pub fn new(target_size: f64) -> Self {
        SubmapOptions {
            target_size,
            sum_mode: SumMode::PerLoop,
            include_max_term: true,
            keep_vertex_angle_deg: 10.0,
            max_pieces: 10_000,
            max_attempts: 4,
        }
    }

    /// Sets [`sum_mode`](Self::sum_mode): per-loop or global sums in the vertex-classification ILP.
    #[must_use]
    pub fn sum_mode(mut self, sum_mode: SumMode) -> Self {
        self.sum_mode = sum_mode;
        self
    }

    /// Sets [`include_max_term`](Self::include_max_term).
    #[must_use]
    pub fn include_max_term(mut self, include_max_term: bool) -> Self {
        self.include_max_term = include_max_term;
        self
    }

    /// Sets [`keep_vertex_angle_deg`](Self::keep_vertex_angle_deg).
    #[must_use]
    pub fn keep_vertex_angle_deg(mut self, keep_vertex_angle_deg: f64) -> Self {
        self.keep_vertex_angle_deg = keep_vertex_angle_deg;
        self
    }

    /// Sets [`max_pieces`](Self::max_pieces): safety limit on the number of pieces.
    #[must_use]
    pub fn max_pieces(mut self, max_pieces: usize) -> Self {
        self.max_pieces = max_pieces;
        self
    }

    /// Sets [`max_attempts`](Self::max_attempts).
    #[must_use]
    pub fn max_attempts(mut self, max_attempts: usize) -> Self {
        self.max_attempts = max_attempts;
        self
    }
}

/// Why submapping failed. Every variant names the ring, hole, piece or point concerned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SubmapError {
    /// The target size is not a finite positive number.
    #[error("submapping: target size must be finite and > 0, got {0}")]
    InvalidTargetSize(f64),
    /// The vertex-classification ILP has no solution for a ring (per-loop mode) or the region
    /// (global mode, `ring = None`).
    #[error("vertex classification of {} failed: {source}", ring.map_or("the region".to_string(), |r| if r == 0 { "the outer ring".to_string() } else { format!("hole {}", r - 1) }))]
    Classification {
        /// Ring (0 = outer, k = hole k−1), or `None` for the global program.
        ring: Option<usize>,
        /// The ILP's error.
        source: CompatError,
    },
    /// The merged loop (after virtual edges) could not be classified.
    #[error("vertex classification of the merged loop failed: {0}")]
    MergedClassification(CompatError),
    /// No CDT edge joins this hole (0-based) to the current outer loop.
    #[error("hole {hole}: no constrained-Delaunay edge joins it to the outer loop")]
    NoVirtualEdge {
        /// The hole.
        hole: usize,
    },
    /// The constrained Delaunay triangulation rejected a point.
    #[error("constrained Delaunay triangulation: point ({x}, {y}): {message}")]
    Triangulation {
        /// x.
        x: f64,
        /// y.
        y: f64,
        /// spade's message.
        message: String,
    },
    /// The edge classification does not close: `Σ α` over the merged loop is not 4.
    #[error("edge classification does not close: Σ α = {sum} on the merged loop, 4 is needed")]
    Closure {
        /// The label sum.
        sum: i64,
    },
    /// The interval assignment ILP (3) failed.
    #[error("interval assignment (3): {0}")]
    Intervals(CompatError),
    /// The computational boundary walk does not return to the origin.
    #[error("computational space: the boundary walk ends at ({x}, {y}) instead of (0, 0)")]
    NotClosed {
        /// Final i.
        x: i64,
        /// Final j.
        y: i64,
    },
    /// The computational loop overlaps itself: two visits of one computational position have
    /// overlapping interior angles (ILP (3) only balances the global sums (2)).
    #[error("computational space: the images of ({}, {}) and ({}, {}) coincide (the computational loop overlaps itself)", a.x, a.y, b.x, b.y)]
    Overlap {
        /// First physical point.
        a: DVec2,
        /// Second physical point.
        b: DVec2,
    },
    /// A piece still has a concave node but no admissible cut line.
    #[error("piece with a concave node at ({x}, {y}) has no admissible cut line (the region is not submappable with this classification)")]
    NoCut {
        /// Physical x of the node.
        x: f64,
        /// Physical y of the node.
        y: f64,
    },
    /// A final piece is not a computational rectangle.
    #[error("piece {piece}: not a computational rectangle ({ends} End nodes)")]
    NotRectangle {
        /// The piece.
        piece: usize,
        /// Its number of End nodes.
        ends: usize,
    },
    /// More pieces than [`SubmapOptions::max_pieces`].
    #[error("more than {0} pieces")]
    TooManyPieces(usize),
    /// TFI or merging failed.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// A region built on the way (the outer contour alone, White's step 1) is not valid.
    #[error(transparent)]
    Geometry(#[from] unamalla_mesh::GeometryError),
    /// White's method does not apply: the outer contour alone is not submappable (its step 1).
    #[error("White's method: the outer contour alone is not submappable: {0}")]
    WhiteOuterNotSubmappable(Box<SubmapError>),
    /// White's method: the return segment of this hole (0-based) from its vertex nearest the
    /// outer contour to the end of the shortest computational cut leaves the region or meets an
    /// earlier one.
    #[error("White's method: hole {hole}: the return segment to the end of the shortest computational cut leaves the region")]
    WhiteReturnSegment {
        /// The hole.
        hole: usize,
    },
}

/// One vertex of the input region with its turning angle and labels.
#[derive(Debug, Clone, PartialEq)]
pub struct VertexInfo {
    /// Ring (0 = outer, k = hole k−1).
    pub ring: usize,
    /// Index in the ring (as stored by [`Region`]).
    pub index: usize,
    /// Position.
    pub point: DVec2,
    /// Turning angle `θ ∈ [−π, π)` (radians).
    pub theta: f64,
    /// `α = θ/(π/2)`.
    pub alpha: f64,
    /// Label from the angle rule (`round(α)` clamped).
    pub initial: VertexKind,
    /// Final label (after the ILP repair, if any).
    pub kind: VertexKind,
}

/// Numbers of Side, End, Corner and Reversal vertices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct KindCounts {
    /// S.
    pub sides: usize,
    /// E.
    pub ends: usize,
    /// C.
    pub corners: usize,
    /// R.
    pub reversals: usize,
}

impl KindCounts {
    /// Counts of a list of kinds.
    pub fn of(kinds: impl IntoIterator<Item = VertexKind>) -> Self {
        let mut c = KindCounts::default();
        for k in kinds {
            match k {
                VertexKind::Side => c.sides += 1,
                VertexKind::End => c.ends += 1,
                VertexKind::Corner => c.corners += 1,
                VertexKind::Reversal => c.reversals += 1,
            }
        }
        c
    }
    /// `E − C − 2R`, which (1)/(7) require to be `4(1 − H)`.
    pub fn condition_value(&self) -> i64 {
        self.ends as i64 - self.corners as i64 - 2 * self.reversals as i64
    }
}

/// Result of step 1–2 (vertex classification with repair).
#[derive(Debug, Clone, PartialEq)]
pub struct Classification {
    /// All ring vertices, outer ring first.
    pub vertices: Vec<VertexInfo>,
    /// Number of holes `H`.
    pub holes: usize,
    /// Counts of the angle-rule labels.
    pub initial_counts: KindCounts,
    /// Counts of the final labels.
    pub counts: KindCounts,
    /// Whether the angle-rule labels already met the condition in force ([`SumMode`]).
    pub initial_condition_holds: bool,
    /// Rings whose labels the ILP changed (all rings `0..=H` in global mode when it ran).
    pub repaired_rings: Vec<usize>,
    /// Total ILP cost `Σ |α_i − ā_i|` of the changes (0 when no repair ran).
    pub ilp_cost: f64,
}

impl Classification {
    /// `E − C − 2R = 4(1 − H)` for the final labels.
    pub fn condition_holds(&self) -> bool {
        self.counts.condition_value() == 4 * (1 - self.holes as i64)
    }
    /// Final kinds of one ring, in ring order.
    pub fn ring_kinds(&self, ring: usize) -> Vec<VertexKind> {
        self.vertices
            .iter()
            .filter(|v| v.ring == ring)
            .map(|v| v.kind)
            .collect()
    }
}

/// A virtual edge (return segment) joining a hole to the outer loop ([Ruiz-Gironés & Sarrate,
/// Fig 8, Fig 10]).
#[derive(Debug, Clone, PartialEq)]
pub struct VirtualEdge {
    /// End on the current outer loop.
    pub a: DVec2,
    /// End on the hole.
    pub b: DVec2,
    /// The hole it connects (0-based).
    pub hole: usize,
    /// The four junction turning angles (degrees): at A entering, at B entering, at B leaving, at
    /// A leaving.
    pub junction_angles_deg: [f64; 4],
    /// Largest deviation of those angles from a multiple of 90° (degrees).
    pub max_deviation_deg: f64,
}

/// What a boundary edge of a piece (or the merged loop) is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EdgeTag {
    /// Region boundary, ring `r` (0 = outer, k = hole k−1).
    Boundary(usize),
    /// A copy of virtual edge `v`.
    Virtual(usize),
    /// Cut line `c`.
    Cut(usize),
}

/// An edge of the merged loop after edge classification and interval assignment.
#[derive(Debug, Clone, PartialEq)]
pub struct CompEdge {
    /// Physical polyline (first and last points are the edge's vertices).
    pub points: Vec<DVec2>,
    /// Computational direction.
    pub direction: Direction,
    /// Physical length `l(e)`.
    pub length: f64,
    /// Lower bound `N_e`.
    pub min_intervals: usize,
    /// Intervals `n_e` from ILP (3) (= computational length).
    pub intervals: usize,
    /// What the edge is.
    pub tag: EdgeTag,
}

/// Kind of a mesh node of the submapping.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum NodeKind {
    /// On the region boundary (fixed during smoothing).
    Boundary,
    /// Interior node of a virtual edge (free).
    Virtual,
    /// Interior node of a cut line (free).
    Cut,
}

/// A cut line made by the decomposition ([Ruiz-Gironés & Sarrate, Fig 6]).
#[derive(Debug, Clone, PartialEq)]
pub struct CutLine {
    /// Node ids from the concave start node to the end node.
    pub nodes: Vec<usize>,
    /// Computational length (= number of elements).
    pub length: usize,
    /// Kind of the start node in its piece (Corner or Reversal).
    pub from: VertexKind,
}

/// A final piece: an `m × n` computational rectangle.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    /// Node ids of the four sides in the TFI convention of `unamalla-mesh`: bottom and top run left
    /// to right, left and right bottom to top (computational orientation).
    pub sides: [Vec<usize>; 4],
    /// Counter-clockwise boundary loop (node ids), starting at the bottom-left corner.
    pub boundary: Vec<usize>,
    /// `tags[k]` says what the edge `boundary[k] → boundary[k+1]` is.
    pub tags: Vec<EdgeTag>,
    /// Computational position of the bottom-left corner.
    pub origin: [i64; 2],
}

impl Piece {
    /// Size in cells `(a, b)` (computational width and height).
    pub fn cells(&self) -> (usize, usize) {
        (self.sides[0].len() - 1, self.sides[3].len() - 1)
    }
}

/// The complete submapping of a region.
#[derive(Debug, Clone, PartialEq)]
pub struct Submapping {
    /// Vertex classification of the input rings.
    pub classification: Classification,
    /// How many choices of virtual edges were tried (a choice whose computational loop overlaps
    /// itself or cannot be cut into rectangles is banned and the next best edges are taken).
    pub attempts: usize,
    /// Virtual edges, in the order they were added.
    pub virtual_edges: Vec<VirtualEdge>,
    /// Whether ILP (6) had to relabel the merged loop's junction vertices.
    pub merged_repaired: bool,
    /// Edges of the merged loop with directions and interval counts.
    pub edges: Vec<CompEdge>,
    /// Objective of ILP (3) for the chosen counts.
    pub interval_objective: f64,
    /// Physical position of every mesh node on a piece boundary.
    pub nodes: Vec<DVec2>,
    /// Kind of every node.
    pub node_kinds: Vec<NodeKind>,
    /// The merged boundary loop in computational space: `(node id, [i, j])`.
    pub comp_loop: Vec<(usize, [i64; 2])>,
    /// The cut lines.
    pub cuts: Vec<CutLine>,
    /// The pieces (computational rectangles).
    pub pieces: Vec<Piece>,
}

/// Runs the whole submapping (steps 1–7 above) on a region.
pub fn submap(region: &Region, options: &SubmapOptions) -> Result<Submapping, SubmapError> {
    let h = options.target_size;
    if !(h.is_finite() && h > 0.0) {
        return Err(SubmapError::InvalidTargetSize(h));
    }
    let classification = classify_region(region, options.sum_mode)?;
    let mut banned: Vec<(DVec2, DVec2)> = Vec::new();
    let mut attempt = 0;
    loop {
        attempt += 1;
        let rings = classify::labelled_rings(region, &classification);
        let merged = virtual_edges::connect(region, rings, h, &banned)?;
        let edges: Vec<(DVec2, DVec2)> = merged.edges.iter().map(|e| (e.a, e.b)).collect();
        match finish(merged, options) {
            Ok(done) => return Ok(assemble(classification, attempt, done)),
            Err(e) if !edges.is_empty() && attempt < options.max_attempts && retryable(&e) => {
                banned.extend(edges);
            }
            Err(e) => return Err(e),
        }
    }
}

/// Failures that another choice of virtual edges may avoid.
fn retryable(e: &SubmapError) -> bool {
    matches!(
        e,
        SubmapError::MergedClassification(_)
            | SubmapError::Closure { .. }
            | SubmapError::Intervals(_)
            | SubmapError::NotClosed { .. }
            | SubmapError::Overlap { .. }
            | SubmapError::NoCut { .. }
            | SubmapError::NotRectangle { .. }
    )
}

/// What steps 4–7 produce.
type Finished = (
    comp::Comp,
    Vec<Piece>,
    Vec<CutLine>,
    Vec<DVec2>,
    Vec<NodeKind>,
    Vec<VirtualEdge>,
    bool,
);

/// The [`Submapping`] of a classification and the result of steps 4–7.
fn assemble(classification: Classification, attempts: usize, done: Finished) -> Submapping {
    let (comp, pieces, cuts, nodes, node_kinds, virtual_edges, merged_repaired) = done;
    Submapping {
        classification,
        attempts,
        virtual_edges,
        merged_repaired,
        edges: comp.edges,
        interval_objective: comp.objective,
        nodes,
        node_kinds,
        comp_loop: comp.occurrences.iter().map(|o| (o.id, o.c)).collect(),
        cuts,
        pieces,
    }
}

/// Steps 4–7 on a merged loop.
fn finish(merged: virtual_edges::Merged, options: &SubmapOptions) -> Result<Finished, SubmapError> {
    let comp = comp::build(merged.points, options)?;
    let mut nodes = comp.nodes.clone();
    let mut node_kinds = comp.node_kinds.clone();
    let (pieces, cuts) = cuts::decompose(
        comp.occurrences.clone(),
        &mut nodes,
        &mut node_kinds,
        options.max_pieces,
    )?;
    Ok((
        comp,
        pieces,
        cuts,
        nodes,
        node_kinds,
        merged.edges,
        merged.repaired,
    ))
}

/// Unit step of a `Z_4` code.
pub(crate) fn dir_step(code: i64) -> [i64; 2] {
    match code.rem_euclid(4) {
        0 => [1, 0],
        1 => [0, 1],
        2 => [-1, 0],
        _ => [0, -1],
    }
}

/// Kind of an integer label (labels outside `−2..=1` are clamped).
pub(crate) fn kind_of(label: i64) -> VertexKind {
    VertexKind::from_label(label.clamp(-2, 1) as i8).unwrap_or(VertexKind::Side)
}
