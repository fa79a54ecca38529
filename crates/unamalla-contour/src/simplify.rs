//! The region-level driver: [`Method`], [`SimplifyOptions`], [`simplify_region`] and its
//! [`SimplifyResult`].

use std::fmt;
use std::str::FromStr;
use std::time::{Duration, Instant};

use glam::DVec2;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use unamalla_mesh::geometry::orient2d;
use unamalla_mesh::{Region, RingId, SegmentIndex};

use crate::criteria::{
    mean_triangle_area, modified_radius, radius_ratio, triangle_area, weighted_area,
};
use crate::error::ContourError;
use crate::mpp::{minimum_perimeter_polygon, MppOptions};
use crate::removal::{batch, sequential, Stop, Workspace};

mod hausdorff;
pub use hausdorff::{hausdorff, subset_hausdorff, SubsetHausdorff};

/// A simplification method of [Méndez 2023, Ch. 3] (names as accepted by [`Method::from_str`]).
///
/// Default thresholds ([`Method::default_epsilon`], [`Method::default_delta`]):
///
/// | method | name | `ε` clean | `ε` noisy | `δ` clean | `δ` noisy | source |
/// |---|---|---|---|---|---|---|
/// | [`Method::Visvalingam`] | `visvalingam` | 1 | 20 | – | – | Tables 3.1–3.3 |
/// | [`Method::Areas`] | `areas` | 1e-4 | 1e-2 | – | – | §3.3.3 step 1; Obs 3.3 range 1e-4..1e-2 |
/// | [`Method::Radii`] | `radii` | 1e-4 | 1e-2 | – | – | §3.3.3 step 3; Obs 3.3 |
/// | [`Method::ModifiedAreas`] | `modified-areas` | 1 | 20 | – | – | Tables 3.1–3.3 |
/// | [`Method::ModifiedRadii`] | `modified-radii` | 1 | 20 | – | – | Tables 3.1–3.3, Obs 3.4 |
/// | [`Method::ThreeStep`] | `three-step` | 1e-4 | 1e-4 | 1e-4 | 1e-3 | §3.3.3 |
/// | [`Method::ModifiedThreeStep`] | `modified-three-step` | 0.1 | 3 | 1e-5 | 1e-4 | §3.3.4 presets, Table 3.1 |
///
/// For the three-step methods `ε` is the threshold of the last step (ρ for `three-step`);
/// their first step always uses the thesis's fixed value (1e-4, resp. 0.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum Method {
    /// Scaled Visvalingam (§3.1.1, Obs 3.1): repeatedly remove the vertex of smallest triangle
    /// area while that area is below `ε · ā`, `ā` the mean triangle area of the input ring
    /// (fixed: with the mean of the *current* ring every `ε ≥ 1` would remove vertices down to
    /// a triangle, since the minimum never exceeds the mean, contradicting the thesis's use of
    /// ε = 1 and ε = 20 in Tables 3.1–3.3).
    Visvalingam,
    /// Area criterion (3.5), batch passes: remove all `v_i` with `ζ_i / ā < 2ε`,
    /// `ζ_i = α_i |sin θ_i|`, `ā` the current mean triangle area; repeat until stable.
    Areas,
    /// Radius criterion (§3.3.2), batch passes: remove all `v_i` with `r_i / R_i < ε`.
    Radii,
    /// Modified area criterion (3.6): one vertex at a time, the one of smallest `ζ`, while
    /// `ζ < ᾱ ε` with `ᾱ` the mean triangle area of the input ring (fixed).
    #[default]
    ModifiedAreas,
    /// Modified radius criterion (3.7)/(3.8): like [`Method::ModifiedAreas`] with
    /// `ρ = 2 r R |sin θ|`.
    ModifiedRadii,
    /// Three-step method (§3.3.3): areas (ε = 1e-4) → minimum-perimeter polygon (δ) → radii (ε).
    ThreeStep,
    /// Modified three-step method (§3.3.4): modified areas (ε = 0.1) → minimum-perimeter
    /// polygon (δ) → modified areas (ε); `ᾱ` of both removal steps is that of the input ring.
    ModifiedThreeStep,
}

impl Method {
    /// Every method, in the order of the thesis.
    pub const ALL: [Method; 7] = [
        Method::Visvalingam,
        Method::Areas,
        Method::Radii,
        Method::ModifiedAreas,
        Method::ModifiedRadii,
        Method::ThreeStep,
        Method::ModifiedThreeStep,
    ];
    /// The accepted names, in the order of [`Method::ALL`].
    pub const NAMES: [&'static str; 7] = [
        "visvalingam",
        "areas",
        "radii",
        "modified-areas",
        "modified-radii",
        "three-step",
        "modified-three-step",
    ];

