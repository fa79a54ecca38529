//! Coarse-to-fine smoothing of one structured grid: solve on a coarse grid of the same region,
//! prolongate, put the exact fine boundary back, and finish with a few iterations on the fine
//! grid (a nested-iteration / "full multigrid" start for the Newton iteration).
//!
//! # Algorithm
//! Let the fine grid have `m × n` nodes and `r` = [`CoarseToFineOptions::ratio`]. The levels are
//! `m_l = (m − 1)/r^l + 1` (and the same for `n`) while both divide exactly and the coarse grid
//! keeps at least [`CoarseToFineOptions::min_nodes`] nodes per side.
//! 1. **Coarse start**: the coarse grid of level `l` is the fine *start* grid subsampled every
//!    `r^l`-th node in both directions. Its boundary nodes are fine boundary nodes, so it
//!    discretizes the same region; for a TFI start its interior is the TFI of that boundary.
//! 2. **Solve** the coarsest level with [`smooth`] (untangling first if it is not ε-convex).
//! 3. **Prolongate** level `l` to level `l − 1` by bilinear interpolation inside each cell
//!    ([`StructuredGrid2::refined`] with `r − 1` new lines per cell: a convex cell gives convex
//!    sub-cells). The new boundary nodes lie on chords of the coarse boundary, not on the
//!    region boundary.
//! 4. **Boundary reset**: the boundary displacement `δ` (exact fine boundary minus
//!    prolongated boundary; `δ = 0` at the four corners, which are coarse nodes) is extended to
//!    the whole grid by transfinite interpolation in the index parameters `u = i/(m−1)`,
//!    `v = j/(n−1)`: `Δ(i,j) = (1−u)δ_L(j) + u δ_R(j) + (1−v)δ_B(i) + v δ_T(i)` (the corner
//!    terms of the Boolean sum vanish). `Δ` equals `δ` on the boundary, is `O(h_c²·curvature)`
//!    and smooth, so it moves interior nodes by about as much as the boundary moved.
//! 5. **Repair**: if the corrected prolongation is not ε-convex (`α₋ ≤ ε·ᾱ`) while the
//!    subsampled start of that level is, the level restarts from the subsampled start (so a
//!    level never starts worse than its plain start); [`smooth`] untangles whatever is left.
//! 6. **Fine iterations**: [`smooth`] on the level (truncated Newton converges in a few
//!    iterations from this start because the error is smooth and small).
//!
//! **Stopping**: coarse levels stop at FTOL [`CoarseToFineOptions::coarse_ftol`] (only a
//! starting point is needed), the finest level uses the caller's
//! [`SmoothOptions::solver`] tolerances; every level that starts from a prolongation (not
//! restarted) runs with the short window of [`crate::StopRules::polish`].
//!
//! **Contract** (as [`smooth`]): the returned grid never has more non-convex cells than the
//! grid given; from a convex start the result is convex. If the coarse-to-fine result would
//! have more non-convex cells than the start, the finest level is re-solved from the start
//! (reported by [`CoarseToFineReport::fallback`]).

use unamalla_mesh::{DVec2, StructuredGrid2};

use crate::drivers::{smooth, SmoothOptions, SmoothReport};
use crate::error::OptimError;
use crate::monitor::Observer;

/// Options of [`smooth_coarse_to_fine`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct CoarseToFineOptions {
    /// The smoothing of every level (functional, ε, solver); the finest level uses these
    /// solver tolerances (with [`crate::StopRules::polish`] when it starts from a prolongation).
    pub smooth: SmoothOptions,
    /// Refinement ratio between levels (`r ≥ 2`; 3 keeps every coarse node a fine node with
    /// the same index stride in both directions).
    pub ratio: usize,
    /// Minimum nodes per side of the coarsest level.
    pub min_nodes: usize,
    /// FTOL of the coarse levels (they only provide a start).
    pub coarse_ftol: f64,
}

impl Default for CoarseToFineOptions {
    fn default() -> Self {
        Self {
            smooth: SmoothOptions::default(),
            ratio: 3,
            min_nodes: 30,
            coarse_ftol: 1e-6,
        }
    }
}

