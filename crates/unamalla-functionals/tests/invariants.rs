//! Invariants of the functionals, with expected values derived by hand or from the formulas.
#![allow(clippy::needless_range_loop)]

mod common;

use std::sync::Arc;

use approx::assert_relative_eq;
use unamalla_functionals::*;
use unamalla_mesh::{DVec2, DVec3, HasNodes, HexMesh, QuadMesh, StructuredGrid2};

fn shoelace(p: &[DVec2]) -> f64 {
    let n = p.len();
    0.5 * (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum::<f64>()
}

#[test]
fn sum_of_alphas_is_four_times_the_area_even_when_folded() {
    for (amp, seed) in [(0.2, 3usize), (1.8, 7), (2.5, 11)] {
        let noise: Vec<f64> = (0..200)
            .map(|i| ((i * 53 + seed) % 97) as f64 / 96.0)
            .collect();
        let g = common::grid2(7, 6, amp, &noise);
        let boundary: Vec<DVec2> = g.boundary_loop().iter().map(|&v| g.nodes()[v]).collect();
        let area = shoelace(&boundary);
        let topo = QuadTopology::from_mesh(&g).unwrap();
        let mut a = vec![0.0; topo.num_triangles()];
        topo.alphas(&topo.initial_x(), &mut a);
        assert_relative_eq!(a.iter().sum::<f64>(), 4.0 * area, max_relative = 1e-12);
        assert_relative_eq!(
            topo.alpha_bar(),
            4.0 * area / a.len() as f64,
            max_relative = 1e-12
        );
    }
}

#[test]
fn right_isosceles_triangle_minimizes_l_over_alpha() {
    // one triangle: P = 0, Q = a, R = b; (|a|² + |b|²)/det(a, b) ≥ 2 with equality iff
    // b = a rotated by +90° ([González Flores, (2.70)–(2.77)]).
    let k = Smoothness::new();
    let term = |a: DVec2, b: DVec2| {
        let s = TriScalars {
            alpha: a.perp_dot(b),
            la: a.length_squared(),
            lb: b.length_squared(),
            o: a.dot(b),
            cell: 0,
            corner: 0,
        };
        k.eval(&s, Order::Gradient)
    };
    let a = DVec2::new(1.3, 0.4);
    let b = a.perp();
    let best = term(a, b);
    assert_relative_eq!(best.v, 2.0, max_relative = 1e-14);
    for i in 0..200 {
        let t = i as f64 * 0.37;
        let pert = 0.3 * DVec2::new(t.sin(), (1.7 * t).cos());
        let other = term(a, b + pert);
        if (a.perp_dot(b + pert)) > 0.0 {
            assert!(other.v >= 2.0 - 1e-14, "{}", other.v);
        }
    }
    // and it is a critical point of the whole functional: a unit square as a mesh with all
    // nodes free has four right-isosceles corner triangles and zero gradient
    let sq = vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(1.0, 0.0),
        DVec2::new(1.0, 1.0),
        DVec2::new(0.0, 1.0),
    ];
    let topo = Arc::new(QuadTopology::new(sq, vec![[0, 1, 2, 3]], vec![false; 4]).unwrap());
    let f = QuadFunctional::new(topo.clone(), Smoothness::new());
    let x = topo.initial_x();
    let mut g = vec![0.0; 8];
    assert_relative_eq!(f.value_grad(&x, &mut g), 8.0, max_relative = 1e-14);
    assert!(g.iter().all(|v| v.abs() < 1e-13), "{g:?}");
}

