//! Property tests derived from the lemmas of [Abelló et al., §1.1–§1.3, §2.1]:
//! Cox–de Boor basics, (33) vs (34), Lemma 1, Lemma 2, Lemma 4, the corrected Prop 1, Prop 2 (39)
//! and every derivative path against finite differences, the α = γδ table (40), the S1 exact
//! checks.

use glam::DVec2;
use proptest::prelude::*;
use unamalla_bspline::synthetic::{greville_square, uniform_square};
use unamalla_bspline::{BSplineCurve, ControlNet, Degree, KnotVector, TensorMap};

/// A random net: the uniform grid of `[0,n−1]×[0,m−1]` scaled to the unit square plus noise.
fn noisy_net(n: usize, m: usize, noise: &[f64], amp: f64) -> ControlNet {
    ControlNet::from_fn(n, m, |i, j| {
        let k = 2 * (j * n + i);
        DVec2::new(
            i as f64 / (n - 1) as f64 + amp * noise[k % noise.len()],
            j as f64 / (m - 1) as f64 + amp * noise[(k + 1) % noise.len()],
        )
    })
    .unwrap()
}

fn noise_strategy() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(-1.0f64..1.0, 64)
}

/// Central finite differences of `x(ξ,η)` (step `h`, kept inside `[0,1]`).
fn fd_partials(map: &TensorMap, xi: f64, eta: f64, h: f64) -> (DVec2, DVec2) {
    let (a0, a1) = ((xi - h).max(0.0), (xi + h).min(1.0));
    let (b0, b1) = ((eta - h).max(0.0), (eta + h).min(1.0));
    (
        (map.eval_cox_de_boor(a1, eta) - map.eval_cox_de_boor(a0, eta)) / (a1 - a0),
        (map.eval_cox_de_boor(xi, b1) - map.eval_cox_de_boor(xi, b0)) / (b1 - b0),
    )
}

