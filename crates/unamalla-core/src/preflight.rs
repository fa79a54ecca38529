//! Checks before the work starts (see `docs/reliability.md`): sizes against a memory limit, and the
//! region features that make a stage fail with an internal message.
//!
//! **Memory.** Every size option and every count derived from one is turned into an estimate
//! of the bytes it implies, `bytes = count × cost`, and compared with a limit *before* anything
//! is allocated, so `--cells 1000000000` is an error naming the option, not an allocation abort
//! after minutes. The per-unit costs ([`COST_PER_MESH_CELL`], …) are measured peak resident
//! sizes divided by the count (docs/reliability.md, "Memory costs"), rounded up. The limit is
//! [`DEFAULT_MEMORY_LIMIT`] (4 GiB), or the environment variable [`MEMORY_LIMIT_ENV`]
//! (`UNAMALLA_MAX_MEMORY`, bytes with an optional `K`/`M`/`G`/`T` suffix, powers of 1024). A
//! fixed documented limit rather than the machine's free memory keeps the answer for the same
//! input and options the same on every machine and under any load.
//!
//! **Unsimplified huge rings.** Decomposition of a region with more than
//! [`MAX_UNSIMPLIFIED_VERTICES`] vertices without simplification is refused with the vertex
//! count: the decomposition's candidate scans are quadratic in the vertex count (measured:
//! docs/reliability.md), so such a run would not end in reasonable time.
//!
//! **Narrow features without simplification.** A region meshed as given (`--no-simplify`)
//! whose boundary folds back onto itself closer than [`MIN_GAP_FRACTION`] × the cell size over
//! more than a cell (a 10⁻⁷-wide spike, a slit) cannot be meshed with cells of that size: the
//! run would end in the guarantee error after the whole pipeline, at fine sizes after minutes
//! in the smoother. [`check_narrow_features`] refuses it before the work, naming the vertex
//! and the width ([`narrow_feature`]); the default simplification removes such features.
//!
//! **Gaps between rings.** A hole closer to the outer ring (or to another hole) than the
//! merge tolerance of block nodes cannot be meshed at all, and one much closer than a cell
//! cannot be meshed with cells of that size: the stages then fail with internal messages
//! ("edge between global nodes 0 and 0 is shared by more than two cells"). [`ring_gaps`]
//! finds the closest pair of distinct rings; [`explain_failure`] turns a stage failure into a
//! message naming the hole, the gap and what to do when such a gap exists.

use std::fmt;

use unamalla_mesh::geometry::point_segment_distance;
use unamalla_mesh::{DVec2, Region, SegmentIndex};

use crate::CoreError;

/// The default memory limit: 4 GiB.
pub const DEFAULT_MEMORY_LIMIT: u64 = 4 << 30;

/// Environment variable overriding [`DEFAULT_MEMORY_LIMIT`].
pub const MEMORY_LIMIT_ENV: &str = "UNAMALLA_MAX_MEMORY";

/// Peak bytes per cell of `unamalla mesh` (all stages, the smoother's Hessian dominates).
pub const COST_PER_MESH_CELL: f64 = 12_000.0;
/// Peak bytes per node of `unamalla tfi` (the grid, its quality arrays, the VTK text).
pub const COST_PER_TFI_NODE: f64 = 400.0;
/// Peak bytes per node of `unamalla hex` (the grid, the untangling/planarity Hessian).
pub const COST_PER_HEX_NODE: f64 = 6_000.0;
/// Peak bytes per control point of `unamalla bspline` (the net, its certificates, exports).
pub const COST_PER_BSPLINE_NET_POINT: f64 = 2_000.0;
/// Peak bytes per node of a quad mesh read from a file and smoothed or solved on.
pub const COST_PER_SMOOTH_NODE: f64 = 12_000.0;

/// Above this many vertices, a region is not decomposed without simplification.
pub const MAX_UNSIMPLIFIED_VERTICES: usize = 200_000;

/// A gap between distinct rings below this fraction of the cell size is named as the cause
/// when a stage fails (and is the suggested lower bound on the cell size otherwise).
pub const MIN_GAP_FRACTION: f64 = 0.01;

