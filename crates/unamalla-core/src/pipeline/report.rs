//! The `report.json` of a run: [`MeshReport`] and the per-block [`BlockQuality`].

use super::*;

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
    /// Input holes left out of the block layout and carved back into the mesh
    /// ([`Mesher::carve_dropped_holes`]; indices in input order).
    pub holes_carved: Vec<usize>,
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

/// Predicted and achieved μ ≥ 0.8 share of one block (report.json `block_quality`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BlockQuality {
    /// Block id.
    pub block: usize,
    /// Cells of the block in the final mesh (of the pieces it was split into around carved
    /// islands, [`MeshReport::holes_carved`]).
    pub cells: usize,
    /// Predicted μ ≥ 0.8 percentage ([`crate::predict`]).
    pub predicted: f64,
    /// Achieved μ ≥ 0.8 percentage in the final mesh.
    pub achieved: f64,
}
