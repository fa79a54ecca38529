//! Narrow spits and inlets cut off at their necks.
//!
//! A mesher with target cell size `h` cannot put convex cells of size `h` into a tongue of land
//! (or water) narrower than a cell: the block layout gives the tongue its own blocks, a few
//! cells across it but with sides shorter than a cell, and the compatible point counts carry
//! their fine resolution along whole sheets of blocks (in the smoothed mesh: rows of cells
//! with 1–2 % of the mean area radiating from the tongue). The vertex-removal criteria of
//! [`crate::remove_features_below`] do not remove such a tongue when it is long: every vertex
//! triangle along it is large, only its width is small.
//!
//! This step works on widths. A **neck** of ring `R` is a vertex `p_i` and the closest point
//! `q` of a non-incident edge `(p_j, p_{j+1})` of the same ring with `|p_i − q| < w`. The chord
//! `p_i q` splits the ring into two closed polygons; the **piece** is the one of smaller
//! area. The piece is cut off — its boundary path replaced by the chord — when
//!
//! 1. it is thin: its mean width `2A/P` (area `A`, perimeter `P` including the chord; `w` for
//!    a long strip of width `w`) is below `w`,
//! 2. it is small: `A ≤` [`NeckOptions::max_piece_share`] of the ring's area,
//! 3. the chord meets no other boundary edge except at its ends, and no other ring lies inside
//!    the piece (an island in a narrow bay keeps the bay),
//! 4. the ring itself is not thin (`2A/P ≥ w` for the whole ring: an island narrower than a
//!    cell is left to the hole filter).
//!
//! A **sharp tip** — a vertex whose two edges make a wedge of angle `φ` below
//! [`NeckOptions::tip_angle`] (θ₋ = 40°: such a vertex cannot be a corner of an admissible
//! block) — is a neck too: it is `w` wide at depth `d = w / (2 sin(φ/2))`, and when both edges
//! are longer than `d` the chord there replaces the tip (a cape loses, a notch gains the
//! triangle `½ d² sin φ`).
//!
//! On the outer ring a piece of region material is a **spit** (peninsula, barrier island
//! attached at one end: the region loses its area) and a piece of exterior is an **inlet**
//! (river mouth, fjord, narrow bay: the region gains it); on a hole the roles swap. The
//! candidates of one round are applied greedily, largest piece first, while their boundary
//! paths do not overlap; rounds repeat until no neck is left ([`NeckOptions::max_rounds`]).
//! If the combined result of a round failed validation (two chords crossing, which non-
//! interleaved chords of a valid ring cannot do), the round is redone one cut at a time.
//!
//! This is the "chordal axis" idea of Prasad (1997, "Morphological analysis of shapes",
//! CNLS Newsletter 139, Los Alamos) — chords between boundary points closer than a scale mark
//! the narrow parts of a shape — used here as a cut-off at the cell scale: our addition, not in
//! the source documents. Work: `O(n log n + n·k)` per round with an R*-tree of the edges (`k`
//! edges within `w` of a vertex).

use glam::DVec2;
use unamalla_mesh::geometry::open_segment_hits;
use unamalla_mesh::{Location, Polygon, Region, RingId, SegmentIndex};

use crate::ContourError;

/// Options of [`cut_narrow_necks`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct NeckOptions {
    /// Neck width `w` (region units): chords shorter than this mark a neck; pieces with a mean
    /// width `2A/P` below it are cut off.
    pub width: f64,
    /// Largest piece, as a share of its ring's area (default 0.02).
    pub max_piece_share: f64,
    /// Rounds of cutting (default 8): a round applies every non-overlapping cut.
    pub max_rounds: usize,
    /// Wedge angle (radians) below which a sharp tip whose two edges are longer than the
    /// truncation depth is truncated where it is `width` wide (default 40°, the critical angle
    /// θ₋ of the decomposition below which a vertex cannot be an admissible block corner;
    /// 0 disables).
    pub tip_angle: f64,
}

