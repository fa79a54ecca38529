//! Flat block corners on the region boundary: the one defect a block-structured quad mesh without
//! interior singularities cannot always avoid, and how the pipeline removes it.
//!
//! **Why they exist.** In a quad mesh of a simply connected region without interior
//! singularities, the boundary nodes satisfy the index count
//! `#(nodes in one cell) − #(nodes in three cells) − 2·#(nodes in four cells) = 4`. A block
//! corner on the region boundary is a node in one cell, so its cell has the region's interior
//! angle there. A block that is a straight-sided triangle has only three corner-like vertices; the
//! triangle-block rule of seed 000 digest §4.2 (our `unamalla-decompose`) therefore puts the
//! fourth corner at a point inserted on a straight edge, and the cell there has an angle of
//! exactly 180° — three collinear, fixed nodes, a corner triangle with α = 0 that no smoothing
//! of the interior can change (the cell is counted non-convex; its Jacobian vanishes at that
//! node).
//!
//! **What we do (our addition, not in the sources).** After the merge, every boundary node
//! that belongs to exactly one cell and whose angle in that cell is at least
//! `180° − min_deficit` is moved **outward**, perpendicular to its two (nearly collinear)
//! boundary edges, by
//!
//! ```text
//! δ = tan(min_deficit) · min(|a − v|, |b − v|)
//! ```
//!
//! where `a`, `b` are its two boundary neighbours. The angle at `v` then drops by
//! `atan(δ/|a−v|) + atan(δ/|b−v|) ≥ min_deficit`, so the corner cell is strictly convex
//! (with the default 5°: an angle of at most 175°). The region gains a sliver of area
//! `½·δ·|b − a|` — a fraction of one cell, far below the contour simplification's own change —
//! and the node stays fixed. A move is skipped (and the corner left flat) when the two new
//! boundary edges would cross any other boundary edge of the mesh. The count of moved corners is
//! reported ([`crate::pipeline::MeshReport::bent_corners`]).

use unamalla_mesh::geometry::segments_intersect;
use unamalla_mesh::quality::quad_boundary_edges;
use unamalla_mesh::{BlockMesh2, DVec2, HasNodes, HasQuadCells};

/// Default angle deficit (degrees) given to a flat boundary corner: its cell's angle becomes at
/// most 180° − 5° = 175°.
pub const DEFAULT_MIN_DEFICIT_DEG: f64 = 5.0;

/// Corners up to this much above 180° (radians; 0.5°) still count as flat (rounding of the
/// inserted points); beyond it a one-cell corner is left alone.
const MAX_REFLEX: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// Moves every flat boundary corner of `mesh` outward as described in the
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
    let nodes = global.nodes().to_vec();
    let mut moves: Vec<(usize, DVec2)> = Vec::new();
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
        // outward unit normal: perpendicular to the chord a→b, away from the cell
        let chord = pb - pa;
        let mut nrm = DVec2::new(-chord.y, chord.x).normalize_or_zero();
        if nrm.dot(toward_cell) > 0.0 {
            nrm = -nrm;
        }
        if nrm == DVec2::ZERO {
            continue;
        }
        // the offset that gives the deficit from the chord, plus the current sag below it
        let sag = (p - pa).dot(nrm); // < 0 if v sits inside the chord (reflex side)
        let delta = deficit.tan() * la.min(lb) - sag.min(0.0);
        let target = p + delta * nrm;
        if crosses_boundary(&boundary, &nodes, (a, v, b), target) {
            continue;
        }
        moves.push((v, target));
    }
    let count = moves.len();
    if count > 0 {
        let nodes = mesh.global_mut().nodes_mut();
        for (v, t) in moves {
            nodes[v] = t;
        }
        mesh.sync_blocks();
    }
    count
}

/// Whether the segments a→t and t→b cross a boundary edge not incident to a, v or b (exact
/// orientation predicates).
fn crosses_boundary(
    edges: &[[usize; 2]],
    nodes: &[DVec2],
    (a, v, b): (usize, usize, usize),
    t: DVec2,
) -> bool {
    let segs = [(nodes[a], t), (nodes[b], t)];
    edges.iter().any(|&[p, q]| {
        if [a, v, b].contains(&p) || [a, v, b].contains(&q) {
            return false;
        }
        segs.iter()
            .any(|&(s0, s1)| segments_intersect(s0, s1, nodes[p], nodes[q]))
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

    #[test]
    fn the_flat_corner_is_bent_by_the_stated_offset_and_its_cell_becomes_convex() {
        let (m, n) = (5, 5);
        let g = triangle_block(m, n);
        // before: the corner cell at P = node (m−1, 0) is degenerate (A, P, B collinear)
        let corner_cell = m - 2; // cell (m−2, 0)
        assert!(non_convex_cells(&g).contains(&corner_cell));
        let mut mesh = BlockMesh2::merge(vec![g.clone()], 1e-9).unwrap();
        let before = mesh.global().nodes().to_vec();
        assert_eq!(bend_flat_corners(&mut mesh, 5.0), 1);
        let after = mesh.global().nodes();
        let moved: Vec<usize> = (0..before.len())
            .filter(|&i| before[i] != after[i])
            .collect();
        assert_eq!(moved.len(), 1);
        let pv = moved[0];
        assert_eq!(before[pv], DVec2::new(2.0, 0.0));
        // neighbours of P: (1.5, 0) on the bottom side (|PA| = 0.5) and (2.5, 0) on the right
        // side (|PB| = 0.5); chord along +x, the cell above, so P moves to −y by
        // δ = tan 5° · 0.5
        let delta = 5f64.to_radians().tan() * 0.5;
        assert!((after[pv] - DVec2::new(2.0, -delta)).length() < 1e-12);
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
    fn a_bend_that_would_cross_another_boundary_edge_is_skipped() {
        // two blocks: the triangle block and, just below the flat corner (closer than δ), the
        // top edge of a separate thin block — the bump would cross it
        let (m, n) = (5, 5);
        let g = triangle_block(m, n);
        let eps = 1e-4; // δ = tan 5° · 0.5 ≈ 0.0437 ≫ eps
        let below = StructuredGrid2::from_fn(3, 2, |i, j| {
            DVec2::new(1.0 + i as f64, -eps - (1 - j) as f64)
        })
        .unwrap();
        let mut mesh = BlockMesh2::merge(vec![g, below], 1e-9).unwrap();
        assert_eq!(bend_flat_corners(&mut mesh, 5.0), 0);
    }
}
