//! Behaviour of the simplifiers on constructed regions, with expected values derived
//! independently (closed-form geometry, naive reference implementations, brute-force checks).

use std::collections::HashMap;

use proptest::prelude::*;
use unamalla_contour::{
    detect_noise_region, hausdorff, overlay_svg, simplify_region, subset_hausdorff, ContourError,
    HoleFilter, Method, Preset, SimplifyOptions,
};
use unamalla_mesh::geometry::{locate_in_ring, segments_intersect};
use unamalla_mesh::{DVec2, Location, Region, RingId};

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

/// Square [0, s]² traversed counter-clockwise with `k` points per side (corners included once).
fn dense_square(origin: DVec2, s: f64, k: usize) -> Vec<DVec2> {
    let mut ring = Vec::new();
    let step = s / k as f64;
    for side in 0..4 {
        for i in 0..k {
            let t = i as f64 * step;
            ring.push(
                origin
                    + match side {
                        0 => v(t, 0.0),
                        1 => v(s, t),
                        2 => v(s - t, s),
                        _ => v(0.0, s - t),
                    },
            );
        }
    }
    ring
}

fn opts(method: Method) -> SimplifyOptions {
    SimplifyOptions::new(method, Preset::Clean)
}

#[test]
fn collinear_vertices_are_removed_exactly_by_every_method() {
    // outer: a slanted quadrilateral whose sides carry exactly collinear integer points
    // (direction (7, 3) etc.), hole: an axis-aligned square with collinear points
    let corners = [v(0., 0.), v(700., 300.), v(400., 1000.), v(-300., 700.)];
    let mut outer = Vec::new();
    for k in 0..4 {
        let (a, b) = (corners[k], corners[(k + 1) % 4]);
        for i in 0..100 {
            // (b − a)/100 is an integer vector, so every point is exact and exactly collinear
            outer.push(a + (b - a) / 100.0 * i as f64);
        }
    }
    let hole: Vec<DVec2> = dense_square(v(100., 300.), 200.0, 16)
        .into_iter()
        .rev()
        .collect();
    let region = Region::new(outer, vec![hole]).unwrap();
    let area = region.area();
    for m in Method::ALL {
        let mut o = opts(m);
        if m.moves_points() {
            o.delta = Some(0.0); // the MPP step is the identity: only removal is tested
        }
        let res = simplify_region(&region, &o).unwrap();
        let out = res.region.outer().points().to_vec();
        assert_eq!(out.len(), 4, "{m}: outer {out:?}");
        for c in corners {
            assert!(out.contains(&c), "{m}: corner {c} lost");
        }
        let h = res.region.holes()[0].points();
        assert_eq!(h.len(), 4, "{m}");
        assert!(h.contains(&v(100., 300.)) && h.contains(&v(300., 500.)));
        assert_eq!(res.region.area(), area, "{m}");
        assert_eq!(res.relative_area_change, 0.0);
        // measured at edge midpoints against the new edges: zero up to rounding
        assert!(res.hausdorff < 1e-9, "{m}: {}", res.hausdorff);
        assert_eq!(res.vertices_before, 400 + 64);
        assert_eq!(res.vertices_after, 8);
        assert_eq!(res.rings[1].ring, RingId::Hole(0));
        assert_eq!((res.rings[1].before, res.rings[1].after), (64, 4));
    }
}

/// Jittered square: side 100, 100 points per side, uniform jitter of ±`amp` across the side.
fn noisy_square(amp: f64, seed: u64) -> Vec<DVec2> {
    let mut s = seed;
    let mut rnd = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    dense_square(DVec2::ZERO, 100.0, 100)
        .into_iter()
        .enumerate()
        .map(|(i, p)| {
            if i % 100 == 0 {
                return p; // corners stay
            }
            let j = amp * rnd();
            match i / 100 {
                0 | 2 => p + v(0.0, j),
                _ => p + v(j, 0.0),
            }
        })
        .collect()
}

