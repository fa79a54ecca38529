//! The end-to-end mesher: region → block-structured, singularity-free, all-convex quad mesh.
//!
//! Stages (after [Méndez 2023, §1.4, §1.5]; the references are listed in `docs/references.md` of
//! the repository):
//!
//! 1. **simplify** the contour (`unamalla-contour`, default: modified areas, thesis threshold,
//!    halved while the area changes by more than 1 %: [`simplify_for_mesh`]),
//!    then remove the boundary features smaller than the target cell size `h` (modified-area
//!    measure ζ < `c·h²`, [`DEFAULT_FEATURE_FACTOR`] `c = 5`,
//!    [`unamalla_contour::remove_features_below`]): a block side zig-zagging at the cell scale
//!    admits no convex cells, so such features would leave folded cells behind; and cut off
//!    the spits and inlets behind a neck narrower than a cell ([`DEFAULT_NECK_FACTOR`],
//!    [`unamalla_contour::cut_narrow_necks`]): a tongue narrower than a cell gets blocks whose
//!    sides are shorter than a cell, and their point counts force rows of tiny cells across
//!    the neighbouring blocks;
//! 2. **decompose** into admissible blocks by cuts and choose four corners per block
//!    (`unamalla-decompose`);
//! 3. **compatible counts** ([`crate::curves`]): every block side is split into curves Q_j
//!    (pieces of the original boundary or whole cuts); point counts m_j with equal counts on both
//!    copies of a cut and on opposite block sides. For a cell count or cell size: the target fit
//!    of `unamalla-compat-ilp` (every curve near `ℓ_j/h + 1` points, deviations paid in cells)
//!    with `h` rescaled until the predicted cell count is within 2 % of the request (default
//!    20 000 cells); for a density factor: the integer program (5.10) with the bounds (5.9);
//! 4. **reparametrize** each curve by arc length with m_j points (§5.3) — a cut is resampled
//!    once and both blocks use the same points;
//! 5. **TFI** per block (§6.1);
//! 6. **merge** into one conformal mesh without duplicate nodes ([`BlockMesh2::merge`]);
//!    flat block corners on the region boundary (triangle blocks) are then bent outward by a
//!    few degrees so their cells can be convex ([`crate::flat_corners`]);
//! 7. **smooth** the merged mesh with `F = (1−σ)·w·F_AO + σ·H_ω` ([Méndez 2023, (6.8), (6.9)]) with
//!    the ε-convexity guarantee of `unamalla-optim`; region boundary nodes are fixed, **cut nodes
//!    are free**. The thesis smooths block by block and then each block with its neighbours. We
//!    first untangle the folded cells in local patches of the merged mesh (the folded cells and `r`
//!    layers around them, across block boundaries, `r` growing until they are convex; patches in
//!    parallel, [`crate::untangle`]; small problems need far fewer iterations), then run one global
//!    optimization over the whole merged mesh with the same functional (the limit of the thesis's
//!    sequence), which starts convex wherever the patches could be untangled. By default the start
//!    is not the TFI mesh but one prolonged from the same decomposition meshed and smoothed with a
//!    quarter of the cells ([`crate::multilevel`], nested iteration; [`Mesher::coarse_levels`]);
//!    the TFI start is kept when that one is not convex.
//!
//!    7b′. **carve** the islands left out of the layout back in ([`crate::carve`]): when
//!    bridging holes at the cell scale fails the guarantee or stays below the quality target
//!    ([`Mesher::mesh_observed`]), or when asked ([`Mesher::carve_islands`]), the holes narrower
//!    than [`NEAR_HOLE_WIDTH`] cell sizes (up to [`CARVE_MAX_WIDTH`] when the decomposition finds
//!    no cuts around the rest) are left out of the layout; each is then removed from the smoothed
//!    mesh as a logical rectangle of cells (a land mask, as in structured ocean models: Griffies
//!    et al. 2000, Ocean Modelling 2, §3) whose ring of nodes moves onto the island's contour,
//!    its block split into the eight blocks around it, and the carved mesh is untangled and
//!    smoothed again with the island rings fixed;
//! 8. **report** quality ([`QualityReport`]) and fidelity (area change, Hausdorff distance of
//!    the mesh boundary to the input region).
//!
//! ## Decomposition strategies ([`Strategy`])
//!
//! * [`Strategy::Cuts`] (default): stages 2–6 as above ([Méndez 2023, Ch. 4–6]).
//! * [`Strategy::Submap`]: stages 2–6 are replaced by **submapping** ([Ruiz-Gironés & Sarrate],
//!   [`unamalla_decompose::submap`]): vertex classification with the ILP (6)/(8) repair, virtual
//!   edges for holes from a constrained Delaunay triangulation, edge classification, interval
//!   assignment ILP (3), computational space, cuts from Corner/Reversal nodes, TFI per piece and
//!   merge. Smoothing (stage 7) is the same; cut and virtual-edge nodes are interior nodes of the
//!   merged mesh and therefore free. The target size is `h = √(area/N)` for
//!   [`MeshSize::Cells`], `h` for [`MeshSize::CellSize`] and (shortest ring edge)/`d` for
//!   [`MeshSize::Density`]. [`MeshResult::decomposition`] then holds the pieces as blocks
//!   ([`Submapping::to_decomposition`]) and [`MeshResult::counts`] is `None`.
//! * [`Strategy::Auto`]: submapping when **every vertex turning angle of the (simplified) region
//!   is within [`AUTO_ANGLE_TOLERANCE_DEG`] = 10° of a multiple of 90° and the angle-rule labels
//!   already satisfy `Σ α = 4` on the outer ring and `−4` on each hole**
//!   ([`unamalla_decompose::submap::prefers_submap`]); otherwise, or if submapping fails, cuts.

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;
use unamalla_compat_ilp as ilp;
use unamalla_contour::{remove_features_below, simplify_region, HoleFilter, SimplifyOptions};
use unamalla_decompose::submap::{prefers_submap, submap, SubmapOptions, Submapping};
use unamalla_decompose::{
    chord_layout_cuts, decompose, layout_from_cuts, split_chord, DecomposeOptions, Decomposition,
    Layout,
};
use unamalla_mesh::quality::QualityReport;
use unamalla_mesh::{BlockMesh2, DVec2, FreeNodes, HasNodes, HasQuadCells, Region};
use unamalla_optim::monitor::{NullObserver, Observer};
use unamalla_optim::{
    improve_shape, smooth, BoundarySlide, ShapeOptions, ShapeReport, SmoothOptions,
};

