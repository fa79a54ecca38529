//! Pipeline step 3: the compatible point counts of the curves `Q_j` of every block side for a
//! [`MeshSize`] ([`compatible_counts`]).
//!
//! The curves and the compatibility problem (5.1)–(5.4) of `unamalla-compat-ilp` come from
//! [`BlockCurves`] (`unamalla-decompose`); this module chooses the counts: the target fit for a
//! cell count or size with the cell-budget loop, or problem (5.10) for a density factor.

use unamalla_compat_ilp as ilp;
use unamalla_decompose::curves::{points_for_deviation, BlockCurves};
use unamalla_decompose::Decomposition;
use unamalla_mesh::resample::polyline_length;

use crate::pipeline::MeshSize;
use crate::CoreError;

/// The area of the decomposed region: the sum of the block areas.
pub fn decomposition_area(d: &Decomposition) -> f64 {
    d.blocks.iter().map(|b| b.area()).sum()
}

/// Relative tolerance of the cell budget loop of [`compatible_counts`]: the cell size is rescaled
/// until the predicted cell count is within 2 % of the request.
pub const BUDGET_TOLERANCE: f64 = 0.02;

/// Largest number of target fits of the cell budget loop.
pub const BUDGET_ITERATIONS: usize = 8;

/// Smallest number of points on a curve of a hole's boundary: two segments, so that no hole
/// collapses to a single edge of a block side (a resolution bound that keeps small islands
/// meshable).
pub const HOLE_MIN_POINTS: usize = 3;

/// The resolution bound of the boundary curves: every curve gets at least the points that keep
/// its resampled polyline within `DEVIATION_FACTOR·h` of the region boundary
/// ([`points_for_deviation`]), so that a coarse count cannot bridge an inlet or cut across a
/// thin island with a chord (a cell there would lie outside the region). h/4 still left one cell
/// centroid outside norway-mainland at 5000 cells (a 3-point curve deviating 1.7 = 0.22·h next
/// to thin cells at a block corner); h/8 is the measured value (docs/results.md, "Cell budget").
pub const DEVIATION_FACTOR: f64 = 0.125;

/// Relative deviation from the requested cell count above which [`compatible_counts`] explains
/// which curves force the cells ([`CompatibleCounts::notes`]).
pub const BUDGET_REPORT_TOLERANCE: f64 = 0.15;

/// The result of pipeline step 3 ([`compatible_counts`]).
#[derive(Debug, Clone)]
pub struct CompatibleCounts {
    /// The curves the counts are indexed by.
    pub curves: BlockCurves,
    /// The counts (verified by `unamalla-compat-ilp`).
    pub solution: ilp::CompatSolution,
    /// The cells the counts make ([`BlockCurves::predicted_cells`]).
    pub predicted_cells: usize,
    /// The requested cell count (`N`, or `area/h²` for a cell size `h`); `None` in density mode.
    pub requested_cells: Option<usize>,
    /// The cell size of the final target fit (after the budget loop); `None` in density mode.
    pub cell_size: Option<f64>,
    /// Target fits run by the budget loop (0 in density mode).
    pub iterations: usize,
    /// When the predicted count misses the request by more than [`BUDGET_REPORT_TOLERANCE`]:
    /// which curves force how many cells.
    pub notes: Vec<String>,
}