#[test]
fn noisy_square_comes_back_as_its_four_corners_with_the_noise_preset() {
    for seed in [1u64, 7, 42] {
        let region = Region::new(noisy_square(0.01, seed), vec![]).unwrap();
        // the detector calls it noisy …
        let (noisy, _) = detect_noise_region(&region);
        assert!(noisy);
        // … and the noise preset of the modified three-step method recovers the square
        let mut o = SimplifyOptions::new(Method::ModifiedThreeStep, Preset::Auto);
        let res = simplify_region(&region, &o).unwrap();
        assert_eq!(res.preset, Preset::Noisy);
        assert_eq!((res.epsilon, res.delta), (3.0, Some(1e-4)));
        let out = res.region.outer().points();
        assert_eq!(out.len(), 4, "seed {seed}: {out:?}");
        // MPP may pull each corner inward by at most h = p0·δ per coordinate (p0 < 401)
        let h = 401.0 * 1e-4;
        for c in [v(0., 0.), v(100., 0.), v(100., 100.), v(0., 100.)] {
            let d = out.iter().map(|p| p.distance(c)).fold(f64::MAX, f64::min);
            assert!(
                d <= h * 2f64.sqrt() + 1e-9,
                "seed {seed}: corner {c} at {d}"
            );
        }
        assert!(
            res.relative_area_change.abs() < 5.0 * h / 100.0, // inset by ≤ h, plus the jitter
            "seed {seed}: {} {out:?}",
            res.relative_area_change
        );
        // explicit preset gives the same
        o.preset = Preset::Noisy;
        assert_eq!(
            simplify_region(&region, &o).unwrap().region.outer().len(),
            4
        );
    }
}

#[test]
fn method_names_parse_exactly() {
    for (m, name) in Method::ALL.iter().zip(Method::NAMES) {
        assert_eq!(name.parse::<Method>().unwrap(), *m);
        assert_eq!(m.to_string(), name);
    }
    let err = "douglas-peucker".parse::<Method>().unwrap_err();
    let msg = err.to_string();
    for name in Method::NAMES {
        assert!(msg.contains(name), "{msg}");
    }
    assert!(matches!(err, ContourError::UnknownMethod { .. }));
    assert!("Modified-Areas".parse::<Method>().is_err());
    assert_eq!(SimplifyOptions::default().method, Method::ModifiedAreas);
}

#[test]
fn bad_parameters_are_typed_errors() {
    let region = Region::new(dense_square(DVec2::ZERO, 1.0, 3), vec![]).unwrap();
    for (eps, delta) in [
        (-1.0, None),
        (f64::NAN, None),
        (1.0, Some(-1e-4)),
        (1.0, Some(f64::INFINITY)),
    ] {
        let mut o = opts(Method::ModifiedThreeStep);
        o.epsilon = Some(eps);
        o.delta = delta;
        assert!(matches!(
            simplify_region(&region, &o),
            Err(ContourError::InvalidParameter { .. })
        ));
    }
    let mut o = opts(Method::Areas);
    o.holes = HoleFilter::MinArea(-2.0);
    assert!(simplify_region(&region, &o).is_err());
}

#[test]
fn small_holes_are_dropped_and_reported() {
    let outer = dense_square(DVec2::ZERO, 100.0, 4);
    let big: Vec<DVec2> = dense_square(v(10., 10.), 20.0, 2)
        .into_iter()
        .rev()
        .collect();
    let small: Vec<DVec2> = dense_square(v(60., 60.), 1.0, 1)
        .into_iter()
        .rev()
        .collect();
    let region = Region::new(outer, vec![small, big]).unwrap();
    let mut o = opts(Method::ModifiedAreas);
    o.holes = HoleFilter::MinAreaFraction(1e-3); // 10 area units
    let res = simplify_region(&region, &o).unwrap();
    assert_eq!(res.dropped_holes.len(), 1);
    assert_eq!(res.dropped_holes[0].hole, 0);
    assert_eq!(res.dropped_holes[0].area, 1.0);
    assert_eq!(res.region.holes().len(), 1);
    assert_eq!(res.rings[1].ring, RingId::Hole(1));
    // area grows by the dropped hole: (9600 − 9599) / 9599
    assert!((res.relative_area_change - 1.0 / 9599.0).abs() < 1e-15);
}

