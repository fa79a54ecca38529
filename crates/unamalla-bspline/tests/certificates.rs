//! Theorems 1 and 2, the Bernstein test and the dense sampler on constructed nets ([Abelló et al.,
//! §1.2–§1.3, §3]): convex nets certify, a net where Theorem 2 fails although the map
//! is injective, a folded net where sampling finds det J ≤ 0; the synthetic regions S1–S5 and the
//! negative tests (reflex corner, self-intersection, orientation).

use glam::DVec2;
use proptest::prelude::*;
use unamalla_bspline::synthetic::{star_literal, uniform_square, Synthetic};
use unamalla_bspline::{
    bernstein_test, optimize_interior, sample_det_j, theorem1, theorem2, BernsteinOutcome,
    BoundaryCurves, BsplineError, ControlNet, Degree, InteriorOptions, TensorMap,
};

/// Uniform grid with a random displacement of the interior points small enough to keep every
/// cell convex (each point moves less than 0.2 of the spacing... checked, not assumed).
fn perturbed(n: usize, m: usize, noise: &[f64], amp: f64) -> ControlNet {
    let mut net = uniform_square(n, m).unwrap();
    let hx = 1.0 / (n - 1) as f64;
    let hy = 1.0 / (m - 1) as f64;
    for j in 1..m - 1 {
        for i in 1..n - 1 {
            let k = 2 * (j * n + i);
            let d = DVec2::new(
                amp * hx * noise[k % noise.len()],
                amp * hy * noise[(k + 1) % noise.len()],
            );
            net.set(i, j, net.get(i, j) + d);
        }
    }
    net
}

/// Brute-force minimum of det J over a grid of parameters with the per-patch partials (an
/// evaluation path independent of the sampler's power-basis Horner scheme).
fn brute_min(map: &TensorMap, k: usize) -> f64 {
    let mut mn = f64::INFINITY;
    for b in 0..k {
        for a in 0..k {
            mn = mn.min(map.det_j(a as f64 / (k - 1) as f64, b as f64 / (k - 1) as f64));
        }
    }
    mn
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// Theorem 1: a convex net gives a bilinear map with det J > 0, bounded below by
    /// (n−1)(m−1)·α₋ (the certified bound); the Bernstein test at depth 0 agrees.
    #[test]
    fn theorem1_convex_net_gives_positive_jacobian(n in 2usize..9, m in 2usize..9, noise in prop::collection::vec(-1.0f64..1.0, 64)) {
        let net = perturbed(n, m, &noise, 0.3);
        let t1 = theorem1(&net);
        prop_assume!(t1.holds);
        let map = TensorMap::new(Degree::Bilinear, net).unwrap();
        let s = sample_det_j(&map, 97, 97).unwrap();
        prop_assert_eq!(s.nonpositive, 0);
        let lb = t1.det_j_lower_bound.unwrap();
        prop_assert!(s.min >= lb - 1e-12, "sampled {} < bound {}", s.min, lb);
        prop_assert!(bernstein_test(&map, 0).certified());
    }

    /// Theorem 2: when all 36 determinants of every patch are positive, sampled det J is
    /// positive and above the certified bound (n−2)(m−2)·min γδD; the Bernstein test then also
    /// certifies (its condition is weaker).
    #[test]
    fn theorem2_positive_determinants_give_positive_jacobian(n in 3usize..9, m in 3usize..9, noise in prop::collection::vec(-1.0f64..1.0, 64)) {
        let net = perturbed(n, m, &noise, 0.15);
        let t2 = theorem2(&net).unwrap();
        prop_assume!(t2.holds);
        let map = TensorMap::new(Degree::Biquadratic, net).unwrap();
        let s = sample_det_j(&map, 97, 97).unwrap();
        let lb = t2.det_j_lower_bound.unwrap();
        prop_assert!(lb > 0.0);
        prop_assert!(s.min >= lb - 1e-12, "sampled {} < bound {}", s.min, lb);
        prop_assert!(bernstein_test(&map, 0).certified());
    }

    /// The Bernstein lower bound never exceeds the sampled minimum, and a refutation's witness
    /// really has det J ≤ 0.
    #[test]
    fn bernstein_bound_is_a_lower_bound(n in 3usize..8, m in 3usize..8, noise in prop::collection::vec(-1.0f64..1.0, 64), amp in 0.1f64..0.9) {
        let net = perturbed(n, m, &noise, amp);
        let map = TensorMap::new(Degree::Biquadratic, net).unwrap();
        let s = sample_det_j(&map, 81, 81).unwrap();
        match bernstein_test(&map, 5).outcome {
            BernsteinOutcome::Certified { lower_bound } => {
                prop_assert!(lower_bound <= s.min + 1e-12);
                prop_assert_eq!(s.nonpositive, 0);
            }
            BernsteinOutcome::Refuted { at, value } => {
                prop_assert!(value <= 0.0);
                prop_assert!(map.det_j(at.0, at.1) <= 1e-12);
            }
            BernsteinOutcome::Inconclusive { .. } => {}
        }
    }
}

