//! Algorithm 3 ([Méndez 2023, §4.2.1]), the concavity cut: candidates from the deepest
//! reflex vertices, scored by the expected quality of the children (crate documentation).

use std::f64::consts::PI;

use rayon::prelude::*;

use unamalla_mesh::DVec2;

use super::run::Shape;
use super::{beyond_best, Builder, Cand};
use crate::concavity::measures_with_hull;
use crate::corners::quad_fit_with_angles;
use crate::geom::{
    child_hull, child_hull_order, convex_hull, hull_from_order, match_vertices, ray_segment,
    ring_angles_matched, total_key, visit_sorted,
};
use crate::piece::{End, Piece, Pos, Ring, Tag};

/// What trying a candidate cut of the concavity cut found: not admissible or a child too
/// small (`Skipped`), or its score.
enum Trial {
    Skipped,
    Score(f64),
}

/// Pieces at least this long try a few candidate cuts at a time in parallel (shorter ones
/// run in parallel with the other leaves).
const PARALLEL_TRIALS_MIN_LEN: usize = 64;

impl Builder<'_> {
    /// Badness B(P) of a hole-free piece: its corner score F* if it is approximately convex
    /// (it will be a block), else 1 + κ₂ + κ₃ (it will be cut again).
    /// The ring's vertex angles (`angles[i]` = `ring_angle(ring, i)`) and convex hull (as
    /// [`concavity_with_hull`](crate::concavity::concavity_with_hull) takes it) are given, for the concavity measures and the corner
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
    pub(super) fn concavity_cut(
        &mut self,
        piece: &Piece,
        shape: &Shape,
    ) -> Option<(Piece, Piece, usize)> {
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
}