/// `HoleFilter::MinWidth`: a hole is dropped when its width (minimum width of its convex hull)
/// is below the width — here a 30 × 0.5 slit (width 0.5, area 15) goes at width 1 although it is
/// larger than the 1 × 1 square (width 1, kept: not below 1) and the 20 × 20 square.
#[test]
fn narrow_holes_are_dropped_by_width_not_area() {
    let outer = dense_square(DVec2::ZERO, 100.0, 4);
    let rev = |r: Vec<DVec2>| r.into_iter().rev().collect::<Vec<_>>();
    let big = rev(dense_square(v(10., 10.), 20.0, 2));
    let unit = rev(dense_square(v(60., 60.), 1.0, 1));
    let slit = vec![v(40., 80.), v(40., 80.5), v(70., 80.5), v(70., 80.)];
    let region = Region::new(outer, vec![big, unit, slit]).unwrap();
    assert_eq!(unamalla_contour::hole_width(&region.holes()[2]), 0.5);
    let mut o = opts(Method::ModifiedAreas);
    o.holes = HoleFilter::MinWidth(1.0);
    let res = simplify_region(&region, &o).unwrap();
    assert_eq!(res.dropped_holes.len(), 1);
    assert_eq!(res.dropped_holes[0].hole, 2);
    assert_eq!(res.dropped_holes[0].area, 15.0);
    assert_eq!(res.region.holes().len(), 2);
    o.holes = HoleFilter::MinWidth(f64::NAN);
    assert!(simplify_region(&region, &o).is_err());
}

/// `hole_width` does not depend on the orientation: a 10 × 0.5 rectangle turned by 45° has a
/// bounding box of side (10 + 0.5)/√2 ≈ 7.42 but width 0.5; a regular octagon of circumradius
/// r has width 2r·cos(22.5°) (between two opposite sides) whatever its turn; a triangle has
/// width 2·area / (longest side) (its smallest height).
#[test]
fn hole_width_is_the_minimum_width_of_the_hull() {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let turn = |p: DVec2| v(s * (p.x - p.y), s * (p.x + p.y));
    let rect: Vec<DVec2> = [v(0., 0.), v(10., 0.), v(10., 0.5), v(0., 0.5)]
        .into_iter()
        .map(turn)
        .collect();
    let w = unamalla_contour::hole_width(&unamalla_mesh::Polygon::new(rect).unwrap());
    assert!((w - 0.5).abs() < 1e-12, "{w}");
    for t0 in [0.0, 0.1, std::f64::consts::FRAC_PI_8] {
        let oct: Vec<DVec2> = (0..8)
            .map(|k| {
                let t = t0 + std::f64::consts::FRAC_PI_4 * k as f64;
                v(2.0 * t.cos(), 2.0 * t.sin())
            })
            .collect();
        let w = unamalla_contour::hole_width(&unamalla_mesh::Polygon::new(oct).unwrap());
        let expected = 4.0 * (std::f64::consts::PI / 8.0).cos();
        assert!((w - expected).abs() < 1e-12, "{w} against {expected}");
    }
    // triangle (0,0), (10,0), (2,3): area 15, longest side 10 → width 3
    let tri = vec![v(0., 0.), v(10., 0.), v(2., 3.)];
    let w = unamalla_contour::hole_width(&unamalla_mesh::Polygon::new(tri).unwrap());
    assert!((w - 3.0).abs() < 1e-12, "{w}");
}

#[test]
fn a_removal_that_would_swallow_a_hole_is_skipped() {
    // outer square with a long shallow bump on top; a hole sits in the bump, above the chord
    let outer = vec![
        v(0., 0.),
        v(100., 0.),
        v(100., 100.),
        v(50., 101.),
        v(0., 100.),
    ];
    let hole = vec![v(49., 100.2), v(50., 100.6), v(51., 100.2)];
    let region = Region::new(outer.clone(), vec![hole]).unwrap();
    for m in Method::ALL {
        let mut o = opts(m);
        o.epsilon = Some(1e9); // would remove everything it is allowed to
        let res = simplify_region(&region, &o).unwrap();
        // (the MPP methods may move the apex by p0·δ ≈ 0.04, not below the hole's top 100.6)
        assert!(
            res.region.outer().points().iter().any(|p| p.y > 100.9),
            "{m} removed the bump apex"
        );
        assert_eq!(res.region.holes().len(), 1);
    }
    // the apex is a flat vertex (ζ ≈ 4 against ᾱ ≈ 4000): ε = 0.01 removes it when no hole
    // is in the way, and keeps it when the hole is
    let alone = Region::new(outer, vec![]).unwrap();
    let mut o = opts(Method::ModifiedAreas);
    o.epsilon = Some(0.01);
    let res = simplify_region(&alone, &o).unwrap();
    assert_eq!(res.region.outer().len(), 4);
    assert!(res.region.outer().points().iter().all(|p| p.y <= 100.0));
    let res = simplify_region(&region, &o).unwrap();
    assert_eq!(res.region.outer().len(), 5);
}

