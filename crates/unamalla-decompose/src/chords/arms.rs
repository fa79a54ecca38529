//! Arms: the neck score of a ring, the test that a block has no arm, and the chord that
//! cuts a block's arm off.

use std::cmp::Ordering::Greater;

use unamalla_mesh::geometry::point_segment_distance;
use unamalla_mesh::{DVec2, Region};

use super::mesh::ChordMesh;
use super::tree::{PieceTree, TreeScratch};
use super::MIN_END_ANGLE_DEG;

/// The **neck score** of a simple polygon (a block): the largest `min(A₁, A₂)/w²` over its
/// chords (module docs) — how many chord widths the smaller side extends beyond its
/// narrowest chord. A convex, roughly square block scores ≤ ½; a block that keeps a narrow arm
/// or a long tongue scores high. Used by the shape-category tests (`unamalla-core/tests/categories.rs`).
pub fn neck_score(ring: &[DVec2]) -> f64 {
    let Ok(region) = Region::new(ring.to_vec(), vec![]) else {
        return f64::NAN;
    };
    let per = region.perimeter();
    let Ok(m) = ChordMesh::new(&region, per / 400.0) else {
        return f64::NAN;
    };
    let open = |t: usize, k: usize| m.nbr[t][k];
    if m.tris.is_empty() {
        return 0.0;
    }
    let Some(tree) = PieceTree::new(&m, 0, &open, &mut TreeScratch::new(&m)) else {
        return f64::NAN;
    };
    tree.chords(&m)
        .map(|(a, b, a1, _)| a1.min(tree.total - a1) / m.pts[a].distance_squared(m.pts[b]))
        .fold(0.0, f64::max)
}

/// A neck score that no chord of a block reaches when [`arm_free`] holds: [`arm_chord`] with
/// a `min_score` at least this large finds nothing there.
pub(super) const ARM_FREE_SCORE: f64 = 3.5;

/// How many pieces [`arm_free`] cuts each of two edges into for its third case.
pub(super) const ARM_FREE_PARTS: usize = 8;