impl CoarseToFineOptions {
    /// Sets [`smooth`](Self::smooth).
    #[must_use]
    pub fn smooth(mut self, smooth: SmoothOptions) -> Self {
        self.smooth = smooth;
        self
    }

    /// Sets [`ratio`](Self::ratio).
    #[must_use]
    pub fn ratio(mut self, ratio: usize) -> Self {
        self.ratio = ratio;
        self
    }

    /// Sets [`min_nodes`](Self::min_nodes): minimum nodes per side of the coarsest level.
    #[must_use]
    pub fn min_nodes(mut self, min_nodes: usize) -> Self {
        self.min_nodes = min_nodes;
        self
    }

    /// Sets [`coarse_ftol`](Self::coarse_ftol): FTOL of the coarse levels (they only provide a
    /// start).
    #[must_use]
    pub fn coarse_ftol(mut self, coarse_ftol: f64) -> Self {
        self.coarse_ftol = coarse_ftol;
        self
    }
}

/// One level of [`smooth_coarse_to_fine`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CoarseToFineLevel {
    /// Nodes along `i`.
    pub m: usize,
    /// Nodes along `j`.
    pub n: usize,
    /// `α₋/ᾱ` of the level's start (after prolongation and boundary reset).
    pub start_alfamin_rel: f64,
    /// The level restarted from the subsampled start (step 5 of the module docs).
    pub restarted: bool,
    /// The smoothing report of the level.
    pub report: SmoothReport,
}

/// The report of [`smooth_coarse_to_fine`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CoarseToFineReport {
    /// The levels, coarsest first; the last is the given grid.
    pub levels: Vec<CoarseToFineLevel>,
    /// The finest level was re-solved from the given start (module docs, contract).
    pub fallback: bool,
}

impl CoarseToFineReport {
    /// The report of the finest level.
    pub fn fine(&self) -> Option<&SmoothReport> {
        self.levels.last().map(|l| &l.report)
    }
}

/// The level sizes `(m, n)`, finest first (module docs).
pub fn level_sizes(m: usize, n: usize, ratio: usize, min_nodes: usize) -> Vec<(usize, usize)> {
    let mut out = vec![(m, n)];
    if ratio < 2 {
        return out;
    }
    loop {
        let (a, b) = out[out.len() - 1];
        if a < 2 || b < 2 || (a - 1) % ratio != 0 || (b - 1) % ratio != 0 {
            break;
        }
        let (ca, cb) = ((a - 1) / ratio + 1, (b - 1) / ratio + 1);
        if ca < min_nodes.max(3) || cb < min_nodes.max(3) {
            break;
        }
        out.push((ca, cb));
    }
    out
}

fn subsample(g: &StructuredGrid2, stride: usize) -> Result<StructuredGrid2, OptimError> {
    let (m, n) = ((g.m() - 1) / stride + 1, (g.n() - 1) / stride + 1);
    Ok(StructuredGrid2::from_fn(m, n, |i, j| {
        g.node(i * stride, j * stride)
    })?)
}

/// `(α₋/ᾱ, non-convex cells)` of a grid ([`unamalla_mesh::quality::alpha_stats`]: the corner
/// α alone, not a whole `QuadTopology` with its Hessian pattern, which made these calls 15 % of
/// the CPU time of the 1000² run).
fn quality(g: &StructuredGrid2) -> Result<(f64, usize), OptimError> {
    let s = unamalla_mesh::quality::alpha_stats(g);
    Ok((s.min / s.mean, s.non_convex_cells))
}