impl NeckOptions {
    /// Necks narrower than `width`, with the default shares and rounds.
    pub fn new(width: f64) -> Self {
        Self {
            width,
            max_piece_share: 0.02,
            max_rounds: 8,
            tip_angle: 40f64.to_radians(),
        }
    }
    /// The same options with the tip angle `radians` ([`NeckOptions::tip_angle`]).
    pub fn with_tip_angle(self, radians: f64) -> Self {
        Self {
            tip_angle: radians,
            ..self
        }
    }
}

/// What a cut removed or filled.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum NeckKind {
    /// Region material cut away (a spit, a peninsula narrower than the neck width).
    Spit,
    /// Exterior filled in (an inlet, a river mouth, a fjord narrower than the neck width).
    Inlet,
}

/// One neck cut made by [`cut_narrow_necks`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct NeckCut {
    /// The ring that was cut (hole numbers as in the input region).
    #[serde(skip)]
    pub ring: RingId,
    /// Spit or inlet.
    pub kind: NeckKind,
    /// The chord's length (the neck's width).
    pub width: f64,
    /// The piece's area (always ≥ 0; a spit lowers the region's area by it, an inlet raises it).
    pub area: f64,
    /// The chord's midpoint.
    pub at: DVec2,
    /// Ring vertices removed by the cut.
    pub vertices_removed: usize,
}

impl std::fmt::Display for NeckCut {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let what = match self.kind {
            NeckKind::Spit => "cut off a spit",
            NeckKind::Inlet => "filled an inlet",
        };
        write!(
            f,
            "{what} of area {:.4e} behind a neck {:.3e} wide at ({:.6}, {:.6}) on the {} ({} vertices)",
            self.area,
            self.width,
            self.at.x,
            self.at.y,
            match self.ring {
                RingId::Outer => "outer ring".to_string(),
                RingId::Hole(k) => format!("hole {k}"),
            },
            self.vertices_removed
        )
    }
}

/// A candidate cut on ring `ring`: the `removed` vertices after `keep` (cyclically) are
/// replaced by `insert` (if any).
#[derive(Debug, Clone, Copy)]
struct Candidate {
    ring: usize,
    /// Kept vertex before the removed run.
    keep: usize,
    /// Number of vertices removed after `keep`.
    removed: usize,
    /// Point inserted after `keep` (the chord's end on an edge), unless it is a ring vertex.
    insert: Option<DVec2>,
    /// A sharp tip truncated: the chord's two ends, inserted after `keep` in ring order (then
    /// `insert` is `None` and `removed` is 1: the tip vertex).
    tip: Option<(DVec2, DVec2)>,
    /// The chord's ends.
    chord: (DVec2, DVec2),
    /// Area of the piece.
    area: f64,
    /// Signed (shoelace) area of the piece, traversed in the ring's direction: positive for
    /// region material (the region lies left of every boundary edge).
    signed_area: f64,
}

impl Candidate {
    /// Whether vertex `v` of this ring is removed or is a vertex next to the removed run.
    fn touches(&self, v: usize, n: usize) -> bool {
        (v + n - self.keep) % n <= self.removed + 1
    }
}