/// Errors of the checks before the work.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PreflightError {
    /// A size needs more memory than the limit.
    #[error(
        "{option} {value}: needs about {} ({count:.3e} {unit} × {cost} bytes), above the memory limit of {} \
         (set {MEMORY_LIMIT_ENV} to raise it)",
        human(*needed), human(*limit as f64)
    )]
    TooLarge {
        /// The option (`--cells`, `--size`, …).
        option: String,
        /// Its value as given.
        value: String,
        /// The count the estimate is based on.
        count: f64,
        /// What is counted ("cells", "nodes", …).
        unit: String,
        /// Bytes per unit.
        cost: f64,
        /// Estimated bytes.
        needed: f64,
        /// The limit in bytes.
        limit: u64,
    },
    /// `UNAMALLA_MAX_MEMORY` does not parse.
    #[error("{MEMORY_LIMIT_ENV}={0}: expected a byte count like 8G, 512M or 1000000")]
    BadLimit(String),
    /// A huge ring without simplification.
    #[error(
        "the region has {vertices} vertices; without simplification at most {max} are decomposed \
         (the decomposition's candidate scans grow quadratically); simplify first (drop --no-simplify, \
         or run `unamalla simplify`)"
    )]
    TooManyVertices {
        /// Vertices of the region.
        vertices: usize,
        /// [`MAX_UNSIMPLIFIED_VERTICES`].
        max: usize,
    },
    /// Without simplification: a part of the boundary folds back on itself closer than the
    /// meshable gap (a spike or slit narrower than [`MIN_GAP_FRACTION`] × the cell size, longer
    /// than a cell).
    #[error(
        "{}, vertex {vertex} ({:.6e}, {:.6e}), is {width:.3e} from the same ring {sep:.3e} further \
         along it: a spike or slit narrower than the meshable gap of {need:.3e} ({MIN_GAP_FRACTION} × the \
         cell size {h:.3e}) cannot be meshed without simplification; drop --no-simplify (the \
         simplification removes it) or use --cell-size ≤ {:.3e}",
        ring_name(*ring), at[0], at[1], width / MIN_GAP_FRACTION
    )]
    NarrowFeature {
        /// The ring (0 = outer, k ≥ 1 = hole k − 1).
        ring: usize,
        /// The vertex of that ring.
        vertex: usize,
        /// Its coordinates.
        at: [f64; 2],
        /// Its distance from the other side of the feature.
        width: f64,
        /// The distance along the ring between the two sides.
        sep: f64,
        /// The cell size.
        h: f64,
        /// `MIN_GAP_FRACTION · h`.
        need: f64,
    },
    /// A failure next to a hole narrower than the cell size ([`small_hole`]).
    #[error("{0}")]
    SmallHole(Box<SmallHole>),
    /// A failure explained by a too-narrow gap between rings.
    #[error(
        "{} is {gap:.3e} from {}, below the meshable gap of {need:.3e} ({MIN_GAP_FRACTION} × the cell size {h:.3e}); \
         use a smaller cell size (--cell-size ≤ {:.3e}), drop the hole (--min-hole-area), or move it \
         (the stage reported: {detail})",
        ring_name(*b), ring_name(*a), gap / MIN_GAP_FRACTION
    )]
    NarrowGap {
        /// The first ring (0 = outer, k ≥ 1 = hole k − 1).
        a: usize,
        /// The second ring.
        b: usize,
        /// Their distance.
        gap: f64,
        /// The cell size.
        h: f64,
        /// `MIN_GAP_FRACTION · h`.
        need: f64,
        /// The stage's own message.
        detail: String,
    },
}

/// The verification's failing cells next to a hole narrower than the cell size (see
/// [`explain_guarantee`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "hole {hole} ({width:.3e} across, centred at ({:.6e}, {:.6e})) is narrower than the cell size \
     {h:.3e}: {cells} of the listed failing cells lie within a cell size of it{}; drop such holes \
     (--min-hole-area {:.3e} drops every hole up to a little above this one's area) or use a cell size of at \
     most half its width (--cell-size {:.3e}) (the check reported: {detail})",
    at[0], at[1],
    if *others > 0 { format!(", and {others} other hole(s) are narrower than a cell too") } else { String::new() },
    area * 1.001, width / 2.0
)]
pub struct SmallHole {
    /// The hole (0-based, as in the input).
    pub hole: usize,
    /// Its width: the smaller side of its bounding box.
    pub width: f64,
    /// The centre of its bounding box.
    pub at: [f64; 2],
    /// Its area.
    pub area: f64,
    /// The cell size.
    pub h: f64,
    /// Listed failing cells (non-convex: a corner within `h` of it; outside: the centroid)
    /// beside it.
    pub cells: usize,
    /// Other holes of the region narrower than `h`.
    pub others: usize,
    /// The verification's own message.
    pub detail: String,
}

/// The width of `hole` for [`SmallHole`]: the smaller side of its bounding box.
fn hole_width(hole: &unamalla_mesh::Polygon) -> (f64, DVec2) {
    let (lo, hi) = hole.bounding_box();
    (unamalla_contour::hole_width(hole), 0.5 * (lo + hi))
}

