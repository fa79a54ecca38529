//! Polygons and polygonal regions with holes, validated on construction.
//!
//! A [`Region`] is a closed bounded set whose boundary is a collection of mutually disjoint simple
//! polygons: the outer ring P₀ and the holes P₁..P_m inside it ([Méndez 2023, Ch. 2]). Rings are
//! stored **open** (the first point is not repeated), the outer ring counter-clockwise and holes
//! clockwise, so the region always lies to the left of every directed boundary edge. Input in
//! the other orientation is normalised (reversed keeping vertex 0 first), never rejected.
//!
//! Validation (exact predicates, R*-tree over all edges, O(n log n)) rejects with a typed
//! [`GeometryError`] naming the ring and vertex/edge: fewer than 3 distinct points, non-finite
//! coordinates, coordinates outside the exact predicates' range ([`MIN_COORDINATE`] ..=
//! [`MAX_COORDINATE`] in magnitude, or 0), repeated consecutive points ([`Region::new_cleaned`] removes them instead),
//! zero-area rings, self-intersecting rings (including zero-angle spikes), rings that touch or
//! cross each other, holes outside the outer ring and nested holes.

use glam::DVec2;
use serde::{Deserialize, Serialize};

use crate::error::{GeometryError, RingId};
use crate::geometry::{self, locate_in_ring, Location};
use crate::spatial::SegmentIndex;

/// Largest accepted coordinate magnitude. Shewchuk's `orient2d` is exact only while the
/// products of coordinate differences do not overflow: differences ≤ 2·10¹⁵⁰ give products
/// ≤ 4·10³⁰⁰ < f64::MAX. Larger coordinates made `orient2d` return ±∞/NaN and validation accept
/// self-intersecting or misoriented rings (found by the `region` fuzz target; see
/// `docs/reliability.md`).
pub const MAX_COORDINATE: f64 = 1e150;

/// Smallest accepted non-zero coordinate magnitude (zero is accepted). Two distinct doubles of
/// magnitude ≥ 10⁻¹⁰⁰ differ by at least ~10⁻¹¹⁶, so the products inside `orient2d` stay far
/// above the subnormal range (2.2·10⁻³⁰⁸) where they would lose exactness.
pub const MIN_COORDINATE: f64 = 1e-100;

/// A simple polygon stored as an open ring of points.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Polygon {
    points: Vec<DVec2>,
}

impl Polygon {
    /// Validates a single ring as a simple polygon (same checks as a region's outer ring) and
    /// normalises it to counter-clockwise.
    pub fn new(points: Vec<DVec2>) -> Result<Self, GeometryError> {
        Ok(Region::new(points, Vec::new())?.outer)
    }

    /// Wraps points without validation. Only for rings produced by our own algorithms that keep
    /// them simple (e.g. a simplifier that checks every removal).
    pub fn from_points_unchecked(points: Vec<DVec2>) -> Self {
        Self { points }
    }