use crate::CoreError;

mod islands;
mod layout;
mod report;
mod run;

pub use layout::*;
pub use report::*;
pub use run::*;

/// How the mesh size is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MeshSize {
    /// About this many cells (the cell size is `√(area / N)`).
    Cells(usize),
    /// Target cell size `h` in region units.
    CellSize(f64),
    /// The thesis's density factor `d` (lower bounds `d·⌈ℓ_j/ℓ_min⌉`).
    Density(usize),
}

impl Default for MeshSize {
    fn default() -> Self {
        MeshSize::Cells(20_000)
    }
}

/// The decomposition strategy (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum Strategy {
    /// Straight cuts into admissible blocks with four corners ([Méndez 2023, Ch. 4]).
    #[default]
    Cuts,
    /// Submapping ([Ruiz-Gironés & Sarrate]).
    Submap,
    /// Submapping when all angles are near multiples of 90°, else cuts.
    Auto,
}

/// Default factor `c` of [`Mesher::feature_factor`]: boundary features with ζ < `c·h²` are
/// removed: spikes and zig-zags narrower than about `√5·h ≈ 2.2` cells go, the chord error on
/// smooth stretches is about `√c·h/8 ≈ 0.28·h` (see [`unamalla_contour::remove_features_below`]).
///
/// Chosen by measurement (`mesh_region` example on the twelve bundled regions at about 20,000
/// cells, docs/results.md): with `c = 0.5` cell-scale coast zig-zags survived and left folded
/// cells in the gulf of Mexico (99), Norway (31,616) and Texas; with `c = 3` and `c = 5` every
/// real fold disappeared, and `c = 5` gave the better μ ≥ 0.8 share on most regions while the
/// area change stayed below 2 % everywhere (largest: Norway 1.6 %). Features of size comparable
/// to a cell cannot be represented by cells of that size anyway; ask for smaller cells
/// (or a smaller factor) to keep them.
pub const DEFAULT_FEATURE_FACTOR: f64 = 5.0;

