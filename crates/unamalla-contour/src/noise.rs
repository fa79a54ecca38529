//! Noise detection, [Méndez 2023, §3.2.1, (3.1)], plus an automatic jump detector.
//!
//! (The chapter summary speaks of areas scaled by the average area, §3.2.1 of the largest one:
//! the two differ by a constant shift of the log profile, which moves no jump.)
//!
//! The thesis plots the **sorted log-area profile** (3.1)
//!
//! ```text
//!   y_i = log10( a_σ(i) / a_σ(1) ),  i = 1..m,   a_σ(1) ≥ a_σ(2) ≥ … > 0
//! ```
//!
//! of the triangle areas `a_i = area(v_{i−1}, v_i, v_{i+1})` (collinear vertices, `a_i = 0`, are
//! left out) and judges by eye: a staircase with large jumps means noise, a gradual decay
//! means none. The thesis gives no automatic rule; ours (documented thresholds, calibrated on
//! synthetic clean, jittered and digitised curves and checked on the 12 fixture regions) looks
//! at the drops `d_i = y_i − y_{i+1}` and calls the ring **noisy** if either
//!
//! * **gap**: some drop after rank `i` with `3 ≤ i < ⌊0.95 m⌋` is at least [`GAP_DECADES`] = 1
//!   decade: a floor of tiny triangles (the noise) lies an order of magnitude below the
//!   shape's corners with nothing in between. Ranks 1 and 2 are excluded: one or two huge
//!   triangles (a long straight closing edge of a map) are outliers, not a noise floor, and
//!   every polygon has at least 3 corners; or
//! * **staircase**: in the *core* — ranks `⌈0.05 m⌉..⌊0.95 m⌋`, leaving out both sparse tails —
//!   the drops that are at least `max(`[`STEP_DECADES`]` = 0.05, 10 ×` the mean core drop`)`
//!   carry at least [`STAIRCASE_FRACTION`] = 50 % of the core decay, and that decay is at least
//!   [`MIN_CORE_DECAY`] = 0.25 decades: the areas take a few discrete values, as on digital
//!   curves (integer coordinates: areas are multiples of 1/2), instead of a continuum.
//!
//! A vertex counts as collinear (and is left out of the profile, as the thesis plots the
//! non-collinear vertices only) when `|sin θ| ≤` [`COLLINEAR_SIN`] `= 10⁻⁹` at it: floating-point
//! round-off leaves points sampled on a straight edge with areas of `10⁻¹³` of the largest,
//! which an exact `a = 0` test would keep as a 13-decade "gap" on a clean contour.
//!
//! Rings with fewer than [`MIN_VERTICES`] = 16 non-collinear vertices are never called noisy.
//! A profile with a single level (all triangles of equal area, e.g. a regular polygon, or a
//! pixel chain with a vertex at every pixel) carries no evidence either way and is reported
//! clean. The verdict suggests a [`Preset`]: [`Preset::Noisy`] or [`Preset::Clean`].

use glam::DVec2;

use crate::criteria::{sin_angle, triangle_area};
use crate::error::ContourError;
use crate::Preset;

/// A single drop of at least this many decades in the profile is a noise gap.
pub const GAP_DECADES: f64 = 1.0;
/// Drops of at least this many decades (and at least 10 × the mean core drop) count as
/// staircase steps.
pub const STEP_DECADES: f64 = 0.05;
/// A staircase needs at least this much decay (decades) over the core of the profile.
pub const MIN_CORE_DECAY: f64 = 0.25;
/// Fraction of the core decay carried by steps that makes a staircase.
pub const STAIRCASE_FRACTION: f64 = 0.5;
/// `|sin θ|` at or below which a vertex counts as collinear (round-off of points on a line).
pub const COLLINEAR_SIN: f64 = 1e-9;
/// Rings with fewer non-collinear vertices than this are reported as not noisy.
pub const MIN_VERTICES: usize = 16;

/// The sorted log-area profile of a ring and the detector's findings.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseReport {
    /// `y_i = log10(a_σ(i) / a_σ(1))`, decreasing, over the non-collinear vertices (3.1).
    pub profile: Vec<f64>,
    /// Number of collinear vertices left out of the profile.
    pub collinear: usize,
    /// Largest single drop (decades) after ranks `3..⌊0.95 m⌋`.
    pub largest_gap: f64,
    /// Rank (1-based) after which the largest drop occurs.
    pub largest_gap_rank: usize,
    /// Fraction of the core decay carried by staircase steps.
    pub staircase_fraction: f64,
    /// Total decay of the core (decades).
    pub core_decay: f64,
    /// The verdict.
    pub noisy: bool,
    /// The preset the verdict suggests.
    pub suggested: Preset,
}