/// `true` if no chord of [`arm_chord`]'s triangulation of the block `ring` (a simple ring of
/// area `area` and perimeter `per`, sampled every `per/400`) with both ends on edges `i`
/// with `eligible[i]` has a neck score `min(A₁, A₂)/w²` of [`ARM_FREE_SCORE`] or more —
/// decided from the ring's edges in O(n²), without the triangulation. `false` means only
/// "not shown".
///
/// Why. A chord of length `w` from `x` (on edge `e`) to `y` (on edge `f ≠ e`: two samples of
/// one edge are joined by boundary edges only) cuts the block into two simple polygons, each
/// bounded by the chord and one boundary arc between `x` and `y`; a side whose arc has
/// length `L` has an area of at most `(L + w)²/(4π)` (isoperimetric inequality). The test
/// asks, for every pair of eligible edges, one of:
///
/// * the directions of the edges `e, e+1, …, f` (or of `f, …, e`), unwrapped along the
///   chain by its turning angles, spread over less than `Θ = 2·acos(1/5)` (≈ 156.9°): then
///   they all lie within `Θ/2` of one direction `u`, so for the arc `γ` along them
///   `w ≥ (y − x)·u ≥ cos(Θ/2)·|γ| = |γ|/5`, and the side bounded by `γ` has an area of at
///   most `(6w)²/(4π) < 2.9·w²`;
/// * the two edges are farther apart than `R = √(A/6)`: then `w > R`, and the smaller side
///   has at most `A/2 < 3·w²`;
/// * cut into [`ARM_FREE_PARTS`] equal pieces each, every piece of `e` and piece of `f` are
///   farther apart than `R`, or the longer of the arcs from one to the other (either way
///   round: from the start of the one to the end of the other) is shorter than `4.9` times
///   their distance: then the side bounded by that arc has an area of at most
///   `(5.9w)²/(4π) < 2.8·w²` (or, as above, `w > R`).
///
/// So every such chord scores below 3. The triangulation computes the score from its
/// samples (rounded points on the edges) and from sums of rounded triangle areas, and the
/// test leaves room for that. Consecutive samples are at least `g` apart (the shortest edge,
/// or a hundredth of the spacing, which [`ChordMesh::new`] keeps between a neck foot and any
/// other sample), so a chord — its ends are not consecutive samples either way round — is
/// at least `min(0.4·g, R)` long (under the first and third cases its arc holds two sample
/// gaps). A sample (like an end of a piece) is off its edge by less than
/// `δ = 4ε·max|coordinate|`, which the test bounds by 5·10⁻⁸·g (directions, lengths and
/// distances along the samples then differ from the edges' by less than 10⁻⁷ relative, far
/// inside the margins on `Θ`, `R` and the factor 4.9). For `N` triangles (at most twice the
/// samples: `per/spacing + n` on the edges and at most one neck foot per vertex and nearby
/// edge), the area error `δ·per + 10·N·ε·per²` (a generous bound of the moved boundary, of
/// the rounded triangle areas and of their sums) is below `0.4·w²`. The computed score then
/// stays below `(3 + 0.4)·(1 + 10⁻⁶) < 3.5`.
pub(super) fn arm_free(ring: &[DVec2], eligible: &[bool], area: f64, per: f64) -> bool {
    let n = ring.len();
    // (written so that NaN counts as not positive)
    if n < 3 || area.partial_cmp(&0.0) != Some(Greater) || per.partial_cmp(&0.0) != Some(Greater) {
        return false;
    }
    let spacing = per / 400.0;
    let edge = |i: usize| (ring[i], ring[(i + 1) % n]);
    let min_edge = (0..n)
        .map(|i| edge(i).0.distance(edge(i).1))
        .fold(f64::INFINITY, f64::min);
    let gap = min_edge.min(0.01 * spacing);
    let max_coord = ring
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0, f64::max);
    // a sample (a rounded point on its edge) is off the edge by less than `delta`
    let delta = 4.0 * f64::EPSILON * max_coord;
    if gap.partial_cmp(&0.0) != Some(Greater) || 2.0 * delta > 1e-7 * gap {
        return false;
    }
    let r = (area / 6.0).sqrt();
    // the distance of two edges (they meet only if they are consecutive: a simple ring)
    let dist = |e: usize, f: usize| {
        let ((a, b), (c, d)) = (edge(e), edge(f));
        point_segment_distance(a, c, d)
            .min(point_segment_distance(b, c, d))
            .min(point_segment_distance(c, a, b))
            .min(point_segment_distance(d, a, b))
    };
    // an upper bound of the neck feet: a vertex closer than half a spacing to an edge not at
    // it may give one
    let feet = (0..n)
        .map(|v| {
            (0..n)
                .filter(|&f| f != v && (f + 1) % n != v)
                .filter(|&f| point_segment_distance(ring[v], edge(f).0, edge(f).1) < spacing)
                .count()
        })
        .sum::<usize>();
    // samples: at most per/spacing + n on the edges, plus the feet; triangles fewer than
    // twice the samples
    let triangles = 2.0 * (400.0 + (n + feet) as f64 + 1.0);
    let w_min = (0.4 * gap).min(r);
    if delta * per + 10.0 * triangles * f64::EPSILON * per * per >= 0.4 * w_min * w_min {
        return false;
    }
    // turning angle at vertex i + 1, from edge i to edge i + 1
    let dir = |i: usize| edge(i).1 - edge(i).0;
    let turn: Vec<f64> = (0..n)
        .map(|i| {
            let (u, v) = (dir(i), dir((i + 1) % n));
            u.perp_dot(v).atan2(u.dot(v))
        })
        .collect();
    // spread[e·n + f]: spread of the unwrapped directions of the edges e, e+1, …, f
    let mut spread = vec![0.0; n * n];
    for e in 0..n {
        let (mut th, mut lo, mut hi) = (0.0f64, 0.0f64, 0.0f64);
        for k in 1..n {
            th += turn[(e + k - 1) % n];
            lo = lo.min(th);
            hi = hi.max(th);
            spread[e * n + (e + k) % n] = hi - lo;
        }
    }
    // Θ, less a margin far above the rounding of the directions
    let theta = 2.0 * 0.2f64.acos() - 1e-6;
    // arc length along the ring from vertex 0 to each vertex
    let mut at = vec![0.0; n + 1];
    for i in 0..n {
        at[i + 1] = at[i] + edge(i).0.distance(edge(i).1);
    }
    // the third case, on edges e < f cut into ARM_FREE_PARTS pieces each: a piece of edge `i`
    // (end points, arc positions of its ends)
    let piece = |i: usize, s: usize| {
        let (a, b) = edge(i);
        let parts = ARM_FREE_PARTS as f64;
        let (t0, t1) = (s as f64 / parts, (s + 1) as f64 / parts);
        let len = at[i + 1] - at[i];
        (
            (a + t0 * (b - a), a + t1 * (b - a)),
            (at[i] + t0 * len, at[i] + t1 * len),
        )
    };
    let pieces_apart = |e: usize, f: usize| {
        (0..ARM_FREE_PARTS).all(|s| {
            (0..ARM_FREE_PARTS).all(|t| {
                let ((a, b), (sa, sb)) = piece(e, s);
                let ((c, d), (tc, td)) = piece(f, t);
                let w = point_segment_distance(a, c, d)
                    .min(point_segment_distance(b, c, d))
                    .min(point_segment_distance(c, a, b))
                    .min(point_segment_distance(d, a, b));
                // the longest arc forward from the piece of e to the piece of f, and back
                let (forward, back) = (td - sa, per - (tc - sb));
                w > 1.01 * r || forward.min(back) < 4.9 * w
            })
        })
    };
    (0..n).filter(|&e| eligible[e]).all(|e| {
        (e + 1..n).filter(|&f| eligible[f]).all(|f| {
            spread[e * n + f] < theta
                || spread[f * n + e] < theta
                || dist(e, f) > 1.01 * r
                || pieces_apart(e, f)
        })
    })
}

