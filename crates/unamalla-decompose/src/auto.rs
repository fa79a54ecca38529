//! The automatic decomposition's options and entry points: Algorithm 1 driving Algorithms
//! 2–4 ([Méndez 2023, §4.2.1]) with the cut score documented in the crate root, and the chord
//! layout driver (layout cuts, arm cuts, withdrawal of layout cuts). The state and the stages
//! of a decomposition are in module `builder`.

use std::collections::HashMap;
use std::sync::Arc;

use rayon::prelude::*;

use unamalla_mesh::{DVec2, Region};

use crate::builder::{layout_from_cuts_cached, Builder, LayoutCache};
use crate::concavity::Tolerances;
use crate::corners::CornerWeights;
use crate::decomposition::{Decomposition, EdgeKind};
use crate::error::DecomposeError;

/// Weights of the cut score S (see the crate documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CutWeights {
    /// w_a: weight of the angle penalty of the four new angles at the cut ends.
    pub angle: f64,
    /// w_l: weight of the cut length relative to √area of the piece.
    pub length: f64,
    /// w_h: weight of the hole-arc balance of the second hole cut.
    pub hole_balance: f64,
}

impl Default for CutWeights {
    fn default() -> Self {
        Self {
            angle: 0.5,
            length: 0.1,
            hole_balance: 1.5,
        }
    }
}

/// Options of [`decompose`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct DecomposeOptions {
    /// Concavity tolerances and the critical angle θ₋.
    pub tolerances: Tolerances,
    /// Pieces smaller than this fraction of the region's area are "negligible": no cut may
    /// create one (default 2·10⁻⁴).
    pub min_area_fraction: f64,
    /// Stop splitting when this many blocks exist (default 400).
    pub max_blocks: usize,
    /// How many of the deepest reflex vertices are tried as the start p of a concavity cut
    /// (default 10).
    pub concave_starts: usize,
    /// Cut score weights.
    pub cut_weights: CutWeights,
    /// Corner score weights.
    pub corner_weights: CornerWeights,
    /// Run Algorithm 4 (extract triangles around critical angles; default `true`).
    pub critical_triangles: bool,
    /// Run the cleanup pass that removes cuts whose two blocks form a better block together
    /// (default `true`).
    pub merge_blocks: bool,
    /// Blunt a triangle block's critical vertex (interior angle below θ₋) as [Méndez 2023,
    /// §4.3] does: two points inserted on its edges become corners and the vertex lies inside
    /// the short side between them, so the mesh node there is shared by two cells of about
    /// half its angle each. Default `false`: the critical vertex is a corner itself (one cell
    /// with its whole angle) and the fourth corner is the midpoint of the longest side.
    /// Measured on the 34 development regions (docs/results.md, "Sharp tips as corners"):
    /// the smallest scaled Jacobian rose on 14 of 16 changed regions at 5,000 cells and on 15
    /// of 18 at 20,000 (e.g. 0.04–0.09 → 0.10–0.13), and OpenFOAM's `checkMesh` passes on
    /// Puget Sound at 12,000 and 20,000 cells where a split 36° tip failed its skewness test.
    pub blunt_critical_tips: bool,
    /// Distance of the points inserted by the triangle-block rule at a critical vertex
    /// ([`blunt_critical_tips`](Self::blunt_critical_tips)), as a fraction of the shorter
    /// incident edge (default 0.25).
    pub triangle_insert_fraction: f64,
    /// Algorithm 4 extracts a triangle around a critical angle when its area is at least this
    /// fraction of the region's area (default 10⁻⁵, a fifth of the mean cell area of a
    /// 20,000-cell mesh). Smaller than `min_area_fraction` on purpose: a sharp cape or the end
    /// of a narrow inlet is often a small piece of the region, and leaving its critical angle
    /// in a block is worse than a small triangle block.
    pub min_triangle_fraction: f64,
    /// Run the corner-repair pass on blocks without four usable corners (interior angle
    /// below `corner_weights.corner_angle_limit`): a cut splitting the block into two blocks
    /// that have four usable corners each, or a merge with a neighbour followed by such a cut
    /// (default `true`).
    pub repair_corners: bool,
    /// Let the corner repair end a cut at the ¼, ½ or ¾ point of an original-boundary edge
    /// when no split at vertices or perpendicular feet is acceptable (default `false`). It
    /// makes a few more blocks admissible (at pipeline defaults 662 of 666 with it), but on
    /// the bundled Norway region the end-to-end mesh got worse with it (μ ≥ 0.8 on 79.2 %
    /// of the cells against 88.6 % without, `mesh_region` example, 2026-11-22), so it is off
    /// by default.
    pub edge_point_cuts: bool,
    /// Which layout places the first cuts (default [`Layout::Chords`]).
    pub layout: Layout,
    /// Aspect threshold T of a transverse chord cut: the smaller side must extend at least T
    /// chord widths (default [`DEFAULT_ASPECT`](crate::chords::DEFAULT_ASPECT)).
    pub chord_aspect: f64,
    /// The cell size the mesh will have, if known: the chord layout samples the boundary at
    /// most this far apart (default `None`: perimeter/1500).
    pub cell_size: Option<f64>,
}