/// Cuts the spits and inlets of `region` narrower than `opts.width` at their necks (see the
/// module documentation). Returns the new region and the cuts made (none: the region
/// unchanged).
///
/// Errors: a width that is not finite and > 0, a share outside (0, 0.5].
pub fn cut_narrow_necks(
    region: &Region,
    opts: &NeckOptions,
) -> Result<(Region, Vec<NeckCut>), ContourError> {
    if !(opts.width.is_finite() && opts.width > 0.0) {
        return Err(ContourError::InvalidParameter {
            name: "neck width",
            value: opts.width,
            reason: "the neck width must be finite and > 0",
        });
    }
    if !(opts.max_piece_share > 0.0 && opts.max_piece_share <= 0.5) {
        return Err(ContourError::InvalidParameter {
            name: "max_piece_share",
            value: opts.max_piece_share,
            reason: "the largest piece must be a share in (0, 0.5] of its ring",
        });
    }
    let mut rings: Vec<Vec<DVec2>> = region.rings().map(|r| r.points().to_vec()).collect();
    let mut cuts = Vec::new();
    let mut current = region.clone();
    for _ in 0..opts.max_rounds {
        let index = SegmentIndex::new(rings.clone());
        let mut cands = candidates(&rings, &index, opts);
        if cands.is_empty() {
            break;
        }
        // largest first; ties by ring and vertex (deterministic)
        cands.sort_by(|a, b| {
            b.area
                .total_cmp(&a.area)
                .then(a.ring.cmp(&b.ring))
                .then(a.keep.cmp(&b.keep))
                .then(a.removed.cmp(&b.removed))
        });
        let mut chosen: Vec<Candidate> = Vec::new();
        for c in &cands {
            let n = rings[c.ring].len();
            let overlaps = chosen.iter().any(|o| {
                o.ring == c.ring && (0..=c.removed + 1).any(|k| o.touches((c.keep + k) % n, n))
            });
            if !overlaps {
                chosen.push(*c);
            }
        }
        let (next, chosen) = match build(&apply(&rings, &chosen)) {
            Some(r) => (r, chosen),
            None => {
                // one cut at a time: the largest
                let one = vec![chosen[0]];
                match build(&apply(&rings, &one)) {
                    Some(r) => (r, one),
                    None => break,
                }
            }
        };
        for c in &chosen {
            cuts.push(NeckCut {
                ring: if c.ring == 0 {
                    RingId::Outer
                } else {
                    RingId::Hole(c.ring - 1)
                },
                kind: if c.signed_area > 0.0 {
                    NeckKind::Spit
                } else {
                    NeckKind::Inlet
                },
                width: c.chord.0.distance(c.chord.1),
                area: c.area,
                at: 0.5 * (c.chord.0 + c.chord.1),
                vertices_removed: c.removed,
            });
        }
        rings = next.rings().map(|r| r.points().to_vec()).collect();
        current = next;
    }
    Ok((current, cuts))
}

/// The rings with the cuts `chosen` applied (non-overlapping on each ring).
fn apply(rings: &[Vec<DVec2>], chosen: &[Candidate]) -> Vec<Vec<DVec2>> {
    rings
        .iter()
        .enumerate()
        .map(|(r, ring)| {
            let n = ring.len();
            let mut removed = vec![false; n];
            let mut insert_after: Vec<Option<DVec2>> = vec![None; n];
            let mut tips: Vec<Option<(DVec2, DVec2)>> = vec![None; n];
            for c in chosen.iter().filter(|c| c.ring == r) {
                for k in 1..=c.removed {
                    removed[(c.keep + k) % n] = true;
                }
                insert_after[c.keep] = c.insert;
                tips[c.keep] = c.tip;
            }
            let mut out = Vec::with_capacity(n + 2 * chosen.len());
            for v in 0..n {
                if !removed[v] {
                    out.push(ring[v]);
                    if let Some(q) = insert_after[v] {
                        out.push(q);
                    }
                    if let Some((u, w)) = tips[v] {
                        out.push(u);
                        out.push(w);
                    }
                }
            }
            out
        })
        .collect()
}

/// The region of `rings` (outer first), `None` if it is not valid.
fn build(rings: &[Vec<DVec2>]) -> Option<Region> {
    let mut it = rings.iter().cloned();
    let outer = it.next()?;
    Region::new(outer, it.collect()).ok()
}

/// Prefix sums of one ring (doubled, so any cyclic chain is a difference of two entries).
struct Chains<'a> {
    ring: &'a [DVec2],
    len: Vec<f64>,
    cross: Vec<f64>,
}