#[test]
fn uniform_area_grid_is_a_critical_point_of_any_area_functional() {
    // a uniform grid of a parallelogram: every corner triangle has α = ᾱ
    // ([González Flores, Prop 3.1])
    let g = StructuredGrid2::from_fn(6, 5, |i, j| {
        DVec2::new(
            1.5 * i as f64 + 0.7 * j as f64,
            0.2 * i as f64 + 1.1 * j as f64,
        )
    })
    .unwrap();
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let x = topo.initial_x();
    let abar = topo.alpha_bar();
    let fs: Vec<KernelExpr> = vec![
        KernelExpr::custom(GenericArea::new(|a: f64| [a.exp(), a.exp(), a.exp()])),
        KernelExpr::custom(GenericArea::new(|a: f64| {
            [a.powi(4), 4.0 * a.powi(3), 12.0 * a * a]
        })),
        KernelExpr::from(Area),
        KernelExpr::from(A4P::new(abar).unwrap()),
        KernelExpr::from(KArea::new(0.3, None).unwrap()),
        KernelExpr::from(RegularizedInverseArea::new(0.5 * abar).unwrap()),
        KernelExpr::from(SOmegaEps::new(10.0, 0.1, abar, SArgument::ScaleInvariant).unwrap()),
    ];
    for k in fs {
        let f = QuadFunctional::new(topo.clone(), k.clone());
        let mut grad = vec![0.0; f.num_vars()];
        let v = f.value_grad(&x, &mut grad);
        let gmax = grad.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(gmax <= 1e-9 * (1.0 + v.abs()), "{k:?}: |g| = {gmax}");
        // and the Hessian is positive semidefinite there for convex f (vᵀHv ≥ 0)
        let mut hv = vec![0.0; f.num_vars()];
        let dir: Vec<f64> = (0..f.num_vars())
            .map(|i| ((i * 13) % 7) as f64 - 3.0)
            .collect();
        f.hess_vec(&x, &dir, &mut hv);
        let q: f64 = dir.iter().zip(&hv).map(|(a, b)| a * b).sum();
        assert!(q >= -1e-9 * (1.0 + v.abs()), "{k:?}: vᵀHv = {q}");
    }
}

#[test]
fn normalized_functionals_are_one_on_the_ideal_grid() {
    // square cells of side 0.5 on [0, 4] × [0, 2.5]: every corner triangle is right isosceles
    // with α = ᾱ = 0.25, l = 2ᾱ, o = 0
    let g =
        StructuredGrid2::from_fn(9, 6, |i, j| DVec2::new(0.5 * i as f64, 0.5 * j as f64)).unwrap();
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let x = topo.initial_x();
    let (n, abar) = (topo.num_triangles(), topo.alpha_bar());
    assert_relative_eq!(abar, 0.25, max_relative = 1e-14);
    let ones = [
        KernelExpr::from(Length),
        KernelExpr::from(Area),
        KernelExpr::from(CastilloArea),
        KernelExpr::from(AreaOrthogonality),
        KernelExpr::from(Smoothness::new()),
        KernelExpr::from(RegularizedSmoothness::with_alpha_bar(abar).unwrap()),
        KernelExpr::from(KSmoothness::new(0.1, None).unwrap()),
        KernelExpr::from(KArea::new(0.1, None).unwrap()),
        KernelExpr::from(HOmega::new(0.1).unwrap()),
        KernelExpr::convex(
            0.1,
            KernelExpr::from(HOmega::new(0.1).unwrap()),
            KernelExpr::from(AreaOrthogonality),
        )
        .unwrap(),
    ];
    for k in ones {
        let f = QuadFunctional::new(topo.clone(), k.clone().normalized(n, abar).unwrap());
        assert_relative_eq!(f.value(&x), 1.0, max_relative = 1e-12);
    }
    // hand-checked constants: length Σl/(2Nᾱ), k-area (k+ᾱ)/N Σ 1/(k+α)
    let f = QuadFunctional::new(topo.clone(), KernelExpr::from(Length));
    assert_relative_eq!(f.value(&x), 2.0 * n as f64 * abar, max_relative = 1e-12);
    // a rectangle with non-square cells (dx = 0.5, dy = 0.4): area-type normalizations are still
    // exactly 1, length-type ones are (dx² + dy²)/(2 dx dy) ≈ 1.025
    let g =
        StructuredGrid2::from_fn(9, 6, |i, j| DVec2::new(0.5 * i as f64, 0.4 * j as f64)).unwrap();
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let x = topo.initial_x();
    let (n, abar) = (topo.num_triangles(), topo.alpha_bar());
    for k in [
        KernelExpr::from(Area),
        KernelExpr::from(AreaOrthogonality),
        KernelExpr::from(KArea::new(0.1, None).unwrap()),
    ] {
        let f = QuadFunctional::new(topo.clone(), k.normalized(n, abar).unwrap());
        assert_relative_eq!(f.value(&x), 1.0, max_relative = 1e-12);
    }
    for k in [
        KernelExpr::from(Length),
        KernelExpr::from(Smoothness::new()),
    ] {
        let f = QuadFunctional::new(topo.clone(), k.normalized(n, abar).unwrap());
        assert_relative_eq!(
            f.value(&x),
            (0.25 + 0.16) / (2.0 * 0.2),
            max_relative = 1e-12
        );
    }
}

