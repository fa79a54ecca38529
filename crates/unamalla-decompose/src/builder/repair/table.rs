//! The tables of the split search: the end angles of every candidate cut of a host ring
//! ([`CutTable`]) and the cheap screen of children that cannot be good ([`ChildScreen`]).

use std::sync::atomic::{AtomicU64, AtomicU8, Ordering};

use unamalla_mesh::DVec2;

use crate::builder::AngleScreen;
use crate::geom::{left_angle, match_vertices, ring_angles};
use crate::piece::{End, Piece, Pos, Ring, Tag};

/// What the split searches of one host ring and of its children (the second cuts of a
/// re-split, [`Builder::best_split3`](crate::builder::Builder::best_split3), search children of the host again and again) need to
/// know about a candidate cut, each computed once: the new angles at its ends in tier 1 — at
/// a vertex towards the cut's other end, and at the foot of a perpendicular from a vertex
/// towards that vertex, as [`Builder::end_angles`](crate::builder::Builder::end_angles) computes them — or that the tier's
/// [`AngleScreen`] rejects one (then every cut with that end is rejected: the screen rejects
/// a cut when it rejects an angle at either end); and whether the cut is admissible in the
/// host.
///
/// Exact: a child's vertex that has the host vertex's point and neighbours, bit for bit,
/// has the same angles towards the same point (the same `atan2` on the same numbers); a
/// child's edge with a host edge's end points has the same foot of the perpendicular from
/// the same point (`targets_on_ring` computes it from those three points alone), and the
/// same angles there. [`CutTable::locate`] finds those vertices and edges. For admissibility
/// see [`CutTable::admissible`].
pub(super) struct CutTable<'a> {
    host: &'a [DVec2],
    /// The screen of tier 1.
    screen: AngleScreen,
    /// `[i·n + j]`: the two angles at host vertex `i` towards host vertex `j`, as bits;
    /// 0 while not computed (an angle is in (0, 2π] or NaN, never +0.0), [`REJECTED`] first
    /// if the screen rejects one of them.
    to_vertex: Vec<[AtomicU64; 2]>,
    /// `[i·n + e]`: the two angles at host vertex `i` towards the foot of its perpendicular
    /// on host edge `e`, then the two at that foot towards vertex `i` (or [`REJECTED`]).
    to_foot: Vec<[AtomicU64; 4]>,
    /// The host as a piece, and its edge index (built when first needed).
    piece: Piece,
    index: std::sync::OnceLock<unamalla_mesh::SegmentIndex>,
    /// `[i·n + j]`, `[i·n + e]`: whether the cut from host vertex `i` to vertex `j`, or to
    /// the foot of its perpendicular on edge `e`, is admissible in the host: 0 not known
    /// yet, 1 no, 2 yes.
    admits_vertex: Vec<AtomicU8>,
    admits_foot: Vec<AtomicU8>,
}

/// The bits an [`CutTable`] entry starts with when the screen rejects it: those of −1, never
/// an angle.
pub(super) const REJECTED: u64 = 0xbff0_0000_0000_0000;

/// Where the vertices and edges of a ring are those of an [`CutTable`] host: host vertex
/// of each ring vertex with the same point and neighbours, host edge of each ring edge with
/// the same end points (`usize::MAX`: none).
pub(super) struct HostMatch {
    pub(super) vertex: Vec<usize>,
    pub(super) edge: Vec<usize>,
}

impl<'a> CutTable<'a> {
    /// An empty table of `host`'s angles, screened by `screen` (tier 1's).
    pub(super) fn new(host: &'a [DVec2], screen: AngleScreen) -> Self {
        let n2 = host.len() * host.len();
        Self {
            host,
            screen,
            to_vertex: (0..n2).map(|_| Default::default()).collect(),
            to_foot: (0..n2).map(|_| Default::default()).collect(),
            piece: Piece {
                outer: Ring {
                    pts: host.to_vec(),
                    tags: vec![Tag::Boundary(0); host.len()],
                },
                holes: Vec::new(),
            },
            index: std::sync::OnceLock::new(),
            admits_vertex: (0..n2).map(|_| AtomicU8::new(0)).collect(),
            admits_foot: (0..n2).map(|_| AtomicU8::new(0)).collect(),
        }
    }

