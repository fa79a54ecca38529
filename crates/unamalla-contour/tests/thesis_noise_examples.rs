//! The noise detector against the thesis's own noisy / clean examples (Méndez 2023,
//! *Parametrización de regiones poligonales complicadas*, §3.2.1 Fig 3.13, §3.2.2 Example 3.4
//! and Figs 3.14–3.17), rebuilt from their descriptions: the images (MPEG-7 shapes `fork10`,
//! `ray10`) are not in the text, so the shapes below are our own outlines with the properties
//! the text states.
//!
//! * **Fork10** (Fig 3.13): two contours of a fork, both with 656 vertices, (a) noisy and
//!   (c) clean; the sorted log-area plot of (a) has large jumps, that of (c) decays gradually.
//!   Rebuilt: a fork outline (handle, four tines with rounded tips) sampled at 656 points by arc
//!   length, (c) as real coordinates, (a) as a *digital curve* — integer coordinates, the
//!   thesis's definition in §3.3.4 — at the size of an MPEG-7 image (≈ 250 px).
//! * **ray10** (Example 3.4): a digital curve of a manta ray (wide wings, long thin tail) whose
//!   area plot is a staircase (noisy); its minimum-perimeter polygon with δ = 3·10⁻⁴ has "the
//!   same number of points" and a plot that "is no longer a staircase" (clean); with
//!   δ = 5·10⁻⁵ "noise remains"; with δ = 10⁻³ the noise is gone (and the shape too).

use std::f64::consts::{PI, TAU};

use unamalla_contour::{detect_noise, minimum_perimeter_polygon, MppOptions};
use unamalla_mesh::DVec2;

/// Points every `step` along a closed polyline (arc length), `n` of them.
fn resample(poly: &[DVec2], n: usize) -> Vec<DVec2> {
    let m = poly.len();
    let seg: Vec<f64> = (0..m)
        .map(|i| poly[i].distance(poly[(i + 1) % m]))
        .collect();
    let total: f64 = seg.iter().sum();
    let mut out = Vec::with_capacity(n);
    let (mut i, mut acc) = (0usize, 0.0);
    for k in 0..n {
        let s = total * k as f64 / n as f64;
        while acc + seg[i] < s {
            acc += seg[i];
            i += 1;
        }
        let t = (s - acc) / seg[i];
        out.push(poly[i].lerp(poly[(i + 1) % m], t));
    }
    out
}

/// A fork outline (counter-clockwise), ≈ 60 × 240 units: a handle, a head and four tines with
/// semicircular tips, as a dense polyline.
fn fork_outline() -> Vec<DVec2> {
    let mut p = Vec::new();
    let arc = |p: &mut Vec<DVec2>, c: DVec2, r: f64, a0: f64, a1: f64| {
        for k in 0..=24 {
            let a = a0 + (a1 - a0) * k as f64 / 24.0;
            p.push(c + r * DVec2::new(a.cos(), a.sin()));
        }
    };
    // handle bottom (rounded end), up the right side
    arc(&mut p, DVec2::new(30.0, 10.0), 8.0, PI, TAU);
    p.push(DVec2::new(38.0, 140.0));
    // head widens to the right
    p.push(DVec2::new(58.0, 165.0));
    // four tines, 8 wide, gaps 6.67 wide, tips at y = 240, from right to left
    let w = 8.0;
    let gap = (60.0 - 4.0 * w) / 3.0;
    for t in (0..4).rev() {
        let x0 = 2.0 + t as f64 * (w + gap);
        p.push(DVec2::new(x0 + w, 230.0));
        arc(&mut p, DVec2::new(x0 + 0.5 * w, 230.0), 0.5 * w, 0.0, PI);
        if t > 0 {
            // down into the gap (rounded bottom)
            p.push(DVec2::new(x0, 180.0));
            arc(
                &mut p,
                DVec2::new(x0 - 0.5 * gap, 180.0),
                0.5 * gap,
                0.0,
                -PI,
            );
        }
    }
    p.push(DVec2::new(2.0, 165.0));
    p.push(DVec2::new(22.0, 140.0));
    p
}