/// A net where Theorem 2 fails but the map is injective ([Abelló et al., Observation 2]: (41) is
/// very restrictive): a polar annulus sector, ξ radial (r from 1 to 2), η angular over 240° with 4
/// control points, i.e. 80° per control-polygon step. Every control cell is convex, but an edge
/// h_{r',s} (radial, direction θ_s) and an edge v_{r,s'} two steps away in angle (tangential,
/// direction θ_{s'} + 90°, |θ_s − θ_{s'}| = 160°) have det < 0. The Bernstein test (with
/// subdivision) certifies det J > 0, and dense sampling agrees.
#[test]
fn theorem2_fails_but_the_map_is_injective() {
    let (n, m) = (3, 4);
    let span = 240f64.to_radians();
    let net = ControlNet::from_fn(n, m, |i, j| {
        let r = 1.0 + i as f64 / (n - 1) as f64;
        let t = span * j as f64 / (m - 1) as f64;
        r * DVec2::new(t.cos(), t.sin())
    })
    .unwrap();
    assert!(theorem1(&net).holds, "the control cells are convex");
    let t2 = theorem2(&net).unwrap();
    assert!(!t2.holds);
    assert!(t2.failing_nongeometric > 0);
    assert_eq!(
        t2.failing_geometric, 0,
        "the 16 triangle determinants are positive"
    );
    let map = TensorMap::new(Degree::Biquadratic, net).unwrap();
    let s = sample_det_j(&map, 1001, 1001).unwrap();
    assert_eq!(s.nonpositive, 0);
    assert!(s.min > 0.0);
    assert!((brute_min(&map, 201) - s.min).abs() < 0.05 * s.min.abs() + 1e-9);
    let b = bernstein_test(&map, 8);
    match b.outcome {
        BernsteinOutcome::Certified { lower_bound } => {
            assert!(lower_bound > 0.0 && lower_bound <= s.min);
        }
        other => panic!("expected a certificate, got {other:?}"),
    }
}

/// A folded net: one interior control point pushed across its neighbours. Theorem 1 fails,
/// the sampler finds det J ≤ 0 for both degrees and the Bernstein test refutes positivity with
/// a witness.
#[test]
fn folded_net_is_detected_by_sampling() {
    let mut net = uniform_square(6, 6).unwrap();
    // P_{2,2} (0-based) from (0.4, 0.4) to beyond P_{3,3} = (0.6, 0.6)
    net.set(2, 2, DVec2::new(0.75, 0.72));
    let t1 = theorem1(&net);
    assert!(!t1.holds && t1.nonconvex_cells > 0);
    assert!(!theorem2(&net).unwrap().holds);
    for deg in [Degree::Bilinear, Degree::Biquadratic] {
        let map = TensorMap::new(deg, net.clone()).unwrap();
        let s = sample_det_j(&map, 401, 401).unwrap();
        assert!(s.min <= 0.0, "{deg:?}: sampled min {}", s.min);
        assert!(s.nonpositive > 0);
        assert!(map.det_j(s.argmin.0, s.argmin.1) <= 0.0);
        match bernstein_test(&map, 6).outcome {
            BernsteinOutcome::Refuted { at, value } => {
                assert!(value <= 0.0);
                assert!(map.det_j(at.0, at.1) <= 1e-12);
            }
            other => panic!("{deg:?}: expected a refutation, got {other:?}"),
        }
    }
}

