//! Step 7b′ of the pipeline: the islands the narrow-hole retry left out of the layout, carved
//! back into the smoothed mesh ([`crate::carve`]) and the carved mesh smoothed again.

use super::*;
use crate::carve::{carve_islands, CarveOutcome, CarveSkip};
use unamalla_mesh::Polygon;

/// The carved and re-smoothed mesh of [`Mesher::carve_dropped`].
pub(super) struct CarveStep {
    /// The carved, untangled and smoothed mesh.
    pub mesh: BlockMesh2,
    /// The meshed region with the carved holes' rings as holes.
    pub region: Region,
    /// The input holes carved, sorted.
    pub carved: Vec<usize>,
    /// For each block of `mesh`, the block of the uncarved mesh it is part of.
    pub origin: Vec<usize>,
}

/// What [`Mesher::carve_dropped`] carves: the input region, the region the mesh was made of
/// (without the islands) and the input holes left out (indices into `input`'s holes).
pub(super) struct Islands<'a> {
    pub input: &'a Region,
    pub simplified: &'a Region,
    pub dropped: &'a [usize],
}

/// Carving attempts of [`Mesher::carve_dropped`]: after the first, the islands next to the
/// cells the re-smoothing left non-convex are left out and the rest carved again once (one
/// more attempt is allowed after leaving out the islands whose ring crossed the boundary).
const CARVE_ATTEMPTS: usize = 2;

impl Mesher {
    /// Carves the input holes `islands.dropped` out of the smoothed `mesh` of
    /// `islands.simplified` and untangles and smooths the carved mesh with the polish options
    /// of `sopts` (only the cells around the islands moved). If cells stay non-convex, the
    /// islands within a cell of them are left out and the rest carved again from `mesh`; if
    /// they still do, or nothing could be carved, `None` (the mesh without the islands stands).
    /// The note says what was carved and why the others were not.
    pub(super) fn carve_dropped(
        &mut self,
        mesh: &BlockMesh2,
        islands: Islands<'_>,
        sopts: &SmoothOptions,
        t_stage: Instant,
        observer: &mut dyn Observer,
    ) -> Result<(Option<CarveStep>, String), CoreError> {
        let Islands {
            input,
            simplified,
            dropped,
        } = islands;
        let mut left_out: Vec<usize> = Vec::new();
        // islands left out because their ring crossed the meshed region's boundary
        let mut invalid = 0;
        for attempt in 0..CARVE_ATTEMPTS + 1 {
            let islands: Vec<(usize, &Polygon)> = dropped
                .iter()
                .filter(|k| !left_out.contains(k))
                .map(|&k| (k, &input.holes()[k]))
                .collect();
            let c = carve_islands(mesh, &islands)?;
            let carved = c.carved_ids();
            let skipped = skip_summary(&c.outcomes, left_out.len() - invalid, invalid);
            if carved.is_empty() {
                let note = format!(
                    "none of the {} island(s) left out of the layout carved back into the mesh{skipped}",
                    dropped.len()
                );
                return Ok((None, note));
            }
            // the meshed region with the carved rings as holes; a ring that does not make a valid
            // region with it (an islet the simplified coast passes through) is left out and the
            // rest carved again
            let region = match with_rings(simplified, &c) {
                Ok(region) => region,
                Err(bad) => {
                    invalid += bad.len();
                    left_out.extend(bad);
                    continue;
                }
            };
            let removed: usize = c
                .outcomes
                .iter()
                .map(|(_, o)| match o {
                    CarveOutcome::Carved { cells, .. } => *cells,
                    _ => 0,
                })
                .sum();
            let origin = c.origin;
            let mut carved_mesh = c.mesh;
            let polish = crate::multilevel::polish_options(sopts);
            self.untangle_and_smooth(&mut carved_mesh, &polish, t_stage, observer)?;
            let bad = unamalla_mesh::quality::mesh::non_convex_cells(carved_mesh.global());
            if bad.is_empty() {
                let mut carved = carved;
                carved.sort_unstable();
                let note = format!(
                    "carved {} of the {} island(s) left out of the layout back into the mesh ({removed} cells removed, the nodes around each moved onto its contour){skipped}",
                    carved.len(),
                    dropped.len(),
                );
                let step = CarveStep {
                    mesh: carved_mesh,
                    region,
                    carved,
                    origin,
                };
                return Ok((Some(step), note));
            }
            if attempt >= CARVE_ATTEMPTS {
                break;
            }
            // the islands within a cell of the cells left non-convex
            let g = carved_mesh.global();
            let centres: Vec<(DVec2, f64)> = bad
                .iter()
                .map(|&q| {
                    let p = g.quad_points(q);
                    let c = (p[0] + p[1] + p[2] + p[3]) / 4.0;
                    let size = p[0].distance(p[2]).max(p[1].distance(p[3]));
                    (c, size)
                })
                .collect();
            for &k in &carved {
                let (lo, hi) = input.holes()[k].bounding_box();
                if centres.iter().any(|&(c, size)| {
                    c.x >= lo.x - size
                        && c.x <= hi.x + size
                        && c.y >= lo.y - size
                        && c.y <= hi.y + size
                }) {
                    left_out.push(k);
                }
            }
            let msg = format!(
                "carving left {} cell(s) non-convex; carving again without the {} island(s) next to them",
                bad.len(),
                left_out.len()
            );
            self.stage(Stage::Smooth, &msg);
        }
        let note = format!(
            "the {} island(s) left out of the layout not carved back: after {} attempts the smoothing still left cells next to carved islands non-convex, or their rings crossed the meshed region's boundary",
            dropped.len(),
            CARVE_ATTEMPTS + 1
        );
        Ok((None, note))
    }
}