#[test]
fn hausdorff_of_a_bump() {
    let sq = [v(0., 0.), v(10., 0.), v(10., 10.), v(0., 10.)];
    let bumped = [v(0., 0.), v(10., 0.), v(10., 10.), v(5., 11.), v(0., 10.)];
    assert!((hausdorff(&sq, &bumped) - 1.0).abs() < 1e-12);
    assert_eq!(hausdorff(&sq, &sq), 0.0);
}

// ---- Hausdorff distance of a vertex subset (per-edge chain scan) ----

fn seg_dist(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let t = if d.length_squared() > 0.0 {
        ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + t * d)
}

/// Brute force directed distance from the closed polyline `from` to the closed polyline `to`:
/// `k` + 1 evenly spaced samples per edge of `from` (vertices included) against every edge of
/// `to`. A lower bound of the true directed distance, within half a sample spacing of it.
fn brute_directed(from: &[DVec2], to: &[DVec2], k: usize) -> f64 {
    let (n, m) = (from.len(), to.len());
    let mut worst = 0.0f64;
    for i in 0..n {
        let (p, q) = (from[i], from[(i + 1) % n]);
        for s in 0..=k {
            let x = p + (s as f64 / k as f64) * (q - p);
            let d = (0..m)
                .map(|j| seg_dist(x, to[j], to[(j + 1) % m]))
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(d);
        }
    }
    worst
}

#[test]
fn subset_hausdorff_of_a_bump_and_of_a_spike() {
    // bump of height 1 on the top side of a 10-square, removed: H = 1, certified (the apex is
    // nearest to its own edge: 1 < 5 to the sides)
    let bumped = [v(0., 0.), v(10., 0.), v(10., 10.), v(5., 11.), v(0., 10.)];
    let h = subset_hausdorff(&bumped, &[0, 1, 2, 4]).unwrap();
    assert_eq!((h.distance, h.exact), (1.0, true));
    // a spike from the top side down to (5, 2), removed: its own edge is 8 away, the bottom
    // side 2, so the certificate fails and the sampled value (a lower bound of H) is returned;
    // H itself is at most the chain bound 8
    let spike = [
        v(0., 0.),
        v(10., 0.),
        v(10., 10.),
        v(6., 10.),
        v(5., 2.),
        v(4., 10.),
        v(0., 10.),
    ];
    let h = subset_hausdorff(&spike, &[0, 1, 2, 3, 5, 6]).unwrap();
    assert!(!h.exact);
    let out = [
        v(0., 0.),
        v(10., 0.),
        v(10., 10.),
        v(6., 10.),
        v(4., 10.),
        v(0., 10.),
    ];
    assert_eq!(h.distance, hausdorff(&spike, &out));
    assert!(h.distance >= 2.0 && h.distance <= 8.0);
    // nothing removed: 0; bad indices: typed errors
    assert_eq!(
        subset_hausdorff(&bumped, &[0, 1, 2, 3, 4])
            .unwrap()
            .distance,
        0.0
    );
    for bad in [&[][..], &[0, 0, 2][..], &[2, 1][..], &[0, 5][..]] {
        assert!(matches!(
            subset_hausdorff(&bumped, bad),
            Err(ContourError::InvalidIndices(_))
        ));
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, .. ProptestConfig::default() })]

    /// `subset_hausdorff` against brute force on random rings and random kept subsets:
    /// certified values equal the densely sampled distance (both directions) up to rounding;
    /// in every case the sampled distance does not exceed the per-edge chain bound `D`
    /// (the theorem `H ≤ D` in the function's documentation).
    #[test]
    fn subset_hausdorff_matches_brute_force(
        n in 5usize..30,
        u in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0), 30),
        keep in prop::collection::vec(any::<bool>(), 30),
    ) {
        let ring = star(DVec2::ZERO, n, 3.0, 10.0, &u);
        let kept: Vec<usize> = (0..n).filter(|&i| keep[i] || i == 0).collect();
        prop_assume!(kept.len() >= 2);
        let out: Vec<DVec2> = kept.iter().map(|&i| ring[i]).collect();
        let h = subset_hausdorff(&ring, &kept).unwrap();
        // chain bound D, computed directly
        let m = kept.len();
        let mut d_chain = 0.0f64;
        for k in 0..m {
            let (i, j) = (kept[k], if k + 1 < m { kept[k + 1] } else { kept[0] + n });
            for t in i + 1..j {
                d_chain = d_chain.max(seg_dist(ring[t % n], ring[i], ring[j % n]));
            }
        }
        let brute = brute_directed(&ring, &out, 64).max(brute_directed(&out, &ring, 64));
        prop_assert!(brute <= d_chain + 1e-12, "sampled {} above chain bound {}", brute, d_chain);
        if h.exact {
            prop_assert_eq!(h.distance, d_chain);
            prop_assert!((h.distance - brute).abs() <= 1e-12 * (1.0 + brute), "{} vs {}", h.distance, brute);
        } else {
            prop_assert!(h.distance <= brute + 1e-12);
        }
    }
}