    /// The vertices (open ring).
    pub fn points(&self) -> &[DVec2] {
        &self.points
    }
    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.points.len()
    }
    /// `true` if the ring has no vertices (never the case for a validated polygon).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
    /// Vertex `i` modulo the ring length.
    #[inline]
    pub fn vertex(&self, i: usize) -> DVec2 {
        self.points[i % self.points.len()]
    }
    /// Signed area by the shoelace formula: positive for counter-clockwise rings.
    pub fn signed_area(&self) -> f64 {
        signed_area(&self.points)
    }
    /// Absolute area.
    pub fn area(&self) -> f64 {
        self.signed_area().abs()
    }
    /// Axis-aligned bounding box `(min, max)` of the ring.
    pub fn bounding_box(&self) -> (DVec2, DVec2) {
        bbox(&self.points)
    }
    /// Perimeter.
    pub fn perimeter(&self) -> f64 {
        let n = self.points.len();
        (0..n)
            .map(|k| self.points[k].distance(self.points[(k + 1) % n]))
            .sum()
    }
    /// The angle at vertex `i` measured on the **left** side of the directed ring, in radians in
    /// `(0, 2π)`: for a counter-clockwise outer ring this is the interior angle; for a clockwise
    /// hole it is the angle on the region's side. A value above π marks a reflex vertex.
    pub fn left_angle(&self, i: usize) -> f64 {
        let n = self.points.len();
        let prev = self.points[(i + n - 1) % n];
        let cur = self.points[i % n];
        let next = self.points[(i + 1) % n];
        let to_next = next - cur;
        let to_prev = prev - cur;
        // angle swept counter-clockwise from `to_next` to `to_prev`
        let a = to_next.perp_dot(to_prev).atan2(to_next.dot(to_prev));
        if a <= 0.0 {
            a + std::f64::consts::TAU
        } else {
            a
        }
    }
    /// All left-side angles ([`Polygon::left_angle`]).
    pub fn left_angles(&self) -> Vec<f64> {
        (0..self.points.len()).map(|i| self.left_angle(i)).collect()
    }
    /// `true` if vertex `i` is reflex on the left side (the region side): the turn at it is
    /// clockwise (exact test).
    pub fn is_reflex(&self, i: usize) -> bool {
        let n = self.points.len();
        geometry::orient2d(
            self.points[(i + n - 1) % n],
            self.points[i % n],
            self.points[(i + 1) % n],
        ) < 0.0
    }
    /// Indices of the convex hull vertices, counter-clockwise.
    pub fn convex_hull(&self) -> Vec<usize> {
        geometry::convex_hull(&self.points)
    }
    /// Exact location of a point with respect to this ring.
    pub fn locate(&self, p: DVec2) -> Location {
        locate_in_ring(&self.points, p)
    }
    /// Returns the ring with reversed orientation, keeping vertex 0 first.
    pub fn reversed(&self) -> Self {
        let mut pts = self.points.clone();
        pts[1..].reverse();
        Self { points: pts }
    }
}

/// Shoelace signed area of an open ring (positive = counter-clockwise).
///
/// Computed as the fan `½ Σ_k (p_k − p_0) × (p_{k+1} − p_0)` from the first vertex — equal to
/// the textbook `½ Σ_k p_k × p_{k+1}` in exact arithmetic (the shoelace sum is invariant
/// under translation), but in floating point the textbook form cancels catastrophically far
/// from the origin: for a ring near (10⁹, 10⁹) the products are ~10¹⁸ and their rounding
/// errors ~10², larger than the area of a 10 × 10 ring (found by the `region` fuzz target).
/// Relative to `p_0` the error scales with the ring's own extent.
pub fn signed_area(ring: &[DVec2]) -> f64 {
    let Some(&o) = ring.first() else {
        return 0.0;
    };
    let mut s = 0.0;
    for w in ring.windows(2).skip(1) {
        s += (w[0] - o).perp_dot(w[1] - o);
    }
    0.5 * s
}

/// Exact orientation of a simple ring: the sign of `orient2d` at its lexicographically
/// smallest vertex (smallest x, then smallest y). That vertex is a strictly convex corner of
/// any simple ring (its neighbours cannot both be collinear with it without a zero-angle
/// spike, which validation rejects), so the sign is that of the ring's area, decided
/// exactly instead of from a rounded area. Returns > 0 for counter-clockwise.
fn exact_orientation(ring: &[DVec2]) -> f64 {
    let n = ring.len();
    let Some((k, _)) = ring
        .iter()
        .enumerate()
        .min_by(|(_, a), (_, b)| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)))
    else {
        return 0.0;
    };
    geometry::orient2d(ring[(k + n - 1) % n], ring[k], ring[(k + 1) % n])
}

/// A validated polygonal region: outer ring (CCW) and holes (CW).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Region {
    outer: Polygon,
    holes: Vec<Polygon>,
    /// For each stored outer vertex, its index in the input ring (closing duplicate removed).
    outer_source: Vec<usize>,
}

impl Region {
    /// Validates and builds a region. Rings may be given closed (a final point equal to the
    /// first is dropped) or open, in either orientation. Any defect is an error naming the ring
    /// and vertex; repeated consecutive points are an error here (see [`Region::new_cleaned`]).
    pub fn new(outer: Vec<DVec2>, holes: Vec<Vec<DVec2>>) -> Result<Self, GeometryError> {
        Self::build(outer, holes, false).map(|(r, _)| r)
    }