    /// The method's name (as accepted by [`Method::from_str`]).
    pub fn name(self) -> &'static str {
        Self::NAMES[Self::ALL.iter().position(|&m| m == self).unwrap_or(0)]
    }

    /// `true` for the methods that move points (they run the minimum-perimeter polygon); the
    /// others return a subset of the input vertices in their original order.
    pub fn moves_points(self) -> bool {
        matches!(self, Method::ThreeStep | Method::ModifiedThreeStep)
    }

    /// Default threshold `ε` for a preset (table in the type documentation).
    pub fn default_epsilon(self, preset: Preset) -> f64 {
        let noisy = preset == Preset::Noisy;
        match self {
            Method::Visvalingam | Method::ModifiedAreas | Method::ModifiedRadii => {
                if noisy {
                    20.0
                } else {
                    1.0
                }
            }
            Method::Areas | Method::Radii => {
                if noisy {
                    1e-2
                } else {
                    1e-4
                }
            }
            Method::ThreeStep => 1e-4,
            Method::ModifiedThreeStep => {
                if noisy {
                    3.0
                } else {
                    0.1
                }
            }
        }
    }

    /// Default MPP factor `δ` for a preset, `None` for methods without the MPP step.
    pub fn default_delta(self, preset: Preset) -> Option<f64> {
        let noisy = preset == Preset::Noisy;
        match self {
            Method::ThreeStep => Some(if noisy { 1e-3 } else { 1e-4 }),
            Method::ModifiedThreeStep => Some(if noisy { 1e-4 } else { 1e-5 }),
            _ => None,
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = ContourError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::NAMES
            .iter()
            .position(|&n| n == s)
            .map(|k| Self::ALL[k])
            .ok_or_else(|| ContourError::UnknownMethod {
                name: s.to_string(),
                valid: Self::NAMES.join(", "),
            })
    }
}

/// Which set of default thresholds to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum Preset {
    /// No noise: simplification thresholds (e.g. modified three-step δ = 1e-5, ε = 0.1).
    #[default]
    Clean,
    /// Noise suppression (e.g. modified three-step δ = 1e-4, ε = 3).
    Noisy,
    /// Decide per region with [`crate::noise::detect_noise_region`].
    Auto,
}

/// Which holes to drop before simplifying (the thesis recommends removing negligible holes
/// before meshing, Obs A.1).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub enum HoleFilter {
    /// Keep every hole.
    #[default]
    KeepAll,
    /// Drop holes whose area is below this value (region units squared).
    MinArea(f64),
    /// Drop holes whose area is below this fraction of the outer ring's area.
    MinAreaFraction(f64),
    /// Drop holes narrower than this (region units): the hole's width ([`hole_width`]: the
    /// minimum width of its convex hull) is below it (what `unamalla_core`'s failure analysis
    /// calls a hole narrower than a cell).
    MinWidth(f64),
}

