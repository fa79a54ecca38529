//! The checks behind [`Decomposition::validate`](super::Decomposition::validate) and the file loader: cuts inside the region
//! and disjoint, blocks tiling it, corners valid; and the edge bookkeeping they derive.

use std::collections::HashMap;
use std::f64::consts::PI;

use rayon::prelude::*;
use unamalla_mesh::geometry::{open_segment_hits, point_segment_distance};
use unamalla_mesh::{DVec2, Region, SegmentIndex};

use super::{Block, Cut, EdgeKind};
use crate::error::DecomposeError;
use crate::geom::{ring_angle, signed_area};

/// Absolute tolerance for "lies on the region boundary": 1e-9 of the bounding-box diagonal.
pub(crate) fn boundary_tol(region: &Region) -> f64 {
    let (lo, hi) = region.bounding_box();
    1e-9 * lo.distance(hi).max(f64::MIN_POSITIVE)
}

/// Edge bookkeeping per block and the two blocks of every cut.
pub(crate) type Classified = (Vec<Vec<EdgeKind>>, Vec<[usize; 2]>);
type PointKey = (u64, u64);
type CoverList = Vec<(f64, DVec2, DVec2)>;

/// Validates the geometry of blocks and cuts (everything but corners) and derives the edge
/// bookkeeping of every block and the two blocks of every cut.
pub(crate) fn classify(
    region: &Region,
    blocks: &[Block],
    cuts: &[Cut],
) -> Result<Classified, DecomposeError> {
    let tol = boundary_tol(region);
    for (k, b) in blocks.iter().enumerate() {
        if b.id != k {
            return Err(DecomposeError::BadId {
                what: "block",
                id: b.id,
                count: blocks.len(),
            });
        }
    }
    for (k, c) in cuts.iter().enumerate() {
        if c.id != k {
            return Err(DecomposeError::BadId {
                what: "cut",
                id: c.id,
                count: cuts.len(),
            });
        }
        for &b in &c.blocks {
            if b >= blocks.len() && c.blocks != [usize::MAX; 2] {
                return Err(DecomposeError::UnknownBlock { cut: k, block: b });
            }
        }
    }
    check_cuts(region, cuts)?;
    // blocks: simple, counter-clockwise (checked in parallel; the first failing block in
    // order gives the error, as a sequential loop would)
    let block_ok = |b: &Block| -> Result<(), DecomposeError> {
        if b.ring.len() < 3 {
            return Err(DecomposeError::BlockTooSmall {
                block: b.id,
                count: b.ring.len(),
            });
        }
        let a = signed_area(&b.ring);
        if a.is_nan() || a <= 0.0 {
            return Err(DecomposeError::BlockNotCounterClockwise {
                block: b.id,
                area: a,
            });
        }
        if let Some((x, y)) = SegmentIndex::new(vec![b.ring.clone()]).first_intersection() {
            return Err(DecomposeError::BlockNotSimple {
                block: b.id,
                edge_a: x.edge,
                edge_b: y.edge,
            });
        }
        Ok(())
    };
    first_error(blocks.par_iter().map(block_ok).collect())?;
    // edges: cut or boundary
    let key = |p: DVec2| (p.x.to_bits(), p.y.to_bits());
    let mut cut_map: HashMap<(PointKey, PointKey), usize> = HashMap::new();
    for c in cuts {
        cut_map.insert((key(c.a), key(c.b)), c.id);
        cut_map.insert((key(c.b), key(c.a)), c.id);
    }
    let rings: Vec<&[DVec2]> = region.rings().map(|p| p.points()).collect();
    let index = region.edge_index();
    // each block's edges, in parallel: the kinds, the cuts used (cut, start point) and the
    // region edges covered ((ring, edge), (t of start, start, end)); gathered in block
    // order below, as a sequential loop would record them
    type BlockEdges = (
        Vec<Option<(bool, usize)>>,
        Vec<(usize, DVec2)>,
        Vec<((usize, usize), (f64, DVec2, DVec2))>,
    );
    let block_edges = |b: &Block| -> Result<BlockEdges, DecomposeError> {
        let n = b.ring.len();
        let mut ks = Vec::with_capacity(n);
        let (mut used, mut covered) = (Vec::new(), Vec::new());
        for e in 0..n {
            let u = b.ring[e];
            let v = b.ring[(e + 1) % n];
            if let Some(&c) = cut_map.get(&(key(u), key(v))) {
                used.push((c, u));
                ks.push(Some((true, c)));
                continue;
            }
            let mid = 0.5 * (u + v);
            let lo = u.min(v) - DVec2::splat(tol);
            let hi = u.max(v) + DVec2::splat(tol);
            let mut found = None;
            for er in index.candidates(lo, hi) {
                let (a, bb) = index.edge(er);
                if point_segment_distance(u, a, bb) <= tol
                    && point_segment_distance(v, a, bb) <= tol
                    && point_segment_distance(mid, a, bb) <= tol
                    && (v - u).dot(bb - a) > 0.0
                {
                    found = Some(er);
                    break;
                }
            }
            let Some(er) = found else {
                return Err(DecomposeError::BlockEdgeUnexplained {
                    block: b.id,
                    edge: e,
                    ax: u.x,
                    ay: u.y,
                    bx: v.x,
                    by: v.y,
                });
            };
            let (a, bb) = index.edge(er);
            let t = crate::geom::project_t(u, a, bb);
            covered.push(((er.ring, er.edge), (t, u, v)));
            ks.push(Some((false, er.ring)));
        }
        Ok((ks, used, covered))
    };
    let per_block: Vec<Result<BlockEdges, DecomposeError>> =
        blocks.par_iter().map(block_edges).collect();
    let mut uses: Vec<Vec<(usize, DVec2)>> = vec![Vec::new(); cuts.len()];
    // per region edge: (t of start, start, end)
    let mut cover: HashMap<(usize, usize), CoverList> = HashMap::new();
    let mut kinds: Vec<Vec<Option<(bool, usize)>>> = Vec::with_capacity(blocks.len());
    for (b, r) in blocks.iter().zip(per_block) {
        let (ks, used, covered) = r?;
        for (c, u) in used {
            uses[c].push((b.id, u));
        }
        for (edge, entry) in covered {
            cover.entry(edge).or_default().push(entry);
        }
        kinds.push(ks);
    }
    // every cut used exactly twice, opposite directions, two different blocks
    let mut sides = Vec::with_capacity(cuts.len());
    for c in cuts {
        let u = &uses[c.id];
        if u.len() != 2 || u[0].1 == u[1].1 || u[0].0 == u[1].0 {
            return Err(DecomposeError::CutNotShared {
                cut: c.id,
                count: u.len(),
            });
        }
        let found = [u[0].0, u[1].0];
        let mut f = found;
        f.sort_unstable();
        let mut l = c.blocks;
        l.sort_unstable();
        // `[usize::MAX; 2]` = not given (files may omit the blocks of a cut)
        if c.blocks != [usize::MAX; 2] && f != l {
            return Err(DecomposeError::CutBlocksMismatch {
                cut: c.id,
                listed: c.blocks,
                found,
            });
        }
        sides.push(found);
    }
    // boundary covered exactly once
    for (r, ring) in rings.iter().enumerate() {
        let n = ring.len();
        for e in 0..n {
            let a = ring[e];
            let b = ring[(e + 1) % n];
            let Some(list) = cover.get_mut(&(r, e)) else {
                return Err(DecomposeError::BoundaryNotCovered { ring: r, edge: e });
            };
            list.sort_by(|x, y| x.0.total_cmp(&y.0));
            let ok = list[0].1.distance(a) <= tol
                && list.last().is_some_and(|l| l.2.distance(b) <= tol)
                && list.windows(2).all(|w| w[0].2 == w[1].1);
            if !ok {
                return Err(DecomposeError::BoundaryNotCovered { ring: r, edge: e });
            }
        }
    }
    // areas
    let total: f64 = blocks.iter().map(|b| signed_area(&b.ring)).sum();
    let area = region.area();
    if (total - area).abs() > 1e-7 * area.abs().max(f64::MIN_POSITIVE) {
        return Err(DecomposeError::AreaMismatch {
            blocks: total,
            region: area,
        });
    }
    Ok((
        kinds
            .into_iter()
            .enumerate()
            .map(|(bid, ks)| {
                ks.into_iter()
                    .map(|k| match k {
                        Some((true, c)) => {
                            let s = sides[c];
                            EdgeKind::Cut {
                                cut: c,
                                neighbour: if s[0] == bid { s[1] } else { s[0] },
                            }
                        }
                        Some((false, ring)) => EdgeKind::Boundary { ring },
                        None => EdgeKind::Boundary { ring: 0 },
                    })
                    .collect()
            })
            .collect(),
        sides,
    ))
}

