//! Flat block corners on the region boundary: the one defect a block-structured quad mesh without
//! interior singularities cannot always avoid, and how the pipeline removes it.
//!
//! **Why they exist.** In a quad mesh of a simply connected region without interior
//! singularities, the boundary nodes satisfy the index count
//! `#(nodes in one cell) − #(nodes in three cells) − 2·#(nodes in four cells) = 4`. A block
//! corner on the region boundary is a node in one cell, so its cell has the region's interior
//! angle there. A block that is a straight-sided triangle has only three corner-like vertices; the
//! triangle-block rule of [Méndez 2023, §5.1.1] (our `unamalla-decompose`) therefore puts the
//! fourth corner at a point inserted on a straight edge, and the cell there has an angle of
//! exactly 180° — three collinear, fixed nodes, a corner triangle with α = 0 that no smoothing
//! of the interior can change (the cell is counted non-convex; its Jacobian vanishes at that
//! node).
//!
//! **What we do (our addition, not in the sources).** After the merge, every boundary node `v`
//! that belongs to exactly one cell and whose angle in that cell is at least
//! `180° − min_deficit` keeps its place, and its two boundary neighbours `a`, `b` are moved
//! **inward** (toward the cell), perpendicular to the chord `a → b`, by
//!
//! ```text
//! δ = tan(min_deficit) · min(|a − v|, |b − v|)
//! ```
//!
//! (plus the height of `v` above the chord when `v` sits slightly on the reflex side). The
//! angle at `v` then drops by `atan(δ/|a−v|) + atan(δ/|b−v|) ≥ min_deficit`, so the corner cell
//! is strictly convex (with the default 5°: an angle of at most 175°). The mesh stays **inside
//! the region**: it loses a sliver of area `½·δ·|b − a|`, a fraction of one cell, and its
//! boundary has two shallow dents at `a` and `b` (the region's boundary nodes otherwise stay
//! on it). An earlier version moved `v` outward instead, which put a node up to `δ` outside
//! the region — outside a clipping box that a named boundary patch follows (`open-sea` along
//! the box of the Puget Sound fixture) and, at some sizes, a cell centroid outside the
//! simplified ring. When `a` or `b` is not a plain boundary node (two cells, two boundary
//! neighbours) or already moved for another corner, when a moved boundary edge would cross
//! another boundary edge of the mesh, or when a cell at `a` or `b` would not be strictly convex
//! (exact `orient2d` of every corner triangle), `v` is moved **outward** by `δ` instead (the
//! earlier rule, leaving the region by `δ` at that one node); if that would cross another
//! boundary edge too, the corner is left flat. The count of bent corners (either way) is
//! reported ([`crate::pipeline::MeshReport::bent_corners`]).

use unamalla_mesh::geometry::{orient2d, segments_intersect};
use unamalla_mesh::quality::quad_boundary_edges;
use unamalla_mesh::{BlockMesh2, DVec2, HasNodes, HasQuadCells};

/// Default angle deficit (degrees) given to a flat boundary corner: its cell's angle becomes at
/// most 180° − 5° = 175°.
pub const DEFAULT_MIN_DEFICIT_DEG: f64 = 5.0;