/// The width [`HoleFilter::MinWidth`] compares: the **minimum width** of the ring's convex hull,
/// the smallest distance between two parallel lines that enclose it. One of the two lines of
/// the minimum passes through an edge of the hull (Houle & Toussaint 1988, "Computing the width
/// of a set", IEEE Trans. PAMI 10(5), 761–765), so the width is
/// `min over hull edges e of max over hull vertices p of dist(p, line(e))`, computed here
/// directly in `O(h²)` for a hull of `h` vertices (islands' hulls are small; rotating calipers
/// would make it `O(h)`). Unlike the smaller side of the axis-aligned bounding box (the measure
/// until 2026-12-06), it does not depend on the island's orientation: a thin island lying
/// diagonally has a bounding box wider than it in both directions (Gulf of Mexico at 20,000
/// cells: an islet 4 units wide, 0.4 cells, had a box 10 units wide). A ring of fewer than three
/// distinct hull vertices has width 0.
pub fn hole_width(hole: &unamalla_mesh::Polygon) -> f64 {
    let pts = hole.points();
    let hull: Vec<unamalla_mesh::DVec2> = hole.convex_hull().iter().map(|&i| pts[i]).collect();
    let n = hull.len();
    if n < 3 {
        return 0.0;
    }
    (0..n)
        .map(|k| {
            let (a, b) = (hull[k], hull[(k + 1) % n]);
            let e = b - a;
            let len = e.length();
            hull.iter()
                .map(|&p| e.perp_dot(p - a).abs() / len)
                .fold(0.0, f64::max)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Options of [`simplify_region`]. `Default` is modified areas with the clean preset (ε = 1),
/// all holes kept.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct SimplifyOptions {
    /// The method.
    pub method: Method,
    /// Which defaults to use when `epsilon` / `delta` are not given.
    pub preset: Preset,
    /// Threshold ε (overrides the preset's).
    pub epsilon: Option<f64>,
    /// MPP factor δ (overrides the preset's; ignored by methods without the MPP step).
    pub delta: Option<f64>,
    /// Hole dropping.
    pub holes: HoleFilter,
    /// MPP solver tuning.
    pub mpp: MppOptions,
}

impl SimplifyOptions {
    /// Options for `method` with the given preset and everything else default.
    pub fn new(method: Method, preset: Preset) -> Self {
        Self {
            method,
            preset,
            ..Self::default()
        }
    }

    /// Sets [`method`](Self::method): the method.
    #[must_use]
    pub fn method(mut self, method: Method) -> Self {
        self.method = method;
        self
    }

    /// Sets [`preset`](Self::preset): which defaults to use when `epsilon` / `delta` are not given.
    #[must_use]
    pub fn preset(mut self, preset: Preset) -> Self {
        self.preset = preset;
        self
    }

    /// Sets [`epsilon`](Self::epsilon): threshold ε (overrides the preset's).
    #[must_use]
    pub fn epsilon(mut self, epsilon: Option<f64>) -> Self {
        self.epsilon = epsilon;
        self
    }

    /// Sets [`delta`](Self::delta).
    #[must_use]
    pub fn delta(mut self, delta: Option<f64>) -> Self {
        self.delta = delta;
        self
    }

    /// Sets [`holes`](Self::holes): hole dropping.
    #[must_use]
    pub fn holes(mut self, holes: HoleFilter) -> Self {
        self.holes = holes;
        self
    }

    /// Sets [`mpp`](Self::mpp): MPP solver tuning.
    #[must_use]
    pub fn mpp(mut self, mpp: MppOptions) -> Self {
        self.mpp = mpp;
        self
    }
}

/// Per-ring figures of a simplification.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RingReport {
    /// Which ring of the **input** region (hole numbers are input numbers).
    pub ring: RingId,
    /// Vertices before.
    pub before: usize,
    /// Vertices after.
    pub after: usize,
    /// `(A_after − A_before) / A_before` of this ring's enclosed area.
    pub relative_area_change: f64,
    /// Hausdorff distance between the input ring and the simplified ring: for the methods that
    /// only remove vertices the value of [`subset_hausdorff`] (exact when its certificate holds,
    /// which is the common case), for the methods that move points the sampled [`hausdorff`].
    pub hausdorff: f64,
}

/// A hole removed by the [`HoleFilter`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DroppedHole {
    /// Its number in the input region.
    pub hole: usize,
    /// Its area.
    pub area: f64,
    /// Its vertex count.
    pub vertices: usize,
}

/// Everything [`simplify_region`] produces.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimplifyResult {
    /// The simplified region (valid by construction; built with the O(n) checks of
    /// [`Region::from_simple_rings`], and debug builds also check it with [`Region::new`]).
    pub region: Region,
    /// The method used.
    pub method: Method,
    /// The preset the defaults came from (`Auto` resolved to `Clean` or `Noisy`).
    pub preset: Preset,
    /// The threshold ε used.
    pub epsilon: f64,
    /// The MPP factor δ used, if the method has an MPP step.
    pub delta: Option<f64>,
    /// Outer ring first, then the kept holes, in input order.
    pub rings: Vec<RingReport>,
    /// Holes dropped by the filter.
    pub dropped_holes: Vec<DroppedHole>,
    /// Total vertices of the input region.
    pub vertices_before: usize,
    /// Total vertices of the result.
    pub vertices_after: usize,
    /// Region area (outer minus holes) before.
    pub area_before: f64,
    /// Region area after.
    pub area_after: f64,
    /// `(area_after − area_before) / area_before` (includes the effect of dropped holes).
    pub relative_area_change: f64,
    /// Largest Hausdorff distance between a kept input ring and its simplified version.
    pub hausdorff: f64,
    /// Wall time of the simplification itself (hole filter, removal, MPP, building the output
    /// region with [`Region::from_simple_rings`]; not the metrics, and not the validation of the
    /// input, which the caller did when building `region`).
    pub elapsed: Duration,
}