/// How the first cuts of a decomposition are placed (crate docs, "Layouts").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Layout {
    /// The thesis's Algorithm 1 alone: hole removal (Algorithm 2) and concavity cuts
    /// (Algorithm 3) from the deepest reflex vertices.
    Concavity,
    /// Hole bridges and transverse cuts chosen from the chords of the boundary's constrained
    /// Delaunay triangulation (module `chords`), then Algorithm 1 on the pieces. [`decompose`]
    /// falls back to [`Layout::Concavity`] when the chord layout cannot be built (the tree
    /// then has no [`Step::Chord`](crate::Step::Chord) node); [`chord_layout`] reports the error instead.
    #[default]
    Chords,
}

impl Default for DecomposeOptions {
    fn default() -> Self {
        Self {
            tolerances: Tolerances::default(),
            min_area_fraction: 2e-4,
            max_blocks: 2000,
            concave_starts: 10,
            cut_weights: CutWeights::default(),
            corner_weights: CornerWeights::default(),
            critical_triangles: true,
            merge_blocks: true,
            blunt_critical_tips: false,
            triangle_insert_fraction: 0.25,
            min_triangle_fraction: 1e-5,
            repair_corners: true,
            edge_point_cuts: false,
            layout: Layout::default(),
            chord_aspect: crate::chords::DEFAULT_ASPECT,
            cell_size: None,
        }
    }
}

impl DecomposeOptions {
    /// Sets [`tolerances`](Self::tolerances): concavity tolerances and the critical angle θ₋.
    #[must_use]
    pub fn tolerances(mut self, tolerances: Tolerances) -> Self {
        self.tolerances = tolerances;
        self
    }

    /// Sets [`min_area_fraction`](Self::min_area_fraction).
    #[must_use]
    pub fn min_area_fraction(mut self, min_area_fraction: f64) -> Self {
        self.min_area_fraction = min_area_fraction;
        self
    }

    /// Sets [`max_blocks`](Self::max_blocks): stop splitting when this many blocks exist (default
    /// 400).
    #[must_use]
    pub fn max_blocks(mut self, max_blocks: usize) -> Self {
        self.max_blocks = max_blocks;
        self
    }

    /// Sets [`concave_starts`](Self::concave_starts).
    #[must_use]
    pub fn concave_starts(mut self, concave_starts: usize) -> Self {
        self.concave_starts = concave_starts;
        self
    }

    /// Sets [`cut_weights`](Self::cut_weights): cut score weights.
    #[must_use]
    pub fn cut_weights(mut self, cut_weights: CutWeights) -> Self {
        self.cut_weights = cut_weights;
        self
    }

    /// Sets [`corner_weights`](Self::corner_weights): corner score weights.
    #[must_use]
    pub fn corner_weights(mut self, corner_weights: CornerWeights) -> Self {
        self.corner_weights = corner_weights;
        self
    }