/// The first error of `results` (in order), as a loop stopping there would return it.
fn first_error(results: Vec<Result<(), DecomposeError>>) -> Result<(), DecomposeError> {
    results.into_iter().collect()
}

/// Cuts: finite, endpoints on the boundary (or at a joint shared with another cut, where the
/// triangle-block rule split a cut), inside the region, pairwise disjoint.
pub(crate) fn check_cuts(region: &Region, cuts: &[Cut]) -> Result<(), DecomposeError> {
    let tol = boundary_tol(region);
    let index = region.edge_index();
    let max_x = region.bounding_box().1.x;
    // each cut on its own, in parallel; the first failing cut in order gives the error, as a
    // sequential loop would
    let cut_ok = |c: &Cut| -> Result<(), DecomposeError> {
        for (name, p) in [('a', c.a), ('b', c.b)] {
            if !p.is_finite() {
                return Err(DecomposeError::NonFinite {
                    what: format!("cut {} endpoint {name}", c.id),
                });
            }
            let lo = p - DVec2::splat(tol);
            let hi = p + DVec2::splat(tol);
            let on = index.candidates(lo, hi).any(|er| {
                let (a, b) = index.edge(er);
                point_segment_distance(p, a, b) <= tol
            });
            // a joint where a cut was split by the triangle-block rule: shared with another cut
            // (only looked for when the end is not on the boundary: the test is pure)
            let joint = || cuts.iter().any(|d| d.id != c.id && (d.a == p || d.b == p));
            if !on && !joint() {
                return Err(DecomposeError::CutEndNotOnBoundary {
                    cut: c.id,
                    endpoint: name,
                    x: p.x,
                    y: p.y,
                });
            }
        }
        let err = DecomposeError::CutCrossesBoundary {
            cut: c.id,
            ax: c.a.x,
            ay: c.a.y,
            bx: c.b.x,
            by: c.b.y,
        };
        if c.a == c.b {
            return Err(err);
        }
        // endpoints may sit a rounding error off the boundary: test the segment shrunk at both
        // ends by a relative 1e-9 or, far from the origin, by 64 units in the last place of
        // the coordinates (at 10⁹ an ulp is 1.2·10⁻⁷, so a 1e-9 shrink of a short cut does
        // not move its ends at all)
        let d = c.b - c.a;
        let scale = c.a.abs().max(c.b.abs()).max_element();
        let shrink = (1e-9f64)
            .max(64.0 * f64::EPSILON * scale / d.length())
            .min(0.25);
        let a2 = c.a + shrink * d;
        let b2 = c.b - shrink * d;
        if !(contains_point_with(region, &index, max_x, a2)
            && contains_point_with(region, &index, max_x, b2)
            && !index.open_segment_blocked(a2, b2))
        {
            return Err(err);
        }
        Ok(())
    };
    first_error(cuts.par_iter().map(cut_ok).collect())?;
    if cuts.len() > 1 {
        let cut_index = SegmentIndex::new(cuts.iter().map(|c| vec![c.a, c.b]).collect());
        let disjoint = |c: &Cut| -> Result<(), DecomposeError> {
            for er in cut_index.candidates(c.a, c.b) {
                if er.ring == c.id {
                    continue;
                }
                let (p, q) = cut_index.edge(er);
                if open_segment_hits(c.a, c.b, p, q) || open_segment_hits(p, q, c.a, c.b) {
                    return Err(DecomposeError::CutsIntersect {
                        cut_a: c.id.min(er.ring),
                        cut_b: c.id.max(er.ring),
                    });
                }
            }
            Ok(())
        };
        first_error(cuts.par_iter().map(disjoint).collect())?;
    }
    Ok(())
}

