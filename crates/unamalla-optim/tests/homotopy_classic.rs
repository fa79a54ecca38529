//! The homotopy paths σ̃(t) of [González Flores, §5.3, (5.16)–(5.18)] in the double homotopy
//! (§5.4, (5.19)–(5.20)), and the classic combinations t-Area–Length and t-Area–Orthogonality
//! (Table 5.1), against hand values.

use std::sync::Arc;

use unamalla_functionals::prelude::*;
use unamalla_functionals::{QuadFunctional, QuadTopology};
use unamalla_mesh::{DVec2, HasNodes, StructuredGrid2};
use unamalla_optim::drivers::{
    adaptive_k, homotopy_weight, smooth, AdaptiveKOptions, ClassicCombination, HomotopySchedule,
    SmoothFunctional, SmoothOptions,
};
use unamalla_optim::fixtures::{ivanenko, perturbed};
use unamalla_optim::monitor::{NullObserver, Session};
use unamalla_optim::Status;

#[test]
fn schedules_by_hand() {
    // k₀ = 0.5, k* = −0.01, k = 0.245: t = (0.5 − 0.245)/(0.5 + 0.01) = 0.255/0.51 = ½;
    // the weight of f₂ is (1 − σ)·σ̃(½) with 1 − σ = 0.5
    let w = |s| homotopy_weight(s, 0.5, 0.5, 0.245, -0.01);
    assert!((w(HomotopySchedule::Linear) - 0.25).abs() < 1e-15);
    assert!((w(HomotopySchedule::Square) - 0.125).abs() < 1e-15);
    assert!((w(HomotopySchedule::Cube) - 0.0625).abs() < 1e-15);
    assert!((w(HomotopySchedule::Sine) - 0.5 * std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15);
    for s in HomotopySchedule::ALL {
        // ends: pure f₁ at k₀, the target weight at k*; k above k₀ (a restart) falls back to
        // f₁, below k* stays at the target
        assert_eq!(s.sigma_tilde(0.0), 0.0, "{s}");
        assert!((s.sigma_tilde(1.0) - 1.0).abs() < 1e-15, "{s}");
        assert_eq!(homotopy_weight(s, 0.5, 0.5, 0.6, -0.01), 0.0, "{s}");
        assert!(
            (homotopy_weight(s, 0.5, 0.5, -0.02, -0.01) - 0.5).abs() < 1e-15,
            "{s}"
        );
        // already at the floor: the target
        assert_eq!(homotopy_weight(s, 0.3, -0.01, -0.01, -0.01), 0.3, "{s}");
        // increasing on [0, 1]
        let v: Vec<f64> = (0..=100).map(|i| s.sigma_tilde(i as f64 / 100.0)).collect();
        assert!(v.windows(2).all(|p| p[1] > p[0]), "{s}");
        assert_eq!(s.name().parse::<HomotopySchedule>().unwrap(), s);
    }
    assert!("t4".parse::<HomotopySchedule>().is_err());
}

fn fixture() -> StructuredGrid2 {
    perturbed(&ivanenko(11, 11).unwrap(), 0.8, 7)
}

fn run(schedule: HomotopySchedule) -> (Vec<f64>, bool, usize) {
    run_with(&AdaptiveKOptions::default().schedule(schedule))
}

fn run_with(opts: &AdaptiveKOptions) -> (Vec<f64>, bool, usize) {
    let g = fixture();
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let mut x = topo.initial_x();
    let probe = QuadFunctional::new(topo.clone(), unamalla_functionals::Length);
    let mut obs = NullObserver;
    let mut s = Session::new(&probe, &x, &mut obs);
    let r = adaptive_k(&topo, &mut x, opts, &mut s).unwrap();
    (x, r.convex, r.initial_inocon)
}

#[test]
fn every_schedule_untangles_the_folded_ivanenko_grid() {
    let (x_lin, convex, inocon0) = run(HomotopySchedule::Linear);
    assert!(inocon0 > 0, "the start is folded");
    assert!(convex);
    let mut differs = 0;
    for s in [
        HomotopySchedule::Square,
        HomotopySchedule::Cube,
        HomotopySchedule::Sine,
    ] {
        let (x, convex, _) = run(s);
        assert!(convex, "{s}");
        if x != x_lin {
            differs += 1;
        }
    }
    // the path is really used: some schedule gives another mesh than the linear one
    assert!(differs > 0);
    // and the default is the linear homotopy (5.20), bit for bit
    assert_eq!(run_with(&AdaptiveKOptions::default()).0, x_lin);
}

/// Corner legs `(a, b)` of every cell of a structured grid (cell `(i,j)` counter-clockwise,
/// corner `k`: `a = v_{k+1} − v_k`, `b = v_{k−1} − v_k`).
fn legs(g: &StructuredGrid2) -> Vec<(DVec2, DVec2)> {
    let (m, n) = (g.m(), g.n());
    let p = |i: usize, j: usize| g.node(i, j);
    let mut out = Vec::new();
    for j in 0..n - 1 {
        for i in 0..m - 1 {
            let v = [p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)];
            for k in 0..4 {
                out.push((v[(k + 1) % 4] - v[k], v[(k + 3) % 4] - v[k]));
            }
        }
    }
    out
}

