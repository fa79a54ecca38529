//! The automatic decomposition: Algorithm 1 driving Algorithms 2–4 ([Méndez 2023, §4.2.1]),
//! with the cut score documented in the crate root, and the assembly of the final blocks.

use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use unamalla_mesh::{DVec2, Region};

use crate::concavity::{concavity_with_hull, measures, measures_with_hull, Tolerances};
use crate::corners::{
    quad_fit, quad_fit_with_angles, select_corners, triangle_rule, CornerWeights, TriangleBlock,
};
use crate::decomposition::{Block, Cut, Decomposition, EdgeKind, Step, TreeNode};
use crate::error::DecomposeError;
use crate::geom::{
    angle_penalty, child_hull, child_hull_order, convex_hull, hull_from_order, hull_order,
    left_angle, match_vertices, perimeter, project_t, ray_segment, ring_angle, ring_angles,
    ring_angles_matched, total_key, visit_sorted, HullKey,
};
use crate::piece::{End, Piece, Pos, Ring, Tag};
use crate::repair::RepairCache;

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
    /// Distance of the points inserted by the triangle-block rule, as a fraction of the
    /// shorter incident edge (default 0.25).
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
    /// then has no [`Step::Chord`] node); [`chord_layout`] reports the error instead.
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

/// Results that the layouts of one region with one option set share (the rebuilds of
/// [`chord_layout_cuts`] after each round of arm cuts and each withdrawal differ from each
/// other in a few pieces only). Each entry is keyed by everything its computation reads, so
/// a hit returns exactly what the computation would; see [`Builder::run_auto_on_leaves`] and
/// the repair pass (`Builder::cached_attempt`).
#[derive(Default)]
pub(crate) struct LayoutCache {
    /// Repair attempts (module `repair`).
    pub repair: Mutex<RepairCache>,
    /// Algorithm 1 on a leaf piece, keyed by [`piece_key`].
    leaf_runs: Mutex<HashMap<Vec<u64>, Arc<LeafRun>>>,
    /// Algorithm 1 on a piece met inside a run, keyed by [`node_key`] (see
    /// [`Builder::run_node`]).
    node_runs: Mutex<HashMap<Vec<u64>, Arc<NodeRun>>>,
    /// The builder after applying each layout's cut list ([`AppliedCuts`]).
    applied: Mutex<Vec<Arc<AppliedCuts>>>,
    /// The merge pass's tests of blocks and unions.
    merges: MergeMemo,
}

/// The merge pass's tests ([`Builder::merge_pass`]), each computed once: pure functions of
/// the points they are keyed by (and of the options, the same for every builder sharing
/// them), so a hit returns what the computation would.
#[derive(Default)]
pub(crate) struct MergeMemo {
    /// `quad_fit` of a ring, keyed by its points.
    fits: Mutex<HashMap<Vec<u64>, f64>>,
    /// [`MergeMemo::union_fit`], keyed by the two rings' points and cut edges.
    unions: Mutex<HashMap<Vec<u64>, Option<f64>>>,
}

/// The bits of `pts`, appended to `key` after their count.
fn push_points(key: &mut Vec<u64>, pts: &[DVec2]) {
    key.push(pts.len() as u64);
    key.extend(pts.iter().flat_map(|p| [p.x.to_bits(), p.y.to_bits()]));
}

impl MergeMemo {
    /// `quad_fit(pts)`.
    fn fit(&self, pts: &[DVec2]) -> f64 {
        let mut key = Vec::with_capacity(2 * pts.len() + 1);
        push_points(&mut key, pts);
        if let Some(&f) = self
            .fits
            .lock()
            .ok()
            .and_then(|m| m.get(&key).copied())
            .as_ref()
        {
            return f;
        }
        let f = quad_fit(pts);
        if let Ok(mut m) = self.fits.lock() {
            m.insert(key, f);
        }
        f
    }

    /// The corner score (`quad_fit`) of the union of blocks `a` and `b` across their cut
    /// edges `ea` and `eb` ([`crate::repair::union_ring`]), if the merge pass may make it: the
    /// two share exactly two points, and the union is approximately convex without a
    /// critical angle; `None` otherwise.
    fn union_fit(&self, tol: &Tolerances, a: &Ring, ea: usize, b: &Ring, eb: usize) -> Option<f64> {
        let mut key = Vec::with_capacity(2 * (a.len() + b.len()) + 4);
        push_points(&mut key, &a.pts);
        key.push(ea as u64);
        push_points(&mut key, &b.pts);
        key.push(eb as u64);
        if let Some(f) = self.unions.lock().ok().and_then(|m| m.get(&key).copied()) {
            return f;
        }
        let f = (|| {
            let shared = a.pts.iter().filter(|p| b.pts.contains(p)).count();
            if shared != 2 {
                return None;
            }
            let u = crate::repair::union_ring(a, ea, b, eb)?;
            let conc = measures(&u.pts);
            if !conc.approximately_convex(tol)
                || !crate::concavity::critical_angles(&u.pts, tol.theta_minus).is_empty()
            {
                return None;
            }
            Some(quad_fit(&u.pts))
        })();
        if let Ok(mut m) = self.unions.lock() {
            m.insert(key, f);
        }
        f
    }
}

/// A [`Builder`] (of the cache's region and options) right after [`Builder::apply_cut`] of
/// each cut of `layout` in order. The rebuilds of [`chord_layout_cuts`] extend the cut list
/// of the layout before them, so they can start from its state and apply only the new cuts.
/// Exact: applying a cut reads and changes only the builder's cuts, tree nodes and pieces,
/// which start from the region alone, so the state after a list of cuts is a function of the
/// region and that list (matched bit for bit, [`same_cuts`]).
struct AppliedCuts {
    layout: Vec<(DVec2, DVec2)>,
    cuts: Vec<(DVec2, DVec2)>,
    nodes: Vec<TreeNode>,
    pieces: Vec<Option<Piece>>,
}

/// Whether two cut lists are the same, coordinates compared bit for bit.
fn same_cuts(a: &[(DVec2, DVec2)], b: &[(DVec2, DVec2)]) -> bool {
    let bits = |p: DVec2| (p.x.to_bits(), p.y.to_bits());
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| bits(x.0) == bits(y.0) && bits(x.1) == bits(y.1))
}

/// The exact content of a piece (vertex bits, edge tags with their cut ids, per ring).
fn piece_key(piece: &Piece) -> Vec<u64> {
    let mut key = Vec::new();
    for r in piece.rings() {
        r.push_key(&mut key, |c, key| key.extend([1, c as u64]));
    }
    key
}

/// What Algorithm 1 computes of a ring before cutting it: the vertex angles, the points in
/// hull order, the convex hull (and whether the points are pairwise different) and the
/// concavity measures — those of [`concavity`], computed the same way.
struct Shape {
    angle: Vec<f64>,
    hull_keys: Vec<HullKey>,
    hull: Vec<usize>,
    distinct: bool,
    conc: crate::concavity::Concavity,
}

impl Shape {
    /// The shape of the ring `pts`.
    fn of(pts: &[DVec2]) -> Self {
        let angle = ring_angles(pts);
        let hull_keys = hull_order(pts);
        let (hull, distinct) = hull_from_order(pts, &hull_keys);
        let conc = concavity_with_hull(pts, &angle, hull.clone());
        Self {
            angle,
            hull_keys,
            hull,
            distinct,
            conc,
        }
    }
}

/// The content of a piece up to its cut ids, and those ids: the points, per edge the region
/// ring or, for a cut, its number in the order the cuts first appear (the piece's rings in
/// order); the cut ids in that order.
fn node_key(piece: &Piece) -> (Vec<u64>, Vec<usize>) {
    let mut key = Vec::new();
    let mut ids: Vec<usize> = Vec::new();
    for r in piece.rings() {
        r.push_key(&mut key, |c, key| {
            let k = ids.iter().position(|&x| x == c).unwrap_or_else(|| {
                ids.push(c);
                ids.len() - 1
            });
            key.extend([1, k as u64]);
        });
    }
    (key, ids)
}

/// `piece` with each cut id `c` replaced by `number(c)`; `Err` if one has no number.
fn renumber_piece(piece: &Piece, number: &dyn Fn(usize) -> Option<usize>) -> Result<Piece, ()> {
    let mut p = piece.clone();
    for r in std::iter::once(&mut p.outer).chain(p.holes.iter_mut()) {
        for t in &mut r.tags {
            if let Tag::Cut(c) = t {
                *c = number(*c).ok_or(())?;
            }
        }
    }
    Ok(p)
}

/// Pieces at least this long keep their [`NodeRun`] in the cache (shorter ones are cheap
/// to cut again).
const NODE_RUN_MIN_LEN: usize = 16;

/// What Algorithm 1 did on a piece ([`Builder::run_node`]), with the piece's cuts numbered
/// as in its [`node_key`] and the cuts it made numbered after them, in order.
pub(crate) struct NodeRun {
    /// The leaves of the subtree (1: the piece was left whole).
    leaves: usize,
    /// The split made on the piece, `None` if it was left whole.
    split: Option<NodeSplit>,
}

/// A split of a [`NodeRun`].
struct NodeSplit {
    step: Step,
    /// The new cuts, in the order they were made.
    cuts: Vec<(DVec2, DVec2)>,
    /// The two children (the first one of a split by Algorithm 4, the triangle, is left
    /// whole).
    children: [ChildRun; 2],
}

/// A child of a [`NodeSplit`]: its piece if it was left whole (numbered as the parent), the
/// parent's number of each of its cuts in its own [`node_key`] order, and its run.
struct ChildRun {
    piece: Option<Piece>,
    ids: Vec<usize>,
    run: Arc<NodeRun>,
}

