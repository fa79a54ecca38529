//! Work pieces of the recursive decomposition: a ring (possibly weakly simple after a hole was
//! bridged to it) with holes, every edge tagged as original boundary or as a cut; cut
//! admissibility inside a piece (exact), and the split / merge operations.

use unamalla_mesh::geometry::open_segment_hits;
use unamalla_mesh::{DVec2, SegmentIndex};

use crate::geom::in_wedge;

/// What an edge of a piece is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Tag {
    /// A piece of region ring `r` (0 = outer, k = hole k−1).
    Boundary(usize),
    /// Cut number `c`.
    Cut(usize),
}

/// An open ring with a tag per edge (`tags[i]` is the edge `pts[i] → pts[i+1]`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Ring {
    pub pts: Vec<DVec2>,
    pub tags: Vec<Tag>,
}

impl Ring {
    /// Appends the exact content of this ring to a cache key: its length, then per vertex the
    /// coordinate bits and the leaving edge's tag — `0, b` for region boundary `b`, and
    /// whatever `cut` writes for a cut (the caches differ in how they name cuts).
    pub(crate) fn push_key(&self, key: &mut Vec<u64>, mut cut: impl FnMut(usize, &mut Vec<u64>)) {
        key.push(self.len() as u64);
        for (p, t) in self.pts.iter().zip(&self.tags) {
            key.push(p.x.to_bits());
            key.push(p.y.to_bits());
            match *t {
                Tag::Boundary(b) => key.extend([0, b as u64]),
                Tag::Cut(c) => cut(c, key),
            }
        }
    }

    pub fn len(&self) -> usize {
        self.pts.len()
    }
    pub fn p(&self, i: usize) -> DVec2 {
        self.pts[i % self.pts.len()]
    }
    pub fn prev(&self, i: usize) -> DVec2 {
        let n = self.pts.len();
        self.pts[(i + n - 1) % n]
    }
    pub fn next(&self, i: usize) -> DVec2 {
        self.pts[(i + 1) % self.pts.len()]
    }
}

/// A piece: outer ring (counter-clockwise, possibly weakly simple) and holes (clockwise).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Piece {
    pub outer: Ring,
    pub holes: Vec<Ring>,
}

/// Position of a cut endpoint on a ring.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Pos {
    /// At vertex `i`.
    Vertex(usize),
    /// At point `x` strictly inside edge `i → i+1` (not yet a vertex).
    OnEdge(usize, DVec2),
}

/// A cut endpoint: ring `ring` of the piece (0 = outer, k = hole k−1) and a position on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct End {
    pub ring: usize,
    pub pos: Pos,
}

impl Piece {
    /// A piece without points (a placeholder for a child that is split at once).
    pub fn empty() -> Self {
        Piece {
            outer: Ring {
                pts: Vec::new(),
                tags: Vec::new(),
            },
            holes: Vec::new(),
        }
    }
    pub fn ring(&self, k: usize) -> &Ring {
        if k == 0 {
            &self.outer
        } else {
            &self.holes[k - 1]
        }
    }
    fn ring_mut(&mut self, k: usize) -> &mut Ring {
        if k == 0 {
            &mut self.outer
        } else {
            &mut self.holes[k - 1]
        }
    }
    pub fn rings(&self) -> impl Iterator<Item = &Ring> {
        std::iter::once(&self.outer).chain(self.holes.iter())
    }
    pub fn point(&self, e: End) -> DVec2 {
        match e.pos {
            Pos::Vertex(i) => self.ring(e.ring).p(i),
            Pos::OnEdge(_, x) => x,
        }
    }
    /// The chain `prev → cur → next` around an endpoint.
    pub fn chain(&self, e: End) -> (DVec2, DVec2, DVec2) {
        let r = self.ring(e.ring);
        match e.pos {
            Pos::Vertex(i) => (r.prev(i), r.p(i), r.next(i)),
            Pos::OnEdge(i, x) => (r.p(i), x, r.next(i)),
        }
    }
    pub fn index(&self) -> SegmentIndex {
        SegmentIndex::new(self.rings().map(|r| r.pts.clone()).collect())
    }
    pub fn area(&self) -> f64 {
        self.rings().map(|r| crate::geom::signed_area(&r.pts)).sum()
    }

    /// `true` if the open segment between the two endpoints lies in the open piece (exact):
    /// the segment leaves each endpoint into the region-side wedge and its open part meets no
    /// edge. Endpoints inside edges are checked against the two half-edges they create.
    pub fn admissible(&self, idx: &SegmentIndex, e1: End, e2: End) -> bool {
        self.admissible_near(e1, e2, &|p, q, test| {
            idx.candidates(p, q)
                .all(|er| test((er.ring, er.edge), idx.edge(er)))
        })
    }

