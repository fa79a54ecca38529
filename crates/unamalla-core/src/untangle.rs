//! Local untangling by patches: the folded cells of the merged mesh (TFI of blocks with wiggly
//! sides) are untangled in small windows.
//!
//! Untangling a whole block with its boundary fixed spends its iterations on every cell of the
//! block and cannot move the cut nodes a fold may need; untangling the whole merged mesh optimizes
//! tens of thousands of cells to move a few hundred. This module does what an engineer would do by
//! hand: take a **patch** — the folded cells and every cell within `r` layers of them (cells
//! sharing a node count as neighbours) — across block boundaries, fix the nodes on the patch's
//! border and on the region boundary, and run the untangling driver ([`unamalla_optim::smooth`],
//! adaptive `k` of [González Flores, Ch. 4] followed by [Méndez 2023, (6.8)]) on that small problem
//! alone. The radius grows (`r = 2, 4, 8, 16, 32` by default) while folded cells remain.
//!
//! Guarantees: only nodes interior to a patch move, and a patch result is copied back only if
//! it has no more non-convex cells than the patch had (the driver's own contract, checked
//! again here), so the number of non-convex cells of the mesh never grows.
//!
//! **Bounded work.** Every patch run is capped at [`PATCH_ITERATION_CAP`] solver iterations
//! (adaptive `k`: at most [`PATCH_K_UPDATES`] updates of 5 iterations, then at most
//! [`PATCH_POLISH_ITER`] iterations of (6.8)), whatever the caller's smoothing options say, and
//! one iteration costs O(patch cells). So the work of a radius is at most
//! `PATCH_ITERATION_CAP × Σ patch cells`, and a patch of radius `r` around `f` folded cells has
//! at most `f·(2r+1)²` cells in a mesh without interior singularities: the hard bound is
//! `PATCH_ITERATION_CAP · folded · Σ_r (2r+1)²` cell-iterations ([`PatchReport::work`],
//! [`PatchReport::work_bound`]). The caps are iteration counts, not wall-clock time, so the
//! result does not depend on the machine's load.
//!
//! **No window tests in a patch.** A patch run ends on its caps, GTOL and FTOL only: the window
//! tests of the caller's options ([`unamalla_optim::StopRules`]) are turned off. They are made
//! for the smoothing of the whole mesh, and on a patch both signals of the quality plateau are
//! blind: its cells are folded or next to folds, far below μ = 0.8 (the μ ≥ 0.8 share of a
//! gulf-of-mexico patch stayed at 5.8 % while the run went on), and α₋/ᾱ of a patch sits at the
//! safeguard's floor ε, constant by construction. With them six gulf-of-mexico patch runs at
//! 20,000 cells stopped on the plateau after 19–60 iterations, most with α₋/ᾱ at the floor;
//! the global run started from there with α₋/ᾱ at the floor (1.0007·10⁻², against 1.57·10⁻²
//! after the patches of the run to convergence, which has no window tests), and the mesh
//! ended at 92.74 % μ ≥ 0.8 against 95.05 % converged; without them 94.75 % (`smooth_study`,
//! docs/benchmarks.md, "Default smoothing against the converged optimum").
//!
//! **Observable.** [`untangle_patches_observed`] solves the patches in fixed batches of
//! [`PATCH_BATCH`] (each batch in parallel; patches are disjoint, so the result does not depend
//! on the batching or the thread count) and calls the observer after every batch with the
//! iterations so far and the folded cells left; [`Control::Stop`] cancels the rest
//! ([`PatchReport::cancelled`]). Folds no patch could remove are listed in
//! [`PatchReport::unresolved`].
//!
//! (Beyond the sources: [Méndez 2023, §6.3] smooths block by block and then each block with its
//! neighbours; local windows around bad cells are standard practice in mesh untangling.)

