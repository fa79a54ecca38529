//! Small geometric helpers shared by the decomposition modules (exact predicates come from
//! `unamalla_mesh::geometry`).

use std::f64::consts::{PI, TAU};

use unamalla_mesh::geometry::orient2d;
use unamalla_mesh::DVec2;

/// Counter-clockwise angle from direction `u` to direction `v`, in `(0, 2π]`.
pub(crate) fn ccw_angle(u: DVec2, v: DVec2) -> f64 {
    let a = u.perp_dot(v).atan2(u.dot(v));
    if a <= 0.0 {
        a + TAU
    } else {
        a
    }
}

/// Angle at `cur` on the left of the directed chain `prev → cur → next`, in `(0, 2π]`.
pub(crate) fn left_angle(prev: DVec2, cur: DVec2, next: DVec2) -> f64 {
    ccw_angle(next - cur, prev - cur)
}

/// Left angle at vertex `i` of an open ring.
pub(crate) fn ring_angle(ring: &[DVec2], i: usize) -> f64 {
    let n = ring.len();
    left_angle(ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n])
}

/// The left angles of all vertices of an open ring (`ring_angle` for each, in order): computed
/// once and handed to the functions that would otherwise recompute them vertex by vertex.
pub(crate) fn ring_angles(ring: &[DVec2]) -> Vec<f64> {
    (0..ring.len()).map(|i| ring_angle(ring, i)).collect()
}

/// For each vertex of `ring` (expected to follow `src` from index `start` on, with points
/// inserted or left out: a child of a split), the index of the vertex of `src` it matches —
/// walking both in order, a vertex matches the next `src` vertex when their coordinates are
/// the same bit for bit — or `usize::MAX`.
pub(crate) fn match_vertices(ring: &[DVec2], src: &[DVec2], start: usize) -> Vec<usize> {
    let m = src.len();
    if m == 0 {
        return vec![usize::MAX; ring.len()];
    }
    let mut s = start % m;
    ring.iter()
        .map(|&p| {
            if same_point(src[s], p) {
                let k = s;
                s = (s + 1) % m;
                k
            } else {
                usize::MAX
            }
        })
        .collect()
}

/// Whether two points have the same coordinates bit for bit.
fn same_point(a: DVec2, b: DVec2) -> bool {
    a.x.to_bits() == b.x.to_bits() && a.y.to_bits() == b.y.to_bits()
}

/// [`ring_angles`] of `ring`, taken from `src_angles` (the [`ring_angles`] of `src`) at every
/// vertex whose predecessor, point and successor are bit for bit those of a vertex of `src`
/// (then `ring_angle` would repeat the same computation on the same numbers) and computed
/// elsewhere. `map` is the match of `ring`'s vertices in `src` ([`match_vertices`]); each
/// vertex's neighbours are checked, so any match gives the exact result, a good one (a
/// child of a split, matched from where it starts in `src`) just reuses more angles.
pub(crate) fn ring_angles_matched(
    ring: &[DVec2],
    src: &[DVec2],
    src_angles: &[f64],
    map: &[usize],
) -> Vec<f64> {
    let (n, m) = (ring.len(), src.len());
    if m == 0 || src_angles.len() != m {
        return ring_angles(ring);
    }
    (0..n)
        .map(|k| {
            let j = map[k];
            let reuse = j != usize::MAX
                && same_point(src[(j + m - 1) % m], ring[(k + n - 1) % n])
                && same_point(src[(j + 1) % m], ring[(k + 1) % n]);
            if reuse {
                src_angles[j]
            } else {
                ring_angle(ring, k)
            }
        })
        .collect()
}