/// Puts the boundary of `exact` on `g` (same size) and moves the interior by the transfinite
/// interpolation of the boundary displacement (module docs, step 4).
fn reset_boundary(g: &mut StructuredGrid2, exact: &StructuredGrid2) {
    let (m, n) = (g.m(), g.n());
    let d = |g: &StructuredGrid2, i: usize, j: usize| exact.node(i, j) - g.node(i, j);
    let bottom: Vec<DVec2> = (0..m).map(|i| d(g, i, 0)).collect();
    let top: Vec<DVec2> = (0..m).map(|i| d(g, i, n - 1)).collect();
    let left: Vec<DVec2> = (0..n).map(|j| d(g, 0, j)).collect();
    let right: Vec<DVec2> = (0..n).map(|j| d(g, m - 1, j)).collect();
    // corner displacements (zero when the corners are shared by both levels)
    let (c00, c10, c01, c11) = (bottom[0], bottom[m - 1], top[0], top[m - 1]);
    for j in 0..n {
        let v = j as f64 / (n - 1) as f64;
        for i in 0..m {
            let u = i as f64 / (m - 1) as f64;
            let corr = (1.0 - u) * left[j] + u * right[j] + (1.0 - v) * bottom[i] + v * top[i]
                - ((1.0 - u) * (1.0 - v) * c00
                    + u * (1.0 - v) * c10
                    + (1.0 - u) * v * c01
                    + u * v * c11);
            let p = g.node(i, j) + corr;
            g.set_node(i, j, p);
        }
    }
    // exact boundary (the Boolean sum is exact there up to rounding)
    for j in 0..n {
        for i in 0..m {
            if g.is_boundary(i, j) {
                g.set_node(i, j, exact.node(i, j));
            }
        }
    }
}

/// The start of a finer level from a coarser result (module docs, steps 3 and 4): `coarse`
/// refined by bilinear interpolation (`ratio − 1` new lines per cell), then the exact boundary
/// of `fine` (a grid of the finer size, e.g. its TFI start) put back by the transfinite
/// correction of the boundary displacement.
///
/// Errors: `ratio < 2`, or sizes that do not match (`m_fine − 1 = ratio·(m_coarse − 1)`, the
/// same for `n`).
///
/// ```
/// use unamalla_optim::coarse_to_fine::prolongate;
/// use unamalla_optim::fixtures::sinusoidal;
///
/// let coarse = sinusoidal(11, 11, 0.1, 2.0)?;
/// let fine = sinusoidal(31, 31, 0.1, 2.0)?;
/// let p = prolongate(&coarse, &fine, 3)?;
/// assert_eq!((p.m(), p.n()), (31, 31));
/// assert_eq!(p.node(0, 7), fine.node(0, 7)); // the exact boundary
/// assert!((p.node(15, 15) - coarse.node(5, 5)).length() < 1e-12); // coarse nodes stay
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn prolongate(
    coarse: &StructuredGrid2,
    fine: &StructuredGrid2,
    ratio: usize,
) -> Result<StructuredGrid2, OptimError> {
    if ratio < 2 {
        return Err(OptimError::InvalidOption {
            name: "ratio",
            value: ratio as f64,
            reason: "the refinement ratio must be at least 2",
        });
    }
    if fine.m() - 1 != ratio * (coarse.m() - 1) || fine.n() - 1 != ratio * (coarse.n() - 1) {
        return Err(OptimError::InvalidOption {
            name: "ratio",
            value: ratio as f64,
            reason: "the fine grid must have ratio·(m − 1) + 1 × ratio·(n − 1) + 1 nodes of the coarse grid's m × n",
        });
    }
    let mut f = coarse.refined(ratio - 1, ratio - 1)?;
    reset_boundary(&mut f, fine);
    Ok(f)
}

