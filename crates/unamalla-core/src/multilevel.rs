//! Coarse-to-fine smoothing of the merged block-structured mesh (nested iteration).
//!
//! The merged mesh is a union of structured blocks whose point counts come from the
//! compatibility integer program ([`crate::curves::compatible_counts`]). The same decomposition
//! is meshed again with about a quarter of the cells ([`COARSE_CELL_RATIO`]) through the same
//! machinery, so the coarse blocks are the fine blocks with about half the points per side and
//! their counts are compatible across every cut by construction. The coarse mesh is smoothed
//! first (recursively, with its own coarse level while it has at least [`MIN_COARSE_CELLS`]
//! cells), and its **displacement** from its own transfinite start is prolonged to the fine
//! mesh: fine start = fine TFI + interpolated (coarse smoothed − coarse TFI). This is nested
//! iteration (Brandt 1977, "Multi-level adaptive solutions to boundary-value problems",
//! Math. Comp. 31(138), §1; Briggs, Henson & McCormick 2000, *A Multigrid Tutorial*, 2nd ed.,
//! ch. 3 "nested iteration"): the fine solve starts from an interpolated coarse solution, so it
//! only has to remove the fine-scale error, which the smoother does quickly. Adding the
//! displacement to the fine transfinite interpolation (Gordon & Hall 1973, "Construction of
//! curvilinear co-ordinate systems and applications to mesh generation", Int. J. Numer. Meth.
//! Eng. 7(4)) instead of interpolating the coarse positions keeps the fine boundary nodes on the
//! fine boundary curves: the displacement of a fixed (region boundary) node is zero.
//!
//! **Transfer in index space.** Node `(i, j)` of fine block `k` is mapped to a fractional index
//! `(s, t)` of coarse block `k` by piecewise-linear maps along each side whose breakpoints are
//! the curve junctions of the side (the curves `Q_j` of [`BlockCurves`]: a curve
//! with `m_j` fine and `m'_j` coarse points spans `m_j − 1` fine and `m'_j − 1` coarse
//! segments), blended transfinitely inside the block:
//! `s = (1−η)·B(i) + η·T(i)`, `t = (1−ξ)·L(j) + ξ·R(j)`, `ξ = i/(m−1)`, `η = j/(n−1)`.
//! On a side this is exactly the side map, and a cut is one curve on both of its blocks with
//! the same counts, so the two blocks give a cut node the same coarse position along the cut
//! (the displacement is then the same 1D interpolation from both sides). A node shared by
//! several blocks gets the mean of their values, in block order (deterministic).
//!
//! **Safeguard.** A coarse level is prolonged only if its smoothing ended ε-convex, and the
//! prolonged start is accepted only if every cell is convex (all four corner
//! triangles positive, the convention of `docs/conventions.md`) once its folded cells, if any
//! and at most [`max_prolonged_folds`] (1 % of the cells, or fewer than the transfinite
//! start has), were untangled in local patches
//! ([`crate::untangle`]); otherwise the caller falls back to the
//! transfinite start ([`CoarseStart::accepted`] is `false`). The fine run that follows
//! starts convex, so the ε-convexity contract of `unamalla-optim` holds as before.

use unamalla_decompose::Decomposition;
use unamalla_mesh::quality::non_convex_cells;
use unamalla_mesh::{BlockMesh2, DVec2, FreeNodes, HasNodes, HasQuadCells};
use unamalla_optim::{smooth, Observer, SmoothOptions};

use crate::curves::compatible_counts;
use crate::pipeline::MeshSize;
use crate::CoreError;
use unamalla_decompose::BlockCurves;

/// The coarse level has about `1 / COARSE_CELL_RATIO` of the cells of the level above (half the
/// points per block side).
pub const COARSE_CELL_RATIO: usize = 4;

/// A coarse level is made only when it gets at least this many cells; below, the level is
/// smoothed from its transfinite start.
pub const MIN_COARSE_CELLS: usize = 2_000;