#[test]
fn overlay_draws_both_regions() {
    let region = Region::new(dense_square(DVec2::ZERO, 10.0, 5), vec![]).unwrap();
    let res = simplify_region(&region, &opts(Method::Visvalingam)).unwrap();
    let svg = overlay_svg(&region, &res.region);
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains("<path") && svg.contains("<polygon"));
    assert!(svg.contains("original: 20 vertices") && svg.contains("simplified: 4 vertices"));
}

// ---- naive reference implementations (O(n²), recompute everything every step) ----

/// Angle-based ζ = α |sin θ| with the angle from `atan2` (independent of the crate's closed form).
fn zeta_trig(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let alpha = (a - b).perp_dot(c - b).abs();
    let th = (a - b).angle_to(c - b);
    alpha * th.sin().abs()
}

fn area(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    0.5 * (b - a).perp_dot(c - a).abs()
}

/// Removes the vertex of smallest key while `key < threshold()`.
fn naive(
    ring: &[DVec2],
    key: impl Fn(DVec2, DVec2, DVec2) -> f64,
    threshold: impl Fn() -> f64,
) -> Vec<DVec2> {
    let mut p = ring.to_vec();
    while p.len() > 3 {
        let n = p.len();
        let keys: Vec<f64> = (0..n)
            .map(|i| key(p[(i + n - 1) % n], p[i], p[(i + 1) % n]))
            .collect();
        let (j, &kmin) = keys
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .unwrap();
        if kmin.partial_cmp(&threshold()) != Some(std::cmp::Ordering::Less) {
            break;
        }
        p.remove(j);
    }
    p
}

fn sorted(mut p: Vec<DVec2>) -> Vec<(u64, u64)> {
    let mut k: Vec<(u64, u64)> = p
        .drain(..)
        .map(|q| (q.x.to_bits(), q.y.to_bits()))
        .collect();
    k.sort();
    k
}

/// Strictly convex ring: points of an ellipse at random increasing angles (every ear triangle
/// is empty, so topology safety never interferes and the naive algorithm is the reference).
fn convex_ring(seed: u64, n: usize) -> Vec<DVec2> {
    let mut s = seed;
    let mut t = 0.0;
    let mut incs = Vec::new();
    for _ in 0..n {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        incs.push(0.2 + (s >> 11) as f64 / (1u64 << 53) as f64);
    }
    let tot: f64 = incs.iter().sum();
    incs.iter()
        .map(|d| {
            t += d / tot * std::f64::consts::TAU;
            v(30.0 * t.cos(), 17.0 * t.sin())
        })
        .collect()
}