    /// Sets [`critical_triangles`](Self::critical_triangles).
    #[must_use]
    pub fn critical_triangles(mut self, critical_triangles: bool) -> Self {
        self.critical_triangles = critical_triangles;
        self
    }

    /// Sets [`merge_blocks`](Self::merge_blocks).
    #[must_use]
    pub fn merge_blocks(mut self, merge_blocks: bool) -> Self {
        self.merge_blocks = merge_blocks;
        self
    }

    /// Sets [`blunt_critical_tips`](Self::blunt_critical_tips).
    #[must_use]
    pub fn blunt_critical_tips(mut self, blunt_critical_tips: bool) -> Self {
        self.blunt_critical_tips = blunt_critical_tips;
        self
    }

    /// Sets [`triangle_insert_fraction`](Self::triangle_insert_fraction).
    #[must_use]
    pub fn triangle_insert_fraction(mut self, triangle_insert_fraction: f64) -> Self {
        self.triangle_insert_fraction = triangle_insert_fraction;
        self
    }

    /// Sets [`min_triangle_fraction`](Self::min_triangle_fraction).
    #[must_use]
    pub fn min_triangle_fraction(mut self, min_triangle_fraction: f64) -> Self {
        self.min_triangle_fraction = min_triangle_fraction;
        self
    }

    /// Sets [`repair_corners`](Self::repair_corners).
    #[must_use]
    pub fn repair_corners(mut self, repair_corners: bool) -> Self {
        self.repair_corners = repair_corners;
        self
    }

    /// Sets [`edge_point_cuts`](Self::edge_point_cuts).
    #[must_use]
    pub fn edge_point_cuts(mut self, edge_point_cuts: bool) -> Self {
        self.edge_point_cuts = edge_point_cuts;
        self
    }

    /// Sets [`layout`](Self::layout): which layout places the first cuts (default
    /// [`Layout::Chords`]).
    #[must_use]
    pub fn layout(mut self, layout: Layout) -> Self {
        self.layout = layout;
        self
    }

    /// Sets [`chord_aspect`](Self::chord_aspect).
    #[must_use]
    pub fn chord_aspect(mut self, chord_aspect: f64) -> Self {
        self.chord_aspect = chord_aspect;
        self
    }

    /// Sets [`cell_size`](Self::cell_size).
    #[must_use]
    pub fn cell_size(mut self, cell_size: Option<f64>) -> Self {
        self.cell_size = cell_size;
        self
    }
}

/// Decomposes a region automatically into admissible blocks with four corners each
/// (Algorithm 1 with exclusive branches: holes → Algorithm 2, not approximately convex →
/// Algorithm 3, critical angles → Algorithm 4), then selects corners.
pub fn decompose(
    region: &Region,
    opts: &DecomposeOptions,
) -> Result<Decomposition, DecomposeError> {
    if opts.layout == Layout::Chords {
        match chord_layout(region, opts) {
            Ok(d) => return Ok(d),
            Err(e) => {
                if std::env::var_os("UNAMALLA_LAYOUT_DEBUG").is_some() {
                    eprintln!("chord layout failed, falling back to the concavity layout: {e}");
                }
            }
        }
    }
    let mut b = Builder::new(region, opts);
    b.run_auto(0)?;
    b.finish()
}

/// The chord layout (module `chords`): its cuts first, then Algorithm 1 on every piece.
pub fn chord_layout(
    region: &Region,
    opts: &DecomposeOptions,
) -> Result<Decomposition, DecomposeError> {
    chord_layout_cuts(region, opts).map(|(_, d)| d)
}

