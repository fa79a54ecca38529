//! The last stage: the merge pass, the repair, corners for every block (the triangle-block
//! rule of [Méndez 2023, §5.1.1] where needed) and the [`Decomposition`].

use std::f64::consts::PI;

use unamalla_mesh::DVec2;

use super::Builder;
use crate::corners::{select_corners, triangle_rule, CornerWeights, TriangleBlock};
use crate::decomposition::{Block, Cut, Decomposition, EdgeKind};
use crate::error::DecomposeError;
use crate::geom::ring_angle;
use crate::piece::{Ring, Tag};
use crate::DecomposeOptions;

impl Builder<'_> {
    /// Inserts `p` on edge `e` of block ring `bid`; if that edge is a cut, the point is also
    /// inserted in the neighbour's ring and the cut is split in two (the second half gets a new
    /// cut id, recorded in the tree node of the original cut).
    fn insert_on_edge(&mut self, rings: &mut [Ring], bid: usize, e: usize, p: DVec2) {
        let tag = rings[bid].tags[e];
        match tag {
            Tag::Boundary(_) => {
                rings[bid].pts.insert(e + 1, p);
                rings[bid].tags.insert(e + 1, tag);
            }
            Tag::Cut(c) => {
                let u = rings[bid].p(e);
                let new_id = self.cuts.len();
                let (a, b) = self.cuts[c];
                // cut c keeps the half at its endpoint a
                let (half_u, half_v) = if a == u { (c, new_id) } else { (new_id, c) };
                self.cuts[c] = (a, p);
                self.cuts.push((p, b));
                if let Some(node) = self.nodes.iter_mut().find(|n| n.cuts.contains(&c)) {
                    node.cuts.push(new_id);
                }
                rings[bid].pts.insert(e + 1, p);
                rings[bid].tags[e] = Tag::Cut(half_u);
                rings[bid].tags.insert(e + 1, Tag::Cut(half_v));
                // the neighbour: the other ring with an edge tagged c
                for (k, r) in rings.iter_mut().enumerate() {
                    if k == bid {
                        continue;
                    }
                    if let Some(f) = r.tags.iter().position(|t| *t == Tag::Cut(c)) {
                        // its edge runs v → u
                        r.pts.insert(f + 1, p);
                        r.tags[f] = Tag::Cut(half_v);
                        r.tags.insert(f + 1, Tag::Cut(half_u));
                        break;
                    }
                }
            }
        }
    }

    /// Turns the leaves into blocks, resolves neighbours, applies the triangle rule, selects
    /// corners and validates the result.
    pub fn finish(mut self) -> Result<Decomposition, DecomposeError> {
        // leaves in DFS order (child 1 before child 2)
        let mut order = Vec::new();
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            if self.nodes[n].children.is_empty() {
                order.push(n);
            } else {
                for &c in self.nodes[n].children.iter().rev() {
                    stack.push(c);
                }
            }
        }
        let mut rings: Vec<Ring> = Vec::with_capacity(order.len());
        for (bid, &n) in order.iter().enumerate() {
            let Some(piece) = self.pieces[n].take() else {
                continue;
            };
            if let Some(h) = piece.holes.first() {
                let hole = match h.tags[0] {
                    Tag::Boundary(r) => r.saturating_sub(1),
                    Tag::Cut(_) => 0,
                };
                return Err(DecomposeError::HoleNotSeparated { hole });
            }
            let mut seen_cuts: Vec<usize> = piece
                .outer
                .tags
                .iter()
                .filter_map(|t| match t {
                    Tag::Cut(c) => Some(*c),
                    Tag::Boundary(_) => None,
                })
                .collect();
            let total = seen_cuts.len();
            seen_cuts.sort_unstable();
            seen_cuts.dedup();
            if seen_cuts.len() != total {
                // a hole bridged by one cut but never separated by a second one
                let hole = piece
                    .outer
                    .tags
                    .iter()
                    .find_map(|t| match t {
                        Tag::Boundary(r) if *r > 0 => Some(r - 1),
                        _ => None,
                    })
                    .unwrap_or(0);
                return Err(DecomposeError::HoleNotSeparated { hole });
            }
            self.nodes[n].block = Some(bid);
            rings.push(piece.outer);
        }
        let rings = if self.opts.merge_blocks {
            self.merge_pass(rings)
        } else {
            rings
        };
        let rings = if self.opts.repair_corners && self.auto_repair {
            self.repair_pass(rings)
        } else {
            rings
        };
        // cut → blocks
        let mut sides: Vec<Vec<usize>> = vec![Vec::new(); self.cuts.len()];
        for (bid, r) in rings.iter().enumerate() {
            for t in &r.tags {
                if let Tag::Cut(c) = t {
                    sides[*c].push(bid);
                }
            }
        }
        let theta = self.opts.tolerances.theta_minus;
        let mut rings = rings;
        // phase A: triangle-block rule (inserting points, splitting cuts when needed)
        let mut corner_points: Vec<Option<[DVec2; 4]>> = vec![None; rings.len()];
        for bid in 0..rings.len() {
            let pts = rings[bid].pts.clone();
            let Some(((new_pts, origin, corners), _)) =
                triangle_plan(&rings[bid], theta, self.opts)
            else {
                continue;
            };
            // apply insertions from the last to the first so edge indices stay valid
            let mut ins: Vec<(usize, DVec2)> = origin
                .iter()
                .zip(&new_pts)
                .filter_map(|(o, p)| o.map(|e| (e, *p)))
                .collect();
            ins.sort_by(|a, b| {
                b.0.cmp(&a.0).then_with(|| {
                    let base = pts[a.0];
                    b.1.distance(base).total_cmp(&a.1.distance(base))
                })
            });
            for (e, p) in ins {
                self.insert_on_edge(&mut rings, bid, e, p);
            }
            corner_points[bid] = Some(corners.map(|k| new_pts[k]));
        }
        // cut → blocks
        let mut sides: Vec<Vec<usize>> = vec![Vec::new(); self.cuts.len()];
        for (bid, r) in rings.iter().enumerate() {
            for t in &r.tags {
                if let Tag::Cut(c) = t {
                    sides[*c].push(bid);
                }
            }
        }
        let cuts: Vec<Cut> = self
            .cuts
            .iter()
            .enumerate()
            .map(|(id, &(a, b))| Cut {
                id,
                a,
                b,
                blocks: [
                    sides[id].first().copied().unwrap_or(0),
                    sides[id].get(1).copied().unwrap_or(0),
                ],
            })
            .collect();
        // phase B: corners
        let mut blocks = Vec::with_capacity(rings.len());
        for (bid, r) in rings.into_iter().enumerate() {
            let edges: Vec<EdgeKind> = r
                .tags
                .iter()
                .map(|t| match *t {
                    Tag::Boundary(ring) => EdgeKind::Boundary { ring },
                    Tag::Cut(c) => EdgeKind::Cut {
                        cut: c,
                        neighbour: cuts[c].blocks[if cuts[c].blocks[0] == bid { 1 } else { 0 }],
                    },
                })
                .collect();
            let (corners, triangle) = match corner_points[bid] {
                Some(cp) => {
                    let mut c: Vec<usize> = cp
                        .iter()
                        .filter_map(|p| r.pts.iter().position(|x| x == p))
                        .collect();
                    c.sort_unstable();
                    if c.len() != 4 {
                        return Err(DecomposeError::BadCorners {
                            block: bid,
                            reason: "triangle-block corners were lost".into(),
                        });
                    }
                    ([c[0], c[1], c[2], c[3]], true)
                }
                None => match select_corners(&r.pts, &self.opts.corner_weights).or_else(|| {
                    // last resort (counted as "corners ≥ 170°" in docs/results.md): any four
                    // non-reflex vertices, however straight; only reached when neither the
                    // corner repair nor the triangle rule could serve the block
                    let w = CornerWeights {
                        max_corner_angle: PI,
                        corner_angle_limit: PI,
                        ..self.opts.corner_weights
                    };
                    select_corners(&r.pts, &w)
                }) {
                    Some((c, _)) => (c, false),
                    None => {
                        return Err(DecomposeError::BadCorners {
                            block: bid,
                            reason: "fewer than four non-reflex vertices".into(),
                        })
                    }
                },
            };
            blocks.push(Block {
                id: bid,
                ring: r.pts,
                corners,
                edges,
                triangle,
            });
        }
        let d = Decomposition {
            blocks,
            cuts,
            tree: self.nodes,
        };
        d.validate(self.region)?;
        Ok(d)
    }
}

