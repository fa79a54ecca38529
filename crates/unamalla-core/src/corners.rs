//! Automatic corner choice for a roughly four-sided ring (seed 000 digest §4.2, thesis §5.1.1).
//!
//! The thesis's heuristic: four vertices that are neither (nearly) collinear points nor reflex
//! vertices, such that opposite sides have approximately equal length. We make it a small
//! optimization over candidate vertices (convex vertices with a left angle below
//! [`MAX_CORNER_ANGLE_DEG`]), minimizing
//!
//! ```text
//! score = Σ_pairs |L₁ − L₂| / (L₁ + L₂)            (balanced opposite sides)
//!       + ½ · Σ_corners |θ − 90°| / 90°             (corners close to right angles)
//!       + Σ_sides (1 − chord / arc length)          (sides that are not folded back on themselves)
//! ```
//!
//! where the first term compares bottom/top and right/left arc lengths. If more than
//! [`MAX_CANDIDATES`] vertices qualify, the sharpest ones (smallest angles) are kept, which is
//! where a person would put corners. The search is exhaustive over the candidates (O(c⁴) with
//! c ≤ 40, well under a second).

use unamalla_mesh::Polygon;

use crate::CoreError;

/// Vertices with a region-side angle above this (degrees) are never corners.
pub const MAX_CORNER_ANGLE_DEG: f64 = 165.0;
/// At most this many candidate vertices enter the exhaustive search.
pub const MAX_CANDIDATES: usize = 40;

/// The score of a corner quadruple (lower is better); see the module documentation.
pub fn corner_score(poly: &Polygon, corners: [usize; 4]) -> f64 {
    let pts = poly.points();
    let n = pts.len();
    let mut arc = [0.0; 4];
    let mut chord = [0.0; 4];
    for s in 0..4 {
        let (a, b) = (corners[s], corners[(s + 1) % 4]);
        let mut k = a;
        while k != b {
            let k2 = (k + 1) % n;
            arc[s] += pts[k].distance(pts[k2]);
            k = k2;
        }
        chord[s] = pts[a].distance(pts[b]);
    }
    let balance = |x: f64, y: f64| {
        if x + y > 0.0 {
            (x - y).abs() / (x + y)
        } else {
            1.0
        }
    };
    let mut score = balance(arc[0], arc[2]) + balance(arc[1], arc[3]);
    for &c in &corners {
        score += 0.5 * (poly.left_angle(c).to_degrees() - 90.0).abs() / 90.0;
    }
    for s in 0..4 {
        if arc[s] > 0.0 {
            score += 1.0 - chord[s] / arc[s];
        }
    }
    score
}

/// Chooses four corners of `poly` (indices into its points, counter-clockwise order). When
/// `aspect` (the wanted ratio bottom-side length / left-side length, e.g. `(M−1)/(N−1)` for an
/// `M × N` grid) is given, the quadruple is rotated so that the bottom/top pair best matches it.
///
/// Errors: fewer than four admissible (convex, non-flat) vertices.
pub fn auto_corners(poly: &Polygon, aspect: Option<f64>) -> Result<[usize; 4], CoreError> {
    let n = poly.len();
    let mut cand: Vec<(usize, f64)> = (0..n)
        .map(|i| (i, poly.left_angle(i).to_degrees()))
        .filter(|&(_, a)| a < MAX_CORNER_ANGLE_DEG)
        .collect();
    if cand.len() < 4 {
        return Err(CoreError::Corners(format!(
            "only {} vertices with an angle below {MAX_CORNER_ANGLE_DEG}°; four corners are needed",
            cand.len()
        )));
    }
    if cand.len() > MAX_CANDIDATES {
        cand.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        cand.truncate(MAX_CANDIDATES);
    }
    let mut idx: Vec<usize> = cand.iter().map(|c| c.0).collect();
    idx.sort_unstable();
    let c = idx.len();
    let mut best: Option<(f64, [usize; 4])> = None;
    for a in 0..c {
        for b in a + 1..c {
            for d in b + 1..c {
                for e in d + 1..c {
                    let q = [idx[a], idx[b], idx[d], idx[e]];
                    let s = corner_score(poly, q);
                    if best.is_none_or(|(bs, _)| s < bs) {
                        best = Some((s, q));
                    }
                }
            }
        }
    }
    let Some((_, mut q)) = best else {
        return Err(CoreError::Corners("no corner quadruple found".into()));
    };
    if let Some(aspect) = aspect.filter(|a| a.is_finite() && *a > 0.0) {
        let pts = poly.points();
        let arc = |a: usize, b: usize| {
            let mut s = 0.0;
            let mut k = a;
            while k != b {
                let k2 = (k + 1) % n;
                s += pts[k].distance(pts[k2]);
                k = k2;
            }
            s
        };
        let l: Vec<f64> = (0..4).map(|s| arc(q[s], q[(s + 1) % 4])).collect();
        let ratio0 = (l[0] + l[2]) / (l[1] + l[3]);
        // rotating by one swaps the roles of the two side pairs
        if (ratio0.ln() - aspect.ln()).abs() > ((1.0 / ratio0).ln() - aspect.ln()).abs() {
            q.rotate_left(1);
        }
    }
    Ok(q)
}

#[cfg(test)]
mod tests {
    use unamalla_mesh::DVec2;

    use super::*;

    #[test]
    fn rectangle_with_extra_points_gets_its_four_corners() {
        // 6 × 2 rectangle with collinear points on every side; starting vertex mid-side
        let pts = vec![
            DVec2::new(3., 0.),
            DVec2::new(6., 0.),
            DVec2::new(6., 1.),
            DVec2::new(6., 2.),
            DVec2::new(2., 2.),
            DVec2::new(0., 2.),
            DVec2::new(0., 0.),
            DVec2::new(1., 0.),
        ];
        let poly = Polygon::new(pts).unwrap();
        let mut q = auto_corners(&poly, None).unwrap();
        q.sort_unstable();
        assert_eq!(q, [1, 3, 5, 6]);
        // aspect 3: the long sides (length 6) must be bottom/top
        let q = auto_corners(&poly, Some(3.0)).unwrap();
        let p = poly.points();
        assert_eq!((p[q[1]] - p[q[0]]).length(), 6.0);
        // aspect 1/3: the long sides become left/right
        let q = auto_corners(&poly, Some(1.0 / 3.0)).unwrap();
        assert_eq!((p[q[1]] - p[q[0]]).length(), 2.0);
    }

    #[test]
    fn triangle_has_no_four_corners() {
        let poly = Polygon::new(vec![DVec2::ZERO, DVec2::X, DVec2::Y]).unwrap();
        assert!(matches!(
            auto_corners(&poly, None),
            Err(CoreError::Corners(_))
        ));
    }

    #[test]
    fn reflex_vertex_is_never_a_corner() {
        // an L-shape: its reflex vertex (2) must not be chosen
        let poly = Polygon::new(vec![
            DVec2::new(0., 0.),
            DVec2::new(4., 0.),
            DVec2::new(4., 1.),
            DVec2::new(1., 1.),
            DVec2::new(1., 4.),
            DVec2::new(0., 4.),
        ])
        .unwrap();
        let q = auto_corners(&poly, None).unwrap();
        assert!(!q.contains(&3));
        for &c in &q {
            assert!(!poly.is_reflex(c));
        }
    }
}
