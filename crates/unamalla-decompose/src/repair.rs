//! Corner repair: every block must have four **usable corners** (our addition: the thesis does not repair corners).
//!
//! A usable corner is a block vertex with interior angle θ < θ_lim (default 170°,
//! [`CornerWeights::corner_angle_limit`](crate::CornerWeights)); module [`corners`](crate::corners)
//! never picks anything else. A block of four or more vertices with fewer than four usable ones
//! (typically a block whose fourth "corner" would be a vertex of a straight boundary stretch, or
//! the end of a cut that meets the boundary at a straight angle) is repaired here, after the
//! merge pass, by the first of (the same is tried for blocks that kept a critical angle — mostly
//! at the end of a cut made by a relaxed tier — or stayed non-convex):
//!
//! 1. **a split**: a cut inside the block (from a vertex to a vertex, to the foot of the
//!    perpendicular on an original-boundary edge; only if none of these works, also to the
//!    quarter points ¼, ½, ¾ of such an edge — so that a cut meeting the boundary at a critical
//!    angle at a vertex can end inside the edge instead; exact admissibility, no new angle
//!    below θ₋)
//!    such that both children are *good* — four usable corners, approximately convex
//!    (criteria 1–4), no critical angle, area at least a tenth of the negligible area;
//! 2. **a merge with a neighbour** across one cut (the two blocks share exactly that cut's two
//!    endpoints) when the union is good, or **a merge followed by a split** of the union into two
//!    good blocks (this moves the shared cut so that it meets the boundary at a better angle).
//!
//! 3. **a re-split by two cuts** (for the critical angles that relaxed-tier cuts
//!    leave where they meet a channel's far shore or another cut): the block alone or its union
//!    with one neighbour is split into **three** good blocks — a first cut leaves one good
//!    child, the best second cut splits the other into two (`Builder::best_split3`) — or, only
//!    when neither works, its union with two neighbours (a neighbour of the block and one of
//!    the block or of that neighbour) into two or three good blocks. A good neighbour may not
//!    come out with a corner score more than `RESPLIT_SLACK` = 0.05 worse than the worst good
//!    block of the union (without this bound a small block's repair re-cornered the Gulf of
//!    Mexico's 39-vertex central basin and its transfinite grid folded). The blocks of the
//!    union are replaced in place, so a repair changes the neighbours of blocks already passed
//!    over: the pass sweeps again while the last sweep changed something (bounded by a budget
//!    of 4 × blocks + 16 attempts).
//!
//! Candidates are scored like the concavity cuts of the crate documentation:
//! `S = ½·max(F₁, F₂) + ¼·(F₁ + F₂) + w_a·ḡ + w_l·ℓ/√A` with F the corner score of a child (a
//! merged block alone scores `F(U)`); the lowest S wins, ties broken by coordinates. User cuts from
//! a file are never removed. Blocks that stay without four usable corners (three-vertex blocks:
//! a triangle cannot be split into quadrilaterals by straight cuts without an interior node of
//! valence 3) get the triangle-block rule of [Méndez 2023, §5.1.1] afterwards.
//!
//! 4. **No corner inside a cut** (`Builder::joint_pass`): a block that is bounded by
//!    cuts on the sides where it would need corners and has fewer than four usable vertices
//!    (maryland's "block 4" at the pipeline defaults: a quadrilateral of four cuts with a
//!    reflex vertex and a 30° vertex) could only get the triangle-block rule by inserting points
//!    **inside cuts** — each such point is a cut joint, an interior mesh node where one grid
//!    has a corner and the neighbour a straight side (valence 3 and 5). When steps 1–3 find no
//!    repair into good blocks, the block is split, or merged with a neighbour (and the union
//!    re-split), by the same candidates with a relaxed acceptance: every resulting block must
//!    take its corners without a point inside a cut, and costs `grade + F` with grade 0 for a
//!    good block, 1 for an approximately convex one with a critical angle (or a triangle block
//!    served on the original boundary), 3 for a non-convex one. A singular mesh node is worse
//!    than a less admissible block. [`Decomposition::cut_joints`](crate::Decomposition::cut_joints)
//!    lists the joints that remain (none on the fixture regions, tested).

use std::cell::Cell;
use std::sync::atomic::{AtomicU64, AtomicU8, Ordering};

use rayon::prelude::*;
use unamalla_mesh::geometry::open_segment_hits;
use unamalla_mesh::DVec2;

use crate::auto::{beyond_best, needs_cut_point, triangle_plan, AngleScreen, Builder};
use crate::concavity::{critical_angles, measures, measures_with_angles};
use crate::corners::{has_four_corners, quad_fit, quad_fit_with_angles, select_corners};
use crate::corners_diametral::CornerChoice;
use crate::decomposition::{Step, TreeNode};
use crate::geom::{left_angle, match_vertices, ring_angles, total_key, visit_sorted};
use crate::piece::{End, Piece, Pos, Ring, Tag};

/// Placeholder cut id used while a candidate split is evaluated.
const TMP_CUT: usize = usize::MAX - 7;

/// Placeholder id of the *first* cut of a three-way split while its second cut (tagged
/// [`TMP_CUT`]) is evaluated.
const TMP_CUT2: usize = usize::MAX - 8;

/// The union of rings `a` and `b` across their shared cut edge (`a.tags[ea]` and `b.tags[eb]`
/// are the same cut, in opposite directions); `None` if the result would be degenerate.
pub(crate) fn union_ring(a: &Ring, ea: usize, b: &Ring, eb: usize) -> Option<Ring> {
    let na = a.len();
    let nb = b.len();
    // A: edge ea runs u → v; union = A from v around to u, then B after u up to before v
    let mut pts = Vec::with_capacity(na + nb - 2);
    let mut tags = Vec::with_capacity(na + nb - 2);
    for s in 1..=na {
        let k = (ea + s) % na;
        pts.push(a.pts[k]);
        tags.push(if s == na {
            b.tags[(eb + 1) % nb]
        } else {
            a.tags[k]
        });
    }
    for s in 2..nb {
        let k = (eb + s) % nb;
        pts.push(b.pts[k]);
        tags.push(b.tags[k]);
    }
    (pts.len() >= 3 && tags.len() == pts.len()).then_some(Ring { pts, tags })
}

/// `r` with every edge tagged cut `from` re-tagged cut `to`.
fn retag(mut r: Ring, from: usize, to: usize) -> Ring {
    for t in &mut r.tags {
        if *t == Tag::Cut(from) {
            *t = Tag::Cut(to);
        }
    }
    r
}

/// `r` with the cut of a two-child split ([`TMP_CUT`]) re-tagged as the first cut of a
/// [`Resplit`] ([`TMP_CUT2`]).
fn as_first_cut(r: Ring) -> Ring {
    retag(r, TMP_CUT, TMP_CUT2)
}

/// Whether candidate score `s` with tie-break key `key` beats the best so far (`best`):
/// lower score, scores within 10⁻¹² broken by the key (coordinates, so that the choice does
/// not depend on ring numbering).
fn beats(s: f64, key: DVec2, best: Option<(f64, DVec2)>) -> bool {
    best.is_none_or(|(b, kb)| {
        s < b - 1e-12 || ((s - b).abs() <= 1e-12 && (key.x, key.y) < (kb.x, kb.y))
    })
}

/// The sum of a ring's vertices: a tie-break key independent of where its numbering starts.
fn ring_key(r: &Ring) -> DVec2 {
    r.pts.iter().fold(DVec2::ZERO, |acc, p| acc + *p)
}

/// A split candidate: score, the two children (new cut tagged [`TMP_CUT`]), cut endpoints.
type Split = (f64, Ring, Ring, (DVec2, DVec2));

/// A merge candidate: score, neighbour slot, shared cut, split of the union (`None`: the union
/// is kept whole), union.
type Merge = (f64, usize, usize, Option<Split>, Ring);

/// A re-split of a block or of a union of blocks (step 3 of the repair): score, the two or
/// three children, and the endpoints of the one or two new cuts (cut `i` tagged `TMP_IDS[i]`
/// in the children).
type Resplit = (f64, Vec<Ring>, Vec<(DVec2, DVec2)>);

/// How much worse (corner score F, module [`corners`](crate::corners)) than the worst good
/// block it replaces a block produced by a re-split (step 3) may be.
const RESPLIT_SLACK: f64 = 0.05;

/// The placeholder tags of the first and second cut of a [`Resplit`].
const TMP_IDS: [usize; 2] = [TMP_CUT2, TMP_CUT];

/// What one repair attempt of a block found (steps 1–3 of [`Builder::repair_pass`]).
#[derive(Clone)]
enum Attempt {
    /// Step 1: a split of the block alone.
    Split(Split),
    /// Step 2: a merge with a neighbour (possibly re-split).
    Merge(Merge),
    /// Step 3: a re-split of the block or of a union with neighbours.
    Resplit(Host, Resplit),
    /// Nothing found.
    Fail,
}

/// Whether cut id `c` is one of the placeholders of a candidate ([`TMP_CUT`], [`TMP_CUT2`]).
fn placeholder(c: usize) -> bool {
    c == TMP_CUT || c == TMP_CUT2
}

/// `r` with every cut id `c` (placeholders excepted) replaced by `cut(c)`; `None` if `cut`
/// has no image for one of them.
fn relabel_ring(r: &Ring, cut: &dyn Fn(usize) -> Option<usize>) -> Option<Ring> {
    let tags = r
        .tags
        .iter()
        .map(|t| match *t {
            Tag::Cut(c) if !placeholder(c) => cut(c).map(Tag::Cut),
            t => Some(t),
        })
        .collect::<Option<Vec<Tag>>>()?;
    Some(Ring {
        pts: r.pts.clone(),
        tags,
    })
}