#[test]
fn energy_density_is_at_least_one_with_equality_for_similarities() {
    // one hexahedron, all nodes free; ω tiny so that every tet is on the 1/V branch and the
    // functional is the mean energy density E = λ/V over the 10 tets
    let cube: Vec<DVec3> = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(0.0, 1.0, 1.0),
    ];
    // a similarity: rotation about an axis, scale 2.5, translation
    let axis = DVec3::new(1.0, 2.0, -0.5).normalize();
    let rot = glam::DQuat::from_axis_angle(axis, 0.8);
    let sim: Vec<DVec3> = cube
        .iter()
        .map(|&p| 2.5 * (rot * p) + DVec3::new(3.0, -1.0, 2.0))
        .collect();
    let eval = |nodes: Vec<DVec3>| {
        let topo = Arc::new(
            HexTopology::new(nodes, vec![[0, 1, 2, 3, 4, 5, 6, 7]], vec![false; 8]).unwrap(),
        );
        let f = HexFunctional::h_omega(topo.clone(), 1e-9, Scaling3::Index).unwrap();
        let x = topo.initial_x();
        let mut v = vec![0.0; 10];
        f.element_measures(&x, &mut v);
        assert!(v.iter().all(|&t| t > 1e-9));
        f.value(&x)
    };
    assert_relative_eq!(eval(cube.clone()), 1.0, max_relative = 1e-12);
    assert_relative_eq!(eval(sim), 1.0, max_relative = 1e-12);
    // random convex perturbations: every tet has E ≥ 1, so the mean is > 1
    for s in 0..20 {
        let pert: Vec<DVec3> = cube
            .iter()
            .enumerate()
            .map(|(i, &p)| {
                let t = (s * 8 + i) as f64;
                p + 0.12 * DVec3::new((1.3 * t).sin(), (2.1 * t).cos(), (0.7 * t).sin())
            })
            .collect();
        assert!(eval(pert) > 1.0);
    }
    // and a stretched box (not a similarity) has E > 1 per tet: columns (2, 1, 1):
    // λ = ((4 + 1 + 1)/3)^{3/2} = 2^{3/2}, V = 2 → E = √2
    let boxed: Vec<DVec3> = cube
        .iter()
        .map(|p| DVec3::new(2.0 * p.x, p.y, p.z))
        .collect();
    assert_relative_eq!(eval(boxed), 2f64.sqrt(), max_relative = 1e-12);
}

#[test]
fn parametric_scaling_makes_the_uniform_grid_of_a_box_harmonic_with_energy_one() {
    // [0,2]×[0,3]×[0,1] with 5×4×3 nodes: index-space columns are (0.5, 1, 0.5) (E ≠ 1), the
    // parametric ones (2, 3, 1) → not similar either; a cube [0,1]³ with 5×3×4 nodes has
    // parametric columns (1, 1, 1): E = 1 exactly
    let g = unamalla_mesh::StructuredGrid3::from_fn(5, 3, 4, |i, j, k| {
        DVec3::new(i as f64 / 4.0, j as f64 / 2.0, k as f64 / 3.0)
    })
    .unwrap();
    let topo = Arc::new(HexTopology::from_mesh(&g).unwrap());
    let f = HexFunctional::h_omega(
        topo.clone(),
        1e-6,
        Scaling3::Parametric { m: 5, n: 3, p: 4 },
    )
    .unwrap();
    assert_relative_eq!(f.value(&topo.initial_x()), 1.0, max_relative = 1e-12);
    let f = HexFunctional::h_omega(topo.clone(), 1e-6, Scaling3::Index).unwrap();
    assert!(f.value(&topo.initial_x()) > 1.01);
}