/// Smooths `grid` coarse-to-fine (module docs). `grid` is the start (e.g. the TFI grid of the
/// region) and is overwritten with the result. Errors as [`smooth`] (invalid options, no free
/// nodes, a boundary enclosing no area) and for a ratio below 2.
///
/// ```
/// use unamalla_optim::fixtures::sinusoidal;
/// use unamalla_optim::{smooth_coarse_to_fine, CoarseToFineOptions, NullObserver};
///
/// // 28 nodes per side: one coarse level of (28 − 1)/3 + 1 = 10 nodes
/// let mut grid = sinusoidal(28, 28, 0.1, 2.0)?;
/// let opts = CoarseToFineOptions::default().min_nodes(8);
/// let rep = smooth_coarse_to_fine(&mut grid, &opts, &mut NullObserver)?;
/// assert_eq!(rep.levels.iter().map(|l| l.m).collect::<Vec<_>>(), vec![10, 28]);
/// assert!(rep.fine().is_some_and(|r| r.eps_convex));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn smooth_coarse_to_fine(
    grid: &mut StructuredGrid2,
    opts: &CoarseToFineOptions,
    observer: &mut dyn Observer,
) -> Result<CoarseToFineReport, OptimError> {
    if opts.ratio < 2 {
        return Err(OptimError::InvalidOption {
            name: "ratio",
            value: opts.ratio as f64,
            reason: "the refinement ratio must be at least 2",
        });
    }
    if !(opts.coarse_ftol.is_finite() && opts.coarse_ftol >= 0.0) {
        return Err(OptimError::InvalidOption {
            name: "coarse_ftol",
            value: opts.coarse_ftol,
            reason: "must be finite and ≥ 0",
        });
    }
    let start = grid.clone();
    let sizes = level_sizes(grid.m(), grid.n(), opts.ratio, opts.min_nodes);
    let nl = sizes.len();
    let coarse_opts = SmoothOptions {
        solver: crate::solver::SolverOptions {
            ftol: opts.coarse_ftol,
            ..opts.smooth.solver.clone()
        },
        ..opts.smooth.clone()
    };
    let eps = opts.smooth.eps;
    let mut levels = Vec::with_capacity(nl);
    let mut cur: Option<StructuredGrid2> = None;
    for (li, &(m, n)) in sizes.iter().enumerate().rev() {
        let stride = opts.ratio.pow(li as u32);
        let plain = if li == 0 {
            start.clone()
        } else {
            subsample(&start, stride)?
        };
        let mut restarted = false;
        let mut g = match cur.take() {
            None => plain.clone(),
            Some(c) => {
                let f = prolongate(&c, &plain, opts.ratio)?;
                let (q, _) = quality(&f)?;
                if q <= eps && quality(&plain)?.0 > eps {
                    restarted = true;
                    plain.clone()
                } else {
                    f
                }
            }
        };
        let (start_q, _) = quality(&g)?;
        let mut o = if li == 0 {
            opts.smooth.clone()
        } else {
            coarse_opts.clone()
        };
        if li + 1 < nl && !restarted {
            // a start prolonged from the level below: a polish run (StopRules::polish)
            o.solver.stop = o.solver.stop.polish();
        }
        let report = smooth(&mut g, &o, observer)?;
        levels.push(CoarseToFineLevel {
            m,
            n,
            start_alfamin_rel: start_q,
            restarted,
            report,
        });
        cur = Some(g);
    }
    let mut result = cur.unwrap_or_else(|| start.clone());
    let mut fallback = false;
    let (_, start_bad) = quality(&start)?;
    let (_, end_bad) = quality(&result)?;
    if end_bad > start_bad {
        fallback = true;
        result = start.clone();
        let report = smooth(&mut result, &opts.smooth, observer)?;
        levels.push(CoarseToFineLevel {
            m: result.m(),
            n: result.n(),
            start_alfamin_rel: quality(&start)?.0,
            restarted: true,
            report,
        });
    }
    *grid = result;
    Ok(CoarseToFineReport { levels, fallback })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::sinusoidal;
    use crate::monitor::NullObserver;
    use crate::solver::{Solver, SolverOptions};
    use crate::Preconditioner;

    #[test]
    fn level_sizes_divide_by_the_ratio() {
        // 999 = 3³·37: 1000 → 334 → 112 → 38 (→ 13 < 30 stops)
        assert_eq!(
            level_sizes(1000, 1000, 3, 30),
            vec![(1000, 1000), (334, 334), (112, 112), (38, 38)]
        );
        // 300 − 1 = 299 is not divisible by 3: one level
        assert_eq!(level_sizes(300, 300, 3, 30), vec![(300, 300)]);
        // both sides must divide
        assert_eq!(level_sizes(91, 101, 3, 10), vec![(91, 101)]);
        assert_eq!(
            level_sizes(91, 91, 3, 10),
            vec![(91, 91), (31, 31), (11, 11)]
        );
    }

    #[test]
    fn boundary_reset_is_exact_and_moves_the_interior_smoothly() {
        // prolongate the subsampled TFI grid and reset: the boundary equals the fine one, and
        // the interior correction is a transfinite interpolation, so every node moves by at
        // most the largest boundary displacement (it is a convex-like combination: the weights
        // (1−u), u, (1−v), v sum to 2, minus corner terms that vanish here)
        let fine = sinusoidal(61, 61, 0.1, 2.0).expect("grid");
        let coarse = subsample(&fine, 3).expect("subsample");
        let mut f = coarse.refined(2, 2).expect("refine");
        let before = f.clone();
        reset_boundary(&mut f, &fine);
        let mut dmax: f64 = 0.0;
        for j in 0..61 {
            for i in 0..61 {
                if fine.is_boundary(i, j) {
                    assert_eq!(f.node(i, j), fine.node(i, j));
                    dmax = dmax.max((fine.node(i, j) - before.node(i, j)).length());
                }
            }
        }
        assert!(dmax > 0.0, "the sinusoidal boundary is curved");
        for j in 0..61 {
            for i in 0..61 {
                assert!((f.node(i, j) - before.node(i, j)).length() <= 2.0 * dmax + 1e-15);
            }
        }
    }

    #[test]
    fn coarse_to_fine_reaches_the_direct_optimum() {
        // same functional, same tolerance: the coarse-to-fine result is ε-convex and its F
        // agrees with the direct run from the TFI grid (both are the same local minimum)
        let opts = SmoothOptions {
            solver: SolverOptions {
                max_iter: 300,
                ftol: 1e-11,
                gtol: 0.0,
                preconditioner: Preconditioner::Multigrid,
                ..SolverOptions::new(Solver::TnTr)
            },
            ..SmoothOptions::default()
        };
        let mut direct = sinusoidal(46, 46, 0.1, 2.0).expect("grid");
        let rd = smooth(&mut direct, &opts, &mut NullObserver).expect("direct");
        let mut g = sinusoidal(46, 46, 0.1, 2.0).expect("grid");
        let co = CoarseToFineOptions {
            smooth: opts,
            min_nodes: 10,
            ..CoarseToFineOptions::default()
        };
        let rep = smooth_coarse_to_fine(&mut g, &co, &mut NullObserver).expect("c2f");
        assert_eq!(rep.levels.len(), 2, "46 → 16");
        assert!(!rep.fallback);
        let fine = rep.fine().expect("fine level");
        assert!(fine.eps_convex && rd.eps_convex);
        assert!(
            (fine.f - rd.f).abs() <= 1e-7 * rd.f,
            "c2f F {} vs direct F {}",
            fine.f,
            rd.f
        );
        let (q, bad) = quality(&g).expect("quality");
        assert_eq!(bad, 0);
        assert!(q > 0.01);
    }

    #[test]
    fn prolongate_checks_the_sizes() {
        let coarse = sinusoidal(11, 11, 0.1, 2.0).expect("grid");
        let fine = sinusoidal(31, 31, 0.1, 2.0).expect("grid");
        assert!(prolongate(&coarse, &fine, 3).is_ok());
        for r in [1, 2, 4] {
            assert!(
                matches!(
                    prolongate(&coarse, &fine, r),
                    Err(OptimError::InvalidOption { name: "ratio", .. })
                ),
                "ratio {r}"
            );
        }
    }

    #[test]
    fn invalid_ratio_is_an_error() {
        let mut g = sinusoidal(10, 10, 0.1, 2.0).expect("grid");
        let co = CoarseToFineOptions {
            ratio: 1,
            ..CoarseToFineOptions::default()
        };
        assert!(matches!(
            smooth_coarse_to_fine(&mut g, &co, &mut NullObserver),
            Err(OptimError::InvalidOption { name: "ratio", .. })
        ));
    }
}
