//! The work that the layouts of one region with one option set share ([`LayoutCache`]):
//! Algorithm 1 runs on leaves and on pieces, the builder state after a list of layout cuts,
//! the merge pass's tests; and the layout build that reads and fills it
//! ([`layout_from_cuts_cached`]).

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use unamalla_mesh::{DVec2, Region};

use super::Builder;
use crate::builder::repair::RepairCache;
use crate::concavity::{measures, Tolerances};
use crate::corners::quad_fit;
use crate::decomposition::{Decomposition, Step, TreeNode};
use crate::error::DecomposeError;
use crate::piece::{Piece, Ring, Tag};
use crate::DecomposeOptions;

/// Results that the layouts of one region with one option set share (the rebuilds of
/// [`chord_layout_cuts`](crate::chord_layout_cuts) after each round of arm cuts and each withdrawal differ from each
/// other in a few pieces only). Each entry is keyed by everything its computation reads, so
/// a hit returns exactly what the computation would; see [`Builder::run_auto_on_leaves`] and
/// the repair pass (`Builder::cached_attempt`).
#[derive(Default)]
pub(crate) struct LayoutCache {
    /// Repair attempts (module `repair`).
    pub repair: Mutex<RepairCache>,
    /// Algorithm 1 on a leaf piece, keyed by [`piece_key`].
    pub(super) leaf_runs: Mutex<HashMap<Vec<u64>, Arc<LeafRun>>>,
    /// Algorithm 1 on a piece met inside a run, keyed by [`node_key`] (see
    /// [`Builder::run_node`]).
    pub(super) node_runs: Mutex<HashMap<Vec<u64>, Arc<NodeRun>>>,
    /// The builder after applying each layout's cut list ([`AppliedCuts`]).
    applied: Mutex<Vec<Arc<AppliedCuts>>>,
    /// The merge pass's tests of blocks and unions.
    pub(super) merges: MergeMemo,
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
    pub(super) fn fit(&self, pts: &[DVec2]) -> f64 {
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
    /// edges `ea` and `eb` ([`crate::builder::repair::union_ring`]), if the merge pass may make it: the
    /// two share exactly two points, and the union is approximately convex without a
    /// critical angle; `None` otherwise.
    pub(super) fn union_fit(
        &self,
        tol: &Tolerances,
        a: &Ring,
        ea: usize,
        b: &Ring,
        eb: usize,
    ) -> Option<f64> {
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
            let u = crate::builder::repair::union_ring(a, ea, b, eb)?;
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
/// each cut of `layout` in order. The rebuilds of [`chord_layout_cuts`](crate::chord_layout_cuts) extend the cut list
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
pub(super) fn piece_key(piece: &Piece) -> Vec<u64> {
    let mut key = Vec::new();
    for r in piece.rings() {
        r.push_key(&mut key, |c, key| key.extend([1, c as u64]));
    }
    key
}

/// The content of a piece up to its cut ids, and those ids: the points, per edge the region
/// ring or, for a cut, its number in the order the cuts first appear (the piece's rings in
/// order); the cut ids in that order.
pub(super) fn node_key(piece: &Piece) -> (Vec<u64>, Vec<usize>) {
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
pub(super) fn renumber_piece(
    piece: &Piece,
    number: &dyn Fn(usize) -> Option<usize>,
) -> Result<Piece, ()> {
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
pub(super) const NODE_RUN_MIN_LEN: usize = 16;

/// What Algorithm 1 did on a piece ([`Builder::run_node`]), with the piece's cuts numbered
/// as in its [`node_key`] and the cuts it made numbered after them, in order.
pub(crate) struct NodeRun {
    /// The leaves of the subtree (1: the piece was left whole).
    pub(super) leaves: usize,
    /// The split made on the piece, `None` if it was left whole.
    pub(super) split: Option<NodeSplit>,
}

/// A split of a [`NodeRun`].
pub(super) struct NodeSplit {
    pub(super) step: Step,
    /// The new cuts, in the order they were made.
    pub(super) cuts: Vec<(DVec2, DVec2)>,
    /// The two children (the first one of a split by Algorithm 4, the triangle, is left
    /// whole).
    pub(super) children: [ChildRun; 2],
}

/// A child of a [`NodeSplit`]: its piece if it was left whole (numbered as the parent), the
/// parent's number of each of its cuts in its own [`node_key`] order, and its run.
pub(super) struct ChildRun {
    pub(super) piece: Option<Piece>,
    pub(super) ids: Vec<usize>,
    pub(super) run: Arc<NodeRun>,
}

/// Algorithm 1 ([`Builder::run_auto`]) on one leaf piece, run in a builder of its own: the
/// nodes it added (node 0 is the leaf, with an empty label), the cuts it made, the pieces.
/// Cut ids from `base` on are its new cuts (`cuts[c - base]`), lower ones are the cuts the
/// piece had already.
pub(super) struct LeafRun {
    pub(super) base: usize,
    pub(super) cuts: Vec<(DVec2, DVec2)>,
    pub(super) nodes: Vec<TreeNode>,
    pub(super) pieces: Vec<Option<Piece>>,
}

/// [`layout_from_cuts`](crate::layout_from_cuts) with the Algorithm 1 runs and repair attempts of earlier layouts of
/// the same region and options ([`LayoutCache`]; the cache only saves work: every entry is
/// what the builder would compute).
pub(crate) fn layout_from_cuts_cached(
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
