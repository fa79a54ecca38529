//! The thesis's own corner heuristic, selectable beside the scoring of [`crate::corners`]:
//! [Méndez 2023, §5.1.1] (the references are listed in `docs/references.md` of the repository) —
//! choose four vertices that are neither (nearly) collinear nor reflex with opposite sides of about
//! equal length, implemented as "two diametrically opposite points of the convex hull and two more
//! on the hull boundary so that opposite sides have the desired length ratio".
//!
//! Here, with the same candidate vertices as the scoring (interior angle below θ_max, or below
//! θ_lim when fewer than four qualify):
//!
//! 1. `H` = the candidates that are vertices of the convex hull of the ring
//!    ([`unamalla_mesh::geometry::convex_hull`], exact orientation);
//! 2. the **diametral pair** `p, q` = the two vertices of `H` farthest apart;
//! 3. on each of the two boundary chains `p → q` and `q → p` one more corner, from `H` if the
//!    chain has a hull candidate and from all candidates otherwise, the pair `(a, b)` that
//!    minimizes the opposite-side imbalance `½(|L₀ − L₂|/(L₀ + L₂) + |L₁ − L₃|/(L₁ + L₃))`
//!    (the "desired ratio" is 1; ties by the angle penalty, then by coordinates).
//!
//! The thesis does not say what to do when the hull has fewer than two candidates or a chain
//! has none (a ring whose hull vertices are all nearly flat); then this falls back to the
//! scoring selection, so a block gets corners whenever the scoring would give it some. The
//! returned value is the corner score F of [`crate::corners`] of the chosen tuple, so callers
//! can compare both choices on the same scale.

use std::f64::consts::PI;

use unamalla_mesh::geometry::convex_hull;
use unamalla_mesh::DVec2;

use crate::corners::{select_corners, CornerWeights};
use crate::geom::{angle_penalty, ring_angle};

/// How [`select_corners`] chooses the four corners of a block.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum CornerChoice {
    /// Exhaustive search of the corner score F over the best candidates (module
    /// [`crate::corners`]).
    #[default]
    Scoring,
    /// The thesis's convex-hull diametral heuristic (this module, [Méndez 2023, §5.1.1]).
    Diametral,
}

/// The corner score F of [`crate::corners`] for the ascending tuple `c`.
fn score(ring: &[DVec2], angles: &[f64], c: [usize; 4], w: &CornerWeights) -> f64 {
    let n = ring.len();
    let mut l = [0.0; 4];
    let mut t = [0.0; 4];
    for k in 0..4 {
        let (a, b) = (c[k], c[(k + 1) % 4]);
        let mut i = a;
        while i != b {
            l[k] += ring[i].distance(ring[(i + 1) % n]);
            i = (i + 1) % n;
            if i != b {
                t[k] += PI - angles[i];
            }
        }
    }
    let ang: f64 = c.iter().map(|&v| angle_penalty(angles[v])).sum::<f64>() / 4.0;
    let tr: f64 = t.iter().map(|x| (x / (PI / 2.0)).powi(2)).sum::<f64>() / 4.0;
    ang + w.balance * imbalance(&l) + w.turn * tr
}

/// `½(|L₀ − L₂|/(L₀ + L₂) + |L₁ − L₃|/(L₁ + L₃))`.
fn imbalance(l: &[f64; 4]) -> f64 {
    0.5 * ((l[0] - l[2]).abs() / (l[0] + l[2]).max(1e-300)
        + (l[1] - l[3]).abs() / (l[1] + l[3]).max(1e-300))
}