    /// Like [`Region::new`], but consecutive repeated points are removed instead of rejected.
    /// Returns the region and the number of points removed.
    pub fn new_cleaned(
        outer: Vec<DVec2>,
        holes: Vec<Vec<DVec2>>,
    ) -> Result<(Self, usize), GeometryError> {
        Self::build(outer, holes, true)
    }

    /// Builds a region from rings that the **caller guarantees** to be simple, pairwise
    /// disjoint (not even touching), with every hole inside the outer ring and no hole inside
    /// another — rings that are valid *by construction*, e.g. the output of a topology-safe
    /// simplification of a valid region in which every change was checked with exact
    /// predicates (`unamalla-contour`). Only the O(n) checks of [`Region::new`] run: finite
    /// coordinates within [`MIN_COORDINATE`]..=[`MAX_COORDINATE`], no repeated consecutive
    /// points (an error, as in [`Region::new`]), at least 3 points and non-zero area per ring;
    /// a closing duplicate is dropped and the orientation is normalised exactly as in
    /// [`Region::new`] (outer counter-clockwise, holes clockwise, vertex 0 kept first), so for
    /// valid rings the result **equals** `Region::new(outer, holes)`.
    ///
    /// Skipped: the O(n log n) simplicity, disjointness and containment tests (R*-tree over
    /// all edges). If the guarantee does not hold nothing unsafe happens, but the region is
    /// invalid and later operations (point location, meshing) give unspecified results: use
    /// [`Region::new`] for any input that is not valid by construction.
    ///
    /// ```
    /// use unamalla_mesh::{DVec2, Region};
    /// let sq = vec![DVec2::new(0., 0.), DVec2::new(0., 1.), DVec2::new(1., 1.), DVec2::new(1., 0.)];
    /// let r = Region::from_simple_rings(sq.clone(), vec![]).unwrap();
    /// assert_eq!(r, Region::new(sq, vec![]).unwrap()); // clockwise input normalised the same way
    /// assert!(Region::from_simple_rings(vec![DVec2::ZERO, DVec2::X, DVec2::X], vec![]).is_err());
    /// ```
    pub fn from_simple_rings(
        outer: Vec<DVec2>,
        holes: Vec<Vec<DVec2>>,
    ) -> Result<Self, GeometryError> {
        let mut polys = Vec::with_capacity(holes.len() + 1);
        let mut outer_source = Vec::new();
        for (k, ring) in std::iter::once(outer).chain(holes).enumerate() {
            let id = ring_id(k);
            let (pts, src, _) = prepare_ring(ring, id, false)?;
            let (p0, p1) = (pts[0], pts[1]);
            if pts[2..]
                .iter()
                .all(|&p| geometry::orient2d(p0, p1, p) == 0.0)
            {
                return Err(GeometryError::ZeroArea { ring: id });
            }
            let o = exact_orientation(&pts);
            let mut poly = Polygon::from_points_unchecked(pts);
            if k == 0 {
                outer_source = src;
                if o < 0.0 {
                    poly = poly.reversed();
                    outer_source[1..].reverse();
                }
            } else if o > 0.0 {
                poly = poly.reversed();
            }
            polys.push(poly);
        }
        let outer = polys.remove(0);
        Ok(Self {
            outer,
            holes: polys,
            outer_source,
        })
    }

