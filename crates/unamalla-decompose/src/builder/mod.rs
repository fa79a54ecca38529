//! The state of one decomposition ([`Builder`]): the cuts, the binary tree T and the pieces
//! at its leaves ([Méndez 2023, §4.3]), and what every stage shares — applying a cut to the
//! piece that admits it and the angle terms of a candidate cut (the tiers of the validity
//! rules, [Méndez 2023, §4.2.3]).
//!
//! The stages, in files of their own (each an `impl Builder` block):
//!
//! - `run`: Algorithm 1 on the leaves ([Méndez 2023, §4.2.1]), with its convexity test, run
//!   in parallel and replayed from the cache;
//! - `holes`: Algorithm 2, hole removal;
//! - `concave`: Algorithm 3, the concavity cut;
//! - `critical`: Algorithm 4, the triangle cut off at a critical angle;
//! - `merge`: the cleanup (merge) pass;
//! - `repair`: the corner repair and re-split;
//! - `finish`: corners (and the triangle-block rule, [Méndez 2023, §5.1.1]) and the final
//!   [`Decomposition`](crate::Decomposition);
//! - `cache`: the work shared by the layouts of one region (Algorithm 1 runs, applied cut
//!   lists, merge tests) and the layout build that uses it.

use std::f64::consts::PI;
use std::sync::Arc;

use unamalla_mesh::{DVec2, Region};

use crate::decomposition::{Step, TreeNode};
use crate::geom::{angle_penalty, left_angle, project_t};
use crate::piece::{End, Piece, Pos, Ring, Tag};
use crate::DecomposeOptions;

mod cache;
mod concave;
mod critical;
mod finish;
mod holes;
mod merge;
pub(crate) mod repair;
mod run;

pub(crate) use cache::{layout_from_cuts_cached, LayoutCache};
pub(crate) use finish::{choose_corners, needs_cut_point, triangle_plan};

/// What [`Builder::apply_cut`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Applied {
    /// The cut split a piece in two.
    Split,
    /// The cut joined a hole to its piece's outer ring.
    Bridged,
    /// The only piece admitting the cut has both ends on holes not yet joined.
    JoinsTwoHoles,
    /// No piece has both ends on its boundary and admits the cut.
    NoPiece,
}

/// A candidate cut inside a piece.
#[derive(Clone, Copy, Debug)]
struct Cand {
    e1: End,
    e2: End,
    pre: f64,
}

/// One decomposition in progress: the cuts made so far, the binary tree T with a piece at
/// each leaf, and the options. The fields are private to this module and its stages, except
/// `cuts`, `protected_cuts` and `auto_repair`, which the file loader (module
/// [`file`](crate::file)) sets after applying the user's cuts.
pub(crate) struct Builder<'a> {
    region: &'a Region,
    opts: &'a DecomposeOptions,
    /// The cuts made so far (end points), by cut id.
    pub(crate) cuts: Vec<(DVec2, DVec2)>,
    /// The nodes of the binary tree T.
    nodes: Vec<TreeNode>,
    /// The piece of each leaf of T (`None` for inner nodes).
    pieces: Vec<Option<Piece>>,
    /// Cuts with an id below this were given by the user and are never merged away.
    pub(crate) protected_cuts: usize,
    min_area: f64,
    min_triangle: f64,
    /// Run the corner repair in [`Builder::finish`] (off for a file that lists cuts only: those
    /// are exactly the user's cuts).
    pub(crate) auto_repair: bool,
    /// Work shared with the other builders of one region and option set (the rebuilds of
    /// [`chord_layout_cuts`](crate::chord_layout_cuts)); `None`: nothing is cached.
    cache: Option<Arc<LayoutCache>>,
    /// [`AngleScreen`]s of the angle limits of [`Builder::angle_terms`]'s tiers 0–1, 2 and 3.
    screens: [AngleScreen; 3],
}