/// Corners up to this much above 180° (radians; 0.5°) still count as flat (rounding of the
/// inserted points); beyond it a one-cell corner is left alone.
const MAX_REFLEX: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// Bends every flat boundary corner of `mesh` (its two boundary neighbours moved inward) as described in the
/// [module documentation](self) and returns how many were moved. `min_deficit_deg` must be in
/// (0°, 45°); other values leave the mesh unchanged and return 0.
pub fn bend_flat_corners(mesh: &mut BlockMesh2, min_deficit_deg: f64) -> usize {
    if !(min_deficit_deg > 0.0 && min_deficit_deg < 45.0) {
        return 0;
    }
    let deficit = min_deficit_deg.to_radians();
    let global = mesh.global();
    let nn = global.num_nodes();
    let mut cells_at = vec![0u32; nn];
    let mut owner = vec![usize::MAX; nn];
    for c in 0..global.num_quads() {
        for v in global.quad(c) {
            cells_at[v] += 1;
            owner[v] = c;
        }
    }
    let boundary = quad_boundary_edges(global);
    let mut cells_of: Vec<Vec<usize>> = vec![Vec::new(); nn];
    for c in 0..global.num_quads() {
        for v in global.quad(c) {
            cells_of[v].push(c);
        }
    }
    let mut nbrs: Vec<Vec<usize>> = vec![Vec::new(); nn];
    for &[p, q] in &boundary {
        nbrs[p].push(q);
        nbrs[q].push(p);
    }
    let mut nodes = global.nodes().to_vec();
    let mut moved = vec![false; nn];
    let mut count = 0;
    for v in 0..nn {
        if cells_at[v] != 1 {
            continue;
        }
        let q = global.quad(owner[v]);
        let Some(k) = q.iter().position(|&x| x == v) else {
            continue;
        };
        let (a, b, opp) = (q[(k + 3) % 4], q[(k + 1) % 4], q[(k + 2) % 4]);
        let (p, pa, pb) = (nodes[v], nodes[a], nodes[b]);
        let (ua, ub) = (pa - p, pb - p);
        let (la, lb) = (ua.length(), ub.length());
        if !(la > 0.0 && lb > 0.0) {
            continue;
        }
        // interior angle of the cell at v: the angle between the legs, measured on the side
        // of the opposite node
        let ang = ua.angle_to(ub).abs();
        let toward_cell = nodes[opp] - p;
        let ang = if ua.perp_dot(ub).signum() == ua.perp_dot(toward_cell).signum()
            || ua.perp_dot(ub) == 0.0
        {
            ang
        } else {
            std::f64::consts::TAU - ang
        };
        // flat corners only: a reflex corner (angle clearly above 180°) is a genuine
        // corner-choice error, not this defect, and moving it would change the region visibly
        if ang < std::f64::consts::PI - deficit || ang > std::f64::consts::PI + MAX_REFLEX {
            continue;
        }
        // inward unit normal: perpendicular to the chord a→b, toward the cell
        let chord = pb - pa;
        let mut nrm = DVec2::new(-chord.y, chord.x).normalize_or_zero();
        if nrm.dot(toward_cell) < 0.0 {
            nrm = -nrm;
        }
        if nrm == DVec2::ZERO || moved[v] {
            continue;
        }
        // the offset that gives the deficit from v, plus the height of v above the chord
        // (> 0 if v sits inside the chord, on the reflex side)
        let height = (p - pa).dot(nrm);
        let delta = deficit.tan() * la.min(lb) + height.max(0.0);
        // the fallback when the neighbours cannot move: v outward by the same offset
        let outward = |nodes: &[DVec2]| {
            let t = p - delta * nrm;
            let hit = [a, b]
                .iter()
                .any(|&x| crosses_boundary(&boundary, nodes, &[a, v, b], nodes[x], t));
            (!hit).then_some(t)
        };
        // the neighbours move: each must be a plain boundary node (two cells, two boundary
        // neighbours), not moved by another corner
        if [a, b]
            .iter()
            .any(|&x| moved[x] || cells_at[x] != 2 || nbrs[x].len() != 2)
        {
            if let Some(t) = outward(&nodes) {
                nodes[v] = t;
                moved[v] = true;
                count += 1;
            }
            continue;
        }
        let (ta, tb) = (pa + delta * nrm, pb + delta * nrm);
        // the new boundary edges must not cross another boundary edge, and every cell at a or
        // b must stay strictly convex (exact orientation of each corner triangle)
        let mut trial = Vec::with_capacity(8);
        for (x, t) in [(a, ta), (b, tb)] {
            for &y in &nbrs[x] {
                trial.push((x, y, t));
            }
        }
        if trial.iter().any(|&(x, y, t)| {
            let ty = if y == a {
                ta
            } else if y == b {
                tb
            } else {
                nodes[y]
            };
            crosses_boundary(&boundary, &nodes, &[x, y, a, b, v], t, ty)
        }) {
            if let Some(t) = outward(&nodes) {
                nodes[v] = t;
                moved[v] = true;
                count += 1;
            }
            continue;
        }
        let (old_a, old_b) = (nodes[a], nodes[b]);
        nodes[a] = ta;
        nodes[b] = tb;
        let convex = cells_of[a].iter().chain(&cells_of[b]).all(|&c| {
            let q = global.quad(c);
            (0..4)
                .all(|i| orient2d(nodes[q[(i + 3) % 4]], nodes[q[i]], nodes[q[(i + 1) % 4]]) > 0.0)
        });
        if !convex {
            nodes[a] = old_a;
            nodes[b] = old_b;
            if let Some(t) = outward(&nodes) {
                nodes[v] = t;
                moved[v] = true;
                count += 1;
            }
            continue;
        }
        moved[a] = true;
        moved[b] = true;
        moved[v] = true;
        count += 1;
    }
    if count > 0 {
        mesh.global_mut().nodes_mut().copy_from_slice(&nodes);
        mesh.sync_blocks();
    }
    count
}

