//! Algorithm 1 ([Méndez 2023, §4.2.1]) with exclusive branches on the leaves of the tree:
//! holes → Algorithm 2, not approximately convex → Algorithm 3, critical angles → Algorithm 4;
//! run in parallel on the leaves and replayed from the [`LayoutCache`](super::LayoutCache).

use std::sync::Arc;

use rayon::prelude::*;

use unamalla_mesh::DVec2;

use super::cache::{
    node_key, piece_key, renumber_piece, ChildRun, LeafRun, NodeRun, NodeSplit, NODE_RUN_MIN_LEN,
};
use super::Builder;
use crate::concavity::concavity_with_hull;
use crate::decomposition::{Step, TreeNode};
use crate::error::DecomposeError;
use crate::geom::{hull_from_order, hull_order, ring_angles, HullKey};
use crate::piece::{Piece, Tag};

/// What Algorithm 1 computes of a ring before cutting it: the vertex angles, the points in
/// hull order, the convex hull (and whether the points are pairwise different) and the
/// concavity measures — those of [`concavity`](crate::concavity::concavity), computed the same way.
pub(super) struct Shape {
    pub(super) angle: Vec<f64>,
    pub(super) hull_keys: Vec<HullKey>,
    pub(super) hull: Vec<usize>,
    pub(super) distinct: bool,
    pub(super) conc: crate::concavity::Concavity,
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

impl Builder<'_> {
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
    /// ([`LayoutCache`](super::LayoutCache)); a failing run also falls back (the sequential error is the first
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
    /// the cuts). With a [`LayoutCache`](super::LayoutCache), what it did on a piece is kept ([`NodeRun`]) and
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
}

#[cfg(test)]
mod tests {
    use unamalla_mesh::Region;

    use super::*;
    use crate::builder::{Applied, LayoutCache};
    use crate::DecomposeOptions;

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