/// Coarse levels below the requested mesh used by the pipeline by default (each with a quarter
/// of the cells of the one above, while it has at least [`MIN_COARSE_CELLS`]).
pub const DEFAULT_COARSE_LEVELS: usize = 2;

/// What one coarse level did.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LevelReport {
    /// Cells of the level.
    pub cells: usize,
    /// Smoothing iterations (solver iterations of the global run, untangling patches excluded).
    pub iterations: usize,
    /// Folded cells of the level's transfinite start (before untangling).
    pub folded_start: usize,
    /// Status of the level's smoothing.
    pub status: String,
    /// Whether the level's smoothing ended ε-convex (`α₋ > ε·ᾱ`); only then is it prolonged.
    pub eps_convex: bool,
    /// Non-convex cells of the start prolonged from this level to the level above
    /// (`usize::MAX`: the level itself did not end ε-convex and nothing was prolonged).
    pub prolonged_non_convex: usize,
    /// Non-convex cells of that start left after untangling them in local patches
    /// ([`crate::untangle`]); the start is used only when this is 0.
    pub remaining_non_convex: usize,
}

/// A start for the fine mesh prolonged from smoothed coarse levels ([`coarse_start`]).
#[derive(Debug, Clone, PartialEq)]
pub struct CoarseStart {
    /// The prolonged node positions of the fine mesh (global node order).
    pub nodes: Vec<DVec2>,
    /// Whether the prolonged start is convex and should be used.
    pub accepted: bool,
    /// The coarse levels, coarsest last.
    pub levels: Vec<LevelReport>,
}

impl CoarseStart {
    /// One line for the progress callback: cells and iterations per level, and whether the
    /// start was used.
    pub fn summary(&self) -> String {
        format!(
            "coarse levels: {:?} cells, {:?} iterations; prolonged start {}",
            self.levels.iter().map(|l| l.cells).collect::<Vec<_>>(),
            self.levels.iter().map(|l| l.iterations).collect::<Vec<_>>(),
            match self.levels.first() {
                Some(l) if !l.eps_convex => {
                    "none (the coarse level did not end ε-convex)".to_string()
                }
                Some(l) => format!(
                    "{} non-convex cells, {} after untangling: {}",
                    l.prolonged_non_convex,
                    l.remaining_non_convex,
                    if self.accepted { "used" } else { "discarded" }
                ),
                None => "none".to_string(),
            }
        )
    }
}

/// The mesh size of the level below `size` for a mesh of `cells` cells, or `None` when it would
/// have fewer than [`MIN_COARSE_CELLS`] cells or the size is a density factor (which does not
/// scale with a cell count).
pub fn coarse_size(size: MeshSize, cells: usize) -> Option<MeshSize> {
    if cells / COARSE_CELL_RATIO < MIN_COARSE_CELLS {
        return None;
    }
    let r = COARSE_CELL_RATIO as f64;
    match size {
        MeshSize::Cells(n) => Some(MeshSize::Cells(((n as f64 / r).round() as usize).max(1))),
        MeshSize::CellSize(h) => Some(MeshSize::CellSize(h * r.sqrt())),
        MeshSize::Density(_) => None,
    }
}

/// How many coarse levels [`coarse_start`] makes and how it bends their flat corners.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoarseLevels {
    /// Coarse levels at most (0: none).
    pub levels: usize,
    /// The flat-corner deficit of the pipeline in degrees
    /// ([`crate::flat_corners::bend_flat_corners`]), applied to the coarse meshes as to the
    /// fine one.
    pub flat_corner_deficit: f64,
}