/// The sampler's min/max/argmin equal a brute-force scan over the same points (the fast path
/// uses the power-basis coefficients; the scan uses the Bézier partials).
#[test]
fn sampler_matches_brute_force() {
    let noise: Vec<f64> = (0..64)
        .map(|k| ((k * 37 % 17) as f64 / 8.0) - 1.0)
        .collect();
    let map = TensorMap::new(Degree::Biquadratic, perturbed(7, 5, &noise, 0.6)).unwrap();
    let k = 123;
    let s = sample_det_j(&map, k, k).unwrap();
    let mut mn = (f64::INFINITY, (0.0, 0.0));
    let mut mx = f64::NEG_INFINITY;
    let mut sum = 0.0;
    for b in 0..k {
        for a in 0..k {
            let (xi, eta) = (a as f64 / (k - 1) as f64, b as f64 / (k - 1) as f64);
            let d = map.det_j(xi, eta);
            sum += d;
            if d < mn.0 {
                mn = (d, (xi, eta));
            }
            mx = mx.max(d);
        }
    }
    assert!((s.min - mn.0).abs() < 1e-10 * (1.0 + mn.0.abs()));
    assert!((s.max - mx).abs() < 1e-10 * (1.0 + mx.abs()));
    assert!((s.mean - sum / (k * k) as f64).abs() < 1e-10);
    assert!((map.det_j(s.argmin.0, s.argmin.1) - mn.0).abs() < 1e-10);
    // ∫_U det J = area of the image (injective map): the sample mean approximates the area 1
    // (equal weights including the boundary rows: an O(1/k) quadrature error, about 1 % here)
    assert!((s.mean - 1.0).abs() < 0.02, "mean {}", s.mean);
}

/// The synthetic regions S1–S5 at a small size: the TFI start may fold (S3, S4), the optimized
/// net is ε-convex, Theorem 1 holds for it, the biquadratic map is certified by the Bernstein
/// test and sampling agrees. (The full table at 18/30/35 is the example `synthetic_table`.)
#[test]
fn synthetic_regions_give_certified_maps() {
    for region in Synthetic::ALL {
        let b = region.boundary(14, 14).unwrap();
        let mut net = ControlNet::from_boundary(&b).unwrap();
        let rep = optimize_interior(&mut net, &InteriorOptions::default()).unwrap();
        assert!(rep.convex && rep.eps_convex, "{}: {rep:?}", region.name());
        // the boundary control points are untouched (Lemma 4 assembly)
        assert_eq!(net.boundary_curves(), b, "{}", region.name());
        assert!(theorem1(&net).holds);
        let map = TensorMap::new(Degree::Biquadratic, net).unwrap();
        let s = sample_det_j(&map, 301, 301).unwrap();
        assert!(s.min > 0.0, "{}: min det J {}", region.name(), s.min);
        let bern = bernstein_test(&map, 6);
        assert!(bern.certified(), "{}: {:?}", region.name(), bern.outcome);
    }
}

/// S1: the optimizer leaves the uniform square net (already the minimizer by symmetry: equal
/// square cells) where it is.
#[test]
fn s1_optimizer_keeps_the_uniform_grid() {
    let b = Synthetic::S1Square.boundary(9, 7).unwrap();
    let mut net = ControlNet::from_boundary(&b).unwrap();
    optimize_interior(&mut net, &InteriorOptions::default()).unwrap();
    let u = uniform_square(9, 7).unwrap();
    for (p, q) in net.points().iter().zip(u.points()) {
        assert!((*p - *q).length() < 1e-6, "{p} vs {q}");
    }
}