#[test]
fn sequential_methods_match_naive_references_on_convex_rings() {
    for seed in 1..6u64 {
        let ring = convex_ring(seed, 150);
        let region = Region::new(ring.clone(), vec![]).unwrap();
        let n0 = ring.len() as f64;
        let abar = (0..ring.len())
            .map(|i| area(ring[(i + 149) % 150], ring[i], ring[(i + 1) % 150]))
            .sum::<f64>()
            / n0;
        for eps in [0.5, 3.0, 40.0] {
            // modified areas (3.6): ᾱ of the input, fixed
            let mut o = opts(Method::ModifiedAreas);
            o.epsilon = Some(eps);
            let got = simplify_region(&region, &o)
                .unwrap()
                .region
                .outer()
                .points()
                .to_vec();
            let want = naive(&ring, zeta_trig, || eps * abar);
            assert_eq!(
                sorted(got),
                sorted(want),
                "modified areas seed {seed} eps {eps}"
            );
            // modified radii (3.8): ρ = 2rR|sin θ| with r = area/s, R = abc/(4 area)
            let rho = |a: DVec2, b: DVec2, c: DVec2| {
                let (l1, l2, l3) = (a.distance(b), b.distance(c), c.distance(a));
                let ar = area(a, b, c);
                let r = ar / (0.5 * (l1 + l2 + l3));
                let rr = l1 * l2 * l3 / (4.0 * ar);
                2.0 * r * rr * (a - b).angle_to(c - b).sin().abs()
            };
            let mut o = opts(Method::ModifiedRadii);
            o.epsilon = Some(eps);
            let got = simplify_region(&region, &o)
                .unwrap()
                .region
                .outer()
                .points()
                .to_vec();
            let want = naive(&ring, rho, || eps * abar);
            assert_eq!(
                sorted(got),
                sorted(want),
                "modified radii seed {seed} eps {eps}"
            );
            // scaled Visvalingam: plain area against ε · (mean area of the input)
            let e2 = eps / 10.0;
            let mut o = opts(Method::Visvalingam);
            o.epsilon = Some(e2);
            let got = simplify_region(&region, &o)
                .unwrap()
                .region
                .outer()
                .points()
                .to_vec();
            let want = naive(&ring, area, || e2 * abar);
            assert_eq!(
                sorted(got),
                sorted(want),
                "visvalingam seed {seed} eps {e2}"
            );
        }
    }
}

// ---- property tests over random simple regions with holes ----

/// Star-shaped ring around `c`: `n` vertices at increasing angles (gaps < π), radii in
/// `[r_min, r_max]`.
fn star(c: DVec2, n: usize, r_min: f64, r_max: f64, u: &[(f64, f64)]) -> Vec<DVec2> {
    let tot: f64 = u.iter().take(n).map(|x| 1.0 + x.0).sum();
    let mut t = 0.0;
    u.iter()
        .take(n)
        .map(|&(a, b)| {
            t += (1.0 + a) / tot * std::f64::consts::TAU;
            let r = r_min + (r_max - r_min) * b;
            c + r * v(t.cos(), t.sin())
        })
        .collect()
}

fn region_strategy() -> impl Strategy<Value = Region> {
    (
        8usize..160,
        prop::collection::vec((0.0f64..1.0, 0.0f64..1.0), 160),
        0usize..4,
        prop::collection::vec(
            (
                3usize..24,
                prop::collection::vec((0.0f64..1.0, 0.0f64..1.0), 24),
            ),
            3,
        ),
    )
        .prop_map(|(n, u, m, holes)| {
            let outer = star(DVec2::ZERO, n, 40.0, 100.0, &u);
            let hs: Vec<Vec<DVec2>> = holes
                .iter()
                .take(m)
                .enumerate()
                .map(|(k, (nh, uh))| {
                    let a = std::f64::consts::TAU * k as f64 / 3.0;
                    star(25.0 * v(a.cos(), a.sin()), *nh, 2.0, 8.0, uh)
                })
                .collect();
            Region::new(outer, hs).expect("generator builds valid regions")
        })
}

/// Brute force: every ring simple, rings pairwise disjoint, holes inside the outer ring and
/// not inside each other — O(n²) pairwise segment tests, no spatial index.
fn assert_valid_brute_force(r: &Region) {
    let rings: Vec<&[DVec2]> = r.rings().map(|p| p.points()).collect();
    let edges: Vec<(usize, usize, DVec2, DVec2)> = rings
        .iter()
        .enumerate()
        .flat_map(|(k, ring)| {
            let n = ring.len();
            (0..n).map(move |e| (k, e, ring[e], ring[(e + 1) % n]))
        })
        .collect();
    for (i, &(ka, ea, a0, a1)) in edges.iter().enumerate() {
        for &(kb, eb, b0, b1) in &edges[i + 1..] {
            let n = rings[ka].len();
            if ka == kb && (eb == (ea + 1) % n || ea == (eb + 1) % n) {
                continue; // adjacent: share a vertex
            }
            assert!(
                !segments_intersect(a0, a1, b0, b1),
                "ring {ka} edge {ea} meets ring {kb} edge {eb}"
            );
        }
    }
    for h in r.holes() {
        assert_eq!(
            locate_in_ring(r.outer().points(), h.points()[0]),
            Location::Inside
        );
        for g in r.holes() {
            if g != h {
                assert_eq!(locate_in_ring(g.points(), h.points()[0]), Location::Outside);
            }
        }
    }
    assert!(r.outer().signed_area() > 0.0);
    assert!(r.holes().iter().all(|h| h.signed_area() < 0.0));
}