    /// [`Piece::admissible`] without an index, for a single test: the piece's edges are
    /// scanned, those whose bounding box misses the segment's skipped (the index's
    /// candidates are those whose box meets it; the others cannot meet the segment), so the
    /// same edges decide.
    pub fn admissible_scan(&self, e1: End, e2: End) -> bool {
        self.admissible_near(e1, e2, &|p, q, test| {
            let (lo, hi) = (p.min(q), p.max(q));
            self.rings().enumerate().all(|(r, ring)| {
                (0..ring.len()).all(|i| {
                    let (a, b) = (ring.p(i), ring.next(i));
                    let apart = a.max(b).cmplt(lo).any() || a.min(b).cmpgt(hi).any();
                    apart || test((r, i), (a, b))
                })
            })
        })
    }

    /// [`Piece::admissible`] with the edges that may meet the open segment `pq`: `near(p, q,
    /// test)` calls `test((ring, edge), (start, end))` on each of them (at least) while it
    /// returns `true`, and says whether all passed.
    #[allow(clippy::type_complexity)]
    fn admissible_near(
        &self,
        e1: End,
        e2: End,
        near: &dyn Fn(DVec2, DVec2, &mut dyn FnMut((usize, usize), (DVec2, DVec2)) -> bool) -> bool,
    ) -> bool {
        let p = self.point(e1);
        let q = self.point(e2);
        if p == q {
            return false;
        }
        let (a1, c1, b1) = self.chain(e1);
        let (a2, c2, b2) = self.chain(e2);
        if !in_wedge(a1, c1, b1, q) || !in_wedge(a2, c2, b2, p) {
            return false;
        }
        let host = |e: End| match e.pos {
            Pos::OnEdge(i, _) => Some((e.ring, i)),
            Pos::Vertex(_) => None,
        };
        let h1 = host(e1);
        let h2 = host(e2);
        if h1.is_some() && h1 == h2 {
            return false;
        }
        let clear = near(p, q, &mut |key, (a, b)| {
            Some(key) == h1 || Some(key) == h2 || !open_segment_hits(p, q, a, b)
        });
        if !clear {
            return false;
        }
        for (e, h) in [(e1, h1), (e2, h2)] {
            if let Some((r, i)) = h {
                let ring = self.ring(r);
                let x = self.point(e);
                if open_segment_hits(p, q, ring.p(i), x) || open_segment_hits(p, q, x, ring.next(i))
                {
                    return false;
                }
            }
        }
        true
    }

    /// Makes both endpoints vertices (inserting on-edge points), returning their vertex indices.
    pub fn insert_ends(&mut self, e1: End, e2: End) -> (usize, usize) {
        let i = self.insert(e1);
        let mut e2 = e2;
        if e1.ring == e2.ring {
            if let Pos::OnEdge(ei, _) = e1.pos {
                e2.pos = match e2.pos {
                    Pos::Vertex(k) if k > ei => Pos::Vertex(k + 1),
                    Pos::OnEdge(k, x) if k > ei => Pos::OnEdge(k + 1, x),
                    other => other,
                };
            }
        }
        let j = self.insert(e2);
        let i = match e2.pos {
            Pos::OnEdge(k, _) if e1.ring == e2.ring && i > k => i + 1,
            _ => i,
        };
        (i, j)
    }

    fn insert(&mut self, e: End) -> usize {
        match e.pos {
            Pos::Vertex(i) => i,
            Pos::OnEdge(i, x) => {
                let r = self.ring_mut(e.ring);
                let t = r.tags[i];
                r.pts.insert(i + 1, x);
                r.tags.insert(i + 1, t);
                i + 1
            }
        }
    }

    /// The two pieces and the end points of the cut `cut` from `e1` to `e2` (on the outer
    /// ring): what `insert_ends(e1, e2)` then `split` on a copy of the piece give, built for
    /// a piece without holes by walking the ring from one end to the other ([`Piece::arc`])
    /// instead of the copy and two insertions. With holes, or both ends inside one edge,
    /// the general path.
    pub fn split_between(&self, e1: End, e2: End, cut: usize) -> (Piece, Piece, (DVec2, DVec2)) {
        let one_edge = matches!(
            (e1.pos, e2.pos),
            (Pos::OnEdge(i, _), Pos::OnEdge(j, _)) if i == j
        );
        if e1.ring != 0 || e2.ring != 0 || one_edge || !self.holes.is_empty() {
            let mut m = self.clone();
            let (x, y) = m.insert_ends(e1, e2);
            let (a, b) = m.split(x, y, cut);
            return (a, b, (m.outer.p(x), m.outer.p(y)));
        }
        let piece = |outer| Piece {
            outer,
            holes: Vec::new(),
        };
        (
            piece(self.arc(e1, e2, cut)),
            piece(self.arc(e2, e1, cut)),
            (self.point(e1), self.point(e2)),
        )
    }

