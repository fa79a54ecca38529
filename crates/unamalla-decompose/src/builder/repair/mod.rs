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

use unamalla_mesh::DVec2;

use crate::builder::{needs_cut_point, triangle_plan, Builder};
use crate::concavity::{critical_angles, measures, measures_with_angles};
use crate::corners::{has_four_corners, quad_fit, quad_fit_with_angles, select_corners};
use crate::corners_diametral::CornerChoice;
use crate::geom::ring_angles;
use crate::piece::{Ring, Tag};

mod cache;
mod merge;
mod split;
mod table;
#[cfg(test)]
mod tests;

use self::cache::Attempt;
use self::merge::{cut_holders, CutHolders, Neighbourhood};
pub(crate) use cache::RepairCache;

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
