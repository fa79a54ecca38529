//! A static spatial index over the edges of one or more rings (an R*-tree from `rstar`),
//! used to test ring simplicity, ring disjointness and cut visibility in O(n log n) instead of
//! O(n²).

use glam::DVec2;
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};

use crate::geometry::{open_segment_hits, segments_intersect};

/// Identifies an edge: ring number (in the order the rings were given) and edge number (edge `e`
/// joins vertex `e` and vertex `e + 1 mod n`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct EdgeRef {
    /// The ring.
    pub ring: usize,
    /// The edge within the ring.
    pub edge: usize,
}

type Entry = GeomWithData<Rectangle<[f64; 2]>, EdgeRef>;

/// An R*-tree of ring edges, built once (bulk loaded) and queried many times.
#[derive(Debug, Clone)]
pub struct SegmentIndex {
    tree: RTree<Entry>,
    rings: Vec<Vec<DVec2>>,
}

impl SegmentIndex {
    /// Indexes every edge of every ring (rings are closed implicitly: last vertex joins first).
    pub fn new(rings: Vec<Vec<DVec2>>) -> Self {
        let mut entries = Vec::with_capacity(rings.iter().map(Vec::len).sum());
        for (r, ring) in rings.iter().enumerate() {
            let n = ring.len();
            for e in 0..n {
                let (a, b) = (ring[e], ring[(e + 1) % n]);
                entries.push(GeomWithData::new(
                    Rectangle::from_corners([a.x, a.y], [b.x, b.y]),
                    EdgeRef { ring: r, edge: e },
                ));
            }
        }
        Self {
            tree: RTree::bulk_load(entries),
            rings,
        }
    }

    /// The rings this index was built from.
    pub fn rings(&self) -> &[Vec<DVec2>] {
        &self.rings
    }

    /// The endpoints of an edge.
    pub fn edge(&self, e: EdgeRef) -> (DVec2, DVec2) {
        let ring = &self.rings[e.ring];
        (ring[e.edge], ring[(e.edge + 1) % ring.len()])
    }

    /// Every indexed edge whose bounding box meets the bounding box of segment `ab`.
    pub fn candidates(&self, a: DVec2, b: DVec2) -> impl Iterator<Item = EdgeRef> + '_ {
        let env = AABB::from_corners([a.x, a.y], [b.x, b.y]);
        self.tree
            .locate_in_envelope_intersecting(&env)
            .map(|entry| entry.data)
    }

    /// The indexed edges that share at least one point with the closed segment `ab` (exact).
    pub fn intersecting(&self, a: DVec2, b: DVec2) -> impl Iterator<Item = EdgeRef> + '_ {
        self.candidates(a, b).filter(move |&e| {
            let (p, q) = self.edge(e);
            segments_intersect(a, b, p, q)
        })
    }

    /// `true` if the open segment `(p, q)` meets some indexed edge (see
    /// [`open_segment_hits`]): the segment crosses or touches the rings anywhere but at its
    /// own endpoints.
    pub fn open_segment_blocked(&self, p: DVec2, q: DVec2) -> bool {
        self.candidates(p, q).any(|e| {
            let (a, b) = self.edge(e);
            open_segment_hits(p, q, a, b)
        })
    }

    /// The first pair of indexed edges that intersect, other than consecutive edges of the same
    /// ring meeting only at their shared vertex. A consecutive pair that folds back on itself
    /// (a zero-angle spike) counts as intersecting. Deterministic: the pair with the smallest
    /// `(ring, edge)` of the first edge, then of the second, is returned.
    pub fn first_intersection(&self) -> Option<(EdgeRef, EdgeRef)> {
        let mut best: Option<(EdgeRef, EdgeRef)> = None;
        let key = |e: EdgeRef| (e.ring, e.edge);
        for (r, ring) in self.rings.iter().enumerate() {
            let n = ring.len();
            for e in 0..n {
                let me = EdgeRef { ring: r, edge: e };
                let (a, b) = self.edge(me);
                for other in self.candidates(a, b) {
                    if key(other) <= key(me) {
                        continue;
                    }
                    let hit = if other.ring == r
                        && n >= 2
                        && (other.edge == (e + 1) % n || e == (other.edge + 1) % n)
                    {
                        // consecutive edges: they share one vertex; only a fold-back is a hit
                        let (shared, before, after) = if other.edge == (e + 1) % n {
                            (b, a, self.edge(other).1)
                        } else {
                            (a, b, self.edge(other).0)
                        };
                        crate::geometry::orient2d(before, shared, after) == 0.0
                            && (before - shared).dot(after - shared) > 0.0
                    } else {
                        let (p, q) = self.edge(other);
                        segments_intersect(a, b, p, q)
                    };
                    if hit {
                        let pair = (me, other);
                        if best.is_none_or(|(x, y)| (key(pair.0), key(pair.1)) < (key(x), key(y))) {
                            best = Some(pair);
                        }
                    }
                }
            }
            if best.is_some() {
                // pairs found from an earlier ring always sort before later rings' pairs
                return best;
            }
        }
        best
    }
}