    /// The outer ring from `from` forward to `to` (vertices, or points inside edges, taking
    /// the tags of the edges they lie in), closed by an edge tagged cut `cut`: the child of
    /// `split` after `insert_ends`, where an inserted point follows the vertex starting its
    /// edge and continues that edge's tag.
    fn arc(&self, from: End, to: End, cut: usize) -> Ring {
        let r = &self.outer;
        let n = r.len();
        // the first vertex of the ring walked, and the last
        let (first, lead) = match from.pos {
            Pos::Vertex(i) => (i, None),
            Pos::OnEdge(i, x) => ((i + 1) % n, Some((x, r.tags[i]))),
        };
        let (last, tail) = match to.pos {
            Pos::Vertex(j) => (j, None),
            Pos::OnEdge(j, x) => (j, Some(x)),
        };
        let len = (last + n - first) % n + 1 + lead.is_some() as usize + tail.is_some() as usize;
        let mut pts = Vec::with_capacity(len);
        let mut tags = Vec::with_capacity(len);
        if let Some((x, t)) = lead {
            pts.push(x);
            tags.push(t);
        }
        let mut k = first;
        loop {
            pts.push(r.pts[k]);
            if k == last {
                match tail {
                    Some(x) => {
                        tags.push(r.tags[k]);
                        pts.push(x);
                        tags.push(Tag::Cut(cut));
                    }
                    None => tags.push(Tag::Cut(cut)),
                }
                break;
            }
            tags.push(r.tags[k]);
            k = (k + 1) % n;
        }
        Ring { pts, tags }
    }

    /// Splits the outer ring at vertices `i` and `j` by cut `cut`; holes go to the child that
    /// contains them. Returns `(A, B)` with A = `i … j` + cut, B = `j … i` + cut.
    pub fn split(&self, i: usize, j: usize, cut: usize) -> (Piece, Piece) {
        let r = &self.outer;
        let n = r.len();
        let take = |from: usize, to: usize| -> Ring {
            // the vertices `from` … `to`, cyclically
            let len = (to + n - from) % n + 1;
            let mut pts = Vec::with_capacity(len);
            let mut tags = Vec::with_capacity(len);
            let mut k = from;
            loop {
                pts.push(r.pts[k]);
                if k == to {
                    tags.push(Tag::Cut(cut));
                    break;
                }
                tags.push(r.tags[k]);
                k = (k + 1) % n;
            }
            Ring { pts, tags }
        };
        let a = take(i, j);
        let b = take(j, i);
        let mut pa = Piece {
            outer: a,
            holes: Vec::new(),
        };
        let mut pb = Piece {
            outer: b,
            holes: Vec::new(),
        };
        for h in &self.holes {
            // the hole is disjoint from the cut, so any of its vertices decides
            let inside_a = unamalla_mesh::geometry::locate_in_ring(&pa.outer.pts, h.pts[0])
                == unamalla_mesh::Location::Inside;
            if inside_a {
                pa.holes.push(h.clone());
            } else {
                pb.holes.push(h.clone());
            }
        }
        (pa, pb)
    }

