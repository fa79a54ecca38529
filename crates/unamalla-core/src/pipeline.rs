//! The end-to-end mesher: region → block-structured, singularity-free, all-convex quad mesh.
//!
//! Stages (seed 000 digest §0.1):
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
//! 4. **reparametrize** each curve by arc length with m_j points (§4.5) — a cut is resampled
//!    once and both blocks use the same points;
//! 5. **TFI** per block (§5.1);
//! 6. **merge** into one conformal mesh without duplicate nodes ([`BlockMesh2::merge`]);
//!    flat block corners on the region boundary (triangle blocks) are then bent outward by a
//!    few degrees so their cells can be convex ([`crate::flat_corners`]);
//! 7. **smooth** the merged mesh with `F = (1−σ)·w·F_AO + σ·H_ω` (seed 000 (6.8)/(6.9)) with the
//!    ε-convexity guarantee of `unamalla-optim`; region boundary nodes are fixed, **cut nodes are
//!    free**. The thesis smooths block by block and then each block with its neighbours. We
//!    first untangle the folded cells in local patches of the merged mesh (the folded cells and
//!    `r` layers around them, across block boundaries, `r` growing until they are convex;
//!    patches in parallel, [`crate::untangle`]; small problems need far fewer iterations), then
//!    run one global optimization over the whole merged mesh with the same functional (the limit
//!    of the thesis's sequence), which starts convex wherever the patches could be untangled.
//!    By default the start is not the TFI mesh but one prolonged from the same decomposition
//!    meshed and smoothed with a quarter of the cells ([`crate::multilevel`], nested
//!    iteration; [`Mesher::coarse_levels`]); the TFI start is kept when that one is not convex.
//! 8. **report** quality ([`QualityReport`]) and fidelity (area change, Hausdorff distance of
//!    the mesh boundary to the input region).
//!
//! ## Decomposition strategies ([`Strategy`])
//!
//! * [`Strategy::Cuts`] (default): stages 2–6 as above (seed 000).
//! * [`Strategy::Submap`]: stages 2–6 are replaced by **submapping** (seed 002,
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
pub enum Strategy {
    /// Straight cuts into admissible blocks with four corners (seed 000).
    #[default]
    Cuts,
    /// Submapping (seed 002).
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
pub type ProgressFn = Box<dyn FnMut(Stage, &str)>;

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
    /// Candidate layouts [`choose_layout`] must not pick (set by the fallback of
    /// [`Mesher::mesh_observed`] after a layout failed the guarantee).
    excluded_layouts: Vec<String>,
}

