//! Steps 1–2: turning angles, the angle rule, the necessary condition and the ILP repair
//! ([Ruiz-Gironés & Sarrate, Fig 3, (1), (4), (6), (7), (8)]).

use std::f64::consts::{FRAC_PI_2, PI};

use unamalla_compat_ilp::{classify_vertices, classify_vertices_to_sum, VertexClassOptions};
use unamalla_mesh::{DVec2, Region};

use super::{kind_of, Classification, EdgeTag, KindCounts, SubmapError, SumMode, VertexInfo};

/// Turning angle `θ = atan2(t_in × t_out, t_in · t_out)` in `[−π, π)` from the incoming to the
/// outgoing tangent (our formula for the paper's tangent angle, Fig 3); exactly antiparallel
/// tangents give `−π` (Reversal), as the paper's range `[−π, π)` implies.
///
/// ```
/// use unamalla_decompose::submap::turning_angle;
/// use unamalla_mesh::DVec2;
/// let left = turning_angle(DVec2::X, DVec2::Y);
/// assert!((left - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
/// assert_eq!(turning_angle(DVec2::X, -DVec2::X), -std::f64::consts::PI);
/// ```
pub fn turning_angle(t_in: DVec2, t_out: DVec2) -> f64 {
    let t = t_in.perp_dot(t_out).atan2(t_in.dot(t_out));
    if t >= PI {
        t - 2.0 * PI
    } else {
        t
    }
}

/// Deviation of an angle from the nearest multiple of `π/2` (radians), `dev(θ)`: our measure of
/// the paper's "best angles" of a virtual edge.
pub(crate) fn right_deviation(theta: f64) -> f64 {
    (theta - FRAC_PI_2 * (theta / FRAC_PI_2).round()).abs()
}

/// The angle-rule label `round(α)` clamped to `−2..=1`.
pub(crate) fn rule_label(alpha: f64) -> i64 {
    (alpha.round() as i64).clamp(-2, 1)
}

/// Turning angles of a closed ring (open storage), vertex by vertex.
pub(crate) fn ring_turnings(pts: &[DVec2]) -> Vec<f64> {
    let n = pts.len();
    (0..n)
        .map(|i| {
            let prev = pts[(i + n - 1) % n];
            let next = pts[(i + 1) % n];
            turning_angle(pts[i] - prev, next - pts[i])
        })
        .collect()
}

/// Largest deviation (degrees) of any vertex turning angle of the region from a multiple of 90°.
pub fn max_right_angle_deviation(region: &Region) -> f64 {
    region
        .rings()
        .flat_map(|r| ring_turnings(r.points()))
        .map(right_deviation)
        .fold(0.0, f64::max)
        .to_degrees()
}

/// The automatic strategy rule: submapping is preferred when **every** vertex turning angle is
/// within `tol_deg` of a multiple of 90° **and** the angle-rule labels already satisfy the
/// per-loop conditions (`Σ α = 4` on the outer ring, `−4` on each hole), i.e. no ILP repair is
/// needed. Regions with curved (finely sampled) or irregular boundaries fail the first test.
pub fn prefers_submap(region: &Region, tol_deg: f64) -> bool {
    if max_right_angle_deviation(region) > tol_deg {
        return false;
    }
    region.rings().enumerate().all(|(r, ring)| {
        let s: i64 = ring_turnings(ring.points())
            .iter()
            .map(|&t| rule_label(t / FRAC_PI_2))
            .sum();
        s == if r == 0 { 4 } else { -4 }
    })
}