/// Sorted log-area profile (3.1) of an open ring; collinear vertices are skipped. Returns the
/// profile and the number of collinear vertices.
pub fn log_area_profile(ring: &[DVec2]) -> Result<(Vec<f64>, usize), ContourError> {
    let n = ring.len();
    if n < 3 {
        return Err(ContourError::DegenerateRing(format!(
            "{n} point(s); a ring needs at least 3"
        )));
    }
    if let Some(k) = ring.iter().position(|p| !p.is_finite()) {
        return Err(ContourError::DegenerateRing(format!(
            "vertex {k} has a non-finite coordinate"
        )));
    }
    let mut areas: Vec<f64> = (0..n)
        .filter_map(|i| {
            let (a, b, c) = (ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]);
            let t = triangle_area(a, b, c);
            (t > 0.0 && sin_angle(a, b, c) > COLLINEAR_SIN).then_some(t)
        })
        .collect();
    let collinear = n - areas.len();
    areas.sort_by(|a, b| b.total_cmp(a));
    let top = areas.first().copied().unwrap_or(1.0);
    Ok((
        areas.iter().map(|&a| (a / top).log10()).collect(),
        collinear,
    ))
}

/// Runs the detector of the module documentation on one ring.
pub fn detect_noise(ring: &[DVec2]) -> Result<NoiseReport, ContourError> {
    let (profile, collinear) = log_area_profile(ring)?;
    let m = profile.len();
    let hi = (0.95 * m as f64).floor() as usize;
    let lo = ((0.05 * m as f64).ceil() as usize).max(1);
    let (mut largest_gap, mut largest_gap_rank) = (0.0, 0);
    for i in 3..hi.min(m) {
        let d = profile[i - 1] - profile[i];
        if d > largest_gap {
            largest_gap = d;
            largest_gap_rank = i;
        }
    }
    let (mut core_decay, mut stepped) = (0.0, 0.0);
    if hi > lo {
        core_decay = profile[lo - 1] - profile[hi - 1];
        let step = STEP_DECADES.max(10.0 * core_decay / (hi - lo) as f64);
        for i in lo..hi {
            let d = profile[i - 1] - profile[i];
            if d >= step {
                stepped += d;
            }
        }
    }
    let staircase_fraction = if core_decay > 0.0 {
        stepped / core_decay
    } else {
        0.0
    };
    let noisy = m >= MIN_VERTICES
        && (largest_gap >= GAP_DECADES
            || (core_decay >= MIN_CORE_DECAY && staircase_fraction >= STAIRCASE_FRACTION));
    Ok(NoiseReport {
        profile,
        collinear,
        largest_gap,
        largest_gap_rank,
        staircase_fraction,
        core_decay,
        noisy,
        suggested: if noisy { Preset::Noisy } else { Preset::Clean },
    })
}

/// Runs the detector on every ring of a region (outer first, then holes). The region verdict
/// is noisy if any ring with at least [`MIN_VERTICES`] vertices is.
// `detect_noise` fails only for rings with fewer than 3 points or non-finite coordinates,
// which `Region` validation has already rejected.
#[allow(clippy::expect_used)]
pub fn detect_noise_region(region: &unamalla_mesh::Region) -> (bool, Vec<NoiseReport>) {
    let reports: Vec<NoiseReport> = region
        .rings()
        .map(|p| detect_noise(p.points()).expect("a validated region has valid rings"))
        .collect();
    (reports.iter().any(|r| r.noisy), reports)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(n: usize, r: f64) -> Vec<DVec2> {
        (0..n)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / n as f64;
                // slightly irregular spacing: a smooth, noise-free curve
                let t = t + 0.3 * (3.0 * t).sin() / n as f64;
                DVec2::new(r * t.cos(), 0.6 * r * t.sin())
            })
            .collect()
    }

    #[test]
    fn smooth_ellipse_is_clean() {
        let rep = detect_noise(&circle(500, 100.0)).unwrap();
        assert!(
            !rep.noisy,
            "{:?}",
            (rep.largest_gap, rep.staircase_fraction)
        );
        assert_eq!(rep.suggested, Preset::Clean);
        assert_eq!(rep.profile[0], 0.0);
        assert!(rep.profile.windows(2).all(|w| w[0] >= w[1]));
    }

    #[test]
    fn digitised_ellipse_is_noisy() {
        // the same ellipse rounded to an integer grid: a digital curve, areas in ½ℤ
        let mut pts: Vec<DVec2> = circle(300, 60.0).iter().map(|p| p.round()).collect();
        pts.dedup();
        if pts.first() == pts.last() {
            pts.pop();
        }
        let rep = detect_noise(&pts).unwrap();
        assert!(rep.noisy, "{:?}", (rep.largest_gap, rep.staircase_fraction));
        assert_eq!(rep.suggested, Preset::Noisy);
    }

    #[test]
    fn jittered_square_has_a_gap() {
        // 4 corners far above a floor of tiny jitter triangles
        let mut pts = Vec::new();
        let mut s = 1u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for side in 0..4 {
            for k in 0..50 {
                let t = k as f64 * 2.0;
                let j = if k == 0 { 0.0 } else { 0.02 * rnd() };
                let p = match side {
                    0 => DVec2::new(t, j),
                    1 => DVec2::new(100.0 + j, t),
                    2 => DVec2::new(100.0 - t, 100.0 + j),
                    _ => DVec2::new(j, 100.0 - t),
                };
                pts.push(p);
            }
        }
        let rep = detect_noise(&pts).unwrap();
        assert!(rep.noisy);
        assert!(rep.largest_gap >= GAP_DECADES);
        assert_eq!(rep.largest_gap_rank, 4);
    }
}