#[test]
fn area_orthogonality_is_half_the_leg_product_by_lagrange() {
    // ½·Σα²/(Nᾱ²) + ½·Σo²/(Nᾱ²) = Σ|a|²|b|²/(2Nᾱ²) since α² + o² = |a|²|b|²
    let g = perturbed(&ivanenko(6, 5).unwrap(), 0.5, 3);
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let x = topo.initial_x();
    let l = legs(&g);
    let n = l.len();
    assert_eq!(n, topo.num_triangles());
    let ab = l.iter().map(|(a, b)| a.perp_dot(*b)).sum::<f64>() / n as f64;
    let want = l
        .iter()
        .map(|(a, b)| a.length_squared() * b.length_squared())
        .sum::<f64>()
        / (2.0 * n as f64 * ab * ab);
    let k = ClassicCombination::AreaOrthogonality
        .kernel(0.5, n, topo.alpha_bar())
        .unwrap();
    let got = QuadFunctional::new(topo, k).value(&x);
    assert!((got - want).abs() < 1e-12 * want, "{got} vs {want}");
    // the weight is fixed
    assert!(ClassicCombination::AreaOrthogonality
        .kernel(0.7, n, ab)
        .is_err());
}

#[test]
fn area_length_is_one_on_the_uniform_grid_for_every_sigma() {
    // squares of side h: α = h² = ᾱ, l = 2h², so Σα²/(Nᾱ²) = 1 and Σl/(2Nᾱ) = 1
    let g =
        StructuredGrid2::from_fn(5, 4, |i, j| DVec2::new(0.5 * i as f64, 0.5 * j as f64)).unwrap();
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let x = topo.initial_x();
    for sigma in [0.0, 0.5, 0.9, 0.95, 1.0] {
        let k = ClassicCombination::AreaLength
            .kernel(sigma, topo.num_triangles(), topo.alpha_bar())
            .unwrap();
        let v = QuadFunctional::new(topo.clone(), k).value(&x);
        assert!((v - 1.0).abs() < 1e-12, "σ = {sigma}: {v}");
    }
    assert!(ClassicCombination::AreaLength.kernel(1.5, 48, 1.0).is_err());
}

#[test]
fn classic_smooth_options_parse_and_keep_a_convex_start_convex() {
    // the unperturbed TFI grid of Ivanenko's region 21 × 21 is folded (6 cells, docs); at
    // 11 × 11 take a convex grid: the adaptive result, then smooth it with each classic pair
    let (x, convex, _) = run(HomotopySchedule::Linear);
    assert!(convex);
    let mut g = fixture();
    let topo = QuadTopology::from_mesh(&g).unwrap();
    topo.scatter(&x, g.nodes_mut());
    for name in ["area-length", "area-ortho"] {
        let f: SmoothFunctional = name.parse().unwrap();
        let f = if name == "area-length" {
            f.with_sigma(0.9).unwrap()
        } else {
            assert!(f.clone().with_sigma(0.9).is_err(), "weight fixed at 0.5");
            f.with_sigma(0.5).unwrap()
        };
        let mut h = g.clone();
        let r = smooth(
            &mut h,
            &SmoothOptions::default().functional(f),
            &mut NullObserver,
        )
        .unwrap();
        assert!(r.convex, "{name}: {:?}", r.status);
        assert!(r.iter_classic > 0, "{name}");
    }
    assert!("homega"
        .parse::<SmoothFunctional>()
        .unwrap()
        .with_sigma(0.5)
        .is_err());
}