/// Smooths coarse versions of `fine` (the merged mesh of `d` with the curve counts
/// `fine_counts`, before any smoothing) and prolongs the result to it (see the module
/// documentation). With `levels.levels == 0` nothing is done (`Ok(None)`); `Ok(None)` also
/// when no coarse level can be made (too few cells, a density size, coarse counts that cannot
/// be solved, blocks that do not match).
///
/// Errors: only those of the smoother on a coarse mesh (invalid options).
pub fn coarse_start(
    d: &Decomposition,
    size: MeshSize,
    fine: &BlockMesh2,
    fine_counts: &[usize],
    opts: &SmoothOptions,
    levels: CoarseLevels,
    observer: &mut dyn Observer,
) -> Result<Option<CoarseStart>, CoreError> {
    let CoarseLevels {
        levels,
        flat_corner_deficit: deficit,
    } = levels;
    if levels == 0 {
        return Ok(None);
    }
    let Some(csize) = coarse_size(size, fine.num_quads()) else {
        return Ok(None);
    };
    let Ok(cc) = compatible_counts(d, csize) else {
        return Ok(None);
    };
    let Ok(grids) = cc.curves.grids(d, &cc.solution.counts) else {
        return Ok(None);
    };
    let Ok(mut coarse) = BlockMesh2::merge(grids, 1e-9) else {
        return Ok(None);
    };
    if coarse.blocks().len() != fine.blocks().len() {
        return Ok(None);
    }
    crate::flat_corners::bend_flat_corners(&mut coarse, deficit);
    let coarse_tfi = coarse.global().nodes().to_vec();
    let folded_start = non_convex_cells(coarse.global()).len();

    // the coarse level itself: from its own coarse level, or from its transfinite start
    let below = coarse_start(
        d,
        csize,
        &coarse,
        &cc.solution.counts,
        opts,
        CoarseLevels {
            levels: levels - 1,
            flat_corner_deficit: deficit,
        },
        observer,
    )?;
    let mut deeper = Vec::new();
    let run_opts = match below {
        Some(s) if s.accepted => {
            coarse.global_mut().nodes_mut().copy_from_slice(&s.nodes);
            deeper = s.levels;
            polish_options(opts)
        }
        other => {
            if let Some(s) = other {
                deeper = s.levels;
            }
            crate::untangle::untangle_patches_observed(
                coarse.global_mut(),
                opts,
                &crate::untangle::DEFAULT_PATCH_RADII,
                observer,
            )?;
            opts.clone()
        }
    };
    let rep = smooth(&mut coarse, &coarse_options(&run_opts), observer)?;
    coarse.sync_blocks();
    let mut level = LevelReport {
        cells: coarse.num_quads(),
        iterations: rep.iterations(),
        folded_start,
        status: rep.status.to_string(),
        prolonged_non_convex: 0,
        remaining_non_convex: 0,
        eps_convex: false,
    };
    level.eps_convex = rep.eps_convex;
    if !rep.eps_convex {
        // a coarse level that stays folded or is not ε-convex (boundary detail below its cell
        // size) has nothing good to give the level above: measured on texas and the gulf of
        // Mexico (docs/benchmarks.md), such starts ended 1–5 points below the transfinite one
        level.prolonged_non_convex = usize::MAX;
        level.remaining_non_convex = usize::MAX;
        let mut levels = vec![level];
        levels.extend(deeper);
        return Ok(Some(CoarseStart {
            nodes: fine.global().nodes().to_vec(),
            accepted: false,
            levels,
        }));
    }

    let curves = BlockCurves::new(d);
    let Some(nodes) = prolong(
        &curves,
        &coarse,
        &coarse_tfi,
        &cc.solution.counts,
        fine,
        fine_counts,
    ) else {
        return Ok(None);
    };
    let prolonged_non_convex = count_non_convex(fine, &nodes);
    // a few folds of the prolonged start (where the fine boundary has detail the coarse level
    // cannot see) are untangled in local patches, as the transfinite start's would be; more
    // than a few only when the transfinite start has even more (the fallback would untangle
    // those, which is more work from a worse start)
    let max_folds = max_prolonged_folds(fine.num_quads(), non_convex_cells(fine.global()).len());
    let (nodes, remaining_non_convex) = if prolonged_non_convex > max_folds {
        (nodes, prolonged_non_convex)
    } else if prolonged_non_convex > 0 {
        let mut g = fine.global().clone();
        g.nodes_mut().copy_from_slice(&nodes);
        let p = crate::untangle::untangle_patches_observed(
            &mut g,
            opts,
            &crate::untangle::DEFAULT_PATCH_RADII,
            observer,
        )?;
        (g.nodes().to_vec(), p.after)
    } else {
        (nodes, 0)
    };
    level.prolonged_non_convex = prolonged_non_convex;
    level.remaining_non_convex = remaining_non_convex;
    let mut levels = vec![level];
    levels.extend(deeper);
    Ok(Some(CoarseStart {
        nodes,
        accepted: remaining_non_convex == 0,
        levels,
    }))
}