/// Algorithm 1 ([`Builder::run_auto`]) on one leaf piece, run in a builder of its own: the
/// nodes it added (node 0 is the leaf, with an empty label), the cuts it made, the pieces.
/// Cut ids from `base` on are its new cuts (`cuts[c - base]`), lower ones are the cuts the
/// piece had already.
struct LeafRun {
    base: usize,
    cuts: Vec<(DVec2, DVec2)>,
    nodes: Vec<TreeNode>,
    pieces: Vec<Option<Piece>>,
}

/// [`layout_from_cuts`] with the Algorithm 1 runs and repair attempts of earlier layouts of
/// the same region and options ([`LayoutCache`]; the cache only saves work: every entry is
/// what the builder would compute).
fn layout_from_cuts_cached(
    region: &Region,
    opts: &DecomposeOptions,
    cuts: &[(DVec2, DVec2)],
    cache: Option<&Arc<LayoutCache>>,
) -> Result<Decomposition, DecomposeError> {
    let tol = crate::decomposition::boundary_tol(region);
    let mut b = Builder::new(region, opts);
    b.cache = cache.cloned();
    // start from the state of the longest cut list applied before that begins this one
    let start = cache
        .and_then(|c| {
            let applied = c.applied.lock().ok()?;
            applied
                .iter()
                .filter(|a| a.layout.len() <= cuts.len())
                .filter(|a| same_cuts(&a.layout, &cuts[..a.layout.len()]))
                .max_by_key(|a| a.layout.len())
                .cloned()
        })
        .map_or(0, |a| {
            b.cuts.clone_from(&a.cuts);
            b.nodes.clone_from(&a.nodes);
            b.pieces.clone_from(&a.pieces);
            a.layout.len()
        });
    for &(p, q) in &cuts[start..] {
        b.apply_cut(p, q, tol, Step::Chord);
    }
    if let Some(c) = cache.filter(|_| start < cuts.len()) {
        if let Ok(mut applied) = c.applied.lock() {
            applied.push(Arc::new(AppliedCuts {
                layout: cuts.to_vec(),
                cuts: b.cuts.clone(),
                nodes: b.nodes.clone(),
                pieces: b.pieces.clone(),
            }));
        }
    }
    b.protected_cuts = b.cuts.len();
    b.run_auto_on_leaves()?;
    b.finish()
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

/// What [`Builder::apply_cut`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Applied {
    /// The cut split a piece in two.
    Split,
    /// The cut joined a hole to its piece's outer ring.
    Bridged,
    /// The only piece admitting the cut has both ends on holes not yet joined.
    JoinsTwoHoles,
    /// No piece has both ends on its boundary and admits the cut.
    NoPiece,
}

/// A candidate cut inside a piece.
#[derive(Clone, Copy, Debug)]
struct Cand {
    e1: End,
    e2: End,
    pre: f64,
}

pub(crate) struct Builder<'a> {
    pub region: &'a Region,
    pub opts: &'a DecomposeOptions,
    pub cuts: Vec<(DVec2, DVec2)>,
    pub nodes: Vec<TreeNode>,
    pub pieces: Vec<Option<Piece>>,
    /// Cuts with an id below this were given by the user and are never merged away.
    pub protected_cuts: usize,
    pub(crate) min_area: f64,
    min_triangle: f64,
    /// Run the corner repair in [`Builder::finish`] (off for a file that lists cuts only: those
    /// are exactly the user's cuts).
    pub auto_repair: bool,
    /// Work shared with the other builders of one region and option set (the rebuilds of
    /// [`chord_layout_cuts`]); `None`: nothing is cached.
    pub(crate) cache: Option<Arc<LayoutCache>>,
    /// [`AngleScreen`]s of the angle limits of [`Builder::angle_terms`]'s tiers 0–1, 2 and 3.
    screens: [AngleScreen; 3],
}

/// A test deciding cheaply, for some vertex chains, that [`left_angle`] is below a limit λ or
/// above π + 10⁻⁹ — decisions that [`Builder::angle_terms`] would reach from the `atan2`
/// angle — and nothing otherwise.
///
/// `left_angle(prev, cur, next)` is `atan2(y, x)` (plus 2π when that is ≤ 0) for
/// `y = u.perp_dot(v)`, `x = u.dot(v)`, `u = next − cur`, `v = prev − cur`; the test reads the
/// same `y` and `x`. Below λ (0 < λ < 1.4): `y > 0`, `x > 0` and `r = fl(y/x)` in
/// `[10⁻²⁰⁰, tan λ·(1 − 10⁻⁹))`. Then `y/x` is within 2⁻⁵² of `r` (relative), so the true
/// angle `atan(y/x)` is at least 10⁻²⁰⁰·(1 − 10⁻¹⁵) and at least 10⁻¹⁰·λ below λ — far more
/// than the error of `atan2` and of `tan` (a few units in the last place): the computed angle
/// is in `(0, λ)` as well. Above π + 10⁻⁹: `y < 0` and either `x ≥ 0` (the computed `atan2`
/// is in `[−π/2, 0]`, so the angle is at least 3π/2 less a rounding) or `x < 0` with
/// `fl(y/x) > 10⁻⁶` (the true `atan2(y, x)` = −π + atan(y/x) is at least −π + 10⁻⁶·(1 − 10⁻⁶),
/// so the computed angle, `atan2 + 2π`, is above π + 10⁻⁹).
#[derive(Clone, Copy, Debug)]
pub(crate) struct AngleScreen {
    /// tan λ·(1 − 10⁻⁹), or 0 (nothing is below) when λ is not in (0, 1.4).
    tan_below: f64,
}

impl AngleScreen {
    /// The screen of the angle limit λ = `limit` (radians).
    fn new(limit: f64) -> Self {
        let tan_below = if limit > 0.0 && limit < 1.4 {
            limit.tan() * (1.0 - 1e-9)
        } else {
            0.0
        };
        Self { tan_below }
    }

    /// The `(y, x)` of `left_angle(prev, cur, next)` (see the type's documentation).
    fn yx(prev: DVec2, cur: DVec2, next: DVec2) -> (f64, f64) {
        let (u, v) = (next - cur, prev - cur);
        (u.perp_dot(v), u.dot(v))
    }

    /// `true` only if `left_angle(prev, cur, next)` is below the limit.
    pub(crate) fn surely_below(&self, prev: DVec2, cur: DVec2, next: DVec2) -> bool {
        let (y, x) = Self::yx(prev, cur, next);
        if !(y > 0.0 && x > 0.0) {
            return false;
        }
        let r = y / x;
        (1e-200..self.tan_below).contains(&r)
    }

    /// `true` only if `left_angle(prev, cur, next)` is above π + 10⁻⁹.
    fn surely_reflex(prev: DVec2, cur: DVec2, next: DVec2) -> bool {
        let (y, x) = Self::yx(prev, cur, next);
        y < 0.0 && (x >= 0.0 || y / x > 1e-6)
    }
}

/// What trying a candidate cut of the concavity cut found: not admissible or a child too
/// small (`Skipped`), or its score.
enum Trial {
    Skipped,
    Score(f64),
}

/// Pieces at least this long try a few candidate cuts at a time in parallel (shorter ones
/// run in parallel with the other leaves).
const PARALLEL_TRIALS_MIN_LEN: usize = 64;

/// Whether a candidate cut whose cheap terms are `pre` (and every later one: the candidates
/// are sorted by `pre`) cannot beat the best score `best` so far.
///
/// Exact for the two-child score `s = ½·max(B₁, B₂) + ¼·(B₁ + B₂) + pre` (`B` a badness or a
/// corner cost, never negative: the quad fit's corner score F is a sum of squares and ratios
/// of lengths with its fixed non-negative weights, its fallback ½ + a mean of squares,
/// `1 + κ₂ + κ₃` is at least 1 and a grade is 0, 1 or 3): the first two terms add up to some
/// `X ≥ 0` (or
/// NaN), and rounding is monotone, so `s = fl(X + pre) ≥ pre ≥ best` (or NaN): `s < best`,
/// the test for a new best, fails. A later candidate has a `pre` at least as large (in the
/// `total_cmp` order of the sort, only a NaN comes after, whose score is NaN).
pub(crate) fn beyond_best(pre: f64, best: f64) -> bool {
    pre >= best
}

impl<'a> Builder<'a> {
    pub fn new(region: &'a Region, opts: &'a DecomposeOptions) -> Self {
        let outer = Ring {
            pts: region.outer().points().to_vec(),
            tags: vec![Tag::Boundary(0); region.outer().len()],
        };
        let holes = region
            .holes()
            .iter()
            .enumerate()
            .map(|(k, h)| Ring {
                pts: h.points().to_vec(),
                tags: vec![Tag::Boundary(k + 1); h.len()],
            })
            .collect();
        Self {
            region,
            opts,
            cuts: Vec::new(),
            nodes: vec![TreeNode::root()],
            pieces: vec![Some(Piece { outer, holes })],
            protected_cuts: 0,
            min_area: opts.min_area_fraction * region.area(),
            min_triangle: opts.min_triangle_fraction * region.area(),
            auto_repair: true,
            cache: None,
            screens: Self::angle_screens(opts),
        }
    }

    /// The [`AngleScreen`]s of the tiers' angle limits ([`Builder::angle_terms`]).
    fn angle_screens(opts: &DecomposeOptions) -> [AngleScreen; 3] {
        let theta = opts.tolerances.theta_minus;
        [theta, 0.5 * theta, 0.2 * theta].map(AngleScreen::new)
    }

    fn leaves(&self) -> usize {
        self.nodes.iter().filter(|n| n.children.is_empty()).count()
    }