/// The points of each cell a verification lists: the corners of a non-convex cell (a folded
/// cell can be long: its centroid may lie several cells from the hole its corners touch), the
/// centroid of a cell outside.
fn failing_cell_points(v: &crate::verify::Verification) -> Vec<Vec<DVec2>> {
    v.non_convex_at
        .iter()
        .map(|c| c.iter().map(|p| DVec2::new(p[0], p[1])).collect())
        .chain(
            v.outside_examples
                .iter()
                .map(|(_, p)| vec![DVec2::new(p[0], p[1])]),
        )
        .collect()
}

/// For each hole of `region`, how many of the failing `cells` (given by their points) have
/// it as their nearest hole at a distance of at most `h` (ties to the lower index).
fn failures_next_to_holes(cells: &[Vec<DVec2>], region: &Region, h: f64) -> Vec<usize> {
    let mut count = vec![0usize; region.holes().len()];
    for pts in cells {
        let nearest = region
            .holes()
            .iter()
            .enumerate()
            .map(|(k, hole)| {
                let q = hole.points();
                let d = pts
                    .iter()
                    .flat_map(|&p| {
                        (0..q.len())
                            .map(move |i| point_segment_distance(p, q[i], q[(i + 1) % q.len()]))
                    })
                    .fold(f64::INFINITY, f64::min);
                (k, d)
            })
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        if let Some((k, d)) = nearest {
            if d <= h {
                count[k] += 1;
            }
        }
    }
    count
}

/// The holes of `region` whose width (the `hole_width` of the narrow-hole retry: the smaller
/// side of the bounding box) lies in `widths` and that are the nearest hole, within `h`, of a
/// cell the verification `v` lists as failing; in increasing order. What the later rounds of
/// the narrow-hole retry of [`crate::Mesher::mesh_observed`] leave out (widths from one to
/// `NEAR_HOLE_WIDTH` cell sizes: the narrower ones are gone already).
pub fn holes_next_to_failures(
    v: &crate::verify::Verification,
    region: &Region,
    h: f64,
    widths: std::ops::Range<f64>,
) -> Vec<usize> {
    if h.is_nan() || h <= 0.0 || region.holes().is_empty() {
        return Vec::new();
    }
    let count = failures_next_to_holes(&failing_cell_points(v), region, h);
    count
        .iter()
        .enumerate()
        .filter(|&(k, &c)| c > 0 && widths.contains(&hole_width(&region.holes()[k]).0))
        .map(|(k, _)| k)
        .collect()
}

/// The hole next to which the failing cells of `v` lie when it is narrower than the cell size
/// `h` (the hole with the most listed failing cells within `h`; ties: the lowest index), or
/// `None`. A listed cell is within `h` of a hole when one of its corners is (a cell outside:
/// its centroid). Each listed cell (at most [`crate::verify::LISTED_CELLS`] per kind) is
/// compared with every edge of every hole: the work is linear in the holes' vertices.
pub fn small_hole(v: &crate::verify::Verification, region: &Region, h: f64) -> Option<SmallHole> {
    if h.is_nan() || h <= 0.0 || region.holes().is_empty() {
        return None;
    }
    let cells = failing_cell_points(v);
    let widths: Vec<(f64, DVec2)> = region.holes().iter().map(hole_width).collect();
    let narrow: Vec<bool> = widths.iter().map(|w| w.0 < h).collect();
    let mut count = failures_next_to_holes(&cells, region, h);
    for (c, &n) in count.iter_mut().zip(&narrow) {
        if !n {
            *c = 0;
        }
    }
    let (hole, &cells) = count
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(&a.0)))?;
    if cells == 0 {
        return None;
    }
    let (width, c) = widths[hole];
    Some(SmallHole {
        hole,
        width,
        at: [c.x, c.y],
        area: region.holes()[hole].area().abs(),
        h,
        cells,
        others: narrow.iter().filter(|&&n| n).count() - 1,
        detail: v.to_string(),
    })
}

fn ring_name(k: usize) -> String {
    if k == 0 {
        "the outer ring".to_string()
    } else {
        format!("hole {}", k - 1)
    }
}

/// `1536` → `"1.5 KiB"`.
pub fn human(b: f64) -> String {
    let units = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut v = b;
    let mut k = 0;
    while v >= 1024.0 && k + 1 < units.len() {
        v /= 1024.0;
        k += 1;
    }
    if k == 0 {
        format!("{v:.0} bytes")
    } else {
        format!("{v:.1} {}", units[k])
    }
}

