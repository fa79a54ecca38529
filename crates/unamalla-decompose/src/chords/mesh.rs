//! The chord mesh: the boundary sampled at the cell size (with the feet of the neck
//! perpendiculars), triangulated by a constrained Delaunay triangulation (`spade`); its
//! interior edges are the chords.

use std::collections::{BTreeMap, VecDeque};

use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
use unamalla_mesh::{DVec2, Region};

use crate::geom::{angle_penalty, left_angle};

/// The triangulated region: boundary samples, inside triangles and their adjacency.
pub(crate) struct ChordMesh {
    /// Sample points.
    pub pts: Vec<DVec2>,
    /// Ring of each sample (0 outer, k hole k−1).
    pub ring: Vec<usize>,
    /// First sample of each ring (and the total count at the end).
    pub ring_start: Vec<usize>,
    /// Arc-length position of each sample along its ring.
    pub arc: Vec<f64>,
    /// Edge of its ring each sample lies on (`i` for the edge from vertex `i` to `i + 1`;
    /// samples at vertex `i` count as on edge `i`).
    pub edge: Vec<usize>,
    /// Perimeter of each ring.
    pub ring_len: Vec<f64>,
    /// Inside triangles (sample indices).
    pub tris: Vec<[usize; 3]>,
    /// `nbr[t][k]`: the inside triangle across edge `(tris[t][k], tris[t][(k+1)%3])`, if that
    /// edge is not a boundary edge.
    pub nbr: Vec<[Option<usize>; 3]>,
    /// Sample spacing per ring: the requested spacing, or a sixteenth of the ring's
    /// perimeter for a small ring (so a small island still has chords all around it).
    pub ring_spacing: Vec<f64>,
}

/// The **neck feet** of a region: for every ring vertex `p` and every edge `ab` (of any ring,
/// not incident to `p`) closer to `p` than half the sample spacing of `ab`'s ring, the
/// parameter `t ∈ (0, 1)` of the foot `q = a + t(b − a)` of the perpendicular from `p`, keyed
/// by (ring, edge). Uniform samples alone miss a neck narrower than their spacing: the CDT
/// then joins `p` to samples up to a spacing away, and the chord there is too long for the
/// neck's score `min(A₁, A₂)/w²` to show (texas at 50,000 cells: a lagoon 2–6 units wide
/// joined to the main body through a 0.15-unit pinch, with chords sampled every 6 units; the
/// block kept the pinch and its cells were squeezed 25-fold). With the foot sampled, `p q`
/// is the shortest chord there and a Delaunay edge. Work: one R*-tree query per vertex.
fn neck_feet(region: &Region, spacings: &[f64]) -> BTreeMap<(usize, usize), Vec<f64>> {
    let rings: Vec<Vec<DVec2>> = region.rings().map(|r| r.points().to_vec()).collect();
    let index = unamalla_mesh::SegmentIndex::new(rings.clone());
    let reach = 0.5 * spacings.iter().copied().fold(0.0, f64::max);
    let mut out: BTreeMap<(usize, usize), Vec<f64>> = BTreeMap::new();
    for (rp, ring) in rings.iter().enumerate() {
        let n = ring.len();
        for (i, &p) in ring.iter().enumerate() {
            let r2 = DVec2::splat(reach);
            for e in index.candidates(p - r2, p + r2) {
                if e.ring == rp && (e.edge == i || (e.edge + 1) % n == i) {
                    continue; // an edge incident to p
                }
                let (a, b) = index.edge(e);
                let d = b - a;
                let len2 = d.length_squared();
                if len2 <= 0.0 {
                    continue;
                }
                let t = (p - a).dot(d) / len2;
                if !(t > 0.0 && t < 1.0) {
                    continue; // the closest point is an end of the edge: a vertex already
                }
                if p.distance(a + t * d) < 0.5 * spacings[e.ring] {
                    out.entry((e.ring, e.edge)).or_default().push(t);
                }
            }
        }
    }
    out
}

/// Why the chord layout could not be computed (the caller falls back to the concavity
/// layout).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ChordError(pub String);