/// [`relabel_ring`] for both children of a [`Split`].
fn relabel_split(s: &Split, cut: &dyn Fn(usize) -> Option<usize>) -> Option<Split> {
    Some((s.0, relabel_ring(&s.1, cut)?, relabel_ring(&s.2, cut)?, s.3))
}

impl Attempt {
    /// The attempt with slot numbers mapped by `slot` and cut ids by `cut` (placeholders
    /// kept); `None` if a map has no image for one of them.
    fn relabel(
        &self,
        slot: &dyn Fn(usize) -> Option<usize>,
        cut: &dyn Fn(usize) -> Option<usize>,
    ) -> Option<Attempt> {
        Some(match self {
            Attempt::Split(s) => Attempt::Split(relabel_split(s, cut)?),
            Attempt::Merge((s, j, c, split, u)) => Attempt::Merge((
                *s,
                slot(*j)?,
                cut(*c)?,
                match split {
                    Some(x) => Some(relabel_split(x, cut)?),
                    None => None,
                },
                relabel_ring(u, cut)?,
            )),
            Attempt::Resplit(host, (s, rings, ends)) => {
                let host = match *host {
                    Host::Alone => Host::Alone,
                    Host::Merged { j, c } => Host::Merged {
                        j: slot(j)?,
                        c: cut(c)?,
                    },
                    Host::Merged2 { j, c, j2, c2 } => Host::Merged2 {
                        j: slot(j)?,
                        c: cut(c)?,
                        j2: slot(j2)?,
                        c2: cut(c2)?,
                    },
                };
                let rings = rings
                    .iter()
                    .map(|r| relabel_ring(r, cut))
                    .collect::<Option<Vec<Ring>>>()?;
                Attempt::Resplit(host, (*s, rings, ends.clone()))
            }
            Attempt::Fail => Attempt::Fail,
        })
    }
}

/// Repair attempts of earlier passes over the same region with the same options (the
/// rebuilds of [`crate::auto::chord_layout_cuts`] repair mostly the same blocks again), keyed
/// by [`Neighbourhood::key`], with slot numbers and cut ids in the key's canonical numbering.
#[derive(Default)]
pub(crate) struct RepairCache {
    attempts: std::collections::HashMap<Vec<u64>, Attempt>,
    /// The candidates of a re-split host ([`Builder::best_resplit`]), keyed by
    /// [`host_key`], the rings' cut ids numbered as in the key.
    hosts: std::collections::HashMap<Vec<u64>, Vec<Resplit>>,
}

/// The key of a re-split host's search: the host ring (points, per edge the region ring or
/// the cut numbered in the order the cuts first appear), the corner-score limit's bits and
/// whether the one-cut split is searched too (a union with two neighbours); and the cut ids
/// in that order.
///
/// The search ([`Builder::best_resplit`]'s `candidates`) reads only these — the points and
/// whether an edge is region boundary or cut, never a cut's id except to copy it to the
/// children — and the options and minimum area, the same for every builder sharing the
/// cache: an equal key means the same search up to the cut ids.
fn host_key(u: &Ring, limit: f64, two: bool) -> (Vec<u64>, Vec<usize>) {
    let mut key = Vec::new();
    let mut ids: Vec<usize> = Vec::new();
    u.push_key(&mut key, |c, key| {
        let k = ids.iter().position(|&x| x == c).unwrap_or_else(|| {
            ids.push(c);
            ids.len() - 1
        });
        key.extend([1, k as u64]);
    });
    key.extend([limit.to_bits(), two as u64]);
    (key, ids)
}

/// `found` with the rings' cut ids mapped by `cut` (placeholders kept); `None` if one has no
/// image.
fn relabel_resplits(
    found: &[Resplit],
    cut: &dyn Fn(usize) -> Option<usize>,
) -> Option<Vec<Resplit>> {
    found
        .iter()
        .map(|(s, rings, ends)| {
            let rings = rings
                .iter()
                .map(|r| relabel_ring(r, cut))
                .collect::<Option<Vec<Ring>>>()?;
            Some((*s, rings, ends.clone()))
        })
        .collect()
}

/// The neighbourhood of a block that a repair attempt reads: block slot `k`, the blocks
/// across its cuts and the blocks across theirs (rings, tags, and whether those cuts are
/// alive and protected), in a numbering independent of slot numbers and cut ids (`key`) and
/// the numbering itself (`slots`, `cuts`): two neighbourhoods are equal exactly when they
/// hold the same blocks in the same slots with the same cuts.
#[derive(PartialEq)]
struct Neighbourhood {
    /// The slots, block first, in the order of discovery (canonical slot `i` is `slots[i]`).
    slots: Vec<usize>,
    /// The cut ids in order of first appearance in the key (canonical cut `i` is `cuts[i]`).
    cuts: Vec<usize>,
    /// For each slot in order: the rank of its slot number among `slots` (the attempt picks
    /// the first slot holding a cut), its vertices, and per edge the original-boundary ring
    /// or the canonical cut id with whether the cut is protected and alive.
    key: Vec<u64>,
}

/// The slots holding each cut, in slot order (as `neighbour_unions` searches them): what
/// [`Neighbourhood::new`] follows from a block to its neighbours. A function of the slots
/// alone, so [`Builder::repair_pass`] computes it once per state of the slots.
type CutHolders = std::collections::HashMap<usize, Vec<usize>>;

/// The [`CutHolders`] of `slot`.
fn cut_holders(slot: &[Option<Ring>]) -> CutHolders {
    let mut holders = CutHolders::new();
    for (j, o) in slot.iter().enumerate() {
        for t in o.iter().flat_map(|r| r.tags.iter()) {
            if let Tag::Cut(c) = *t {
                let h = holders.entry(c).or_default();
                if h.last() != Some(&j) {
                    h.push(j);
                }
            }
        }
    }
    holders
}

impl Neighbourhood {
    /// The neighbourhood of block slot `k`; `holders` = [`cut_holders`]`(slot)`.
    fn new(
        slot: &[Option<Ring>],
        holders: &CutHolders,
        k: usize,
        alive: &[bool],
        protected: usize,
    ) -> Self {
        let mut slots = vec![k];
        let mut frontier = vec![k];
        for _ in 0..2 {
            let mut next = Vec::new();
            for &s in &frontier {
                for t in slot[s].iter().flat_map(|r| r.tags.iter()) {
                    let Tag::Cut(c) = *t else { continue };
                    for &j in holders.get(&c).map(Vec::as_slice).unwrap_or(&[]) {
                        if !slots.contains(&j) {
                            slots.push(j);
                            next.push(j);
                        }
                    }
                }
            }
            frontier = next;
        }
        let mut sorted = slots.clone();
        sorted.sort_unstable();
        let mut cuts: Vec<usize> = Vec::new();
        let mut key = vec![slots.len() as u64];
        for &s in &slots {
            key.push(sorted.binary_search(&s).unwrap_or(usize::MAX) as u64);
            let Some(r) = slot[s].as_ref() else {
                key.push(u64::MAX);
                continue;
            };
            r.push_key(&mut key, |c, key| {
                let canon = match cuts.iter().position(|&x| x == c) {
                    Some(i) => i,
                    None => {
                        cuts.push(c);
                        cuts.len() - 1
                    }
                };
                let live = alive.get(c).copied().unwrap_or(false);
                key.extend([1, canon as u64, (c < protected) as u64, live as u64]);
            });
        }
        Self { slots, cuts, key }
    }
}

/// A memo of [`Builder::good_fit`] by exact vertex sequence, for one re-split search
/// ([`Builder::best_resplit`]): its two-cut searches meet the same child rings many times
/// (a block cut by X then Y has the pieces of the block cut by Y then X, and the second-cut
/// searches of different first cuts share most of their children). Exact: `good_fit` is a
/// function of the vertex sequence alone (the builder's options and minimum area are fixed),
/// and entries are matched on the full sequence, bit for bit.
#[derive(Default)]
struct FitMemo(std::sync::Mutex<std::collections::HashMap<u64, Vec<FitEntry>>>);

/// An entry of a [`FitMemo`]: a vertex sequence and its `good_fit`.
type FitEntry = (Box<[DVec2]>, Option<f64>);

impl FitMemo {
    /// `b.good_fit(ring)`, computed once per vertex sequence.
    fn good_fit(&self, b: &Builder<'_>, ring: &Ring) -> Option<f64> {
        let same = |p: &[DVec2]| {
            p.len() == ring.pts.len()
                && p.iter()
                    .zip(&ring.pts)
                    .all(|(a, b)| a.x.to_bits() == b.x.to_bits() && a.y.to_bits() == b.y.to_bits())
        };
        // the bucket: a quick hash of the coordinates' bits (FxHash's multiply and rotate;
        // the entries in a bucket are told apart by the full sequence)
        const K: u64 = 0x517c_c1b7_2722_0a95;
        let mix = |h: u64, x: f64| (h.rotate_left(5) ^ x.to_bits()).wrapping_mul(K);
        let h = ring.pts.iter().fold(0u64, |h, p| mix(mix(h, p.x), p.y));
        if let Ok(m) = self.0.lock() {
            if let Some(f) = m.get(&h).and_then(|v| v.iter().find(|e| same(&e.0))) {
                return f.1;
            }
        }
        let f = b.good_fit(ring);
        if let Ok(mut m) = self.0.lock() {
            m.entry(h)
                .or_default()
                .push((ring.pts.clone().into_boxed_slice(), f));
        }
        f
    }
}