impl<'a> Chains<'a> {
    fn new(ring: &'a [DVec2]) -> Self {
        let n = ring.len();
        let mut len = vec![0.0; 2 * n + 1];
        let mut cross = vec![0.0; 2 * n + 1];
        for k in 0..2 * n {
            let (a, b) = (ring[k % n], ring[(k + 1) % n]);
            len[k + 1] = len[k] + a.distance(b);
            cross[k + 1] = cross[k] + a.perp_dot(b);
        }
        Self { ring, len, cross }
    }

    /// Signed area and perimeter of the closed polygon `p_s, p_{s+1}, …, p_e, x` (cyclic
    /// indices, `m = e − s` edges along the ring).
    fn piece(&self, s: usize, m: usize, x: DVec2) -> (f64, f64) {
        let n = self.ring.len();
        let (ps, pe) = (self.ring[s], self.ring[(s + m) % n]);
        let shoelace = self.cross[s + m] - self.cross[s] + pe.perp_dot(x) + x.perp_dot(ps);
        let perimeter = self.len[s + m] - self.len[s] + pe.distance(x) + x.distance(ps);
        (0.5 * shoelace, perimeter)
    }
}

/// Every admissible cut of the current rings (conditions 1–4 of the module documentation), at
/// most one per (ring, vertex): the largest.
fn candidates(rings: &[Vec<DVec2>], index: &SegmentIndex, opts: &NeckOptions) -> Vec<Candidate> {
    let w = opts.width;
    let mut out = Vec::new();
    for (r, ring) in rings.iter().enumerate() {
        let n = ring.len();
        if n < 3 {
            continue;
        }
        let chains = Chains::new(ring);
        let (ring_area, ring_perimeter) = {
            let (a, p) = chains.piece(0, n - 1, ring[n - 1]);
            (a.abs(), p)
        };
        if 2.0 * ring_area / ring_perimeter < w {
            continue; // the whole ring is thin (condition 4)
        }
        for i in 0..n {
            let p = ring[i];
            let mut best: Option<Candidate> = None;
            let reach = DVec2::splat(w);
            for e in index.candidates(p - reach, p + reach) {
                let j = e.edge;
                if e.ring != r || j == i || (j + 1) % n == i {
                    continue; // another ring, or an edge incident to p_i
                }
                let (a, b) = (ring[j], ring[(j + 1) % n]);
                let q = closest_on_segment(p, a, b);
                let width = p.distance(q);
                if !(width < w && width > 0.0) {
                    continue;
                }
                // forward piece p_i … p_j, q: removes p_{i+1..=j}, inserts q after p_i
                let m_f = (j + n - i) % n;
                let (sa_f, per_f) = chains.piece(i, m_f, q);
                // backward piece p_{j+1} … p_i, q: removes p_{j+1..=i−1}, inserts q after p_j
                let s_b = (j + 1) % n;
                let m_b = (i + n - s_b) % n;
                let (sa_b, per_b) = chains.piece(s_b, m_b, q);
                // the smaller piece: (signed area, perimeter, first chain vertex, chain edges,
                // kept vertex before the removed run, removed vertices, chord)
                let (signed, perimeter, start, edges, keep, removed, chord) =
                    if sa_f.abs() <= sa_b.abs() {
                        // q = p_j: p_j stays (one fewer removed, nothing inserted)
                        let removed = if q == a { m_f - 1 } else { m_f };
                        (sa_f, per_f, i, m_f, i, removed, (p, q))
                    } else {
                        // q = p_{j+1}: p_{j+1} stays (the run starts after it)
                        let (keep, removed) = if q == b { (s_b, m_b - 1) } else { (j, m_b) };
                        (sa_b, per_b, s_b, m_b, keep, removed, (q, p))
                    };
                let cand = Candidate {
                    ring: r,
                    keep,
                    removed,
                    insert: (q != a && q != b).then_some(q),
                    tip: None,
                    chord,
                    area: signed.abs(),
                    signed_area: signed,
                };
                let kept = n - cand.removed + usize::from(cand.insert.is_some());
                if cand.removed == 0 || kept < 4 || cand.area.is_nan() || cand.area <= 0.0 {
                    continue;
                }
                // conditions 1 and 2
                if 2.0 * cand.area / perimeter >= w || cand.area > opts.max_piece_share * ring_area
                {
                    continue;
                }
                if best.as_ref().is_some_and(|b| b.area >= cand.area) {
                    continue;
                }
                // condition 3
                let piece = (0..=edges)
                    .map(|k| ring[(start + k) % n])
                    .chain([q])
                    .collect();
                let incident = [i, (i + n - 1) % n, j];
                if !chord_clear(index, r, &incident, p, q) || encloses_other_ring(rings, r, piece) {
                    continue;
                }
                best = Some(cand);
            }
            if let Some(t) = tip_candidate(rings, index, r, i, opts) {
                if best.as_ref().is_none_or(|b| b.area < t.area) {
                    best = Some(t);
                }
            }
            out.extend(best);
        }
    }
    out
}