    /// Replaces leaf `node` by two children.
    pub fn branch(
        &mut self,
        node: usize,
        step: Step,
        cuts: Vec<usize>,
        a: Piece,
        b: Piece,
    ) -> [usize; 2] {
        let mut ids = [0; 2];
        for (k, p) in [a, b].into_iter().enumerate() {
            let label = if self.nodes[node].label.is_empty() {
                format!("{}", k + 1)
            } else {
                format!("{}.{}", self.nodes[node].label, k + 1)
            };
            self.nodes.push(TreeNode {
                label,
                parent: Some(node),
                children: Vec::new(),
                step: None,
                cuts: Vec::new(),
                block: None,
            });
            self.pieces.push(Some(p));
            ids[k] = self.nodes.len() - 1;
        }
        self.nodes[node].children = ids.to_vec();
        self.nodes[node].step = Some(step);
        self.nodes[node].cuts = cuts;
        self.pieces[node] = None;
        ids
    }

    /// Applies the straight cut `a`–`b` to the first leaf piece that has both points on its
    /// boundary (within `tol`) and admits the cut: a split when both ends are on the piece's
    /// outer ring, a bridge when one end is on a hole. Used by the decomposition file (user
    /// cuts) and by the chord layout.
    pub fn apply_cut(&mut self, a: DVec2, b: DVec2, tol: f64, step: Step) -> Applied {
        let mut joins_holes = false;
        for node in 0..self.nodes.len() {
            let Some(piece) = self.pieces[node].as_ref() else {
                continue;
            };
            let locate = |p: DVec2| -> Option<End> {
                for (r, ring) in piece.rings().enumerate() {
                    if let Some(i) = ring.pts.iter().position(|&x| x == p) {
                        return Some(End {
                            ring: r,
                            pos: Pos::Vertex(i),
                        });
                    }
                }
                for (r, ring) in piece.rings().enumerate() {
                    if let Some(i) = ring.pts.iter().position(|&x| x.distance(p) <= tol) {
                        return Some(End {
                            ring: r,
                            pos: Pos::Vertex(i),
                        });
                    }
                    for i in 0..ring.len() {
                        if matches!(ring.tags[i], Tag::Boundary(_))
                            && unamalla_mesh::geometry::point_segment_distance(
                                p,
                                ring.p(i),
                                ring.next(i),
                            ) <= tol
                        {
                            return Some(End {
                                ring: r,
                                pos: Pos::OnEdge(i, p),
                            });
                        }
                    }
                }
                None
            };
            let (Some(e1), Some(e2)) = (locate(a), locate(b)) else {
                continue;
            };
            // one test on this piece: a scan of its edges (`admissible_scan`)
            if !piece.admissible_scan(e1, e2) {
                continue;
            }
            if e1.ring != 0 && e2.ring != 0 {
                joins_holes = true;
                continue;
            }
            let mut m = piece.clone();
            let (x, y) = m.insert_ends(e1, e2);
            let id = self.new_cut(m.ring(e1.ring).p(x), m.ring(e2.ring).p(y));
            if e1.ring == 0 && e2.ring == 0 {
                let (pa, pb) = m.split(x, y, id);
                self.branch(node, step, vec![id], pa, pb);
                return Applied::Split;
            }
            let (o, h, k) = if e1.ring == 0 {
                (x, e2.ring, y)
            } else {
                (y, e1.ring, x)
            };
            m.merge(o, h, k, id);
            self.pieces[node] = Some(m);
            self.nodes[node].cuts.push(id);
            return Applied::Bridged;
        }
        if joins_holes {
            Applied::JoinsTwoHoles
        } else {
            Applied::NoPiece
        }
    }

    pub fn new_cut(&mut self, a: DVec2, b: DVec2) -> usize {
        self.cuts.push((a, b));
        self.cuts.len() - 1
    }

    /// Runs Algorithm 1 ([`Builder::run_auto`]) on every current leaf piece.
    ///
    /// The leaves are run in parallel, each in a builder of its own ([`LeafRun`]), and the
    /// runs are appended in leaf order, which is exactly the sequential result: Algorithm 1
    /// on a leaf reads only its piece, the options and the minimum areas (never another
    /// leaf, nor the value of a cut id — only whether an edge is a cut), and it appends its
    /// nodes and cuts in the same order; new cut ids are renumbered from the cut count at
    /// the leaf's turn and node labels prefixed with the leaf's label. The one global read,
    /// the block budget (`leaves() >= max_blocks`), is met by a fallback: when the runs would
    /// reach it, everything is run sequentially instead. A run is cached by its piece
    /// ([`LayoutCache`]); a failing run also falls back (the sequential error is the first
    /// leaf's error).
    pub fn run_auto_on_leaves(&mut self) -> Result<(), DecomposeError> {
        let leaves: Vec<usize> = (0..self.nodes.len())
            .filter(|&n| self.pieces[n].is_some())
            .collect();
        let runs: Vec<Option<Arc<LeafRun>>> =
            leaves.par_iter().map(|&n| self.leaf_run(n)).collect();
        // every branch turns one leaf into two
        let added: usize = runs
            .iter()
            .map(|r| r.as_ref().map_or(0, |r| (r.nodes.len() - 1) / 2))
            .sum();
        if runs.iter().any(Option::is_none) || self.leaves() + added >= self.opts.max_blocks {
            for n in leaves {
                self.run_auto(n)?;
            }
            return Ok(());
        }
        for (n, run) in leaves.into_iter().zip(runs) {
            if let Some(run) = run {
                self.append_leaf_run(n, &run);
            }
        }
        Ok(())
    }

    /// Algorithm 1 on leaf `n` in a builder of its own (or from the cache); `None` if it
    /// fails.
    fn leaf_run(&self, n: usize) -> Option<Arc<LeafRun>> {
        let piece = self.pieces[n].as_ref()?;
        let key = self.cache.as_ref().map(|_| piece_key(piece));
        if let (Some(cache), Some(key)) = (self.cache.as_ref(), key.as_ref()) {
            if let Some(run) = cache.leaf_runs.lock().ok()?.get(key) {
                return Some(run.clone());
            }
        }
        let base = self.cuts.len();
        let mut b = Builder {
            region: self.region,
            opts: self.opts,
            cuts: self.cuts.clone(),
            nodes: vec![TreeNode::root()],
            pieces: vec![Some(piece.clone())],
            protected_cuts: self.protected_cuts,
            min_area: self.min_area,
            min_triangle: self.min_triangle,
            auto_repair: self.auto_repair,
            // for the runs of the pieces met inside (`run_node`)
            cache: self.cache.clone(),
            screens: self.screens,
        };
        b.run_auto(0).ok()?;
        let run = Arc::new(LeafRun {
            base,
            cuts: b.cuts.split_off(base),
            nodes: b.nodes,
            pieces: b.pieces,
        });
        if let (Some(cache), Some(key)) = (self.cache.as_ref(), key) {
            cache.leaf_runs.lock().ok()?.insert(key, run.clone());
        }
        Some(run)
    }

    /// Appends a [`LeafRun`] of leaf `n`: its new cuts get the next ids, its nodes the next
    /// node ids and the leaf's label as prefix.
    fn append_leaf_run(&mut self, n: usize, run: &LeafRun) {
        let cut_base = self.cuts.len();
        let cut = |c: usize| {
            if c >= run.base {
                c - run.base + cut_base
            } else {
                c
            }
        };
        let node_base = self.nodes.len() - 1;
        let node = |i: usize| if i == 0 { n } else { i + node_base };
        let prefix = self.nodes[n].label.clone();
        self.cuts.extend_from_slice(&run.cuts);
        let retag = |p: &Piece| {
            let mut p = p.clone();
            for r in std::iter::once(&mut p.outer).chain(p.holes.iter_mut()) {
                for t in &mut r.tags {
                    if let Tag::Cut(c) = t {
                        *c = cut(*c);
                    }
                }
            }
            p
        };
        for (i, (t, p)) in run.nodes.iter().zip(&run.pieces).enumerate() {
            let children = t.children.iter().map(|&c| node(c)).collect();
            let cuts = t.cuts.iter().map(|&c| cut(c)).collect();
            let piece = p.as_ref().map(retag);
            if i == 0 {
                // a leaf that Algorithm 1 left whole is untouched (it may carry the cut of a
                // hole bridge); a split one is overwritten as `branch` does
                if !t.children.is_empty() {
                    let root = &mut self.nodes[n];
                    root.children = children;
                    root.step = t.step;
                    root.cuts = cuts;
                    self.pieces[n] = piece;
                }
            } else {
                self.nodes.push(TreeNode {
                    label: if prefix.is_empty() {
                        t.label.clone()
                    } else {
                        format!("{prefix}.{}", t.label)
                    },
                    parent: t.parent.map(node),
                    children,
                    step: t.step,
                    cuts,
                    block: t.block,
                });
                self.pieces.push(piece);
            }
        }
    }

    /// Algorithm 1 on the subtree rooted at `root` (a leaf).
    ///
    /// Depth first, child 1 of a split before child 2 (the order of the tree's nodes and of
    /// the cuts). With a [`LayoutCache`], what it did on a piece is kept ([`NodeRun`]) and
    /// replayed on a piece with the same content up to its cut ids (exact, see
    /// [`Builder::run_node`]).
    pub fn run_auto(&mut self, root: usize) -> Result<(), DecomposeError> {
        self.run_node(root).map(|_| ())
    }