fn check_param(name: &'static str, v: f64) -> Result<f64, ContourError> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(ContourError::InvalidParameter {
            name,
            value: v,
            reason: "must be finite and >= 0",
        })
    }
}

/// Simplifies every ring of `region` (outer ring and each kept hole separately, §3.3, Obs 3.3)
/// with `opts.method`, never letting a ring self-intersect or touch another ring (see
/// the crate documentation, *Topology safety*). The output is valid by construction and built
/// with the O(n) checks of [`Region::from_simple_rings`] (debug builds re-validate it with
/// [`Region::new`]).
pub fn simplify_region(
    region: &Region,
    opts: &SimplifyOptions,
) -> Result<SimplifyResult, ContourError> {
    let t0 = Instant::now();
    let preset = match opts.preset {
        Preset::Auto => {
            if crate::noise::detect_noise_region(region).0 {
                Preset::Noisy
            } else {
                Preset::Clean
            }
        }
        p => p,
    };
    let method = opts.method;
    let eps = check_param(
        "epsilon",
        opts.epsilon.unwrap_or(method.default_epsilon(preset)),
    )?;
    let delta = match method.default_delta(preset) {
        Some(d) => Some(check_param("delta", opts.delta.unwrap_or(d))?),
        None => None,
    };
    // hole filter
    let outer_area = region.outer().area();
    let (min_area, min_width) = match opts.holes {
        HoleFilter::KeepAll => (0.0, 0.0),
        HoleFilter::MinArea(a) => (check_param("min_hole_area", a)?, 0.0),
        HoleFilter::MinAreaFraction(f) => {
            (check_param("min_hole_area_fraction", f)? * outer_area, 0.0)
        }
        HoleFilter::MinWidth(w) => (0.0, check_param("min_hole_width", w)?),
    };
    let mut kept: Vec<usize> = Vec::new();
    let mut dropped_holes = Vec::new();
    for (k, h) in region.holes().iter().enumerate() {
        if h.area() < min_area || hole_width(h) < min_width {
            dropped_holes.push(DroppedHole {
                hole: k,
                area: h.area(),
                vertices: h.len(),
            });
        } else {
            kept.push(k);
        }
    }
    let input: Vec<Vec<DVec2>> = std::iter::once(region.outer().points().to_vec())
        .chain(kept.iter().map(|&k| region.holes()[k].points().to_vec()))
        .collect();
    let (output, kept_ids) = run_method(&input, method, eps, delta, &opts.mpp)?;
    let simplified = output_region(output)?;
    let elapsed = t0.elapsed();

    let rings: Vec<RingReport> = simplified
        .rings()
        .zip(&input)
        .enumerate()
        .map(|(k, (s, orig))| {
            let a0 = unamalla_mesh::region::signed_area(orig).abs();
            // vertex-removal methods: the per-edge chain scan (exact when certified, see
            // `subset_hausdorff`); methods that move points: the sampled distance
            let h = match kept_ids.as_ref().and_then(|ids| ids.get(k)) {
                Some(ids) => subset_hausdorff(orig, ids)?.distance,
                None => hausdorff(orig, s.points()),
            };
            Ok(RingReport {
                ring: if k == 0 {
                    RingId::Outer
                } else {
                    RingId::Hole(kept[k - 1])
                },
                before: orig.len(),
                after: s.len(),
                relative_area_change: (s.area() - a0) / a0,
                hausdorff: h,
            })
        })
        .collect::<Result<_, ContourError>>()?;
    let area_before = region.area();
    let area_after = simplified.area();
    Ok(SimplifyResult {
        vertices_before: region.num_vertices(),
        vertices_after: simplified.num_vertices(),
        relative_area_change: (area_after - area_before) / area_before,
        hausdorff: rings.iter().map(|r| r.hausdorff).fold(0.0, f64::max),
        region: simplified,
        method,
        preset,
        epsilon: eps,
        delta,
        rings,
        dropped_holes,
        area_before,
        area_after,
        elapsed,
    })
}