/// The truncation of a sharp tip at vertex `i` of ring `r`: the wedge between the two edges at
/// `p_i` has angle `φ < opts.tip_angle` (on the region's side or on the exterior's: a sharp
/// cape or a sharp notch); it is `w` wide at depth `d = w / (2 sin(φ/2))` from the tip, and the
/// chord there replaces `p_i` when both edges are longer than `d` (shorter edges leave the
/// neck to a neighbouring vertex's chord). Conditions 2 and 3 as for the other cuts.
fn tip_candidate(
    rings: &[Vec<DVec2>],
    index: &SegmentIndex,
    r: usize,
    i: usize,
    opts: &NeckOptions,
) -> Option<Candidate> {
    let ring = &rings[r];
    let n = ring.len();
    let (a, p, b) = (ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]);
    let (ea, eb) = (a - p, b - p);
    let (la, lb) = (ea.length(), eb.length());
    if !(la > 0.0 && lb > 0.0) {
        return None;
    }
    let phi = ea.perp_dot(eb).abs().atan2(ea.dot(eb));
    if !(phi > 0.0 && phi < opts.tip_angle) {
        return None;
    }
    let d = opts.width / (2.0 * (0.5 * phi).sin());
    if !(d < la && d < lb) {
        return None;
    }
    let (u, v) = (p + ea * (d / la), p + eb * (d / lb));
    // the triangle u, p, v in ring order (a → u → p → v → b)
    let signed = 0.5 * ((p - u).perp_dot(v - u));
    let ring_area = unamalla_mesh::region::signed_area(ring).abs();
    if signed.abs() > opts.max_piece_share * ring_area {
        return None;
    }
    let prev = (i + n - 1) % n;
    let clear =
        chord_clear(index, r, &[i, prev], u, v) && !encloses_other_ring(rings, r, vec![u, p, v]);
    clear.then_some(Candidate {
        ring: r,
        keep: prev,
        removed: 1,
        insert: None,
        tip: Some((u, v)),
        chord: (u, v),
        area: signed.abs(),
        signed_area: signed,
    })
}

/// The closest point of segment `ab` to `p` (exactly `a` or `b` at the ends).
fn closest_on_segment(p: DVec2, a: DVec2, b: DVec2) -> DVec2 {
    let d = b - a;
    let len2 = d.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    if t >= 1.0 {
        b
    } else if t <= 0.0 {
        a
    } else {
        a + t * d
    }
}

/// Condition 3, first half: the chord `u v` meets no boundary edge except the edges `skip` of
/// ring `r` (those incident to the chord's ends).
fn chord_clear(index: &SegmentIndex, r: usize, skip: &[usize], u: DVec2, v: DVec2) -> bool {
    !index.candidates(u, v).any(|e| {
        if e.ring == r && skip.contains(&e.edge) {
            return false;
        }
        let (a, b) = index.edge(e);
        open_segment_hits(u, v, a, b)
    })
}

