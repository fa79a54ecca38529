//! The boundary geometry of the pass: the rings a boundary node slides on, the sliding nodes
//! ([`BoundarySlide`]) and the cell centroid the ring guard checks.

use std::collections::HashMap;

use unamalla_mesh::{DVec2, QuadMesh, Region, SegmentIndex};

/// The ring geometry a boundary node slides on: vertices, cumulative arc length and the arc
/// positions of the feature vertices.
#[derive(Debug, Clone)]
pub(super) struct Ring {
    pub(super) pts: Vec<DVec2>,
    /// `cum[i]`: arc length from vertex 0 to vertex `i`; `cum[n]` = perimeter.
    cum: Vec<f64>,
    /// Arc positions of the feature vertices, increasing.
    features: Vec<f64>,
}

impl Ring {
    pub(super) fn new(pts: &[DVec2], feature_angle: f64) -> Self {
        let n = pts.len();
        let mut cum = Vec::with_capacity(n + 1);
        let mut s = 0.0;
        cum.push(0.0);
        for i in 0..n {
            s += pts[i].distance(pts[(i + 1) % n]);
            cum.push(s);
        }
        let features = (0..n)
            .filter(|&i| {
                let d1 = pts[i] - pts[(i + n - 1) % n];
                let d2 = pts[(i + 1) % n] - pts[i];
                d1.perp_dot(d2).atan2(d1.dot(d2)).abs() > feature_angle
            })
            .map(|i| cum[i])
            .collect();
        Self {
            pts: pts.to_vec(),
            cum,
            features,
        }
    }

    pub(super) fn len(&self) -> f64 {
        self.cum[self.cum.len() - 1]
    }

    /// `s` wrapped into `(−L/2, L/2]`.
    pub(super) fn wrap_offset(&self, d: f64) -> f64 {
        let l = self.len();
        let mut d = d.rem_euclid(l);
        if d > 0.5 * l {
            d -= l;
        }
        d
    }

    /// The point at arc position `s` (any real, taken modulo the perimeter).
    pub(super) fn at(&self, s: f64) -> DVec2 {
        let l = self.len();
        let s = s.rem_euclid(l);
        let n = self.pts.len();
        // the edge e with cum[e] <= s < cum[e + 1]
        let e = self
            .cum
            .partition_point(|&c| c <= s)
            .saturating_sub(1)
            .min(n - 1);
        let len = self.cum[e + 1] - self.cum[e];
        let t = if len > 0.0 {
            ((s - self.cum[e]) / len).clamp(0.0, 1.0)
        } else {
            0.0
        };
        self.pts[e].lerp(self.pts[(e + 1) % n], t)
    }

    /// Offset (in `(0, L)`) of the first feature strictly after `s`, if any.
    pub(super) fn next_feature(&self, s: f64) -> Option<f64> {
        let l = self.len();
        let s = s.rem_euclid(l);
        let i = self.features.partition_point(|&f| f <= s);
        match (self.features.get(i), self.features.first()) {
            (Some(&f), _) => Some(f - s),
            (None, Some(&f)) => Some(f + l - s),
            _ => None,
        }
    }

    /// Offset (in `(0, L)`) of the last feature strictly before `s`, if any.
    pub(super) fn prev_feature(&self, s: f64) -> Option<f64> {
        let l = self.len();
        let s = s.rem_euclid(l);
        let i = self.features.partition_point(|&f| f < s);
        match (
            i.checked_sub(1).map(|k| self.features[k]),
            self.features.last(),
        ) {
            (Some(f), _) => Some(s - f),
            (None, Some(&f)) => Some(s + l - f),
            _ => None,
        }
    }
}

/// A boundary node that may slide: its ring and its two boundary neighbours.
#[derive(Debug, Clone, Copy)]
pub(super) struct Slider {
    pub(super) ring: usize,
    pub(super) nbr: [usize; 2],
}