    /// Whether the cut from host vertex `i` to `to` (a host vertex, or the foot of the
    /// perpendicular from vertex `i` on a host edge) is admissible in the host
    /// ([`Piece::admissible`], computed once).
    ///
    /// In a child of the host whose vertex there has the host's neighbours (and whose edge
    /// holding a foot is the host's), the cut is admissible exactly when it is admissible in
    /// the host and its open segment meets none of the child's edges that are not host edges
    /// (the cut that made the child, or part of a host edge it split): the wedges at the ends
    /// are the same; a segment inside the child is inside the host, meets no child edge and
    /// so none of those; and a segment inside the host that meets no child edge outside the
    /// host's stays on one side of the cut, the child's side at its ends.
    pub(super) fn admissible(&self, i: usize, to: End) -> bool {
        let n = self.host.len();
        let slot = match to.pos {
            Pos::Vertex(j) => &self.admits_vertex[i * n + j],
            Pos::OnEdge(e, _) => &self.admits_foot[i * n + e],
        };
        match slot.load(Ordering::Relaxed) {
            1 => false,
            2 => true,
            _ => {
                let idx = self.index.get_or_init(|| self.piece.index());
                let from = End {
                    ring: 0,
                    pos: Pos::Vertex(i),
                };
                let a = self.piece.admissible(idx, from, to);
                slot.store(if a { 2 } else { 1 }, Ordering::Relaxed);
                a
            }
        }
    }

    /// The vertices and edges of `ring` that are the host's (see [`HostMatch`]).
    pub(super) fn locate(&self, ring: &Ring) -> HostMatch {
        let (n, m) = (ring.len(), self.host.len());
        let same =
            |a: DVec2, b: DVec2| a.x.to_bits() == b.x.to_bits() && a.y.to_bits() == b.y.to_bits();
        // match from the host vertex of the ring's first point (or second, when the first
        // is a point inserted by a cut)
        let start = ring
            .pts
            .iter()
            .take(2)
            .find_map(|&p| self.host.iter().position(|&h| same(h, p)))
            .unwrap_or(0);
        let map = match_vertices(&ring.pts, self.host, start);
        let vertex = (0..n)
            .map(|k| {
                let j = map[k];
                let kept = j != usize::MAX
                    && same(self.host[(j + m - 1) % m], ring.prev(k))
                    && same(self.host[(j + 1) % m], ring.next(k));
                if kept {
                    j
                } else {
                    usize::MAX
                }
            })
            .collect();
        let edge = (0..n)
            .map(|k| {
                let (j, l) = (map[k], map[(k + 1) % n]);
                if j != usize::MAX && l == (j + 1) % m {
                    j
                } else {
                    usize::MAX
                }
            })
            .collect();
        HostMatch { vertex, edge }
    }

    /// Reads the angles stored at `slot`, or stores and returns those `compute` gives;
    /// `None` if they are (or `compute` finds them) rejected by the screen.
    fn cached<const K: usize>(
        slot: &[AtomicU64; K],
        compute: impl FnOnce() -> Option<[f64; K]>,
    ) -> Option<[f64; K]> {
        let bits = slot.each_ref().map(|a| a.load(Ordering::Relaxed));
        if bits[0] == REJECTED {
            return None;
        }
        if bits.iter().all(|&b| b != 0) {
            return Some(bits.map(f64::from_bits));
        }
        // another thread may compute the same angles at the same time: the same values
        let v = compute();
        match v {
            None => slot[0].store(REJECTED, Ordering::Relaxed),
            Some(v) => {
                for (a, x) in slot.iter().zip(v) {
                    a.store(x.to_bits(), Ordering::Relaxed);
                }
            }
        }
        v
    }

    /// The angles at host vertex `i` towards host vertex `j`, `None` if the screen rejects
    /// one.
    pub(super) fn vertex_angles(&self, i: usize, j: usize) -> Option<[f64; 2]> {
        let h = self.host;
        let n = h.len();
        Self::cached(&self.to_vertex[i * n + j], || {
            let (prev, p, next, q) = (h[(i + n - 1) % n], h[i], h[(i + 1) % n], h[j]);
            let screened =
                self.screen.surely_below(q, p, next) || self.screen.surely_below(prev, p, q);
            (!screened).then(|| [left_angle(q, p, next), left_angle(prev, p, q)])
        })
    }