/// [`Region::contains_point`] (`p` in the open region) with `index` =
/// [`Region::edge_index`] of `region` and `max_x` the largest `x` of its bounding box,
/// looking only at the edges whose bounding box meets the horizontal ray from `p` to the
/// right (up to `max_x`).
///
/// The same answer: `contains_point` locates `p` in each ring by the winding number of
/// `locate_in_ring` (an edge counts +1 if it goes up across the height of `p` with `p`
/// strictly on its left, −1 if it goes down with `p` strictly on its right, both by the
/// exact `orient2d`), and `p` on any edge (exactly) is on the boundary. An edge that counts
/// crosses the height of `p` to its right, and an edge holding `p` holds it in its bounding
/// box: either way the box meets the ray, so the edges left out count 0 and do not hold `p`.
/// The rules are evaluated here on the same numbers with the same predicates. `p` is inside
/// exactly when it is on no edge, the outer ring's winding number is not 0 and every hole's
/// is (a point inside a hole or on any ring is not in the open region).
pub(crate) fn contains_point_with(
    region: &Region,
    index: &SegmentIndex,
    max_x: f64,
    p: DVec2,
) -> bool {
    let mut winding = vec![0i64; region.rings().count()];
    for er in index.candidates(p, DVec2::new(max_x, p.y)) {
        let (a, b) = index.edge(er);
        let o = unamalla_mesh::geometry::orient2d(a, b, p);
        if o == 0.0 && unamalla_mesh::geometry::point_on_segment(a, b, p) {
            return false;
        }
        if a.y <= p.y {
            if b.y > p.y && o > 0.0 {
                winding[er.ring] += 1;
            }
        } else if b.y <= p.y && o < 0.0 {
            winding[er.ring] -= 1;
        }
    }
    winding[0] != 0 && winding[1..].iter().all(|&w| w == 0)
}