/// [`chord_layout`] with its layout cuts: the ordered cut list (hole bridges, closing chords,
/// transverse cuts, arm cuts) that [`layout_from_cuts`] turns into the same decomposition.
/// A caller can append cuts to the list and rebuild (the mesher's predicted-quality
/// re-split, `unamalla_core::pipeline::choose_layout`).
pub fn chord_layout_cuts(
    region: &Region,
    opts: &DecomposeOptions,
) -> Result<(Vec<(DVec2, DVec2)>, Decomposition), DecomposeError> {
    let per = region.perimeter();
    let spacing = opts
        .cell_size
        .unwrap_or(f64::INFINITY)
        .min(per / 1500.0)
        .max(per / 20000.0);
    let mut cuts = crate::chords::layout_cuts(
        region,
        spacing,
        opts.chord_aspect,
        opts.min_area_fraction * region.area(),
    )
    .map_err(|e| DecomposeError::Layout(e.0))?;
    // up to ARM_ROUNDS times: blocks that still keep an arm (a part ≥ ARM_SCORE chord widths
    // beyond a chord between two boundary points) get that chord as one more layout cut
    let mut d = None;
    // the layouts below run Algorithm 1 on mostly the same pieces and repair mostly the
    // same blocks: those results are shared (exact, see LayoutCache)
    let cache = Arc::new(LayoutCache::default());
    // the arm chord of a block depends only on its ring and which edges are region boundary;
    // most blocks come back unchanged from one round to the next, so each is searched once
    // (the search triangulates the block, the costliest step of the layout)
    let mut searched: HashMap<Vec<u64>, Option<(DVec2, DVec2)>> = HashMap::new();
    for round in 0..=ARM_ROUNDS {
        let dec = layout_from_cuts_cached(region, opts, &cuts, Some(&cache))?;
        let extra: Vec<(DVec2, DVec2)> = if round < ARM_ROUNDS {
            let keyed: Vec<(Vec<u64>, Vec<bool>)> = dec
                .blocks
                .iter()
                .map(|blk| {
                    let on: Vec<bool> = blk
                        .edges
                        .iter()
                        .map(|e| matches!(e, EdgeKind::Boundary { .. }))
                        .collect();
                    let mut key = blk.geometry_key();
                    key.extend(on.iter().map(|&b| b as u64));
                    (key, on)
                })
                .collect();
            // blocks not searched before, in block order; searched in parallel (the results
            // are collected in that order, so the layout does not depend on the threads)
            let todo: Vec<usize> = (0..keyed.len())
                .filter(|&b| !searched.contains_key(&keyed[b].0))
                .collect();
            let found: Vec<Option<(DVec2, DVec2)>> = todo
                .par_iter()
                .map(|&b| {
                    crate::chords::arm_chord(&dec.blocks[b].ring, &keyed[b].1, ARM_SCORE, 0.0)
                })
                .collect();
            for (&b, f) in todo.iter().zip(found) {
                searched.insert(keyed[b].0.clone(), f);
            }
            keyed
                .iter()
                .filter_map(|(key, _)| searched.get(key).copied().flatten())
                .collect()
        } else {
            Vec::new()
        };
        d = Some(dec);
        if extra.is_empty() {
            break;
        }
        cuts.extend(extra);
    }
    let mut d = d.ok_or_else(|| DecomposeError::Layout("no decomposition".into()))?;
    // a layout cut bordering a block that Algorithm 1 could not make admissible (a sliver
    // between a chord and the coast, too small for Algorithm 3 or 4 to cut) is withdrawn,
    // and the piece is left to Algorithm 1 alone, while that lowers the number of such blocks
    let tol = crate::decomposition::boundary_tol(region);
    for _ in 0..WITHDRAW_ROUNDS {
        if d.blocks.len() > WITHDRAW_MAX_BLOCKS {
            break;
        }
        let bad = inadmissible_blocks(&d, &opts.tolerances);
        if bad.is_empty() {
            break;
        }
        let on = |x: DVec2, (p, q): (DVec2, DVec2)| {
            unamalla_mesh::geometry::point_segment_distance(x, p, q) <= tol
        };
        let mut drop = vec![false; cuts.len()];
        for &b in &bad {
            for e in &d.blocks[b].edges {
                if let EdgeKind::Cut { cut, .. } = *e {
                    let c = &d.cuts[cut];
                    for (k, &lc) in cuts.iter().enumerate() {
                        if on(c.a, lc) && on(c.b, lc) {
                            drop[k] = true;
                        }
                    }
                }
            }
        }
        if !drop.iter().any(|&x| x) {
            break;
        }
        let kept: Vec<(DVec2, DVec2)> = cuts
            .iter()
            .zip(&drop)
            .filter(|(_, &x)| !x)
            .map(|(&c, _)| c)
            .collect();
        let nd = layout_from_cuts_cached(region, opts, &kept, Some(&cache))?;
        if inadmissible_blocks(&nd, &opts.tolerances).len() >= bad.len() {
            break;
        }
        cuts = kept;
        d = nd;
    }
    Ok((cuts, d))
}

