//! Corner selection ([Méndez 2023, §5.1.1]; the references are listed in `docs/references.md`
//! of the repository) and the triangle-block rule.
//!
//! **Quadrilateral blocks.** Candidates are vertices with interior angle θ < θ_max (default
//! 165°: neither reflex nor nearly collinear); when fewer than four qualify, every vertex with
//! θ < θ_lim (default **170°**, the hard bound) is a candidate. A vertex with θ ≥ θ_lim is
//! **never** a corner: at such a corner the two block sides leave in (nearly) opposite
//! directions, so the corner cell of any structured grid has a (nearly) straight angle there —
//! with fixed boundary nodes its corner triangle has α ≈ 0 and no smoothing can repair it.
//! Blocks without four such vertices get no corners here; the decomposition repairs them with
//! an extra cut (module `auto`). The 170° bound is ours (the thesis only says "not collinear",
//! [Méndez 2023, §5.1.1]); 165°–170° corners still give cells with a 165°–170° angle, which the
//! smoother can only improve by moving interior nodes. Among the best `M` candidates (ranked by the angle penalty g(θ)), every
//! cyclically ordered 4-tuple c₀ < c₁ < c₂ < c₃ is scored by
//!
//! ```text
//! F = ¼ Σ_k g(θ_{c_k})                                   corner angles near 90°
//!   + w_bal · ½ (|L₀ − L₂|/(L₀ + L₂) + |L₁ − L₃|/(L₁ + L₃))   balanced opposite sides
//!   + w_turn · ¼ Σ_k (T_k / (π/2))²                        straight sides
//! ```
//!
//! with g(θ) = ((θ − π/2)/(π/2))², L_k the arc length of side k and T_k the total turning
//! Σ(π − θ_v) over the vertices strictly inside side k (a side containing a 90° bend has
//! T = π/2). Side lengths and turnings come from prefix sums, so a tuple costs O(1).
//! Ties are broken by the corner coordinates, never by ring numbering.
//!
//! **Triangle blocks** (three vertices, or fewer than four candidates): with the three
//! smallest-angle vertices as the triangle's corners, a vertex with a critical angle (< θ₋) is
//! replaced by two points inserted on its two incident edges at the same distance
//! d = f·min(incident edge lengths) (f = 0.25); one critical vertex gives 2 inserted points +
//! the 2 other vertices, two critical vertices give the 4 inserted points. A triangle without
//! a critical angle gets its fourth corner at the midpoint of its longest edge.

use std::f64::consts::PI;

use unamalla_mesh::DVec2;

use crate::corners_diametral::{select_diametral, CornerChoice};
use crate::geom::{angle_penalty, ring_angle, ring_angles};

/// Weights of the corner score F.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerWeights {
    /// w_bal: weight of the opposite-side balance.
    pub balance: f64,
    /// w_turn: weight of the side straightness.
    pub turn: f64,
    /// θ_max: vertices with a larger interior angle are not preferred as corners.
    pub max_corner_angle: f64,
    /// θ_lim: vertices with this interior angle or more are never corners (default 170°).
    pub corner_angle_limit: f64,
    /// M: how many candidates enter the exhaustive 4-tuple search.
    pub candidates: usize,
    /// The selection: this module's scoring (default) or the thesis's convex-hull diametral
    /// heuristic ([`crate::corners_diametral`]).
    pub choice: CornerChoice,
}

impl Default for CornerWeights {
    fn default() -> Self {
        Self {
            balance: 0.5,
            turn: 1.0,
            max_corner_angle: 165f64.to_radians(),
            corner_angle_limit: 170f64.to_radians(),
            candidates: 18,
            choice: CornerChoice::Scoring,
        }
    }
}

/// The best corner 4-tuple of a ring and its score F (lower is better), or `None` when the
/// ring has fewer than four vertices with an interior angle below `w.corner_angle_limit`.
pub fn select_corners(ring: &[DVec2], w: &CornerWeights) -> Option<([usize; 4], f64)> {
    if w.choice == CornerChoice::Diametral {
        return select_diametral(ring, w);
    }
    if ring.len() < 4 {
        return None;
    }
    select_corners_with_angles(ring, &ring_angles(ring), w)
}