/// Default factor of [`Mesher::neck_factor`]: spits and inlets behind a neck narrower than
/// one target cell (`1.0·h`) whose mean width is below one cell are cut off at the neck
/// ([`unamalla_contour::cut_narrow_necks`]). A tongue narrower than a cell admits no convex
/// cells of the requested size: the layout gave it blocks whose sides are shorter than a cell,
/// and their counts forced rows of cells with 1–2 % of the mean area across the neighbouring
/// blocks (Texas at 20,000 cells: two barrier spits, μ ≥ 0.8 on 79.8 % of the cells; see
/// docs/results.md).
pub const DEFAULT_NECK_FACTOR: f64 = 1.0;

/// Default of [`Mesher::carve_islands`]: holes narrower than one cell size leave the block
/// layout and are carved into the smoothed mesh ([`crate::carve`]) — a feature smaller than
/// the cell scale must not make blocks that force finer cells elsewhere; bridged by cuts, an
/// islet of 0.4 cells next to the Gulf of Mexico's coast made a sliver block one cell thick
/// whose cells had μ ≈ 0.02 and held the smoother at its convexity floor for hundreds of
/// iterations (docs/results.md, "Islands narrower than a cell carved by default").
pub const DEFAULT_CARVE_WIDTH: f64 = 1.0;

/// Largest accepted relative area change of the mesh against the **input** region (20 %),
/// checked when no hole was dropped on purpose: the default simplification keeps the change
/// below 2 % on the bundled regions (docs/results.md), and the feature removal may drop a
/// notch that cannot be meshed at the cell size (the bad-input catalogue's near-touching notch:
/// 11 %); a mesh with far fewer cells than the region's features (`--cells 1` on Texas: 32 %)
/// or a lost MultiPolygon part is above.
pub const INPUT_AREA_TOLERANCE: f64 = 0.20;

/// Angle tolerance (degrees) of the [`Strategy::Auto`] rule.
pub const AUTO_ANGLE_TOLERANCE_DEG: f64 = 10.0;

/// A stage of the pipeline, for progress callbacks and timings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// Contour simplification.
    Simplify,
    /// Decomposition and corners.
    Decompose,
    /// Compatible point counts.
    Counts,
    /// Reparametrization and TFI.
    Tfi,
    /// Merge into one mesh.
    Merge,
    /// Smoothing.
    Smooth,
    /// Local shape improvement with boundary sliding ([`unamalla_optim::shape`]).
    Shape,
    /// Quality report.
    Report,
}

/// A progress callback: the stage that starts and a short message.
///
/// `Send`, so a configured [`Mesher`] can be handed to another thread (a worker pool, an
/// async task) before it runs.
pub type ProgressFn = Box<dyn FnMut(Stage, &str) + Send>;