/// A test deciding cheaply, for some vertex chains, that [`left_angle`] is below a limit λ or
/// above π + 10⁻⁹ — decisions that [`Builder::angle_terms`] would reach from the `atan2`
/// angle — and nothing otherwise.
///
/// `left_angle(prev, cur, next)` is `atan2(y, x)` (plus 2π when that is ≤ 0) for
/// `y = u.perp_dot(v)`, `x = u.dot(v)`, `u = next − cur`, `v = prev − cur`; the test reads the
/// same `y` and `x`. Below λ (0 < λ < 1.4): `y > 0`, `x > 0` and `r = fl(y/x)` in
/// `[10⁻²⁰⁰, tan λ·(1 − 10⁻⁹))`. Then `y/x` is within 2⁻⁵² of `r` (relative), so the true
/// angle `atan(y/x)` is at least 10⁻²⁰⁰·(1 − 10⁻¹⁵) and at least 10⁻¹⁰·λ below λ — far more
/// than the error of `atan2` and of `tan` (a few units in the last place): the computed angle
/// is in `(0, λ)` as well. Above π + 10⁻⁹: `y < 0` and either `x ≥ 0` (the computed `atan2`
/// is in `[−π/2, 0]`, so the angle is at least 3π/2 less a rounding) or `x < 0` with
/// `fl(y/x) > 10⁻⁶` (the true `atan2(y, x)` = −π + atan(y/x) is at least −π + 10⁻⁶·(1 − 10⁻⁶),
/// so the computed angle, `atan2 + 2π`, is above π + 10⁻⁹).
#[derive(Clone, Copy, Debug)]
pub(crate) struct AngleScreen {
    /// tan λ·(1 − 10⁻⁹), or 0 (nothing is below) when λ is not in (0, 1.4).
    tan_below: f64,
}

impl AngleScreen {
    /// The screen of the angle limit λ = `limit` (radians).
    fn new(limit: f64) -> Self {
        let tan_below = if limit > 0.0 && limit < 1.4 {
            limit.tan() * (1.0 - 1e-9)
        } else {
            0.0
        };
        Self { tan_below }
    }

    /// The `(y, x)` of `left_angle(prev, cur, next)` (see the type's documentation).
    fn yx(prev: DVec2, cur: DVec2, next: DVec2) -> (f64, f64) {
        let (u, v) = (next - cur, prev - cur);
        (u.perp_dot(v), u.dot(v))
    }

    /// `true` only if `left_angle(prev, cur, next)` is below the limit.
    pub(crate) fn surely_below(&self, prev: DVec2, cur: DVec2, next: DVec2) -> bool {
        let (y, x) = Self::yx(prev, cur, next);
        if !(y > 0.0 && x > 0.0) {
            return false;
        }
        let r = y / x;
        (1e-200..self.tan_below).contains(&r)
    }

    /// `true` only if `left_angle(prev, cur, next)` is above π + 10⁻⁹.
    fn surely_reflex(prev: DVec2, cur: DVec2, next: DVec2) -> bool {
        let (y, x) = Self::yx(prev, cur, next);
        y < 0.0 && (x >= 0.0 || y / x > 1e-6)
    }
}

/// Whether a candidate cut whose cheap terms are `pre` (and every later one: the candidates
/// are sorted by `pre`) cannot beat the best score `best` so far.
///
/// Exact for the two-child score `s = ½·max(B₁, B₂) + ¼·(B₁ + B₂) + pre` (`B` a badness or a
/// corner cost, never negative: the quad fit's corner score F is a sum of squares and ratios
/// of lengths with its fixed non-negative weights, its fallback ½ + a mean of squares,
/// `1 + κ₂ + κ₃` is at least 1 and a grade is 0, 1 or 3): the first two terms add up to some
/// `X ≥ 0` (or
/// NaN), and rounding is monotone, so `s = fl(X + pre) ≥ pre ≥ best` (or NaN): `s < best`,
/// the test for a new best, fails. A later candidate has a `pre` at least as large (in the
/// `total_cmp` order of the sort, only a NaN comes after, whose score is NaN).
pub(crate) fn beyond_best(pre: f64, best: f64) -> bool {
    pre >= best
}

impl<'a> Builder<'a> {
    pub fn new(region: &'a Region, opts: &'a DecomposeOptions) -> Self {
        let outer = Ring {
            pts: region.outer().points().to_vec(),
            tags: vec![Tag::Boundary(0); region.outer().len()],
        };
        let holes = region
            .holes()
            .iter()
            .enumerate()
            .map(|(k, h)| Ring {
                pts: h.points().to_vec(),
                tags: vec![Tag::Boundary(k + 1); h.len()],
            })
            .collect();
        Self {
            region,
            opts,
            cuts: Vec::new(),
            nodes: vec![TreeNode::root()],
            pieces: vec![Some(Piece { outer, holes })],
            protected_cuts: 0,
            min_area: opts.min_area_fraction * region.area(),
            min_triangle: opts.min_triangle_fraction * region.area(),
            auto_repair: true,
            cache: None,
            screens: Self::angle_screens(opts),
        }
    }

