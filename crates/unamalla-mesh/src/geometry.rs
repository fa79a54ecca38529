//! Exact geometric predicates and small geometric helpers.
//!
//! Orientation tests use Shewchuk's adaptive-precision `orient2d` from the `robust` crate, so the
//! answers (left / right / collinear) are exact for any `f64` input. Everything that decides
//! topology — ring simplicity, ring disjointness, "does this cut lie inside the region" — is
//! built on these predicates.

use glam::DVec2;
use robust::Coord;

/// Twice the signed area of triangle `abc`, computed exactly in sign (Shewchuk's `orient2d`):
/// positive if `a, b, c` turn counter-clockwise, negative if clockwise, exactly `0.0` iff the
/// three points are collinear. The magnitude equals `det(b − a, c − a)` up to rounding.
#[inline]
pub fn orient2d(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    robust::orient2d(
        Coord { x: a.x, y: a.y },
        Coord { x: b.x, y: b.y },
        Coord { x: c.x, y: c.y },
    )
}

/// The doubled signed area α(P, Q, R) = det(Q − P, R − P) ([González Flores, (2.68)]), in plain
/// floating point (use [`orient2d`] when only the sign matters and must be exact).
#[inline]
pub fn doubled_signed_area(p: DVec2, q: DVec2, r: DVec2) -> f64 {
    (q - p).perp_dot(r - p)
}

/// `true` if `p`, known to be collinear with segment `ab`, lies on the closed segment `ab`.
#[inline]
fn collinear_on_segment(a: DVec2, b: DVec2, p: DVec2) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

/// `true` if `p` lies on the closed segment `ab` (exact).
pub fn point_on_segment(a: DVec2, b: DVec2, p: DVec2) -> bool {
    orient2d(a, b, p) == 0.0 && collinear_on_segment(a, b, p)
}

/// `true` if the closed segments `p1p2` and `q1q2` share at least one point (exact; touching and
/// collinear overlap count).
pub fn segments_intersect(p1: DVec2, p2: DVec2, q1: DVec2, q2: DVec2) -> bool {
    let d1 = orient2d(q1, q2, p1);
    let d2 = orient2d(q1, q2, p2);
    let d3 = orient2d(p1, p2, q1);
    let d4 = orient2d(p1, p2, q2);
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && collinear_on_segment(q1, q2, p1))
        || (d2 == 0.0 && collinear_on_segment(q1, q2, p2))
        || (d3 == 0.0 && collinear_on_segment(p1, p2, q1))
        || (d4 == 0.0 && collinear_on_segment(p1, p2, q2))
}

/// `true` if the **open** segment `(p, q)` meets the closed segment `ab` — i.e. they intersect at
/// a point other than `p` or `q` (exact). This is the test a cut `pq` must pass against every
/// boundary edge: touching the boundary at its own endpoints is allowed, anything else is not.
pub fn open_segment_hits(p: DVec2, q: DVec2, a: DVec2, b: DVec2) -> bool {
    let da = orient2d(p, q, a);
    let db = orient2d(p, q, b);
    if da == 0.0 && db == 0.0 {
        // Collinear: compare parameter intervals along pq.
        let d = q - p;
        let len2 = d.length_squared();
        if len2 == 0.0 {
            return false;
        }
        let ta = (a - p).dot(d) / len2;
        let tb = (b - p).dot(d) / len2;
        let lo = ta.min(tb).max(0.0);
        let hi = ta.max(tb).min(1.0);
        return hi > lo || (hi == lo && lo > 0.0 && lo < 1.0);
    }
    let strictly_inside_pq = |x: DVec2| collinear_on_segment(p, q, x) && x != p && x != q;
    if (da == 0.0 && strictly_inside_pq(a)) || (db == 0.0 && strictly_inside_pq(b)) {
        return true;
    }
    let dp = orient2d(a, b, p);
    let dq = orient2d(a, b, q);
    ((da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0))
        && ((dp > 0.0 && dq < 0.0) || (dp < 0.0 && dq > 0.0))
}

/// Euclidean distance from `p` to the closed segment `ab`.
pub fn point_segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let len2 = d.length_squared();
    if len2 == 0.0 {
        return p.distance(a);
    }
    let t = ((p - a).dot(d) / len2).clamp(0.0, 1.0);
    p.distance(a + t * d)
}

/// Convex hull of a point set (Andrew's monotone chain with exact orientation), counter-clockwise,
/// starting at the lowest-then-leftmost point, without collinear points. Returns indices into
/// `points`. Fewer than 3 non-collinear points give the extreme points only.
pub fn convex_hull(points: &[DVec2]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..points.len()).collect();
    idx.sort_by(|&a, &b| {
        let (p, q) = (points[a], points[b]);
        p.x.total_cmp(&q.x).then(p.y.total_cmp(&q.y))
    });
    idx.dedup_by(|a, b| points[*a] == points[*b]);
    if idx.len() < 3 {
        return idx;
    }
    hull_of_sorted(points, &idx)
}