/// The builder of the end-to-end mesher. Every stage has a default and can be overridden.
///
/// ```no_run
/// use unamalla_core::pipeline::Mesher;
/// let region = unamalla_core::io::read_region_geojson(
///     "fixtures/regions/puget-sound.geojson", Default::default()).unwrap();
/// let result = Mesher::new().cells(10_000).mesh(&region).unwrap();
/// assert_eq!(result.report.non_convex_cells, 0);
/// ```
pub struct Mesher {
    size: MeshSize,
    simplify: Option<SimplifyOptions>,
    decompose_opts: DecomposeOptions,
    layout: Option<Layout>,
    decomposition: Option<Decomposition>,
    smooth_opts: SmoothOptions,
    boundary_density: f64,
    time_limit: Option<f64>,
    feature_factor: f64,
    neck_factor: f64,
    flat_corner_deficit: f64,
    progress: Option<ProgressFn>,
    strategy: Strategy,
    allow_non_convex: bool,
    coarse_levels: usize,
    shape: Option<ShapeOptions>,
    quality_target: f64,
    drop_narrow_holes: bool,
    /// Holes (indices into the input region) left out before the simplification: set by the
    /// narrow-hole retry of [`Mesher::mesh_observed`] for the holes near the cell scale next to
    /// which a retry still failed.
    dropped_near_failure: Vec<usize>,
    /// Whether the holes the narrow-hole retry leaves out are carved back in
    /// ([`Mesher::carve_dropped_holes`]).
    carve_dropped: bool,
    /// Holes narrower than this many cell sizes are carved instead of bridged
    /// ([`Mesher::carve_islands`]; 0 = only by the retries).
    carve_width: f64,
    /// Set by the narrow-hole retry of [`Mesher::mesh_observed`]: the holes dropped by the
    /// simplification were left out by the pipeline, not by the user's filter.
    auto_dropped: bool,
    /// Candidate layouts [`choose_layout`] must not pick (set by the fallback of
    /// [`Mesher::mesh_observed`] after a layout failed the guarantee).
    excluded_layouts: Vec<String>,
}

impl Default for Mesher {
    fn default() -> Self {
        Self::new()
    }
}

/// Every setting, the progress callback shown only as present or absent.
impl std::fmt::Debug for Mesher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Mesher")
            .field("size", &self.size)
            .field("strategy", &self.strategy)
            .field("simplify", &self.simplify)
            .field("decompose_opts", &self.decompose_opts)
            .field("layout", &self.layout)
            .field(
                "decomposition",
                &self.decomposition.as_ref().map(|_| "given"),
            )
            .field("smooth_opts", &self.smooth_opts)
            .field("boundary_density", &self.boundary_density)
            .field("time_limit", &self.time_limit)
            .field("feature_factor", &self.feature_factor)
            .field("neck_factor", &self.neck_factor)
            .field("flat_corner_deficit", &self.flat_corner_deficit)
            .field("allow_non_convex", &self.allow_non_convex)
            .field("coarse_levels", &self.coarse_levels)
            .field("shape", &self.shape)
            .field("quality_target", &self.quality_target)
            .field("drop_narrow_holes", &self.drop_narrow_holes)
            .field("dropped_near_failure", &self.dropped_near_failure)
            .field("excluded_layouts", &self.excluded_layouts)
            .field("progress", &self.progress.as_ref().map(|_| "callback"))
            .finish()
    }
}

/// Everything the mesher produced.
pub struct MeshResult {
    /// The region after simplification (the mesh's boundary lies on it).
    pub simplified: Region,
    /// The decomposition used (for [`Strategy::Submap`]: the pieces as blocks).
    pub decomposition: Decomposition,
    /// The compatible counts per curve and the block sizes (`None` when submapping made the
    /// blocks; its interval counts are in [`MeshResult::submap`]).
    pub counts: Option<ilp::CompatSolution>,
    /// The submapping, when that strategy was used.
    pub submap: Option<Submapping>,
    /// The block-structured mesh (blocks + conformal global mesh).
    pub mesh: BlockMesh2,
    /// The report.
    pub report: MeshReport,
}