    /// The [`AngleScreen`]s of the tiers' angle limits ([`Builder::angle_terms`]).
    fn angle_screens(opts: &DecomposeOptions) -> [AngleScreen; 3] {
        let theta = opts.tolerances.theta_minus;
        [theta, 0.5 * theta, 0.2 * theta].map(AngleScreen::new)
    }

    fn leaves(&self) -> usize {
        self.nodes.iter().filter(|n| n.children.is_empty()).count()
    }

    /// Replaces leaf `node` by two children.
    pub fn branch(
        &mut self,
        node: usize,
        step: Step,
        cuts: Vec<usize>,
        a: Piece,
        b: Piece,
    ) -> [usize; 2] {
        let mut ids = [0; 2];
        for (k, p) in [a, b].into_iter().enumerate() {
            let label = if self.nodes[node].label.is_empty() {
                format!("{}", k + 1)
            } else {
                format!("{}.{}", self.nodes[node].label, k + 1)
            };
            self.nodes.push(TreeNode {
                label,
                parent: Some(node),
                children: Vec::new(),
                step: None,
                cuts: Vec::new(),
                block: None,
            });
            self.pieces.push(Some(p));
            ids[k] = self.nodes.len() - 1;
        }
        self.nodes[node].children = ids.to_vec();
        self.nodes[node].step = Some(step);
        self.nodes[node].cuts = cuts;
        self.pieces[node] = None;
        ids
    }

    /// Applies the straight cut `a`–`b` to the first leaf piece that has both points on its
    /// boundary (within `tol`) and admits the cut: a split when both ends are on the piece's
    /// outer ring, a bridge when one end is on a hole. Used by the decomposition file (user
    /// cuts) and by the chord layout.
    pub fn apply_cut(&mut self, a: DVec2, b: DVec2, tol: f64, step: Step) -> Applied {
        let mut joins_holes = false;
        for node in 0..self.nodes.len() {
            let Some(piece) = self.pieces[node].as_ref() else {
                continue;
            };
            let locate = |p: DVec2| -> Option<End> {
                for (r, ring) in piece.rings().enumerate() {
                    if let Some(i) = ring.pts.iter().position(|&x| x == p) {
                        return Some(End {
                            ring: r,
                            pos: Pos::Vertex(i),
                        });
                    }
                }
                for (r, ring) in piece.rings().enumerate() {
                    if let Some(i) = ring.pts.iter().position(|&x| x.distance(p) <= tol) {
                        return Some(End {
                            ring: r,
                            pos: Pos::Vertex(i),
                        });
                    }
                    for i in 0..ring.len() {
                        if matches!(ring.tags[i], Tag::Boundary(_))
                            && unamalla_mesh::geometry::point_segment_distance(
                                p,
                                ring.p(i),
                                ring.next(i),
                            ) <= tol
                        {
                            return Some(End {
                                ring: r,
                                pos: Pos::OnEdge(i, p),
                            });
                        }
                    }
                }
                None
            };
            let (Some(e1), Some(e2)) = (locate(a), locate(b)) else {
                continue;
            };
            // one test on this piece: a scan of its edges (`admissible_scan`)
            if !piece.admissible_scan(e1, e2) {
                continue;
            }
            if e1.ring != 0 && e2.ring != 0 {
                joins_holes = true;
                continue;
            }
            let mut m = piece.clone();
            let (x, y) = m.insert_ends(e1, e2);
            let id = self.new_cut(m.ring(e1.ring).p(x), m.ring(e2.ring).p(y));
            if e1.ring == 0 && e2.ring == 0 {
                let (pa, pb) = m.split(x, y, id);
                self.branch(node, step, vec![id], pa, pb);
                return Applied::Split;
            }
            let (o, h, k) = if e1.ring == 0 {
                (x, e2.ring, y)
            } else {
                (y, e1.ring, x)
            };
            m.merge(o, h, k, id);
            self.pieces[node] = Some(m);
            self.nodes[node].cuts.push(id);
            return Applied::Bridged;
        }
        if joins_holes {
            Applied::JoinsTwoHoles
        } else {
            Applied::NoPiece
        }
    }

    pub fn new_cut(&mut self, a: DVec2, b: DVec2) -> usize {
        self.cuts.push((a, b));
        self.cuts.len() - 1
    }