/// A prolonged start with more non-convex cells than this share of the cells is discarded
/// without untangling. Chosen by measurement (`smooth_study`, docs/benchmarks.md): on the 34
/// development regions at 20,000 cells the accepted starts had at most 92 folds (0.5 %) and
/// ended within 0.1 points of the transfinite start or above; the Tyrrhenian sea's had 269
/// (1.3 %) and ended 1.8 points below it.
pub const MAX_PROLONGED_FOLD_SHARE: f64 = 0.01;

/// The most non-convex cells a prolonged start may have and still be untangled in local
/// patches: [`MAX_PROLONGED_FOLD_SHARE`] of the `cells`, or fewer than the `tfi_folds`
/// non-convex cells of the fine transfinite start when that is more. The transfinite start is
/// the fallback and would be untangled in the same patches, so a prolonged start with fewer
/// folds is the cheaper and better start to untangle. Measured (`smooth_study` at 20,000 cells,
/// 2026-12-06): tyrrhenian-sea's prolonged start had 282 folds (1.4 %) against 727 of its
/// transfinite start; untangled and used it took the smooth stage from 4.11 to 1.66 s and the
/// μ ≥ 0.8 share from 96.80 to 96.98 %; no other region changed.
pub fn max_prolonged_folds(cells: usize, tfi_folds: usize) -> usize {
    let share = (MAX_PROLONGED_FOLD_SHARE * cells as f64) as usize;
    share.max(tfi_folds.saturating_sub(1))
}

/// Iteration cap of each solver phase on a coarse level.
pub const COARSE_MAX_ITER: usize = 300;
/// Cap on the `k` updates of the untangling homotopy on a coarse level (5 iterations each).
pub const COARSE_K_UPDATES: usize = 20;

/// `opts` with the caps of a coarse level ([`COARSE_MAX_ITER`], [`COARSE_K_UPDATES`]): a coarse
/// level is only a start, and one that needs more work (a wiggly boundary at its cell size) is
/// not a good one.
pub fn coarse_options(opts: &SmoothOptions) -> SmoothOptions {
    let mut o = opts.clone();
    o.solver.max_iter = o.solver.max_iter.min(COARSE_MAX_ITER);
    o.max_k_updates = o.max_k_updates.min(COARSE_K_UPDATES);
    o
}

/// The options of the fine run from a prolonged start: `opts` without its σ continuation (the
/// coarse levels already ran it; the start is a smoothed mesh at the final σ), and its
/// convergence tests with the short window FTOL of a polish run
/// ([`unamalla_optim::StopRules::polish`]: nested iteration leaves only the fine-scale error,
/// which Newton removes in a few iterations; the quality plateau keeps its window).
pub fn polish_options(opts: &SmoothOptions) -> SmoothOptions {
    let mut o = opts.clone().sigma_continuation(Vec::new());
    o.solver.stop = o.solver.stop.polish();
    o
}