/// The meshed region `simplified` with the rings carved in `c` as holes, or the ids of the
/// islands whose ring does not make a valid region with it (each ring added alone to the rings
/// that did).
fn with_rings(simplified: &Region, c: &crate::carve::Carved) -> Result<Region, Vec<usize>> {
    let outer = simplified.outer().points().to_vec();
    let mut holes: Vec<Vec<DVec2>> = simplified
        .holes()
        .iter()
        .map(|h| h.points().to_vec())
        .collect();
    let rings = c.rings();
    let all: Vec<Vec<DVec2>> = holes.iter().cloned().chain(rings.iter().cloned()).collect();
    if let Ok(region) = Region::new(outer.clone(), all) {
        return Ok(region);
    }
    let mut bad = Vec::new();
    for (id, ring) in c.carved_ids().into_iter().zip(rings) {
        holes.push(ring);
        if Region::new(outer.clone(), holes.clone()).is_err() {
            holes.pop();
            bad.push(id);
        }
    }
    if bad.is_empty() {
        // the rings are valid one by one but not all together: leave them all out
        bad = c.carved_ids();
    }
    Err(bad)
}

/// `; N not carved (a: reason, …)` for the islands skipped, or empty.
fn skip_summary(outcomes: &[(usize, CarveOutcome)], left_out: usize, invalid: usize) -> String {
    let reasons = [
        CarveSkip::BelowMinArea,
        CarveSkip::OutsideMesh,
        CarveSkip::NotCompact,
        CarveSkip::TouchesBoundary,
        CarveSkip::TouchesCarved,
    ];
    let mut parts: Vec<String> = reasons
        .iter()
        .filter_map(|r| {
            let n = outcomes
                .iter()
                .filter(|(_, o)| *o == CarveOutcome::Skipped(*r))
                .count();
            (n > 0).then(|| format!("{n}: {r}"))
        })
        .collect();
    if left_out > 0 {
        parts.push(format!(
            "{left_out}: the smoothing left a cell next to it non-convex"
        ));
    }
    if invalid > 0 {
        parts.push(format!(
            "{invalid}: its ring crosses the meshed region's boundary"
        ));
    }
    if parts.is_empty() {
        String::new()
    } else {
        format!("; not carved ({})", parts.join("; "))
    }
}