/// `true` if the point `x` lies strictly inside the open wedge on the left of the chain
/// `prev → cur → next` (the region side at `cur`). Exact.
pub(crate) fn in_wedge(prev: DVec2, cur: DVec2, next: DVec2, x: DVec2) -> bool {
    let turn = orient2d(prev, cur, next);
    let a = orient2d(cur, next, x);
    let b = orient2d(cur, prev, x);
    if turn > 0.0 {
        a > 0.0 && b < 0.0
    } else if turn < 0.0 {
        a > 0.0 || b < 0.0
    } else if (next - cur).dot(prev - cur) < 0.0 {
        a > 0.0
    } else {
        // zero-width spike: the left side is everything but the ray itself
        a != 0.0 || (x - cur).dot(next - cur) < 0.0
    }
}

/// [`unamalla_mesh::geometry::convex_hull`] (Andrew's monotone chain with the exact
/// `orient2d`: counter-clockwise hull indices from the lowest-then-leftmost point, no
/// collinear points, the lowest index of equal points), computed the same way with a
/// faster sort.
///
/// The same result: that function sorts the indices stably by `x`, then `y` (each by
/// `total_cmp`), so equal coordinates stay in index order; here the triples (`x` key, `y`
/// key, index) are sorted, with keys that order as `total_cmp` does — the same sequence,
/// without the indirect reads and the stable sort's buffer. The removal of equal points
/// (`==`, as there), the two chains and the rotation are the same steps on the same values.
pub(crate) fn convex_hull(points: &[DVec2]) -> Vec<usize> {
    convex_hull_distinct(points).0
}

/// A point's place in the sort of [`convex_hull`]: the keys of its `x` and `y` (ordering as
/// `f64::total_cmp` does) and its index.
pub(crate) type HullKey = (u64, u64, usize);

/// The key of `v` that orders as `f64::total_cmp` (the bits with the magnitude flipped for
/// negative numbers, compared as i64), shifted to compare as u64.
pub(crate) fn total_key(v: f64) -> u64 {
    let b = v.to_bits() as i64;
    ((b ^ (((b >> 63) as u64) >> 1) as i64) as u64) ^ (1 << 63)
}

/// The [`HullKey`]s of `points` in ascending order: the order in which the mesh crate's
/// stable sort (by `x`, then `y`, equal points in index order) leaves them.
pub(crate) fn hull_order(points: &[DVec2]) -> Vec<HullKey> {
    let mut keyed: Vec<HullKey> = points
        .iter()
        .enumerate()
        .map(|(i, p)| (total_key(p.x), total_key(p.y), i))
        .collect();
    keyed.sort_unstable();
    keyed
}

/// [`convex_hull`], and whether the points are pairwise different (`!=`).
pub(crate) fn convex_hull_distinct(points: &[DVec2]) -> (Vec<usize>, bool) {
    hull_from_order(points, &hull_order(points))
}