/// A parameter strictly inside a patch (finite differences do not straddle a breakpoint,
/// where the partials are only C⁰/C¹).
fn inside(map: &TensorMap, t: f64, along_xi: bool) -> f64 {
    let k = if along_xi {
        map.knots_xi()
    } else {
        map.knots_eta()
    };
    let bp = k.breakpoints();
    let s = bp.len() - 1;
    let piece = ((t * s as f64) as usize).min(s - 1);
    let (a, b) = (bp[piece], bp[piece + 1]);
    a + (b - a) * (0.2 + 0.6 * t.fract().max(0.0))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Partition of unity and non-negativity of B^k_i on clamped uniform knots; the fast
    /// triangular scheme equals the literal recursion; its derivatives equal (33).
    #[test]
    fn cox_de_boor_basics(order in 1usize..5, extra in 0usize..6, t in 0.0f64..=1.0) {
        let n = order + extra;
        let k = KnotVector::clamped_uniform(order, n).unwrap();
        let mut sum = 0.0;
        for i in 0..n {
            let b = k.basis(i, t);
            prop_assert!(b >= -1e-15);
            sum += b;
        }
        prop_assert!((sum - 1.0).abs() < 1e-12, "Σ B = {sum}");
        let mut b = [0.0; 16];
        let mut d = [0.0; 16];
        let mu = k.nonzero_basis(t, &mut b, Some(&mut d));
        for s in 0..order {
            let i = mu + 1 - order + s;
            prop_assert!((b[s] - k.basis(i, t)).abs() < 1e-12);
            prop_assert!((d[s] - k.basis_derivative(i, t)).abs() < 1e-9 * (1.0 + d[s].abs()));
        }
    }

    /// (33) against central finite differences of the basis (inside a knot span).
    #[test]
    fn basis_derivative_matches_finite_differences(order in 2usize..5, extra in 0usize..6, u in 0.05f64..0.95) {
        let n = order + extra;
        let k = KnotVector::clamped_uniform(order, n).unwrap();
        let bp = k.breakpoints();
        let piece = ((u * (bp.len() - 1) as f64) as usize).min(bp.len() - 2);
        let t = bp[piece] + (bp[piece + 1] - bp[piece]) * (0.25 + 0.5 * u);
        let h = 1e-6;
        for i in 0..n {
            let fd = (k.basis(i, t + h) - k.basis(i, t - h)) / (2.0 * h);
            prop_assert!((fd - k.basis_derivative(i, t)).abs() < 1e-6 * (1.0 + fd.abs()));
        }
    }

    /// Lemma 1 (7)–(9): the bilinear map interpolates the net and is linear along its edges.
    #[test]
    fn lemma1_bilinear_interpolates_the_net(n in 2usize..8, m in 2usize..8, noise in noise_strategy(), a in 0.0f64..=1.0) {
        let net = noisy_net(n, m, &noise, 0.2);
        let map = TensorMap::new(Degree::Bilinear, net.clone()).unwrap();
        let xi = |i: usize| i as f64 / (n - 1) as f64;
        let eta = |j: usize| j as f64 / (m - 1) as f64;
        for j in 0..m {
            for i in 0..n {
                prop_assert!((map.eval(xi(i), eta(j)) - net.get(i, j)).length() < 1e-13);
                prop_assert!((map.eval_cox_de_boor(xi(i), eta(j)) - net.get(i, j)).length() < 1e-13);
                if i + 1 < n {
                    let p = map.eval(a * xi(i) + (1.0 - a) * xi(i + 1), eta(j));
                    let q = a * net.get(i, j) + (1.0 - a) * net.get(i + 1, j);
                    prop_assert!((p - q).length() < 1e-13);
                }
                if j + 1 < m {
                    let p = map.eval(xi(i), a * eta(j) + (1.0 - a) * eta(j + 1));
                    let q = a * net.get(i, j) + (1.0 - a) * net.get(i, j + 1);
                    prop_assert!((p - q).length() < 1e-13);
                }
            }
        }
    }

    /// Lemma 2 (28)–(31): at the breakpoints the biquadratic map is the average of 1, 2 or 4
    /// control points.
    #[test]
    fn lemma2_values_at_breakpoints(n in 3usize..8, m in 3usize..8, noise in noise_strategy()) {
        let net = noisy_net(n, m, &noise, 0.2);
        let map = TensorMap::new(Degree::Biquadratic, net.clone()).unwrap();
        // 1-based breakpoints ξ_i = (i−1)/(n−2), i = 1..n−1; P_{i,j} = net.get(i−1, j−1)
        let xi = |i: usize| (i - 1) as f64 / (n - 2) as f64;
        let eta = |j: usize| (j - 1) as f64 / (m - 2) as f64;
        let p = |i: usize, j: usize| net.get(i - 1, j - 1);
        let close = |a: DVec2, b: DVec2| (a - b).length() < 1e-13;
        // (28) corners
        prop_assert!(close(map.eval(xi(1), eta(1)), p(1, 1)));
        prop_assert!(close(map.eval(xi(1), eta(m - 1)), p(1, m)));
        prop_assert!(close(map.eval(xi(n - 1), eta(1)), p(n, 1)));
        prop_assert!(close(map.eval(xi(n - 1), eta(m - 1)), p(n, m)));
        // (29) bottom/top rows
        for i in 2..=n - 2 {
            prop_assert!(close(map.eval(xi(i), eta(1)), 0.5 * (p(i, 1) + p(i + 1, 1))));
            prop_assert!(close(map.eval(xi(i), eta(m - 1)), 0.5 * (p(i, m) + p(i + 1, m))));
        }
        // (30) left/right columns
        for j in 2..=m - 2 {
            prop_assert!(close(map.eval(xi(1), eta(j)), 0.5 * (p(1, j) + p(1, j + 1))));
            prop_assert!(close(map.eval(xi(n - 1), eta(j)), 0.5 * (p(n, j) + p(n, j + 1))));
        }
        // (31) interior
        for i in 2..=n - 2 {
            for j in 2..=m - 2 {
                let q = 0.25 * (p(i, j) + p(i + 1, j) + p(i, j + 1) + p(i + 1, j + 1));
                prop_assert!(close(map.eval(xi(i), eta(j)), q));
                prop_assert!(close(map.eval_cox_de_boor(xi(i), eta(j)), q));
            }
        }
    }

    /// Lemma 4 (50)–(53): the biquadratic map restricted to ∂U is the four boundary curves.
    #[test]
    fn lemma4_boundary_reproduces_the_curves(n in 3usize..9, m in 3usize..9, noise in noise_strategy(), t in 0.0f64..=1.0) {
        let net = noisy_net(n, m, &noise, 0.15);
        let b = net.boundary_curves();
        let map = TensorMap::new(Degree::Biquadratic, net).unwrap();
        let c = |pts: &Vec<DVec2>| BSplineCurve::clamped_uniform(3, pts.clone()).unwrap();
        let close = |a: DVec2, b: DVec2| (a - b).length() < 1e-13;
        prop_assert!(close(map.eval(t, 0.0), c(&b.south).eval(t)));   // (50)
        prop_assert!(close(map.eval(t, 1.0), c(&b.north).eval(t)));   // (51)
        prop_assert!(close(map.eval(0.0, t), c(&b.west).eval(t)));    // (52)
        prop_assert!(close(map.eval(1.0, t), c(&b.east).eval(t)));    // (53)
        // corners Q, R, T, S
        prop_assert!(close(map.eval(0.0, 0.0), b.south[0]));
        prop_assert!(close(map.eval(1.0, 0.0), b.south[n - 1]));
        prop_assert!(close(map.eval(0.0, 1.0), b.north[0]));
        prop_assert!(close(map.eval(1.0, 1.0), b.north[n - 1]));
    }

    /// Partial derivatives: the per-patch Bézier path equals the Cox–de Boor path with (33) and
    /// central finite differences; det J from partials equals the Bernstein form and the
    /// paper's closed forms (Prop 1 corrected, Prop 2 (39) with α = γδ). Both degrees,
    /// including the single-patch case n = m = 3 ((34) holds only for n ≥ 4).
    #[test]
    fn derivatives_and_closed_forms(deg in 1usize..=2, n in 3usize..8, m in 3usize..8, noise in noise_strategy(), s in 0.0f64..1.0, r in 0.0f64..1.0) {
        let net = noisy_net(n, m, &noise, 0.2);
        let map = TensorMap::new(Degree::from_degree(deg).unwrap(), net).unwrap();
        let xi = inside(&map, s, true);
        let eta = inside(&map, r, false);
        let (x, xu, xv) = map.partials(xi, eta);
        prop_assert!((x - map.eval_cox_de_boor(xi, eta)).length() < 1e-12);
        let (cu, cv) = map.partials_cox_de_boor(xi, eta);
        prop_assert!((xu - cu).length() < 1e-10 * (1.0 + cu.length()));
        prop_assert!((xv - cv).length() < 1e-10 * (1.0 + cv.length()));
        let (fu, fv) = fd_partials(&map, xi, eta, 1e-6);
        prop_assert!((xu - fu).length() < 1e-5 * (1.0 + fu.length()), "x_ξ {xu} vs FD {fu}");
        prop_assert!((xv - fv).length() < 1e-5 * (1.0 + fv.length()), "x_η {xv} vs FD {fv}");
        let dj = xu.perp_dot(xv);
        let dj_fd = fu.perp_dot(fv);
        prop_assert!((dj - dj_fd).abs() < 1e-4 * (1.0 + dj.abs()));
        prop_assert!((dj - map.det_j_bernstein(xi, eta)).abs() < 1e-10 * (1.0 + dj.abs()));
        let closed = map.det_j_closed_form(xi, eta);
        prop_assert!((dj - closed).abs() < 1e-10 * (1.0 + dj.abs()), "det J {dj} vs closed form {closed}");
    }

    /// ᾱ (mean doubled triangle area) depends only on the boundary: moving interior points
    /// leaves it unchanged (worked out here; not in the paper).
    #[test]
    fn alpha_bar_is_invariant_under_interior_moves(n in 3usize..8, m in 3usize..8, noise in noise_strategy()) {
        let net = noisy_net(n, m, &noise, 0.1);
        let mut moved = net.clone();
        for j in 1..m - 1 {
            for i in 1..n - 1 {
                let k = (i * 7 + j * 13) % noise.len();
                moved.set(i, j, net.get(i, j) + DVec2::new(noise[k], noise[(k + 5) % noise.len()]));
            }
        }
        // ᾱ from the triangles themselves (Σα/N), not from the boundary formula
        let mean = |g: &ControlNet| {
            let mut s = 0.0;
            for j in 0..m - 1 { for i in 0..n - 1 { s += g.cell_triangles(i, j).iter().sum::<f64>(); } }
            s / (4 * (n - 1) * (m - 1)) as f64
        };
        prop_assert!((mean(&net) - mean(&moved)).abs() < 1e-12);
        prop_assert!((mean(&net) - net.alpha_bar()).abs() < 1e-12);
    }
}

