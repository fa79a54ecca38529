//! Step 1 and 3 of the repair: the best split of a block into two good blocks, or into three
//! by two cuts, and committing a split to the tree.

use std::cell::Cell;

use rayon::prelude::*;
use unamalla_mesh::geometry::open_segment_hits;
use unamalla_mesh::DVec2;

use super::table::{ChildScreen, CutTable};
use super::{as_first_cut, retag, Resplit, Split, TMP_CUT, TMP_IDS};
use crate::builder::{beyond_best, Builder};
use crate::decomposition::{Step, TreeNode};
use crate::geom::{total_key, visit_sorted};
use crate::piece::{End, Piece, Pos, Ring, Tag};

impl Builder<'_> {
    /// The best cut splitting `ring` into two good blocks.
    pub(super) fn best_split(&self, ring: &Ring) -> Option<Split> {
        self.best_split_by(ring, &|r: &Ring| self.good_fit(r), true, None)
    }

    /// The best cut splitting `ring` into two blocks that `accept` takes; `accept` returns the
    /// cost F of a child (its corner score, plus a grade penalty in the relaxed pass) and the
    /// split scores `½·max(F₁, F₂) + ¼·(F₁ + F₂) + w_a·ḡ + w_l·ℓ/√A`.
    ///
    /// The quarter points of the original-boundary edges are offered only when the vertices
    /// and feet give no acceptable split (so they add repairs without changing the ones that
    /// worked before), and only with [`DecomposeOptions::edge_point_cuts`](crate::DecomposeOptions::edge_point_cuts).
    ///
    /// `good_only` says that `accept` takes only good blocks ([`Builder::good_fit`], possibly
    /// narrowed): then candidates whose children cannot both be good are not built
    /// ([`Builder::for_each_split`]); it changes no result. `angles`: the [`CutTable`] of a
    /// ring that `ring` is a child of (or `ring` itself), if the caller keeps one.
    pub(super) fn best_split_by(
        &self,
        ring: &Ring,
        accept: &(dyn Fn(&Ring) -> Option<f64> + Sync),
        good_only: bool,
        angles: Option<&CutTable>,
    ) -> Option<Split> {
        self.best_split_with(ring, accept, good_only, false, angles)
            .or_else(|| {
                self.opts
                    .edge_point_cuts
                    .then(|| self.best_split_with(ring, accept, good_only, true, angles))
                    .flatten()
            })
    }

    /// [`Builder::best_split_by`] with or without the quarter-point targets.
    fn best_split_with(
        &self,
        ring: &Ring,
        accept: &(dyn Fn(&Ring) -> Option<f64> + Sync),
        good_only: bool,
        quarter_points: bool,
        angles: Option<&CutTable>,
    ) -> Option<Split> {
        let mut best: Option<Split> = None;
        let need = if good_only { 2 } else { 0 };
        // the best score so far: the search ends at the first candidate whose cheap terms
        // reach it (exact, `beyond_best`: `accept` costs are never negative)
        let bound = Cell::new(f64::NAN);
        self.for_each_split(
            ring,
            quarter_points,
            need,
            Some(&bound),
            angles,
            &mut |pre, a, b, ends| {
                // `accept` is pure: the second child is not looked at when the first fails
                let Some(fa) = accept(&a) else { return };
                let Some(fb) = accept(&b) else { return };
                let s = 0.5 * fa.max(fb) + 0.25 * (fa + fb) + pre;
                if best.as_ref().is_none_or(|b| s < b.0) {
                    bound.set(s);
                    best = Some((s, a, b, ends));
                }
            },
        );
        best
    }

    /// Calls `visit(pre, a, b, ends)` for the first 80 admissible cuts of `ring` in the order
    /// of their cheap terms `pre = w_a·ḡ + w_l·ℓ/√A` (ties broken by coordinates): `a`, `b` are
    /// the children (the new cut tagged [`TMP_CUT`]) and `ends` the cut's endpoints. Targets:
    /// vertex → vertex and vertex → foot of the perpendicular on an original-boundary edge,
    /// with `quarter_points` also the quarter points of those edges.
    ///
    /// With `need` = 1 or 2, the caller will only use a candidate of which at least `need`
    /// children are good ([`Builder::good_fit`]): a counted candidate (it still counts towards
    /// the 80) whose children cannot be is not built or visited ([`ChildScreen`]), and when no
    /// candidate can pass, nothing is searched. `need` = 0 visits every counted candidate.
    ///
    /// With a `bound` (the caller's best two-child score so far, NaN while there is none),
    /// the search ends at the first candidate whose `pre` reaches it: the caller keeps a
    /// candidate only if it scores below the bound, which no candidate from there on can
    /// (`beyond_best`). With `angles`, the new angles at the ends of a cut (without the
    /// quarter points) come from that table where `ring`'s vertices and edges are its host's.
    fn for_each_split(
        &self,
        ring: &Ring,
        quarter_points: bool,
        need: usize,
        bound: Option<&Cell<f64>>,
        angles: Option<&CutTable>,
        visit: &mut dyn FnMut(f64, Ring, Ring, (DVec2, DVec2)),
    ) {
        let n = ring.len();
        if n < 4 {
            return;
        }
        let screen = (need > 0).then(|| ChildScreen::new(ring, self.opts));
        if screen.as_ref().is_some_and(|c| need == 2 && c.bad > 3) {
            // a cut changes the angles of at most three vertices of `ring` (its start vertex,
            // and its end vertex or the two ends of the edge it ends on): some bad vertex
            // keeps its angle in a child, which is then not good
            return;
        }
        let piece = Piece {
            outer: ring.clone(),
            holes: Vec::new(),
        };
        // the ring's edge index, built if a cut is tested without the table
        let idx_cell = std::cell::OnceCell::new();
        let idx = || idx_cell.get_or_init(|| piece.index());
        let sq = piece.area().abs().sqrt().max(1e-300);
        let w = self.opts.cut_weights;
        let mut cands: Vec<(f64, End, End)> = Vec::new();
        let table = angles
            .filter(|_| !quarter_points)
            .map(|t| (t, t.locate(ring)));
        // the cut from vertex `i` to `e2` in the host's numbering, where the table has it:
        // the host vertex of `i`, and the host vertex or the foot on a host edge of `e2`
        let in_host = |i: usize, e2: End| {
            let (t, at) = table.as_ref()?;
            let hi = at.vertex[i];
            if hi == usize::MAX {
                return None;
            }
            let to = match e2.pos {
                Pos::Vertex(j) if at.vertex[j] != usize::MAX => Pos::Vertex(at.vertex[j]),
                Pos::OnEdge(e, x) if at.edge[e] != usize::MAX => Pos::OnEdge(at.edge[e], x),
                _ => return None,
            };
            Some((*t, hi, End { ring: 0, pos: to }))
        };
        // the angle terms of the cut from vertex `i` (as `angle_terms` in tier 1), from the
        // table where it has the angles
        let terms = |i: usize, e2: End| {
            let e1 = End {
                ring: 0,
                pos: Pos::Vertex(i),
            };
            // (a cut the screen rejects at either end gets `None`, as in `angle_terms`)
            match in_host(i, e2) {
                None => self.angle_terms(&piece, e1, e2, 1),
                Some((
                    t,
                    hi,
                    End {
                        pos: Pos::Vertex(hj),
                        ..
                    },
                )) => {
                    let [a, b] = t.vertex_angles(hi, hj)?;
                    let [c, d] = t.vertex_angles(hj, hi)?;
                    self.angle_terms_of([a, b, c, d], 1)
                }
                Some((
                    t,
                    hi,
                    End {
                        pos: Pos::OnEdge(he, x),
                        ..
                    },
                )) => self.angle_terms_of(t.foot_angles(hi, he, x)?, 1),
            }
        };
        // the ring's edges that are not the host's (see `CutTable::admissible`)
        let not_host: Vec<(DVec2, DVec2)> = table
            .as_ref()
            .map(|(_, at)| {
                (0..n)
                    .filter(|&k| at.edge[k] == usize::MAX)
                    .map(|k| (ring.p(k), ring.next(k)))
                    .collect()
            })
            .unwrap_or_default();
        let admissible = |e1: End, e2: End| {
            let Pos::Vertex(i) = e1.pos else {
                return piece.admissible(idx(), e1, e2);
            };
            match in_host(i, e2) {
                Some((t, hi, to)) => {
                    let (p, q) = (piece.point(e1), piece.point(e2));
                    t.admissible(hi, to)
                        && !not_host.iter().any(|&(a, b)| open_segment_hits(p, q, a, b))
                }
                None => piece.admissible(idx(), e1, e2),
            }
        };
        // the target list, reused for every start vertex
        let mut t = Vec::new();
        for i in 0..n {
            let p = ring.p(i);
            let e1 = End {
                ring: 0,
                pos: Pos::Vertex(i),
            };
            let near = |j: usize| j == i || j == (i + 1) % n || j == (i + n - 1) % n;
            t.clear();
            Self::targets_on_ring(&piece, 0, p, &near, &mut t);
            // also the quarter points of the original-boundary edges: a cut that met the
            // boundary at a critical angle at a vertex can end inside the edge instead, where
            // the foot of the perpendicular is not on the edge
            for e in (0..n).filter(|_| quarter_points) {
                let e2 = (e + 1) % n;
                if near(e) || near(e2) || !matches!(ring.tags[e], Tag::Boundary(_)) {
                    continue;
                }
                let (a, b) = (ring.p(e), ring.p(e2));
                for f in [0.25, 0.5, 0.75] {
                    t.push(End {
                        ring: 0,
                        pos: Pos::OnEdge(e, a + f * (b - a)),
                    });
                }
            }
            for &e2 in &t {
                if let Pos::Vertex(j) = e2.pos {
                    if j < i {
                        continue; // each vertex pair once
                    }
                }
                let Some((pen, _)) = terms(i, e2) else {
                    continue;
                };
                let q = piece.point(e2);
                cands.push((w.angle * pen + w.length * p.distance(q) / sq, e1, e2));
            }
        }
        // the candidates in the order of (pre, coordinates of both ends, position): the
        // sequence a stable sort by pre and coordinates gives, sorted only as far as the
        // search goes (`visit_sorted`)
        // (pre by its `total_cmp` key)
        let mut order: Vec<(u64, usize)> = (0..cands.len())
            .map(|k| (total_key(cands[k].0), k))
            .collect();
        let mut evaluated = 0;
        let cmp = |&(sa, ka): &(u64, usize), &(sb, kb): &(u64, usize)| {
            sa.cmp(&sb)
                .then_with(|| {
                    let (a, b) = (&cands[ka], &cands[kb]);
                    let (pa, pb) = (piece.point(a.1), piece.point(b.1));
                    let (qa, qb) = (piece.point(a.2), piece.point(b.2));
                    pa.x.total_cmp(&pb.x)
                        .then(pa.y.total_cmp(&pb.y))
                        .then(qa.x.total_cmp(&qb.x))
                        .then(qa.y.total_cmp(&qb.y))
                })
                .then(ka.cmp(&kb))
        };
        visit_sorted(&mut order, cmp, |&(_, k)| {
            let (pre, e1, e2) = cands[k];
            if evaluated >= 80 || bound.is_some_and(|b| beyond_best(pre, b.get())) {
                return false;
            }
            if !admissible(e1, e2) {
                return true;
            }
            evaluated += 1;
            if screen
                .as_ref()
                .is_some_and(|c| c.possibly_good(e1, e2) < need)
            {
                return true;
            }
            let (a, b, ends) = piece.split_between(e1, e2, TMP_CUT);
            visit(pre, a.outer, b.outer, ends);
            true
        });
    }

    /// The best split of `ring` by **two** cuts into three blocks that `accept` takes (step 3
    /// of the repair): a first cut leaves one accepted child and one that the best second cut
    /// ([`Builder::best_split_by`]) splits into two accepted children. Only first cuts that do
    /// not already give two accepted children are followed (those are steps 1–2). Score
    /// `½·max(F₁, F₂, F₃) + (F₁ + F₂ + F₃)/6 + pre₁ + pre₂` — the two-child score
    /// `½·max + ½·mean` with the mean over three, plus both cuts' angle and length terms.
    /// `good_only` as in [`Builder::best_split_by`].
    ///
    /// `angles` is the [`CutTable`] table of `ring`, shared by the search of the first cuts
    /// and the searches of the second cuts in their children.
    pub(super) fn best_split3(
        &self,
        ring: &Ring,
        accept: &(dyn Fn(&Ring) -> Option<f64> + Sync),
        good_only: bool,
        angles: &CutTable,
    ) -> Option<Resplit> {
        let mut best: Option<Resplit> = None;
        for quarter_points in [false, true] {
            if quarter_points && (best.is_some() || !self.opts.edge_point_cuts) {
                break;
            }
            // the first cuts in their order, then the second-cut searches in parallel, the
            // results compared in that same order (as a sequential loop would)
            let mut firsts = Vec::new();
            // a first cut is followed only if it leaves exactly one accepted child
            let need = if good_only { 1 } else { 0 };
            self.for_each_split(
                ring,
                quarter_points,
                need,
                None,
                Some(angles),
                &mut |pre1, a, b, ends1| {
                    firsts.push((pre1, a, b, ends1));
                },
            );
            let found: Vec<Option<Resplit>> = firsts
                .into_par_iter()
                .map(|(pre1, a, b, ends1)| {
                    let (fa, fb) = (accept(&a), accept(&b));
                    let (kept, fk, rest) = match (fa, fb) {
                        (Some(fa), None) => (a, fa, b),
                        (None, Some(fb)) => (b, fb, a),
                        _ => return None,
                    };
                    let (s2, r1, r2, ends2) =
                        self.best_split_by(&as_first_cut(rest), accept, good_only, Some(angles))?;
                    let (f1, f2) = (accept(&r1)?, accept(&r2)?);
                    let pre2 = s2 - 0.5 * f1.max(f2) - 0.25 * (f1 + f2);
                    let s = 0.5 * fk.max(f1).max(f2) + (fk + f1 + f2) / 6.0 + pre1 + pre2;
                    Some((s, vec![as_first_cut(kept), r1, r2], vec![ends1, ends2]))
                })
                .collect();
            for c in found.into_iter().flatten() {
                if best.as_ref().is_none_or(|b| c.0 < b.0) {
                    best = Some(c);
                }
            }
        }
        best
    }

    /// Commits a split: a real cut id replaces [`TMP_CUT`].
    pub(super) fn commit_split(
        &mut self,
        a: Ring,
        b: Ring,
        ends: (DVec2, DVec2),
    ) -> (Ring, Ring, usize) {
        let id = self.new_cut(ends.0, ends.1);
        (retag(a, TMP_CUT, id), retag(b, TMP_CUT, id), id)
    }

    /// Commits a [`Resplit`]'s cuts: real cut ids replace the placeholder tags.
    pub(super) fn commit_resplit(
        &mut self,
        children: Vec<Ring>,
        ends: &[(DVec2, DVec2)],
    ) -> (Vec<Ring>, Vec<usize>) {
        let ids: Vec<usize> = ends.iter().map(|e| self.new_cut(e.0, e.1)).collect();
        let children = children
            .into_iter()
            .map(|r| {
                ids.iter()
                    .zip(TMP_IDS)
                    .fold(r, |r, (&id, tmp)| retag(r, tmp, id))
            })
            .collect();
        (children, ids)
    }

    /// Records a repair split of block slot `k` into slots `k` and `m` in the tree: the first
    /// leaf pointing to `k` gets two children.
    pub(super) fn branch_leaf(&mut self, k: usize, m: usize, cut: usize) {
        let Some(leaf) = self
            .nodes
            .iter()
            .position(|n| n.children.is_empty() && n.block == Some(k))
        else {
            return;
        };
        let label = self.nodes[leaf].label.clone();
        let mut ids = Vec::with_capacity(2);
        for (s, block) in [(1, k), (2, m)] {
            self.nodes.push(TreeNode {
                label: if label.is_empty() {
                    format!("{s}")
                } else {
                    format!("{label}.{s}")
                },
                parent: Some(leaf),
                children: Vec::new(),
                step: None,
                cuts: Vec::new(),
                block: Some(block),
            });
            self.pieces.push(None);
            ids.push(self.nodes.len() - 1);
        }
        let node = &mut self.nodes[leaf];
        node.children = ids;
        node.step = Some(Step::CornerRepair);
        node.cuts = vec![cut];
        node.block = None;
    }
}