    /// Algorithm 1 on leaf `n` and the leaves its splits make, depth first; the [`NodeRun`]
    /// of `n`, or `None` where the block budget stopped a split in the subtree (or may have).
    ///
    /// A cached run is replayed instead when the piece has the same [`node_key`]: Algorithm 1
    /// reads the piece's points, the kinds and region rings of its edges and whether an edge
    /// is a cut, never a cut's id (only to copy it to the children), and the options and
    /// minimum areas (the same for every builder sharing the cache); the one other thing it
    /// reads, the leaf count against the block budget, is left out by storing and replaying
    /// a run only when the budget cannot be reached in it (the leaf count only grows, by the
    /// run's leaves less one). Replaying makes the same calls in the same order (new cuts,
    /// then the split), so the nodes, labels and cut ids come out as computing would.
    fn run_node(&mut self, n: usize) -> Result<Option<Arc<NodeRun>>, DecomposeError> {
        let Some(piece) = self.pieces[n].clone() else {
            return Ok(None);
        };
        let leaves_before = self.leaves();
        if leaves_before >= self.opts.max_blocks && piece.holes.is_empty() {
            return Ok(None);
        }
        let within_budget = |run: &NodeRun| leaves_before - 1 + run.leaves < self.opts.max_blocks;
        let (key, ids) = node_key(&piece);
        if let Some(memo) = self.cache.as_ref().map(|c| &c.node_runs) {
            let hit = memo.lock().ok().and_then(|m| m.get(&key).cloned());
            if let Some(run) = hit.filter(|r| within_budget(r)) {
                self.replay(n, &run, &ids);
                return Ok(Some(run));
            }
        }
        let tol = &self.opts.tolerances;
        let out = if !piece.holes.is_empty() {
            let (a, b, c1, c2) = self.remove_hole(&piece)?;
            Some((Step::HoleRemoval, vec![c1, c2], a, b, true))
        } else {
            let shape = Shape::of(&piece.outer.pts);
            let mut r = None;
            if !shape.conc.approximately_convex(tol) {
                r = self
                    .concavity_cut(&piece, &shape)
                    .map(|(a, b, c)| (Step::Concavity, vec![c], a, b, true));
            }
            if r.is_none() && self.opts.critical_triangles && piece.outer.len() > 3 {
                r = self
                    .critical_cut(&piece)
                    .map(|(a, b, c)| (Step::CriticalAngle, vec![c], a, b, false));
            }
            r
        };
        let run = match out {
            None => NodeRun {
                leaves: 1,
                split: None,
            },
            Some((step, cuts, a, b, both)) => {
                // this node's numbering of cuts: the piece's, then the new ones
                let mut numbered = ids.clone();
                numbered.extend(&cuts);
                let number = |c: usize| numbered.iter().position(|&x| x == c);
                let segments = cuts.iter().map(|&c| self.cuts[c]).collect();
                let child_ids = [&a, &b].map(|p| node_key(p).1);
                let ids_of = self.branch(n, step, cuts, a, b);
                // child 1, then child 2 (the triangle of Algorithm 4 is left whole)
                let first = if both {
                    self.run_node(ids_of[0])?
                } else {
                    Some(Arc::new(NodeRun {
                        leaves: 1,
                        split: None,
                    }))
                };
                let second = self.run_node(ids_of[1])?;
                let (Some(first), Some(second)) = (first, second) else {
                    return Ok(None);
                };
                let mut children = Vec::with_capacity(2);
                for ((run, id), cids) in [first, second].into_iter().zip(ids_of).zip(child_ids) {
                    // a child left whole keeps its piece (numbered as this node)
                    let piece = match (&run.split, &self.pieces[id]) {
                        (None, Some(p)) => match renumber_piece(p, &|c| number(c)) {
                            Ok(p) => Some(p),
                            Err(()) => return Ok(None),
                        },
                        _ => None,
                    };
                    let Some(ids) = cids.iter().map(|&c| number(c)).collect() else {
                        return Ok(None);
                    };
                    children.push(ChildRun { piece, ids, run });
                }
                let children: [ChildRun; 2] = match children.try_into() {
                    Ok(c) => c,
                    Err(_) => return Ok(None),
                };
                NodeRun {
                    leaves: children[0].run.leaves + children[1].run.leaves,
                    split: Some(NodeSplit {
                        step,
                        cuts: segments,
                        children,
                    }),
                }
            }
        };
        if !within_budget(&run) {
            return Ok(None);
        }
        let run = Arc::new(run);
        if let Some(memo) = self.cache.as_ref().map(|c| &c.node_runs) {
            if piece.outer.len() >= NODE_RUN_MIN_LEN {
                if let Ok(mut m) = memo.lock() {
                    m.insert(key, run.clone());
                }
            }
        }
        Ok(Some(run))
    }

    /// Replays `run` on leaf `n`, whose piece's cuts in [`node_key`] order are `ids` (the
    /// run's numbering): the same new cuts, split and runs of the children, in the same order
    /// as [`Builder::run_node`] made them.
    fn replay(&mut self, n: usize, run: &NodeRun, ids: &[usize]) {
        let Some(split) = &run.split else {
            return;
        };
        let mut actual = ids.to_vec();
        let first_new = actual.len();
        for &(a, b) in &split.cuts {
            let c = self.new_cut(a, b);
            actual.push(c);
        }
        let cuts = actual[first_new..].to_vec();
        let piece = |c: &ChildRun| {
            c.piece
                .as_ref()
                .map(|p| renumber_piece(p, &|k| actual.get(k).copied()))
                .and_then(Result::ok)
                .unwrap_or_else(Piece::empty)
        };
        let (a, b) = (piece(&split.children[0]), piece(&split.children[1]));
        let ids_of = self.branch(n, split.step, cuts, a, b);
        for (c, id) in split.children.iter().zip(ids_of) {
            if c.run.split.is_some() {
                let child: Vec<usize> = c.ids.iter().map(|&k| actual[k]).collect();
                self.replay(id, &c.run, &child);
            }
        }
    }

    /// The two new angles at a cut end going towards `target`: (angle on the side of the
    /// outgoing edge, angle on the side of the incoming edge).
    pub(crate) fn end_angles(piece: &Piece, e: End, target: DVec2) -> (f64, f64) {
        let (prev, cur, next) = piece.chain(e);
        (left_angle(target, cur, next), left_angle(prev, cur, target))
    }

    /// Angle penalty ḡ of a candidate cut and its smallest new angle, or `None` if a new angle
    /// is below the tier's limit: tiers 0 and 1 use θ₋ (tier 0 also requires that a reflex start
    /// vertex is resolved: both new angles at `e1` at most 180°), tier 2 uses ½θ₋, tier 3 uses
    /// ⅕θ₋ (relaxed passes, only tried when the stricter ones find nothing).
    pub(crate) fn angle_terms(
        &self,
        piece: &Piece,
        e1: End,
        e2: End,
        tier: usize,
    ) -> Option<(f64, f64)> {
        if self.screened_out(piece, e1, e2, tier) {
            return None;
        }
        let (p, q) = (piece.point(e1), piece.point(e2));
        let (a, b) = Self::end_angles(piece, e1, q);
        let (c, d) = Self::end_angles(piece, e2, p);
        self.angle_terms_of([a, b, c, d], tier)
    }

    /// The [`AngleScreen`] of the angle limit of tier 1 (θ₋), the tier of the repair's
    /// searches.
    pub(crate) fn tier1_screen(&self) -> &AngleScreen {
        &self.screens[0]
    }

    /// Whether [`AngleScreen`] rejects the candidate cut from `e1` to `e2` in `tier`: a new
    /// angle surely below the tier's limit, or in tier 0 a reflex angle at `e1` — decisions
    /// that [`Builder::angle_terms_of`] would reach from the `atan2` angles (exact, see the
    /// screen), so [`Builder::angle_terms`] returns `None` without computing them.
    pub(crate) fn screened_out(&self, piece: &Piece, e1: End, e2: End, tier: usize) -> bool {
        let p = piece.point(e1);
        let q = piece.point(e2);
        let screen = &self.screens[tier.saturating_sub(1).min(2)];
        let (prev1, _, next1) = piece.chain(e1);
        let (prev2, _, next2) = piece.chain(e2);
        screen.surely_below(q, p, next1)
            || screen.surely_below(prev1, p, q)
            || screen.surely_below(p, q, next2)
            || screen.surely_below(prev2, q, p)
            || (tier == 0
                && (AngleScreen::surely_reflex(q, p, next1)
                    || AngleScreen::surely_reflex(prev1, p, q)))
    }

    /// [`Builder::angle_terms`] from the four new angles: `a`, `b` at the first end (as
    /// [`Builder::end_angles`] gives them towards the second end), `c`, `d` at the second.
    pub(crate) fn angle_terms_of(&self, [a, b, c, d]: [f64; 4], tier: usize) -> Option<(f64, f64)> {
        let min = a.min(b).min(c).min(d);
        let theta = self.opts.tolerances.theta_minus;
        let limit = match tier {
            0 | 1 => theta,
            2 => 0.5 * theta,
            _ => 0.2 * theta,
        };
        if min < limit {
            return None;
        }
        if tier == 0 && a.max(b) > PI + 1e-9 {
            return None;
        }
        let pen = angle_penalty(a) + angle_penalty(b) + angle_penalty(c) + angle_penalty(d);
        Some((pen / 4.0, min))
    }

    /// Feet of the perpendicular from `p` on the boundary-tagged edges of ring `r` of the piece
    /// (strictly inside the edge, away from its ends), plus the ring's vertices.
    pub(crate) fn targets_on_ring(
        piece: &Piece,
        r: usize,
        p: DVec2,
        skip: &dyn Fn(usize) -> bool,
        out: &mut Vec<End>,
    ) {
        let ring = piece.ring(r);
        let n = ring.len();
        for i in 0..n {
            if !skip(i) {
                out.push(End {
                    ring: r,
                    pos: Pos::Vertex(i),
                });
            }
            if skip(i) || skip((i + 1) % n) {
                continue;
            }
            if let Tag::Boundary(_) = ring.tags[i] {
                let a = ring.p(i);
                let b = ring.next(i);
                let t = project_t(p, a, b);
                if t > 0.03 && t < 0.97 {
                    out.push(End {
                        ring: r,
                        pos: Pos::OnEdge(i, a + t * (b - a)),
                    });
                }
            }
        }
    }

