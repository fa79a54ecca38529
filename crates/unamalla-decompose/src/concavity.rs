//! Concavity measures κ₁–κ₄, bridges and pockets, critical angles and the admissible-region
//! test ([Méndez 2023, §4.1, §4.4]).
//!
//! For a simple counter-clockwise ring Ω with convex hull 𝒞:
//!
//! * κ₁(Ω) = (perimeter(Ω) − perimeter(𝒞)) / perimeter(Ω)  (thesis (4.1)/(4.2));
//! * κ₂(Ω) = (area(𝒞) − area(Ω)) / area(𝒞)  (4.3);
//! * a **bridge** β is a hull edge that is not a polygon edge, its **pocket** ρ the chain of
//!   polygon vertices strictly between the bridge's endpoints;
//! * κ₃(p) = distance from p to its bridge segment, with Ω rescaled so that its circumscribing
//!   circle has radius 1 — we use the radius R = diam(𝒞)/2 (half the hull diameter; the exact
//!   minimal enclosing circle lies between diam/2 and diam/√3, and the thesis does not say which it uses);
//! * κ₄(p) = arc length along the pocket from p to the nearer bridge endpoint, divided by
//!   perimeter(Ω) (Ω rescaled to perimeter 1);
//! * κᵢ(β) = max over the pocket, κᵢ(Ω) = max over bridges (0 for a convex ring).
//!
//! Criteria (4.4)–(4.7): κᵢ(Ω) ≤ τᵢ⁻. Defaults (thesis Obs 4.8): τ₁⁺ = 0.5, τ₁⁻ = 0.1,
//! τ₂⁻ = 0.45, τ₃⁻ = 0.1. A **critical angle** is an interior angle below θ₋ = 40°.
//!
//! **Spike criterion** (beyond the thesis): a piece is approximately convex only if no interior
//! angle exceeds θ₊ (default 350°). κ₁–κ₄ are area and distance measures, so a needle that
//! points into the piece — the tip of a sliver island, the end of a one-vertex-wide spit of
//! the complement — hardly changes them, yet a structured grid cannot pass such a tip inside a
//! block side: the tip would be a side node shared by two cells of angle α/2 ≈ 179° each (issue
//! #8, gulf-of-mexico). With the criterion the concavity cut starts at the tip and the cut
//! along its bisector leaves two angles of α/2 ≤ 180° that are side nodes of two blocks, i.e.
//! four cells meet at the tip.

use serde::{Deserialize, Serialize};
use unamalla_mesh::geometry::point_segment_distance;
use unamalla_mesh::DVec2;

use crate::geom::{convex_hull, diameter, perimeter, ring_angle, ring_angles, signed_area};

/// Tolerances of the concavity criteria and the critical angle (thesis Obs 4.8, §4.1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Tolerances {
    /// τ₁⁺: a region with κ₁ above it is "highly concave" (default 0.5; informative only).
    pub tau1_plus: f64,
    /// τ₁⁻: criterion 1, κ₁ ≤ τ₁⁻ (default 0.1). `None`-like behaviour: set to `f64::INFINITY`.
    pub tau1_minus: f64,
    /// τ₂⁻: criterion 2, κ₂ ≤ τ₂⁻ (default 0.45).
    pub tau2_minus: f64,
    /// τ₃⁻: criterion 3, κ₃ ≤ τ₃⁻ (default 0.1).
    pub tau3_minus: f64,
    /// τ₄⁻: criterion 4, κ₄ ≤ τ₄⁻ (the thesis gives no default; default `+∞` = not used).
    pub tau4_minus: f64,
    /// θ₋ in radians: interior angles below it are critical (default 40°).
    pub theta_minus: f64,
    /// θ₊ in radians: a piece with an interior angle above it (a needle tip pointing into the
    /// piece) is not approximately convex (default 350°; beyond the thesis, see the module
    /// documentation). Files written before this field existed read the default.
    #[serde(default = "default_theta_plus")]
    pub theta_plus: f64,
}

fn default_theta_plus() -> f64 {
    350f64.to_radians()
}

impl Default for Tolerances {
    fn default() -> Self {
        Self {
            tau1_plus: 0.5,
            tau1_minus: 0.1,
            tau2_minus: 0.45,
            tau3_minus: 0.1,
            tau4_minus: f64::INFINITY,
            theta_minus: 40f64.to_radians(),
            theta_plus: default_theta_plus(),
        }
    }
}