impl ChordMesh {
    /// Samples every ring every `spacing` (at most a sixteenth of its perimeter; original
    /// vertices kept) and triangulates.
    pub fn new(region: &Region, spacing: f64) -> Result<Self, ChordError> {
        let mut ring_spacing = Vec::new();
        let mut edge = Vec::new();
        let mut pts = Vec::new();
        let mut ring = Vec::new();
        let mut ring_start = Vec::new();
        let mut arc = Vec::new();
        let mut ring_len = Vec::new();
        let spacings: Vec<f64> = region
            .rings()
            .map(|poly| spacing.min(poly.perimeter() / 16.0))
            .collect();
        let mut feet = neck_feet(region, &spacings);
        for (r, poly) in region.rings().enumerate() {
            ring_start.push(pts.len());
            let p = poly.points();
            let n = p.len();
            let spacing = spacings[r];
            ring_spacing.push(spacing);
            let mut s_acc = 0.0;
            for i in 0..n {
                let (a, b) = (p[i], p[(i + 1) % n]);
                let len = a.distance(b);
                let k = ((len / spacing).ceil() as usize).clamp(1, 1 << 20);
                let mut ts: Vec<f64> = (0..k).map(|j| j as f64 / k as f64).collect();
                if let Some(extra) = feet.remove(&(r, i)) {
                    // a foot closer than a hundredth of the spacing to a sample is that sample
                    let near = 0.01 * spacing / len.max(f64::MIN_POSITIVE);
                    for t in extra {
                        if ts.iter().all(|&u| (u - t).abs() > near) && 1.0 - t > near {
                            ts.push(t);
                        }
                    }
                    ts.sort_by(f64::total_cmp);
                }
                for t in ts {
                    pts.push(a.lerp(b, t));
                    ring.push(r);
                    arc.push(s_acc + t * len);
                    edge.push(i);
                }
                s_acc += len;
            }
            ring_len.push(s_acc);
        }
        ring_start.push(pts.len());

        let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
            ConstrainedDelaunayTriangulation::new();
        let mut handles = Vec::with_capacity(pts.len());
        let mut owner: Vec<usize> = Vec::new();
        for (i, p) in pts.iter().enumerate() {
            let hd = cdt
                .insert(Point2::new(p.x, p.y))
                .map_err(|e| ChordError(format!("triangulation at ({}, {}): {e:?}", p.x, p.y)))?;
            if owner.len() <= hd.index() {
                owner.resize(hd.index() + 1, usize::MAX);
            }
            if owner[hd.index()] != usize::MAX {
                return Err(ChordError(format!(
                    "two boundary samples coincide at ({}, {})",
                    p.x, p.y
                )));
            }
            owner[hd.index()] = i;
            handles.push(hd);
        }
        for r in 0..ring_start.len() - 1 {
            let (s, e) = (ring_start[r], ring_start[r + 1]);
            for i in s..e {
                let j = if i + 1 == e { s } else { i + 1 };
                if !cdt.can_add_constraint(handles[i], handles[j]) {
                    return Err(ChordError(format!(
                        "boundary edge at ({}, {}) crosses another ring",
                        pts[i].x, pts[i].y
                    )));
                }
                cdt.add_constraint(handles[i], handles[j]);
            }
        }
        // parity flood from the outer face: crossing a constraint edge flips inside/outside
        let nf = cdt.num_all_faces();
        let mut inside: Vec<Option<bool>> = vec![None; nf];
        let mut queue = VecDeque::new();
        for h in cdt.convex_hull() {
            let c = cdt.is_constraint_edge(h.as_undirected().fix());
            for f in [h.face(), h.rev().face()] {
                if f.as_inner().is_some() && inside[f.fix().index()].is_none() {
                    inside[f.fix().index()] = Some(c);
                    queue.push_back(f.fix());
                }
            }
        }
        while let Some(f) = queue.pop_front() {
            let here = inside[f.index()].unwrap_or(false);
            let Some(inner) = cdt.face(f).as_inner() else {
                continue;
            };
            for e in inner.adjacent_edges() {
                let g = e.rev().face();
                if g.as_inner().is_none() || inside[g.fix().index()].is_some() {
                    continue;
                }
                let c = cdt.is_constraint_edge(e.as_undirected().fix());
                inside[g.fix().index()] = Some(here ^ c);
                queue.push_back(g.fix());
            }
        }
        let mut id_of = vec![usize::MAX; nf];
        let mut tris = Vec::new();
        for f in cdt.inner_faces() {
            if inside[f.fix().index()] == Some(true) {
                id_of[f.fix().index()] = tris.len();
                let v = f.vertices();
                tris.push([
                    owner[v[0].fix().index()],
                    owner[v[1].fix().index()],
                    owner[v[2].fix().index()],
                ]);
            }
        }
        let mut nbr = vec![[None; 3]; tris.len()];
        for f in cdt.inner_faces() {
            let t = id_of[f.fix().index()];
            if t == usize::MAX {
                continue;
            }
            for e in f.adjacent_edges() {
                if cdt.is_constraint_edge(e.as_undirected().fix()) {
                    continue;
                }
                let [a, _] = e.vertices();
                let a = owner[a.fix().index()];
                let k = (0..3).find(|&k| tris[t][k] == a).unwrap_or(0);
                let g = id_of[e.rev().face().fix().index()];
                if g != usize::MAX {
                    nbr[t][k] = Some(g);
                }
            }
        }
        Ok(Self {
            pts,
            ring,
            ring_start,
            arc,
            edge,
            ring_len,
            tris,
            nbr,
            ring_spacing,
        })
    }