impl Mesher {
    /// Defaults: about 20,000 cells, default simplification, automatic decomposition, (6.8)
    /// smoothing with σ = [`DEFAULT_SIGMA`] and no boundary density.
    pub fn new() -> Self {
        Self {
            size: MeshSize::default(),
            simplify: Some(SimplifyOptions::default()),
            decompose_opts: DecomposeOptions::default(),
            layout: None,
            decomposition: None,
            smooth_opts: default_smooth_options(),
            boundary_density: 1.0,
            time_limit: None,
            feature_factor: DEFAULT_FEATURE_FACTOR,
            neck_factor: DEFAULT_NECK_FACTOR,
            flat_corner_deficit: crate::flat_corners::DEFAULT_MIN_DEFICIT_DEG,
            progress: None,
            strategy: Strategy::Cuts,
            allow_non_convex: false,
            coarse_levels: crate::multilevel::DEFAULT_COARSE_LEVELS,
            shape: Some(ShapeOptions::default()),
            quality_target: QUALITY_TARGET_PERCENT,
            drop_narrow_holes: true,
            dropped_near_failure: Vec::new(),
            carve_dropped: true,
            carve_width: DEFAULT_CARVE_WIDTH,
            auto_dropped: false,
            excluded_layouts: Vec::new(),
        }
    }
    /// The decomposition strategy (default [`Strategy::Cuts`]).
    pub fn strategy(mut self, s: Strategy) -> Self {
        self.strategy = s;
        self
    }
    /// Angle deficit (degrees) given to flat block corners on the region boundary after the
    /// merge (default [`crate::flat_corners::DEFAULT_MIN_DEFICIT_DEG`]; 0 keeps them flat —
    /// each then leaves one degenerate cell; see [`crate::flat_corners`]).
    pub fn flat_corner_deficit(mut self, deg: f64) -> Self {
        self.flat_corner_deficit = if deg.is_finite() { deg.max(0.0) } else { 0.0 };
        self
    }