/// The two chains of Andrew's monotone chain and the rotation of [`convex_hull`], from `idx`:
/// indices of pairwise different points of `points` sorted by `x`, then `y` (for instance
/// after a sort and removal of equal points, as `convex_hull` does). Counter-clockwise,
/// starting at the lowest-then-leftmost point, without collinear points (exact orientation).
/// For callers that keep the sorted order of a point set and update it instead of sorting
/// again.
pub fn hull_of_sorted(points: &[DVec2], idx: &[usize]) -> Vec<usize> {
    if idx.len() < 3 {
        return idx.to_vec();
    }
    let mut hull: Vec<usize> = Vec::with_capacity(idx.len() * 2);
    for pass in 0..2 {
        let start = hull.len();
        for k in 0..idx.len() {
            let i = if pass == 0 {
                idx[k]
            } else {
                idx[idx.len() - 1 - k]
            };
            while hull.len() >= start + 2 {
                let (a, b) = (hull[hull.len() - 2], hull[hull.len() - 1]);
                if orient2d(points[a], points[b], points[i]) <= 0.0 {
                    hull.pop();
                } else {
                    break;
                }
            }
            hull.push(i);
        }
        hull.pop();
    }
    // rotate to start at the lowest-then-leftmost point
    if let Some(k) = (0..hull.len()).min_by(|&a, &b| {
        let (p, q) = (points[hull[a]], points[hull[b]]);
        p.y.total_cmp(&q.y).then(p.x.total_cmp(&q.x))
    }) {
        hull.rotate_left(k);
    }
    hull
}

/// Where a point lies with respect to a closed ring.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// Strictly inside.
    Inside,
    /// On an edge or vertex.
    OnBoundary,
    /// Strictly outside.
    Outside,
}

/// Locates `p` with respect to the closed polygon `ring` (either orientation), exactly, by the
/// winding number with exact orientation tests. O(n).
pub fn locate_in_ring(ring: &[DVec2], p: DVec2) -> Location {
    let n = ring.len();
    let mut winding = 0i64;
    for k in 0..n {
        let a = ring[k];
        let b = ring[(k + 1) % n];
        let o = orient2d(a, b, p);
        if o == 0.0 && collinear_on_segment(a, b, p) {
            return Location::OnBoundary;
        }
        if a.y <= p.y {
            if b.y > p.y && o > 0.0 {
                winding += 1;
            }
        } else if b.y <= p.y && o < 0.0 {
            winding -= 1;
        }
    }
    if winding != 0 {
        Location::Inside
    } else {
        Location::Outside
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn orientation_is_exact_on_near_collinear_points() {
        // Classic failure case of naive arithmetic: points on a line with tiny offsets.
        let a = v(0.5, 0.5);
        let b = v(12.0, 12.0);
        let c = v(24.0, 24.0);
        assert_eq!(orient2d(a, b, c), 0.0);
        let c2 = v(24.0, 24.0 + 1e-14);
        assert!(orient2d(a, b, c2) > 0.0);
    }

    #[test]
    fn segment_intersection_cases() {
        assert!(segments_intersect(
            v(0., 0.),
            v(2., 2.),
            v(0., 2.),
            v(2., 0.)
        ));
        assert!(segments_intersect(
            v(0., 0.),
            v(2., 0.),
            v(1., 0.),
            v(1., 5.)
        )); // T touch
        assert!(segments_intersect(
            v(0., 0.),
            v(2., 0.),
            v(1., 0.),
            v(3., 0.)
        )); // overlap
        assert!(!segments_intersect(
            v(0., 0.),
            v(2., 0.),
            v(3., 0.),
            v(4., 0.)
        ));
        assert!(!segments_intersect(
            v(0., 0.),
            v(2., 0.),
            v(0., 1.),
            v(2., 1.)
        ));
    }

    #[test]
    fn open_segment_rules() {
        // touching at its own endpoint is allowed
        assert!(!open_segment_hits(
            v(0., 0.),
            v(2., 0.),
            v(2., 0.),
            v(2., 3.)
        ));
        // passing through a boundary vertex is not
        assert!(open_segment_hits(
            v(0., 0.),
            v(2., 0.),
            v(1., 0.),
            v(1., 3.)
        ));
        // proper crossing
        assert!(open_segment_hits(
            v(0., 0.),
            v(2., 0.),
            v(1., -1.),
            v(1., 1.)
        ));
        // collinear overlap
        assert!(open_segment_hits(
            v(0., 0.),
            v(2., 0.),
            v(1., 0.),
            v(5., 0.)
        ));
        // collinear, touching only at q
        assert!(!open_segment_hits(
            v(0., 0.),
            v(2., 0.),
            v(2., 0.),
            v(5., 0.)
        ));
        // edge through p (p lies on edge interior) is allowed
        assert!(!open_segment_hits(
            v(0., 0.),
            v(2., 0.),
            v(0., -1.),
            v(0., 1.)
        ));
    }

    #[test]
    fn hull_of_square_with_inner_points() {
        let pts = vec![
            v(0., 0.),
            v(1., 0.),
            v(0.5, 0.5),
            v(1., 1.),
            v(0., 1.),
            v(0.5, 0.),
        ];
        assert_eq!(convex_hull(&pts), vec![0, 1, 3, 4]);
    }

    #[test]
    fn locate_points() {
        let sq = [v(0., 0.), v(1., 0.), v(1., 1.), v(0., 1.)];
        assert_eq!(locate_in_ring(&sq, v(0.5, 0.5)), Location::Inside);
        assert_eq!(locate_in_ring(&sq, v(1.0, 0.5)), Location::OnBoundary);
        assert_eq!(locate_in_ring(&sq, v(1.5, 0.5)), Location::Outside);
        let cw: Vec<_> = sq.iter().rev().copied().collect();
        assert_eq!(locate_in_ring(&cw, v(0.5, 0.5)), Location::Inside);
    }

    #[test]
    fn distance_to_segment() {
        assert_eq!(point_segment_distance(v(1., 1.), v(0., 0.), v(2., 0.)), 1.0);
        assert_eq!(point_segment_distance(v(3., 0.), v(0., 0.), v(2., 0.)), 1.0);
    }
}