/// Classifies every ring vertex by the angle rule and repairs the labels with ILP (6)/(8) when the
/// condition of `mode` fails (the paper's strategy: the angle rule first, the ILP only when (1) or
/// (7) fails).
pub fn classify_region(region: &Region, mode: SumMode) -> Result<Classification, SubmapError> {
    let holes = region.holes().len();
    let mut vertices = Vec::new();
    let mut ring_alphas: Vec<Vec<f64>> = Vec::new();
    for (r, ring) in region.rings().enumerate() {
        let turns = ring_turnings(ring.points());
        let mut alphas = Vec::with_capacity(turns.len());
        for (i, &theta) in turns.iter().enumerate() {
            let alpha = theta / FRAC_PI_2;
            alphas.push(alpha);
            let k = kind_of(rule_label(alpha));
            vertices.push(VertexInfo {
                ring: r,
                index: i,
                point: ring.points()[i],
                theta,
                alpha,
                initial: k,
                kind: k,
            });
        }
        ring_alphas.push(alphas);
    }
    let initial_counts = KindCounts::of(vertices.iter().map(|v| v.initial));
    let ring_sum = |r: usize, vs: &[VertexInfo]| -> i64 {
        vs.iter()
            .filter(|v| v.ring == r)
            .map(|v| label_of(v.kind))
            .sum()
    };
    let mut repaired_rings = Vec::new();
    let mut ilp_cost = 0.0;
    let initial_condition_holds;
    match mode {
        SumMode::PerLoop => {
            let mut ok = true;
            for (r, alphas) in ring_alphas.iter().enumerate() {
                let target = if r == 0 { 4 } else { -4 };
                if ring_sum(r, &vertices) == target {
                    continue;
                }
                ok = false;
                let c = classify_vertices_to_sum(alphas, target, &VertexClassOptions::default())
                    .map_err(|source| SubmapError::Classification {
                        ring: Some(r),
                        source,
                    })?;
                ilp_cost += c.cost;
                repaired_rings.push(r);
                for (v, k) in vertices.iter_mut().filter(|v| v.ring == r).zip(&c.kinds) {
                    v.kind = *k;
                }
            }
            initial_condition_holds = ok;
        }
        SumMode::Global => {
            let total: i64 = vertices.iter().map(|v| label_of(v.kind)).sum();
            initial_condition_holds = total == 4 * (1 - holes as i64);
            if !initial_condition_holds {
                let all: Vec<f64> = vertices.iter().map(|v| v.alpha).collect();
                let opts = VertexClassOptions::default().holes(holes);
                let c = classify_vertices(&all, &opts)
                    .map_err(|source| SubmapError::Classification { ring: None, source })?;
                ilp_cost = c.cost;
                repaired_rings = (0..=holes).collect();
                for (v, k) in vertices.iter_mut().zip(&c.kinds) {
                    v.kind = *k;
                }
            }
        }
    }
    let counts = KindCounts::of(vertices.iter().map(|v| v.kind));
    Ok(Classification {
        vertices,
        holes,
        initial_counts,
        counts,
        initial_condition_holds,
        repaired_rings,
        ilp_cost,
    })
}

/// Integer label of a kind.
pub(crate) fn label_of(k: unamalla_compat_ilp::VertexKind) -> i64 {
    use unamalla_compat_ilp::VertexKind as K;
    match k {
        K::Reversal => -2,
        K::Corner => -1,
        K::Side => 0,
        K::End => 1,
    }
}

/// A point of a (merged) boundary loop before discretization.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LPoint {
    /// Position.
    pub pos: DVec2,
    /// Physical identity (both occurrences of a junction point share it).
    pub key: usize,
    /// Integer label.
    pub label: i64,
    /// Forced edge break (virtual-edge end).
    pub brk: bool,
    /// The edge leaving this point.
    pub tag: EdgeTag,
    /// Junction occurrences get their label from the angle rule after the surgery.
    pub junction: bool,
}

/// The region's rings as labelled point loops (keys 0.. in ring order).
pub(crate) fn labelled_rings(region: &Region, c: &Classification) -> Vec<Vec<LPoint>> {
    let mut out: Vec<Vec<LPoint>> = region.rings().map(|_| Vec::new()).collect();
    for (key, v) in c.vertices.iter().enumerate() {
        out[v.ring].push(LPoint {
            pos: v.point,
            key,
            label: label_of(v.kind),
            brk: false,
            tag: EdgeTag::Boundary(v.ring),
            junction: false,
        });
    }
    out
}