/// Corners: four distinct indices in range, in counter-clockwise ring order, none reflex.
pub(crate) fn check_corners(
    block: usize,
    ring: &[DVec2],
    corners: &[usize; 4],
) -> Result<(), DecomposeError> {
    let n = ring.len();
    if let Some(&c) = corners.iter().find(|&&c| c >= n) {
        return Err(DecomposeError::BadCorners {
            block,
            reason: format!("corner index {c} is out of range (ring has {n} points)"),
        });
    }
    // cyclic order: the forward gaps must add up to exactly one turn
    let gaps: usize = (0..4)
        .map(|k| (corners[(k + 1) % 4] + n - corners[k]) % n)
        .sum();
    if gaps != n
        || corners
            .iter()
            .any(|c| corners.iter().filter(|d| *d == c).count() > 1)
    {
        return Err(DecomposeError::BadCorners {
            block,
            reason: format!(
                "corners {corners:?} must be four distinct indices in counter-clockwise ring order"
            ),
        });
    }
    for &c in corners {
        let a = ring_angle(ring, c);
        if a > PI + 1e-6 {
            return Err(DecomposeError::BadCorners {
                block,
                reason: format!(
                    "corner at ring index {c} is reflex ({:.1}°)",
                    a.to_degrees()
                ),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `contains_point_with` answers as `Region::contains_point` on a region with a hole and
    /// horizontal edges, at vertices, on edges, at the heights of vertices and elsewhere.
    #[test]
    fn indexed_point_location_matches_contains_point() {
        let v = DVec2::new;
        let region = Region::new(
            vec![
                v(0.0, 0.0),
                v(6.0, 0.0),
                v(6.0, 2.0),
                v(4.0, 2.0),
                v(5.0, 4.0),
                v(6.0, 6.0),
                v(0.0, 6.0),
                v(1.0, 3.0),
            ],
            vec![vec![v(2.0, 2.0), v(2.0, 4.0), v(3.0, 4.0), v(3.0, 2.0)]],
        )
        .expect("region");
        let index = region.edge_index();
        let mut points: Vec<DVec2> = region.rings().flat_map(|r| r.points().to_vec()).collect();
        for r in region.rings() {
            let p = r.points();
            for k in 0..p.len() {
                points.push(0.5 * (p[k] + p[(k + 1) % p.len()]));
            }
        }
        for i in 0..=28 {
            for j in 0..=28 {
                points.push(v(-0.5 + 0.25 * i as f64, -0.5 + 0.25 * j as f64));
            }
        }
        for p in points {
            assert_eq!(
                contains_point_with(&region, &index, region.bounding_box().1.x, p),
                region.contains_point(p),
                "{p:?}"
            );
        }
    }
}