    /// Boundary features whose modified-area measure ζ ([Méndez 2023, (3.4)]) is below
    /// `c·h²` are removed after the contour simplification, `h` the target cell size
    /// (default [`DEFAULT_FEATURE_FACTOR`]; 0 disables; see
    /// [`unamalla_contour::remove_features_below`]). Not applied with `--density` sizes (no
    /// `h`), without simplification, or with a decomposition file.
    pub fn feature_factor(mut self, c: f64) -> Self {
        self.feature_factor = if c.is_finite() { c.max(0.0) } else { 0.0 };
        self
    }
    /// Spits and inlets behind a neck narrower than `c·h` (and thinner than that on average)
    /// are cut off at the neck after the feature removal, `h` the target cell size (default
    /// [`DEFAULT_NECK_FACTOR`]; 0 disables; see [`unamalla_contour::cut_narrow_necks`]). Not
    /// applied where [`Mesher::feature_factor`] is not. The cuts are listed in the report's
    /// notes.
    pub fn neck_factor(mut self, c: f64) -> Self {
        self.neck_factor = if c.is_finite() { c.max(0.0) } else { 0.0 };
        self
    }
    /// The μ ≥ 0.8 share (percent of the cells) an automatically chosen layout should reach
    /// (default [`QUALITY_TARGET_PERCENT`]; 0 disables the retry). A mesh that passes the
    /// guarantee but stays below it is re-made from the next candidate layouts, best predicted
    /// first, at most [`QUALITY_FALLBACKS`] times, and the attempt with the highest share is
    /// kept: the layout is chosen by a prediction made on a coarse mesh, and the achieved share
    /// is the measurement that prediction stands in for. Each retry is a whole run of the
    /// pipeline and is named in the report's notes. Values outside `[0, 100]` are clamped.
    pub fn quality_target(mut self, percent: f64) -> Self {
        self.quality_target = if percent.is_finite() {
            percent.clamp(0.0, 100.0)
        } else {
            0.0
        };
        self
    }
    /// Whether a mesh that fails the guarantee next to holes narrower than the cell size `h`
    /// is made again without every hole narrower than `h` (default `true`). Cells of size `h`
    /// cannot go around an island narrower than one of them: the block layout gives it its
    /// own blocks, a cell or two across, and the untangling cannot always open them. The
    /// retry runs only when the hole filter of the simplification is [`HoleFilter::KeepAll`]
    /// (a filter the user set is kept as it is) and the failure lies next to such a hole
    /// ([`crate::preflight::small_hole`]); it uses [`HoleFilter::MinWidth`]`(h)`, the dropped
    /// holes are listed in [`MeshReport::holes_dropped`] and the report's notes say why. If
    /// that mesh fails too, at most [`NEAR_HOLE_ROUNDS`] more runs each also leave out the
    /// holes narrower than `NEAR_HOLE_WIDTH · h` that lie within `h` of a failing cell (an
    /// island one or two cells across gets blocks too thin to untangle, as one narrower than a
    /// cell does; the others stay). With carving on ([`Mesher::carve_dropped_holes`]) the holes
    /// narrower than [`Mesher::carve_islands`] cells are left out from the start and the
    /// retries leave out wider ones, all carved back where they can be. With `false` every hole
    /// stays in the layout and the run fails with the error naming the hole and the remedies (a
    /// smaller cell size keeps the holes).
    pub fn drop_narrow_holes(mut self, yes: bool) -> Self {
        self.drop_narrow_holes = yes;
        self
    }
    /// Whether holes are carved at all (default `true`): those narrower than
    /// [`Mesher::carve_islands`] cell sizes from the start, and those the retries of
    /// [`Mesher::mesh_observed`] left out of the layout: the cells covering each
    /// such island are removed, the nodes around them moved onto its contour, and the mesh
    /// smoothed again ([`crate::carve`]). The islands carved are listed in
    /// [`MeshReport::holes_carved`], the others stay in [`MeshReport::holes_dropped`] and the
    /// report's notes say why. Holes dropped by a hole filter the user set are never carved.
    pub fn carve_dropped_holes(mut self, yes: bool) -> Self {
        self.carve_dropped = yes;
        self
    }
    /// Leaves every hole narrower than `width` cell sizes ([`unamalla_contour::hole_width`]) out
    /// of the block layout from the start and carves it into the smoothed mesh
    /// ([`crate::carve`]); default [`DEFAULT_CARVE_WIDTH`] = 1: an island narrower than a cell
    /// cannot be bridged by blocks of cells of that size (the cuts around it make blocks
    /// thinner than a cell, whose counts force slivers). Wider holes are carved by the retries
    /// of [`Mesher::mesh_observed`] when bridging them fails or stays below the quality target.
    /// Applies with the default hole filter ([`HoleFilter::KeepAll`]) and while
    /// [`Mesher::carve_dropped_holes`] and [`Mesher::drop_narrow_holes`] are on (an island too
    /// small to carve is dropped); the islands carved are listed in
    /// [`MeshReport::holes_carved`], those too small to carve in [`MeshReport::holes_dropped`].
    /// 0 keeps every hole in the layout. Negative or non-finite values are 0.
    pub fn carve_islands(mut self, width: f64) -> Self {
        self.carve_width = if width.is_finite() {
            width.max(0.0)
        } else {
            0.0
        };
        self
    }
    /// About `n` cells.
    pub fn cells(mut self, n: usize) -> Self {
        self.size = MeshSize::Cells(n);
        self
    }
    /// Target cell size.
    pub fn cell_size(mut self, h: f64) -> Self {
        self.size = MeshSize::CellSize(h);
        self
    }
    /// The thesis's density factor.
    pub fn density(mut self, d: usize) -> Self {
        self.size = MeshSize::Density(d);
        self
    }
    /// Simplification options, or `None` to mesh the region as given.
    pub fn simplify(mut self, opts: Option<SimplifyOptions>) -> Self {
        self.simplify = opts;
        self
    }
    /// Decomposition options for the automatic decomposition.
    pub fn decompose_options(mut self, opts: DecomposeOptions) -> Self {
        self.decompose_opts = opts;
        self
    }