    /// The two new angles at a cut end going towards `target`: (angle on the side of the
    /// outgoing edge, angle on the side of the incoming edge).
    pub(crate) fn end_angles(piece: &Piece, e: End, target: DVec2) -> (f64, f64) {
        let (prev, cur, next) = piece.chain(e);
        (left_angle(target, cur, next), left_angle(prev, cur, target))
    }

    /// Angle penalty ḡ of a candidate cut and its smallest new angle, or `None` if a new angle
    /// is below the tier's limit: tiers 0 and 1 use θ₋ (tier 0 also requires that a reflex start
    /// vertex is resolved: both new angles at `e1` at most 180°), tier 2 uses ½θ₋, tier 3 uses
    /// ⅕θ₋ (relaxed passes, only tried when the stricter ones find nothing).
    pub(crate) fn angle_terms(
        &self,
        piece: &Piece,
        e1: End,
        e2: End,
        tier: usize,
    ) -> Option<(f64, f64)> {
        if self.screened_out(piece, e1, e2, tier) {
            return None;
        }
        let (p, q) = (piece.point(e1), piece.point(e2));
        let (a, b) = Self::end_angles(piece, e1, q);
        let (c, d) = Self::end_angles(piece, e2, p);
        self.angle_terms_of([a, b, c, d], tier)
    }

    /// The [`AngleScreen`] of the angle limit of tier 1 (θ₋), the tier of the repair's
    /// searches.
    pub(crate) fn tier1_screen(&self) -> &AngleScreen {
        &self.screens[0]
    }

    /// Whether [`AngleScreen`] rejects the candidate cut from `e1` to `e2` in `tier`: a new
    /// angle surely below the tier's limit, or in tier 0 a reflex angle at `e1` — decisions
    /// that [`Builder::angle_terms_of`] would reach from the `atan2` angles (exact, see the
    /// screen), so [`Builder::angle_terms`] returns `None` without computing them.
    pub(crate) fn screened_out(&self, piece: &Piece, e1: End, e2: End, tier: usize) -> bool {
        let p = piece.point(e1);
        let q = piece.point(e2);
        let screen = &self.screens[tier.saturating_sub(1).min(2)];
        let (prev1, _, next1) = piece.chain(e1);
        let (prev2, _, next2) = piece.chain(e2);
        screen.surely_below(q, p, next1)
            || screen.surely_below(prev1, p, q)
            || screen.surely_below(p, q, next2)
            || screen.surely_below(prev2, q, p)
            || (tier == 0
                && (AngleScreen::surely_reflex(q, p, next1)
                    || AngleScreen::surely_reflex(prev1, p, q)))
    }

    /// [`Builder::angle_terms`] from the four new angles: `a`, `b` at the first end (as
    /// [`Builder::end_angles`] gives them towards the second end), `c`, `d` at the second.
    pub(crate) fn angle_terms_of(&self, [a, b, c, d]: [f64; 4], tier: usize) -> Option<(f64, f64)> {
        let min = a.min(b).min(c).min(d);
        let theta = self.opts.tolerances.theta_minus;
        let limit = match tier {
            0 | 1 => theta,
            2 => 0.5 * theta,
            _ => 0.2 * theta,
        };
        if min < limit {
            return None;
        }
        if tier == 0 && a.max(b) > PI + 1e-9 {
            return None;
        }
        let pen = angle_penalty(a) + angle_penalty(b) + angle_penalty(c) + angle_penalty(d);
        Some((pen / 4.0, min))
    }

    /// Feet of the perpendicular from `p` on the boundary-tagged edges of ring `r` of the piece
    /// (strictly inside the edge, away from its ends), plus the ring's vertices.
    pub(crate) fn targets_on_ring(
        piece: &Piece,
        r: usize,
        p: DVec2,
        skip: &dyn Fn(usize) -> bool,
        out: &mut Vec<End>,
    ) {
        let ring = piece.ring(r);
        let n = ring.len();
        for i in 0..n {
            if !skip(i) {
                out.push(End {
                    ring: r,
                    pos: Pos::Vertex(i),
                });
            }
            if skip(i) || skip((i + 1) % n) {
                continue;
            }
            if let Tag::Boundary(_) = ring.tags[i] {
                let a = ring.p(i);
                let b = ring.next(i);
                let t = project_t(p, a, b);
                if t > 0.03 && t < 0.97 {
                    out.push(End {
                        ring: r,
                        pos: Pos::OnEdge(i, a + t * (b - a)),
                    });
                }
            }
        }
    }
}