/// The best **arm cut** of a block: the chord with the highest `min(A₁, A₂)/w²`, at least
/// `min_score`, whose ends both lie on edges with `on_boundary[i]` (original region boundary,
/// so the chord is a valid cut of the region), strictly inside those edges or at their
/// vertices, that meets the boundary at no less than [`MIN_END_ANGLE_DEG`], and whose smaller
/// side has an area of at least `min_area`.
pub(crate) fn arm_chord(
    ring: &[DVec2],
    on_boundary: &[bool],
    min_score: f64,
    min_area: f64,
) -> Option<(DVec2, DVec2)> {
    let region = Region::new(ring.to_vec(), vec![]).ok()?;
    // Region::new may have reversed the ring: map edges by their end points
    let n = ring.len();
    let boundary_edge = |i: usize| {
        let (a, b) = (
            region.outer().points()[i],
            region.outer().points()[(i + 1) % n],
        );
        (0..n).any(|k| {
            on_boundary[k]
                && ((ring[k] == a && ring[(k + 1) % n] == b)
                    || (ring[k] == b && ring[(k + 1) % n] == a))
        })
    };
    let on: Vec<bool> = (0..n).map(boundary_edge).collect();
    // most blocks have no arm: shown without the triangulation, the costliest step
    if min_score >= ARM_FREE_SCORE
        && arm_free(
            region.outer().points(),
            &on,
            region.area(),
            region.perimeter(),
        )
    {
        return None;
    }
    let m = ChordMesh::new(&region, region.perimeter() / 400.0).ok()?;
    if m.tris.is_empty() {
        return None;
    }
    let open = |t: usize, k: usize| m.nbr[t][k];
    let tree = PieceTree::new(&m, 0, &open, &mut TreeScratch::new(&m))?;
    let min_angle = MIN_END_ANGLE_DEG.to_radians();
    let mut best: Option<(f64, usize, usize)> = None;
    for (a, b, a1, _) in tree.chords(&m) {
        let w2 = m.pts[a].distance_squared(m.pts[b]);
        let small = a1.min(tree.total - a1);
        let score = small / w2;
        if small < min_area || score < min_score || best.is_some_and(|(s, _, _)| s >= score) {
            continue;
        }
        if !on[m.edge[a]] || !on[m.edge[b]] {
            continue;
        }
        let (amin, _) = m.chord_angles(a, b);
        if amin < min_angle {
            continue;
        }
        best = Some((score, a, b));
    }
    best.map(|(_, a, b)| (m.pts[a], m.pts[b]))
}