/// [`select_corners`] for the scoring selection with the ring's vertex angles given
/// (`angles[i]` = `ring_angle(ring, i)`, [`ring_angles`]): the same computation on the same
/// values.
pub(crate) fn select_corners_with_angles(
    ring: &[DVec2],
    angles: &[f64],
    w: &CornerWeights,
) -> Option<([usize; 4], f64)> {
    let n = ring.len();
    if n < 4 {
        return None;
    }
    debug_assert_eq!(angles.len(), n);
    let preferred = w.max_corner_angle.min(w.corner_angle_limit);
    let mut cands: Vec<usize> = (0..n).filter(|&i| angles[i] < preferred).collect();
    if cands.len() < 4 {
        let limit = w.corner_angle_limit.min(PI);
        cands = (0..n).filter(|&i| angles[i] < limit).collect();
    }
    if cands.len() < 4 {
        return None;
    }
    cands.sort_by(|&a, &b| {
        angle_penalty(angles[a])
            .total_cmp(&angle_penalty(angles[b]))
            .then(ring[a].x.total_cmp(&ring[b].x))
            .then(ring[a].y.total_cmp(&ring[b].y))
    });
    cands.truncate(w.candidates.max(4));
    cands.sort_unstable();
    // prefix sums: arc length to vertex i, turning of vertices 0..i
    let mut arc = vec![0.0; n + 1];
    let mut turn = vec![0.0; n + 1];
    for i in 0..n {
        arc[i + 1] = arc[i] + ring[i].distance(ring[(i + 1) % n]);
        turn[i + 1] = turn[i] + (PI - angles[i]);
    }
    let total_arc = arc[n];
    let total_turn = turn[n];
    let side = |a: usize, b: usize| -> (f64, f64) {
        // a < b: arc a→b and turning of vertices a+1..b-1; a > b wraps
        if a < b {
            (arc[b] - arc[a], turn[b] - turn[a + 1])
        } else {
            (
                total_arc - arc[a] + arc[b],
                total_turn - turn[a + 1] + turn[b],
            )
        }
    };
    let m = cands.len();
    let mut best: Option<([usize; 4], f64, [f64; 8])> = None;
    for i0 in 0..m {
        for i1 in i0 + 1..m {
            for i2 in i1 + 1..m {
                for i3 in i2 + 1..m {
                    let c = [cands[i0], cands[i1], cands[i2], cands[i3]];
                    let mut l = [0.0; 4];
                    let mut t = [0.0; 4];
                    for k in 0..4 {
                        let (a, b) = side(c[k], c[(k + 1) % 4]);
                        l[k] = a;
                        t[k] = b;
                    }
                    let ang: f64 = c.iter().map(|&v| angle_penalty(angles[v])).sum::<f64>() / 4.0;
                    let bal = 0.5
                        * ((l[0] - l[2]).abs() / (l[0] + l[2]).max(1e-300)
                            + (l[1] - l[3]).abs() / (l[1] + l[3]).max(1e-300));
                    let tr: f64 = t.iter().map(|x| (x / (PI / 2.0)).powi(2)).sum::<f64>() / 4.0;
                    let f = ang + w.balance * bal + w.turn * tr;
                    // deterministic tie-break on coordinates
                    let key = [
                        ring[c[0]].x,
                        ring[c[0]].y,
                        ring[c[1]].x,
                        ring[c[1]].y,
                        ring[c[2]].x,
                        ring[c[2]].y,
                        ring[c[3]].x,
                        ring[c[3]].y,
                    ];
                    let better = match &best {
                        None => true,
                        Some((_, bf, bk)) => {
                            f < *bf - 1e-12
                                || ((f - *bf).abs() <= 1e-12
                                    && key.partial_cmp(bk) == Some(std::cmp::Ordering::Less))
                        }
                    };
                    if better {
                        best = Some((c, f, key));
                    }
                }
            }
        }
    }
    best.map(|(c, f, _)| (c, f))
}

/// How well a ring would mesh as one block, for scoring candidate cuts: the corner score F
/// of its best corner tuple (with a smaller candidate set), or for rings without four
/// non-reflex vertices ½ + the mean angle penalty of its vertices.
pub(crate) fn quad_fit(ring: &[DVec2]) -> f64 {
    quad_fit_with_angles(ring, &ring_angles(ring))
}

/// [`quad_fit`] with the ring's vertex angles given (`angles[i]` = `ring_angle(ring, i)`,
/// [`ring_angles`]): the same computation on the same values (`quad_fit` uses the scoring
/// selection, so [`select_corners_with_angles`] is what it calls).
pub(crate) fn quad_fit_with_angles(ring: &[DVec2], angles: &[f64]) -> f64 {
    let w = CornerWeights {
        candidates: 10,
        ..CornerWeights::default()
    };
    debug_assert_eq!(w.choice, CornerChoice::Scoring);
    match select_corners_with_angles(ring, angles, &w) {
        Some((_, f)) if ring.len() > 3 => f,
        _ => {
            let n = ring.len().max(1);
            0.5 + angles.iter().map(|&a| angle_penalty(a)).sum::<f64>() / n as f64
        }
    }
}