/// Where a re-split applies: the block alone, its union with the neighbour in slot
/// `j` across cut `c`, or its union with two neighbours (`j` across `c`, then `j2` across `c2`,
/// a neighbour of the block or of `j`).
#[derive(Clone, Copy)]
enum Host {
    Alone,
    Merged {
        j: usize,
        c: usize,
    },
    Merged2 {
        j: usize,
        c: usize,
        j2: usize,
        c2: usize,
    },
}

impl Host {
    /// The slots of the blocks the host unites (block `k` first) and the cuts between them.
    fn parts(self, k: usize) -> (Vec<usize>, Vec<usize>) {
        match self {
            Host::Alone => (vec![k], vec![]),
            Host::Merged { j, c } => (vec![k, j], vec![c]),
            Host::Merged2 { j, c, j2, c2 } => (vec![k, j, j2], vec![c, c2]),
        }
    }
}

/// What the split searches of one host ring and of its children (the second cuts of a
/// re-split, [`Builder::best_split3`], search children of the host again and again) need to
/// know about a candidate cut, each computed once: the new angles at its ends in tier 1 — at
/// a vertex towards the cut's other end, and at the foot of a perpendicular from a vertex
/// towards that vertex, as [`Builder::end_angles`] computes them — or that the tier's
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
struct CutTable<'a> {
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
const REJECTED: u64 = 0xbff0_0000_0000_0000;

/// Where the vertices and edges of a ring are those of an [`CutTable`] host: host vertex
/// of each ring vertex with the same point and neighbours, host edge of each ring edge with
/// the same end points (`usize::MAX`: none).
struct HostMatch {
    vertex: Vec<usize>,
    edge: Vec<usize>,
}

