//! White's method for multiply connected surfaces, the baseline the submapping paper compares
//! against (E. Ruiz-Gironés & J. Sarrate, "Discretización de superficies múltiplemente conexas
//! mediante submapping", LaCàN, Universitat Politècnica de Catalunya — the section on multiply
//! connected surfaces and its Fig. 9; the method is its reference 1: D. White, "Automatic
//! quadrilateral and hexahedral meshing of pseudo-cartesian geometries using virtual
//! subdivision", Dept. of Civil and Environmental Engineering, Brigham Young University, 1996).
//!
//! The paper lists five phases (I)–(V) (it announces four):
//!
//! 1. submap the region **ignoring the holes** (the outer contour alone);
//! 2. sort the holes from nearest to farthest from the outer contour (physical distance);
//! 3. for each hole, the **initial vertex** is its vertex nearest the outer contour, and the
//!    **initial node** the node of the step-1 mesh nearest that vertex;
//! 4. from the initial node, the **shortest cut line in computational space** (the axis rays of
//!    the paper's cut search) ends at the **final node** on the outer contour; the
//!    virtual edge joins the initial vertex to the final node;
//! 5. with every hole connected, submap the merged loop as usual.
//!
//! Its drawback, which the paper's own method (virtual edges from a constrained Delaunay
//! triangulation, [`super::submap`]) removes: step 1 needs the outer contour **alone** to be
//! submappable, and the virtual edge's direction follows the step-1 grid, not the angles at the
//! hole (a return segment of White's method can leave the region or meet the hole at an angle far
//! from a multiple of 90°). [`white_submap`] reports such failures as errors naming the hole.
//!
//! Choices the paper leaves open, made here: distances are Euclidean to the outer ring's edges;
//! ties between equally near hole vertices or mesh nodes go to the lower index; the ray search
//! walks the node lattice of the step-1 mesh (every piece's TFI grid placed at its computational
//! origin) from the initial node along ±i, ±j and stops at the first position on the outer loop;
//! the shortest ray wins, ties by the order +i, +j, −i, −j.

use std::collections::{BTreeMap, BTreeSet};

use unamalla_mesh::geometry::point_segment_distance;
use unamalla_mesh::{DVec2, Region};

use super::{classify, classify_region, dir_step, finish, virtual_edges, SubmapError};
use super::{SubmapOptions, Submapping};

/// What White's method did besides the final submapping.
#[derive(Debug, Clone, PartialEq)]
pub struct WhiteSubmapping {
    /// The submapping of the merged loop (step 5).
    pub submapping: Submapping,
    /// Cells of the step-1 mesh of the outer contour alone.
    pub outer_cells: usize,
    /// Per connected hole, in the order processed (nearest first): the hole (0-based), its
    /// initial vertex, the initial node's position and the computational length of the cut from
    /// it to the final node.
    pub steps: Vec<WhiteStep>,
}

/// One hole connected by White's method.
#[derive(Debug, Clone, PartialEq)]
pub struct WhiteStep {
    /// The hole (0-based).
    pub hole: usize,
    /// Its vertex nearest the outer contour.
    pub initial_vertex: DVec2,
    /// The step-1 mesh node nearest that vertex.
    pub initial_node: DVec2,
    /// The final node on the outer contour (the virtual edge is initial vertex → final node).
    pub final_node: DVec2,
    /// Computational length of the cut from the initial node to the final node.
    pub cut_length: usize,
}

/// Runs White's method (module docs). Errors: [`SubmapError::WhiteOuterNotSubmappable`] when
/// step 1 fails (the method does not apply), [`SubmapError::WhiteReturnSegment`] when a hole's
/// return segment leaves the region, and the errors of the submapping steps.
pub fn white_submap(
    region: &Region,
    options: &SubmapOptions,
) -> Result<WhiteSubmapping, SubmapError> {
    let outer_pts = region.outer().points().to_vec();
    let outer_only = Region::new(outer_pts.clone(), vec![])?;
    // step 1
    let s1 = super::submap(&outer_only, options)
        .map_err(|e| SubmapError::WhiteOuterNotSubmappable(Box::new(e)))?;
    let grids = s1.grids()?;
    // the node lattice of the step-1 mesh: computational position → physical position (the
    // first piece listing a shared position wins; shared positions are the same node)
    let mut lattice: BTreeMap<[i64; 2], DVec2> = BTreeMap::new();
    for (piece, g) in s1.pieces.iter().zip(&grids) {
        for j in 0..g.n() {
            for i in 0..g.m() {
                lattice
                    .entry([piece.origin[0] + i as i64, piece.origin[1] + j as i64])
                    .or_insert(g.node(i, j));
            }
        }
    }
    let on_outer: BTreeSet<[i64; 2]> = s1.comp_loop.iter().map(|&(_, c)| c).collect();
    let n_out = outer_pts.len();
    let dist_to_outer = |p: DVec2| {
        (0..n_out)
            .map(|k| point_segment_distance(p, outer_pts[k], outer_pts[(k + 1) % n_out]))
            .fold(f64::INFINITY, f64::min)
    };
    // step 2: holes by distance (ties by number)
    let mut order: Vec<(f64, usize, DVec2)> = region
        .holes()
        .iter()
        .enumerate()
        .map(|(h, ring)| {
            // step 3a: the initial vertex (first of equally near ones)
            let mut best = (f64::INFINITY, DVec2::ZERO);
            for &v in ring.points() {
                let d = dist_to_outer(v);
                if d < best.0 {
                    best = (d, v);
                }
            }
            (best.0, h, best.1)
        })
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut steps = Vec::with_capacity(order.len());
    let mut chosen = Vec::with_capacity(order.len());
    for &(_, hole, v) in &order {
        // step 3b: the initial node (lowest computational position among equally near ones)
        let mut start: Option<([i64; 2], DVec2, f64)> = None;
        for (&c, &p) in &lattice {
            let d = p.distance(v);
            if start.is_none_or(|s| d < s.2) {
                start = Some((c, p, d));
            }
        }
        let Some((c0, p0, _)) = start else {
            return Err(SubmapError::WhiteReturnSegment { hole });
        };
        // step 4: the shortest axis ray to the outer loop
        let mut best: Option<(usize, [i64; 2])> = None;
        for code in 0..4 {
            let step = dir_step(code);
            let mut c = c0;
            let mut len = 0usize;
            while lattice.contains_key(&c) {
                if on_outer.contains(&c) {
                    if best.is_none_or(|b| len < b.0) {
                        best = Some((len, c));
                    }
                    break;
                }
                c = [c[0] + step[0], c[1] + step[1]];
                len += 1;
            }
        }
        let Some((cut_length, cf)) = best else {
            return Err(SubmapError::WhiteReturnSegment { hole });
        };
        let pf = lattice[&cf];
        steps.push(WhiteStep {
            hole,
            initial_vertex: v,
            initial_node: p0,
            final_node: pf,
            cut_length,
        });
        chosen.push((hole + 1, pf, v));
    }
    // step 5: submap the merged loop
    let classification = classify_region(region, options.sum_mode)?;
    let rings = classify::labelled_rings(region, &classification);
    let merged = match virtual_edges::connect_prescribed(region, rings, &chosen) {
        Err(SubmapError::NoVirtualEdge { hole }) => {
            return Err(SubmapError::WhiteReturnSegment { hole })
        }
        r => r?,
    };
    let done = finish(merged, options)?;
    Ok(WhiteSubmapping {
        submapping: super::assemble(classification, 1, done),
        outer_cells: s1.num_cells(),
        steps,
    })
}