use rayon::prelude::*;
use unamalla_mesh::quality::non_convex_cells;
use unamalla_mesh::{DVec2, FreeNodes, HasNodes, HasQuadCells, QuadMesh};
use unamalla_optim::{
    smooth, Control, Monitor, NullObserver, Observer, OptimError, Phase, SmoothOptions,
};

/// Default patch radii (layers of cells around the folded ones), tried in order.
pub const DEFAULT_PATCH_RADII: [usize; 5] = [2, 4, 8, 16, 32];

/// Adaptive-`k` updates of a patch run (5 iterations each).
pub const PATCH_K_UPDATES: usize = 40;
/// (6.8) iterations of a patch run after its untangling.
pub const PATCH_POLISH_ITER: usize = 100;
/// Solver iterations of one patch run at most: `5·PATCH_K_UPDATES + PATCH_POLISH_ITER`.
pub const PATCH_ITERATION_CAP: usize = 5 * PATCH_K_UPDATES + PATCH_POLISH_ITER;
/// Patches solved (in parallel) between two observer calls.
pub const PATCH_BATCH: usize = 16;

/// What [`untangle_patches`] did.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct PatchReport {
    /// Non-convex cells before.
    pub before: usize,
    /// Non-convex cells after.
    pub after: usize,
    /// Patches solved (over all radii).
    pub patches: usize,
    /// The largest radius that was needed (0 if nothing was folded).
    pub max_radius: usize,
    /// Solver iterations over all patches.
    pub iterations: usize,
    /// Work done: Σ over patch runs of iterations × patch cells.
    pub work: usize,
    /// The hard bound on [`Self::work`]: [`PATCH_ITERATION_CAP`] × Σ patch cells over the
    /// radii tried.
    pub work_bound: usize,
    /// The observer stopped the untangling (or the time limit was reached).
    pub cancelled: bool,
    /// The cells still non-convex at the end (sorted): folds no patch could remove, left to
    /// the global run.
    pub unresolved: Vec<usize>,
}

/// Untangles the non-convex cells of `mesh` by local patches of growing radius (see the module
/// docs). `opts` are the smoothing options of each patch run (its iteration caps are lowered
/// to [`PATCH_ITERATION_CAP`]); `radii` the patch radii to try in order. Nodes with `is_fixed`
/// stay fixed.
pub fn untangle_patches<M>(
    mesh: &mut M,
    opts: &SmoothOptions,
    radii: &[usize],
) -> Result<PatchReport, OptimError>
where
    M: HasQuadCells + FreeNodes + HasNodes<DVec2> + Sync + ?Sized,
{
    untangle_patches_observed(mesh, opts, radii, &mut NullObserver)
}