    /// Algorithm 2: removes the hole nearest to the outer ring with two cuts.
    fn remove_hole(
        &mut self,
        piece: &Piece,
    ) -> Result<(Piece, Piece, usize, usize), DecomposeError> {
        let region_hole = |piece: &Piece, k: usize| match piece.holes[k - 1].tags[0] {
            Tag::Boundary(r) => r.saturating_sub(1),
            Tag::Cut(_) => 0,
        };
        let area_scale = piece.area().abs().sqrt();
        for tier in [1, 2, 3] {
            // --- first cut: shortest admissible bridges between a hole and the outer ring
            let idx = piece.index();
            let mut cands: Vec<Cand> = Vec::new();
            for k in 1..=piece.holes.len() {
                let h = piece.ring(k);
                for j in 0..h.len() {
                    let q = h.p(j);
                    let mut t = Vec::new();
                    Self::targets_on_ring(piece, 0, q, &|_| false, &mut t);
                    for e in t {
                        cands.push(Cand {
                            e1: e,
                            e2: End {
                                ring: k,
                                pos: Pos::Vertex(j),
                            },
                            pre: piece.point(e).distance(q),
                        });
                    }
                }
                for i in 0..piece.outer.len() {
                    let p = piece.outer.p(i);
                    let mut t = Vec::new();
                    Self::targets_on_ring(piece, k, p, &|_| true, &mut t);
                    // only the feet (vertices were covered above)
                    for j in 0..h.len() {
                        let a = h.p(j);
                        let b = h.next(j);
                        let tt = project_t(p, a, b);
                        if tt > 0.03 && tt < 0.97 {
                            t.push(End {
                                ring: k,
                                pos: Pos::OnEdge(j, a + tt * (b - a)),
                            });
                        }
                    }
                    for e in t {
                        cands.push(Cand {
                            e1: End {
                                ring: 0,
                                pos: Pos::Vertex(i),
                            },
                            e2: e,
                            pre: p.distance(piece.point(e)),
                        });
                    }
                }
            }
            cands.sort_by(|a, b| a.pre.total_cmp(&b.pre));
            let mut found: Vec<(f64, Cand)> = Vec::new();
            let mut lmin = None;
            for c in &cands {
                if found.len() >= 60 {
                    break;
                }
                if !piece.admissible(&idx, c.e1, c.e2) {
                    continue;
                }
                let Some((pen, _)) = self.angle_terms(piece, c.e1, c.e2, tier) else {
                    continue;
                };
                let l = *lmin.get_or_insert(c.pre.max(1e-300));
                let s = c.pre / l + self.opts.cut_weights.angle * pen;
                found.push((s, *c));
            }
            found.sort_by(|a, b| a.0.total_cmp(&b.0));
            for (_, c1) in found {
                if let Some(r) = self.second_hole_cut(piece, c1, tier, area_scale) {
                    return Ok(r);
                }
            }
        }
        Err(DecomposeError::HoleNotRemoved {
            hole: region_hole(piece, 1),
        })
    }

    fn second_hole_cut(
        &mut self,
        piece: &Piece,
        c1: Cand,
        tier: usize,
        _area_scale: f64,
    ) -> Option<(Piece, Piece, usize, usize)> {
        let k = c1.e2.ring;
        let hole_per = perimeter(&piece.ring(k).pts);
        let len1 = c1.pre;
        let mut m = piece.clone();
        let (i, j) = m.insert_ends(c1.e1, c1.e2);
        let cut1_pts = (m.outer.p(i), m.ring(k).p(j));
        let (qa, qb, pb) = m.merge(i, k, j, usize::MAX);
        let n = m.outer.len();
        // arc length along the hole part from qa
        let mut arc = vec![0.0; n + 1];
        for s in qa..qb {
            arc[s + 1] = arc[s] + m.outer.p(s).distance(m.outer.next(s));
        }
        let in_outer = |s: usize| s < i || s > pb;
        let reference = len1 + hole_per / PI;
        let idx = m.index();
        let mut cands: Vec<(Cand, f64)> = Vec::new();
        for (s, &arc_s) in arc.iter().enumerate().take(qb).skip(qa + 1) {
            let q = m.outer.p(s);
            let f = arc_s / hole_per;
            let bal = 4.0 * (f - 0.5) * (f - 0.5);
            for t in 0..n {
                if !in_outer(t) {
                    continue;
                }
                let mut ends = vec![End {
                    ring: 0,
                    pos: Pos::Vertex(t),
                }];
                if in_outer((t + 1) % n) && matches!(m.outer.tags[t], Tag::Boundary(_)) {
                    let a = m.outer.p(t);
                    let b = m.outer.next(t);
                    let tt = project_t(q, a, b);
                    if tt > 0.03 && tt < 0.97 {
                        ends.push(End {
                            ring: 0,
                            pos: Pos::OnEdge(t, a + tt * (b - a)),
                        });
                    }
                }
                for e in ends {
                    let l = m.point(e).distance(q);
                    cands.push((
                        Cand {
                            e1: End {
                                ring: 0,
                                pos: Pos::Vertex(s),
                            },
                            e2: e,
                            pre: self.opts.cut_weights.hole_balance * bal + l / reference,
                        },
                        l,
                    ));
                }
            }
        }
        cands.sort_by(|a, b| a.0.pre.total_cmp(&b.0.pre));
        let mut best: Option<(f64, Piece, Piece, DVec2, DVec2)> = None;
        let mut tested = 0;
        for (c, _) in &cands {
            if tested >= 40 {
                break;
            }
            if !m.admissible(&idx, c.e1, c.e2) {
                continue;
            }
            let Some((pen, _)) = self.angle_terms(&m, c.e1, c.e2, tier) else {
                continue;
            };
            let mut m2 = m.clone();
            let (x, y) = m2.insert_ends(c.e1, c.e2);
            let (a, b) = m2.split(x, y, usize::MAX - 1);
            if a.area() < self.min_area || b.area() < self.min_area {
                continue;
            }
            tested += 1;
            let s = c.pre + self.opts.cut_weights.angle * pen;
            if best.as_ref().is_none_or(|b| s < b.0) {
                best = Some((s, a, b, m2.outer.p(x), m2.outer.p(y)));
            }
        }
        let (_, a, b, xa, xb) = best?;
        // commit: real cut ids
        let id1 = self.new_cut(cut1_pts.0, cut1_pts.1);
        let id2 = self.new_cut(xa, xb);
        let fix = |mut p: Piece| {
            for r in std::iter::once(&mut p.outer).chain(p.holes.iter_mut()) {
                for t in &mut r.tags {
                    if *t == Tag::Cut(usize::MAX) {
                        *t = Tag::Cut(id1);
                    } else if *t == Tag::Cut(usize::MAX - 1) {
                        *t = Tag::Cut(id2);
                    }
                }
            }
            p
        };
        Some((fix(a), fix(b), id1, id2))
    }

    /// Badness B(P) of a hole-free piece: its corner score F* if it is approximately convex
    /// (it will be a block), else 1 + κ₂ + κ₃ (it will be cut again).
    /// The ring's vertex angles (`angles[i]` = `ring_angle(ring, i)`) and convex hull (as
    /// [`concavity_with_hull`] takes it) are given, for the concavity measures and the corner
    /// score.
    fn badness_with_hull(&self, ring: &[DVec2], angles: &[f64], hull: Vec<usize>) -> f64 {
        let c = measures_with_hull(ring, angles, hull);
        if c.approximately_convex(&self.opts.tolerances) {
            quad_fit_with_angles(ring, angles)
        } else {
            1.0 + c.kappa2 + c.kappa3
        }
    }