/// Whether [`select_corners`] with the scoring selection finds a corner tuple, from the ring's
/// vertex angles (`angles[i]` = `ring_angle(ring, i)`): exactly when the ring has four vertices
/// and four candidates survive the θ_max filter or, failing that, the θ_lim filter — the
/// exhaustive search over four or more candidates always keeps its first tuple.
pub(crate) fn has_four_corners(angles: &[f64], w: &CornerWeights) -> bool {
    if angles.len() < 4 {
        return false;
    }
    let preferred = w.max_corner_angle.min(w.corner_angle_limit);
    let limit = w.corner_angle_limit.min(PI);
    angles.iter().filter(|&&a| a < preferred).count() >= 4
        || angles.iter().filter(|&&a| a < limit).count() >= 4
}

/// New ring, origin edge of every ring vertex (`None` = old vertex), four corners.
pub(crate) type TriangleBlock = (Vec<DVec2>, Vec<Option<usize>>, [usize; 4]);

/// The triangle-block rule. `ring` is a block with (at least) three corner-like vertices;
/// `can_insert(e)` says whether a point may be inserted on edge `e` (original boundary only).
/// Returns the new ring, for each new ring vertex the edge of the old ring it was inserted on
/// (`None` for old vertices), and the four corners. `None` if the rule does not apply.
pub(crate) fn triangle_rule(
    ring: &[DVec2],
    theta_minus: f64,
    fraction: f64,
    can_insert: &dyn Fn(usize) -> bool,
) -> Option<TriangleBlock> {
    let n = ring.len();
    if n < 3 {
        return None;
    }
    let angles: Vec<f64> = (0..n).map(|i| ring_angle(ring, i)).collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| {
        angles[a]
            .total_cmp(&angles[b])
            .then(ring[a].x.total_cmp(&ring[b].x))
            .then(ring[a].y.total_cmp(&ring[b].y))
    });
    let mut tri = [order[0], order[1], order[2]];
    tri.sort_unstable();
    // at most the two sharpest critical vertices get inserted points (tri is sorted by index,
    // `order` by angle)
    let critical: Vec<usize> = order[..3]
        .iter()
        .copied()
        .filter(|&v| angles[v] < theta_minus)
        .take(2)
        .collect();
    // insertions: (edge, point) with the point on edge e = ring[e] → ring[e+1]
    let mut ins: Vec<(usize, DVec2)> = Vec::new();
    let mut corner_pts: Vec<DVec2> = Vec::new();
    if critical.is_empty() {
        // the three vertices + the arc-length midpoint of the longest side between them
        let mut arc = vec![0.0; n + 1];
        for i in 0..n {
            arc[i + 1] = arc[i] + ring[i].distance(ring[(i + 1) % n]);
        }
        let side_len = |a: usize, b: usize| {
            if a < b {
                arc[b] - arc[a]
            } else {
                arc[n] - arc[a] + arc[b]
            }
        };
        let (s0, s1) = (0..3)
            .map(|k| (tri[k], tri[(k + 1) % 3]))
            .max_by(|x, y| side_len(x.0, x.1).total_cmp(&side_len(y.0, y.1)))
            .unwrap_or((tri[0], tri[1]));
        let half = 0.5 * side_len(s0, s1);
        let mut walked = 0.0;
        let mut e = s0;
        loop {
            let l = ring[e].distance(ring[(e + 1) % n]);
            if walked + l >= half || (e + 1) % n == s1 {
                let t = if l > 0.0 {
                    ((half - walked) / l).clamp(0.0, 1.0)
                } else {
                    0.5
                };
                let w = (e + 1) % n;
                if t > 0.95 && w != s1 && ring_angle(ring, w) < PI {
                    corner_pts.push(ring[w]);
                } else if t < 0.05 && e != s0 && ring_angle(ring, e) < PI {
                    corner_pts.push(ring[e]);
                } else {
                    let (e, w, t) = if can_insert(e) {
                        (e, w, t)
                    } else {
                        // the midpoint of the longest edge that may take a point
                        let f = (0..n).filter(|&f| can_insert(f)).max_by(|&a, &b| {
                            ring[a]
                                .distance(ring[(a + 1) % n])
                                .total_cmp(&ring[b].distance(ring[(b + 1) % n]))
                        })?;
                        (f, (f + 1) % n, 0.5)
                    };
                    let t = t.clamp(0.05, 0.95);
                    let mid = ring[e] + t * (ring[w] - ring[e]);
                    ins.push((e, mid));
                    corner_pts.push(mid);
                }
                break;
            }
            walked += l;
            e = (e + 1) % n;
        }
        corner_pts.extend(tri.iter().map(|&v| ring[v]));
    } else {
        for &v in &tri {
            if !critical.contains(&v) {
                if critical.len() < 2 {
                    corner_pts.push(ring[v]);
                }
                continue;
            }
            let ep = (v + n - 1) % n;
            let en = v;
            if !can_insert(ep) || !can_insert(en) {
                return None;
            }
            let prev = ring[ep];
            let next = ring[(v + 1) % n];
            let d = fraction * ring[v].distance(prev).min(ring[v].distance(next));
            let p = ring[v] + (prev - ring[v]).normalize() * d;
            let q = ring[v] + (next - ring[v]).normalize() * d;
            ins.push((ep, p));
            ins.push((en, q));
            corner_pts.push(p);
            corner_pts.push(q);
        }
        if corner_pts.len() != 4 {
            return None;
        }
    }
    // build the new ring
    let mut pts = Vec::with_capacity(n + ins.len());
    let mut origin = Vec::with_capacity(n + ins.len());
    for (i, &ri) in ring.iter().enumerate() {
        pts.push(ri);
        origin.push(None);
        let mut here: Vec<DVec2> = ins.iter().filter(|x| x.0 == i).map(|x| x.1).collect();
        here.sort_by(|a, b| a.distance(ri).total_cmp(&b.distance(ri)));
        for p in here {
            pts.push(p);
            origin.push(Some(i));
        }
    }
    let mut corners: Vec<usize> = corner_pts
        .iter()
        .filter_map(|c| pts.iter().position(|p| p == c))
        .collect();
    corners.sort_unstable();
    corners.dedup();
    if corners.len() != 4 {
        return None;
    }
    Some((
        pts,
        origin,
        [corners[0], corners[1], corners[2], corners[3]],
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn rectangle_picks_its_four_vertices() {
        let ring = vec![
            v(0., 0.),
            v(1., 0.),
            v(2., 0.),
            v(2., 1.),
            v(1., 1.),
            v(0., 1.),
        ];
        let (c, f) = select_corners(&ring, &CornerWeights::default()).unwrap();
        assert_eq!(c, [0, 2, 3, 5]);
        assert!(f.abs() < 1e-12);
    }

    /// y-offset that gives a 178° vertex at (2, −h) between (0,0) and (4,0):
    /// the two edges turn by atan(h/2) each, so the interior angle is 180° − 2·atan(h/2) = 178°.
    fn h178() -> f64 {
        2.0 * 1f64.to_radians().tan()
    }

    #[test]
    fn a_178_degree_vertex_is_never_a_corner() {
        let h = h178();
        // triangle-like: apex 2,3 and a 178° vertex on the base: only three usable corners
        let tri = vec![v(0., 0.), v(2., -h), v(4., 0.), v(2., 3.)];
        assert!((ring_angle(&tri, 1).to_degrees() - 178.0).abs() < 1e-9);
        assert_eq!(select_corners(&tri, &CornerWeights::default()), None);
        // even when θ_max would admit it, the hard limit θ_lim = 170° does not
        let loose = CornerWeights {
            max_corner_angle: PI,
            ..CornerWeights::default()
        };
        assert_eq!(select_corners(&tri, &loose), None);
        // with a fourth usable vertex the straight one is skipped
        let rect = vec![v(0., 0.), v(2., -h), v(4., 0.), v(4., 2.), v(0., 2.)];
        let (c, _) = select_corners(&rect, &CornerWeights::default()).unwrap();
        assert_eq!(c, [0, 2, 3, 4]);
        // and a 169° vertex is still usable when it is needed (three 60°-ish corners)
        let h169 = 2.0 * 5.5f64.to_radians().tan();
        let tri2 = vec![v(0., 0.), v(2., -h169), v(4., 0.), v(2., 3.)];
        let (c, _) = select_corners(&tri2, &CornerWeights::default()).unwrap();
        assert_eq!(c, [0, 1, 2, 3]);
    }

    #[test]
    fn one_critical_vertex_gets_two_points() {
        // 24°/78°/78° isosceles triangle with the tip at the origin
        let h = (12f64.to_radians()).tan();
        let ring = vec![v(0., 0.), v(1., -h), v(1., h)];
        let (pts, origin, c) = triangle_rule(&ring, 40f64.to_radians(), 0.25, &|_| true).unwrap();
        assert_eq!(pts.len(), 5);
        assert_eq!(origin.iter().filter(|o| o.is_some()).count(), 2);
        // corners: the two base vertices and two points at equal distance from the tip
        let d: Vec<f64> = c.iter().map(|&i| pts[i].distance(v(0., 0.))).collect();
        assert!(!c.contains(&0));
        let inserted: Vec<f64> = d.iter().copied().filter(|x| *x < 0.9).collect();
        assert_eq!(inserted.len(), 2);
        assert!((inserted[0] - inserted[1]).abs() < 1e-12);
    }
}