/// (33) = (34) for n ≥ 4 on the uniform biquadratic knots; for n = 3 (34) is wrong
/// (a single interval) while (33) matches finite differences.
#[test]
fn eq33_equals_eq34_for_n_at_least_4_and_fails_for_n3() {
    // (34), 1-based i, with B²_q the order-2 B-splines on the same knots (0-based q−1)
    let eq34 = |k: &KnotVector, n: usize, i: usize, t: f64| -> f64 {
        let b2 = |q: usize| k.basis_of_order(q - 1, 2, t);
        let c = (n - 2) as f64;
        if i == 1 {
            -2.0 * c * b2(2)
        } else if i == 2 {
            c * (2.0 * b2(2) - b2(3))
        } else if i <= n - 2 {
            c * (b2(i) - b2(i + 1))
        } else if i == n - 1 {
            c * (b2(n - 1) - 2.0 * b2(n))
        } else {
            2.0 * c * b2(n)
        }
    };
    for n in 4..10 {
        let k = KnotVector::biquadratic(n).unwrap();
        for l in 0..=40 {
            let t = l as f64 / 40.0;
            for i in 1..=n {
                let a = k.basis_derivative(i - 1, t);
                let b = eq34(&k, n, i, t);
                assert!(
                    (a - b).abs() < 1e-12,
                    "n={n} i={i} t={t}: (33) {a} vs (34) {b}"
                );
            }
        }
    }
    // n = 3: B³_2 = 2t(1−t) on [0,1], derivative 2 − 4t; (34) takes the "i = 2" branch
    // (n−2)(2B²_2 − B²_3) = 2(1−t) − t = 2 − 3t, which is wrong for t > 0.
    let k = KnotVector::biquadratic(3).unwrap();
    let t = 0.5;
    let exact = 2.0 - 4.0 * t;
    assert!((k.basis_derivative(1, t) - exact).abs() < 1e-14);
    assert!((eq34(&k, 3, 2, t) - exact).abs() > 0.4);
}