/// The diametral choice (module docs): the four corners in ascending ring order and their
/// score F, or the scoring selection's result when the heuristic has no hull candidates to
/// work with; `None` when the ring has fewer than four vertices below θ_lim.
pub(crate) fn select_diametral(ring: &[DVec2], w: &CornerWeights) -> Option<([usize; 4], f64)> {
    let scoring = CornerWeights {
        choice: CornerChoice::Scoring,
        ..*w
    };
    let n = ring.len();
    if n < 4 {
        return None;
    }
    let angles: Vec<f64> = (0..n).map(|i| ring_angle(ring, i)).collect();
    let preferred = w.max_corner_angle.min(w.corner_angle_limit);
    let mut is_cand: Vec<bool> = angles.iter().map(|&a| a < preferred).collect();
    if is_cand.iter().filter(|&&c| c).count() < 4 {
        let limit = w.corner_angle_limit.min(PI);
        is_cand = angles.iter().map(|&a| a < limit).collect();
    }
    if is_cand.iter().filter(|&&c| c).count() < 4 {
        return None;
    }
    let mut on_hull = vec![false; n];
    for i in convex_hull(ring) {
        on_hull[i] = is_cand[i];
    }
    let h: Vec<usize> = (0..n).filter(|&i| on_hull[i]).collect();
    // 2. the diametral pair (ties: the lexicographically smallest coordinates)
    let key = |i: usize| (ring[i].x, ring[i].y);
    let mut best: Option<(usize, usize, f64)> = None;
    for (k, &i) in h.iter().enumerate() {
        for &j in &h[k + 1..] {
            let d = ring[i].distance_squared(ring[j]);
            let better = match best {
                None => true,
                Some((bi, bj, bd)) => d > bd || (d == bd && (key(i), key(j)) < (key(bi), key(bj))),
            };
            if better {
                best = Some((i, j, d));
            }
        }
    }
    let Some((p, q, _)) = best else {
        return select_corners(ring, &scoring);
    };
    // 3. one more corner on each chain p → q (exclusive) and q → p
    let chain = |from: usize, to: usize| -> Vec<usize> {
        let mut v = Vec::new();
        let mut i = (from + 1) % n;
        while i != to {
            v.push(i);
            i = (i + 1) % n;
        }
        let on: Vec<usize> = v.iter().copied().filter(|&i| on_hull[i]).collect();
        if on.is_empty() {
            v.into_iter().filter(|&i| is_cand[i]).collect()
        } else {
            on
        }
    };
    let (ca, cb) = (chain(p, q), chain(q, p));
    if ca.is_empty() || cb.is_empty() {
        return select_corners(ring, &scoring);
    }
    let mut arc = vec![0.0; n + 1];
    for i in 0..n {
        arc[i + 1] = arc[i] + ring[i].distance(ring[(i + 1) % n]);
    }
    let len = |a: usize, b: usize| {
        if a <= b {
            arc[b] - arc[a]
        } else {
            arc[n] - arc[a] + arc[b]
        }
    };
    // (corners, (imbalance, angle penalty, coordinates)): the lexicographic order is the choice
    type Pick = ([usize; 4], (f64, f64, [f64; 8]));
    let mut pick: Option<Pick> = None;
    for &a in &ca {
        for &b in &cb {
            // ring order p, a, q, b
            let l = [len(p, a), len(a, q), len(q, b), len(b, p)];
            let mut c = [p, a, q, b];
            c.sort_unstable();
            let pen: f64 = c.iter().map(|&v| angle_penalty(angles[v])).sum();
            let mut k = [0.0; 8];
            for (m, &v) in c.iter().enumerate() {
                k[2 * m] = ring[v].x;
                k[2 * m + 1] = ring[v].y;
            }
            let cand = (imbalance(&l), pen, k);
            let better = match &pick {
                None => true,
                Some((_, bk)) => cand.partial_cmp(bk) == Some(std::cmp::Ordering::Less),
            };
            if better {
                pick = Some((c, cand));
            }
        }
    }
    let (c, _) = pick?;
    Some((c, score(ring, &angles, c, w)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    /// A pentagon worked out by hand: (0,0), (4,0), (4.5,0.8), (4,2), (0,2).
    /// Edges 4, √0.89 = 0.9434, √1.69 = 1.3, 4, 2; angles (from the edge-vector cosines
    /// −0.53, −0.5789, −0.3846) 90°, 122.005°, 125.377°, 112.620°, 90°, so
    /// g = ((θ − 90°)/90°)² = 0, 0.12646, 0.15451, 0.06317, 0.
    fn pentagon() -> Vec<DVec2> {
        vec![
            v(0.0, 0.0),
            v(4.0, 0.0),
            v(4.5, 0.8),
            v(4.0, 2.0),
            v(0.0, 2.0),
        ]
    }

    #[test]
    fn diametral_corners_of_the_pentagon_by_hand() {
        // hull = all five; farthest pair: (0,2)–(4.5,0.8), √21.69 = 4.657 (> (0,0)–(4.5,0.8),
        // √20.89, and (0,0)–(4,2), √20). Chains: 2 → 4 = {3}; 4 → 2 = {0, 1}.
        // b = 0: L = (4.9434, 1.3, 4, 2), imbalance ½(0.9434/8.9434 + 0.7/3.3) = 0.1588;
        // b = 1: L = (0.9434, 1.3, 4, 6), imbalance ½(3.0566/4.9434 + 4.7/7.3) = 0.6311.
        let w = CornerWeights {
            choice: CornerChoice::Diametral,
            ..CornerWeights::default()
        };
        let (c, f) = select_corners(&pentagon(), &w).unwrap();
        assert_eq!(c, [0, 2, 3, 4]);
        // F = (0 + 0.15451 + 0.06317 + 0)/4 = 0.05442 + ½·0.15880 + turning of vertex 1 on
        // side 0 (π − 122.005° = 1.01220 rad: (1.01220/(π/2))²/4 = 0.10381) = 0.23763
        assert!((f - 0.23763).abs() < 1e-4, "{f}");
    }

    #[test]
    fn scoring_corners_of_the_same_pentagon_by_hand() {
        // the scoring puts the 125.4° vertex inside a side instead: [0,1,3,4] has
        // g mean (0 + 0.12646 + 0.06317 + 0)/4 = 0.04741, imbalance ½(0 + 0.2434/4.2434) =
        // 0.02868 (× ½), turning (0.95335/(π/2))²/4 = 0.09209: F = 0.15384, the smallest of the
        // five tuples (the others: 0.2376, 0.3351, 0.6455, 0.6515)
        let (c, f) = select_corners(&pentagon(), &CornerWeights::default()).unwrap();
        assert_eq!(c, [0, 1, 3, 4]);
        assert!((f - 0.15384).abs() < 1e-4, "{f}");
    }

    #[test]
    fn falls_back_to_the_scoring_without_hull_candidates() {
        // a ring with fewer than four candidates (one reflex vertex, three convex) gives
        // the same answer (None) with both choices
        let tri = vec![v(0.0, 0.0), v(1.0, 0.0), v(0.5, 1.0), v(0.5, 0.5)];
        let w = CornerWeights {
            choice: CornerChoice::Diametral,
            ..CornerWeights::default()
        };
        assert_eq!(
            select_corners(&tri, &w),
            select_corners(&tri, &CornerWeights::default())
        );
    }
}