/// One bridge of the convex hull and its pocket.
#[derive(Debug, Clone, PartialEq)]
pub struct Pocket {
    /// Ring indices of the bridge endpoints (hull vertices), in ring order.
    pub bridge: (usize, usize),
    /// Ring indices strictly between the bridge endpoints (the pocket's vertices).
    pub vertices: Vec<usize>,
    /// κ₃(β): largest scaled distance of a pocket vertex to the bridge.
    pub kappa3: f64,
    /// κ₄(β): largest scaled arc distance of a pocket vertex to the bridge.
    pub kappa4: f64,
}

/// All concavity measures of a simple counter-clockwise ring.
#[derive(Debug, Clone, PartialEq)]
pub struct Concavity {
    /// κ₁ (perimeter based).
    pub kappa1: f64,
    /// κ₂ (area based).
    pub kappa2: f64,
    /// κ₃(Ω) = max over pockets.
    pub kappa3: f64,
    /// κ₄(Ω) = max over pockets.
    pub kappa4: f64,
    /// The pockets (one per bridge).
    pub pockets: Vec<Pocket>,
    /// κ₃(p) for every ring vertex (0 on the hull).
    pub point_kappa3: Vec<f64>,
    /// κ₄(p) for every ring vertex (0 on the hull).
    pub point_kappa4: Vec<f64>,
    /// The largest interior angle of the ring, in radians (compared with θ₊).
    pub max_angle: f64,
}

/// Computes κ₁–κ₄, the pockets and the point concavities of a simple counter-clockwise ring
/// (stored open). O(n log n + h²) with h the number of hull vertices.
pub fn concavity(ring: &[DVec2]) -> Concavity {
    if ring.len() < 3 {
        return concavity_with_angles(ring, &[]);
    }
    concavity_with_angles(ring, &ring_angles(ring))
}

/// [`concavity`] with the ring's vertex angles given (`angles[i]` = `ring_angle(ring, i)`,
/// [`ring_angles`]; ignored for fewer than three vertices). The same result bit for bit: the
/// largest angle is folded over the same values in the same order.
pub(crate) fn concavity_with_angles(ring: &[DVec2], angles: &[f64]) -> Concavity {
    concavity_with_hull(ring, angles, convex_hull(ring))
}

/// [`concavity_with_angles`] with the ring's convex hull given: `hull` holds the indices
/// that `convex_hull(ring)` returns, in their cyclic order, from any of them on (the
/// measures start it at its smallest index).
pub(crate) fn concavity_with_hull(ring: &[DVec2], angles: &[f64], hull: Vec<usize>) -> Concavity {
    let n = ring.len();
    let mut point_kappa3 = vec![0.0; n];
    let mut point_kappa4 = vec![0.0; n];
    let mut pockets = Vec::new();
    let m = measure(
        ring,
        angles,
        hull,
        |i, d3, d4| {
            point_kappa3[i] = d3;
            point_kappa4[i] = d4;
        },
        |(u, v), gap, kappa3, kappa4| {
            pockets.push(Pocket {
                bridge: (u, v),
                vertices: (1..gap).map(|s| (u + s) % n).collect(),
                kappa3,
                kappa4,
            })
        },
    );
    Concavity {
        kappa1: m.kappa1,
        kappa2: m.kappa2,
        kappa3: m.kappa3,
        kappa4: m.kappa4,
        pockets,
        point_kappa3,
        point_kappa4,
        max_angle: m.max_angle,
    }
}

/// The measures of a [`Concavity`] that approximate convexity reads (κ₁–κ₄ and the largest
/// angle), without its pockets and point measures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Measures {
    pub kappa1: f64,
    pub kappa2: f64,
    pub kappa3: f64,
    pub kappa4: f64,
    pub max_angle: f64,
}

impl Measures {
    /// [`Concavity::approximately_convex`] of these measures.
    pub(crate) fn approximately_convex(&self, tol: &Tolerances) -> bool {
        self.max_angle <= tol.theta_plus
            && self.kappa1 <= tol.tau1_minus
            && self.kappa2 <= tol.tau2_minus
            && self.kappa3 <= tol.tau3_minus
            && self.kappa4 <= tol.tau4_minus
    }
}

/// The [`Measures`] of [`concavity`] (the same computation).
pub(crate) fn measures(ring: &[DVec2]) -> Measures {
    if ring.len() < 3 {
        return measures_with_angles(ring, &[]);
    }
    measures_with_angles(ring, &ring_angles(ring))
}