/// Non-convex cells of `mesh` with its nodes at `nodes`.
fn count_non_convex(mesh: &BlockMesh2, nodes: &[DVec2]) -> usize {
    (0..mesh.num_quads())
        .filter(|&c| {
            let q = mesh.quad(c);
            (0..4).any(|k| {
                let p = nodes[q[k]];
                let a = nodes[q[(k + 1) % 4]] - p;
                let b = nodes[q[(k + 3) % 4]] - p;
                a.perp_dot(b) <= 0.0
            })
        })
        .count()
}

/// The segment counts of the curves of side `s` of block `k`, cumulated from the side's
/// counter-clockwise start: `[0, m_1 − 1, m_1 + m_2 − 2, …]`.
fn side_breaks(curves: &BlockCurves, counts: &[usize], k: usize, s: usize) -> Vec<f64> {
    let mut out = vec![0.0];
    let mut acc = 0usize;
    for &j in &curves.block_sides(k)[s] {
        acc += counts[j].saturating_sub(1);
        out.push(acc as f64);
    }
    out
}

/// The piecewise-linear map taking the breakpoints `from` to `to`, at `x` (clamped to the
/// range). Both have the same length ≥ 2 and are non-decreasing.
fn piecewise_linear(from: &[f64], to: &[f64], x: f64) -> f64 {
    let last = from.len() - 1;
    let x = x.clamp(from[0], from[last]);
    let q = (0..last).find(|&q| x <= from[q + 1]).unwrap_or(last - 1);
    let span = from[q + 1] - from[q];
    let t = if span > 0.0 {
        (x - from[q]) / span
    } else {
        0.0
    };
    to[q] + t * (to[q + 1] - to[q])
}