/// Rounds to the integer grid and drops repeated points: a digital curve.
fn digital(pts: &[DVec2]) -> Vec<DVec2> {
    let mut d: Vec<DVec2> = pts.iter().map(|p| p.round()).collect();
    d.dedup();
    while d.len() > 1 && d.first() == d.last() {
        d.pop();
    }
    d
}

/// A manta ray (counter-clockwise), ≈ 300 × 260 units: wide triangular wings with rounded
/// tips, a head notch and a long thin tail.
fn ray_outline(n: usize) -> Vec<DVec2> {
    (0..n)
        .map(|k| {
            let t = TAU * k as f64 / n as f64;
            // wings: wide in x, a body that is taller at the front
            let wing = 0.35 + 0.65 * t.cos().abs().powf(0.6);
            let mut r = 110.0 * wing;
            // head lobes at the front (t = π/2)
            r += 12.0 * (-(((t - PI / 2.0).abs() - 0.25) / 0.08).powi(2)).exp();
            // the tail at t = 3π/2: a thin spike of length 130
            r += 130.0 * (-((t - 1.5 * PI) / 0.025).powi(2)).exp();
            DVec2::new(150.0 + r * t.cos(), 140.0 + 0.8 * r * t.sin())
        })
        .collect()
}

#[test]
fn fork10_noisy_and_clean_contours_as_in_fig_3_13() {
    // (c): 656 real points along the outline — gradual decay, clean
    let fork = resample(&fork_outline(), 656);
    assert_eq!(fork.len(), 656);
    let clean = detect_noise(&fork).unwrap();
    assert!(
        !clean.noisy,
        "{:?}",
        (clean.largest_gap, clean.staircase_fraction)
    );
    // (a): the same 656 points as a digital curve (integer pixels) — staircase, noisy
    let digital_fork = digital(&fork);
    assert_eq!(digital_fork.len(), 656, "no two samples fall on one pixel");
    let noisy = detect_noise(&digital_fork).unwrap();
    assert!(
        noisy.noisy,
        "{:?}",
        (noisy.largest_gap, noisy.staircase_fraction)
    );
}

#[test]
fn ray10_minimum_perimeter_polygon_keeps_the_point_count_and_flattens_the_staircase() {
    // what the detector agrees with in Example 3.4: the MPP keeps every point, and the
    // staircase share of the profile falls as δ grows (5·10⁻⁵ → 3·10⁻⁴ → 10⁻³)
    let ray = digital(&ray_outline(900));
    let mut fractions = Vec::new();
    for d in [5e-5, 3e-4, 1e-3] {
        let m = minimum_perimeter_polygon(&ray, d, &MppOptions::default()).unwrap();
        assert_eq!(m.points.len(), ray.len());
        fractions.push(detect_noise(&m.points).unwrap().staircase_fraction);
    }
    assert!(
        fractions[0] > fractions[1] && fractions[1] > fractions[2],
        "{fractions:?}"
    );
}

#[test]
fn ray10_verdicts_differ_from_the_thesis() {
    // Documented disagreement (docs/results.md, "Noise detector against the thesis's
    // examples"): the thesis calls the digital ray10 noisy and its MPP at δ = 3·10⁻⁴ clean.
    // Our detector says the opposite on our rebuild: (1) on a digital curve whose vertices are
    // a few pixels apart, 90 % of the turn triangles have the same area ½, so the core of the
    // profile is one level (no decay) and the rule "a single level carries no evidence" calls
    // it clean; (2) the MPP pulls runs of pixels onto straight segments, leaving near-collinear
    // vertices whose areas spread over many decades, so the gap rule (a drop ≥ 1 decade)
    // fires even at δ = 10⁻³, where the thesis says the noise is gone.
    let ray = digital(&ray_outline(900));
    let r0 = detect_noise(&ray).unwrap();
    assert!(
        !r0.noisy && r0.core_decay == 0.0,
        "{:?}",
        (r0.core_decay, r0.noisy)
    );
    for d in [3e-4, 1e-3] {
        let m = minimum_perimeter_polygon(&ray, d, &MppOptions::default()).unwrap();
        let r = detect_noise(&m.points).unwrap();
        assert!(
            r.noisy && r.largest_gap >= 1.0,
            "δ = {d}: {:?}",
            r.largest_gap
        );
    }
}