/// The [`Measures`] of [`concavity_with_angles`] (the same computation).
pub(crate) fn measures_with_angles(ring: &[DVec2], angles: &[f64]) -> Measures {
    measures_with_hull(ring, angles, convex_hull(ring))
}

/// The [`Measures`] of [`concavity_with_hull`] (the same computation: both call [`measure`]).
pub(crate) fn measures_with_hull(ring: &[DVec2], angles: &[f64], hull: Vec<usize>) -> Measures {
    measure(ring, angles, hull, |_, _, _| {}, |_, _, _, _| {})
}

/// The computation of [`concavity_with_hull`]: the measures, with `point(i, κ₃(i), κ₄(i))`
/// called for every pocket vertex and `pocket(bridge, gap, κ₃(β), κ₄(β))` for every pocket
/// (`gap`: ring steps from one bridge end to the other).
fn measure(
    ring: &[DVec2],
    angles: &[f64],
    hull: Vec<usize>,
    mut point: impl FnMut(usize, f64, f64),
    mut pocket: impl FnMut((usize, usize), usize, f64, f64),
) -> Measures {
    let n = ring.len();
    let max_angle = if n < 3 {
        0.0
    } else {
        debug_assert_eq!(angles.len(), n);
        angles.iter().copied().fold(0.0, f64::max)
    };
    let mut hull = hull;
    if n < 3 || hull.len() < 3 {
        return Measures {
            kappa1: 0.0,
            kappa2: 0.0,
            kappa3: 0.0,
            kappa4: 0.0,
            max_angle,
        };
    }
    // hull in ring order: rotate so it starts at its smallest ring index (the hull of a simple
    // CCW ring visits its vertices in ring order)
    let start = (0..hull.len()).min_by_key(|&k| hull[k]).unwrap_or(0);
    hull.rotate_left(start);
    let hull_pts: Vec<DVec2> = hull.iter().map(|&i| ring[i]).collect();
    let per = perimeter(ring);
    let hull_per = perimeter(&hull_pts);
    let area = signed_area(ring).abs();
    let hull_area = signed_area(&hull_pts).abs();
    let kappa1 = if per > 0.0 {
        ((per - hull_per) / per).max(0.0)
    } else {
        0.0
    };
    let kappa2 = if hull_area > 0.0 {
        ((hull_area - area) / hull_area).max(0.0)
    } else {
        0.0
    };
    let radius = 0.5 * diameter(ring, &hull);
    // the largest pocket measures, folded from 0 over the pockets in order
    let (mut kappa3, mut kappa4) = (0.0f64, 0.0f64);
    let mut steps: Vec<f64> = Vec::new();
    let h = hull.len();
    for k in 0..h {
        let u = hull[k];
        let v = hull[(k + 1) % h];
        let gap = (v + n - u) % n;
        if gap <= 1 {
            continue;
        }
        let a = ring[u];
        let b = ring[v];
        // the pocket's edge lengths from u, and its arc length summed edge by edge (for the
        // total, then again, the same sums, up to each vertex)
        steps.clear();
        let mut i = u;
        for _ in 0..gap {
            let next = if i + 1 == n { 0 } else { i + 1 };
            steps.push(ring[i].distance(ring[next]));
            i = next;
        }
        let total = steps.iter().fold(0.0, |acc, &d| acc + d);
        let (mut k3, mut k4) = (0.0f64, 0.0f64);
        let mut along = 0.0;
        for s in 1..gap {
            let i = (u + s) % n;
            along += steps[s - 1];
            let d3 = if radius > 0.0 {
                point_segment_distance(ring[i], a, b) / radius
            } else {
                0.0
            };
            let d4 = if per > 0.0 {
                along.min(total - along) / per
            } else {
                0.0
            };
            point(i, d3, d4);
            k3 = k3.max(d3);
            k4 = k4.max(d4);
        }
        pocket((u, v), gap, k3, k4);
        kappa3 = kappa3.max(k3);
        kappa4 = kappa4.max(k4);
    }
    Measures {
        kappa1,
        kappa2,
        kappa3,
        kappa4,
        max_angle,
    }
}

/// κ₁ of a ring (see [`concavity`]).
pub fn kappa1(ring: &[DVec2]) -> f64 {
    concavity(ring).kappa1
}

/// κ₂ of a ring (see [`concavity`]).
pub fn kappa2(ring: &[DVec2]) -> f64 {
    concavity(ring).kappa2
}

/// Indices of the vertices whose interior (left) angle is below `theta_minus` (radians).
pub fn critical_angles(ring: &[DVec2], theta_minus: f64) -> Vec<usize> {
    (0..ring.len())
        .filter(|&i| ring_angle(ring, i) < theta_minus)
        .collect()
}