/// Whether the segment s→t crosses a boundary edge not incident to any node of `skip` (exact
/// orientation predicates).
fn crosses_boundary(
    edges: &[[usize; 2]],
    nodes: &[DVec2],
    skip: &[usize],
    s: DVec2,
    t: DVec2,
) -> bool {
    edges.iter().any(|&[p, q]| {
        !skip.contains(&p) && !skip.contains(&q) && segments_intersect(s, t, nodes[p], nodes[q])
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use unamalla_mesh::quality::non_convex_cells;
    use unamalla_mesh::StructuredGrid2;

    /// The triangle-rule block: corners V = (0,0), P = (2,0) (inserted on the straight edge
    /// V→W, 180°), W = (4,0), U = (0,4); bilinear map of an `m × n` grid.
    fn triangle_block(m: usize, n: usize) -> StructuredGrid2 {
        let (v, p, w, u) = (
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(4.0, 0.0),
            DVec2::new(0.0, 4.0),
        );
        StructuredGrid2::from_fn(m, n, |i, j| {
            let (s, t) = (i as f64 / (m - 1) as f64, j as f64 / (n - 1) as f64);
            (1.0 - s) * (1.0 - t) * v + s * (1.0 - t) * p + s * t * w + (1.0 - s) * t * u
        })
        .unwrap()
    }

    /// Bends the flat corners of the one-block mesh of `g`: the mesh, the count returned, the
    /// nodes before and the indices of the nodes that moved.
    fn bend(g: StructuredGrid2) -> (BlockMesh2, usize, Vec<DVec2>, Vec<usize>) {
        let mut mesh = BlockMesh2::merge(vec![g], 1e-9).unwrap();
        let before = mesh.global().nodes().to_vec();
        let count = bend_flat_corners(&mut mesh, 5.0);
        let after = mesh.global().nodes();
        let moved = (0..before.len())
            .filter(|&i| before[i] != after[i])
            .collect();
        (mesh, count, before, moved)
    }

    #[test]
    fn the_flat_corner_is_bent_by_the_stated_offset_and_its_cell_becomes_convex() {
        let (m, n) = (5, 5);
        let g = triangle_block(m, n);
        // before: the corner cell at P = node (m−1, 0) is degenerate (A, P, B collinear)
        let corner_cell = m - 2; // cell (m−2, 0)
        assert!(non_convex_cells(&g).contains(&corner_cell));
        let (mesh, count, _, moved) = bend(g);
        assert_eq!(count, 1);
        let after = mesh.global().nodes();
        // neighbours of P = (2, 0): A = (1.5, 0) on the bottom side (|PA| = 0.5) and
        // B = (2.5, 0) on the right side (|PB| = 0.5); chord along +x, the cell above, so A and
        // B move to +y by δ = tan 5° · 0.5 and P stays
        assert_eq!(moved.len(), 2);
        let delta = 5f64.to_radians().tan() * 0.5;
        let mut got: Vec<DVec2> = moved.iter().map(|&i| after[i]).collect();
        got.sort_by(|p, q| p.x.total_cmp(&q.x));
        assert!(
            (got[0] - DVec2::new(1.5, delta)).length() < 1e-12,
            "{got:?}"
        );
        assert!(
            (got[1] - DVec2::new(2.5, delta)).length() < 1e-12,
            "{got:?}"
        );
        assert!(after.contains(&DVec2::new(2.0, 0.0)));
        // the mesh stays inside the triangle: no node below y = 0 or left of x = 0
        assert!(after.iter().all(|p| p.x >= 0.0 && p.y >= 0.0));
        // the angle at P is now 180° − 2·atan(δ/0.5) = 170°, and no cell is non-convex
        let b = &mesh.blocks()[0];
        assert!(non_convex_cells(b).is_empty(), "{:?}", non_convex_cells(b));
        let q = b.quad_points(corner_cell);
        let ang = (q[0] - q[1]).angle_to(q[2] - q[1]).abs().to_degrees();
        assert!((ang - 170.0).abs() < 1e-9, "{ang}");
    }

    #[test]
    fn a_convex_block_is_left_alone() {
        let g = StructuredGrid2::from_fn(4, 3, |i, j| DVec2::new(i as f64, j as f64)).unwrap();
        let mut mesh = BlockMesh2::merge(vec![g], 1e-9).unwrap();
        let before = mesh.global().nodes().to_vec();
        assert_eq!(bend_flat_corners(&mut mesh, 5.0), 0);
        assert_eq!(mesh.global().nodes(), &before[..]);
        assert_eq!(bend_flat_corners(&mut mesh, 0.0), 0);
        assert_eq!(bend_flat_corners(&mut mesh, f64::NAN), 0);
    }

    #[test]
    fn a_bend_that_would_fold_a_neighbouring_cell_moves_the_corner_outward() {
        // 5 × 200 nodes: the cells along the bottom side are 4·(1 − s)/199 ≤ 0.0151 high at A
        // and B; P's neighbours are A = (1.5, 0) and B = P + (W − P)/199 = (2 + 2/199, 0), so
        // δ = tan 5° · 2/199 ≈ 8.8e-4 — lifting A and B by δ would fold the cells on their
        // other sides (0.5 × 4/199 ≈ 0.01 wide at B … ); the fallback moves P = (2, 0) outward
        // to (2, −δ) and nothing else
        let (mesh, count, before, moved) = bend(triangle_block(5, 200));
        assert_eq!(count, 1);
        let after = mesh.global().nodes();
        assert_eq!(moved.len(), 1);
        assert_eq!(before[moved[0]], DVec2::new(2.0, 0.0));
        let delta = 5f64.to_radians().tan() * 2.0 / 199.0;
        assert!(
            (after[moved[0]] - DVec2::new(2.0, -delta)).length() < 1e-12,
            "{}",
            after[moved[0]]
        );
        assert!(non_convex_cells(&mesh.blocks()[0]).is_empty());
    }

    #[test]
    fn a_corner_whose_neighbours_are_corners_moves_outward() {
        // one degenerate cell (0,0), (1,0), (2,0), (1,1): the flat node (1,0) has the one-cell
        // corners (0,0) and (2,0) as neighbours, which are not moved; the flat node goes
        // outward instead, to (1, −tan 5°) (both legs 1 long)
        let nodes = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(1.0, 1.0),
        ];
        let g = StructuredGrid2::from_fn(2, 2, |i, j| match (i, j) {
            (0, 0) => nodes[1],
            (1, 0) => nodes[2],
            (1, 1) => nodes[3],
            _ => nodes[0],
        })
        .unwrap();
        let mut mesh = BlockMesh2::merge(vec![g], 1e-9).unwrap();
        assert_eq!(bend_flat_corners(&mut mesh, 5.0), 1);
        let t = DVec2::new(1.0, -5f64.to_radians().tan());
        assert!(mesh
            .global()
            .nodes()
            .iter()
            .any(|p| (*p - t).length() < 1e-12));
        assert!(mesh.global().nodes().contains(&DVec2::new(0.0, 0.0)));
        assert!(mesh.global().nodes().contains(&DVec2::new(2.0, 0.0)));
    }
}