/// The boundary sliding data of a mesh on a region: which fixed nodes lie on which ring, where.
#[derive(Debug, Clone)]
pub struct BoundarySlide {
    pub(super) rings: Vec<Ring>,
    /// Arc position of every fixed node found on a ring (sliding or not).
    pub(super) arcs: HashMap<usize, f64>,
    pub(super) sliders: HashMap<usize, Slider>,
    pub(super) index: SegmentIndex,
}

impl BoundarySlide {
    /// Finds, for every fixed node of `mesh` with exactly two boundary neighbours, the ring of
    /// `region` it lies on (within `1e-9` of the region's diameter) and its arc position; nodes
    /// on a feature vertex (turning by more than `feature_angle_deg`) or on no ring are left
    /// out and stay where they are.
    pub fn new(mesh: &QuadMesh, region: &Region, feature_angle_deg: f64) -> Self {
        let fa = feature_angle_deg.to_radians();
        let rings: Vec<Ring> = region.rings().map(|p| Ring::new(p.points(), fa)).collect();
        let index = region.edge_index();
        let (lo, hi) = region.bounding_box();
        let tol = 1e-9 * (hi - lo).length().max(f64::MIN_POSITIVE);
        let fixed = mesh.fixed();
        let nodes = unamalla_mesh::HasNodes::nodes(mesh);
        // boundary edges (used by one cell) with both ends fixed
        let mut nbrs: HashMap<usize, Vec<usize>> = HashMap::new();
        for [a, b] in unamalla_mesh::quality::quad_boundary_edges(mesh) {
            if fixed[a] && fixed[b] {
                nbrs.entry(a).or_default().push(b);
                nbrs.entry(b).or_default().push(a);
            }
        }
        let locate = |p: DVec2| -> Option<(usize, f64)> {
            let d = DVec2::splat(tol);
            index
                .candidates(p - d, p + d)
                .map(|e| {
                    let (a, b) = index.edge(e);
                    let ab = b - a;
                    let t = if ab.length_squared() > 0.0 {
                        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    let dist = p.distance(a + t * ab);
                    (dist, e.ring, rings[e.ring].cum[e.edge] + t * ab.length())
                })
                .filter(|&(dist, _, _)| dist <= tol)
                // deterministic: nearest, then smallest (ring, arc)
                .min_by(|x, y| x.partial_cmp(y).unwrap_or(std::cmp::Ordering::Equal))
                .map(|(_, r, s)| (r, s))
        };
        let on_ring: HashMap<usize, (usize, f64)> = nbrs
            .keys()
            .filter_map(|&v| locate(nodes[v]).map(|l| (v, l)))
            .collect();
        let mut sliders = HashMap::new();
        for (&v, nb) in &nbrs {
            if nb.len() != 2 {
                continue;
            }
            let Some(&(ring, arc)) = on_ring.get(&v) else {
                continue;
            };
            // both boundary neighbours on the same ring (not, e.g., a flat corner bent inward)
            if !nb
                .iter()
                .all(|w| on_ring.get(w).is_some_and(|&(r, _)| r == ring))
            {
                continue;
            }
            let r = &rings[ring];
            let at_feature = r
                .features
                .iter()
                .any(|&f| r.wrap_offset(f - arc).abs() <= tol);
            if at_feature {
                continue;
            }
            let mut nbr = [nb[0], nb[1]];
            nbr.sort_unstable();
            sliders.insert(v, Slider { ring, nbr });
        }
        Self {
            rings,
            arcs: on_ring.into_iter().map(|(v, (_, s))| (v, s)).collect(),
            sliders,
            index,
        }
    }

    /// Boundary nodes that may slide.
    pub fn num_sliders(&self) -> usize {
        self.sliders.len()
    }
}

/// Mean of the four corners.
pub(super) fn centroid(q: &[DVec2; 4]) -> DVec2 {
    (q[0] + q[1] + q[2] + q[3]) * 0.25
}