    fn build(
        outer: Vec<DVec2>,
        holes: Vec<Vec<DVec2>>,
        clean: bool,
    ) -> Result<(Self, usize), GeometryError> {
        let mut removed = 0;
        let mut rings = Vec::with_capacity(holes.len() + 1);
        let mut sources = Vec::with_capacity(holes.len() + 1);
        for (k, ring) in std::iter::once(outer).chain(holes).enumerate() {
            let id = ring_id(k);
            let (pts, src, r) = prepare_ring(ring, id, clean)?;
            removed += r;
            rings.push(pts);
            sources.push(src);
        }
        // zero area: all points collinear (exact)
        for (k, ring) in rings.iter().enumerate() {
            let p0 = ring[0];
            let p1 = ring[1];
            if ring[2..]
                .iter()
                .all(|&p| geometry::orient2d(p0, p1, p) == 0.0)
            {
                return Err(GeometryError::ZeroArea { ring: ring_id(k) });
            }
        }
        // simplicity and disjointness in one pass over all edges
        let index = SegmentIndex::new(rings);
        if let Some((a, b)) = index.first_intersection() {
            let src = |e: crate::spatial::EdgeRef| sources[e.ring][e.edge];
            return Err(if a.ring == b.ring {
                let (x, y) = (src(a), src(b));
                GeometryError::SelfIntersection {
                    ring: ring_id(a.ring),
                    edge_a: x.min(y),
                    edge_b: x.max(y),
                }
            } else {
                GeometryError::RingsIntersect {
                    ring_a: ring_id(a.ring),
                    edge_a: src(a),
                    ring_b: ring_id(b.ring),
                    edge_b: src(b),
                }
            });
        }
        let rings = index.rings();
        // containment: rings are disjoint, so one vertex decides
        for h in 1..rings.len() {
            if locate_in_ring(&rings[0], rings[h][0]) != Location::Inside {
                return Err(GeometryError::HoleOutside { hole: h - 1 });
            }
        }
        let bboxes: Vec<(DVec2, DVec2)> = rings.iter().map(|r| bbox(r)).collect();
        for h in 1..rings.len() {
            let p = rings[h][0];
            for g in 1..rings.len() {
                if g == h {
                    continue;
                }
                let (lo, hi) = bboxes[g];
                if p.cmpge(lo).all()
                    && p.cmple(hi).all()
                    && locate_in_ring(&rings[g], p) == Location::Inside
                {
                    return Err(GeometryError::NestedHole {
                        outer: g - 1,
                        inner: h - 1,
                    });
                }
            }
        }
        // orientation: outer CCW, holes CW (reverse keeping vertex 0 first)
        let mut polys: Vec<Polygon> = rings
            .iter()
            .map(|r| Polygon::from_points_unchecked(r.clone()))
            .collect();
        let mut outer_source = sources.swap_remove(0);
        if exact_orientation(polys[0].points()) < 0.0 {
            polys[0] = polys[0].reversed();
            outer_source[1..].reverse();
        }
        for p in polys.iter_mut().skip(1) {
            if exact_orientation(p.points()) > 0.0 {
                *p = p.reversed();
            }
        }
        let outer = polys.remove(0);
        Ok((
            Self {
                outer,
                holes: polys,
                outer_source,
            },
            removed,
        ))
    }