    /// Algorithm 3: one concavity cut from a deep reflex vertex p to the best q.
    /// `shape` is the [`Shape`] of the piece's outer ring.
    fn concavity_cut(&mut self, piece: &Piece, shape: &Shape) -> Option<(Piece, Piece, usize)> {
        let ring = &piece.outer;
        let n = ring.len();
        let Shape {
            angle,
            hull_keys,
            hull,
            distinct,
            conc,
        } = shape;
        let (hull_keys, hull, distinct) = (hull_keys.as_slice(), hull.as_slice(), *distinct);
        let area = piece.area();
        let sq = area.sqrt();
        let mut starts: Vec<usize> = (0..n)
            .filter(|&i| angle[i] > PI && conc.point_kappa3[i] > 0.0)
            .collect();
        starts.sort_by(|&a, &b| {
            conc.point_kappa3[b]
                .total_cmp(&conc.point_kappa3[a])
                .then(ring.p(a).x.total_cmp(&ring.p(b).x))
                .then(ring.p(a).y.total_cmp(&ring.p(b).y))
        });
        starts.truncate(self.opts.concave_starts);
        // spike tips (angle above θ₊) start first whatever their depth: a needle barely
        // changes κ₃, but it is the reason the piece is not approximately convex
        let theta_plus = self.opts.tolerances.theta_plus;
        let mut spikes: Vec<usize> = (0..n).filter(|&i| angle[i] > theta_plus).collect();
        spikes.sort_by(|&a, &b| {
            angle[b]
                .total_cmp(&angle[a])
                .then(ring.p(a).x.total_cmp(&ring.p(b).x))
                .then(ring.p(a).y.total_cmp(&ring.p(b).y))
        });
        starts.retain(|i| !spikes.contains(i));
        spikes.extend(starts);
        let starts = spikes;
        let idx = piece.index();
        let w = self.opts.cut_weights;
        for tier in 0..4 {
            let mut cands: Vec<Cand> = Vec::new();
            for &i in &starts {
                let p = ring.p(i);
                let e1 = End {
                    ring: 0,
                    pos: Pos::Vertex(i),
                };
                let mut t = Vec::new();
                let near = |j: usize| j == i || j == (i + 1) % n || j == (i + n - 1) % n;
                Self::targets_on_ring(piece, 0, p, &near, &mut t);
                // rays: extensions of both incident edges and the bisector
                let din = (p - ring.prev(i)).normalize_or_zero();
                let dout = (p - ring.next(i)).normalize_or_zero();
                let bis = (din + dout).normalize_or_zero();
                for d in [din, dout, bis] {
                    if d == DVec2::ZERO {
                        continue;
                    }
                    if let Some(e) = Self::ray_hit(ring, i, p, d) {
                        t.push(e);
                    }
                }
                for e2 in t {
                    let q = piece.point(e2);
                    let Some((pen, _)) = self.angle_terms(piece, e1, e2, tier) else {
                        continue;
                    };
                    cands.push(Cand {
                        e1,
                        e2,
                        pre: w.angle * pen + w.length * p.distance(q) / sq,
                    });
                }
            }
            // the candidates in the order of (pre, coordinates of the second end, position):
            // the sequence a stable sort by pre and coordinates gives, sorted only as far as
            // the search goes (`visit_sorted`)
            // (pre by its `total_cmp` key)
            let mut order: Vec<(u64, usize)> = (0..cands.len())
                .map(|k| (total_key(cands[k].pre), k))
                .collect();
            let cmp = |&(sa, ka): &(u64, usize), &(sb, kb): &(u64, usize)| {
                sa.cmp(&sb)
                    .then_with(|| {
                        let (a, b) = (&cands[ka], &cands[kb]);
                        let (pa, pb) = (piece.point(a.e2), piece.point(b.e2));
                        pa.x.total_cmp(&pb.x).then(pa.y.total_cmp(&pb.y))
                    })
                    .then(ka.cmp(&kb))
            };
            // the trial of a candidate (pure: admissible, both children large enough, their
            // score); for a large piece a few are tried at a time in parallel and their trials
            // taken in order as the sequential loop would (one tried beyond where it stops
            // is work lost, not a different result)
            let this = &*self;
            let trial = |c: &Cand| -> Trial {
                if !piece.admissible(&idx, c.e1, c.e2) {
                    return Trial::Skipped;
                }
                let (a, b, _) = piece.split_between(c.e1, c.e2, usize::MAX);
                let (aa, ab) = (a.area(), b.area());
                // the last tier also accepts pieces down to a tenth of the negligible area
                let min_area = if tier == 3 {
                    0.1 * this.min_area
                } else {
                    this.min_area
                };
                if aa < min_area || ab < min_area {
                    return Trial::Skipped;
                }
                // the children's vertex angles from the piece's where a vertex keeps its
                // neighbours (exact, `ring_angles_matched`): `a` starts at the cut's first end
                // (vertex `i` of the piece), `b` at its second end (a vertex, or a point inside
                // an edge followed by the edge's end)
                let start_b = match c.e2.pos {
                    Pos::Vertex(j) => j,
                    Pos::OnEdge(e, _) => e + 1,
                };
                let start_a = match c.e1.pos {
                    Pos::Vertex(i) => i,
                    Pos::OnEdge(e, _) => e + 1,
                };
                // and their convex hulls from the piece's: from the piece's hull vertices
                // the child keeps and its points beyond them (`child_hull`), else from the
                // piece's sorted points for a large child (`child_hull_order`; both exact,
                // for pairwise different points)
                let badness = |child: &[DVec2], start: usize| {
                    let map = match_vertices(child, &ring.pts, start);
                    let angles = ring_angles_matched(child, &ring.pts, angle, &map);
                    let large = 8 * child.len() >= n;
                    let hull = distinct
                        .then(|| child_hull(&ring.pts, hull, child, &map))
                        .flatten()
                        .or_else(|| {
                            let keys = (distinct && large)
                                .then(|| child_hull_order(hull_keys, n, child, &map))
                                .flatten()?;
                            Some(hull_from_order(child, &keys).0)
                        })
                        .unwrap_or_else(|| convex_hull(child));
                    this.badness_with_hull(child, &angles, hull)
                };
                let ba = badness(&a.outer.pts, start_a);
                let bb = badness(&b.outer.pts, start_b);
                Trial::Score(0.5 * ba.max(bb) + 0.25 * (ba + bb) + c.pre)
            };
            let chunk = if n >= PARALLEL_TRIALS_MIN_LEN {
                rayon::current_num_threads().max(1)
            } else {
                1
            };
            let mut best: Option<(f64, Cand)> = None;
            let mut evaluated = 0;
            // takes the trials of `ks` in order; `false` where the sequential loop stops
            let mut take = |ks: &[usize]| -> bool {
                let trials: Vec<Trial> = if ks.len() > 1 {
                    ks.par_iter().map(|&k| trial(&cands[k])).collect()
                } else {
                    ks.iter().map(|&k| trial(&cands[k])).collect()
                };
                for (&k, t) in ks.iter().zip(trials) {
                    let c = &cands[k];
                    if evaluated >= 60 {
                        return false;
                    }
                    // no later candidate can win (exact, see `beyond_best`)
                    if best.is_some_and(|(s, _)| beyond_best(c.pre, s)) {
                        return false;
                    }
                    let Trial::Score(s) = t else {
                        continue;
                    };
                    evaluated += 1;
                    if best.as_ref().is_none_or(|b| s < b.0) {
                        best = Some((s, *c));
                    }
                }
                true
            };
            let mut pending: Vec<usize> = Vec::with_capacity(chunk);
            let mut going = true;
            visit_sorted(&mut order, cmp, |&(_, k)| {
                pending.push(k);
                if pending.len() < chunk {
                    return true;
                }
                going = take(&pending);
                pending.clear();
                going
            });
            if going && !pending.is_empty() {
                take(&pending);
            }
            if let Some((_, c)) = best {
                let mut m = piece.clone();
                let (x, y) = m.insert_ends(c.e1, c.e2);
                let id = self.new_cut(m.outer.p(x), m.outer.p(y));
                let (a, b) = m.split(x, y, id);
                return Some((a, b, id));
            }
        }
        None
    }

    /// First boundary point hit by the ray from vertex `i` in direction `d`.
    fn ray_hit(ring: &Ring, i: usize, p: DVec2, d: DVec2) -> Option<End> {
        let n = ring.len();
        let mut best: Option<(f64, usize, f64)> = None;
        for e in 0..n {
            if e == i || (e + 1) % n == i {
                continue;
            }
            if let Some((s, t)) = ray_segment(p, d, ring.p(e), ring.next(e)) {
                if best.is_none_or(|b| s < b.0) {
                    best = Some((s, e, t));
                }
            }
        }
        let (_, e, t) = best?;
        if t > 0.03 && t < 0.97 && matches!(ring.tags[e], Tag::Boundary(_)) {
            Some(End {
                ring: 0,
                pos: Pos::OnEdge(e, p + d * ray_segment(p, d, ring.p(e), ring.next(e))?.0),
            })
        } else {
            let v = if t < 0.5 { e } else { (e + 1) % n };
            (v != i).then_some(End {
                ring: 0,
                pos: Pos::Vertex(v),
            })
        }
    }

    /// Algorithm 4: cut a triangle around the sharpest critical angle.
    fn critical_cut(&mut self, piece: &Piece) -> Option<(Piece, Piece, usize)> {
        let ring = &piece.outer;
        let n = ring.len();
        let theta = self.opts.tolerances.theta_minus;
        let mut acute: Vec<(f64, usize)> = (0..n)
            .map(|i| (ring_angle(&ring.pts, i), i))
            .filter(|x| x.0 < theta)
            .collect();
        acute.sort_by(|a, b| a.0.total_cmp(&b.0));
        let idx = piece.index();
        for (_, v) in acute {
            let ep = (v + n - 1) % n;
            if !matches!(ring.tags[ep], Tag::Boundary(_))
                || !matches!(ring.tags[v], Tag::Boundary(_))
            {
                continue;
            }
            let pv = ring.p(v);
            let prev = ring.prev(v);
            let next = ring.next(v);
            let mut d = 0.5 * pv.distance(prev).min(pv.distance(next));
            for _ in 0..4 {
                let p = pv + (prev - pv).normalize() * d;
                let q = pv + (next - pv).normalize() * d;
                let e1 = End {
                    ring: 0,
                    pos: Pos::OnEdge(ep, p),
                };
                let e2 = End {
                    ring: 0,
                    pos: Pos::OnEdge(v, q),
                };
                let tri_area = 0.5 * (pv - p).perp_dot(q - p).abs();
                if tri_area < self.min_triangle {
                    break;
                }
                if piece.admissible(&idx, e1, e2) {
                    let mut m = piece.clone();
                    let (x, y) = m.insert_ends(e1, e2);
                    let id = self.new_cut(m.outer.p(x), m.outer.p(y));
                    let (a, b) = m.split(x, y, id);
                    return Some((a, b, id));
                }
                d *= 0.5;
            }
        }
        None
    }

    /// Inserts `p` on edge `e` of block ring `bid`; if that edge is a cut, the point is also
    /// inserted in the neighbour's ring and the cut is split in two (the second half gets a new
    /// cut id, recorded in the tree node of the original cut).
    fn insert_on_edge(&mut self, rings: &mut [Ring], bid: usize, e: usize, p: DVec2) {
        let tag = rings[bid].tags[e];
        match tag {
            Tag::Boundary(_) => {
                rings[bid].pts.insert(e + 1, p);
                rings[bid].tags.insert(e + 1, tag);
            }
            Tag::Cut(c) => {
                let u = rings[bid].p(e);
                let new_id = self.cuts.len();
                let (a, b) = self.cuts[c];
                // cut c keeps the half at its endpoint a
                let (half_u, half_v) = if a == u { (c, new_id) } else { (new_id, c) };
                self.cuts[c] = (a, p);
                self.cuts.push((p, b));
                if let Some(node) = self.nodes.iter_mut().find(|n| n.cuts.contains(&c)) {
                    node.cuts.push(new_id);
                }
                rings[bid].pts.insert(e + 1, p);
                rings[bid].tags[e] = Tag::Cut(half_u);
                rings[bid].tags.insert(e + 1, Tag::Cut(half_v));
                // the neighbour: the other ring with an edge tagged c
                for (k, r) in rings.iter_mut().enumerate() {
                    if k == bid {
                        continue;
                    }
                    if let Some(f) = r.tags.iter().position(|t| *t == Tag::Cut(c)) {
                        // its edge runs v → u
                        r.pts.insert(f + 1, p);
                        r.tags[f] = Tag::Cut(half_v);
                        r.tags.insert(f + 1, Tag::Cut(half_u));
                        break;
                    }
                }
            }
        }
    }