/// `true` if a block gets the triangle-block rule: three vertices, or fewer than four
/// corner-like (interior angle below θ_max) vertices.
fn is_triangle_like(ring: &[DVec2], w: &CornerWeights) -> bool {
    let n = ring.len();
    n == 3
        || (0..n)
            .filter(|&i| ring_angle(ring, i) < w.corner_angle_limit)
            .count()
            < 4
}

/// The triangle-block rule for a block ring as [`Builder::finish`] applies it, and whether it
/// puts a point **inside a cut** (`true`: a cut joint, an interior mesh node of valence 3).
/// `None` when the block is not triangle-like or takes its corners among four non-reflex
/// vertices instead.
///
/// Points are inserted on original-boundary edges only if possible; a critical vertex is a
/// corner unless [`DecomposeOptions::blunt_critical_tips`] asks for the two inserted points
/// beside it; a three-corner block keeps its critical vertex as a corner and gets its fourth
/// corner on the boundary; only when neither works is a point put inside a cut (the repair
/// pass, module `repair`, removes every such block it can before this runs).
pub(crate) fn triangle_plan(
    ring: &Ring,
    theta: f64,
    opts: &DecomposeOptions,
) -> Option<(TriangleBlock, bool)> {
    let pts = &ring.pts;
    if !is_triangle_like(pts, &opts.corner_weights) {
        return None;
    }
    let tags = &ring.tags;
    let boundary_only = |e: usize| matches!(tags.get(e), Some(Tag::Boundary(_)));
    let frac = opts.triangle_insert_fraction;
    if let Some(t) = triangle_rule(pts, tip_angle(opts, theta), frac, &boundary_only) {
        return Some((t, false));
    }
    // with four non-reflex vertices, phase B picks corners among them instead
    let non_reflex = (0..pts.len()).filter(|&i| ring_angle(pts, i) < PI).count();
    if non_reflex >= 4 {
        return None;
    }
    // keep the critical vertex as a corner, fourth corner on boundary
    if let Some(t) = triangle_rule(pts, 0.0, frac, &boundary_only) {
        return Some((t, false));
    }
    let t = triangle_rule(pts, theta, frac, &|_| true)?;
    let in_cut =
        t.1.iter()
            .any(|o| o.is_some_and(|e| matches!(tags.get(e), Some(Tag::Cut(_)))));
    Some((t, in_cut))
}