    /// Bridges hole `hole` (1-based ring number) to the outer ring by cut `cut` between outer
    /// vertex `i` and hole vertex `k`. Returns the positions in the new outer ring of the two
    /// copies of the hole vertex and of the outer vertex: `(q_first, q_second, p_second)`;
    /// `p_first = i`.
    pub fn merge(&mut self, i: usize, hole: usize, k: usize, cut: usize) -> (usize, usize, usize) {
        let h = self.holes.remove(hole - 1);
        let o = &self.outer;
        let nh = h.len();
        let mut pts = Vec::with_capacity(o.len() + nh + 2);
        let mut tags = Vec::with_capacity(o.len() + nh + 2);
        pts.extend_from_slice(&o.pts[..=i]);
        tags.extend_from_slice(&o.tags[..i]);
        tags.push(Tag::Cut(cut));
        for s in 0..=nh {
            pts.push(h.pts[(k + s) % nh]);
            if s < nh {
                tags.push(h.tags[(k + s) % nh]);
            }
        }
        tags.push(Tag::Cut(cut));
        pts.push(o.pts[i]);
        tags.push(o.tags[i]);
        pts.extend_from_slice(&o.pts[i + 1..]);
        tags.extend_from_slice(&o.tags[i + 1..]);
        self.outer = Ring { pts, tags };
        (i + 1, i + 1 + nh, i + 2 + nh)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    fn square_with_hole() -> Piece {
        let outer = vec![v(0., 0.), v(4., 0.), v(4., 4.), v(0., 4.)];
        // clockwise hole
        let hole = vec![v(1., 1.), v(1., 3.), v(3., 3.), v(3., 1.)];
        Piece {
            outer: Ring {
                tags: vec![Tag::Boundary(0); 4],
                pts: outer,
            },
            holes: vec![Ring {
                tags: vec![Tag::Boundary(1); 4],
                pts: hole,
            }],
        }
    }

    /// `split_between` gives what a copy with `insert_ends` and `split` gives, for every pair
    /// of ends (vertices, points inside edges) of a hexagon.
    #[test]
    fn split_between_matches_insert_then_split() {
        let pts = vec![
            v(0., 0.),
            v(2., -1.),
            v(4., 0.),
            v(4., 3.),
            v(2., 4.),
            v(0., 3.),
        ];
        let n = pts.len();
        let piece = Piece {
            outer: Ring {
                tags: (0..n)
                    .map(|i| {
                        if i % 2 == 0 {
                            Tag::Boundary(0)
                        } else {
                            Tag::Cut(i)
                        }
                    })
                    .collect(),
                pts: pts.clone(),
            },
            holes: Vec::new(),
        };
        let ends: Vec<End> = (0..n)
            .flat_map(|i| {
                let (a, b) = (pts[i], pts[(i + 1) % n]);
                [Pos::Vertex(i), Pos::OnEdge(i, a + 0.3 * (b - a))]
            })
            .map(|pos| End { ring: 0, pos })
            .collect();
        for &e1 in &ends {
            for &e2 in &ends {
                if e1 == e2 {
                    continue;
                }
                let mut m = piece.clone();
                let (x, y) = m.insert_ends(e1, e2);
                let (a, b) = m.split(x, y, 99);
                let want = (a, b, (m.outer.p(x), m.outer.p(y)));
                assert_eq!(piece.split_between(e1, e2, 99), want, "{e1:?} {e2:?}");
            }
        }
    }

    /// `admissible_scan` answers as `admissible` with an index, for every pair of ends
    /// (vertices, points inside edges) of a square with a square hole.
    #[test]
    fn scanned_admissibility_matches_the_indexed_one() {
        let p = square_with_hole();
        let idx = p.index();
        let ends: Vec<End> = p
            .rings()
            .enumerate()
            .flat_map(|(r, ring)| {
                (0..ring.len()).flat_map(move |i| {
                    let (a, b) = (ring.p(i), ring.next(i));
                    [Pos::Vertex(i), Pos::OnEdge(i, a + 0.5 * (b - a))]
                        .map(|pos| End { ring: r, pos })
                })
            })
            .collect();
        let mut admitted = 0;
        for &e1 in &ends {
            for &e2 in &ends {
                let want = p.admissible(&idx, e1, e2);
                assert_eq!(p.admissible_scan(e1, e2), want, "{e1:?} {e2:?}");
                admitted += want as usize;
            }
        }
        assert!(admitted > 10, "{admitted}");
    }

    #[test]
    fn merge_then_split_gives_two_simple_pieces() {
        let mut p = square_with_hole();
        let idx = p.index();
        let e1 = End {
            ring: 0,
            pos: Pos::OnEdge(0, v(2., 0.)),
        };
        let e2 = End {
            ring: 1,
            pos: Pos::OnEdge(3, v(2., 1.)),
        };
        assert!(p.admissible(&idx, e1, e2));
        // a segment through the hole is not admissible
        let bad = End {
            ring: 0,
            pos: Pos::OnEdge(2, v(2., 4.)),
        };
        assert!(!p.admissible(&idx, e1, bad));
        let (i, k) = p.insert_ends(e1, e2);
        assert_eq!(p.outer.p(i), v(2., 0.));
        assert_eq!(p.holes[0].p(k), v(2., 1.));
        let area = p.area();
        let (q1, q2, p2) = p.merge(i, 1, k, 0);
        assert_eq!(p.outer.p(q1), v(2., 1.));
        assert_eq!(p.outer.p(q2), v(2., 1.));
        assert_eq!(p.outer.p(p2), v(2., 0.));
        assert!((p.area() - area).abs() < 1e-12);
        // second cut from the hole's top to the outer top
        let idx = p.index();
        let top_h = p.outer.pts.iter().position(|&x| x == v(1., 3.)).unwrap();
        let e3 = End {
            ring: 0,
            pos: Pos::Vertex(top_h),
        };
        let e4 = End {
            ring: 0,
            pos: Pos::Vertex(p.outer.pts.iter().position(|&x| x == v(0., 4.)).unwrap()),
        };
        assert!(p.admissible(&idx, e3, e4));
        let (a, b) = p.split(
            top_h,
            p.outer.pts.iter().position(|&x| x == v(0., 4.)).unwrap(),
            1,
        );
        assert!((a.area() + b.area() - area).abs() < 1e-12);
        assert!(a.area() > 0.0 && b.area() > 0.0);
    }
}