impl Default for Mesher {
    fn default() -> Self {
        Self::new()
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

/// The `report.json` of a run.
#[derive(Debug, Clone, Serialize)]
pub struct MeshReport {
    /// Region name (file stem) if known.
    pub region: String,
    /// Number of cells.
    pub cells: usize,
    /// Number of nodes.
    pub nodes: usize,
    /// Number of blocks.
    pub blocks: usize,
    /// The decomposition strategy that made the blocks (`cuts` or `submap`).
    pub strategy: Strategy,
    /// Cells with a non-positive corner triangle.
    pub non_convex_cells: usize,
    /// Interior nodes with valence ≠ 4.
    pub interior_singularities: usize,
    /// Flat block corners on the region boundary moved outward to make their cells convex
    /// ([`crate::flat_corners`]).
    pub bent_corners: usize,
    /// Percentage of cells with μ ≥ 0.8.
    pub mu_ge_0_8_percent: f64,
    /// Percentages of cells with μ ≥ 0.8, 0.4 ≤ μ < 0.8, μ < 0.4.
    pub mu_bands: [f64; 3],
    /// Minimum Verdict scaled Jacobian.
    pub min_scaled_jacobian: f64,
    /// 5th percentile of the scaled Jacobian.
    pub p5_scaled_jacobian: f64,
    /// α₋ / ᾱ.
    pub min_alpha_over_mean: f64,
    /// |area(mesh) − area(input region)| / area(input region) · 100.
    pub area_change_percent: f64,
    /// Hausdorff distance between the mesh boundary and the input region's boundary.
    pub hausdorff: f64,
    /// Input holes that were dropped (indices in input order).
    pub holes_dropped: Vec<usize>,
    /// Smoother status message.
    pub smoothing: String,
    /// What the shape pass after the smoothing did (`None` when it is off).
    pub shape: Option<ShapeReport>,
    /// Total wall time in seconds (with a layout fallback of [`Mesher::mesh_observed`]: of
    /// every attempt; `stage_seconds` are those of the attempt kept).
    pub seconds: f64,
    /// Wall time per stage.
    pub stage_seconds: Vec<(Stage, f64)>,
    /// The layout chosen by predicted quality (`None` when the layout was given, read from a
    /// file or made by submapping).
    pub layout: Option<LayoutChoice>,
    /// Predicted and achieved μ ≥ 0.8 share per block (empty without a prediction).
    pub block_quality: Vec<BlockQuality>,
    /// The full quality report of the final mesh.
    pub quality: QualityReport,
    /// Notes of the pipeline, e.g. which curves force cells when the counts miss the requested
    /// cell count by more than 15 % ([`crate::curves::CompatibleCounts::notes`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// The independent check of the final mesh ([`crate::verify`]).
    pub verification: crate::verify::Verification,
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

    /// Boundary features whose modified-area measure ζ (seed 000 (3.4)) is below
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
    /// holes are listed in [`MeshReport::holes_dropped`] and the report's notes say why. With
    /// `false` the run fails with the error naming the hole and the remedies (a smaller cell
    /// size keeps the holes).
    pub fn drop_narrow_holes(mut self, yes: bool) -> Self {
        self.drop_narrow_holes = yes;
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
    /// Smoothing options.
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
    pub fn on_progress(mut self, f: impl FnMut(Stage, &str) + 'static) -> Self {
        self.progress = Some(Box::new(f));
        self
    }

    /// Target size of the submapping strategy (see the module documentation).
    fn submap_size(&self, region: &Region) -> f64 {
        match self.size {
            MeshSize::Cells(n) => (region.area() / n.max(1) as f64).sqrt(),
            MeshSize::CellSize(h) => h,
            MeshSize::Density(d) => {
                let shortest = region
                    .rings()
                    .flat_map(|r| {
                        let p = r.points();
                        (0..p.len()).map(move |i| p[i].distance(p[(i + 1) % p.len()]))
                    })
                    .fold(f64::INFINITY, f64::min);
                shortest / d.max(1) as f64
            }
        }
    }

    fn stage(&mut self, s: Stage, msg: &str) {
        if let Some(f) = self.progress.as_mut() {
            f(s, msg);
        }
    }

    /// Pipeline steps 1 and 1b alone: the region simplified by the contour method
    /// ([`simplify_for_mesh`]) and then without the boundary features below the cell size
    /// ([`Mesher::feature_factor`]). The mesher meshes [`PreparedRegion::mesh_region`]; a
    /// decomposition file must have been made for it or for [`PreparedRegion::simplified`].
    pub fn prepare_region(&self, region: &Region) -> Result<PreparedRegion, CoreError> {
        let (simplified, holes_dropped) = match &self.simplify {
            Some(opts) => {
                let r = simplify_for_mesh(region, opts)?;
                let dropped = r.dropped_holes.iter().map(|h| h.hole).collect();
                (r.region, dropped)
            }
            None => (region.clone(), Vec::new()),
        };
        let h = match self.size {
            MeshSize::Cells(n) => Some((simplified.area() / n.max(1) as f64).sqrt()),
            MeshSize::CellSize(h) => Some(h),
            MeshSize::Density(_) => None,
        };
        let mesh_region = match (h, &self.simplify) {
            (Some(h), Some(_)) if self.feature_factor > 0.0 => {
                remove_features_below(&simplified, self.feature_factor * h * h)?
            }
            _ => simplified.clone(),
        };
        let (mesh_region, necks) = match (h, &self.simplify) {
            (Some(h), Some(_)) if self.feature_factor > 0.0 && self.neck_factor > 0.0 => {
                unamalla_contour::cut_narrow_necks(
                    &mesh_region,
                    // sharp tips are not truncated: measured at 20,000 cells (θ₋ = 40°) it
                    // raised chesapeake-bay and norway above 90 % but lost 3 points on
                    // danish-straits and gulf-of-finland and left newfoundland with a cell
                    // outside the region (31 of 34 regions at target against 33; docs/results.md)
                    &unamalla_contour::NeckOptions::new(self.neck_factor * h).with_tip_angle(0.0),
                )?
            }
            _ => (mesh_region, Vec::new()),
        };
        Ok(PreparedRegion {
            simplified,
            mesh_region,
            holes_dropped,
            necks,
        })
    }

    /// Runs the pipeline with no smoothing observer.
    pub fn mesh(self, region: &Region) -> Result<MeshResult, CoreError> {
        self.mesh_observed(region, &mut NullObserver)
    }

    /// Runs the pipeline; `observer` sees every smoothing iteration.
    ///
    /// Before the work: the size against the memory limit and the vertex count of an
    /// unsimplified region ([`crate::preflight`]). A stage failure caused by a too-narrow gap
    /// between rings is reported as such ([`crate::preflight::explain_failure`]). After the
    /// work, the mesh is checked independently ([`crate::verify::verify_quads`]: convex cells,
    /// centroids inside the meshed region, its area and hole count; the area against the input
    /// region within [`INPUT_AREA_TOLERANCE`] unless holes were dropped on purpose); a failure is
    /// [`CoreError::Guarantee`] unless [`Mesher::allow_non_convex`] was set. When the layout was
    /// chosen automatically and the mesh has non-convex cells or cells whose centroid lies outside
    /// the region, the mesh is re-made from the next candidate layouts (at most
    /// [`LAYOUT_FALLBACKS`] more runs; the report's notes name each layout that failed); when
    /// the mesh passes but its μ ≥ 0.8 share is below [`Mesher::quality_target`], at most
    /// [`QUALITY_FALLBACKS`] more candidates are tried and the best share is kept.
    pub fn mesh_observed(
        mut self,
        region: &Region,
        observer: &mut dyn Observer,
    ) -> Result<MeshResult, CoreError> {
        use crate::preflight;
        let t_start = Instant::now();
        let h = self.submap_size(region);
        let limit = preflight::memory_limit()?;
        let (option, value) = match self.size {
            MeshSize::Cells(0) => {
                return Err(CoreError::Unsupported(
                    "--cells 0: a mesh needs at least 1 cell".into(),
                ))
            }
            MeshSize::Cells(n) => ("--cells", n.to_string()),
            MeshSize::CellSize(h) => ("--cell-size", h.to_string()),
            MeshSize::Density(d) => ("--density", d.to_string()),
        };
        preflight::check_size(
            option,
            &value,
            region.area() / (h * h),
            "cells",
            preflight::COST_PER_MESH_CELL,
            limit,
        )?;
        let allow = self.allow_non_convex;
        if self.simplify.is_none() && self.decomposition.is_none() {
            preflight::check_unsimplified(region)?;
            if !allow {
                preflight::check_narrow_features(region, h)?;
            }
        }
        let verify = |result: &MeshResult| {
            let mut v = crate::verify::verify_quads(
                result.mesh.global(),
                Some(&result.simplified),
                &crate::verify::VerifyOptions::default(),
            );
            if result.report.holes_dropped.is_empty() {
                v.input_area_defect = Some(result.report.area_change_percent / 100.0);
                v.input_area_tolerance = Some(INPUT_AREA_TOLERANCE);
            }
            v
        };
        let mut result = self
            .mesh_unverified(region, observer)
            .map_err(|e| preflight::explain_failure(e, region, h))?;
        let mut v = verify(&result);
        // fallback: a mesh of an automatically chosen layout with cells left folded (a block
        // whose transfinite start no untangling can fix, e.g. a side notched deeper than its
        // cells) or reaching out of the region (a boundary chord that skips a sharp reflex
        // vertex next to a block corner, with the cell behind it thinner than the excursion) is
        // re-made from the next candidate layout, best predicted first, at most
        // [`LAYOUT_FALLBACKS`] times; every attempt is named in the report's notes, and if none
        // passes, the attempt with the fewest such cells is the one reported
        let mut failed: Vec<String> = Vec::new();
        // the layout and the bad cells of the last attempt (the kept one may be an earlier one)
        let mut last;
        ((result, v), last) =
            self.layout_fallback(region, observer, &verify, (result, v), &mut failed);
        // holes narrower than a cell: with the default hole filter, a failure next to such a
        // hole is meshed again without every hole narrower than h ([`Mesher::drop_narrow_holes`])
        if !allow && !v.passed() && self.drop_narrow_holes && h > 0.0 {
            let default_filter = self
                .simplify
                .as_ref()
                .is_some_and(|o| o.holes == HoleFilter::KeepAll);
            let narrow = region
                .holes()
                .iter()
                .filter(|hole| unamalla_contour::hole_width(hole) < h)
                .count();
            if default_filter && narrow > 0 && preflight::small_hole(&v, region, h).is_some() {
                let note = format!(
                    "the mesh keeping every hole failed the guarantee next to a hole narrower than the cell size {h:.4e}; made again without the {narrow} hole(s) narrower than that (a cell size of at most half their width keeps them)"
                );
                self.stage(Stage::Decompose, &note);
                if let Some(o) = self.simplify.as_mut() {
                    o.holes = HoleFilter::MinWidth(h);
                }
                self.excluded_layouts.clear();
                if let Ok(retry) = self.mesh_unverified(region, observer) {
                    let rv = verify(&retry);
                    // the layout fallback once more, on the region without those holes
                    let mut notes = vec![note];
                    let ((retry, rv), rv_last) =
                        self.layout_fallback(region, observer, &verify, (retry, rv), &mut notes);
                    if rv.passed() {
                        failed.append(&mut notes);
                        result = retry;
                        v = rv;
                        last = rv_last;
                    }
                }
            }
        }
        // quality fallback: a mesh that passed but is below the quality target is re-made from
        // the next candidate layouts (best predicted first), keeping the best achieved share
        let mut quality_tries = 0;
        // the share of the last attempt (the kept one may be an earlier one)
        let mut last_share = result.report.mu_ge_0_8_percent;
        while !allow
            && self.quality_target > 0.0
            && v.passed()
            && result.report.mu_ge_0_8_percent < self.quality_target
            && quality_tries < QUALITY_FALLBACKS
        {
            let Some(name) = last.0.take() else {
                break;
            };
            quality_tries += 1;
            let note = format!(
                "layout {name} reached μ ≥ 0.8 on {last_share:.1} % of the cells, below the target {} %; re-made from the next candidate layout",
                self.quality_target
            );
            let Some((retry, rv)) =
                self.remake_excluding(name, note, &mut failed, region, observer, &verify)
            else {
                break;
            };
            last = (layout_name(&retry), bad_cells(&rv));
            let share = retry.report.mu_ge_0_8_percent;
            last_share = share;
            failed.push(format!(
                "layout {} reached μ ≥ 0.8 on {share:.1} % ({})",
                last.0.as_deref().unwrap_or("?"),
                if !rv.passed() {
                    "failed the guarantee: not kept"
                } else if share > result.report.mu_ge_0_8_percent {
                    "kept"
                } else {
                    "not better: not kept"
                }
            ));
            if rv.passed() && share > result.report.mu_ge_0_8_percent {
                result = retry;
                v = rv;
            }
        }
        if !failed.is_empty() {
            result.report.seconds = t_start.elapsed().as_secs_f64();
            let mut notes = failed;
            notes.append(&mut result.report.notes);
            result.report.notes = notes;
        }
        result.report.verification = v.clone();
        if !allow {
            v.into_result()
                .map_err(|e| preflight::explain_guarantee(e, region, h))?;
        }
        Ok(result)
    }

    /// The layout fallback of [`Mesher::mesh_observed`]: while the kept attempt `best` fails
    /// the guarantee with non-convex cells or cells outside the region, the mesh is re-made from
    /// the next candidate layout (the last attempt's layout excluded), at most
    /// [`LAYOUT_FALLBACKS`] times, each named in `notes`; the attempt with the fewest such cells
    /// is kept (the earlier on a tie; a passing one always). Returns the kept attempt and the
    /// layout and bad-cell count of the last one.
    fn layout_fallback(
        &mut self,
        region: &Region,
        observer: &mut dyn Observer,
        verify: &dyn Fn(&MeshResult) -> crate::verify::Verification,
        best: (MeshResult, crate::verify::Verification),
        notes: &mut Vec<String>,
    ) -> (
        (MeshResult, crate::verify::Verification),
        (Option<String>, usize),
    ) {
        let (mut result, mut v) = best;
        let mut last = (layout_name(&result), bad_cells(&v));
        let mut tries = 0;
        while !self.allow_non_convex && !v.passed() && last.1 > 0 && tries < LAYOUT_FALLBACKS {
            let (Some(name), bad) = (last.0.take(), last.1) else {
                break;
            };
            tries += 1;
            let note = format!(
                "layout {name} left {bad} cell(s) non-convex or outside the region; re-made from the next candidate layout"
            );
            // no candidate left, or the next one fails in a stage: keep what we have
            let Some((retry, rv)) =
                self.remake_excluding(name, note, notes, region, observer, verify)
            else {
                break;
            };
            last = (layout_name(&retry), bad_cells(&rv));
            if rv.passed() || bad_cells(&rv) < bad_cells(&v) {
                result = retry;
                v = rv;
            }
        }
        ((result, v), last)
    }

    /// One retry of the fallbacks of [`Mesher::mesh_observed`]: `note` goes to the progress
    /// line and to `notes`, layout `name` is excluded, and the mesh is re-made from the next
    /// candidate layout and verified; `None` when no candidate is left or a stage fails.
    fn remake_excluding(
        &mut self,
        name: String,
        note: String,
        notes: &mut Vec<String>,
        region: &Region,
        observer: &mut dyn Observer,
        verify: &dyn Fn(&MeshResult) -> crate::verify::Verification,
    ) -> Option<(MeshResult, crate::verify::Verification)> {
        self.stage(Stage::Decompose, &note);
        notes.push(note);
        self.excluded_layouts.push(name);
        let retry = self.mesh_unverified(region, observer).ok()?;
        let rv = verify(&retry);
        Some((retry, rv))
    }

    /// The pipeline without the checks of [`Mesher::mesh_observed`].
    fn mesh_unverified(
        &mut self,
        region: &Region,
        observer: &mut dyn Observer,
    ) -> Result<MeshResult, CoreError> {
        let t0 = Instant::now();
        let mut stage_seconds = Vec::new();
        let mut timer = Instant::now();
        let mut lap = |s: Stage, timer: &mut Instant| {
            stage_seconds.push((s, timer.elapsed().as_secs_f64()));
            *timer = Instant::now();
        };

        // 1. simplify, 1b. remove the features below the cell size
        self.stage(Stage::Simplify, "simplifying the contour");
        let prepared = self.prepare_region(region)?;
        let holes_dropped = prepared.holes_dropped;
        let neck_notes: Vec<String> = prepared.necks.iter().map(|c| c.to_string()).collect();
        // a decomposition file fits either region: ours (saved by a previous run) fits the one
        // without features, one made by hand for the simplified region fits the other
        // (validated here, once: the error names the simplified region when neither fits)
        let simplified = match &self.decomposition {
            Some(d) if d.validate(&prepared.mesh_region).is_err() => {
                d.validate(&prepared.simplified)?;
                prepared.simplified
            }
            _ => prepared.mesh_region,
        };
        lap(Stage::Simplify, &mut timer);

        // 2–6 by submapping (seed 002) when the strategy asks for it
        // notes of step 3 for the report (cells the counts cannot avoid)
        let mut counts_notes: Vec<String> = Vec::new();
        let submapping = match (self.strategy, self.decomposition.is_some()) {
            (Strategy::Submap, true) => {
                return Err(CoreError::Unsupported(
                    "a decomposition file and the submap strategy exclude each other".into(),
                ))
            }
            (Strategy::Submap, false) => {
                self.stage(Stage::Decompose, "submapping (seed 002)");
                Some(submap(
                    &simplified,
                    &SubmapOptions::new(self.submap_size(&simplified)),
                )?)
            }
            (Strategy::Auto, false) if prefers_submap(&simplified, AUTO_ANGLE_TOLERANCE_DEG) => {
                self.stage(Stage::Decompose, "submapping (seed 002, automatic choice)");
                submap(
                    &simplified,
                    &SubmapOptions::new(self.submap_size(&simplified)),
                )
                .ok()
            }
            _ => None,
        };
        let mut layout_choice: Option<LayoutChoice> = None;
        let (decomposition, counts, mut mesh) = match submapping.as_ref() {
            Some(s) => {
                lap(Stage::Decompose, &mut timer);
                lap(Stage::Counts, &mut timer);
                self.stage(Stage::Tfi, "transfinite interpolation per piece");
                let grids = s.grids()?;
                lap(Stage::Tfi, &mut timer);
                self.stage(Stage::Merge, "merging pieces");
                let mesh = BlockMesh2::merge(grids, 1e-9)?;
                lap(Stage::Merge, &mut timer);
                (s.to_decomposition(), None, mesh)
            }
            None => {
                // 2. decompose
                self.stage(Stage::Decompose, "decomposing into blocks");
                let decomposition = match self.decomposition.take() {
                    Some(d) => d,
                    None => {
                        // the chord layout samples the boundary at the cell size
                        let mut opts = self.decompose_opts.clone();
                        if opts.cell_size.is_none() {
                            opts.cell_size = match self.size {
                                MeshSize::Cells(n) => {
                                    Some((simplified.area() / n.max(1) as f64).sqrt())
                                }
                                MeshSize::CellSize(h) => Some(h),
                                MeshSize::Density(_) => None,
                            };
                        }
                        match self.layout {
                            Some(l) => {
                                opts.layout = l;
                                decompose(&simplified, &opts)?
                            }
                            None => {
                                let (d, choice) = choose_layout_excluding(
                                    &simplified,
                                    &opts,
                                    self.size,
                                    &self.excluded_layouts,
                                )?;
                                layout_choice = Some(choice);
                                d
                            }
                        }
                    }
                };
                lap(Stage::Decompose, &mut timer);

                // 3. compatible counts
                self.stage(Stage::Counts, "solving for compatible point counts");
                let step3 = crate::curves::compatible_counts(&decomposition, self.size)?;
                counts_notes = step3.notes;
                let (curves, counts) = (step3.curves, step3.solution);
                lap(Stage::Counts, &mut timer);

                // 4–5. reparametrize + TFI
                self.stage(Stage::Tfi, "transfinite interpolation per block");
                let grids = curves.grids(&decomposition, &counts.counts)?;
                lap(Stage::Tfi, &mut timer);

                // 6. merge
                self.stage(Stage::Merge, "merging blocks");
                let mesh = BlockMesh2::merge(grids, 1e-9)?;
                lap(Stage::Merge, &mut timer);
                (decomposition, Some(counts), mesh)
            }
        };

        // 6b. flat block corners on the boundary (triangle blocks): bent outward so their
        // cells can be convex
        let bent_corners =
            crate::flat_corners::bend_flat_corners(&mut mesh, self.flat_corner_deficit);

        // 7. smooth (region boundary fixed, cut nodes free)
        // (a mesh without interior nodes — every node on the region boundary, e.g. one cell
        // per block — has nothing to smooth: it is kept as the transfinite interpolation made it)
        let smoothing_status = if mesh.global().num_free() == 0 {
            self.stage(Stage::Smooth, "no interior node: nothing to smooth");
            lap(Stage::Smooth, &mut timer);
            "not smoothed: the mesh has no interior node".to_string()
        } else {
            self.stage(Stage::Smooth, "smoothing (convexity-preserving)");
            let mut sopts = self.smooth_opts.clone();
            if let unamalla_optim::SmoothFunctional::BlockSmoothing { density, .. } =
                &mut sopts.functional
            {
                *density = self.boundary_density;
            }
            // the explicit time limit (if any) counts from the start of the stage
            let t_stage = Instant::now();
            sopts.time_limit = self.time_limit;
            // 7-. a start prolonged from smoothed coarse levels ([`crate::multilevel`]); when it is
            // used, the untangling below has nothing to do (the start is convex)
            let coarse = match (&counts, submapping.is_none()) {
                (Some(c), true) => crate::multilevel::coarse_start(
                    &decomposition,
                    self.size,
                    &mesh,
                    &c.counts,
                    &sopts,
                    crate::multilevel::CoarseLevels {
                        levels: self.coarse_levels,
                        flat_corner_deficit: self.flat_corner_deficit,
                    },
                    observer,
                )?,
                _ => None,
            };
            if let Some(c) = &coarse {
                self.stage(Stage::Smooth, &c.summary());
                if c.accepted {
                    mesh.global_mut().nodes_mut().copy_from_slice(&c.nodes);
                    sopts = crate::multilevel::polish_options(&sopts);
                }
            }
            // 7a. the folded cells (TFI of a wiggly block) are untangled in local patches across
            // block boundaries ([`crate::untangle`]): small problems converge in far fewer
            // iterations than the global one, the work is bounded by iteration limits (not
            // wall-clock time, so the result does not depend on the load), and the global run
            // below then starts convex (or nearly so)
            let patches = crate::untangle::untangle_patches_observed(
                mesh.global_mut(),
                &sopts,
                &crate::untangle::DEFAULT_PATCH_RADII,
                observer,
            )?;
            if patches.before > 0 {
                mesh.sync_blocks();
                let msg = format!(
                    "untangled {} → {} non-convex cells in {} local patch(es) (radius ≤ {}, {} iterations, {:.2} s)",
                    patches.before,
                    patches.after,
                    patches.patches,
                    patches.max_radius,
                    patches.iterations,
                    t_stage.elapsed().as_secs_f64()
                );
                self.stage(Stage::Smooth, &msg);
                if !patches.unresolved.is_empty() {
                    let msg = format!(
                        "{} fold(s) could not be removed by local patches{} (cells {:?}{}); left to the global run",
                        patches.unresolved.len(),
                        if patches.cancelled { " (cancelled)" } else { "" },
                        &patches.unresolved[..patches.unresolved.len().min(8)],
                        if patches.unresolved.len() > 8 { ", …" } else { "" },
                    );
                    self.stage(Stage::Smooth, &msg);
                }
            }
            // 7b. the global run, ended by the convergence tests of `sopts.solver.stop`
            if let Some(t) = self.time_limit {
                sopts.time_limit = Some((t - t_stage.elapsed().as_secs_f64()).max(0.0));
            }
            let smoothing = smooth(&mut mesh, &sopts, observer)?;
            mesh.sync_blocks();
            lap(Stage::Smooth, &mut timer);
            smoothing.status.to_string()
        };

        // 7c. local shape improvement, the region-boundary nodes sliding along the boundary
        // ([`unamalla_optim::shape`]): the smoother keeps them where the transfinite
        // interpolation put them, so rows of cells meeting the boundary obliquely stay sheared
        let shape = match self.shape.clone() {
            Some(o) if o.max_sweeps > 0 => {
                self.stage(Stage::Shape, "shape pass (boundary nodes sliding)");
                let slide = BoundarySlide::new(mesh.global(), &simplified, o.feature_angle_deg);
                let r = improve_shape(mesh.global_mut(), Some(&slide), &o, observer);
                mesh.sync_blocks();
                self.stage(
                    Stage::Shape,
                    &format!(
                        "shape pass: μ ≥ {} on {:.1} → {:.1} % of the cells ({} sweeps, {} moves, {} slides)",
                        o.keep, r.good_before, r.good_after, r.sweeps, r.moved, r.slid
                    ),
                );
                lap(Stage::Shape, &mut timer);
                Some(r)
            }
            _ => None,
        };

        // 8. report
        self.stage(Stage::Report, "quality report");
        let quality = QualityReport::for_quads(&mesh);
        let q = quality.quad.as_ref();
        let sj = quality.metric("scaled_jacobian");
        let mesh_area: f64 = (0..mesh.num_quads())
            .map(|c| polygon_area(&mesh.quad_points(c)))
            .sum();
        let area_change_percent = (mesh_area - region.area()).abs() / region.area() * 100.0;
        let hausdorff = boundary_hausdorff(&mesh, region);
        lap(Stage::Report, &mut timer);
        let report = MeshReport {
            region: String::new(),
            cells: mesh.num_quads(),
            nodes: mesh.num_nodes(),
            blocks: mesh.blocks().len(),
            strategy: if submapping.is_some() {
                Strategy::Submap
            } else {
                Strategy::Cuts
            },
            non_convex_cells: quality.non_convex_cells,
            interior_singularities: q.map_or(0, |q| q.interior_singularities),
            bent_corners,
            mu_ge_0_8_percent: q.map_or(0.0, |q| q.mu_bands.good),
            mu_bands: q.map_or([0.0; 3], |q| {
                [q.mu_bands.good, q.mu_bands.fair, q.mu_bands.poor]
            }),
            min_scaled_jacobian: sj.map_or(f64::NAN, |m| m.min),
            p5_scaled_jacobian: sj.map_or(f64::NAN, |m| m.p5),
            min_alpha_over_mean: q.map_or(f64::NAN, |q| q.alpha_min_ratio),
            area_change_percent,
            hausdorff,
            holes_dropped,
            smoothing: smoothing_status,
            shape,
            seconds: t0.elapsed().as_secs_f64(),
            stage_seconds,
            block_quality: layout_choice
                .as_ref()
                .map(|c| {
                    c.blocks
                        .iter()
                        .enumerate()
                        .filter(|(b, _)| *b < mesh.blocks().len())
                        .map(|(b, &p)| {
                            let (a, cells) = crate::predict::block_good_share(&mesh, b);
                            BlockQuality {
                                block: b,
                                cells,
                                predicted: 100.0 * p,
                                achieved: 100.0 * a,
                            }
                        })
                        .collect()
                })
                .unwrap_or_default(),
            layout: layout_choice,
            quality,
            notes: neck_notes.into_iter().chain(counts_notes).collect(),
            verification: Default::default(),
        };
        Ok(MeshResult {
            simplified,
            decomposition,
            counts,
            submap: submapping,
            mesh,
            report,
        })
    }
}

/// The region after pipeline steps 1 and 1b ([`Mesher::prepare_region`]).
#[derive(Debug, Clone)]
pub struct PreparedRegion {
    /// After the contour simplification ([`simplify_for_mesh`]); the input region itself
    /// without simplification.
    pub simplified: Region,
    /// After the removal of boundary features below the cell size: the region that is meshed.
    pub mesh_region: Region,
    /// Input holes dropped by the simplification (indices in input order).
    pub holes_dropped: Vec<usize>,
    /// Spits and inlets cut off at their necks ([`Mesher::neck_factor`]).
    pub necks: Vec<unamalla_contour::NeckCut>,
}

/// Largest relative area change (a fraction) the pipeline accepts from the contour
/// simplification before it retries with a smaller threshold (see [`simplify_for_mesh`]).
pub const MAX_SIMPLIFY_AREA_CHANGE: f64 = 0.01;

/// The contour simplification of pipeline step 1: [`simplify_region`] with `opts`, retried with
/// the threshold ε halved (at most six times) while the region's area changes by more than
/// [`MAX_SIMPLIFY_AREA_CHANGE`] — unless the finer result has a vertex almost touching another
/// edge (closer than 10⁻⁶ of the region's size), which the coarser one had removed. The thesis's default thresholds are tuned for dense, noisy
/// contours; on a coarse silhouette of a few dozen vertices the same ε removes real shape (the
/// bundled `horse` lost 2.1 % of its area). Use this function to reproduce the pipeline's
/// simplified region (e.g. to validate a decomposition file against it).
pub fn simplify_for_mesh(
    region: &Region,
    opts: &SimplifyOptions,
) -> Result<unamalla_contour::SimplifyResult, CoreError> {
    let mut r = simplify_region(region, opts)?;
    for _ in 0..6 {
        if r.relative_area_change.abs() <= MAX_SIMPLIFY_AREA_CHANGE {
            break;
        }
        let smaller = SimplifyOptions {
            epsilon: Some(0.5 * r.epsilon),
            ..opts.clone()
        };
        let retry = simplify_region(region, &smaller)?;
        // keep the coarser result when the finer one brings back a near contact (a vertex
        // within 10⁻⁶ of the region's size of a non-adjacent edge): no mesh can resolve it
        if nearly_touching(&retry.region, 1e-6) {
            break;
        }
        r = retry;
    }
    Ok(r)
}

/// Whether some vertex of `region` lies within `rel·diag` (diag = bounding-box diagonal) of an
/// edge of any ring other than its two own edges.
fn nearly_touching(region: &Region, rel: f64) -> bool {
    let (lo, hi) = region.bounding_box();
    let tol = rel * (hi - lo).length();
    let index = region.edge_index();
    let rings = index.rings();
    rings.iter().enumerate().any(|(ri, ring)| {
        let n = ring.len();
        ring.iter().enumerate().any(|(i, &p)| {
            let d = DVec2::splat(tol);
            index.candidates(p - d, p + d).any(|e| {
                let own = e.ring == ri && (e.edge == i || (e.edge + 1) % n == i);
                let (a, b) = index.edge(e);
                !own && unamalla_mesh::geometry::point_segment_distance(p, a, b) <= tol
            })
        })
    })
}

/// Weight σ of H_ω in the pipeline's smoothing functional (6.8), `(1 − σ)·F_AO + σ·H_ω`.
///
/// The thesis's examples use σ = 0.1 (seed 000, the Laguna Honda region); the pipeline uses
/// 0.5. Measured with the `smooth_study` example on the 34 development regions (docs/results.md,
/// "Smoothing weight σ"): at σ = 0.1 the converged meshes of large open blocks whose cells are
/// anisotropic (the compatible counts make them 1.5–2.5 times longer than wide) are **buckled**
/// — grid lines in herringbone waves, with diagonal stripes of sheared cells (μ 0.6–0.8) a few
/// cells apart — because the area–orthogonality term is nearly singular for diagonal shear
/// waves (its Hessian's Rayleigh quotient is about `2θ⁴` for wave number θ, against `16θ²`
/// for the other polarisation; the test `area_orthogonality_hessian_is_weak_for_diagonal_shear_waves`
/// of `unamalla-functionals`) and H_ω at weight 0.1 does not hold them; running the σ = 0.1
/// smoother to its FTOL (88 iterations instead of 51) does not remove the stripes. With
/// σ = 0.5 the μ ≥ 0.8 share rose on **every** region at 5,000 cells (by 0.2–7 points; 22 → 26
/// regions at ≥ 90 %) and at 20,000 cells (by 0.1–3.9 points; 30 → 33) with about half the
/// iterations; σ = 0.3 and σ = 0.7 were close behind, σ = 1 (H_ω alone) lost on the
/// silhouettes (crow 74.7 % at 5,000 cells).
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
/// 1 % and the μ ≥ 0.8 share by less than 0.05 points.
pub const DEFAULT_STOP_RULES: unamalla_optim::StopRules = unamalla_optim::StopRules {
    window: 10,
    window_ftol: 1e-4,
    plateau_alpha: 0.01,
    plateau_share: 0.05,
};

/// The automatically chosen layout of a mesh (`None`: the layout was given).
fn layout_name(result: &MeshResult) -> Option<String> {
    result.report.layout.as_ref().map(|c| c.layout.clone())
}

/// The cells a layout fallback counts against an attempt: non-convex, or with the centroid
/// outside the region.
fn bad_cells(v: &crate::verify::Verification) -> usize {
    v.non_convex_cells + v.centroids_outside.unwrap_or(0)
}

fn polygon_area(p: &[DVec2]) -> f64 {
    unamalla_mesh::region::signed_area(p)
}

/// The Hausdorff distance between the mesh's boundary loops and the region's rings: each mesh
/// loop is compared with the input ring it approximates (the outer loop with the outer ring, each
/// hole loop with the input hole whose centroid is nearest).
fn boundary_hausdorff(mesh: &BlockMesh2, region: &Region) -> f64 {
    let loops = unamalla_io::msh::boundary_loops(mesh);
    let nodes = mesh.nodes();
    let centroid = |p: &[DVec2]| p.iter().copied().sum::<DVec2>() / p.len().max(1) as f64;
    let mut worst: f64 = 0.0;
    for l in &loops {
        let pts: Vec<DVec2> = l.edges.iter().map(|e| nodes[e[0]]).collect();
        let target = if l.signed_area > 0.0 {
            region.outer().points()
        } else {
            let c = centroid(&pts);
            match region.holes().iter().min_by(|a, b| {
                centroid(a.points())
                    .distance(c)
                    .total_cmp(&centroid(b.points()).distance(c))
            }) {
                Some(h) => h.points(),
                None => continue,
            }
        };
        worst = worst.max(unamalla_contour::hausdorff(&pts, target));
    }
    worst
}

/// At most this many other candidate layouts are tried after the automatically chosen one
/// left non-convex cells or cells outside the region ([`Mesher::mesh_observed`]); each try is
/// a whole run of the pipeline, so the work is bounded by `1 + LAYOUT_FALLBACKS` runs.
pub const LAYOUT_FALLBACKS: usize = 2;

/// Default of [`Mesher::quality_target`]: μ ≥ 0.8 on 90 % of the cells, the acceptance level
/// of the project's region tables (and of `unamalla mesh --strict`).
pub const QUALITY_TARGET_PERCENT: f64 = 90.0;

/// At most this many other candidate layouts are tried after the automatically chosen one
/// passed the guarantee below [`Mesher::quality_target`]; with [`LAYOUT_FALLBACKS`] the work
/// is bounded by `1 + LAYOUT_FALLBACKS + QUALITY_FALLBACKS` runs of the pipeline.
pub const QUALITY_FALLBACKS: usize = 2;

/// Margin (share of cells) by which the chord layout's prediction must beat the concavity
/// layout's to be chosen: the prediction is made on a coarse mesh with a few Laplacian sweeps,
/// so differences below a percent are not resolved by it (`tests/predictor.rs`).
pub const LAYOUT_MARGIN: f64 = 0.01;

/// The chord layouts [`choose_layout`] tries: aspect thresholds T of the transverse cuts
/// (`unamalla_decompose::chords`). Measured with the predictor on the 34 development regions
/// at 20,000 cells (`layout_eval --predict-only --aspect T`): mean predicted μ ≥ 0.8 share of
/// the chord layout alone 86.9 % (T = 0.35), 84.0 % (0.75), 82.8 % (1.5), 81.9 % (2), 81.0 %
/// (3), against 83.0 % for the concavity layout; no single T is best on every region, the best
/// of the three per region averages 89.4 %.
pub const LAYOUT_ASPECTS: [(&str, f64); 3] = [
    ("chords-0.35", 0.35),
    ("chords-0.75", 0.75),
    ("chords-1.5", 1.5),
];

/// Predicted-quality re-split: at most this many candidate cuts are tried
/// ([`choose_layout`]).
pub const RESPLIT_EVALS: usize = 8;
/// Layouts with more blocks than this are not re-split: every candidate rebuilds and predicts
/// the whole layout (work linear in the blocks), so the re-split's work is bounded by
/// `RESPLIT_EVALS` rebuilds of a layout of at most this size.
pub const RESPLIT_MAX_BLOCKS: usize = 150;
/// A block is a re-split candidate while its predicted μ ≥ 0.8 share is below this.
pub const RESPLIT_BELOW: f64 = 0.9;
/// Smallest chord score `min(A₁, A₂)/w²` of a re-split cut: the smaller part extends at
/// least half a chord width beyond it (a half disc at its base scores π/8 ≈ 0.39, so a cape
/// is not cut off).
pub const RESPLIT_SCORE: f64 = 0.5;
/// A re-split cut leaves at least this many cells of the requested size on its smaller side
/// (a cut off a smaller feature cannot change the mesh beyond its few cells).
pub const RESPLIT_CELLS: f64 = 16.0;
/// A re-split cut is kept when it raises the predicted share of the whole mesh by at least
/// this much (a fifth of a percentage point; the prediction resolves differences of that
/// order between layouts that differ in one block).
pub const RESPLIT_GAIN: f64 = 0.002;

/// Which layout [`Mesher`] chose, and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LayoutChoice {
    /// `"concavity"` or `"chords-T"` (T the aspect threshold, [`LAYOUT_ASPECTS`]).
    pub layout: String,
    /// Predicted μ ≥ 0.8 percentage of the chosen layout.
    pub predicted_percent: f64,
    /// Predicted μ ≥ 0.8 percentage of every candidate (`(layout, percent)`; a candidate that
    /// could not be built or predicted is absent).
    pub candidates: Vec<(String, f64)>,
    /// Predicted μ ≥ 0.8 share per block of the chosen layout.
    pub blocks: Vec<f64>,
    /// Cuts added to the chosen layout by the predicted-quality re-split (each raised the
    /// predicted share by at least [`RESPLIT_GAIN`]).
    pub resplit_cuts: usize,
    /// Candidate cuts the re-split evaluated (at most [`RESPLIT_EVALS`]).
    pub resplit_tried: usize,
}

/// Rule breaks of a layout: interior singularities of its coarse mesh (cut joints, which the
/// triangle-block rule makes when it must split a cut) plus blocks that are not admissible.
fn rule_breaks(
    d: &Decomposition,
    p: &crate::predict::Prediction,
    opts: &DecomposeOptions,
) -> usize {
    let bad: Vec<usize> = (0..d.blocks.len())
        .filter(|&b| !d.block_admissible(b, &opts.tolerances))
        .collect();
    if std::env::var_os("UNAMALLA_LAYOUT_DEBUG").is_some() {
        for &b in &bad {
            let blk = &d.blocks[b];
            let c = unamalla_decompose::concavity(&blk.ring);
            let crit = unamalla_decompose::critical_angles(&blk.ring, opts.tolerances.theta_minus);
            eprintln!(
                "  inadmissible block {b}: {} vertices, area {:.4e}, triangle {}, convex {}, kappa {:.3} {:.3} {:.3} {:.3}, critical {:?} at {:?}",
                blk.ring.len(),
                blk.area(),
                blk.triangle,
                c.approximately_convex(&opts.tolerances),
                c.kappa1, c.kappa2, c.kappa3, c.kappa4,
                crit,
                blk.ring.first()
            );
        }
    }
    p.singularities + bad.len()
}

/// Builds the concavity layout and the chord layouts of [`LAYOUT_ASPECTS`] of `region` and
/// keeps the one with the highest predicted μ ≥ 0.8 share ([`crate::predict::predict_mesh`]):
/// a layout whose coarse mesh has fewer interior singularities always wins; then the predicted
/// share decides (the concavity layout wins ties within [`LAYOUT_MARGIN`]), then fewer
/// non-admissible blocks, then fewer blocks. (Until 2026-12-06 non-admissible blocks counted
/// with the singularities, before the prediction; measured on the 34 development regions:
/// docs/results.md, "Seventh pass".)
///
/// A chosen chord layout is then **re-split by the prediction**: the block with the most
/// predicted bad cells (`(1 − share)·cells`, share below [`RESPLIT_BELOW`]) that has a chord
/// of score ≥ [`RESPLIT_SCORE`] between boundary points or layout cuts
/// ([`unamalla_decompose::split_chord`]) gets it as one more layout cut; the layout is rebuilt
/// ([`unamalla_decompose::layout_from_cuts`]) and predicted again, and the cut is kept when the
/// predicted share rises by at least [`RESPLIT_GAIN`] without more rule breaks. At most
/// [`RESPLIT_EVALS`] candidates are tried, on layouts of at most [`RESPLIT_MAX_BLOCKS`]
/// blocks, so the work is bounded.
pub fn choose_layout(
    region: &Region,
    opts: &DecomposeOptions,
    size: MeshSize,
) -> Result<(Decomposition, LayoutChoice), CoreError> {
    choose_layout_excluding(region, opts, size, &[])
}

/// [`choose_layout`] without the candidates named in `excluded` (the names of
/// [`LayoutChoice::layout`]: `concavity` and those of [`LAYOUT_ASPECTS`]); when every
/// candidate is excluded, the same error as when none can be built.
pub fn choose_layout_excluding(
    region: &Region,
    opts: &DecomposeOptions,
    size: MeshSize,
    excluded: &[String],
) -> Result<(Decomposition, LayoutChoice), CoreError> {
    // (name, layout cuts for a chord layout, decomposition)
    type Cand = (&'static str, Option<Vec<(DVec2, DVec2)>>, Decomposition);
    // the candidate layouts are independent: built (and predicted below) in parallel, the
    // results kept in the order of the list, so the choice does not depend on the threads
    let conc_opts = DecomposeOptions {
        layout: Layout::Concavity,
        ..opts.clone()
    };
    let (conc, chord_layouts) = rayon::join(
        || decompose(region, &conc_opts),
        || {
            LAYOUT_ASPECTS
                .par_iter()
                .map(|&(name, aspect)| {
                    let o = DecomposeOptions {
                        chord_aspect: aspect,
                        ..opts.clone()
                    };
                    (name, chord_layout_cuts(region, &o))
                })
                .collect::<Vec<_>>()
        },
    );
    let mut cands: Vec<Cand> = Vec::new();
    let conc_err = match conc {
        Ok(d) => {
            cands.push(("concavity", None, d));
            None
        }
        Err(e) => Some(e),
    };
    for (name, built) in chord_layouts {
        if let Ok((cuts, d)) = built {
            if !cands.iter().any(|(_, _, c)| *c == d) {
                cands.push((name, Some(cuts), d));
            }
        }
    }
    cands.retain(|(name, _, _)| !excluded.iter().any(|e| e == name));
    let predictions: Vec<_> = cands
        .par_iter()
        .map(|(_, _, d)| crate::predict::predict_mesh(d, size))
        .collect();
    // key: fewer interior singularities, then the predicted share, then fewer rule breaks,
    // then fewer blocks
    type Key = (usize, f64, usize, usize);
    let mut best: Option<(Key, usize, crate::predict::Prediction)> = None;
    let mut scores = Vec::new();
    for (k, ((name, _, d), pred)) in cands.iter().zip(predictions).enumerate() {
        let Ok(p) = pred else {
            continue;
        };
        scores.push((name.to_string(), 100.0 * p.good_share));
        let share = p.good_share
            + if *name == "concavity" {
                LAYOUT_MARGIN
            } else {
                0.0
            };
        // interior singularities are a hard rule (the mesh must have none); a block that is not
        // admissible (a corner below the critical angle) only costs the cells the prediction
        // already counts, so the predicted share decides before it (norway-mainland at
        // 100,000 cells: the layout with the fewest such blocks was predicted 12 points below
        // the best; docs/results.md, "Seventh pass")
        let key = (
            p.singularities,
            share,
            rule_breaks(d, &p, opts),
            d.blocks.len(),
        );
        if std::env::var_os("UNAMALLA_LAYOUT_DEBUG").is_some() {
            eprintln!(
                "layout {name}: {} blocks, predicted {:.2} %, {} singular nodes, {} rule breaks",
                d.blocks.len(),
                100.0 * p.good_share,
                p.singularities,
                key.0
            );
        }
        let better = match &best {
            None => true,
            Some((bk, _, _)) => {
                key.0 < bk.0
                    || (key.0 == bk.0
                        && (key.1 > bk.1 || (key.1 == bk.1 && (key.2, key.3) < (bk.2, bk.3))))
            }
        };
        if better {
            best = Some((key, k, p));
        }
    }
    match best {
        Some((_, k, p)) => {
            let (name, cuts, d) = cands.swap_remove(k);
            let aspect = LAYOUT_ASPECTS
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, a)| *a);
            let (d, p, added, tried) = match (cuts, aspect) {
                (Some(cuts), Some(aspect)) => {
                    let o = DecomposeOptions {
                        chord_aspect: aspect,
                        ..opts.clone()
                    };
                    resplit(region, &o, size, cuts, d, p)
                }
                _ => (d, p, 0, 0),
            };
            let choice = LayoutChoice {
                layout: name.to_string(),
                predicted_percent: 100.0 * p.good_share,
                candidates: scores,
                blocks: p.blocks,
                resplit_cuts: added,
                resplit_tried: tried,
            };
            Ok((d, choice))
        }
        None => match cands.pop() {
            Some((name, _, d)) => Ok((
                d,
                LayoutChoice {
                    layout: name.to_string(),
                    predicted_percent: f64::NAN,
                    candidates: scores,
                    blocks: Vec::new(),
                    resplit_cuts: 0,
                    resplit_tried: 0,
                },
            )),
            None => Err(conc_err
                .map(CoreError::from)
                .unwrap_or_else(|| CoreError::Unsupported("no layout".into()))),
        },
    }
}

/// The split chords found by [`resplit`], by (block geometry key, number of layout cuts).
type ChordCache = std::collections::HashMap<(Vec<u64>, usize), Option<(DVec2, DVec2)>>;

/// The predicted-quality re-split of a chord layout ([`choose_layout`]): returns the
/// decomposition, its prediction, the cuts added and the candidates tried.
fn resplit(
    region: &Region,
    opts: &DecomposeOptions,
    size: MeshSize,
    mut cuts: Vec<(DVec2, DVec2)>,
    mut d: Decomposition,
    mut p: crate::predict::Prediction,
) -> (Decomposition, crate::predict::Prediction, usize, usize) {
    let mut breaks = rule_breaks(&d, &p, opts);
    // a cut must leave at least RESPLIT_CELLS cells of the requested size on its smaller side
    let area = crate::curves::decomposition_area(&d);
    let h2 = match size {
        MeshSize::Cells(n) => area / n.max(1) as f64,
        MeshSize::CellSize(h) => h * h,
        _ => area / 20_000.0,
    };
    let min_area = RESPLIT_CELLS * h2;
    let mut tried: Vec<(DVec2, DVec2)> = Vec::new();
    let mut searched: ChordCache = ChordCache::new();
    let mut added = 0;
    while tried.len() < RESPLIT_EVALS && d.blocks.len() <= RESPLIT_MAX_BLOCKS {
        let mut order: Vec<(f64, usize)> = (0..d.blocks.len().min(p.blocks.len()))
            .filter(|&b| p.blocks[b] < RESPLIT_BELOW)
            .map(|b| ((1.0 - p.blocks[b]) * p.block_cells[b] as f64, b))
            .collect();
        order.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
        let cand = order.iter().find_map(|&(_, b)| {
            // a block's chord depends on its ring and on the layout cuts, which only grow
            // (by an accepted cut): each (ring, layout) is searched once
            let key = (d.blocks[b].geometry_key(), cuts.len());
            let chord = *searched
                .entry(key)
                .or_insert_with(|| split_chord(region, &d, b, &cuts, RESPLIT_SCORE, min_area));
            chord.filter(|c| !tried.contains(c))
        });
        let Some(c) = cand else {
            break;
        };
        tried.push(c);
        let mut next = cuts.clone();
        next.push(c);
        let Ok(nd) = layout_from_cuts(region, opts, &next) else {
            continue;
        };
        if nd == d {
            continue;
        }
        let Ok(np) = crate::predict::predict_mesh(&nd, size) else {
            continue;
        };
        let nb = rule_breaks(&nd, &np, opts);
        if std::env::var_os("UNAMALLA_LAYOUT_DEBUG").is_some() {
            eprintln!(
                "re-split candidate {:?}-{:?}: {} -> {} blocks, {:.2} % -> {:.2} %, breaks {breaks} -> {nb}",
                c.0,
                c.1,
                d.blocks.len(),
                nd.blocks.len(),
                100.0 * p.good_share,
                100.0 * np.good_share
            );
        }
        if nb <= breaks && np.good_share >= p.good_share + RESPLIT_GAIN {
            if std::env::var_os("UNAMALLA_LAYOUT_DEBUG").is_some() {
                eprintln!(
                    "re-split: {:?}-{:?} predicted {:.2} % -> {:.2} %",
                    c.0,
                    c.1,
                    100.0 * p.good_share,
                    100.0 * np.good_share
                );
            }
            cuts = next;
            d = nd;
            p = np;
            breaks = nb;
            added += 1;
        }
    }
    (d, p, added, tried.len())
}

/// Predicted and achieved μ ≥ 0.8 share of one block (report.json `block_quality`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BlockQuality {
    /// Block id.
    pub block: usize,
    /// Cells of the block in the final mesh.
    pub cells: usize,
    /// Predicted μ ≥ 0.8 percentage ([`crate::predict`]).
    pub predicted: f64,
    /// Achieved μ ≥ 0.8 percentage in the final mesh.
    pub achieved: f64,
}