/// `true` if the block ring would get a corner inside a cut (see [`triangle_plan`]).
pub(crate) fn needs_cut_point(ring: &Ring, theta: f64, opts: &DecomposeOptions) -> bool {
    triangle_plan(ring, theta, opts).is_some_and(|(_, in_cut)| in_cut)
}

/// The critical angle the triangle-block rule blunts below: θ₋ with
/// [`DecomposeOptions::blunt_critical_tips`], else 0 (no vertex is blunted: a sharp vertex
/// stays a corner).
fn tip_angle(opts: &DecomposeOptions, theta_minus: f64) -> f64 {
    if opts.blunt_critical_tips {
        theta_minus
    } else {
        0.0
    }
}

/// A block's (possibly extended) ring, its edge bookkeeping, corners and triangle flag.
pub(crate) type CornerChoice = (Vec<DVec2>, Vec<EdgeKind>, [usize; 4], bool);

/// Corner choice for one block: the quadrilateral selection, or the triangle rule when the
/// block has fewer than four corner-like vertices or is a triangle.
pub(crate) fn choose_corners(
    block: usize,
    ring: &[DVec2],
    edges: &[EdgeKind],
    theta_minus: f64,
    opts: &DecomposeOptions,
) -> Result<CornerChoice, DecomposeError> {
    let n = ring.len();
    let strong = (0..n)
        .filter(|&i| ring_angle(ring, i) < opts.corner_weights.corner_angle_limit)
        .count();
    if n == 3 || strong < 4 {
        let can = |e: usize| matches!(edges[e], EdgeKind::Boundary { .. });
        if let Some((pts, origin, corners)) = triangle_rule(
            ring,
            tip_angle(opts, theta_minus),
            opts.triangle_insert_fraction,
            &can,
        ) {
            // edge k describes pts[k] → pts[k+1]: an old vertex i starts a piece of old edge i,
            // an inserted point on edge e continues old edge e.
            let mut fixed = Vec::with_capacity(pts.len());
            let mut cur = 0usize;
            for o in &origin {
                match o {
                    None => {
                        fixed.push(edges[cur]);
                        cur += 1;
                    }
                    Some(e) => fixed.push(edges[*e]),
                }
            }
            return Ok((pts, fixed, corners, true));
        }
    }
    match select_corners(ring, &opts.corner_weights) {
        Some((c, _)) => Ok((ring.to_vec(), edges.to_vec(), c, false)),
        None => Err(DecomposeError::BadCorners {
            block,
            reason: "fewer than four non-reflex vertices and the triangle rule does not apply"
                .into(),
        }),
    }
}