/// The compatible point counts of pipeline step 3 for a decomposition and a mesh size (the
/// region's area is the sum of the block areas).
///
/// * [`MeshSize::Cells`]`(N)` and [`MeshSize::CellSize`]`(h)` (request `N = area/h²`): the
///   **target fit** [`ilp::solve_fit`] — every curve close to `ℓ_j/h + 1` points, deviations paid
///   in cells, opposite sides equal, both copies of a cut equal, at least 2 points per curve,
///   [`HOLE_MIN_POINTS`] on hole boundaries and the resolution bound of [`DEVIATION_FACTOR`] on
///   boundary curves. The predicted count `C(h) = Σ_k (n_b − 1)(n_l − 1)`
///   is brought to `N` by rescaling `h ← h·√(C/N)` (cells scale like `h⁻²`) until
///   `|C/N − 1| ≤` [`BUDGET_TOLERANCE`] or [`BUDGET_ITERATIONS`] fits were run (the fit closest
///   to `N` is kept). Starts at `h = √(area/N)` or the given `h`.
/// * [`MeshSize::Density`]`(d)`: problem (5.10) with the density bounds ([Méndez 2023, (5.9)]).
pub fn compatible_counts(d: &Decomposition, size: MeshSize) -> Result<CompatibleCounts, CoreError> {
    let curves = BlockCurves::new(d);
    let problem = curves.problem();
    let area = decomposition_area(d);
    let (requested, h0) = match size {
        MeshSize::Density(dens) => {
            let opts = ilp::SolveOptions::density(dens.max(1));
            let solution = ilp::solve(&problem, &opts)?;
            let predicted_cells = curves.predicted_cells(&solution.counts);
            return Ok(CompatibleCounts {
                curves,
                solution,
                predicted_cells,
                requested_cells: None,
                cell_size: None,
                iterations: 0,
                notes: Vec::new(),
            });
        }
        MeshSize::Cells(n) => {
            let n = n.max(1);
            (n, (area / n as f64).sqrt())
        }
        MeshSize::CellSize(h) => {
            if !(h.is_finite() && h > 0.0) {
                return Err(ilp::CompatError::InvalidParameter(format!(
                    "the target cell size must be finite and > 0, got {h}"
                ))
                .into());
            }
            (((area / (h * h)).round() as usize).max(1), h)
        }
    };
    let want = requested as f64;
    let fit = |h: f64| -> Result<(ilp::FitTargets, ilp::CompatSolution), CoreError> {
        let mut targets = ilp::FitTargets::for_cell_size(&problem, h)?;
        for (j, m) in targets.minimums.iter_mut().enumerate() {
            if let Some(ring) = curves.ring(j) {
                if ring > 0 {
                    *m = (*m).max(HOLE_MIN_POINTS);
                }
                // the resolution bound: the mesh boundary within DEVIATION_FACTOR·h
                let p = curves.points(j);
                let hi = 2 * (polyline_length(p) / h).ceil() as usize + 2;
                *m = (*m).max(points_for_deviation(p, DEVIATION_FACTOR * h, hi));
            }
        }
        let sol = ilp::solve_fit(&problem, &targets, &ilp::FitOptions::default())?;
        Ok((targets, sol))
    };
    let mut h = h0;
    let mut best: Option<(f64, ilp::FitTargets, ilp::CompatSolution, usize)> = None;
    let mut iterations = 0;
    for _ in 0..BUDGET_ITERATIONS {
        iterations += 1;
        let (targets, sol) = fit(h)?;
        let cells = curves.predicted_cells(&sol.counts);
        let miss = |c: usize| (c as f64 / want - 1.0).abs();
        if best.as_ref().is_none_or(|b| miss(cells) < miss(b.3)) {
            best = Some((h, targets, sol, cells));
        }
        if miss(cells) <= BUDGET_TOLERANCE || cells == 0 {
            break;
        }
        let next = h * (cells as f64 / want).sqrt();
        // a fit that no longer changes with h (minimums bind everywhere) ends the loop
        if !(next.is_finite() && next > 0.0) || (next / h - 1.0).abs() < 1e-6 {
            break;
        }
        h = next;
    }
    let Some((h, targets, solution, predicted_cells)) = best else {
        return Err(CoreError::NoCellBudget);
    };
    let mut notes = Vec::new();
    if (predicted_cells as f64 / want - 1.0).abs() > BUDGET_REPORT_TOLERANCE {
        notes.push(format!(
            "the counts give {predicted_cells} cells for {requested} requested \
             ({:+.0} %, cell size {h:.4e} after {iterations} target fits)",
            (predicted_cells as f64 / want - 1.0) * 100.0
        ));
        notes.extend(forcing_curves(&curves, &targets, &solution.counts, 3));
    }
    Ok(CompatibleCounts {
        curves,
        solution,
        predicted_cells,
        requested_cells: Some(requested),
        cell_size: Some(h),
        iterations,
        notes,
    })
}

/// The `top` curves whose counts are farthest above their targets, in cells
/// (`(m_j − t_j)·w_j/10`, `w_j` the block depth in tenths of cells), described for the report.
fn forcing_curves(
    curves: &BlockCurves,
    targets: &ilp::FitTargets,
    counts: &[usize],
    top: usize,
) -> Vec<String> {
    let mut excess: Vec<(f64, usize)> = (0..curves.len())
        .map(|j| {
            let e = (counts[j] as f64 - targets.targets[j]) * targets.weights[j] as f64 / 10.0;
            (e, j)
        })
        .filter(|&(e, _)| e >= 1.0)
        .collect();
    excess.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    excess
        .into_iter()
        .take(top)
        .map(|(e, j)| {
            let (k, s) = (0..curves.blocks())
                .flat_map(|k| (0..4).map(move |s| (k, s)))
                .find(|&(k, s)| curves.block_sides(k)[s].contains(&j))
                .unwrap_or((0, 0));
            let side = ["bottom", "right", "top", "left"][s];
            let what = match (curves.cut(j), curves.ring(j)) {
                (Some(c), _) => format!("cut {c}"),
                (None, Some(0)) => "the outer boundary".to_string(),
                (None, Some(r)) => format!("the boundary of hole {}", r - 1),
                (None, None) => "a curve".to_string(),
            };
            format!(
                "curve {j} ({what}, {side} side of block {k}, length {:.4e}) has {} points for a \
                 target of {:.1}: it forces about {e:.0} cells",
                polyline_length(curves.points(j)),
                counts[j],
                targets.targets[j]
            )
        })
        .collect()
}