/// Parses `8G`, `512M`, `1000000` (powers of 1024).
pub fn parse_bytes(s: &str) -> Option<u64> {
    let t = s.trim();
    let (num, mult) = match t.chars().last()?.to_ascii_uppercase() {
        'K' => (&t[..t.len() - 1], 1u64 << 10),
        'M' => (&t[..t.len() - 1], 1 << 20),
        'G' => (&t[..t.len() - 1], 1 << 30),
        'T' => (&t[..t.len() - 1], 1 << 40),
        _ => (t, 1),
    };
    let v: f64 = num.trim().parse().ok()?;
    (v.is_finite() && v > 0.0 && v * (mult as f64) < 1.8e19).then_some((v * mult as f64) as u64)
}

/// The memory limit: [`MEMORY_LIMIT_ENV`] if set, else [`DEFAULT_MEMORY_LIMIT`].
pub fn memory_limit() -> Result<u64, PreflightError> {
    match std::env::var(MEMORY_LIMIT_ENV) {
        Ok(s) => parse_bytes(&s).ok_or(PreflightError::BadLimit(s)),
        Err(_) => Ok(DEFAULT_MEMORY_LIMIT),
    }
}

/// `count × cost` against `limit`; the error names `option` and `value`.
pub fn check_size(
    option: &str,
    value: impl fmt::Display,
    count: f64,
    unit: &str,
    cost: f64,
    limit: u64,
) -> Result<(), PreflightError> {
    let needed = count * cost;
    if needed.is_finite() && needed <= limit as f64 {
        Ok(())
    } else {
        Err(PreflightError::TooLarge {
            option: option.to_string(),
            value: value.to_string(),
            count,
            unit: unit.to_string(),
            cost,
            needed,
            limit,
        })
    }
}

/// Refuses a region of more than [`MAX_UNSIMPLIFIED_VERTICES`] vertices that is to be
/// decomposed as given.
pub fn check_unsimplified(region: &Region) -> Result<(), PreflightError> {
    let v = region.num_vertices();
    if v > MAX_UNSIMPLIFIED_VERTICES {
        Err(PreflightError::TooManyVertices {
            vertices: v,
            max: MAX_UNSIMPLIFIED_VERTICES,
        })
    } else {
        Ok(())
    }
}