#[test]
fn k_functionals_grow_without_bound_as_min_alpha_approaches_minus_k() {
    let noise: Vec<f64> = (0..64).map(|i| ((i * 31 + 3) % 64) as f64 / 63.0).collect();
    let g = common::grid2(6, 5, 1.6, &noise);
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let x = topo.initial_x();
    let amin = topo.alpha_summary(&x).min;
    assert!(amin < 0.0);
    let mut prev_s = 0.0;
    let mut prev_a = 0.0;
    for j in 1..8 {
        let gap = 10f64.powi(-j);
        let k = -amin + gap; // min(k + α) = gap
        let fs = QuadFunctional::new(topo.clone(), KSmoothness::new(k, None).unwrap()).value(&x);
        let fa = QuadFunctional::new(topo.clone(), KArea::new(k, None).unwrap()).value(&x);
        // the worst triangle alone contributes ≥ 1/gap (k-area) and ≥ 2k/gap (k-smoothness)
        assert!(fa >= 1.0 / gap && fs >= 2.0 * k / gap, "{fa} {fs}");
        assert!(fa > prev_a && fs > prev_s);
        prev_a = fa;
        prev_s = fs;
    }
    // beyond the barrier: +∞ without the continuation, finite with it
    let k = -amin - 0.1;
    assert_eq!(
        QuadFunctional::new(topo.clone(), KArea::new(k, None).unwrap()).value(&x),
        f64::INFINITY
    );
    let ah = -k + 0.01;
    let f = QuadFunctional::new(topo.clone(), KSmoothness::new(k, Some(ah)).unwrap());
    let mut grad = vec![0.0; f.num_vars()];
    let v = f.value_grad(&x, &mut grad);
    assert!(v.is_finite() && grad.iter().all(|g| g.is_finite()));
}

#[test]
fn quadratic_continuation_is_c2_at_the_matching_point() {
    let (k, ah) = (0.4, -0.3);
    let left = inv_k(k, Some(ah), ah - 1e-12);
    let right = inv_k(k, Some(ah), ah);
    let exact = [
        1.0 / (k + ah),
        -1.0 / (k + ah).powi(2),
        2.0 / (k + ah).powi(3),
    ];
    for i in 0..3 {
        assert_relative_eq!(left[i], exact[i], max_relative = 1e-9);
        assert_relative_eq!(right[i], exact[i], max_relative = 1e-12);
    }
    // φ_ω and the regularized 1/α are C¹ at their switch points
    let w = 0.7;
    let (a, b) = (phi_omega(w, w - 1e-13), phi_omega(w, w));
    assert_relative_eq!(a[0], b[0], max_relative = 1e-9);
    assert_relative_eq!(a[1], b[1], max_relative = 1e-9);
    let e = 0.3;
    let (a, b) = (phi_regularized(e, e - 1e-13), phi_regularized(e, e));
    assert_relative_eq!(a[0], b[0], max_relative = 1e-9);
    assert_relative_eq!(a[1], b[1], max_relative = 1e-9);
    // (56) is C² at 1
    let (a, b) = (s_function(1.0 - 1e-13), s_function(1.0));
    for i in 0..3 {
        assert_relative_eq!(a[i], b[i], max_relative = 1e-9);
    }
}

#[test]
fn evaluation_is_deterministic_for_any_thread_count() {
    let noise: Vec<f64> = (0..500)
        .map(|i| ((i * 7919 + 13) % 1000) as f64 / 999.0)
        .collect();
    let g = common::grid2(130, 120, 0.4, &noise);
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    assert!(topo.num_cells() > 10 * unamalla_functionals::assembly::CHUNK_CELLS);
    let x = topo.initial_x();
    let f = QuadFunctional::new(
        topo.clone(),
        KernelExpr::convex(
            0.9,
            AreaOrthogonality.into(),
            HOmega::new(0.5 * topo.alpha_bar()).unwrap().into(),
        )
        .unwrap(),
    );
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut grad = vec![0.0; f.num_vars()];
            let v = f.value_grad(&x, &mut grad);
            let mut h = f.hessian_pattern();
            f.hessian(&x, &mut h);
            let mut hv = vec![0.0; f.num_vars()];
            f.hess_vec(&x, &grad, &mut hv);
            (v, f.value(&x), grad, h.values, hv)
        })
    };
    let a = run(1);
    let b = run(2);
    let c = run(3);
    for r in [&b, &c] {
        assert_eq!(a.0.to_bits(), r.0.to_bits());
        assert_eq!(a.1.to_bits(), r.1.to_bits());
        assert!(a
            .2
            .iter()
            .zip(&r.2)
            .all(|(p, q)| p.to_bits() == q.to_bits()));
        assert!(a
            .3
            .iter()
            .zip(&r.3)
            .all(|(p, q)| p.to_bits() == q.to_bits()));
        assert!(a
            .4
            .iter()
            .zip(&r.4)
            .all(|(p, q)| p.to_bits() == q.to_bits()));
    }
    // 3D as well
    let g3 = common::grid3(30, 25, 20, 0.3, &noise);
    let t3 = Arc::new(HexTopology::from_mesh(&g3).unwrap());
    let f3 = HexFunctional::h_omega(t3.clone(), 0.5, Scaling3::Index)
        .unwrap()
        .with_coplanarity(1.0)
        .unwrap();
    let x3 = t3.initial_x();
    let run3 = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut grad = vec![0.0; f3.num_vars()];
            let v = f3.value_grad(&x3, &mut grad);
            (v, grad)
        })
    };
    let (a, b) = (run3(1), run3(2));
    assert_eq!(a.0.to_bits(), b.0.to_bits());
    assert!(a
        .1
        .iter()
        .zip(&b.1)
        .all(|(p, q)| p.to_bits() == q.to_bits()));
}