/// Condition 3, second half: some ring other than `r` lies inside the piece (the rings are
/// disjoint and the chord crosses none, so one vertex of each tells).
fn encloses_other_ring(rings: &[Vec<DVec2>], r: usize, piece: Vec<DVec2>) -> bool {
    let poly = Polygon::from_points_unchecked(piece);
    rings
        .iter()
        .enumerate()
        .any(|(k, other)| k != r && poly.locate(other[0]) == Location::Inside)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(pts: &[(f64, f64)]) -> Vec<DVec2> {
        pts.iter().map(|&(x, y)| DVec2::new(x, y)).collect()
    }

    /// The 20 × 20 square with a feature on its top side between x = 10 and x = 10.5.
    fn square_with(top: &[(f64, f64)]) -> Vec<DVec2> {
        let mut p = vec![(0.0, 0.0), (20.0, 0.0), (20.0, 20.0)];
        p.extend_from_slice(top);
        p.push((0.0, 20.0));
        v(&p)
    }

    #[test]
    fn a_spit_half_a_cell_wide_is_cut_at_its_base() {
        // a 0.5 × 10 tongue on the square's top side: piece area 5, mean width
        // 2·5/(10 + 0.5 + 10 + 0.5) = 0.476 < 1, 5/405 = 1.2 % of the ring
        let ring = square_with(&[(10.5, 20.0), (10.5, 30.0), (10.0, 30.0), (10.0, 20.0)]);
        let region = Region::new(ring, vec![]).unwrap();
        assert!((region.area() - 405.0).abs() < 1e-12);
        let (out, cuts) = cut_narrow_necks(&region, &NeckOptions::new(1.0)).unwrap();
        assert_eq!(cuts.len(), 1, "{cuts:?}");
        let c = cuts[0];
        assert_eq!(c.kind, NeckKind::Spit);
        assert!((c.area - 5.0).abs() < 1e-12);
        assert!((c.width - 0.5).abs() < 1e-12);
        assert_eq!(c.vertices_removed, 2);
        assert!((out.area() - 400.0).abs() < 1e-12);
        assert!(out.outer().points().iter().all(|p| p.y <= 20.0));
    }

    #[test]
    fn an_inlet_half_a_cell_wide_is_filled() {
        // a 0.5 × 10 notch into the square: the region gains its 5 units of area
        let ring = square_with(&[(10.5, 20.0), (10.5, 10.0), (10.0, 10.0), (10.0, 20.0)]);
        let region = Region::new(ring, vec![]).unwrap();
        assert!((region.area() - 395.0).abs() < 1e-12);
        let (out, cuts) = cut_narrow_necks(&region, &NeckOptions::new(1.0)).unwrap();
        assert_eq!(cuts.len(), 1, "{cuts:?}");
        assert_eq!(cuts[0].kind, NeckKind::Inlet);
        assert!((cuts[0].area - 5.0).abs() < 1e-12);
        assert!((out.area() - 400.0).abs() < 1e-12);
    }

    #[test]
    fn a_neck_off_the_vertices_gets_an_inserted_point() {
        // a tongue whose base is narrower than its free end's width would suggest: the side
        // vertex (10.5, 22) is 0.5 from the edge x = 10, so the chord ends at (10, 22), on the
        // edge from (10, 30) to (10, 20); the piece above it is 0.5 × 8 = 4, plus nothing below
        let ring = square_with(&[
            (11.0, 20.0),
            (10.5, 22.0),
            (10.5, 30.0),
            (10.0, 30.0),
            (10.0, 20.0),
        ]);
        let region = Region::new(ring, vec![]).unwrap();
        let (out, cuts) = cut_narrow_necks(&region, &NeckOptions::new(0.75)).unwrap();
        assert!(!cuts.is_empty());
        // every cut is a spit; what is left above y = 20 is thinner than 0.75 nowhere but at
        // the base triangle (11,20), (10.5,22), (10,22), (10,20): area 1.5
        assert!(cuts.iter().all(|c| c.kind == NeckKind::Spit));
        let removed: f64 = cuts.iter().map(|c| c.area).sum();
        assert!((region.area() - out.area() - removed).abs() < 1e-9);
        assert!(out.area() >= 400.0 - 1e-9);
        assert!(out.outer().points().iter().all(|p| p.y <= 22.0 + 1e-12));
    }

    #[test]
    fn wide_features_thin_rings_and_enclosed_holes_are_kept() {
        // a spit 3 wide (wider than the neck width 1)
        let wide = square_with(&[(13.0, 20.0), (13.0, 30.0), (10.0, 30.0), (10.0, 20.0)]);
        let region = Region::new(wide, vec![]).unwrap();
        let (out, cuts) = cut_narrow_necks(&region, &NeckOptions::new(1.0)).unwrap();
        assert!(cuts.is_empty());
        assert_eq!(out, region);
        // a strip 0.5 wide as the whole region
        let strip = v(&[(0.0, 0.0), (30.0, 0.0), (30.0, 0.5), (0.0, 0.5)]);
        let region = Region::new(strip, vec![]).unwrap();
        assert!(cut_narrow_necks(&region, &NeckOptions::new(1.0))
            .unwrap()
            .1
            .is_empty());
        // a 0.8-wide spit holding a small lake: cutting it would put the lake outside
        let ring = square_with(&[(10.8, 20.0), (10.8, 30.0), (10.0, 30.0), (10.0, 20.0)]);
        let lake = v(&[(10.3, 25.0), (10.3, 25.2), (10.5, 25.2), (10.5, 25.0)]);
        let region = Region::new(ring, vec![lake]).unwrap();
        assert!(cut_narrow_necks(&region, &NeckOptions::new(1.0))
            .unwrap()
            .1
            .is_empty());
    }

    #[test]
    fn a_sharp_cape_is_truncated_where_it_is_one_width_wide() {
        // isosceles triangle with a 30° apex at the origin and legs of 100: the apex is cut at
        // depth d = w / (2 sin 15°) along both legs; the tip triangle has area ½ d² sin 30°
        let apex = 30f64.to_radians();
        let ring = vec![
            DVec2::ZERO,
            DVec2::new(100.0, 0.0),
            DVec2::new(100.0 * apex.cos(), 100.0 * apex.sin()),
        ];
        let region = Region::new(ring, vec![]).unwrap();
        let w = 1.0;
        let d = w / (2.0 * (0.5 * apex).sin());
        let (out, cuts) = cut_narrow_necks(&region, &NeckOptions::new(w)).unwrap();
        assert_eq!(cuts.len(), 1, "{cuts:?}");
        assert_eq!(cuts[0].kind, NeckKind::Spit);
        assert!((cuts[0].width - w).abs() < 1e-12);
        let tip_area = 0.5 * d * d * apex.sin();
        assert!((cuts[0].area - tip_area).abs() < 1e-12);
        assert!((region.area() - out.area() - tip_area).abs() < 1e-9);
        assert_eq!(out.outer().len(), 4);
        assert!(out.outer().points().iter().all(|p| p.length() >= d - 1e-9));
        // the 75° corners stay; with the tip angle off nothing is cut
        let off = NeckOptions {
            tip_angle: 0.0,
            ..NeckOptions::new(w)
        };
        assert!(cut_narrow_necks(&region, &off).unwrap().1.is_empty());
    }

    #[test]
    fn bad_widths_are_errors() {
        let region = Region::new(square_with(&[]), vec![]).unwrap();
        for w in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(cut_narrow_necks(&region, &NeckOptions::new(w)).is_err());
        }
    }
}