/// `out` is a subsequence (cyclically) of `inp`.
fn assert_subsequence(inp: &[DVec2], out: &[DVec2]) {
    let pos: HashMap<(u64, u64), usize> = inp
        .iter()
        .enumerate()
        .map(|(i, p)| ((p.x.to_bits(), p.y.to_bits()), i))
        .collect();
    let idx: Vec<usize> = out
        .iter()
        .map(|p| {
            *pos.get(&(p.x.to_bits(), p.y.to_bits()))
                .expect("output vertex not in input")
        })
        .collect();
    let descents = (0..idx.len())
        .filter(|&k| idx[(k + 1) % idx.len()] <= idx[k])
        .count();
    assert_eq!(descents, 1, "vertices out of order: {idx:?}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, .. ProptestConfig::default() })]

    #[test]
    fn vertex_removal_methods_keep_valid_regions_and_input_vertex_order(
        region in region_strategy(),
        method in prop::sample::select(vec![
            Method::Visvalingam, Method::Areas, Method::Radii,
            Method::ModifiedAreas, Method::ModifiedRadii,
        ]),
        log_eps in -3.0f64..4.0,
    ) {
        let mut o = opts(method);
        o.epsilon = Some(if matches!(method, Method::Radii) { 10f64.powf(log_eps / 7.0 - 0.5) } else { 10f64.powf(log_eps) });
        let res = simplify_region(&region, &o).unwrap();
        assert_valid_brute_force(&res.region);
        prop_assert_eq!(res.region.holes().len(), region.holes().len());
        for (inp, out) in region.rings().zip(res.region.rings()) {
            prop_assert!(out.len() >= 3 && out.len() <= inp.len());
            assert_subsequence(inp.points(), out.points());
        }
        prop_assert!(res.hausdorff.is_finite());
    }

    #[test]
    fn mpp_methods_keep_valid_regions(
        region in region_strategy(),
        three in any::<bool>(),
        log_delta in -5.0f64..-2.0,
        log_eps in -1.0f64..1.5,
    ) {
        let m = if three { Method::ThreeStep } else { Method::ModifiedThreeStep };
        let mut o = opts(m);
        o.delta = Some(10f64.powf(log_delta));
        o.epsilon = Some(if three { 10f64.powf(log_eps - 3.0) } else { 10f64.powf(log_eps) });
        let res = simplify_region(&region, &o).unwrap();
        assert_valid_brute_force(&res.region);
        prop_assert_eq!(res.region.holes().len(), region.holes().len());
    }
}

#[test]
fn features_below_an_absolute_area_are_removed_and_larger_ones_kept() {
    // Square [0,10]² with a thin spike (width 0.2, height 1) on its bottom side and a hole.
    // ζ = α²/(l₁l₂) (eq. 3.4) of the spike apex (5,1): legs (−0.1,−1), (0.1,−1), α = 0.2,
    // l₁l₂ = 1.01 → ζ ≈ 0.0396 < 0.1, removed; then the two spike feet are collinear with the
    // side (ζ = 0), removed. The square corners have ζ = 10²·1 = 100 and the hole's corners
    // (side 2) ζ = 4: all kept at the threshold 0.1.
    let outer = vec![
        v(0., 0.),
        v(4.9, 0.),
        v(5., 1.),
        v(5.1, 0.),
        v(10., 0.),
        v(10., 10.),
        v(0., 10.),
    ];
    let hole = vec![v(6., 6.), v(6., 8.), v(8., 8.), v(8., 6.)];
    let r = Region::new(outer, vec![hole.clone()]).unwrap();
    let out = unamalla_contour::remove_features_below(&r, 0.1).unwrap();
    assert_eq!(out.outer().len(), 4);
    assert!((out.outer().area() - 100.0).abs() < 1e-12);
    assert_eq!(out.holes().len(), 1);
    assert_eq!(out.holes()[0].len(), 4);
    // below the apex's ζ nothing goes
    let same = unamalla_contour::remove_features_below(&r, 0.03).unwrap();
    assert_eq!(same.outer().len(), 7);
    // a negative or NaN threshold is a typed error
    assert!(unamalla_contour::remove_features_below(&r, f64::NAN).is_err());
    assert!(unamalla_contour::remove_features_below(&r, -1.0).is_err());
}