#[test]
fn structured_and_unstructured_views_agree() {
    let noise: Vec<f64> = (0..64).map(|i| ((i * 17 + 1) % 64) as f64 / 63.0).collect();
    let g = common::grid2(7, 5, 0.3, &noise);
    let q = QuadMesh::from_grid(&g);
    let t1 = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let t2 = Arc::new(QuadTopology::from_mesh(&q).unwrap());
    let k = KernelExpr::convex(0.5, Length.into(), Area.into()).unwrap();
    let f1 = QuadFunctional::new(t1.clone(), k.clone());
    let f2 = QuadFunctional::new(t2.clone(), k);
    assert_eq!(f1.value(&t1.initial_x()), f2.value(&t2.initial_x()));
    let g3 = common::grid3(4, 4, 5, 0.3, &noise);
    let h = HexMesh::from_grid(&g3);
    let a = Arc::new(HexTopology::from_mesh(&g3).unwrap());
    let b = Arc::new(HexTopology::from_mesh(&h).unwrap());
    let fa = HexFunctional::h_omega(a.clone(), 0.3, Scaling3::Index).unwrap();
    let fb = HexFunctional::h_omega(b.clone(), 0.3, Scaling3::Index).unwrap();
    assert_eq!(fa.value(&a.initial_x()), fb.value(&b.initial_x()));
}

#[test]
fn coplanarity_vanishes_on_planar_faces_and_matches_the_cosine() {
    // a sheared box grid: all faces planar
    let g = unamalla_mesh::StructuredGrid3::from_fn(5, 5, 5, |i, j, k| {
        DVec3::new(
            i as f64 + 0.3 * j as f64,
            j as f64,
            k as f64 + 0.2 * i as f64,
        )
    })
    .unwrap();
    let topo = Arc::new(HexTopology::from_mesh(&g).unwrap());
    let f = HexFunctional::coplanarity(topo.clone(), 3.0).unwrap();
    let x = topo.initial_x();
    assert!(f.value(&x).abs() < 1e-24);
    assert_eq!(
        topo.interior_cells().iter().filter(|&&b| b).count(),
        2 * 2 * 2
    );
    // lift one corner of a unit square face by h: N = (0,0,1), AC = (1,1,h):
    // cos = h/√(2 + h²)
    let h = 0.3;
    let face = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(1.0, 1.0, h),
        DVec3::new(0.0, 1.0, 0.0),
    ];
    assert_relative_eq!(
        face_coplanarity_cos(face),
        h / (2.0 + h * h).sqrt(),
        max_relative = 1e-14
    );
    assert!(face_planarity_max_cos(face) >= face_coplanarity_cos(face).abs());
    // moving one interior node of the planar grid off its planes makes the penalty positive
    let mut x2 = x.clone();
    x2[3 * 3 + 2] += 0.2;
    assert!(f.value(&x2) > 0.0);
    let (worst, bad) = topo.planarity_report(&x2, 1e-2);
    assert!(worst > 1e-2 && bad > 0);
}

#[test]
#[should_panic(expected = "does not come from hessian_pattern")]
fn a_hessian_of_another_pattern_is_rejected() {
    let noise: Vec<f64> = (0..64).map(|i| (i % 13) as f64 / 12.0).collect();
    let a = Arc::new(QuadTopology::from_mesh(&common::grid2(5, 5, 0.2, &noise)).unwrap());
    let mut cells: Vec<[usize; 4]> = (0..a.num_cells()).map(|c| a.cell(c)).collect();
    cells.remove(5); // cell (1, 1): all four nodes free, so two diagonal couplings disappear
    let mut fixed = vec![true; a.num_nodes()];
    for &v in a.free_nodes() {
        fixed[v] = false;
    }
    // same free nodes, one interior cell fewer: same size, different pattern
    let b = Arc::new(QuadTopology::new(a.coords().to_vec(), cells, fixed).unwrap());
    let fa = QuadFunctional::new(a.clone(), Area);
    let fb = QuadFunctional::new(b.clone(), Area);
    let mut h = fb.hessian_pattern();
    assert_eq!(h.nrows, fa.num_vars());
    fa.hessian(&a.initial_x(), &mut h);
}