/// The printed (14) divides by (n−1)(m−1); the correct factor multiplies
/// (the paper's (19)–(20) invert `1/(ξ_{i+1} − ξ_i)`). On the
/// uniform unit-square net with n = 5, m = 4, det J ≡ 1 (the map is the identity), while the
/// printed formula gives 1/((n−1)(m−1))² = 1/144.
#[test]
fn prop1_factor_is_corrected() {
    let (n, m) = (5, 4);
    let map = TensorMap::new(Degree::Bilinear, uniform_square(n, m).unwrap()).unwrap();
    for &(xi, eta) in &[(0.1, 0.2), (0.5, 0.5), (0.9, 0.7)] {
        let dj = map.det_j_closed_form(xi, eta);
        assert!((dj - 1.0).abs() < 1e-13);
        assert!((map.det_j(xi, eta) - 1.0).abs() < 1e-13);
        let printed = dj / (((n - 1) * (m - 1)) as f64).powi(2);
        assert!((printed - 1.0 / 144.0).abs() < 1e-15);
    }
}

/// The α_{r',s'} table (40), garbled in print, read as: γ_{r'}δ_{s'} = 4 at the corners, 2
/// on the edges, 1 inside.
#[test]
fn alpha_table_is_gamma_times_delta() {
    let (n, m) = (7, 6);
    let map = TensorMap::new(Degree::Biquadratic, uniform_square(n, m).unwrap()).unwrap();
    for rp in 0..n - 1 {
        for sp in 0..m - 1 {
            let edge_r = rp == 0 || rp == n - 2;
            let edge_s = sp == 0 || sp == m - 2;
            let want = match (edge_r, edge_s) {
                (true, true) => 4.0,
                (true, false) | (false, true) => 2.0,
                (false, false) => 1.0,
            };
            let a = map.gamma(rp) * map.delta(sp);
            assert!((a - want).abs() < 1e-12, "r'={rp} s'={sp}: {a}");
        }
    }
    // n = 3: γ_1 = γ_2 = 2 (by the general form γ_r = 2Δ/(t_{r+3} − t_{r+1}))
    let map = TensorMap::new(Degree::Biquadratic, uniform_square(3, 3).unwrap()).unwrap();
    assert!((map.gamma(0) - 2.0).abs() < 1e-12 && (map.gamma(1) - 2.0).abs() < 1e-12);
}