/// The narrowest fold of one ring onto itself, as `(ring, vertex, width, separation)`: the
/// vertex of `region` closest to an edge of its own ring among the pairs that are closer than
/// `gap` in the plane but more than `h` apart along the ring (cyclic arc length), or `None`.
///
/// Two boundary points within `gap` of each other whose connecting arc is longer than `h`
/// bound a feature (spike, slit, neck) narrower than `gap` over more than a cell: no cell of
/// size `h` fits in it. A smooth, densely sampled boundary has no such pair (points close in
/// the plane are close along the ring), and a corner only if it is sharper than
/// `2·asin(gap / h)` (about 1.15° for `gap = 0.01·h`). Each vertex queries the ring's segment
/// index with a box of half-width `gap`, so the work is `O(n log n)` for `gap` below the
/// vertex spacing.
pub fn narrow_feature(region: &Region, gap: f64, h: f64) -> Option<(usize, usize, f64, f64)> {
    if !(gap > 0.0 && h > 0.0) {
        return None;
    }
    let rings: Vec<Vec<DVec2>> = region.rings().map(|r| r.points().to_vec()).collect();
    let cum: Vec<Vec<f64>> = rings
        .iter()
        .map(|ring| {
            let n = ring.len();
            let mut c = Vec::with_capacity(n + 1);
            c.push(0.0);
            for k in 0..n {
                c.push(c[k] + (ring[(k + 1) % n] - ring[k]).length());
            }
            c
        })
        .collect();
    let index = SegmentIndex::new(rings.clone());
    let mut best: Option<(usize, usize, f64, f64)> = None;
    let d = DVec2::splat(gap);
    for (r, ring) in rings.iter().enumerate() {
        let total = cum[r][ring.len()];
        for (k, &p) in ring.iter().enumerate() {
            for e in index.candidates(p - d, p + d) {
                if e.ring != r {
                    continue;
                }
                let (a, b) = index.edge(e);
                let dist = point_segment_distance(p, a, b);
                if dist >= gap || best.is_some_and(|x| dist >= x.2) {
                    continue;
                }
                let ab = b - a;
                let t = if ab.length_squared() > 0.0 {
                    ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let sq = cum[r][e.edge] + t * (cum[r][e.edge + 1] - cum[r][e.edge]);
                let diff = (sq - cum[r][k]).abs();
                let sep = diff.min(total - diff);
                if sep > h {
                    best = Some((r, k, dist, sep));
                }
            }
        }
    }
    best
}

/// Refuses to mesh `region` as given (without simplification) at cell size `h` when it has a
/// [`narrow_feature`] below [`MIN_GAP_FRACTION`] × `h`: such a run cannot meet the guarantee
/// and, at fine sizes, spent minutes failing in the smoother (a 10⁻⁷-wide spike took
/// 681 s to exit 3 at the default size).
pub fn check_narrow_features(region: &Region, h: f64) -> Result<(), PreflightError> {
    let need = MIN_GAP_FRACTION * h;
    match narrow_feature(region, need, h) {
        Some((ring, vertex, width, sep)) => {
            let p = region
                .rings()
                .nth(ring)
                .map_or(DVec2::NAN, |r| r.points()[vertex]);
            Err(PreflightError::NarrowFeature {
                ring,
                vertex,
                at: [p.x, p.y],
                width,
                sep,
                h,
                need,
            })
        }
        None => Ok(()),
    }
}

/// The closest pair of distinct rings `(a, b, distance)` (rings numbered as in
/// [`PreflightError::NarrowGap`]), or `None` without holes. Uses the region's segment index:
/// for every vertex, the edges of other rings within the current best distance.
pub fn ring_gaps(region: &Region) -> Option<(usize, usize, f64)> {
    if region.holes().is_empty() {
        return None;
    }
    let rings: Vec<Vec<DVec2>> = region.rings().map(|r| r.points().to_vec()).collect();
    // brute force over ring pairs is O(n²) only in the holes' vertices against the rest;
    // bound the work with the segment index's box queries instead
    let index = SegmentIndex::new(rings.clone());
    let mut best: Option<(usize, usize, f64)> = None;
    // holes first (usually small and near something): the best distance shrinks early, and the
    // outer ring's vertices then query small boxes
    for ra in (1..rings.len()).chain([0]) {
        for &p in &rings[ra] {
            let r = best.map_or_else(
                || {
                    let (lo, hi) = region.bounding_box();
                    (hi - lo).length()
                },
                |b| b.2,
            );
            let d = DVec2::splat(r);
            for e in index.candidates(p - d, p + d) {
                if e.ring == ra {
                    continue;
                }
                let (a, b) = index.edge(e);
                let dist = point_segment_distance(p, a, b);
                if best.is_none_or(|x| dist < x.2) {
                    best = Some((ra.min(e.ring), ra.max(e.ring), dist));
                }
            }
        }
    }
    best
}

/// Replaces a stage failure `e` by [`PreflightError::NarrowGap`] when `region` has two rings
/// closer than [`MIN_GAP_FRACTION`] × `h`; other errors pass unchanged. Guarantee and
/// preflight errors are never replaced.
pub fn explain_failure(e: CoreError, region: &Region, h: f64) -> CoreError {
    if matches!(e, CoreError::Guarantee(_) | CoreError::Preflight(_)) || h.is_nan() || h <= 0.0 {
        return e;
    }
    match ring_gaps(region) {
        Some((a, b, gap)) if gap < MIN_GAP_FRACTION * h => {
            CoreError::Preflight(PreflightError::NarrowGap {
                a,
                b,
                gap,
                h,
                need: MIN_GAP_FRACTION * h,
                detail: e.to_string(),
            })
        }
        _ => e,
    }
}

/// The guarantee error `e` of a finished mesh, explained like [`explain_failure`]: when
/// `region` has two rings closer than [`MIN_GAP_FRACTION`] × `h` the cause is that gap (an
/// input the size cannot mesh, [`PreflightError::NarrowGap`] with the verification's failures
/// as the detail), not the cells it produced there; when the failing cells lie next to a hole
/// narrower than the cell size, that hole ([`PreflightError::SmallHole`], [`small_hole`]);
/// otherwise `e` unchanged.
pub fn explain_guarantee(e: crate::verify::GuaranteeNotMet, region: &Region, h: f64) -> CoreError {
    match ring_gaps(region) {
        Some((a, b, gap)) if h > 0.0 && gap < MIN_GAP_FRACTION * h => {
            CoreError::Preflight(PreflightError::NarrowGap {
                a,
                b,
                gap,
                h,
                need: MIN_GAP_FRACTION * h,
                detail: e.0.to_string(),
            })
        }
        _ => match small_hole(&e.0, region, h) {
            Some(s) => CoreError::Preflight(PreflightError::SmallHole(Box::new(s))),
            None => CoreError::Guarantee(e),
        },
    }
}

#[cfg(test)]
mod tests;