/// S4 at 18×18: the TFI start is folded; the optimizer unfolds it.
#[test]
fn s4_tfi_start_is_folded_and_gets_unfolded() {
    let b = Synthetic::S4Puzzle.boundary(18, 18).unwrap();
    let mut net = ControlNet::from_boundary(&b).unwrap();
    assert!(net.convexity().nonconvex_cells > 0);
    let rep = optimize_interior(&mut net, &InteriorOptions::default()).unwrap();
    assert!(rep.initial_nonconvex_cells > 0);
    assert!(rep.convex && rep.eps_convex, "{rep:?}");
}

/// Negative tests: a reflex corner (the literal S3 corners), a self-intersecting
/// control polygon, clockwise orientation, corners that do not meet, too few points.
#[test]
fn invalid_boundaries_are_reported() {
    // reflex corner R of the literal star
    match ControlNet::from_boundary(&star_literal(18, 18)) {
        Err(BsplineError::ReflexCorner { corner, .. }) => assert!(corner == 'R' || corner == 'S'),
        other => panic!("expected a reflex corner, got {other:?}"),
    }
    let sq = Synthetic::S1Square.boundary(5, 5).unwrap();
    // clockwise: swap the roles of the sides (mirror x ↦ −x keeps the corner identities)
    let mirror = |v: &Vec<DVec2>| v.iter().map(|p| DVec2::new(-p.x, p.y)).collect::<Vec<_>>();
    let cw = BoundaryCurves {
        south: mirror(&sq.south),
        east: mirror(&sq.east),
        north: mirror(&sq.north),
        west: mirror(&sq.west),
    };
    assert!(matches!(
        ControlNet::from_boundary(&cw),
        Err(BsplineError::Clockwise { .. })
    ));
    // self-intersection: a south point pulled far above the north side
    let mut bad = sq.clone();
    bad.south[2] = DVec2::new(0.5, 1.5);
    assert!(matches!(
        ControlNet::from_boundary(&bad),
        Err(BsplineError::NotSimple(_))
    ));
    // corners that do not meet
    let mut bad = sq.clone();
    bad.east[0] = DVec2::new(1.0, 0.01);
    assert!(matches!(
        ControlNet::from_boundary(&bad),
        Err(BsplineError::CornerMismatch { corner: 'R', .. })
    ));
    // opposite sides with different counts
    let mut bad = sq.clone();
    bad.north.pop();
    assert!(matches!(
        ControlNet::from_boundary(&bad),
        Err(BsplineError::Count { .. })
    ));
    // too few points for a quadratic curve
    assert!(Synthetic::S1Square.boundary(2, 5).is_err());
    // a degree that does not exist
    assert!(Degree::from_degree(3).is_err());
}

/// n = m = 3: a single biquadratic patch (the (34) edge case) is handled by every path.
#[test]
fn single_patch_net() {
    let net = ControlNet::from_fn(3, 3, |i, j| {
        DVec2::new(
            i as f64 + 0.1 * (j * j) as f64,
            j as f64 + 0.05 * (i * j) as f64,
        )
    })
    .unwrap();
    let map = TensorMap::new(Degree::Biquadratic, net).unwrap();
    assert_eq!(map.num_patches(), (1, 1));
    for &(xi, eta) in &[(0.2, 0.3), (0.7, 0.9), (0.5, 0.5)] {
        let a = map.det_j(xi, eta);
        assert!((a - map.det_j_closed_form(xi, eta)).abs() < 1e-12);
        assert!((a - map.det_j_bernstein(xi, eta)).abs() < 1e-12);
    }
    let t2 = theorem2(map.net()).unwrap();
    assert_eq!(t2.patches, 1);
}