/// Removes every boundary feature smaller than `min_area` (an absolute area, region units²):
/// the modified-area criterion (3.6) run sequentially on each ring, as in
/// [`Method::ModifiedAreas`], but with the absolute threshold `ζ_i < min_area` instead of
/// `ζ_i < ε·ᾱ` (ᾱ of the input ring). Topology-safe like every method here (no ring becomes
/// self-intersecting or touches another); holes are kept even when they shrink to triangles.
///
/// Why an absolute threshold: a mesher with target cell size `h` cannot follow boundary
/// wiggles much smaller than a cell — a zig-zag of cell-sized legs on one side of a block two
/// cells wide admits no convex cells at all. With `min_area = c·h²`, a smooth stretch of
/// radius of curvature `R` keeps vertices about `s ≈ (c·h²·R²)^{1/4}` apart (ζ ≈ s⁴/R² for
/// spacing `s`), so the chord error there is `s²/(8R) ≈ √c·h/8`, a fraction of a cell, while
/// spikes and zig-zags of width ≲ `√c·h` (ζ ≈ width²) are removed. (Our addition, not in
/// the thesis; the criterion and its ζ are [Méndez 2023, (3.4), (3.6)].)
pub fn remove_features_below(region: &Region, min_area: f64) -> Result<Region, ContourError> {
    let min_area = check_param("min_area", min_area)?;
    let input: Vec<Vec<DVec2>> = region.rings().map(|r| r.points().to_vec()).collect();
    let mut ws = Workspace::new(&input);
    for r in 0..input.len() {
        sequential(&mut ws, r, weighted_area, Stop::Below(min_area));
    }
    output_region((0..ws.num_rings()).map(|r| ws.ring_points(r)).collect())
}

/// The region of the output rings (outer first) of a topology-safe method.
///
/// The rings are valid **by construction**: the input was a valid region, and every change
/// since was either a vertex removal accepted by the exact topology check of
/// `removal::Workspace` (which keeps each ring simple, all rings disjoint, every hole inside
/// the outer ring and the orientation; see its module documentation) or an MPP step whose
/// result `mpp_step` validated with [`Region::new`]. So the O(n log n) re-validation of
/// [`Region::new`] (R*-tree over all edges, ≈ 8 % of the 100k benchmark) is skipped:
/// [`Region::from_simple_rings`] runs only the O(n) checks (finite, no repeated points, ≥ 3
/// points, non-zero area) and normalises the orientation the same way, so the result equals
/// `Region::new` on the same rings — which debug builds (every test) assert.
fn output_region(rings: Vec<Vec<DVec2>>) -> Result<Region, ContourError> {
    let mut it = rings.into_iter();
    let outer = it.next().unwrap_or_default();
    let holes: Vec<Vec<DVec2>> = it.collect();
    #[cfg(debug_assertions)]
    let full = Region::new(outer.clone(), holes.clone());
    let region = Region::from_simple_rings(outer, holes)?;
    #[cfg(debug_assertions)]
    debug_assert_eq!(
        full.as_ref().ok(),
        Some(&region),
        "full validation disagrees"
    );
    Ok(region)
}

/// The new rings of [`run_method`] and, for the methods that only remove vertices, the kept
/// vertices of each ring as indices into the input ring.
type MethodOutput = (Vec<Vec<DVec2>>, Option<Vec<Vec<usize>>>);