    /// The cleanup pass: removes every cut whose two blocks form a better block together.
    /// Two blocks sharing exactly one cut (and no other point) are merged when the union is
    /// approximately convex, has no critical angle and its corner score is not worse than the
    /// worse of the two (`F*(A ∪ B) ≤ max(F*(A), F*(B)) + 0.02`). Candidates are applied in
    /// order of gain, each block at most once per pass, until a pass merges nothing. Removed
    /// cuts are dropped and the remaining cuts renumbered; leaf nodes of the tree point to the
    /// merged block.
    fn merge_pass(&mut self, rings: Vec<Ring>) -> Vec<Ring> {
        // the tests of blocks and unions, shared with the other layouts of the region (or
        // kept for this pass's rounds)
        let cache = self.cache.clone();
        let local = MergeMemo::default();
        let memo = cache.as_deref().map_or(&local, |c| &c.merges);
        let mut slot: Vec<Option<Ring>> = rings.into_iter().map(Some).collect();
        let mut owner: Vec<usize> = (0..slot.len()).collect(); // union-find over slots
        let mut fit: Vec<f64> = slot
            .iter()
            .map(|r| r.as_ref().map_or(0.0, |r| memo.fit(&r.pts)))
            .collect();
        let mut alive_cut = vec![true; self.cuts.len()];
        loop {
            // cut → (slot, edge) uses
            let mut uses: Vec<Vec<(usize, usize)>> = vec![Vec::new(); self.cuts.len()];
            for (k, r) in slot.iter().enumerate() {
                if let Some(r) = r {
                    for (e, t) in r.tags.iter().enumerate() {
                        if let Tag::Cut(c) = t {
                            uses[*c].push((k, e));
                        }
                    }
                }
            }
            let mut cands: Vec<(f64, usize, Ring)> = Vec::new();
            for (c, u) in uses.iter().enumerate() {
                if c < self.protected_cuts || u.len() != 2 || u[0].0 == u[1].0 {
                    continue;
                }
                let ((ka, ea), (kb, eb)) = (u[0], u[1]);
                let (Some(a), Some(b)) = (&slot[ka], &slot[kb]) else {
                    continue;
                };
                // exactly one shared cut and no other shared point; the union approximately
                // convex and without a critical angle
                let Some(f) = memo.union_fit(&self.opts.tolerances, a, ea, b, eb) else {
                    continue;
                };
                let worst = fit[ka].max(fit[kb]);
                // a triangle bounded by cuts only could get its fourth corner only inside a cut
                // (a valence-3 interior node): merge it whenever the union is admissible
                let cut_triangle =
                    |r: &Ring| r.len() == 3 && r.tags.iter().all(|t| matches!(t, Tag::Cut(_)));
                if f <= worst + 0.02 || cut_triangle(a) || cut_triangle(b) {
                    if let Some(u) = crate::repair::union_ring(a, ea, b, eb) {
                        cands.push((worst - f, c, u));
                    }
                }
            }
            if cands.is_empty() {
                break;
            }
            cands.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
            let mut touched = vec![false; slot.len()];
            let mut merged = false;
            for (_, c, ring) in cands {
                let u = &uses[c];
                let (ka, kb) = (u[0].0, u[1].0);
                if touched[ka] || touched[kb] {
                    continue;
                }
                touched[ka] = true;
                touched[kb] = true;
                fit[ka] = memo.fit(&ring.pts);
                slot[ka] = Some(ring);
                slot[kb] = None;
                owner[kb] = ka;
                alive_cut[c] = false;
                merged = true;
            }
            if !merged {
                break;
            }
        }
        self.renumber(slot, owner, alive_cut)
    }

    /// Turns the leaves into blocks, resolves neighbours, applies the triangle rule, selects
    /// corners and validates the result.
    pub fn finish(mut self) -> Result<Decomposition, DecomposeError> {
        // leaves in DFS order (child 1 before child 2)
        let mut order = Vec::new();
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            if self.nodes[n].children.is_empty() {
                order.push(n);
            } else {
                for &c in self.nodes[n].children.iter().rev() {
                    stack.push(c);
                }
            }
        }
        let mut rings: Vec<Ring> = Vec::with_capacity(order.len());
        for (bid, &n) in order.iter().enumerate() {
            let Some(piece) = self.pieces[n].take() else {
                continue;
            };
            if let Some(h) = piece.holes.first() {
                let hole = match h.tags[0] {
                    Tag::Boundary(r) => r.saturating_sub(1),
                    Tag::Cut(_) => 0,
                };
                return Err(DecomposeError::HoleNotSeparated { hole });
            }
            let mut seen_cuts: Vec<usize> = piece
                .outer
                .tags
                .iter()
                .filter_map(|t| match t {
                    Tag::Cut(c) => Some(*c),
                    Tag::Boundary(_) => None,
                })
                .collect();
            let total = seen_cuts.len();
            seen_cuts.sort_unstable();
            seen_cuts.dedup();
            if seen_cuts.len() != total {
                // a hole bridged by one cut but never separated by a second one
                let hole = piece
                    .outer
                    .tags
                    .iter()
                    .find_map(|t| match t {
                        Tag::Boundary(r) if *r > 0 => Some(r - 1),
                        _ => None,
                    })
                    .unwrap_or(0);
                return Err(DecomposeError::HoleNotSeparated { hole });
            }
            self.nodes[n].block = Some(bid);
            rings.push(piece.outer);
        }
        let rings = if self.opts.merge_blocks {
            self.merge_pass(rings)
        } else {
            rings
        };
        let rings = if self.opts.repair_corners && self.auto_repair {
            self.repair_pass(rings)
        } else {
            rings
        };
        // cut → blocks
        let mut sides: Vec<Vec<usize>> = vec![Vec::new(); self.cuts.len()];
        for (bid, r) in rings.iter().enumerate() {
            for t in &r.tags {
                if let Tag::Cut(c) = t {
                    sides[*c].push(bid);
                }
            }
        }
        let theta = self.opts.tolerances.theta_minus;
        let mut rings = rings;
        // phase A: triangle-block rule (inserting points, splitting cuts when needed)
        let mut corner_points: Vec<Option<[DVec2; 4]>> = vec![None; rings.len()];
        for bid in 0..rings.len() {
            let pts = rings[bid].pts.clone();
            let Some(((new_pts, origin, corners), _)) =
                triangle_plan(&rings[bid], theta, self.opts)
            else {
                continue;
            };
            // apply insertions from the last to the first so edge indices stay valid
            let mut ins: Vec<(usize, DVec2)> = origin
                .iter()
                .zip(&new_pts)
                .filter_map(|(o, p)| o.map(|e| (e, *p)))
                .collect();
            ins.sort_by(|a, b| {
                b.0.cmp(&a.0).then_with(|| {
                    let base = pts[a.0];
                    b.1.distance(base).total_cmp(&a.1.distance(base))
                })
            });
            for (e, p) in ins {
                self.insert_on_edge(&mut rings, bid, e, p);
            }
            corner_points[bid] = Some(corners.map(|k| new_pts[k]));
        }
        // cut → blocks
        let mut sides: Vec<Vec<usize>> = vec![Vec::new(); self.cuts.len()];
        for (bid, r) in rings.iter().enumerate() {
            for t in &r.tags {
                if let Tag::Cut(c) = t {
                    sides[*c].push(bid);
                }
            }
        }
        let cuts: Vec<Cut> = self
            .cuts
            .iter()
            .enumerate()
            .map(|(id, &(a, b))| Cut {
                id,
                a,
                b,
                blocks: [
                    sides[id].first().copied().unwrap_or(0),
                    sides[id].get(1).copied().unwrap_or(0),
                ],
            })
            .collect();
        // phase B: corners
        let mut blocks = Vec::with_capacity(rings.len());
        for (bid, r) in rings.into_iter().enumerate() {
            let edges: Vec<EdgeKind> = r
                .tags
                .iter()
                .map(|t| match *t {
                    Tag::Boundary(ring) => EdgeKind::Boundary { ring },
                    Tag::Cut(c) => EdgeKind::Cut {
                        cut: c,
                        neighbour: cuts[c].blocks[if cuts[c].blocks[0] == bid { 1 } else { 0 }],
                    },
                })
                .collect();
            let (corners, triangle) = match corner_points[bid] {
                Some(cp) => {
                    let mut c: Vec<usize> = cp
                        .iter()
                        .filter_map(|p| r.pts.iter().position(|x| x == p))
                        .collect();
                    c.sort_unstable();
                    if c.len() != 4 {
                        return Err(DecomposeError::BadCorners {
                            block: bid,
                            reason: "triangle-block corners were lost".into(),
                        });
                    }
                    ([c[0], c[1], c[2], c[3]], true)
                }
                None => match select_corners(&r.pts, &self.opts.corner_weights).or_else(|| {
                    // last resort (counted as "corners ≥ 170°" in docs/results.md): any four
                    // non-reflex vertices, however straight; only reached when neither the
                    // corner repair nor the triangle rule could serve the block
                    let w = CornerWeights {
                        max_corner_angle: PI,
                        corner_angle_limit: PI,
                        ..self.opts.corner_weights
                    };
                    select_corners(&r.pts, &w)
                }) {
                    Some((c, _)) => (c, false),
                    None => {
                        return Err(DecomposeError::BadCorners {
                            block: bid,
                            reason: "fewer than four non-reflex vertices".into(),
                        })
                    }
                },
            };
            blocks.push(Block {
                id: bid,
                ring: r.pts,
                corners,
                edges,
                triangle,
            });
        }
        let d = Decomposition {
            blocks,
            cuts,
            tree: self.nodes,
        };
        d.validate(self.region)?;
        Ok(d)
    }
}

