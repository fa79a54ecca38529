//! Triangle measures behind every criterion of [Méndez 2023, §3.3] (§3.3.1–§3.3.4).
//!
//! For a vertex `b` with ring neighbours `a` (previous) and `c` (next) the triangle is
//! `T = (a, b, c)`, with side lengths `ℓ₁ = |b − a|`, `ℓ₂ = |c − b|`, `ℓ₃ = |c − a|`, perimeter
//! `p = ℓ₁ + ℓ₂ + ℓ₃`, doubled signed area `α = det(b − a, c − a)` (computed with the exact-sign
//! predicate, so exactly collinear vertices give exactly `0`) and interior angle `θ` at `b`.
//! Closed forms used (no trigonometry):
//!
//! * `|sin θ| = |α| / (ℓ₁ ℓ₂)`;
//! * weighted area (3.4): `ζ = |α| · |sin θ| = α² / (ℓ₁ ℓ₂)`;
//! * in/circumradius ratio (§3.3.2): `r = |α| / p`, `R = ℓ₁ℓ₂ℓ₃ / (2|α|)`, so
//!   `r / R = 2 α² / (p ℓ₁ ℓ₂ ℓ₃)` ∈ `[0, 1/2]`;
//! * modified radius metric (3.7): `ρ = 2 r R |sin θ| = (ℓ₁ℓ₂ℓ₃ / p) · |α| / (ℓ₁ℓ₂) = ℓ₃ |α| / p`
//!   (the thesis writes `sin(v_i)`; with `|sin θ|` the metric is ≥ 0 at reflex vertices too).

use glam::DVec2;
use unamalla_mesh::geometry::orient2d;

/// `orient2d(a, b, c)` (the value of `robust::orient2d`, which `unamalla_mesh::geometry::orient2d`
/// wraps), with its floating-point filter inlined: `robust` 1.2 first computes
/// `det = (a − c)ₓ(b − c)_y − (a − c)_y(b − c)ₓ` and returns it when
/// `|det| ≥ θ·|detleft + detright|`, θ = 3.3306690621773722e-16 (the filter of Ozaki et al.,
/// BIT 2016, that `robust` uses); only otherwise does it run the adaptive exact stage. The same
/// operations in the same order are repeated here, and the exact predicate is called when the
/// filter is inconclusive, so the result is **bit-identical** to `orient2d` (checked by a
/// property test) — the keys, and so the removal order, do not change — while the common case
/// avoids a non-inlined cross-crate call. Sign exact, like `orient2d`.
#[inline(always)]
pub(crate) fn orient2d_fast(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    const THETA: f64 = 3.3306690621773722e-16;
    let detleft = (a.x - c.x) * (b.y - c.y);
    let detright = (a.y - c.y) * (b.x - c.x);
    let det = detleft - detright;
    let errbound = THETA * (detleft + detright).abs();
    if det >= errbound || -det >= errbound {
        det
    } else {
        orient2d(a, b, c)
    }
}

/// `|α|`, the doubled (unsigned) area of triangle `abc`; exactly `0` iff collinear.
#[inline]
pub fn doubled_area(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    orient2d_fast(a, b, c).abs()
}

/// Area of triangle `abc` (Visvalingam's effective area, §3.1.1).
#[inline]
pub fn triangle_area(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    0.5 * doubled_area(a, b, c)
}

/// `|sin θ|` of the angle at `b` between `ba` and `bc`; `0` if either side is degenerate.
#[inline]
pub fn sin_angle(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let l1l2 = a.distance(b) * c.distance(b);
    if l1l2 > 0.0 {
        (doubled_area(a, b, c) / l1l2).min(1.0)
    } else {
        0.0
    }
}

/// Weighted area ζ = α·|sin θ| (eq. 3.4), α the doubled area and θ the angle at `b`.
#[inline]
pub fn weighted_area(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let al = doubled_area(a, b, c);
    let l1l2 = a.distance(b) * c.distance(b);
    if l1l2 > 0.0 {
        al * al / l1l2
    } else {
        0.0
    }
}

/// Ratio r/R of inradius to circumradius of triangle `abc` (§3.3.2): `1/2` for an
/// equilateral triangle, `0` for a degenerate one.
#[inline]
pub fn radius_ratio(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let (l1, l2, l3) = (a.distance(b), c.distance(b), c.distance(a));
    let den = (l1 + l2 + l3) * l1 * l2 * l3;
    if den > 0.0 {
        let al = doubled_area(a, b, c);
        2.0 * al * al / den
    } else {
        0.0
    }
}