impl<'a> CutTable<'a> {
    /// An empty table of `host`'s angles, screened by `screen` (tier 1's).
    fn new(host: &'a [DVec2], screen: AngleScreen) -> Self {
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
    fn admissible(&self, i: usize, to: End) -> bool {
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
    fn locate(&self, ring: &Ring) -> HostMatch {
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
    fn vertex_angles(&self, i: usize, j: usize) -> Option<[f64; 2]> {
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
    fn foot_angles(&self, i: usize, e: usize, x: DVec2) -> Option<[f64; 4]> {
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

/// A screen of the children of the candidate cuts of one ring ([`Builder::for_each_split`]),
/// from the ring's vertex angles: a child cannot be good ([`Builder::good_fit`]) if it has
/// fewer than four vertices, or if a vertex whose two neighbours it keeps (so that its
/// `ring_angle` is the same computation on the same points as in the ring, bit for bit) has
/// a critical angle (below θ₋: a critical angle of the child) or one above θ₊ (the child's
/// largest angle exceeds θ₊: not approximately convex). Such vertices are *bad*.
struct ChildScreen {
    /// The ring's vertex count.
    n: usize,
    /// `prefix[k]`: bad vertices among `k mod n` for indices `0..k` of the ring read twice.
    prefix: Vec<u32>,
    /// The number of bad vertices.
    bad: u32,
}

impl ChildScreen {
    /// The screen of `ring`'s children: its bad vertices (by `ring_angle`) under the
    /// tolerances of `opts`.
    fn new(ring: &Ring, opts: &crate::DecomposeOptions) -> Self {
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
    /// point inside an edge, as [`Builder::for_each_split`] makes them) may be good.
    ///
    /// The cut from vertex `i` to vertex `j` gives the children `i … j` and `j … i`; the
    /// vertices strictly between keep both neighbours. To the point `x` inside edge `e`
    /// (`e`, `e + 1` not next to `i`) it gives `i … e, x` and `x, e + 1 … i`, in which `e`
    /// and `e + 1` get `x` as a neighbour, so only `i + 1 … e − 1` and `e + 2 … i − 1` keep
    /// theirs. The angles at the cut ends and at `e`, `e + 1` are not screened.
    fn possibly_good(&self, e1: End, e2: End) -> usize {
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

impl Builder<'_> {
    /// Four usable corners (see the module documentation).
    pub(crate) fn usable(&self, ring: &[DVec2]) -> bool {
        ring.len() >= 4 && self.usable_with_angles(ring, &ring_angles(ring))
    }

    /// [`Builder::usable`] with the ring's vertex angles given (`angles[i]` =
    /// `ring_angle(ring, i)`). For the scoring selection only the existence of a corner tuple
    /// matters, which [`has_four_corners`] decides from the angles alone (the same answer as
    /// the exhaustive search, without it).
    fn usable_with_angles(&self, ring: &[DVec2], angles: &[f64]) -> bool {
        let w = &self.opts.corner_weights;
        ring.len() >= 4
            && if w.choice == CornerChoice::Scoring {
                has_four_corners(angles, w)
            } else {
                select_corners(ring, w).is_some()
            }
    }

    /// A block that needs no repair and may be produced by one: four usable corners,
    /// approximately convex, no critical angle, not negligible.
    #[cfg(test)]
    fn good(&self, ring: &Ring) -> bool {
        crate::geom::signed_area(&ring.pts) >= 0.1 * self.min_area
            && self.good_with_angles(ring, &ring_angles(&ring.pts))
    }

    /// [`Builder::good`] apart from the area test, with the ring's vertex angles given
    /// (`angles[i]` = `ring_angle(ring, i)`). The tests are pure, so their order does not
    /// change the answer; the cheap ones from the angles come first and the convex hull of
    /// the concavity measures last. The spike criterion (largest angle ≤ θ₊) is the first
    /// test of [`Concavity::approximately_convex`](crate::Concavity::approximately_convex),
    /// on the same largest angle (the fold of the same values), so testing it early changes
    /// nothing.
    fn good_with_angles(&self, ring: &Ring, angles: &[f64]) -> bool {
        let tol = &self.opts.tolerances;
        !angles.iter().any(|&a| a < tol.theta_minus)
            && (ring.len() < 3 || angles.iter().copied().fold(0.0, f64::max) <= tol.theta_plus)
            && self.usable_with_angles(&ring.pts, angles)
            && measures_with_angles(&ring.pts, angles).approximately_convex(tol)
    }

    /// The corner score F of a good block ([`Builder::good`]); `None` if it is not good. The
    /// acceptance of steps 1–3. The vertex angles are computed once for all the tests and the
    /// score.
    fn good_fit(&self, ring: &Ring) -> Option<f64> {
        // the area test of `good`, as written there (a NaN area fails it)
        let big_enough = crate::geom::signed_area(&ring.pts) >= 0.1 * self.min_area;
        if !big_enough {
            return None;
        }
        let angles = ring_angles(&ring.pts);
        self.good_with_angles(ring, &angles)
            .then(|| quad_fit_with_angles(&ring.pts, &angles))
    }

    /// `true` if block `ring` should be repaired: four or more vertices and fewer than four
    /// usable corners, a critical angle or not approximately convex; or a triangle that the
    /// triangle-block rule cannot serve without a 180° corner or a point inside a cut (no
    /// critical angle, or a critical vertex with a cut as one of its edges).
    fn needs_repair(&self, ring: &Ring) -> bool {
        let tol = &self.opts.tolerances;
        let crit = critical_angles(&ring.pts, tol.theta_minus);
        if ring.len() == 3 {
            crit.is_empty()
                || crit.iter().any(|&v| {
                    let n = ring.len();
                    matches!(ring.tags[v], Tag::Cut(_))
                        || matches!(ring.tags[(v + n - 1) % n], Tag::Cut(_))
                })
        } else {
            !crit.is_empty()
                || !self.usable(&ring.pts)
                || !measures(&ring.pts).approximately_convex(tol)
        }
    }

    /// The best cut splitting `ring` into two good blocks.
    fn best_split(&self, ring: &Ring) -> Option<Split> {
        self.best_split_by(ring, &|r: &Ring| self.good_fit(r), true, None)
    }

    /// The best cut splitting `ring` into two blocks that `accept` takes; `accept` returns the
    /// cost F of a child (its corner score, plus a grade penalty in the relaxed pass) and the
    /// split scores `½·max(F₁, F₂) + ¼·(F₁ + F₂) + w_a·ḡ + w_l·ℓ/√A`.
    ///
    /// The quarter points of the original-boundary edges are offered only when the vertices
    /// and feet give no acceptable split (so they add repairs without changing the ones that
    /// worked before), and only with [`DecomposeOptions::edge_point_cuts`](crate::DecomposeOptions::edge_point_cuts).
    ///
    /// `good_only` says that `accept` takes only good blocks ([`Builder::good_fit`], possibly
    /// narrowed): then candidates whose children cannot both be good are not built
    /// ([`Builder::for_each_split`]); it changes no result. `angles`: the [`CutTable`] of a
    /// ring that `ring` is a child of (or `ring` itself), if the caller keeps one.
    fn best_split_by(
        &self,
        ring: &Ring,
        accept: &(dyn Fn(&Ring) -> Option<f64> + Sync),
        good_only: bool,
        angles: Option<&CutTable>,
    ) -> Option<Split> {
        self.best_split_with(ring, accept, good_only, false, angles)
            .or_else(|| {
                self.opts
                    .edge_point_cuts
                    .then(|| self.best_split_with(ring, accept, good_only, true, angles))
                    .flatten()
            })
    }

    /// [`Builder::best_split_by`] with or without the quarter-point targets.
    fn best_split_with(
        &self,
        ring: &Ring,
        accept: &(dyn Fn(&Ring) -> Option<f64> + Sync),
        good_only: bool,
        quarter_points: bool,
        angles: Option<&CutTable>,
    ) -> Option<Split> {
        let mut best: Option<Split> = None;
        let need = if good_only { 2 } else { 0 };
        // the best score so far: the search ends at the first candidate whose cheap terms
        // reach it (exact, `beyond_best`: `accept` costs are never negative)
        let bound = Cell::new(f64::NAN);
        self.for_each_split(
            ring,
            quarter_points,
            need,
            Some(&bound),
            angles,
            &mut |pre, a, b, ends| {
                // `accept` is pure: the second child is not looked at when the first fails
                let Some(fa) = accept(&a) else { return };
                let Some(fb) = accept(&b) else { return };
                let s = 0.5 * fa.max(fb) + 0.25 * (fa + fb) + pre;
                if best.as_ref().is_none_or(|b| s < b.0) {
                    bound.set(s);
                    best = Some((s, a, b, ends));
                }
            },
        );
        best
    }

    /// Calls `visit(pre, a, b, ends)` for the first 80 admissible cuts of `ring` in the order
    /// of their cheap terms `pre = w_a·ḡ + w_l·ℓ/√A` (ties broken by coordinates): `a`, `b` are
    /// the children (the new cut tagged [`TMP_CUT`]) and `ends` the cut's endpoints. Targets:
    /// vertex → vertex and vertex → foot of the perpendicular on an original-boundary edge,
    /// with `quarter_points` also the quarter points of those edges.
    ///
    /// With `need` = 1 or 2, the caller will only use a candidate of which at least `need`
    /// children are good ([`Builder::good_fit`]): a counted candidate (it still counts towards
    /// the 80) whose children cannot be is not built or visited ([`ChildScreen`]), and when no
    /// candidate can pass, nothing is searched. `need` = 0 visits every counted candidate.
    ///
    /// With a `bound` (the caller's best two-child score so far, NaN while there is none),
    /// the search ends at the first candidate whose `pre` reaches it: the caller keeps a
    /// candidate only if it scores below the bound, which no candidate from there on can
    /// (`beyond_best`). With `angles`, the new angles at the ends of a cut (without the
    /// quarter points) come from that table where `ring`'s vertices and edges are its host's.
    fn for_each_split(
        &self,
        ring: &Ring,
        quarter_points: bool,
        need: usize,
        bound: Option<&Cell<f64>>,
        angles: Option<&CutTable>,
        visit: &mut dyn FnMut(f64, Ring, Ring, (DVec2, DVec2)),
    ) {
        let n = ring.len();
        if n < 4 {
            return;
        }
        let screen = (need > 0).then(|| ChildScreen::new(ring, self.opts));
        if screen.as_ref().is_some_and(|c| need == 2 && c.bad > 3) {
            // a cut changes the angles of at most three vertices of `ring` (its start vertex,
            // and its end vertex or the two ends of the edge it ends on): some bad vertex
            // keeps its angle in a child, which is then not good
            return;
        }
        let piece = Piece {
            outer: ring.clone(),
            holes: Vec::new(),
        };
        // the ring's edge index, built if a cut is tested without the table
        let idx_cell = std::cell::OnceCell::new();
        let idx = || idx_cell.get_or_init(|| piece.index());
        let sq = piece.area().abs().sqrt().max(1e-300);
        let w = self.opts.cut_weights;
        let mut cands: Vec<(f64, End, End)> = Vec::new();
        let table = angles
            .filter(|_| !quarter_points)
            .map(|t| (t, t.locate(ring)));
        // the cut from vertex `i` to `e2` in the host's numbering, where the table has it:
        // the host vertex of `i`, and the host vertex or the foot on a host edge of `e2`
        let in_host = |i: usize, e2: End| {
            let (t, at) = table.as_ref()?;
            let hi = at.vertex[i];
            if hi == usize::MAX {
                return None;
            }
            let to = match e2.pos {
                Pos::Vertex(j) if at.vertex[j] != usize::MAX => Pos::Vertex(at.vertex[j]),
                Pos::OnEdge(e, x) if at.edge[e] != usize::MAX => Pos::OnEdge(at.edge[e], x),
                _ => return None,
            };
            Some((*t, hi, End { ring: 0, pos: to }))
        };
        // the angle terms of the cut from vertex `i` (as `angle_terms` in tier 1), from the
        // table where it has the angles
        let terms = |i: usize, e2: End| {
            let e1 = End {
                ring: 0,
                pos: Pos::Vertex(i),
            };
            // (a cut the screen rejects at either end gets `None`, as in `angle_terms`)
            match in_host(i, e2) {
                None => self.angle_terms(&piece, e1, e2, 1),
                Some((
                    t,
                    hi,
                    End {
                        pos: Pos::Vertex(hj),
                        ..
                    },
                )) => {
                    let [a, b] = t.vertex_angles(hi, hj)?;
                    let [c, d] = t.vertex_angles(hj, hi)?;
                    self.angle_terms_of([a, b, c, d], 1)
                }
                Some((
                    t,
                    hi,
                    End {
                        pos: Pos::OnEdge(he, x),
                        ..
                    },
                )) => self.angle_terms_of(t.foot_angles(hi, he, x)?, 1),
            }
        };
        // the ring's edges that are not the host's (see `CutTable::admissible`)
        let not_host: Vec<(DVec2, DVec2)> = table
            .as_ref()
            .map(|(_, at)| {
                (0..n)
                    .filter(|&k| at.edge[k] == usize::MAX)
                    .map(|k| (ring.p(k), ring.next(k)))
                    .collect()
            })
            .unwrap_or_default();
        let admissible = |e1: End, e2: End| {
            let Pos::Vertex(i) = e1.pos else {
                return piece.admissible(idx(), e1, e2);
            };
            match in_host(i, e2) {
                Some((t, hi, to)) => {
                    let (p, q) = (piece.point(e1), piece.point(e2));
                    t.admissible(hi, to)
                        && !not_host.iter().any(|&(a, b)| open_segment_hits(p, q, a, b))
                }
                None => piece.admissible(idx(), e1, e2),
            }
        };
        // the target list, reused for every start vertex
        let mut t = Vec::new();
        for i in 0..n {
            let p = ring.p(i);
            let e1 = End {
                ring: 0,
                pos: Pos::Vertex(i),
            };
            let near = |j: usize| j == i || j == (i + 1) % n || j == (i + n - 1) % n;
            t.clear();
            Self::targets_on_ring(&piece, 0, p, &near, &mut t);
            // also the quarter points of the original-boundary edges: a cut that met the
            // boundary at a critical angle at a vertex can end inside the edge instead, where
            // the foot of the perpendicular is not on the edge
            for e in (0..n).filter(|_| quarter_points) {
                let e2 = (e + 1) % n;
                if near(e) || near(e2) || !matches!(ring.tags[e], Tag::Boundary(_)) {
                    continue;
                }
                let (a, b) = (ring.p(e), ring.p(e2));
                for f in [0.25, 0.5, 0.75] {
                    t.push(End {
                        ring: 0,
                        pos: Pos::OnEdge(e, a + f * (b - a)),
                    });
                }
            }
            for &e2 in &t {
                if let Pos::Vertex(j) = e2.pos {
                    if j < i {
                        continue; // each vertex pair once
                    }
                }
                let Some((pen, _)) = terms(i, e2) else {
                    continue;
                };
                let q = piece.point(e2);
                cands.push((w.angle * pen + w.length * p.distance(q) / sq, e1, e2));
            }
        }
        // the candidates in the order of (pre, coordinates of both ends, position): the
        // sequence a stable sort by pre and coordinates gives, sorted only as far as the
        // search goes (`visit_sorted`)
        // (pre by its `total_cmp` key)
        let mut order: Vec<(u64, usize)> = (0..cands.len())
            .map(|k| (total_key(cands[k].0), k))
            .collect();
        let mut evaluated = 0;
        let cmp = |&(sa, ka): &(u64, usize), &(sb, kb): &(u64, usize)| {
            sa.cmp(&sb)
                .then_with(|| {
                    let (a, b) = (&cands[ka], &cands[kb]);
                    let (pa, pb) = (piece.point(a.1), piece.point(b.1));
                    let (qa, qb) = (piece.point(a.2), piece.point(b.2));
                    pa.x.total_cmp(&pb.x)
                        .then(pa.y.total_cmp(&pb.y))
                        .then(qa.x.total_cmp(&qb.x))
                        .then(qa.y.total_cmp(&qb.y))
                })
                .then(ka.cmp(&kb))
        };
        visit_sorted(&mut order, cmp, |&(_, k)| {
            let (pre, e1, e2) = cands[k];
            if evaluated >= 80 || bound.is_some_and(|b| beyond_best(pre, b.get())) {
                return false;
            }
            if !admissible(e1, e2) {
                return true;
            }
            evaluated += 1;
            if screen
                .as_ref()
                .is_some_and(|c| c.possibly_good(e1, e2) < need)
            {
                return true;
            }
            let (a, b, ends) = piece.split_between(e1, e2, TMP_CUT);
            visit(pre, a.outer, b.outer, ends);
            true
        });
    }

    /// The best split of `ring` by **two** cuts into three blocks that `accept` takes (step 3
    /// of the repair): a first cut leaves one accepted child and one that the best second cut
    /// ([`Builder::best_split_by`]) splits into two accepted children. Only first cuts that do
    /// not already give two accepted children are followed (those are steps 1–2). Score
    /// `½·max(F₁, F₂, F₃) + (F₁ + F₂ + F₃)/6 + pre₁ + pre₂` — the two-child score
    /// `½·max + ½·mean` with the mean over three, plus both cuts' angle and length terms.
    /// `good_only` as in [`Builder::best_split_by`].
    ///
    /// `angles` is the [`CutTable`] table of `ring`, shared by the search of the first cuts
    /// and the searches of the second cuts in their children.
    fn best_split3(
        &self,
        ring: &Ring,
        accept: &(dyn Fn(&Ring) -> Option<f64> + Sync),
        good_only: bool,
        angles: &CutTable,
    ) -> Option<Resplit> {
        let mut best: Option<Resplit> = None;
        for quarter_points in [false, true] {
            if quarter_points && (best.is_some() || !self.opts.edge_point_cuts) {
                break;
            }
            // the first cuts in their order, then the second-cut searches in parallel, the
            // results compared in that same order (as a sequential loop would)
            let mut firsts = Vec::new();
            // a first cut is followed only if it leaves exactly one accepted child
            let need = if good_only { 1 } else { 0 };
            self.for_each_split(
                ring,
                quarter_points,
                need,
                None,
                Some(angles),
                &mut |pre1, a, b, ends1| {
                    firsts.push((pre1, a, b, ends1));
                },
            );
            let found: Vec<Option<Resplit>> = firsts
                .into_par_iter()
                .map(|(pre1, a, b, ends1)| {
                    let (fa, fb) = (accept(&a), accept(&b));
                    let (kept, fk, rest) = match (fa, fb) {
                        (Some(fa), None) => (a, fa, b),
                        (None, Some(fb)) => (b, fb, a),
                        _ => return None,
                    };
                    let (s2, r1, r2, ends2) =
                        self.best_split_by(&as_first_cut(rest), accept, good_only, Some(angles))?;
                    let (f1, f2) = (accept(&r1)?, accept(&r2)?);
                    let pre2 = s2 - 0.5 * f1.max(f2) - 0.25 * (f1 + f2);
                    let s = 0.5 * fk.max(f1).max(f2) + (fk + f1 + f2) / 6.0 + pre1 + pre2;
                    Some((s, vec![as_first_cut(kept), r1, r2], vec![ends1, ends2]))
                })
                .collect();
            for c in found.into_iter().flatten() {
                if best.as_ref().is_none_or(|b| c.0 < b.0) {
                    best = Some(c);
                }
            }
        }
        best
    }

    /// Commits a split: a real cut id replaces [`TMP_CUT`].
    fn commit_split(&mut self, a: Ring, b: Ring, ends: (DVec2, DVec2)) -> (Ring, Ring, usize) {
        let id = self.new_cut(ends.0, ends.1);
        (retag(a, TMP_CUT, id), retag(b, TMP_CUT, id), id)
    }

    /// Commits a [`Resplit`]'s cuts: real cut ids replace the placeholder tags.
    fn commit_resplit(
        &mut self,
        children: Vec<Ring>,
        ends: &[(DVec2, DVec2)],
    ) -> (Vec<Ring>, Vec<usize>) {
        let ids: Vec<usize> = ends.iter().map(|e| self.new_cut(e.0, e.1)).collect();
        let children = children
            .into_iter()
            .map(|r| {
                ids.iter()
                    .zip(TMP_IDS)
                    .fold(r, |r, (&id, tmp)| retag(r, tmp, id))
            })
            .collect();
        (children, ids)
    }

    /// Records a repair split of block slot `k` into slots `k` and `m` in the tree: the first
    /// leaf pointing to `k` gets two children.
    fn branch_leaf(&mut self, k: usize, m: usize, cut: usize) {
        let Some(leaf) = self
            .nodes
            .iter()
            .position(|n| n.children.is_empty() && n.block == Some(k))
        else {
            return;
        };
        let label = self.nodes[leaf].label.clone();
        let mut ids = Vec::with_capacity(2);
        for (s, block) in [(1, k), (2, m)] {
            self.nodes.push(TreeNode {
                label: if label.is_empty() {
                    format!("{s}")
                } else {
                    format!("{label}.{s}")
                },
                parent: Some(leaf),
                children: Vec::new(),
                step: None,
                cuts: Vec::new(),
                block: Some(block),
            });
            self.pieces.push(None);
            ids.push(self.nodes.len() - 1);
        }
        let node = &mut self.nodes[leaf];
        node.children = ids;
        node.step = Some(Step::CornerRepair);
        node.cuts = vec![cut];
        node.block = None;
    }

    /// The best merge of block slot `k` with a neighbour across one live, unprotected cut
    /// (the two blocks share exactly that cut's endpoints): the union alone if `accept` takes
    /// it, else the best split of the union by `accept`. Returns (score, neighbour slot, cut,
    /// split or `None` for the union alone, union).
    /// `good_only` as in [`Builder::best_split_by`].
    fn best_merge(
        &self,
        slot: &[Option<Ring>],
        k: usize,
        alive: &[bool],
        accept: &(dyn Fn(&Ring) -> Option<f64> + Sync),
        good_only: bool,
    ) -> Option<Merge> {
        let mut best: Option<Merge> = None;
        let r = slot[k].as_ref()?;
        let unions = self.neighbour_unions(slot, r, &[k], alive);
        // the unions are searched in parallel and compared in order (the searches are pure)
        let options: Vec<Option<(f64, Option<Split>)>> = unions
            .par_iter()
            .map(|(_, _, u)| match accept(u) {
                Some(cost) => Some((cost, None)),
                None => self
                    .best_split_by(u, accept, good_only, None)
                    .map(|s| (s.0, Some(s))),
            })
            .collect();
        for ((j, c, u), option) in unions.into_iter().zip(options) {
            if let Some((s, split)) = option {
                if beats(
                    s,
                    ring_key(&u),
                    best.as_ref().map(|b| (b.0, ring_key(&b.4))),
                ) {
                    best = Some((s, j, c, split, u));
                }
            }
        }
        best
    }

    /// The unions of ring `r` (a block, or a union of the blocks in slots `exclude`) with each
    /// other block across one live, unprotected cut (the two share exactly that cut's
    /// endpoints), as (neighbour slot, cut, union); degenerate or clockwise unions are left out.
    fn neighbour_unions(
        &self,
        slot: &[Option<Ring>],
        r: &Ring,
        exclude: &[usize],
        alive: &[bool],
    ) -> Vec<(usize, usize, Ring)> {
        let mut out = Vec::new();
        for (e, t) in r.tags.iter().enumerate() {
            let Tag::Cut(c) = *t else { continue };
            if c < self.protected_cuts || !alive.get(c).copied().unwrap_or(false) {
                continue;
            }
            let Some((j, f)) = slot.iter().enumerate().find_map(|(j, o)| {
                let o = o.as_ref()?;
                if exclude.contains(&j) {
                    return None;
                }
                o.tags
                    .iter()
                    .position(|x| *x == Tag::Cut(c))
                    .map(|f| (j, f))
            }) else {
                continue;
            };
            let Some(other) = slot[j].as_ref() else {
                continue;
            };
            if r.pts.iter().filter(|p| other.pts.contains(p)).count() != 2 {
                continue;
            }
            let Some(u) = union_ring(r, e, other, f) else {
                continue;
            };
            if crate::geom::signed_area(&u.pts) > 0.0 {
                out.push((j, c, u));
            }
        }
        out
    }

    /// Step 3 of the repair: the best re-split into good blocks of block slot `k` alone, of
    /// its union with one neighbour (both by two cuts into three blocks,
    /// [`Builder::best_split3`]), or of its union with two neighbours (by two cuts into three
    /// blocks, or by one cut into two). The lowest score wins, ties broken by the coordinates
    /// of the first child's vertices.
    fn best_resplit(
        &self,
        slot: &[Option<Ring>],
        k: usize,
        alive: &[bool],
    ) -> Option<(Host, Resplit)> {
        let r = slot[k].as_ref()?;
        let mut hosts = vec![(Host::Alone, r.clone())];
        let mut hosts2 = Vec::new();
        let mut pairs = Vec::new();
        for (j, c, u) in self.neighbour_unions(slot, r, &[k], alive) {
            for (j2, c2, u2) in self.neighbour_unions(slot, &u, &[k, j], alive) {
                if !pairs.contains(&(j2.min(j), j2.max(j))) {
                    pairs.push((j2.min(j), j2.max(j)));
                    hosts2.push((Host::Merged2 { j, c, j2, c2 }, u2));
                }
            }
            hosts.push((Host::Merged { j, c }, u));
        }
        let memo = FitMemo::default();
        // the candidates of one host, in the order the search yields them: the split of a
        // union with two neighbours by one cut, then the split by two cuts
        let candidates = |(host, u): &(Host, Ring)| -> Vec<Resplit> {
            // a good neighbour may not come out with a worse corner score than RESPLIT_SLACK
            // above the worst good block it replaces (gulf-of-mexico: the repair of a small
            // block re-cornered the 39-vertex central basin, F 0.13 → 0.20, whose transfinite
            // grid then folded over more area than it covered)
            let limit = host
                .parts(k)
                .0
                .iter()
                .filter_map(|&s| slot[s].as_ref().and_then(|r| memo.good_fit(self, r)))
                .map(|f| f + RESPLIT_SLACK)
                .fold(f64::NEG_INFINITY, f64::max);
            let limit = if limit == f64::NEG_INFINITY {
                f64::INFINITY
            } else {
                limit
            };
            let is_two = matches!(host, Host::Merged2 { .. });
            // the same host searched before (in an earlier sweep or layout): its candidates
            // (exact, `host_key`)
            let cache = self.cache.as_ref().map(|c| &c.repair);
            let (key, ids) = host_key(u, limit, is_two);
            let hit = cache.and_then(|c| c.lock().ok()?.hosts.get(&key).cloned());
            if let Some(found) = hit.and_then(|f| relabel_resplits(&f, &|c| ids.get(c).copied())) {
                return found;
            }
            let good = |u: &Ring| memo.good_fit(self, u).filter(|&f| f <= limit);
            let angles = CutTable::new(&u.pts, *self.tier1_screen());
            let two = is_two
                .then(|| self.best_split_by(u, &good, true, Some(&angles)))
                .flatten()
                .map(|(s, a, b, ends)| (s, vec![as_first_cut(a), as_first_cut(b)], vec![ends]));
            let found: Vec<Resplit> = two
                .into_iter()
                .chain(self.best_split3(u, &good, true, &angles))
                .collect();
            let canon = relabel_resplits(&found, &|c| ids.iter().position(|&x| x == c));
            if let (Some(cache), Some(canon)) = (cache, canon) {
                if let Ok(mut c) = cache.lock() {
                    c.hosts.insert(key, canon);
                }
            }
            found
        };
        // the lowest score wins, candidates compared in host order (as a sequential loop
        // over the hosts would: the searches are pure, the memo only saves work)
        let fold = |best: &mut Option<(Host, Resplit)>, host: Host, found: Vec<Resplit>| {
            for s in found {
                if beats(
                    s.0,
                    ring_key(&s.1[0]),
                    best.as_ref().map(|(_, b)| (b.0, ring_key(&b.1[0]))),
                ) {
                    *best = Some((host, s));
                }
            }
        };
        let mut best: Option<(Host, Resplit)> = None;
        let found: Vec<Vec<Resplit>> = hosts.par_iter().map(candidates).collect();
        for ((host, _), f) in hosts.iter().zip(found) {
            fold(&mut best, *host, f);
        }
        // the fewest blocks disturbed: two neighbours only when no re-split of the block
        // alone or with one neighbour works, and then the first of those that works (the
        // sequential loop stops at the next one once it has a candidate; searched in
        // parallel, the later ones are given up once an earlier one has candidates)
        if best.is_none() {
            let first = hosts2
                .par_iter()
                .map(|h| (h.0, candidates(h)))
                .find_first(|(_, found)| !found.is_empty());
            if let Some((host, found)) = first {
                fold(&mut best, host, found);
            }
        }
        best
    }

    /// Applies a re-split found by [`Builder::best_resplit`]: the merged cuts die, the children
    /// take the slots of the host's blocks in order (block `k` first), a third child of fewer
    /// host blocks gets a new slot and a leaf in the tree, a host block left without a child
    /// is merged into `k`.
    fn apply_resplit(
        &mut self,
        slot: &mut Vec<Option<Ring>>,
        owner: &mut Vec<usize>,
        alive: &mut Vec<bool>,
        k: usize,
        (host, (_, children, ends)): (Host, Resplit),
    ) {
        let (children, ids) = self.commit_resplit(children, &ends);
        alive.extend(ids.iter().map(|_| true));
        let (mut slots, merged) = host.parts(k);
        for c in merged {
            alive[c] = false;
        }
        let n = children.len();
        for (i, child) in children.into_iter().enumerate() {
            if i < slots.len() {
                slot[slots[i]] = Some(child);
            } else {
                slot.push(Some(child));
                let m = slot.len() - 1;
                owner.push(m);
                self.branch_leaf(slots[i - 1], m, ids[i - 1]);
                slots.push(m);
            }
        }
        for &s in &slots[n..] {
            slot[s] = None;
            owner[s] = k;
        }
    }

    /// Cost of a block for the **relaxed** repair of blocks that would get a corner inside a
    /// cut: `None` if it would itself need one (or has no usable corners at all, or is
    /// negligible); else `grade + F` with F its corner score and grade 0 for a good block, 1
    /// for an approximately convex block that keeps a critical angle or is a triangle block
    /// served on the original boundary, 3 for a block that is not approximately convex.
    fn relaxed_cost(&self, ring: &Ring) -> Option<f64> {
        let tol = &self.opts.tolerances;
        if crate::geom::signed_area(&ring.pts) < 0.1 * self.min_area {
            return None;
        }
        if let Some(f) = self.good_fit(ring) {
            return Some(f);
        }
        let triangle = triangle_plan(ring, tol.theta_minus, self.opts);
        if triangle.as_ref().is_some_and(|t| t.1) {
            return None;
        }
        if triangle.is_none() && !self.usable(&ring.pts) {
            return None;
        }
        let grade = if measures(&ring.pts).approximately_convex(tol) {
            1.0
        } else {
            3.0
        };
        Some(grade + quad_fit(&ring.pts))
    }

    /// Applies a merge found by [`Builder::best_merge`] to slots `k` and `j`.
    fn apply_merge(
        &mut self,
        slot: &mut [Option<Ring>],
        owner: &mut [usize],
        alive: &mut Vec<bool>,
        k: usize,
        m: Merge,
    ) {
        let (_, j, c, split, u) = m;
        alive[c] = false;
        match split {
            None => {
                slot[k] = Some(u);
                slot[j] = None;
                owner[j] = k;
            }
            Some((_, a, b, ends)) => {
                let (a, b, _) = self.commit_split(a, b, ends);
                alive.push(true);
                slot[k] = Some(a);
                slot[j] = Some(b);
            }
        }
    }

    /// Step 4 of the repair: every block that would still get a corner inside a
    /// cut (a cut joint: a block bounded by cuts without four usable corners, whose
    /// triangle-block rule cannot insert on the original boundary) is split, or merged with a
    /// neighbour (and the union re-split), into blocks that take their corners without one —
    /// accepting a critical angle or a non-convex block ([`Builder::relaxed_cost`]): a
    /// singular mesh node is worse than a less admissible block. Split alone or merge, the
    /// lower score wins.
    fn joint_pass(
        &mut self,
        slot: &mut Vec<Option<Ring>>,
        owner: &mut Vec<usize>,
        alive: &mut Vec<bool>,
    ) {
        // relaxed: a block that would still get a corner inside a cut (a cut joint) is
        // split, or merged (and re-split), into blocks that can take their corners without one,
        // accepting a critical angle or a non-convex block (relaxed_cost) — a singular mesh
        // node is worse than a less admissible block
        let theta = self.opts.tolerances.theta_minus;
        let mut k = 0;
        let mut budget = 2 * slot.len() + 8;
        while k < slot.len() && budget > 0 {
            let Some(r) = slot[k].clone() else {
                k += 1;
                continue;
            };
            if !needs_cut_point(&r, theta, self.opts) {
                k += 1;
                continue;
            }
            budget -= 1;
            let relaxed = |u: &Ring| self.relaxed_cost(u);
            let alone = self.best_split_by(&r, &relaxed, false, None);
            let merge = self.best_merge(slot, k, alive, &relaxed, false);
            match (alone, merge) {
                (Some(s), m) if m.as_ref().is_none_or(|m| s.0 <= m.0) => {
                    let (_, a, b, ends) = s;
                    let (a, b, id) = self.commit_split(a, b, ends);
                    alive.push(true);
                    slot[k] = Some(a);
                    slot.push(Some(b));
                    owner.push(slot.len() - 1);
                    self.branch_leaf(k, slot.len() - 1, id);
                }
                (_, Some(m)) => self.apply_merge(slot, owner, alive, k, m),
                _ => k += 1,
            }
        }
    }

    /// Steps 1–3 of the repair of block slot `k` (ring `r`), in that order: the first step
    /// that finds something decides.
    fn attempt(&self, slot: &[Option<Ring>], k: usize, alive: &[bool], r: &Ring) -> Attempt {
        if let Some(s) = self.best_split(r) {
            return Attempt::Split(s);
        }
        if let Some(m) = self.best_merge(slot, k, alive, &|u: &Ring| self.good_fit(u), true) {
            return Attempt::Merge(m);
        }
        match self.best_resplit(slot, k, alive) {
            Some((host, t)) => Attempt::Resplit(host, t),
            None => Attempt::Fail,
        }
    }

    /// [`Builder::attempt`] through the builder's [`RepairCache`] (if it has one).
    ///
    /// Exact: the attempt reads only the rings of the blocks in the neighbourhood of `k`
    /// (block `k`, the blocks across its cuts and the blocks across theirs), which of their
    /// cuts are alive and protected, and which slots share a cut (and in which slot order);
    /// the builder's options and minimum area are the same for every builder sharing a cache
    /// (one region, one option set). [`Neighbourhood`] encodes exactly that with slot numbers
    /// replaced by their rank in the neighbourhood and cut ids by their order of appearance,
    /// so an equal key means the same search on relabelled input, whose result is the cached
    /// one relabelled back. The key is stored whole (no hash collision can change a result).
    fn cached_attempt(
        &self,
        slot: &[Option<Ring>],
        k: usize,
        alive: &[bool],
        r: &Ring,
        nb: &Neighbourhood,
    ) -> Attempt {
        let Some(cache) = self.cache.as_ref().map(|c| &c.repair) else {
            return self.attempt(slot, k, alive, r);
        };
        let hit = cache
            .lock()
            .ok()
            .and_then(|c| c.attempts.get(&nb.key).cloned());
        if let Some(a) = hit {
            if let Some(a) = a.relabel(&|p| nb.slots.get(p).copied(), &|c| nb.cuts.get(c).copied())
            {
                return a;
            }
        }
        let a = self.attempt(slot, k, alive, r);
        if let Some(canon) = a.relabel(&|s| nb.slots.iter().position(|&x| x == s), &|c| {
            nb.cuts.iter().position(|&x| x == c)
        }) {
            if let Ok(mut c) = cache.lock() {
                c.attempts.insert(nb.key.clone(), canon);
            }
        }
        a
    }

    /// The corner-repair pass (module documentation). `rings[k]` is block `k`; the tree's leaf
    /// nodes point to block ids. Returns the new blocks (cuts and tree renumbered).
    pub(crate) fn repair_pass(&mut self, rings: Vec<Ring>) -> Vec<Ring> {
        let mut slot: Vec<Option<Ring>> = rings.into_iter().map(Some).collect();
        let mut owner: Vec<usize> = (0..slot.len()).collect();
        let mut alive = vec![true; self.cuts.len()];
        let mut k = 0;
        let mut budget = 4 * slot.len() + 16;
        // a repair changes the neighbours of blocks already passed over: sweep again while
        // the last sweep changed something (and the budget lasts)
        let mut changed = false;
        // the neighbourhood of each block whose repair failed: the search depends only on the
        // block, its neighbours and theirs (and the live cuts between them), so while those
        // are unchanged a later sweep would fail again on the same candidates
        let mut failed: Vec<Option<Neighbourhood>> = Vec::new();
        // the cut holders of the current slots, recomputed after each change of the slots
        // (a failed attempt changes nothing, and most attempts fail)
        let mut holders: Option<CutHolders> = None;
        while budget > 0 {
            if k >= slot.len() {
                if !changed {
                    break;
                }
                (k, changed) = (0, false);
            }
            let Some(r) = slot[k].clone() else {
                k += 1;
                continue;
            };
            if !self.needs_repair(&r) {
                k += 1;
                continue;
            }
            let held = holders.get_or_insert_with(|| cut_holders(&slot));
            let nb = Neighbourhood::new(&slot, held, k, &alive, self.protected_cuts);
            if failed.get(k).is_some_and(|f| f.as_ref() == Some(&nb)) {
                k += 1;
                continue;
            }
            budget -= 1;
            let attempt = self.cached_attempt(&slot, k, &alive, &r, &nb);
            if !matches!(attempt, Attempt::Fail) {
                holders = None;
            }
            match attempt {
                // 1. split alone
                Attempt::Split((_, a, b, ends)) => {
                    let (a, b, id) = self.commit_split(a, b, ends);
                    alive.push(true);
                    slot[k] = Some(a);
                    slot.push(Some(b));
                    owner.push(slot.len() - 1);
                    self.branch_leaf(k, slot.len() - 1, id);
                    changed = true;
                }
                // 2. merge with a neighbour, possibly followed by a split
                Attempt::Merge(m) => {
                    self.apply_merge(&mut slot, &mut owner, &mut alive, k, m);
                    changed = true;
                }
                // 3. the block alone or merged with one neighbour, by two cuts into three good
                //    blocks; merged with two neighbours, by one or two cuts
                Attempt::Resplit(host, t) => {
                    self.apply_resplit(&mut slot, &mut owner, &mut alive, k, (host, t));
                    changed = true;
                }
                Attempt::Fail => {
                    if failed.len() <= k {
                        failed.resize_with(k + 1, || None);
                    }
                    failed[k] = Some(nb);
                    k += 1;
                }
            }
        }
        self.joint_pass(&mut slot, &mut owner, &mut alive);
        self.renumber(slot, owner, alive)
    }

    /// Drops dead cuts and empty slots, renumbers cut tags, tree cuts and leaf blocks
    /// (`owner`: union-find over the slots, a merged slot points at the slot it joined).
    pub(crate) fn renumber(
        &mut self,
        slot: Vec<Option<Ring>>,
        mut owner: Vec<usize>,
        alive: Vec<bool>,
    ) -> Vec<Ring> {
        fn root(o: &mut [usize], x: usize) -> usize {
            let mut r = x;
            while o[r] != r {
                r = o[r];
            }
            o[x] = r;
            r
        }
        let mut new_id = vec![usize::MAX; self.cuts.len()];
        let mut cuts = Vec::new();
        for (c, &a) in alive.iter().enumerate().take(self.cuts.len()) {
            if a {
                new_id[c] = cuts.len();
                cuts.push(self.cuts[c]);
            }
        }
        self.cuts = cuts;
        let mut block_of_slot = vec![usize::MAX; slot.len()];
        let mut out = Vec::new();
        for (k, r) in slot.into_iter().enumerate() {
            if let Some(mut r) = r {
                for t in &mut r.tags {
                    if let Tag::Cut(c) = t {
                        *c = new_id[*c];
                    }
                }
                block_of_slot[k] = out.len();
                out.push(r);
            }
        }
        for node in &mut self.nodes {
            node.cuts
                .retain(|c| new_id.get(*c).is_some_and(|x| *x != usize::MAX));
            for c in &mut node.cuts {
                *c = new_id[*c];
            }
            if let Some(b) = node.block {
                if b < owner.len() {
                    let r = root(&mut owner, b);
                    node.block = block_of_slot.get(r).copied().filter(|x| *x != usize::MAX);
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::auto::DecomposeOptions;
    use unamalla_mesh::Region;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    fn ring(pts: &[(f64, f64)], tags: &[Tag]) -> Ring {
        Ring {
            pts: pts.iter().map(|&(x, y)| v(x, y)).collect(),
            tags: tags.to_vec(),
        }
    }

    const B: Tag = Tag::Boundary(0);

    /// L-shape (4×4 square minus the 2×2 top-right square) with a straight boundary vertex
    /// S = (0, 2) on its left side.
    fn l_region() -> Region {
        Region::new(
            vec![
                v(0., 0.),
                v(4., 0.),
                v(4., 2.),
                v(2., 2.),
                v(2., 4.),
                v(0., 4.),
                v(0., 2.),
            ],
            vec![],
        )
        .unwrap()
    }

    #[test]
    fn triangle_without_usable_fourth_corner_gets_a_moved_cut() {
        // a bad cut (2,2)–(0,4) leaves the triangle (2,2),(2,4),(0,4) (45°/90°/45°: three
        // usable corners only). The union with its neighbour is the L-shape, not approximately
        // convex (κ₃ = 0.5 > 0.1, see the concavity tests), so the repair must re-split it: the
        // best splits into two good blocks are the cuts (2,2)–(0,2) and (2,2)–(2,0) (two
        // rectangles of areas 8 and 4, corner score 0 each: four 90° corners, balanced sides,
        // straight sides; the same cut length and end angles, so they tie on the score).
        let region = l_region();
        let opts = DecomposeOptions::default();
        let mut b = Builder::new(&region, &opts);
        b.cuts = vec![(v(2., 2.), v(0., 4.))];
        let tri = ring(&[(2., 2.), (2., 4.), (0., 4.)], &[B, B, Tag::Cut(0)]);
        let rest = ring(
            &[(0., 0.), (4., 0.), (4., 2.), (2., 2.), (0., 4.), (0., 2.)],
            &[B, B, B, Tag::Cut(0), B, B],
        );
        assert!(b.needs_repair(&tri));
        let out = b.repair_pass(vec![rest, tri]);
        assert_eq!(out.len(), 2);
        assert_eq!(b.cuts.len(), 1);
        let (p, q) = b.cuts[0];
        let ends = [p, q];
        assert!(
            ends.contains(&v(2., 2.)) && (ends.contains(&v(0., 2.)) || ends.contains(&v(2., 0.))),
            "{ends:?}"
        );
        for r in &out {
            assert!(b.good(r), "{:?}", r.pts);
            let a = crate::geom::signed_area(&r.pts);
            assert!(
                (a - 8.0).abs() < 1e-12 || (a - 4.0).abs() < 1e-12,
                "area {a}"
            );
        }
    }

    #[test]
    fn u_shaped_block_needs_two_cuts() {
        // U = 3×3 square minus the 1×2 slot (1,1)–(2,3): κ₁ = (16 − 12)/16 = 0.25 > τ₁⁻, so it
        // needs a repair. Every single cut leaves a child with a reflex vertex and κ₁ ≥ 0.1
        // (an L or the U itself), so steps 1–2 find nothing (no neighbours to merge with);
        // step 3 must split it by two cuts into three rectangles (four usable 90° corners
        // each), with areas adding up to 9 − 2 = 7.
        let u = [
            (0., 0.),
            (3., 0.),
            (3., 3.),
            (2., 3.),
            (2., 1.),
            (1., 1.),
            (1., 3.),
            (0., 3.),
        ];
        let region = Region::new(u.iter().map(|&(x, y)| v(x, y)).collect(), vec![]).unwrap();
        let opts = DecomposeOptions::default();
        let mut b = Builder::new(&region, &opts);
        let block = ring(&u, &[B; 8]);
        assert!(b.needs_repair(&block));
        assert!(b.best_split(&block).is_none());
        let out = b.repair_pass(vec![block]);
        assert_eq!(out.len(), 3, "{out:?}");
        assert_eq!(b.cuts.len(), 2);
        let mut total = 0.0;
        for r in &out {
            assert!(b.good(r), "{:?}", r.pts);
            // a rectangle: every corner the best fit picks is a right angle
            let (c, _) = select_corners(&r.pts, &opts.corner_weights).expect("four corners");
            for &i in &c {
                let n = r.len();
                let (p, a, q) = (r.pts[(i + n - 1) % n], r.pts[i], r.pts[(i + 1) % n]);
                assert!((p - a).dot(q - a).abs() < 1e-12, "{:?} at {a:?}", r.pts);
            }
            total += crate::geom::signed_area(&r.pts);
        }
        assert!((total - 7.0).abs() < 1e-12, "area {total}");
        // each new cut has both ends on the region boundary and length 1 (the slot's depth
        // from a reflex vertex to the opposite side, or across an arm)
        for &(p, q) in &b.cuts {
            assert!((p.distance(q) - 1.0).abs() < 1e-12, "{p:?}–{q:?}");
        }
    }

    /// Where `CutTable::locate` matches a child's vertices and edges to the host's, the
    /// table's angles are `Builder::end_angles` on the child, bit for bit, and a cut between
    /// two such vertices is admissible in the child exactly when the table has it admissible
    /// in the host and it meets none of the child's other edges.
    #[test]
    fn end_angle_table_matches_the_child_angles() {
        let mut state = 0x5eed_1234_abcd_0001u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let bits = |a: [f64; 2]| a.map(f64::to_bits);
        let (mut checked, mut admitted) = (0, 0);
        for _ in 0..200 {
            let n = 6 + (next() * 30.0) as usize;
            let pts: Vec<DVec2> = (0..n)
                .map(|i| {
                    let t = std::f64::consts::TAU * (i as f64 + 0.5 * next()) / n as f64;
                    let r = 0.5 + next();
                    v(r * t.cos(), r * t.sin())
                })
                .collect();
            let host = ring(
                &pts.iter().map(|p| (p.x, p.y)).collect::<Vec<_>>(),
                &vec![B; n],
            );
            let opts = DecomposeOptions::default();
            let region = l_region();
            let builder = Builder::new(&region, &opts);
            let table = CutTable::new(&host.pts, *builder.tier1_screen());
            // a child: the host from vertex i on, closed by a cut to a point inside an edge
            let i = (next() * n as f64) as usize % n;
            let len = 3 + (next() * (n - 4) as f64) as usize;
            let mut child: Vec<DVec2> = (0..len).map(|k| host.pts[(i + k) % n]).collect();
            let (a, b) = (host.pts[(i + len - 1) % n], host.pts[(i + len) % n]);
            let x = a + 0.5 * (b - a);
            child.push(x);
            // a child of an admissible cut lies in the host (admissibility is compared there)
            let host_piece = Piece {
                outer: host.clone(),
                holes: Vec::new(),
            };
            let cut_ends = [
                End {
                    ring: 0,
                    pos: Pos::OnEdge((i + len - 1) % n, x),
                },
                End {
                    ring: 0,
                    pos: Pos::Vertex(i),
                },
            ];
            let inside = host_piece.admissible_scan(cut_ends[0], cut_ends[1]);
            let child = Ring {
                tags: vec![B; child.len()],
                pts: child,
            };
            let at = table.locate(&child);
            let piece = Piece {
                outer: child.clone(),
                holes: Vec::new(),
            };
            let m = child.len();
            for k in (0..m).filter(|&k| at.vertex[k] != usize::MAX) {
                let e1 = End {
                    ring: 0,
                    pos: Pos::Vertex(k),
                };
                for l in (0..m).filter(|&l| l != k && at.vertex[l] != usize::MAX) {
                    let q = child.pts[l];
                    let (x, y) = Builder::end_angles(&piece, e1, q);
                    // the screen rejects only angles below θ₋
                    match table.vertex_angles(at.vertex[k], at.vertex[l]) {
                        Some(got) => assert_eq!(bits(got), bits([x, y])),
                        None => assert!(x.min(y) < opts.tolerances.theta_minus),
                    }
                    checked += 1;
                    // admissibility from the host's and the child's other edges
                    let idx = piece.index();
                    let e2 = End {
                        ring: 0,
                        pos: Pos::Vertex(l),
                    };
                    let to = End {
                        ring: 0,
                        pos: Pos::Vertex(at.vertex[l]),
                    };
                    let p = child.pts[k];
                    let hits = (0..m)
                        .filter(|&f| at.edge[f] == usize::MAX)
                        .any(|f| open_segment_hits(p, q, child.p(f), child.next(f)));
                    if inside {
                        let via_host = table.admissible(at.vertex[k], to) && !hits;
                        assert_eq!(piece.admissible(&idx, e1, e2), via_host, "{k} {l}");
                        admitted += via_host as usize;
                    }
                }
                for e in (0..m).filter(|&e| at.edge[e] != usize::MAX) {
                    let (a, b) = (child.p(e), child.next(e));
                    let x = a + crate::geom::project_t(child.pts[k], a, b) * (b - a);
                    let (p0, p1) = Builder::end_angles(&piece, e1, x);
                    let e2 = End {
                        ring: 0,
                        pos: Pos::OnEdge(e, x),
                    };
                    let (f0, f1) = Builder::end_angles(&piece, e2, child.pts[k]);
                    let want = [p0, p1, f0, f1];
                    match table.foot_angles(at.vertex[k], at.edge[e], x) {
                        Some(got) => assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits)),
                        None => assert!(want.iter().any(|&a| a < opts.tolerances.theta_minus)),
                    }
                }
            }
        }
        assert!(checked > 1000, "{checked}");
        assert!(admitted > 100, "{admitted}");
    }

    #[test]
    fn non_convex_block_bounded_by_cuts_is_split() {
        // the L-shape as a block whose every edge is a cut (like the pentagon of cuts around the
        // Gulf of Mexico's central basin): new cuts may end only at its vertices; the cut from
        // the reflex vertex (2,2) to the vertex (0,2) gives two rectangles (the foot (2,0) is
        // not offered: that edge is a cut, and a cut ending inside a cut is a T-junction).
        let region = l_region();
        let opts = DecomposeOptions::default();
        let mut b = Builder::new(&region, &opts);
        // pretend cut ids 0..7 exist (the outer neighbours are not part of this test)
        b.cuts = (0..7).map(|_| (v(0., 0.), v(1., 0.))).collect();
        let tags: Vec<Tag> = (0..7).map(Tag::Cut).collect();
        let l = ring(
            &[
                (0., 0.),
                (4., 0.),
                (4., 2.),
                (2., 2.),
                (2., 4.),
                (0., 4.),
                (0., 2.),
            ],
            &tags,
        );
        assert!(b.needs_repair(&l));
        let (_, a, c, ends) = b.best_split(&l).expect("a split");
        assert!(b.good(&a) && b.good(&c));
        let e = [ends.0, ends.1];
        assert!(
            e.contains(&v(2., 2.)) && (e.contains(&v(0., 2.)) || e.contains(&v(2., 0.))),
            "{e:?}"
        );
    }

    #[test]
    fn cut_free_triangle_merges_back() {
        // rectangle with a straight vertex S = (2,0); a cut S–(4,2) leaves a 45°/90°/45°
        // triangle. The union is the rectangle (four 90° corners): merge, no cut left.
        let region = Region::new(
            vec![v(0., 0.), v(2., 0.), v(4., 0.), v(4., 2.), v(0., 2.)],
            vec![],
        )
        .unwrap();
        let opts = DecomposeOptions::default();
        let mut b = Builder::new(&region, &opts);
        b.cuts = vec![(v(2., 0.), v(4., 2.))];
        let tri = ring(&[(2., 0.), (4., 0.), (4., 2.)], &[B, B, Tag::Cut(0)]);
        let rest = ring(
            &[(0., 0.), (2., 0.), (4., 2.), (0., 2.)],
            &[B, Tag::Cut(0), B, B],
        );
        let out = b.repair_pass(vec![rest, tri]);
        assert_eq!(out.len(), 1);
        assert!(b.cuts.is_empty());
        assert!((crate::geom::signed_area(&out[0].pts) - 8.0).abs() < 1e-12);
    }

    #[test]
    fn triangle_of_cuts_gets_no_corner_inside_a_cut() {
        // 10 × 10 square cut by the triangle of cuts P = (5,0), Q = (10,6), R = (0,6) (the
        // situation once seen on maryland: a piece bounded by cuts only). Its angles are
        // 2·atan(5/6) = 79.6° at P and atan(6/5) = 50.2° at Q and R (no critical angle), so the
        // triangle-block rule would put its fourth corner at the midpoint of its longest side —
        // inside a cut (a valence-3 node in the mesh). The joint pass must merge it away.
        let region =
            Region::new(vec![v(0., 0.), v(10., 0.), v(10., 10.), v(0., 10.)], vec![]).unwrap();
        let opts = DecomposeOptions::default();
        let mut b = Builder::new(&region, &opts);
        b.cuts = vec![
            (v(5., 0.), v(10., 6.)),
            (v(10., 6.), v(0., 6.)),
            (v(0., 6.), v(5., 0.)),
        ];
        let (c0, c1, c2) = (Tag::Cut(0), Tag::Cut(1), Tag::Cut(2));
        let t = ring(&[(5., 0.), (10., 6.), (0., 6.)], &[c0, c1, c2]);
        let theta = opts.tolerances.theta_minus;
        assert!(needs_cut_point(&t, theta, &opts));
        let mut slot = vec![
            Some(t),
            Some(ring(&[(5., 0.), (10., 0.), (10., 6.)], &[B, B, c0])),
            Some(ring(
                &[(10., 6.), (10., 10.), (0., 10.), (0., 6.)],
                &[B, B, B, c1],
            )),
            Some(ring(&[(0., 0.), (5., 0.), (0., 6.)], &[B, c2, B])),
        ];
        // the outer blocks are served on the boundary (triangles with two boundary edges,
        // the rectangle-like top block has four usable corners)
        for r in slot.iter().skip(1).flatten() {
            assert!(!needs_cut_point(r, theta, &opts), "{:?}", r.pts);
        }
        let mut owner: Vec<usize> = (0..4).collect();
        let mut alive = vec![true; 3];
        b.joint_pass(&mut slot, &mut owner, &mut alive);
        let out = b.renumber(slot, owner, alive);
        // one cut fewer at least, no block needs a point inside a cut, area 100 preserved
        assert!(out.len() <= 3, "{} blocks", out.len());
        assert_eq!(b.cuts.len(), out.len() - 1);
        let area: f64 = out.iter().map(|r| crate::geom::signed_area(&r.pts)).sum();
        assert!((area - 100.0).abs() < 1e-9, "area {area}");
        for r in &out {
            assert!(!needs_cut_point(r, theta, &opts), "{:?}", r.pts);
            assert!(r.tags.iter().any(|t| matches!(t, Tag::Boundary(_))));
        }
    }
}