    /// Uses this block layout instead of choosing one by predicted quality (the default:
    /// both the chord layout and the concavity layout are built and the one with the higher
    /// predicted μ ≥ 0.8 share is meshed, module [`crate::predict`]).
    pub fn layout(mut self, layout: Layout) -> Self {
        self.layout = Some(layout);
        self
    }
    /// Use this decomposition (e.g. loaded from a file) instead of computing one. It must belong
    /// to the region after simplification (pass `simplify(None)` when it was made for the raw
    /// region).
    pub fn decomposition(mut self, d: Decomposition) -> Self {
        self.decomposition = Some(d);
        self
    }
    /// Smoothing options (default [`default_smooth_options`]). The options structs of the
    /// stage crates are `#[non_exhaustive]`: start from a default or a constructor and chain
    /// the setters (named after the fields), or assign the fields of a default value.
    ///
    /// ```
    /// use unamalla_core::optim::SmoothOptions;
    /// use unamalla_core::pipeline::default_smooth_options;
    /// use unamalla_core::Mesher;
    ///
    /// let base = default_smooth_options();
    /// let opts = base.clone().eps(0.02).solver(base.solver.clone().max_iter(300));
    /// assert_eq!((opts.eps, opts.solver.max_iter), (0.02, 300));
    /// let mut other = SmoothOptions::default();
    /// other.solver.max_iter = 300;
    /// assert_eq!(other.solver.max_iter, opts.solver.max_iter);
    /// let _mesher = Mesher::new().cells(5_000).smooth_options(opts);
    /// ```
    pub fn smooth_options(mut self, opts: SmoothOptions) -> Self {
        self.smooth_opts = opts;
        self
    }
    /// Boundary density `w` of (6.9) (1 = plain (6.8)).
    pub fn boundary_density(mut self, w: f64) -> Self {
        self.boundary_density = w;
        self
    }
    /// An explicit wall-clock limit of the smoothing stage (untangling and the global run) in
    /// seconds. By default there is none: smoothing ends on its convergence tests and iteration
    /// caps ([`default_smooth_options`]), so the mesh does not depend on the machine or its
    /// load. With a limit the optimizer is stopped when it is reached and its current iterate
    /// is kept (convex, by the safeguard, if it was convex); the report's `smoothing` field then
    /// says "STOP by TIME LIMIT". A non-finite or negative value is rejected by the smoother
    /// ([`unamalla_optim::OptimError::InvalidOption`] naming `time_limit`).
    pub fn time_limit(mut self, seconds: Option<f64>) -> Self {
        self.time_limit = seconds;
        self
    }
    /// Return a mesh that fails the independent check ([`crate::verify`]) as `Ok`, with the
    /// failures in [`MeshReport::verification`], instead of [`CoreError::Guarantee`]
    /// (default `false`; the CLI's `--allow-non-convex`).
    pub fn allow_non_convex(mut self, allow: bool) -> Self {
        self.allow_non_convex = allow;
        self
    }
    /// Coarse levels of the smoothing (default [`crate::multilevel::DEFAULT_COARSE_LEVELS`];
    /// 0: smooth from the transfinite start): the decomposition is meshed again with a quarter
    /// of the cells per level, smoothed, and the result prolonged to the level above as its
    /// start ([`crate::multilevel`]). Only for the cuts strategy and cell-count or cell-size
    /// requests; a prolonged start that is not convex is discarded.
    pub fn coarse_levels(mut self, levels: usize) -> Self {
        self.coarse_levels = levels;
        self
    }
    /// The local shape pass after the smoothing ([`unamalla_optim::shape`]; default
    /// [`ShapeOptions::default`]: cells below μ = 0.85 improved, region-boundary nodes sliding
    /// along the boundary); `None` turns it off.
    pub fn shape(mut self, opts: Option<ShapeOptions>) -> Self {
        self.shape = opts;
        self
    }
    /// A progress callback called at the start of every stage.
    pub fn on_progress(mut self, f: impl FnMut(Stage, &str) + Send + 'static) -> Self {
        self.progress = Some(Box::new(f));
        self
    }
}