/// [`untangle_patches`] reporting to `observer` after every batch of [`PATCH_BATCH`] patches:
/// the monitor's `iter_homotopic` is the patch iterations so far, `inocon` the folded cells
/// not yet untangled, `phase` [`Phase::Homotopic`]. [`Control::Stop`] cancels the remaining
/// patches (the mesh keeps what was solved). An explicit `opts.time_limit` counts from the
/// call and also cancels.
pub fn untangle_patches_observed<M>(
    mesh: &mut M,
    opts: &SmoothOptions,
    radii: &[usize],
    observer: &mut dyn Observer,
) -> Result<PatchReport, OptimError>
where
    M: HasQuadCells + FreeNodes + HasNodes<DVec2> + Sync + ?Sized,
{
    let started = std::time::Instant::now();
    let mut popts = opts.clone();
    popts.max_k_updates = PATCH_K_UPDATES;
    popts.iters_per_k = 5;
    popts.presmooth = 0;
    popts.solver.max_iter = PATCH_POLISH_ITER;
    popts.sigma_continuation.clear();
    // no window tests in a patch (module docs)
    popts.solver.stop = unamalla_optim::StopRules::default();
    let mut bad = non_convex_cells(mesh);
    let mut report = PatchReport {
        before: bad.len(),
        after: bad.len(),
        ..PatchReport::default()
    };
    if bad.is_empty() {
        return Ok(report);
    }
    let n_nodes = mesh.num_nodes();
    let n_cells = mesh.num_quads();
    // node → cells (CSR)
    let mut start = vec![0usize; n_nodes + 1];
    for c in 0..n_cells {
        for v in mesh.quad(c) {
            start[v + 1] += 1;
        }
    }
    for v in 0..n_nodes {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut node_cells = vec![0usize; start[n_nodes]];
    for c in 0..n_cells {
        for v in mesh.quad(c) {
            node_cells[fill[v]] = c;
            fill[v] += 1;
        }
    }
    let adj = NodeCells {
        start,
        cells: node_cells,
    };

    for &r in radii {
        if bad.is_empty() {
            break;
        }
        report.max_radius = r;
        // grow the folded cells by r layers (BFS over node-sharing neighbours)
        let mut layer = vec![usize::MAX; n_cells];
        let mut frontier = bad.clone();
        for &c in &frontier {
            layer[c] = 0;
        }
        for depth in 1..=r {
            let mut next = Vec::new();
            for &c in &frontier {
                for v in mesh.quad(c) {
                    for &d in adj.of(v) {
                        if layer[d] == usize::MAX {
                            layer[d] = depth;
                            next.push(d);
                        }
                    }
                }
            }
            frontier = next;
        }
        // connected components (node sharing) of the selected cells = the patches
        let mut comp = vec![usize::MAX; n_cells];
        let mut patches: Vec<Vec<usize>> = Vec::new();
        for seed in 0..n_cells {
            if layer[seed] == usize::MAX || comp[seed] != usize::MAX {
                continue;
            }
            let id = patches.len();
            let mut cells = vec![seed];
            comp[seed] = id;
            let mut k = 0;
            while k < cells.len() {
                let c = cells[k];
                k += 1;
                for v in mesh.quad(c) {
                    for &d in adj.of(v) {
                        if layer[d] != usize::MAX && comp[d] == usize::MAX {
                            comp[d] = id;
                            cells.push(d);
                        }
                    }
                }
            }
            cells.sort_unstable();
            patches.push(cells);
        }
        // patches are disjoint (node-sharing components) and only their interior nodes move,
        // so a batch is solved in parallel and written back afterwards (in patch order)
        report.work_bound += PATCH_ITERATION_CAP * patches.iter().map(Vec::len).sum::<usize>();
        let mut left = bad.len();
        for batch in patches.chunks(PATCH_BATCH) {
            if let Some(t) = opts.time_limit {
                let rest = t - started.elapsed().as_secs_f64();
                if rest <= 0.0 {
                    report.cancelled = true;
                    break;
                }
                popts.time_limit = Some(rest);
            }
            let view: &M = mesh;
            let solved: Vec<Result<Option<PatchSolution>, OptimError>> = batch
                .par_iter()
                .map(|cells| solve_patch(view, cells, &bad, &comp, &adj, &popts))
                .collect();
            for (s, cells) in solved.into_iter().zip(batch) {
                let Some(s) = s? else { continue };
                report.patches += 1;
                report.iterations += s.iterations;
                report.work += s.iterations * cells.len();
                left -= s.before;
                if s.improved {
                    left += s.after;
                    let out = mesh.nodes_mut();
                    for (v, p) in s.moved {
                        out[v] = p;
                    }
                } else {
                    left += s.before;
                }
            }
            let m = Monitor {
                inocon: left,
                iter_homotopic: report.iterations,
                phase: Phase::Homotopic,
                elapsed: started.elapsed(),
                ..Monitor::default()
            };
            if observer.observe(&m) == Control::Stop {
                report.cancelled = true;
                break;
            }
        }
        bad = non_convex_cells(mesh);
        report.after = bad.len();
        if report.cancelled {
            break;
        }
    }
    report.unresolved = bad;
    Ok(report)
}

/// The outcome of one patch run: the new positions of its free nodes (global ids).
struct PatchSolution {
    moved: Vec<(usize, DVec2)>,
    improved: bool,
    iterations: usize,
    before: usize,
    after: usize,
}

/// Solves one patch (`cells`, sorted) of `mesh`; `None` if it holds no folded cell or has no
/// free node. A node is free iff it is free in the mesh and every cell around it is in the
/// patch.
fn solve_patch<M>(
    mesh: &M,
    cells: &[usize],
    bad: &[usize],
    comp: &[usize],
    adj: &NodeCells,
    opts: &SmoothOptions,
) -> Result<Option<PatchSolution>, OptimError>
where
    M: HasQuadCells + FreeNodes + HasNodes<DVec2> + ?Sized,
{
    let before = cells
        .iter()
        .filter(|c| bad.binary_search(c).is_ok())
        .count();
    let Some(&first) = cells.first() else {
        return Ok(None);
    };
    if before == 0 {
        return Ok(None);
    }
    let pid = comp[first];
    let mut local = std::collections::HashMap::new();
    let mut nodes = Vec::new();
    let mut quads = Vec::with_capacity(cells.len());
    for &c in cells {
        let q = mesh.quad(c).map(|v| {
            *local.entry(v).or_insert_with(|| {
                nodes.push(v);
                nodes.len() - 1
            })
        });
        quads.push(q);
    }
    let pts: Vec<DVec2> = nodes.iter().map(|&v| mesh.nodes()[v]).collect();
    let fixed: Vec<bool> = nodes
        .iter()
        .map(|&v| mesh.is_fixed(v) || adj.of(v).iter().any(|&d| comp[d] != pid))
        .collect();
    if fixed.iter().all(|&f| f) {
        return Ok(None);
    }
    let mut patch = QuadMesh::new(pts, quads)?;
    patch.set_fixed(fixed)?;
    let mut never_stop = |_: &Monitor| Control::Continue;
    let res = match smooth(&mut patch, opts, &mut never_stop) {
        Ok(res) => res,
        // a patch folded so badly that its cells have a negative total area has no mean α to
        // scale the functional by: leave it to a larger patch or to the global run
        Err(OptimError::InvalidOption {
            name: "mean alpha", ..
        }) => return Ok(None),
        Err(e) => return Err(e),
    };
    let after = non_convex_cells(&patch).len();
    let moved = nodes
        .iter()
        .enumerate()
        .filter(|&(l, _)| !patch.is_fixed(l))
        .map(|(l, &v)| (v, patch.nodes()[l]))
        .collect();
    Ok(Some(PatchSolution {
        moved,
        improved: after <= before,
        iterations: res.iter_smooth + res.iter_homotopic + res.iter_classic,
        before,
        after,
    }))
}

/// Node → cells incidence in CSR form.
struct NodeCells {
    start: Vec<usize>,
    cells: Vec<usize>,
}

impl NodeCells {
    /// The cells around node `v`.
    fn of(&self, v: usize) -> &[usize] {
        &self.cells[self.start[v]..self.start[v + 1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use unamalla_mesh::StructuredGrid2;

    /// The `n × n` grid of the unit square as a `QuadMesh` (boundary fixed) and its cell width.
    fn unit_square(n: usize) -> (QuadMesh, f64) {
        let h = 1.0 / (n - 1) as f64;
        let g = StructuredGrid2::from_fn(n, n, |i, j| DVec2::new(i as f64 * h, j as f64 * h))
            .expect("grid");
        (QuadMesh::from_grid(&g), h)
    }

    /// A 21 × 21 unit-square grid (as a `QuadMesh`, boundary fixed) with interior nodes pushed
    /// across their neighbours in two separate spots: each pushed node moves by 1.5 cell widths,
    /// so the four cells around it fold. Two patches must untangle both spots, the boundary
    /// must not move and nodes far from the folds must stay where they were.
    #[test]
    fn two_folds_are_untangled_by_local_patches() {
        let n = 21;
        let (mut mesh, h) = unit_square(n);
        let at = |i: usize, j: usize| j * n + i;
        mesh.nodes_mut()[at(5, 5)] += DVec2::new(1.5 * h, 1.5 * h);
        mesh.nodes_mut()[at(15, 14)] -= DVec2::new(1.5 * h, 0.0);
        let before = non_convex_cells(&mesh).len();
        assert!(
            before >= 4,
            "the perturbation must fold cells, got {before}"
        );
        let start = mesh.nodes().to_vec();
        let r = untangle_patches(&mut mesh, &SmoothOptions::default(), &DEFAULT_PATCH_RADII)
            .expect("untangle");
        assert_eq!(r.before, before);
        assert_eq!(r.after, 0);
        assert_eq!(non_convex_cells(&mesh).len(), 0);
        assert!(r.patches >= 2, "two separate folds give two patches: {r:?}");
        for (v, p0) in start.iter().enumerate() {
            if mesh.is_fixed(v) {
                assert_eq!(mesh.nodes()[v], *p0, "boundary node {v} moved");
            }
        }
        // solved within radius 8, so node (19, 1) — 9 or more cell layers from both folded
        // spots — belongs to no patch and must not move
        assert!(r.max_radius <= 8, "{r:?}");
        assert_eq!(mesh.nodes()[at(19, 1)], start[at(19, 1)]);
    }

    /// The window tests of the caller's options do not reach the patch runs (module docs): rules
    /// that would stop any run after two convex iterates (window 1, a window FTOL no decrease
    /// passes, a plateau every spread passes) leave the untangled mesh identical, bit for bit,
    /// to the one without rules.
    #[test]
    fn patch_runs_ignore_the_callers_window_tests() {
        let n = 21;
        let (mut plain, h) = unit_square(n);
        plain.nodes_mut()[5 * n + 5] += DVec2::new(1.5 * h, 1.5 * h);
        let mut ruled = plain.clone();
        let opts = SmoothOptions::default();
        let mut eager = opts.clone();
        eager.solver.stop = unamalla_optim::StopRules {
            window: 1,
            window_ftol: 1e9,
            plateau_alpha: 1e9,
            plateau_share: 1e9,
            plateau_window: 1,
        };
        let a = untangle_patches(&mut plain, &opts, &DEFAULT_PATCH_RADII).expect("untangle");
        let b = untangle_patches(&mut ruled, &eager, &DEFAULT_PATCH_RADII).expect("untangle");
        assert_eq!(a.after, 0);
        assert_eq!(
            (a.after, a.patches, a.iterations),
            (b.after, b.patches, b.iterations)
        );
        assert_eq!(plain.nodes(), ruled.nodes());
    }

    /// A patch whose fixed nodes enclose a negative area (here the whole mesh is a mirrored
    /// grid: every cell is clockwise) has no mean α to scale the functional by; it is skipped,
    /// not an error that would stop the pipeline (gulf-of-mexico once failed this way), and
    /// nothing moves.
    #[test]
    fn a_patch_enclosing_negative_area_is_skipped() {
        let g =
            StructuredGrid2::from_fn(5, 5, |i, j| DVec2::new(-(i as f64), j as f64)).expect("grid");
        let mut mesh = QuadMesh::from_grid(&g);
        let start = mesh.nodes().to_vec();
        let before = non_convex_cells(&mesh).len();
        assert_eq!(before, 16, "every mirrored cell is clockwise");
        let r = untangle_patches(&mut mesh, &SmoothOptions::default(), &DEFAULT_PATCH_RADII)
            .expect("a negative-area patch is skipped, not an error");
        assert_eq!((r.before, r.after, r.patches), (16, 16, 0));
        assert_eq!(mesh.nodes(), &start[..]);
    }

    /// 49 × 49 grid with 36 folded spots (a node pushed 1.5 cells diagonally every 8 nodes):
    /// the untangling finishes within its hard work bound, the observer sees every batch of
    /// [`PATCH_BATCH`] patches (so at least ⌈36/16⌉ = 3 progress calls) with non-decreasing
    /// iteration counts, and a stop request at the first call cancels the rest.
    #[test]
    fn many_folds_finish_within_the_work_bound_and_report_progress() {
        let n = 49;
        let (mut mesh, h) = unit_square(n);
        let spots: Vec<(usize, usize)> = (0..6)
            .flat_map(|a| (0..6).map(move |b| (4 + 8 * a, 4 + 8 * b)))
            .collect();
        for &(i, j) in &spots {
            mesh.nodes_mut()[j * n + i] += DVec2::new(1.5 * h, 1.5 * h);
        }
        let mesh0 = mesh.clone();
        // a node moved to (i+1.5, j+1.5) leaves its SW cell a convex kite and folds the other
        // three (the NE cell has the node outside, SE and NW turn the wrong way at it)
        let before = non_convex_cells(&mesh).len();
        assert_eq!(before, 3 * spots.len());
        let mut calls: Vec<(usize, usize)> = Vec::new();
        let mut watch = |m: &Monitor| {
            calls.push((m.iter_homotopic, m.inocon));
            Control::Continue
        };
        let opts = SmoothOptions::default();
        let r = untangle_patches_observed(&mut mesh, &opts, &DEFAULT_PATCH_RADII, &mut watch)
            .expect("untangle");
        assert_eq!((r.before, r.after), (before, 0), "{r:?}");
        assert!(r.unresolved.is_empty() && !r.cancelled);
        assert!(
            r.patches >= spots.len(),
            "one patch per spot at least: {r:?}"
        );
        // the hard bound: cap × patch cells, and a patch of radius r around f folded cells
        // has at most f·(2r+1)² cells
        assert!(r.work <= r.work_bound, "{r:?}");
        let radii_used: usize = DEFAULT_PATCH_RADII
            .iter()
            .take_while(|&&q| q <= r.max_radius)
            .map(|&q| (2 * q + 1) * (2 * q + 1))
            .sum();
        assert!(
            r.work_bound <= PATCH_ITERATION_CAP * before * radii_used,
            "{r:?}"
        );
        assert!(r.iterations <= r.patches * PATCH_ITERATION_CAP, "{r:?}");
        assert!(
            calls.len() >= spots.len().div_ceil(PATCH_BATCH),
            "{calls:?}"
        );
        assert!(calls.windows(2).all(|w| w[0].0 <= w[1].0), "{calls:?}");
        assert_eq!(
            calls.last().map(|c| c.1),
            Some(0),
            "the last call sees no fold left"
        );

        // cancelled at the first progress call: one batch solved, the rest left folded
        let mut mesh = mesh0;
        let mut stop = |_: &Monitor| Control::Stop;
        let r = untangle_patches_observed(&mut mesh, &opts, &DEFAULT_PATCH_RADII, &mut stop)
            .expect("untangle");
        assert!(r.cancelled && r.patches <= PATCH_BATCH, "{r:?}");
        assert!(r.after > 0 && r.after < before, "{r:?}");
        assert_eq!(r.unresolved.len(), r.after);
    }

    /// Nothing folded: nothing moves and no patch is solved.
    #[test]
    fn a_convex_mesh_is_left_alone() {
        let g = StructuredGrid2::from_fn(6, 5, |i, j| DVec2::new(i as f64, 0.5 * j as f64))
            .expect("grid");
        let mut mesh = QuadMesh::from_grid(&g);
        let start = mesh.nodes().to_vec();
        let r = untangle_patches(&mut mesh, &SmoothOptions::default(), &DEFAULT_PATCH_RADII)
            .expect("untangle");
        assert_eq!(r, PatchReport::default());
        assert_eq!(mesh.nodes(), &start[..]);
    }
}