/// [`convex_hull_distinct`] from the points' [`hull_order`]: the removal of equal points,
/// the two chains and the rotation of the mesh crate's function.
pub(crate) fn hull_from_order(points: &[DVec2], order: &[HullKey]) -> (Vec<usize>, bool) {
    let mut idx: Vec<usize> = Vec::with_capacity(order.len());
    for &(_, _, i) in order {
        if idx.last().is_none_or(|&l| points[l] != points[i]) {
            idx.push(i);
        }
    }
    let distinct = idx.len() == points.len();
    if idx.len() < 3 {
        return (idx, distinct);
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
    (hull, distinct)
}

/// The [`hull_order`] of `child` from the hull order `parent_order` of `parent` (whose
/// `parent_len` points must be pairwise different), with `map` from [`match_vertices`]: the
/// matched vertices in the parent's order, under their child indices, merged with the other
/// child points in theirs. `None` if `map` matches a parent vertex twice.
///
/// The same sequence in O(parent + child) instead of a sort: a matched vertex has its parent
/// vertex's coordinates bit for bit, so its keys; the parent's keys are all different, so
/// the parent's order is the order of the matched vertices' keys whatever their indices, and
/// merging with the sorted others on whole keys gives the ascending order of all of them.
pub(crate) fn child_hull_order(
    parent_order: &[HullKey],
    parent_len: usize,
    child: &[DVec2],
    map: &[usize],
) -> Option<Vec<HullKey>> {
    // the child index of each parent vertex
    let mut at = vec![usize::MAX; parent_len];
    for (k, &j) in map.iter().enumerate() {
        if j != usize::MAX {
            if at[j] != usize::MAX {
                return None;
            }
            at[j] = k;
        }
    }
    let mut others: Vec<HullKey> = map
        .iter()
        .zip(child)
        .enumerate()
        .filter(|(_, (&j, _))| j == usize::MAX)
        .map(|(k, (_, p))| (total_key(p.x), total_key(p.y), k))
        .collect();
    others.sort_unstable();
    let mut others = others.into_iter().peekable();
    let mut out = Vec::with_capacity(child.len());
    for &(kx, ky, j) in parent_order {
        if at[j] == usize::MAX {
            continue;
        }
        let item = (kx, ky, at[j]);
        while let Some(o) = others.next_if(|&o| o < item) {
            out.push(o);
        }
        out.push(item);
    }
    out.extend(others);
    Some(out)
}

/// The [`convex_hull`] of `child`, from the hull `parent_hull` of `parent` it was cut from
/// (`map` from [`match_vertices`]), where that is certain: `parent`'s points are pairwise
/// different (`!=`, the caller's to know), the parent hull vertices among `child`'s (at least
/// three) are all of them or all but one run of the hull cycle, between `a` and `b`, and
/// each of `child`'s points not matched to `parent` differs from its other points. `None`
/// otherwise.
///
/// Why: the hull of the kept parent hull vertices is the parent hull cut by the chord from
/// `a` to `b` (its side away from the left-out run). A matched child point is a parent
/// point, so inside or on the parent hull; unless it is strictly beyond the chord it is in
/// that cut hull, and then it is no hull vertex of `child` (no other child point equals it,
/// the parent's points being different and the others checked). So the hull of `child` is
/// the hull of the kept vertices, the matched points beyond the chord and the unmatched
/// points, with the same lowest index for equal points: the monotone chain on those alone.
pub(crate) fn child_hull(
    parent: &[DVec2],
    parent_hull: &[usize],
    child: &[DVec2],
    map: &[usize],
) -> Option<Vec<usize>> {
    let h = parent_hull.len();
    if h < 3 {
        return None;
    }
    // the child index of each parent vertex
    let mut at = vec![usize::MAX; parent.len()];
    for (k, &j) in map.iter().enumerate() {
        if j != usize::MAX {
            if at[j] != usize::MAX {
                return None;
            }
            at[j] = k;
        }
    }
    let kept: Vec<bool> = parent_hull.iter().map(|&j| at[j] != usize::MAX).collect();
    if kept.iter().filter(|&&k| k).count() < 3 {
        return None;
    }
    // the chord over the left-out run: from its last kept vertex before to the first after
    let ends: Vec<usize> = (0..h).filter(|&i| kept[i] && !kept[(i + 1) % h]).collect();
    let beyond: Box<dyn Fn(DVec2) -> bool> = match ends[..] {
        [] => Box::new(|_| false),
        [i] => {
            let a = parent[parent_hull[i]];
            let next_kept = (1..h).map(|d| (i + d) % h).find(|&l| kept[l]);
            let b = parent[parent_hull[next_kept?]];
            Box::new(move |p| orient2d(a, b, p) < 0.0)
        }
        _ => return None,
    };
    let mut on_hull = vec![false; parent.len()];
    for &j in parent_hull {
        on_hull[j] = true;
    }
    let mut points: Vec<usize> = parent_hull
        .iter()
        .filter_map(|&j| (at[j] != usize::MAX).then_some(at[j]))
        .collect();
    for (k, (&j, &p)) in map.iter().zip(child).enumerate() {
        if j == usize::MAX {
            let repeated = child.iter().enumerate().any(|(l, &q)| l != k && q == p);
            if repeated {
                return None;
            }
            points.push(k);
        } else if !on_hull[j] && beyond(p) {
            points.push(k);
        }
    }
    let mut keys: Vec<HullKey> = points
        .iter()
        .map(|&k| (total_key(child[k].x), total_key(child[k].y), k))
        .collect();
    keys.sort_unstable();
    Some(hull_from_order(child, &keys).0)
}

/// Calls `visit` on the elements of `items` in ascending `cmp` order until it returns
/// `false`, sorting only as far as the visits go: the next chunk of smallest elements is
/// found by selection and sorted (chunks of 64, then doubling). `cmp` must be a strict total
/// order (no two elements equal), so the sequence is the one a full sort would give.
pub(crate) fn visit_sorted<T>(
    items: &mut [T],
    cmp: impl Fn(&T, &T) -> std::cmp::Ordering,
    mut visit: impl FnMut(&T) -> bool,
) {
    let (mut start, mut chunk) = (0, 64);
    while start < items.len() {
        let rest = &mut items[start..];
        let c = chunk.min(rest.len());
        if c < rest.len() {
            // the c smallest first, in some order
            rest.select_nth_unstable_by(c - 1, &cmp);
        }
        rest[..c].sort_unstable_by(&cmp);
        for x in &rest[..c] {
            if !visit(x) {
                return;
            }
        }
        start += c;
        chunk *= 2;
    }
}

/// Shoelace signed area (positive for counter-clockwise rings).
pub(crate) fn signed_area(ring: &[DVec2]) -> f64 {
    unamalla_mesh::region::signed_area(ring)
}

/// Perimeter of an open ring.
pub(crate) fn perimeter(ring: &[DVec2]) -> f64 {
    let n = ring.len();
    (0..n).map(|k| ring[k].distance(ring[(k + 1) % n])).sum()
}

/// Area centroid of a simple ring (falls back to the vertex mean for degenerate rings).
pub(crate) fn centroid(ring: &[DVec2]) -> DVec2 {
    let n = ring.len();
    let mut a = 0.0;
    let mut c = DVec2::ZERO;
    for k in 0..n {
        let p = ring[k];
        let q = ring[(k + 1) % n];
        let w = p.perp_dot(q);
        a += w;
        c += (p + q) * w;
    }
    if a.abs() < 1e-300 {
        ring.iter().copied().sum::<DVec2>() / n.max(1) as f64
    } else {
        c / (3.0 * a)
    }
}

/// Penalty of an angle `α` (radians) for a quadrilateral-like block: `((α − π/2)/(π/2))²` for
/// `α ≤ π` (0 at 90°, 1 at 0° and 180°), `1 + (α − π)/(π/2)` for reflex angles.
pub(crate) fn angle_penalty(alpha: f64) -> f64 {
    if alpha <= PI {
        let d = (alpha - PI / 2.0) / (PI / 2.0);
        d * d
    } else {
        1.0 + (alpha - PI) / (PI / 2.0)
    }
}

/// Diameter (largest vertex distance) of a point set given by indices.
pub(crate) fn diameter(points: &[DVec2], idx: &[usize]) -> f64 {
    let mut d2: f64 = 0.0;
    for (k, &i) in idx.iter().enumerate() {
        for &j in &idx[k + 1..] {
            d2 = d2.max(points[i].distance_squared(points[j]));
        }
    }
    d2.sqrt()
}

/// Parameter `t` of the orthogonal projection of `p` on the line `ab`.
pub(crate) fn project_t(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let l2 = d.length_squared();
    if l2 == 0.0 {
        0.0
    } else {
        (p - a).dot(d) / l2
    }
}

/// First intersection of the ray `o + s·d` (`s > 0`) with segment `ab`: `(s, t)`.
pub(crate) fn ray_segment(o: DVec2, d: DVec2, a: DVec2, b: DVec2) -> Option<(f64, f64)> {
    let e = b - a;
    let den = d.perp_dot(e);
    if den.abs() < 1e-300 {
        return None;
    }
    let w = a - o;
    let s = w.perp_dot(e) / den;
    let t = w.perp_dot(d) / den;
    if s > 0.0 && (0.0..=1.0).contains(&t) {
        Some((s, t))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wedge_convex_and_reflex() {
        let o = DVec2::ZERO;
        // chain (0,1) → o → (1,0) turns left: the region is the first quadrant (90°)
        let prev = DVec2::new(0.0, 1.0);
        let next = DVec2::new(1.0, 0.0);
        assert!(in_wedge(prev, o, next, DVec2::new(1.0, 1.0)));
        assert!(!in_wedge(prev, o, next, DVec2::new(-1.0, -1.0)));
        assert!(!in_wedge(prev, o, next, DVec2::new(1.0, 0.0)));
        // reversed chain: the reflex 270° side
        assert!(!in_wedge(next, o, prev, DVec2::new(1.0, 1.0)));
        assert!(in_wedge(next, o, prev, DVec2::new(-1.0, -1.0)));
        assert!(in_wedge(next, o, prev, DVec2::new(-1.0, 1.0)));
        assert!((left_angle(prev, o, next) - PI / 2.0).abs() < 1e-12);
        assert!((left_angle(next, o, prev) - 1.5 * PI).abs() < 1e-12);
    }

    /// `convex_hull` returns what `unamalla_mesh::geometry::convex_hull` returns: on
    /// pseudo-random point sets with repeated points, collinear runs, signed zeros and
    /// coordinates of both signs.
    #[test]
    fn hull_matches_the_mesh_crates() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for case in 0..400 {
            let n = 1 + (next() % 40) as usize;
            let grid = 1 + (case % 7) as u64;
            let mut pts: Vec<DVec2> = (0..n)
                .map(|_| {
                    let c = |r: u64| (r % (2 * grid + 1)) as f64 - grid as f64;
                    DVec2::new(c(next()), c(next()))
                })
                .collect();
            if case % 5 == 0 {
                // signed zeros and exact repeats
                pts.push(DVec2::new(-0.0, 0.0));
                pts.push(DVec2::new(0.0, -0.0));
                pts.push(pts[0]);
            }
            if case % 4 == 1 {
                // general positions
                pts.extend((0..50).map(|_| {
                    let c = |r: u64| (r as f64 / u64::MAX as f64 - 0.5) * 1e3;
                    DVec2::new(c(next()), c(next()))
                }));
            }
            if case % 3 == 0 {
                // a collinear run
                pts.extend((0..5).map(|k| DVec2::new(k as f64 * 0.5, 1.0 + k as f64 * 0.25)));
            }
            assert_eq!(
                convex_hull(&pts),
                unamalla_mesh::geometry::convex_hull(&pts),
                "{pts:?}"
            );
        }
    }

    /// Where `child_hull` answers, its hull is `convex_hull` of the child: children of
    /// pseudo-random star-shaped rings cut between two vertices, or from a vertex to a point
    /// inserted inside an edge, or with a point added anywhere.
    #[test]
    fn child_hulls_match_the_computed_ones() {
        let mut state = 0x1234_5678_9abc_def1u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut derived = 0;
        for _ in 0..2000 {
            let n = 5 + (next() * 40.0) as usize;
            let ring: Vec<DVec2> = (0..n)
                .map(|i| {
                    let t = std::f64::consts::TAU * (i as f64 + 0.5 * next()) / n as f64;
                    let r = 0.5 + next();
                    DVec2::new(r * t.cos(), r * t.sin())
                })
                .collect();
            let (hull, distinct) = convex_hull_distinct(&ring);
            assert!(distinct);
            let i = (next() * n as f64) as usize % n;
            // a child of any size, or one that leaves out a few vertices only (which keeps
            // the hull more often)
            let len = if next() < 0.5 {
                3 + (next() * (n - 3) as f64) as usize
            } else {
                n - 1 - (next() * 3.0) as usize
            };
            let mut child: Vec<DVec2> = (0..len).map(|k| ring[(i + k) % n]).collect();
            let extra = next();
            if extra < 0.4 {
                // the cut ends inside the edge after the child's last vertex
                let (a, b) = (ring[(i + len - 1) % n], ring[(i + len) % n]);
                child.push(a + next() * (b - a));
            } else if extra < 0.6 {
                // a point anywhere (inside or outside the ring's hull)
                child.push(DVec2::new(3.0 * next() - 1.5, 3.0 * next() - 1.5));
            }
            let map = match_vertices(&child, &ring, i);
            if let Some(h) = child_hull(&ring, &hull, &child, &map) {
                derived += 1;
                assert_eq!(h, convex_hull(&child), "{child:?}");
            }
        }
        assert!(derived > 1000, "{derived}");
    }

    /// `child_hull_order` gives the hull order a sort of the child gives, so the same hull.
    #[test]
    fn child_hull_orders_match_the_sorted_ones() {
        let mut state = 0x00dd_ba11_5eed_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..1000 {
            let n = 5 + (next() * 40.0) as usize;
            let ring: Vec<DVec2> = (0..n)
                .map(|i| {
                    let t = std::f64::consts::TAU * (i as f64 + 0.5 * next()) / n as f64;
                    let r = 0.5 + next();
                    DVec2::new(r * t.cos(), r * t.sin())
                })
                .collect();
            let order = hull_order(&ring);
            let i = (next() * n as f64) as usize % n;
            let len = 3 + (next() * (n - 3) as f64) as usize;
            let mut child: Vec<DVec2> = (0..len).map(|k| ring[(i + k) % n]).collect();
            if next() < 0.5 {
                let (a, b) = (ring[(i + len - 1) % n], ring[(i + len) % n]);
                child.push(a + next() * (b - a));
            }
            if next() < 0.3 {
                // a copy of a vertex, and a point anywhere
                child.insert(1, ring[(i + len / 2) % n]);
                child.push(DVec2::new(3.0 * next() - 1.5, 3.0 * next() - 1.5));
            }
            let map = match_vertices(&child, &ring, i);
            let derived = child_hull_order(&order, n, &child, &map).expect("a match");
            assert_eq!(derived, hull_order(&child));
            assert_eq!(
                hull_from_order(&child, &derived),
                convex_hull_distinct(&child)
            );
        }
    }

    /// `visit_sorted` visits in the order of a full sort and stops when told.
    #[test]
    fn sorted_visits_follow_the_full_sort() {
        let mut state = 7u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for n in [0, 1, 5, 63, 64, 65, 200, 1000] {
            let items: Vec<(u64, usize)> = (0..n).map(|k| (next() % 50, k)).collect();
            let mut sorted = items.clone();
            sorted.sort();
            for stop in [0, 1, 64, 100, usize::MAX] {
                let mut seen = Vec::new();
                let mut work = items.clone();
                visit_sorted(
                    &mut work,
                    |a, b| a.cmp(b),
                    |&x| {
                        seen.push(x);
                        seen.len() < stop
                    },
                );
                let expect = &sorted[..sorted.len().min(stop.max(1))];
                assert_eq!(&seen[..], expect, "n {n} stop {stop}");
            }
        }
    }

    #[test]
    fn penalty_shape() {
        assert_eq!(angle_penalty(PI / 2.0), 0.0);
        assert!((angle_penalty(PI) - 1.0).abs() < 1e-12);
        assert!((angle_penalty(1.5 * PI) - 2.0).abs() < 1e-12);
    }
}
