//! Arc-length reparametrization of polylines ([Méndez 2023, §5.3]).
//!
//! An open polyline γ with vertices v₁..v_s and cumulative arc lengths L₁ = 0 < … < L_s = L is
//! the linear spline β(t) through (L_i, v_i); evaluating β at the uniform partition
//! t_k = (k−1)·L/(m−1), k = 1..m gives m points equidistant in arc length. Both endpoints are
//! reproduced exactly.

use glam::DVec2;

use crate::error::MeshError;

/// Cumulative arc lengths of a polyline: `L[0] = 0`, `L[i] = L[i−1] + |v_i − v_{i−1}|`.
pub fn cumulative_lengths(poly: &[DVec2]) -> Vec<f64> {
    let mut acc = Vec::with_capacity(poly.len());
    let mut s = 0.0;
    for (k, p) in poly.iter().enumerate() {
        if k > 0 {
            s += p.distance(poly[k - 1]);
        }
        acc.push(s);
    }
    acc
}

/// Total length of an open polyline.
pub fn polyline_length(poly: &[DVec2]) -> f64 {
    poly.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// Resamples an open polyline into `k ≥ 2` points equally spaced in arc length; the first and
/// last points are the polyline's endpoints exactly.
///
/// Errors: fewer than 2 input points, `k < 2`, non-finite input, or zero total length.
pub fn resample_arc_length(poly: &[DVec2], k: usize) -> Result<Vec<DVec2>, MeshError> {
    if poly.len() < 2 {
        return Err(MeshError::Degenerate(format!(
            "a polyline needs at least 2 points, got {}",
            poly.len()
        )));
    }
    if k < 2 {
        return Err(MeshError::InvalidSize(format!(
            "resampling needs at least 2 output points, got {k}"
        )));
    }
    if let Some(v) = poly.iter().position(|p| !p.is_finite()) {
        return Err(MeshError::NonFinite { node: v });
    }
    let cum = cumulative_lengths(poly);
    let total = cum[cum.len() - 1];
    if total <= 0.0 {
        return Err(MeshError::Degenerate("polyline has zero length".into()));
    }
    let mut out = Vec::with_capacity(k);
    out.push(poly[0]);
    let mut seg = 0;
    for s in 1..k - 1 {
        let t = total * s as f64 / (k - 1) as f64;
        while seg + 2 < cum.len() && cum[seg + 1] < t {
            seg += 1;
        }
        let len = cum[seg + 1] - cum[seg];
        let u = if len > 0.0 { (t - cum[seg]) / len } else { 0.0 };
        out.push(poly[seg].lerp(poly[seg + 1], u.clamp(0.0, 1.0)));
    }
    out.push(poly[poly.len() - 1]);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn resampling_an_l_path() {
        // path of length 4: (0,0) → (2,0) → (2,2); 5 points every 1.0
        let p = [DVec2::new(0., 0.), DVec2::new(2., 0.), DVec2::new(2., 2.)];
        let r = resample_arc_length(&p, 5).unwrap();
        let expect = [(0., 0.), (1., 0.), (2., 0.), (2., 1.), (2., 2.)];
        for (a, (x, y)) in r.iter().zip(expect) {
            assert!(a.distance(DVec2::new(x, y)) < 1e-12, "{a}");
        }
    }

    #[test]
    fn errors() {
        assert!(resample_arc_length(&[DVec2::ZERO], 3).is_err());
        assert!(resample_arc_length(&[DVec2::ZERO, DVec2::ZERO], 3).is_err());
        assert!(resample_arc_length(&[DVec2::ZERO, DVec2::ONE], 1).is_err());
        assert!(resample_arc_length(&[DVec2::ZERO, DVec2::NAN], 3).is_err());
    }

    proptest! {
        #[test]
        fn resampled_points_are_equidistant_on_a_straight_line(
            ts in prop::collection::vec(0.0f64..1.0, 1..20), k in 2usize..40
        ) {
            // random vertices along a straight segment: arc length = coordinate
            let mut s = ts.clone();
            s.push(0.0);
            s.push(1.0);
            s.sort_by(f64::total_cmp);
            s.dedup();
            let poly: Vec<DVec2> = s.iter().map(|&t| DVec2::new(3.0 * t, -t)).collect();
            let r = resample_arc_length(&poly, k).unwrap();
            prop_assert_eq!(r.len(), k);
            prop_assert_eq!(r[0], poly[0]);
            prop_assert_eq!(r[k - 1], poly[poly.len() - 1]);
            for (i, p) in r.iter().enumerate() {
                let t = i as f64 / (k - 1) as f64;
                prop_assert!(p.distance(DVec2::new(3.0 * t, -t)) < 1e-12);
            }
        }
    }
}