/// The area–orthogonality term is not elliptic: on the uniform grid its Hessian gives
/// diagonal waves `u(i, j) = w·sin(θ(i + j))` an energy that depends on the polarization `w`.
/// With `f = ½|a|²|b|²` per corner triangle, the second variation summed over a cell's four
/// corners (legs `a, b` along the cell edges, `c = cos θ`) is, per unit `|w|²`:
/// * `w = (1, −1)` (area- and angle-preserving shear along the diagonal): corners 0 and 2
///   cancel exactly, corners 1 and 3 give `4(1 − c)²` each → Rayleigh quotient `8(1 − c)²`
///   (≈ `2θ⁴`, fourth order);
/// * `w = (1, 1)`: corners 0 and 2 give `8(1 − c)`, corners 1 and 3 `4(1 − c)(1 + c)` →
///   `8(1 − c)(3 + c)` (≈ `16θ²`, second order).
///
/// So smooth `(1, −1)` waves cost `(1 − c)/(3 + c) ≈ θ²/8` of the other polarization, and only
/// `H_ω` bounds them from below. `H_ω` is isotropic: at the identity Winslow's `l/α` has the second
/// variation `|∇u|² − 2 det ∇u` (expand `(2 + 2 div u + |∇u|²)/(1 + div u + det ∇u)`), and `det ∇u`
/// sums to zero with the boundary fixed, so both quotients are equal — the reason the (6.8) optimum
/// at σ = 0.1 is so flat (docs/benchmarks.md, "Why 1000² in 5 s is out of reach at σ = 0.1"). The
/// waves are multiplied by the envelope `sin(πi/(n−1))·sin(πj/(n−1))` so that they vanish on the
/// fixed boundary; its frequency `π/(n−1)` is small against θ, hence the 5 % tolerance.
#[test]
fn area_orthogonality_hessian_is_weak_for_diagonal_shear_waves() {
    let n = 161;
    let g = StructuredGrid2::from_fn(n, n, |i, j| DVec2::new(i as f64, j as f64)).unwrap();
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let x = topo.initial_x();
    let rayleigh = |f: &dyn Problem, theta: f64, w: (f64, f64)| {
        let mut v = vec![0.0; x.len()];
        let e = std::f64::consts::PI / (n - 1) as f64;
        for j in 1..n - 1 {
            for i in 1..n - 1 {
                let var = topo.var_of(j * n + i).unwrap();
                let s =
                    (theta * (i + j) as f64).sin() * (e * i as f64).sin() * (e * j as f64).sin();
                v[2 * var] = w.0 * s;
                v[2 * var + 1] = w.1 * s;
            }
        }
        let mut hv = vec![0.0; x.len()];
        f.hess_vec(&x, &v, &mut hv);
        let vhv: f64 = v.iter().zip(&hv).map(|(a, b)| a * b).sum();
        vhv / v.iter().map(|a| a * a).sum::<f64>()
    };
    let ao = QuadFunctional::new(topo.clone(), KernelExpr::from(AreaOrthogonality));
    let winslow = QuadFunctional::new(topo.clone(), KernelExpr::from(HOmega::new(0.01).unwrap()));
    for theta in [0.8, 0.6] {
        let c: f64 = f64::cos(theta);
        let weak = rayleigh(&ao, theta, (1.0, -1.0));
        let strong = rayleigh(&ao, theta, (1.0, 1.0));
        assert_relative_eq!(weak, 8.0 * (1.0 - c).powi(2), max_relative = 0.05);
        assert_relative_eq!(strong, 8.0 * (1.0 - c) * (3.0 + c), max_relative = 0.05);
        assert!(weak < 0.1 * strong, "θ = {theta}: {weak} vs {strong}");
        // H_ω at the identity is isotropic: both polarizations cost the same
        let (pw, ps) = (
            rayleigh(&winslow, theta, (1.0, -1.0)),
            rayleigh(&winslow, theta, (1.0, 1.0)),
        );
        assert_relative_eq!(pw, ps, max_relative = 1e-9);
    }
}
