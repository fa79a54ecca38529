//! Algorithm 2 ([Méndez 2023, §4.2.1]), hole removal: a bridge from a hole to the outer ring
//! and a second cut that splits the piece and the hole.

use std::f64::consts::PI;

use unamalla_mesh::DVec2;

use super::{Builder, Cand};
use crate::error::DecomposeError;
use crate::geom::{perimeter, project_t};
use crate::piece::{End, Piece, Pos, Tag};

impl Builder<'_> {
    /// Algorithm 2: removes the hole nearest to the outer ring with two cuts.
    pub(super) fn remove_hole(
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
}