/// `true` if a block gets the triangle-block rule: three vertices, or fewer than four
/// corner-like (interior angle below θ_max) vertices.
fn is_triangle_like(ring: &[DVec2], w: &CornerWeights) -> bool {
    let n = ring.len();
    n == 3
        || (0..n)
            .filter(|&i| ring_angle(ring, i) < w.corner_angle_limit)
            .count()
            < 4
}

/// The triangle-block rule for a block ring as [`Builder::finish`] applies it, and whether it
/// puts a point **inside a cut** (`true`: a cut joint, an interior mesh node of valence 3).
/// `None` when the block is not triangle-like or takes its corners among four non-reflex
/// vertices instead.
///
/// Points are inserted on original-boundary edges only if possible; a three-corner block
/// keeps its critical vertex as a corner and gets its fourth corner on the boundary; only
/// when neither works is a point put inside a cut (the repair pass, module `repair`, removes
/// every such block it can before this runs).
pub(crate) fn triangle_plan(
    ring: &Ring,
    theta: f64,
    opts: &DecomposeOptions,
) -> Option<(TriangleBlock, bool)> {
    let pts = &ring.pts;
    if !is_triangle_like(pts, &opts.corner_weights) {
        return None;
    }
    let tags = &ring.tags;
    let boundary_only = |e: usize| matches!(tags.get(e), Some(Tag::Boundary(_)));
    let frac = opts.triangle_insert_fraction;
    if let Some(t) = triangle_rule(pts, theta, frac, &boundary_only) {
        return Some((t, false));
    }
    // with four non-reflex vertices, phase B picks corners among them instead
    let non_reflex = (0..pts.len()).filter(|&i| ring_angle(pts, i) < PI).count();
    if non_reflex >= 4 {
        return None;
    }
    // keep the critical vertex as a corner, fourth corner on boundary
    if let Some(t) = triangle_rule(pts, 0.0, frac, &boundary_only) {
        return Some((t, false));
    }
    let t = triangle_rule(pts, theta, frac, &|_| true)?;
    let in_cut =
        t.1.iter()
            .any(|o| o.is_some_and(|e| matches!(tags.get(e), Some(Tag::Cut(_)))));
    Some((t, in_cut))
}

/// `true` if the block ring would get a corner inside a cut (see [`triangle_plan`]).
pub(crate) fn needs_cut_point(ring: &Ring, theta: f64, opts: &DecomposeOptions) -> bool {
    triangle_plan(ring, theta, opts).is_some_and(|(_, in_cut)| in_cut)
}

/// A block's (possibly extended) ring, its edge bookkeeping, corners and triangle flag.
pub(crate) type CornerChoice = (Vec<DVec2>, Vec<EdgeKind>, [usize; 4], bool);

/// Corner choice for one block: the quadrilateral selection, or the triangle rule when the
/// block has fewer than four corner-like vertices or is a triangle.
pub(crate) fn choose_corners(
    block: usize,
    ring: &[DVec2],
    edges: &[EdgeKind],
    theta_minus: f64,
    opts: &DecomposeOptions,
) -> Result<CornerChoice, DecomposeError> {
    let n = ring.len();
    let strong = (0..n)
        .filter(|&i| ring_angle(ring, i) < opts.corner_weights.corner_angle_limit)
        .count();
    if n == 3 || strong < 4 {
        let can = |e: usize| matches!(edges[e], EdgeKind::Boundary { .. });
        if let Some((pts, origin, corners)) =
            triangle_rule(ring, theta_minus, opts.triangle_insert_fraction, &can)
        {
            // edge k describes pts[k] → pts[k+1]: an old vertex i starts a piece of old edge i,
            // an inserted point on edge e continues old edge e.
            let mut fixed = Vec::with_capacity(pts.len());
            let mut cur = 0usize;
            for o in &origin {
                match o {
                    None => {
                        fixed.push(edges[cur]);
                        cur += 1;
                    }
                    Some(e) => fixed.push(edges[*e]),
                }
            }
            return Ok((pts, fixed, corners, true));
        }
    }
    match select_corners(ring, &opts.corner_weights) {
        Some((c, _)) => Ok((ring.to_vec(), edges.to_vec(), c, false)),
        None => Err(DecomposeError::BadCorners {
            block,
            reason: "fewer than four non-reflex vertices and the triangle rule does not apply"
                .into(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A comb: a 14 × 2 base with six 1 × 3 teeth (28 vertices, not approximately convex).
    fn comb() -> Region {
        let v = DVec2::new;
        let mut pts = vec![v(0.0, 0.0), v(14.0, 0.0), v(14.0, 2.0)];
        for t in (0..6).rev() {
            let x = 1.0 + 2.0 * t as f64;
            pts.extend([
                v(x + 1.5, 2.0),
                v(x + 1.5, 5.0),
                v(x + 0.5, 5.0),
                v(x + 0.5, 2.0),
            ]);
        }
        pts.push(v(0.0, 2.0));
        Region::new(pts, vec![]).expect("comb")
    }

    /// A comb with teeth on both sides of a 14 × 2 base (52 vertices).
    fn double_comb() -> Region {
        let v = DVec2::new;
        let mut pts = vec![v(0.0, 0.0)];
        for t in 0..6 {
            let x = 1.0 + 2.0 * t as f64;
            pts.extend([
                v(x + 0.5, 0.0),
                v(x + 0.5, -3.0),
                v(x + 1.5, -3.0),
                v(x + 1.5, 0.0),
            ]);
        }
        pts.extend([v(14.0, 0.0), v(14.0, 2.0)]);
        for t in (0..6).rev() {
            let x = 1.0 + 2.0 * t as f64;
            pts.extend([
                v(x + 1.5, 2.0),
                v(x + 1.5, 5.0),
                v(x + 0.5, 5.0),
                v(x + 0.5, 2.0),
            ]);
        }
        pts.push(v(0.0, 2.0));
        Region::new(pts, vec![]).expect("double comb")
    }

    /// A star of 20 spikes (40 vertices) around the origin, centred at (7, 1) and scaled so
    /// that the layout cut of [`run`] crosses it.
    fn star() -> Region {
        let pts = (0..40)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / 40.0;
                let r = if i % 2 == 0 {
                    6.0
                } else {
                    2.5 + 0.1 * (i % 7) as f64
                };
                DVec2::new(7.0 + r * t.cos(), 1.0 + r * t.sin())
            })
            .collect();
        Region::new(pts, vec![]).expect("star")
    }

    /// The state Algorithm 1 leaves in a builder.
    type State = (Vec<(DVec2, DVec2)>, Vec<TreeNode>, Vec<Option<Piece>>);

    /// Algorithm 1 on the two pieces of `region` after the layout cut `cut`, with `dummies`
    /// unrelated cuts made first (so that every cut id is shifted by that much).
    fn run(
        region: &Region,
        cut: (DVec2, DVec2),
        cache: Option<&Arc<LayoutCache>>,
        dummies: usize,
    ) -> State {
        let opts = DecomposeOptions::default();
        let mut b = Builder::new(region, &opts);
        b.cache = cache.cloned();
        for _ in 0..dummies {
            b.new_cut(DVec2::ZERO, DVec2::ONE);
        }
        let tol = crate::decomposition::boundary_tol(region);
        let applied = b.apply_cut(cut.0, cut.1, tol, Step::Chord);
        assert_eq!(applied, Applied::Split);
        for n in [1, 2] {
            b.run_auto(n).expect("Algorithm 1");
        }
        (b.cuts.split_off(dummies), b.nodes, b.pieces)
    }

    /// `state` with every cut id `c` ≥ `shift` made `c − shift`.
    fn unshift(state: State, shift: usize) -> State {
        let (cuts, mut nodes, pieces) = state;
        for n in &mut nodes {
            for c in &mut n.cuts {
                *c -= shift;
            }
        }
        let pieces = pieces
            .into_iter()
            .map(|p| p.map(|p| renumber_piece(&p, &|c| c.checked_sub(shift)).expect("ids")))
            .collect();
        (cuts, nodes, pieces)
    }

    /// Runs replayed from the cache (also with other cut ids) give what computing gives; on
    /// the star some kept runs split both children further.
    #[test]
    fn replayed_runs_are_the_computed_ones() {
        let across = (DVec2::new(7.0, 0.0), DVec2::new(7.0, 2.0));
        replayed_runs_on(&comb(), across);
        replayed_runs_on(&double_comb(), across);
        let star = star();
        let p = star.outer().points();
        assert!(replayed_runs_on(&star, (p[1], p[21])) > 0);
    }

    /// Checks the runs of [`run`] on `region` computed, computed with a cache and replayed
    /// from it; the number of kept runs that split both children further.
    fn replayed_runs_on(region: &Region, cut: (DVec2, DVec2)) -> usize {
        let plain = run(region, cut, None, 0);
        assert!(plain.0.len() > 4, "{} cuts", plain.0.len());
        let cache = Arc::new(LayoutCache::default());
        assert_eq!(run(region, cut, Some(&cache), 0), plain);
        let split_both = |r: &NodeRun| {
            r.split
                .as_ref()
                .is_some_and(|s| s.children.iter().all(|c| c.run.split.is_some()))
        };
        let (stored, both) = cache
            .node_runs
            .lock()
            .map(|m| (m.len(), m.values().filter(|r| split_both(r)).count()))
            .unwrap_or((0, 0));
        assert!(stored > 0);
        // from the cache, on pieces whose cut ids are shifted by three
        assert_eq!(unshift(run(region, cut, Some(&cache), 3), 3), plain);
        assert_eq!(run(region, cut, Some(&cache), 0), plain);
        both
    }
}