/// Runs one method on a valid set of rings (outer first); returns the new rings (and the kept
/// input indices when no point moved).
fn run_method(
    input: &[Vec<DVec2>],
    method: Method,
    eps: f64,
    delta: Option<f64>,
    mpp: &MppOptions,
) -> Result<MethodOutput, ContourError> {
    let extract = |ws: &Workspace| -> Vec<Vec<DVec2>> {
        (0..ws.num_rings()).map(|r| ws.ring_points(r)).collect()
    };
    let mut ws = Workspace::new(input);
    let n_rings = input.len();
    match method {
        Method::Visvalingam => {
            for (r, ring) in input.iter().enumerate() {
                let abar = mean_triangle_area(ring);
                sequential(&mut ws, r, triangle_area, Stop::Below(eps * abar));
            }
        }
        Method::Areas => {
            for r in 0..n_rings {
                batch(&mut ws, r, |a, b, c, mean| {
                    weighted_area(a, b, c) < 2.0 * eps * mean
                });
            }
        }
        Method::Radii => {
            for r in 0..n_rings {
                batch(&mut ws, r, |a, b, c, _| radius_ratio(a, b, c) < eps);
            }
        }
        Method::ModifiedAreas | Method::ModifiedRadii => {
            let key = if method == Method::ModifiedAreas {
                weighted_area
            } else {
                modified_radius
            };
            for (r, ring) in input.iter().enumerate() {
                let abar = mean_triangle_area(ring);
                sequential(&mut ws, r, key, Stop::Below(eps * abar));
            }
        }
        Method::ThreeStep => {
            for r in 0..n_rings {
                batch(&mut ws, r, |a, b, c, mean| {
                    weighted_area(a, b, c) < 2.0 * 1e-4 * mean
                });
            }
            let moved = mpp_step(&extract(&ws), delta.unwrap_or(0.0), mpp)?;
            ws = Workspace::new(&moved);
            for r in 0..n_rings {
                batch(&mut ws, r, |a, b, c, _| radius_ratio(a, b, c) < eps);
            }
        }
        Method::ModifiedThreeStep => {
            let abar: Vec<f64> = input.iter().map(|r| mean_triangle_area(r)).collect();
            for (r, &ab) in abar.iter().enumerate() {
                sequential(&mut ws, r, weighted_area, Stop::Below(0.1 * ab));
            }
            let moved = mpp_step(&extract(&ws), delta.unwrap_or(0.0), mpp)?;
            ws = Workspace::new(&moved);
            for (r, &ab) in abar.iter().enumerate() {
                sequential(&mut ws, r, weighted_area, Stop::Below(eps * ab));
            }
        }
    }
    let ids = (!method.moves_points())
        .then(|| (0..ws.num_rings()).map(|r| ws.ring_local_ids(r)).collect());
    Ok((extract(&ws), ids))
}

/// MPP on every ring separately, then a topology repair: vertices of edges that came to
/// intersect (or coincide) are put back at their input positions until the rings are valid
/// again. Each round restores at least one moved vertex, and the all-restored configuration is
/// the valid input, so this terminates with a valid region.
fn mpp_step(
    rings: &[Vec<DVec2>],
    delta: f64,
    opts: &MppOptions,
) -> Result<Vec<Vec<DVec2>>, ContourError> {
    // rings are independent problems: solve them in parallel
    let mut moved = rings
        .par_iter()
        .map(|ring| minimum_perimeter_polygon(ring, delta, opts).map(|r| r.points))
        .collect::<Result<Vec<_>, _>>()?;
    loop {
        let conflicts = conflicts(&moved);
        if conflicts.is_empty() {
            let mut it = moved.iter().cloned();
            let outer = it.next().unwrap_or_default();
            if Region::new(outer, it.collect()).is_ok() {
                return Ok(moved);
            }
            return Ok(rings.to_vec());
        }
        let mut progress = false;
        for (r, i) in conflicts {
            if moved[r][i] != rings[r][i] {
                moved[r][i] = rings[r][i];
                progress = true;
            }
        }
        if !progress {
            return Ok(rings.to_vec());
        }
    }
}

/// Vertices involved in any defect of the rings: repeated consecutive points, intersecting or
/// touching non-adjacent edges (same or different ring), folded-back adjacent edges.
fn conflicts(rings: &[Vec<DVec2>]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for (r, ring) in rings.iter().enumerate() {
        let n = ring.len();
        for i in 0..n {
            if ring[i] == ring[(i + 1) % n] {
                out.push((r, i));
                out.push((r, (i + 1) % n));
            }
        }
    }
    if !out.is_empty() {
        return out;
    }
    let index = SegmentIndex::new(rings.to_vec());
    for (r, ring) in rings.iter().enumerate() {
        let n = ring.len();
        for e in 0..n {
            let (a, b) = (ring[e], ring[(e + 1) % n]);
            for o in index.intersecting(a, b) {
                if (o.ring, o.edge) <= (r, e) {
                    continue;
                }
                let hit = if o.ring == r && o.edge == (e + 1) % n {
                    let c = ring[(e + 2) % n];
                    orient2d(a, b, c) == 0.0 && (a - b).dot(c - b) > 0.0
                } else if o.ring == r && e == (o.edge + 1) % n {
                    let z = ring[(e + n - 1) % n];
                    orient2d(z, a, b) == 0.0 && (z - a).dot(b - a) > 0.0
                } else {
                    true
                };
                if hit {
                    let m = rings[o.ring].len();
                    out.extend([
                        (r, e),
                        (r, (e + 1) % n),
                        (o.ring, o.edge),
                        (o.ring, (o.edge + 1) % m),
                    ]);
                }
            }
        }
    }
    out
}