    /// The outer ring (counter-clockwise).
    pub fn outer(&self) -> &Polygon {
        &self.outer
    }
    /// The holes (clockwise).
    pub fn holes(&self) -> &[Polygon] {
        &self.holes
    }
    /// All rings: the outer ring first, then the holes.
    pub fn rings(&self) -> impl Iterator<Item = &Polygon> {
        std::iter::once(&self.outer).chain(self.holes.iter())
    }
    /// Total number of vertices over all rings.
    pub fn num_vertices(&self) -> usize {
        self.rings().map(Polygon::len).sum()
    }
    /// Area of the region (outer area minus hole areas).
    pub fn area(&self) -> f64 {
        self.outer.area() - self.holes.iter().map(Polygon::area).sum::<f64>()
    }
    /// Total boundary length (outer ring and holes).
    pub fn perimeter(&self) -> f64 {
        self.rings().map(Polygon::perimeter).sum()
    }
    /// Axis-aligned bounding box `(min, max)`.
    pub fn bounding_box(&self) -> (DVec2, DVec2) {
        bbox(self.outer.points())
    }
    /// The stored index of the outer-ring vertex that was number `input_index` in the input
    /// ring as given (closing duplicate not counted), or `None` if that vertex was removed by
    /// cleaning or is out of range.
    pub fn outer_index_from_input(&self, input_index: usize) -> Option<usize> {
        self.outer_source.iter().position(|&s| s == input_index)
    }
    /// Exact location of a point: `Inside` the open region, `OnBoundary` of any ring, or
    /// `Outside` (including inside a hole).
    pub fn locate(&self, p: DVec2) -> Location {
        match self.outer.locate(p) {
            Location::Inside => {}
            other => return other,
        }
        for h in &self.holes {
            match h.locate(p) {
                Location::Outside => {}
                Location::Inside => return Location::Outside,
                Location::OnBoundary => return Location::OnBoundary,
            }
        }
        Location::Inside
    }
    /// `true` if `p` lies in the open region (not on its boundary, not in a hole).
    pub fn contains_point(&self, p: DVec2) -> bool {
        self.locate(p) == Location::Inside
    }
    /// A spatial index over all boundary edges (ring 0 = outer, ring k = hole k−1), for many
    /// repeated segment queries.
    pub fn edge_index(&self) -> SegmentIndex {
        SegmentIndex::new(self.rings().map(|p| p.points().to_vec()).collect())
    }
    /// `true` if the open segment `(p, q)` lies in the open region: it meets the boundary at
    /// most at its endpoints (which may be boundary points) and its midpoint is inside. This is
    /// the admissibility test of a cut ([Méndez 2023, §4.1]). For many queries build
    /// [`Region::edge_index`] once and use [`Region::segment_inside_with`].
    pub fn segment_inside(&self, p: DVec2, q: DVec2) -> bool {
        self.segment_inside_with(&self.edge_index(), p, q)
    }
    /// [`Region::segment_inside`] with a prebuilt edge index of this region.
    pub fn segment_inside_with(&self, index: &SegmentIndex, p: DVec2, q: DVec2) -> bool {
        p != q && !index.open_segment_blocked(p, q) && self.contains_point(0.5 * (p + q))
    }
}

fn ring_id(k: usize) -> RingId {
    if k == 0 {
        RingId::Outer
    } else {
        RingId::Hole(k - 1)
    }
}

fn bbox(points: &[DVec2]) -> (DVec2, DVec2) {
    points.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    )
}

/// Checks finiteness, drops a closing duplicate, handles repeated points and counts distinct
/// points. Returns the open ring, the input index of each kept vertex and the number removed.
fn prepare_ring(
    mut ring: Vec<DVec2>,
    id: RingId,
    clean: bool,
) -> Result<(Vec<DVec2>, Vec<usize>, usize), GeometryError> {
    if let Some(v) = ring.iter().position(|p| !p.is_finite()) {
        return Err(GeometryError::NonFinite {
            ring: id,
            vertex: v,
            x: ring[v].x,
            y: ring[v].y,
        });
    }
    let out_of_range = |c: f64| c != 0.0 && !(MIN_COORDINATE..=MAX_COORDINATE).contains(&c.abs());
    if let Some(v) = ring
        .iter()
        .position(|p| out_of_range(p.x) || out_of_range(p.y))
    {
        return Err(GeometryError::CoordinateOutOfRange {
            ring: id,
            vertex: v,
            x: ring[v].x,
            y: ring[v].y,
        });
    }
    if ring.len() >= 2 && ring.first() == ring.last() {
        ring.pop();
    }
    let mut pts = Vec::with_capacity(ring.len());
    let mut src = Vec::with_capacity(ring.len());
    let mut removed = 0;
    for (k, &p) in ring.iter().enumerate() {
        if pts.last() == Some(&p) {
            if !clean {
                return Err(GeometryError::RepeatedPoint {
                    ring: id,
                    vertex: k,
                });
            }
            removed += 1;
            continue;
        }
        pts.push(p);
        src.push(k);
    }
    // wrap-around repeats (last == first after dropping the closing point)
    while pts.len() >= 2 && pts.first() == pts.last() {
        if !clean {
            return Err(GeometryError::RepeatedPoint {
                ring: id,
                vertex: ring.len() - 1,
            });
        }
        pts.pop();
        src.pop();
        removed += 1;
    }
    if pts.len() < 3 {
        let mut distinct = pts.clone();
        distinct.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
        distinct.dedup();
        return Err(GeometryError::TooFewPoints {
            ring: id,
            count: distinct.len(),
        });
    }
    Ok((pts, src, removed))
}