/// The fine start: the fine mesh's nodes plus the coarse displacement (`coarse` nodes minus
/// `coarse_tfi`) interpolated in each block's index space; fixed nodes keep their position.
/// `None` when the block sizes do not match the counts.
fn prolong(
    curves: &BlockCurves,
    coarse: &BlockMesh2,
    coarse_tfi: &[DVec2],
    coarse_counts: &[usize],
    fine: &BlockMesh2,
    fine_counts: &[usize],
) -> Option<Vec<DVec2>> {
    let cn = coarse.global().nodes();
    let fine_global = fine.global();
    let nn = fine_global.num_nodes();
    let mut sum = vec![DVec2::ZERO; nn];
    let mut hits = vec![0u32; nn];
    for (k, (fb, cb)) in fine.blocks().iter().zip(coarse.blocks()).enumerate() {
        let (mf, nf) = (fb.m(), fb.n());
        let (mc, nc) = (cb.m(), cb.n());
        if mf < 2 || nf < 2 || mc < 2 || nc < 2 {
            return None;
        }
        let fbr: Vec<Vec<f64>> = (0..4)
            .map(|s| side_breaks(curves, fine_counts, k, s))
            .collect();
        let cbr: Vec<Vec<f64>> = (0..4)
            .map(|s| side_breaks(curves, coarse_counts, k, s))
            .collect();
        let ends = [mf - 1, nf - 1, mf - 1, nf - 1];
        let cends = [mc - 1, nc - 1, mc - 1, nc - 1];
        for s in 0..4 {
            if fbr[s].last() != Some(&(ends[s] as f64)) || cbr[s].last() != Some(&(cends[s] as f64))
            {
                return None;
            }
        }
        let (fm, cmax_i, cmax_j) = ((mf - 1) as f64, (mc - 1) as f64, (nc - 1) as f64);
        let fnn = (nf - 1) as f64;
        let cmap = coarse.block_node_map(k);
        let disp = |i: usize, j: usize| {
            let g = cmap[j * mc + i];
            cn[g] - coarse_tfi[g]
        };
        let fmap = fine.block_node_map(k);
        for j in 0..nf {
            let eta = j as f64 / fnn;
            let l = cmax_j - piecewise_linear(&fbr[3], &cbr[3], fnn - j as f64);
            let r = piecewise_linear(&fbr[1], &cbr[1], j as f64);
            for i in 0..mf {
                let g = fmap[j * mf + i];
                if fine_global.is_fixed(g) {
                    continue;
                }
                let xi = i as f64 / fm;
                let b = piecewise_linear(&fbr[0], &cbr[0], i as f64);
                let t_ = cmax_i - piecewise_linear(&fbr[2], &cbr[2], fm - i as f64);
                let s = ((1.0 - eta) * b + eta * t_).clamp(0.0, cmax_i);
                let t = ((1.0 - xi) * l + xi * r).clamp(0.0, cmax_j);
                let i0 = (s.floor() as usize).min(mc - 2);
                let j0 = (t.floor() as usize).min(nc - 2);
                let (a, c) = (s - i0 as f64, t - j0 as f64);
                let d = (1.0 - a) * (1.0 - c) * disp(i0, j0)
                    + a * (1.0 - c) * disp(i0 + 1, j0)
                    + a * c * disp(i0 + 1, j0 + 1)
                    + (1.0 - a) * c * disp(i0, j0 + 1);
                sum[g] += d;
                hits[g] += 1;
            }
        }
    }
    Some(
        fine_global
            .nodes()
            .iter()
            .zip(sum.iter().zip(&hits))
            .map(|(&p, (&d, &h))| if h > 0 { p + d / h as f64 } else { p })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use unamalla_decompose::{decompose, DecomposeOptions};

    /// The L-shape `(0,0),(2,0),(2,1),(1,1),(1,2),(0,2)` decomposed (one cut from the reflex
    /// corner), meshed with about `fine` and `fine / 4` cells: (decomposition, fine mesh and
    /// counts, coarse mesh and counts).
    fn l_shape_levels(
        fine: usize,
    ) -> (
        Decomposition,
        BlockMesh2,
        Vec<usize>,
        BlockMesh2,
        Vec<usize>,
    ) {
        let region = unamalla_decompose::submap::shapes::l_shape().unwrap();
        let d = decompose(&region, &DecomposeOptions::default()).unwrap();
        assert!(d.blocks.len() >= 2, "the L-shape needs a cut");
        let mesh = |n: usize| {
            let cc = compatible_counts(&d, MeshSize::Cells(n)).unwrap();
            let grids = cc.curves.grids(&d, &cc.solution.counts).unwrap();
            (BlockMesh2::merge(grids, 1e-9).unwrap(), cc.solution.counts)
        };
        let (f, fc) = mesh(fine);
        let (c, cc) = mesh(fine / 4);
        (d, f, fc, c, cc)
    }

    /// Fine nodes that are free and belong to two or more blocks: the nodes on cuts.
    fn cut_nodes(m: &BlockMesh2) -> Vec<usize> {
        let mut blocks_of = vec![0usize; m.global().num_nodes()];
        for b in 0..m.blocks().len() {
            for &g in m.block_node_map(b) {
                blocks_of[g] += 1;
            }
        }
        (0..blocks_of.len())
            .filter(|&g| blocks_of[g] >= 2 && !m.global().is_fixed(g))
            .collect()
    }

    #[test]
    fn a_constant_displacement_moves_every_free_node_by_it() {
        // bilinear weights sum to one (and the mean over blocks of equal values is that value),
        // so a displacement c at every coarse node moves every free fine node by exactly c
        let (d, fine, fc, mut coarse, cc) = l_shape_levels(800);
        let tfi = coarse.global().nodes().to_vec();
        let c = DVec2::new(0.003, -0.002);
        for p in coarse.global_mut().nodes_mut() {
            *p += c;
        }
        let curves = BlockCurves::new(&d);
        let out = prolong(&curves, &coarse, &tfi, &cc, &fine, &fc).unwrap();
        for (g, (&p, &q)) in fine.global().nodes().iter().zip(&out).enumerate() {
            let want = if fine.global().is_fixed(g) { p } else { p + c };
            assert!((q - want).length() < 1e-14, "node {g}: {q} vs {want}");
        }
    }

    #[test]
    fn cut_nodes_get_the_displacement_of_their_point_along_the_cut() {
        // an affine field g(p) = A·p on the coarse nodes; a cut is a straight segment sampled
        // uniformly on both levels, and the junction-aligned map sends fine node k of m to the
        // coarse index k·(m'−1)/(m−1) at the same fraction of the cut, where the linear
        // interpolation of g equals g at the fine node: the same value from both blocks
        let (d, fine, fc, mut coarse, cc) = l_shape_levels(800);
        let tfi = coarse.global().nodes().to_vec();
        let g = |p: DVec2| DVec2::new(0.01 * p.x + 0.02 * p.y, -0.03 * p.x + 0.005 * p.y);
        for p in coarse.global_mut().nodes_mut() {
            *p += g(*p);
        }
        let curves = BlockCurves::new(&d);
        let out = prolong(&curves, &coarse, &tfi, &cc, &fine, &fc).unwrap();
        let cuts = cut_nodes(&fine);
        assert!(!cuts.is_empty());
        for n in cuts {
            let p = fine.global().nodes()[n];
            assert!(
                (out[n] - p - g(p)).length() < 1e-12,
                "cut node {n} at {p}: moved by {} instead of {}",
                out[n] - p,
                g(p)
            );
        }
    }

    #[test]
    fn piecewise_linear_maps_breakpoints_to_breakpoints() {
        // fine side: curves of 11 and 5 points (10 + 4 segments); coarse: 6 and 3 (5 + 2)
        let from = [0.0, 10.0, 14.0];
        let to = [0.0, 5.0, 7.0];
        assert_eq!(piecewise_linear(&from, &to, 0.0), 0.0);
        assert_eq!(piecewise_linear(&from, &to, 10.0), 5.0);
        assert_eq!(piecewise_linear(&from, &to, 14.0), 7.0);
        // inside the first curve: 4 of 10 segments → 2 of 5
        assert!((piecewise_linear(&from, &to, 4.0) - 2.0).abs() < 1e-15);
        // inside the second: 2 of 4 segments past the junction → 1 of 2
        assert!((piecewise_linear(&from, &to, 12.0) - 6.0).abs() < 1e-15);
        // clamped outside the range
        assert_eq!(piecewise_linear(&from, &to, -1.0), 0.0);
        assert_eq!(piecewise_linear(&from, &to, 20.0), 7.0);
    }

    #[test]
    fn coarse_size_quarters_the_cells_and_doubles_the_area_per_cell() {
        assert_eq!(
            coarse_size(MeshSize::Cells(20_000), 20_000),
            Some(MeshSize::Cells(5_000))
        );
        // h → 2h gives a quarter of the cells
        assert_eq!(
            coarse_size(MeshSize::CellSize(0.5), 20_000),
            Some(MeshSize::CellSize(1.0))
        );
        assert_eq!(coarse_size(MeshSize::Density(4), 20_000), None);
        // a level with fewer than MIN_COARSE_CELLS cells is not made
        assert_eq!(coarse_size(MeshSize::Cells(7_000), 7_000), None);
    }

    #[test]
    fn a_prolonged_start_is_untangled_below_one_percent_or_below_the_transfinite_folds() {
        // 1 % of 20,000 cells is 200 folds
        assert_eq!(max_prolonged_folds(20_000, 0), 200);
        assert_eq!(max_prolonged_folds(20_000, 150), 200);
        // a transfinite start with 727 folds: a prolonged start with up to 726 is untangled
        assert_eq!(max_prolonged_folds(20_000, 727), 726);
        // a mesh of fewer than 100 cells allows no fold unless the transfinite start has more
        assert_eq!(max_prolonged_folds(99, 0), 0);
        assert_eq!(max_prolonged_folds(99, 3), 2);
    }
}
