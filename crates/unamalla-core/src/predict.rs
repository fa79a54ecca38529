//! Predicted mesh quality of a block layout: the acceptance criterion that chooses
//! between layouts.
//!
//! Admissibility (corner angles, convexity) says whether a block *can* be meshed; the
//! predictor estimates how well. For a decomposition it runs the pipeline's own steps 3–6 at a
//! coarse size — compatible counts ([`crate::curves::compatible_counts`]) for
//! `min(N, PREDICT_CELLS)` cells, transfinite interpolation per block, the conformal merge —
//! then [`PREDICT_SWEEPS`] Jacobi sweeps of the discrete Laplacian on the free nodes (every
//! node off the region boundary, cut nodes included):
//!
//! ```text
//! x_i ← (1/|N(i)|) Σ_{j ∈ N(i)} x_j      (N(i): the nodes sharing a cell edge with i)
//! ```
//!
//! and measures the share of cells with μ ≥ 0.8 (the "rectangles 2015" μ of [Méndez 2023, §2.2],
//! [`unamalla_mesh::quality::mu`]), overall and per block. A few Laplacian sweeps remove what
//! the smoother removes easily (TFI's uneven spacing across a cut, kinks at cut ends) and keep
//! what it cannot (a block whose corners sit at the tip of an arm, sheared slivers, a fine
//! count forced along a sheet of blocks). The work is bounded: `O(PREDICT_CELLS ·
//! PREDICT_SWEEPS)` after the counts, independent of the requested size and of the clock.
//! `tests/predictor.rs` checks that the prediction per block correlates with the μ ≥ 0.8 share
//! the finished mesh reaches in that block.

use unamalla_decompose::Decomposition;
use unamalla_mesh::quality::{interior_singularities, mu};
use unamalla_mesh::{BlockMesh2, DVec2, HasNodes, HasQuadCells};

use crate::curves::{compatible_counts, decomposition_area};
use crate::pipeline::MeshSize;
use crate::CoreError;

/// Cells of the coarse mesh the prediction is made on (at most).
pub const PREDICT_CELLS: usize = 6000;
/// Laplacian sweeps of the prediction.
pub const PREDICT_SWEEPS: usize = 40;

/// The predicted quality of a layout.
#[derive(Debug, Clone, PartialEq)]
pub struct Prediction {
    /// Predicted share (0–1) of cells with μ ≥ 0.8 over the whole mesh.
    pub good_share: f64,
    /// Predicted share per block.
    pub blocks: Vec<f64>,
    /// Cells of each block in the coarse prediction mesh.
    pub block_cells: Vec<usize>,
    /// Cells of the coarse prediction mesh.
    pub cells: usize,
    /// Interior nodes of the coarse mesh with valence ≠ 4 (a layout with cut joints, or one
    /// whose blocks do not merge conformally, has some; the pipeline's layouts should not).
    pub singularities: usize,
}

/// Share of the cells of block `b` of `mesh` (global node coordinates) with μ ≥ 0.8, and the
/// block's cell count.
pub fn block_good_share(mesh: &BlockMesh2, b: usize) -> (f64, usize) {
    let g = &mesh.blocks()[b];
    let map = mesh.block_node_map(b);
    let nodes = mesh.global().nodes();
    let (m, n) = (g.m(), g.n());
    let mut good = 0usize;
    let mut total = 0usize;
    for j in 0..n.saturating_sub(1) {
        for i in 0..m.saturating_sub(1) {
            let q = [
                nodes[map[j * m + i]],
                nodes[map[j * m + i + 1]],
                nodes[map[(j + 1) * m + i + 1]],
                nodes[map[(j + 1) * m + i]],
            ];
            total += 1;
            if mu(&q) >= 0.8 {
                good += 1;
            }
        }
    }
    (good as f64 / total.max(1) as f64, total)
}

/// Runs `sweeps` Jacobi sweeps of the Laplacian on the free nodes of `mesh`.
pub fn laplacian_sweeps(mesh: &mut BlockMesh2, sweeps: usize) {
    let global = mesh.global();
    let fixed = global.fixed().to_vec();
    let nn = global.nodes().len();
    let mut nbr: Vec<Vec<usize>> = vec![Vec::new(); nn];
    for c in global.cells() {
        for k in 0..4 {
            let (a, b) = (c[k], c[(k + 1) % 4]);
            nbr[a].push(b);
            nbr[b].push(a);
        }
    }
    for l in &mut nbr {
        l.sort_unstable();
        l.dedup();
    }
    let mut x: Vec<DVec2> = global.nodes().to_vec();
    let mut y = x.clone();
    for _ in 0..sweeps {
        for i in 0..nn {
            if fixed[i] || nbr[i].is_empty() {
                continue;
            }
            let s: DVec2 = nbr[i].iter().map(|&j| x[j]).sum();
            y[i] = s / nbr[i].len() as f64;
        }
        std::mem::swap(&mut x, &mut y);
    }
    mesh.global_mut().nodes_mut().copy_from_slice(&x);
    mesh.sync_blocks();
}

/// Predicts the μ ≥ 0.8 share of the mesh the pipeline would make from `d` at `size`.
pub fn predict_mesh(d: &Decomposition, size: MeshSize) -> Result<Prediction, CoreError> {
    let area = decomposition_area(d);
    let n = match size {
        MeshSize::Cells(n) => n,
        MeshSize::CellSize(h) if h > 0.0 => (area / (h * h)).min(1e12) as usize,
        _ => PREDICT_CELLS,
    };
    let coarse = MeshSize::Cells(n.clamp(1, PREDICT_CELLS));
    let cc = compatible_counts(d, coarse)?;
    let grids = cc.curves.grids(d, &cc.solution.counts)?;
    let mut mesh = BlockMesh2::merge(grids, 1e-9)?;
    let singularities = interior_singularities(mesh.global()).count();
    laplacian_sweeps(&mut mesh, PREDICT_SWEEPS);
    let mut good = 0.0;
    let mut total = 0usize;
    let mut blocks = Vec::with_capacity(mesh.blocks().len());
    let mut block_cells = Vec::with_capacity(mesh.blocks().len());
    for b in 0..mesh.blocks().len() {
        let (s, c) = block_good_share(&mesh, b);
        good += s * c as f64;
        total += c;
        blocks.push(s);
        block_cells.push(c);
    }
    Ok(Prediction {
        good_share: good / total.max(1) as f64,
        blocks,
        block_cells,
        cells: mesh.num_quads(),
        singularities,
    })
}

/// Weighted Pearson correlation of `(x, y, weight)` triples (NaN with fewer than two distinct
/// points or zero weight): how `MeshReport::block_quality` predictions track the achieved
/// shares, weighted by the blocks' cells.
pub fn weighted_correlation(v: &[(f64, f64, f64)]) -> f64 {
    let w: f64 = v.iter().map(|x| x.2).sum();
    if w <= 0.0 {
        return f64::NAN;
    }
    let mx = v.iter().map(|x| x.0 * x.2).sum::<f64>() / w;
    let my = v.iter().map(|x| x.1 * x.2).sum::<f64>() / w;
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for &(x, y, c) in v {
        sxy += c * (x - mx) * (y - my);
        sxx += c * (x - mx) * (x - mx);
        syy += c * (y - my) * (y - my);
    }
    sxy / (sxx * syy).sqrt()
}