/// S1 check (i): the net at the Greville abscissae gives the identity map, det J ≡ 1. For
/// n = 6 the abscissae are 0, 0.125, 0.375, 0.625, 0.875, 1 (S1 check (i)).
#[test]
fn s1_greville_net_is_the_identity() {
    let g = KnotVector::biquadratic(6).unwrap().greville();
    let want = [0.0, 0.125, 0.375, 0.625, 0.875, 1.0];
    for (a, b) in g.iter().zip(want) {
        assert!((a - b).abs() < 1e-15);
    }
    let map = TensorMap::new(Degree::Biquadratic, greville_square(6, 7).unwrap()).unwrap();
    for l in 0..=20 {
        for k in 0..=20 {
            let (xi, eta) = (k as f64 / 20.0, l as f64 / 20.0);
            assert!((map.eval(xi, eta) - DVec2::new(xi, eta)).length() < 1e-14);
            assert!((map.det_j(xi, eta) - 1.0).abs() < 1e-12);
        }
    }
    // every Bernstein coefficient of det J is 1 (a constant polynomial)
    for p in map.patches() {
        for row in &p.jac {
            for &c in row {
                assert!((c - 1.0).abs() < 1e-12);
            }
        }
    }
    let s = unamalla_bspline::sample_det_j(&map, 101, 101).unwrap();
    assert!((s.min - 1.0).abs() < 1e-12 && (s.max - 1.0).abs() < 1e-12);
}

/// S1 check (ii): uniformly spaced square net, n = 6, m = 5: det J is positive but not
/// constant, ranging over about [0.60, 2.39] (computed
/// independently when the S1 checks were designed).
#[test]
fn s1_uniform_net_jacobian_range() {
    let map = TensorMap::new(Degree::Biquadratic, uniform_square(6, 5).unwrap()).unwrap();
    let s = unamalla_bspline::sample_det_j(&map, 801, 801).unwrap();
    assert!((s.min - 0.60).abs() < 0.006, "min {}", s.min);
    // the maximum is at a corner, where it is exactly 2.4 (below); the "about 2.39"
    // above agrees to 0.01
    assert!((s.max - 2.4).abs() < 1e-12, "max {}", s.max);
    assert!((s.max - 2.39).abs() <= 0.0100001);
    // hand check at the corner: x_ξ = (n−2)·γ_1·h = 4·2·(1/5) = 1.6 along x,
    // x_η = (m−2)·δ_1·v = 3·2·(1/4) = 1.5 along y ⇒ det J(0,0) = 2.4
    assert!((map.det_j(0.0, 0.0) - 2.4).abs() < 1e-12);
}

/// A B-spline curve's derivative curve (Q_r) agrees with the pointwise derivative and
/// with finite differences.
#[test]
fn curve_derivative_curve() {
    let pts: Vec<DVec2> = (0..7)
        .map(|i| DVec2::new(i as f64, ((i * i) % 5) as f64))
        .collect();
    let c = BSplineCurve::clamped_uniform(3, pts).unwrap();
    let d = c.derivative().unwrap();
    assert_eq!(d.knots().order(), 2);
    for l in 1..40 {
        let t = l as f64 / 40.0 + 0.003;
        let h = 1e-6;
        let fd = (c.eval(t + h) - c.eval(t - h)) / (2.0 * h);
        assert!((d.eval(t) - c.derivative_at(t)).length() < 1e-12);
        assert!((fd - d.eval(t)).length() < 1e-6 * (1.0 + fd.length()));
    }
}

/// f of (56) is C² at 1: value 1, f' = −1, f'' = 2 from both sides.
#[test]
fn s_function_is_c2_at_one() {
    let f = unamalla_functionals::s_function;
    let (l, r) = (f(1.0 - 1e-9), f(1.0 + 1e-9));
    for k in 0..3 {
        assert!(
            (l[k] - r[k]).abs() < 1e-7,
            "derivative {k}: {} vs {}",
            l[k],
            r[k]
        );
    }
    assert_eq!(f(1.0), [1.0, -1.0, 2.0]);
    // finite for folded triangles: f(−1) = (−2)(−3) + 1 = 7
    assert_eq!(f(-1.0)[0], 7.0);
}