/// Rounds of layout-cut withdrawal in [`chord_layout_cuts`].
const WITHDRAW_ROUNDS: usize = 3;
/// Layouts with more blocks than this get no withdrawal: each round rebuilds the whole layout
/// (work linear in its blocks and rings), so the withdrawal's work is bounded by
/// `WITHDRAW_ROUNDS` rebuilds of a layout of at most this size.
const WITHDRAW_MAX_BLOCKS: usize = 600;

/// The blocks of `d` that are not admissible ([`Decomposition::block_admissible`]).
fn inadmissible_blocks(d: &Decomposition, tol: &Tolerances) -> Vec<usize> {
    (0..d.blocks.len())
        .filter(|&b| !d.block_admissible(b, tol))
        .collect()
}

/// The decomposition with the given **layout cuts**: each straight cut `p`–`q` (both ends on
/// the region boundary or on an earlier cut of the list) is applied in order to the piece
/// that admits it, the layout cuts are protected from the merge pass, and Algorithm 1
/// finishes every piece. A cut no piece admits (an end off every piece boundary, or a cut
/// crossing an earlier one) is skipped: Algorithm 1 then treats that piece as it would
/// without it.
pub fn layout_from_cuts(
    region: &Region,
    opts: &DecomposeOptions,
    cuts: &[(DVec2, DVec2)],
) -> Result<Decomposition, DecomposeError> {
    layout_from_cuts_cached(region, opts, cuts, None)
}

/// A straight cut that splits block `blk` of `d` (a decomposition of `region`) across its
/// narrowest place relative to its size: the chord with the highest `min(A₁, A₂)/w²` of at least `min_score` (module `chords`)
/// whose ends lie on the region boundary or on one of the `layout` cuts (so that
/// [`layout_from_cuts`] can replay it after them), meeting the boundary at no less than
/// [`crate::chords::MIN_END_ANGLE_DEG`], and leaving at least `min_area` on its smaller side.
/// `None` if the block has no such chord.
pub fn split_chord(
    region: &Region,
    d: &Decomposition,
    blk: usize,
    layout: &[(DVec2, DVec2)],
    min_score: f64,
    min_area: f64,
) -> Option<(DVec2, DVec2)> {
    let tol = crate::decomposition::boundary_tol(region);
    let b = d.blocks.get(blk)?;
    let n = b.ring.len();
    let on_layout = |p: DVec2| {
        layout
            .iter()
            .any(|&(a, q)| unamalla_mesh::geometry::point_segment_distance(p, a, q) <= tol)
    };
    let on: Vec<bool> = (0..n)
        .map(|i| match b.edges[i] {
            EdgeKind::Boundary { .. } => true,
            EdgeKind::Cut { .. } => on_layout(b.ring[i]) && on_layout(b.ring[(i + 1) % n]),
        })
        .collect();
    crate::chords::arm_chord(&b.ring, &on, min_score, min_area)
}

/// A block part extending at least this many chord widths beyond a chord (the chord's
/// `min(A₁, A₂)/w²`, module `chords`) is an arm: the chord layout cuts it off.
pub const ARM_SCORE: f64 = 4.0;
/// Rounds of arm cuts after the first decomposition.
const ARM_ROUNDS: usize = 2;