/// Modified radius metric ρ = 2 r R |sin θ| (eq. 3.7) with `2rR = ℓ₁ℓ₂ℓ₃/(ℓ₁+ℓ₂+ℓ₃)`.
#[inline]
pub fn modified_radius(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let (l1, l2, l3) = (a.distance(b), c.distance(b), c.distance(a));
    let p = l1 + l2 + l3;
    if p > 0.0 {
        l3 * doubled_area(a, b, c) / p
    } else {
        0.0
    }
}

/// Mean triangle area ā = (1/n) Σ area(v_{i−1}, v_i, v_{i+1}) over a cyclic ring (the
/// normalisation of (3.3), (3.5), (3.6), (3.8)).
pub fn mean_triangle_area(ring: &[DVec2]) -> f64 {
    let n = ring.len();
    if n < 3 {
        return 0.0;
    }
    let s: f64 = (0..n)
        .map(|i| triangle_area(ring[(i + n - 1) % n], ring[i], ring[(i + 1) % n]))
        .sum();
    s / n as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn equilateral_and_right_triangles() {
        let (a, b, c) = (v(0., 0.), v(0.5, 3f64.sqrt() / 2.), v(1., 0.));
        assert!((radius_ratio(a, b, c) - 0.5).abs() < 1e-12);
        // Carnot: r/R = cos A + cos B + cos C − 1 = 3/2 − 1
        // right isosceles, legs 1: r = (2 − √2)/2, R = √2/2
        let (a, b, c) = (v(1., 0.), v(0., 0.), v(0., 1.));
        let r = (2.0 - 2f64.sqrt()) / 2.0;
        let rr = 2f64.sqrt() / 2.0;
        assert!((radius_ratio(a, b, c) - r / rr).abs() < 1e-12);
        // angle at b is 90°: ζ = α·1 = 1, ρ = 2 r R = 2·r·R
        assert!((weighted_area(a, b, c) - 1.0).abs() < 1e-12);
        assert!((modified_radius(a, b, c) - 2.0 * r * rr).abs() < 1e-12);
        assert!((sin_angle(a, b, c) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn collinear_is_exactly_zero() {
        let (a, b, c) = (v(0.1, 0.1), v(0.2, 0.2), v(0.7, 0.7));
        assert_eq!(weighted_area(a, b, c), 0.0);
        assert_eq!(radius_ratio(a, b, c), 0.0);
        assert_eq!(modified_radius(a, b, c), 0.0);
        assert_eq!(triangle_area(a, b, c), 0.0);
    }

    #[test]
    fn weighted_area_uses_sine_of_the_angle_at_b() {
        // angle 30° at b, sides 2 and 3: α = 2·3·sin30 = 3, ζ = 3·0.5
        let b = v(0., 0.);
        let a = v(2., 0.);
        let t = 30f64.to_radians();
        let c = v(3. * t.cos(), 3. * t.sin());
        assert!((weighted_area(a, b, c) - 1.5).abs() < 1e-12);
        // 2rR = ℓ1ℓ2ℓ3/p
        let l3 = a.distance(c);
        let expect = 2.0 * 3.0 * l3 / (5.0 + l3) * 0.5;
        assert!((modified_radius(a, b, c) - expect).abs() < 1e-12);
    }

    use proptest::prelude::*;

    proptest! {
        /// The inlined filter returns exactly the bits of `orient2d`, also for exactly and
        /// nearly collinear points (where the exact stage decides).
        #[test]
        fn fast_orientation_is_bit_identical(
            ax in -1e3f64..1e3, ay in -1e3f64..1e3, bx in -1e3f64..1e3, by in -1e3f64..1e3,
            t in -2.0f64..3.0, ulps in -3i64..4,
        ) {
            let (a, b) = (v(ax, ay), v(bx, by));
            let p = a + t * (b - a);
            let p = v(f64::from_bits((p.x.to_bits() as i64 + ulps) as u64), p.y);
            for (x, y, z) in [(a, b, p), (b, p, a), (p, a, b), (a, a, p)] {
                prop_assert_eq!(orient2d_fast(x, y, z).to_bits(), orient2d(x, y, z).to_bits());
            }
        }
    }
}