    /// Sample spacing at sample `i`.
    pub(super) fn spacing(&self, i: usize) -> f64 {
        self.ring_spacing[self.ring[i]]
    }

    fn next_on_ring(&self, i: usize, steps: usize) -> usize {
        let r = self.ring[i];
        let (s, e) = (self.ring_start[r], self.ring_start[r + 1]);
        s + (i - s + steps) % (e - s)
    }

    fn prev_on_ring(&self, i: usize, steps: usize) -> usize {
        let r = self.ring[i];
        let (s, e) = (self.ring_start[r], self.ring_start[r + 1]);
        let n = e - s;
        s + (i - s + n - steps % n) % n
    }

    /// The two new angles at sample `i` of a chord going to `target`, with the boundary
    /// direction taken over a stretch of ≈ `reach` on each side (smooths sampling noise).
    fn end_angles(&self, i: usize, target: DVec2, reach: f64) -> (f64, f64) {
        let r = self.ring[i];
        let n = self.ring_start[r + 1] - self.ring_start[r];
        let steps = ((reach / self.ring_spacing[r]).round() as usize).clamp(1, (n / 4).max(1));
        let next = self.pts[self.next_on_ring(i, steps)];
        let prev = self.pts[self.prev_on_ring(i, steps)];
        let cur = self.pts[i];
        (left_angle(target, cur, next), left_angle(prev, cur, target))
    }

    /// `(min angle, ḡ)` of chord `(a, b)`.
    pub(super) fn chord_angles(&self, a: usize, b: usize) -> (f64, f64) {
        let w = self.pts[a].distance(self.pts[b]);
        let (a1, a2) = self.end_angles(a, self.pts[b], (0.5 * w).max(self.spacing(a)));
        let (b1, b2) = self.end_angles(b, self.pts[a], (0.5 * w).max(self.spacing(b)));
        let m = a1.min(a2).min(b1).min(b2);
        let g =
            0.25 * (angle_penalty(a1) + angle_penalty(a2) + angle_penalty(b1) + angle_penalty(b2));
        (m, g)
    }

    /// All chords (interior edges), each once, as `(a, b)` with `a < b`, sorted.
    pub(super) fn chords(&self) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for (t, tri) in self.tris.iter().enumerate() {
            for k in 0..3 {
                if let Some(u) = self.nbr[t][k] {
                    if t < u {
                        let (a, b) = (tri[k], tri[(k + 1) % 3]);
                        out.push((a.min(b), a.max(b)));
                    }
                }
            }
        }
        out.sort_unstable();
        out
    }

    pub(super) fn tri_area(&self, t: usize) -> f64 {
        let [a, b, c] = self.tris[t];
        0.5 * (self.pts[b] - self.pts[a])
            .perp_dot(self.pts[c] - self.pts[a])
            .abs()
    }
}