impl Concavity {
    /// `true` if every concavity criterion 1–4 holds with the given tolerances and no interior
    /// angle exceeds θ₊ (the region is "approximately convex"; the θ₊ spike criterion is beyond
    /// the thesis, see the module documentation).
    pub fn approximately_convex(&self, tol: &Tolerances) -> bool {
        self.max_angle <= tol.theta_plus
            && self.kappa1 <= tol.tau1_minus
            && self.kappa2 <= tol.tau2_minus
            && self.kappa3 <= tol.tau3_minus
            && self.kappa4 <= tol.tau4_minus
    }
    /// `true` if κ₁ > τ₁⁺ ("highly concave").
    pub fn highly_concave(&self, tol: &Tolerances) -> bool {
        self.kappa1 > tol.tau1_plus
    }
}

/// The admissible-region test (thesis §4.1) for a hole-free region given by its simple
/// counter-clockwise boundary: approximately convex (criteria 1–4) and no acute critical angle.
/// (Noise-freeness is the simplifier's job and is not tested here.) Triangles are admissible
/// blocks even with critical angles: they are the leaves Algorithm 4 produces.
pub fn is_admissible(ring: &[DVec2], tol: &Tolerances) -> bool {
    let c = concavity(ring);
    c.approximately_convex(tol)
        && (ring.len() == 3 || critical_angles(ring, tol.theta_minus).is_empty())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn l_shape_measures() {
        // L: 2x2 square minus the unit square at the top right
        let ring = vec![
            v(0., 0.),
            v(2., 0.),
            v(2., 1.),
            v(1., 1.),
            v(1., 2.),
            v(0., 2.),
        ];
        let c = concavity(&ring);
        // hull: (0,0),(2,0),(2,1),(1,2),(0,2): perimeter 2+1+√2+1+2
        let hp = 6.0 + 2f64.sqrt();
        assert!((c.kappa1 - (8.0 - hp) / 8.0).abs() < 1e-12);
        // hull area 4 − 0.5 = 3.5, area 3
        assert!((c.kappa2 - 0.5 / 3.5).abs() < 1e-12);
        assert_eq!(c.pockets.len(), 1);
        assert_eq!(c.pockets[0].vertices, vec![3]);
        // distance of (1,1) to the bridge (2,1)-(1,2) is √2/2; R = diam/2 = √8/2 = √2
        assert!((c.kappa3 - 0.5).abs() < 1e-12);
        // arc from (1,1) to either bridge end is 1, perimeter 8
        assert!((c.kappa4 - 1.0 / 8.0).abs() < 1e-12);
        assert!(!c.approximately_convex(&Tolerances::default()));
    }

    #[test]
    fn convex_is_zero() {
        let ring = vec![v(0., 0.), v(3., 0.), v(3., 1.), v(0., 1.)];
        let c = concavity(&ring);
        assert_eq!(
            (c.kappa1, c.kappa2, c.kappa3, c.kappa4),
            (0.0, 0.0, 0.0, 0.0)
        );
        assert!(is_admissible(&ring, &Tolerances::default()));
    }

    /// `measures` gives `concavity`'s numbers bit for bit (pseudo-random star-shaped rings,
    /// deep pockets included).
    #[test]
    fn measures_are_the_concavity_numbers() {
        let mut state = 0xfeed_0123_4567_89abu64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..300 {
            let n = 3 + (next() * 60.0) as usize;
            let ring: Vec<DVec2> = (0..n)
                .map(|i| {
                    let t = std::f64::consts::TAU * (i as f64 + 0.5 * next()) / n as f64;
                    let r = 0.2 + next();
                    v(r * t.cos(), r * t.sin())
                })
                .collect();
            let c = concavity(&ring);
            let m = measures(&ring);
            let bits = |x: [f64; 5]| x.map(f64::to_bits);
            assert_eq!(
                bits([m.kappa1, m.kappa2, m.kappa3, m.kappa4, m.max_angle]),
                bits([c.kappa1, c.kappa2, c.kappa3, c.kappa4, c.max_angle])
            );
        }
    }

    #[test]
    fn critical_angle_detection() {
        // 20° tip at the origin
        let t = 20f64.to_radians();
        let ring = vec![v(0., 0.), v(1., 0.), v(t.cos(), t.sin())];
        assert_eq!(critical_angles(&ring, 40f64.to_radians()), vec![0]);
    }
}