/// Weight σ of H_ω in the pipeline's smoothing functional (6.8), `(1 − σ)·F_AO + σ·H_ω`.
///
/// The thesis's examples use σ = 0.1 ([Méndez 2023, Example 6.3], the Laguna Honda region); the
/// pipeline uses 0.5. Measured with the `smooth_study` example on the 34 development regions
/// (docs/results.md, "Smoothing weight σ"): at σ = 0.1 the converged meshes of large open blocks
/// whose cells are anisotropic (the compatible counts make them 1.5–2.5 times longer than wide) are
/// **buckled** — grid lines in herringbone waves, with diagonal stripes of sheared cells (μ
/// 0.6–0.8) a few cells apart — because the area–orthogonality term is nearly singular for diagonal
/// shear waves (its Hessian's Rayleigh quotient is about `2θ⁴` for wave number θ, against `16θ²`
/// for the other polarisation; the test
/// `area_orthogonality_hessian_is_weak_for_diagonal_shear_waves` of `unamalla-functionals`) and H_ω
/// at weight 0.1 does not hold them; running the σ = 0.1 smoother to its FTOL (88 iterations
/// instead of 51) does not remove the stripes. With σ = 0.5 the μ ≥ 0.8 share rose on **every**
/// region at 5,000 cells (by 0.2–7 points; 22 → 26 regions at ≥ 90 %) and at 20,000 cells (by
/// 0.1–3.9 points; 30 → 33) with about half the iterations; σ = 0.3 and σ = 0.7 were close behind,
/// σ = 1 (H_ω alone) lost on the silhouettes (crow 74.7 % at 5,000 cells).
pub const DEFAULT_SIGMA: f64 = 0.5;

/// The pipeline's smoothing defaults: (6.8) with σ = [`DEFAULT_SIGMA`] and truncated Newton
/// (trust region) with the inner CG capped at 40 iterations — on meshes of ~20,000 cells an
/// inexact Newton step is far cheaper than an exact one and the outer iteration still
/// converges — ended by the convergence tests [`DEFAULT_STOP_RULES`] and at most 1000
/// iterations per phase; no time limit, no σ continuation (the former first stage at σ = 0.5
/// before a σ = 0.1 run is now the whole run).
pub fn default_smooth_options() -> SmoothOptions {
    let mut o = SmoothOptions::default();
    o.solver.cg_max_iter = 40;
    o.solver.max_iter = 1000;
    o.solver.stop = DEFAULT_STOP_RULES;
    o.functional = unamalla_optim::SmoothFunctional::block_smoothing(DEFAULT_SIGMA);
    o
}

/// The convergence tests of the pipeline's smoothing ([`unamalla_optim::StopRules`]): over a
/// window of 10 iterations, F decreased by less than 10⁻⁴ relative, or α₋/ᾱ moved by less than
/// 1 % and the μ ≥ 0.8 share by less than 0.05 points; neither while F's decrease per
/// iteration grows geometrically (the trust region regrowing after a step cut by the
/// safeguard, [`unamalla_optim::StopRules::regrowing`]). Polish runs shorten the window of F to
/// [`unamalla_optim::POLISH_WINDOW`] and keep the plateau's ([`unamalla_optim::StopRules::polish`]);
/// untangling patches run without these tests ([`crate::untangle`]).
pub const DEFAULT_STOP_RULES: unamalla_optim::StopRules = unamalla_optim::StopRules {
    window: 10,
    window_ftol: 1e-4,
    plateau_alpha: 0.01,
    plateau_share: 0.05,
    plateau_window: 10,
};