#[test]
fn ivanenko_functional_untangles_the_folded_ivanenko_grid_to_eps_convexity() {
    // Σ((ε_I − α)₊)² is 0 exactly when α ≥ ε_I everywhere; the driver targets ε_I = 2εᾱ, so
    // from the folded 11 × 11 start the run must end ε-convex (α₋ > 0.01ᾱ) with F ≈ 0
    let mut g = fixture();
    let r = smooth(
        &mut g,
        &SmoothOptions::default().functional("ivanenko".parse().unwrap()),
        &mut NullObserver,
    )
    .unwrap();
    assert!(r.initial_inocon > 0);
    assert!(
        r.convex && r.eps_convex,
        "{:?} {} {}",
        r.status,
        r.alfamin / r.alpha_bar,
        r.f
    );
    assert!(r.alfamin >= 0.01 * r.alpha_bar * (1.0 - 1e-9));
    assert!(r.f.abs() < 1e-6, "{}", r.f);
    // an ε-convex start is left alone
    let before = g.clone();
    let r2 = smooth(
        &mut g,
        &SmoothOptions::default().functional(SmoothFunctional::Ivanenko),
        &mut NullObserver,
    )
    .unwrap();
    assert_eq!(r2.iterations(), 0);
    assert_eq!(g.nodes(), before.nodes());
    assert!(SmoothFunctional::Ivanenko.with_sigma(0.5).is_err());
}

#[test]
fn stopping_at_the_target_bound_ends_a_homotopy_the_thesis_loop_cannot_end() {
    // 3 × 3 nodes on the unit square, one free node p; the bottom middle node sits at (δ, 0).
    // Corner triangles (doubled areas) of p's cells that bound α₋: at (δ, 0) in the lower
    // left cell δ·p_y, at (0.5, 1) in the upper left cell 0.5·(1 − p_y). So
    // α₋ ≤ max_p min(δ·p_y, 0.5·(1 − p_y)) = 0.5δ/(0.5 + δ), with ᾱ = 4·area/16 = 0.25:
    // for δ = 0.004, α₋/ᾱ ≤ 0.01587 — above the target 0.01 of k* = −0.01, below the
    // 0.02/1.0015 that the thesis's exit k̃ = −1.0015·α₋ + 0.01·ᾱ ≤ k*·ᾱ needs.
    let delta = 0.004;
    let xs = [0.0, 0.5, 1.0];
    let g = StructuredGrid2::from_fn(3, 3, |i, j| match (i, j) {
        (1, 0) => DVec2::new(delta, 0.0),
        (1, 1) => DVec2::new(0.5, 0.5),
        _ => DVec2::new(xs[i], xs[j]),
    })
    .unwrap();
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let probe = QuadFunctional::new(topo.clone(), unamalla_functionals::Length);
    let bound = 0.5 * delta / (0.5 + delta) / 0.25;
    let run = |stop_at_target: bool| {
        let mut x = topo.initial_x();
        let mut obs = NullObserver;
        let mut s = Session::new(&probe, &x, &mut obs);
        let opts = AdaptiveKOptions::default()
            .classic(false)
            .max_updates(40)
            .stop_at_target(stop_at_target);
        let r = adaptive_k(&topo, &mut x, &opts, &mut s).unwrap();
        // α₋ over the triangles with a free vertex (the corner (0, 0) of the lower left cell,
        // 0.5δ, is boundary data)
        assert!((r.alpha_bar - 0.25).abs() < 1e-12);
        assert!(
            (r.initial_alfamin - 0.5 * delta).abs() < 1e-12,
            "the start: α₋ = δ·p_y = 0.5δ"
        );
        let q = r.alfamin / r.alpha_bar;
        (r, q)
    };
    let (thesis, q_t) = run(false);
    let (target, q_s) = run(true);
    assert!(q_t <= bound + 1e-12 && q_s <= bound + 1e-12);
    // the thesis's loop cannot reach its exit: it stops without "the homotopic step is ok"
    assert!(
        !thesis.messages.contains(&Status::HomotopicOk),
        "{:?}",
        thesis.messages
    );
    // at the target: convex with α₋ > 0.01ᾱ, ended by the homotopy itself
    assert!(target.convex && q_s > 0.01, "α₋/ᾱ = {q_s}");
    assert!(
        target.messages.contains(&Status::HomotopicOk),
        "{:?}",
        target.messages
    );
    assert!(target.iter_homotopic < thesis.iter_homotopic);
}