    /// The angles at host vertex `i` towards `x`, the foot of its perpendicular on host edge
    /// `e`, then at `x` towards vertex `i`; `None` if the screen rejects one.
    pub(super) fn foot_angles(&self, i: usize, e: usize, x: DVec2) -> Option<[f64; 4]> {
        let h = self.host;
        let n = h.len();
        Self::cached(&self.to_foot[i * n + e], || {
            let (prev, p, next) = (h[(i + n - 1) % n], h[i], h[(i + 1) % n]);
            let (a, b) = (h[e], h[(e + 1) % n]);
            let sc = &self.screen;
            let screened = sc.surely_below(x, p, next)
                || sc.surely_below(prev, p, x)
                || sc.surely_below(p, x, b)
                || sc.surely_below(a, x, p);
            (!screened).then(|| {
                [
                    left_angle(x, p, next),
                    left_angle(prev, p, x),
                    left_angle(p, x, b),
                    left_angle(a, x, p),
                ]
            })
        })
    }
}

/// A screen of the children of the candidate cuts of one ring ([`Builder::for_each_split`](crate::builder::Builder::for_each_split)),
/// from the ring's vertex angles: a child cannot be good ([`Builder::good_fit`](crate::builder::Builder::good_fit)) if it has
/// fewer than four vertices, or if a vertex whose two neighbours it keeps (so that its
/// `ring_angle` is the same computation on the same points as in the ring, bit for bit) has
/// a critical angle (below θ₋: a critical angle of the child) or one above θ₊ (the child's
/// largest angle exceeds θ₊: not approximately convex). Such vertices are *bad*.
pub(super) struct ChildScreen {
    /// The ring's vertex count.
    n: usize,
    /// `prefix[k]`: bad vertices among `k mod n` for indices `0..k` of the ring read twice.
    prefix: Vec<u32>,
    /// The number of bad vertices.
    pub(super) bad: u32,
}

impl ChildScreen {
    /// The screen of `ring`'s children: its bad vertices (by `ring_angle`) under the
    /// tolerances of `opts`.
    pub(super) fn new(ring: &Ring, opts: &crate::DecomposeOptions) -> Self {
        let tol = &opts.tolerances;
        let n = ring.len();
        let is_bad: Vec<bool> = ring_angles(&ring.pts)
            .into_iter()
            .map(|a| a < tol.theta_minus || a > tol.theta_plus)
            .collect();
        let mut prefix = Vec::with_capacity(2 * n + 1);
        prefix.push(0);
        for k in 0..2 * n {
            prefix.push(prefix[k] + is_bad[k % n] as u32);
        }
        let bad = prefix[n];
        Self { n, prefix, bad }
    }

    /// Bad vertices among the `len` ring vertices from `start` on (cyclically, `len` ≤ n).
    fn bad_in(&self, start: usize, len: usize) -> u32 {
        let s = start % self.n;
        self.prefix[s + len] - self.prefix[s]
    }

    /// How many of the two children of the cut from vertex `e1` to `e2` (a vertex or a
    /// point inside an edge, as [`Builder::for_each_split`](crate::builder::Builder::for_each_split) makes them) may be good.
    ///
    /// The cut from vertex `i` to vertex `j` gives the children `i … j` and `j … i`; the
    /// vertices strictly between keep both neighbours. To the point `x` inside edge `e`
    /// (`e`, `e + 1` not next to `i`) it gives `i … e, x` and `x, e + 1 … i`, in which `e`
    /// and `e + 1` get `x` as a neighbour, so only `i + 1 … e − 1` and `e + 2 … i − 1` keep
    /// theirs. The angles at the cut ends and at `e`, `e + 1` are not screened.
    pub(super) fn possibly_good(&self, e1: End, e2: End) -> usize {
        let n = self.n;
        let Pos::Vertex(i) = e1.pos else {
            return 2;
        };
        // (vertex count, first kept vertex, kept vertex count) of each child
        let children = match e2.pos {
            Pos::Vertex(j) => {
                let (ij, ji) = ((j + n - i) % n, (i + n - j) % n);
                [(ij + 1, i + 1, ij - 1), (ji + 1, j + 1, ji - 1)]
            }
            Pos::OnEdge(e, _) => {
                let (ie, ei) = ((e + n - i) % n, (i + 2 * n - e - 2) % n);
                [(ie + 2, i + 1, ie - 1), (ei + 3, e + 2, ei)]
            }
        };
        children
            .iter()
            .filter(|&&(count, start, len)| count >= 4 && self.bad_in(start, len) == 0)
            .count()
    }
}
