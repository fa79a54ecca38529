//! Ivanenko's convex-mesh functional `Σ ((ε − α)₊)²` ([González Flores, (2.50)]) on a 3 × 3-node
//! grid whose only free node is moved by hand.
//!
//! Grid: nodes `(i, j)`, `i, j ∈ {0, 1, 2}`, on the square `[0, 2]²`; the centre node
//! `C = (1 + t, 1)` is free. Of the 16 corner triangles, the 4 at the outer corners and the 4 at
//! the edge midpoints whose legs are one horizontal boundary edge and one edge to `C` have
//! `α = 1` for every `t` (one leg is `(±1, 0)`, the other has vertical component ±1); the 4
//! triangles of the two left cells that touch `C` otherwise have `α = 1 + t`, the 4 of the right
//! cells `α = 1 − t` (worked out in the comments of the first test). Hence, with `ε > 1 + |t|`,
//! `F = 8(ε − 1)² + 4(ε − 1 − t)² + 4(ε − 1 + t)²` and `∂F/∂x_C = −8(ε − 1 − t) + 8(ε − 1 + t)`.

mod common;

use std::sync::Arc;

use unamalla_functionals::prelude::*;
use unamalla_functionals::{IvanenkoConvex, KernelExpr, QuadFunctional, QuadTopology};
use unamalla_mesh::{DVec2, StructuredGrid2};

fn grid(t: f64) -> StructuredGrid2 {
    StructuredGrid2::from_fn(3, 3, |i, j| {
        if i == 1 && j == 1 {
            DVec2::new(1.0 + t, 1.0)
        } else {
            DVec2::new(i as f64, j as f64)
        }
    })
    .unwrap()
}

fn functional(t: f64, eps: f64) -> (QuadFunctional, Vec<f64>) {
    let topo = Arc::new(QuadTopology::from_mesh(&grid(t)).unwrap());
    let x = topo.initial_x();
    let f = QuadFunctional::new(topo, KernelExpr::from(IvanenkoConvex::new(eps).unwrap()));
    (f, x)
}

#[test]
fn hand_values_with_every_triangle_below_eps() {
    // cell (0,0) = (0,0),(1,0),C,(0,1) with C = (1+t, 1):
    //   corner (0,0): det((1,0),(0,1)) = 1; corner (1,0): det(C−(1,0), (−1,0)) = det((t,1),(−1,0)) = 1;
    //   corner C: det((0,1)−C, (1,0)−C) = det((−1−t,0),(−t,−1)) = 1+t;
    //   corner (0,1): det((0,0)−(0,1), C−(0,1)) = det((0,−1),(1+t,0)) = 1+t.
    // cell (1,0) = (1,0),(2,0),(2,1),C: corners 1, (2,1): det(C−(2,1),(2,0)−(2,1)) = det((t−1,0),(0,−1)) = 1−t,
    //   C: det((1,0)−C,(2,1)−C) = det((−t,−1),(1−t,0)) = 1−t, and (1,0): det((1,0),(t,1)) = 1.
    // The top cells mirror these. So α ∈ {1 ×8, 1+t ×4, 1−t ×4}.
    let (t, eps) = (0.2, 1.5);
    let (f, x) = functional(t, eps);
    let want = 8.0 * 0.5f64.powi(2) + 4.0 * 0.3f64.powi(2) + 4.0 * 0.7f64.powi(2); // 4.32
    assert!((f.value(&x) - 4.32).abs() < 1e-12);
    assert!((want - 4.32).abs() < 1e-12);
    let mut g = vec![0.0; 2];
    let v = f.value_grad(&x, &mut g);
    assert!((v - 4.32).abs() < 1e-12);
    // ∂/∂x_C: the 1+t triangles have ∂α/∂x = +1, the 1−t ones −1, the others 0:
    // 4·(−2·0.3)·1 + 4·(−2·0.7)·(−1) = −2.4 + 5.6 = 3.2
    assert!((g[0] - 3.2).abs() < 1e-12, "{g:?}");
    // ∂/∂y_C is 0 by the mirror symmetry y ↦ 2 − y
    assert!(g[1].abs() < 1e-12, "{g:?}");
    // ∂²/∂x_C²: f″ = 2 on the 8 triangles whose α moves with slope ±1
    let mut h = f.hessian_pattern();
    f.hessian(&x, &mut h);
    let hxx = h.get(0, 0);
    assert!((hxx - 16.0).abs() < 1e-12, "{hxx}");
}

#[test]
fn hand_values_with_only_some_triangles_below_eps() {
    // ε = 0.9, t = 0.2: only the four α = 0.8 triangles count, each (0.1)²
    let (f, x) = functional(0.2, 0.9);
    let mut g = vec![0.0; 2];
    let v = f.value_grad(&x, &mut g);
    assert!((v - 0.04).abs() < 1e-12, "{v}");
    // 4·(−2·0.1)·(−1) = 0.8
    assert!((g[0] - 0.8).abs() < 1e-12, "{g:?}");
}

#[test]
fn zero_exactly_on_eps_convex_meshes() {
    // the uniform grid has every α = 1: zero for ε ≤ 1, 16(ε − 1)² above
    let (f, x) = functional(0.0, 1.0);
    assert_eq!(f.value(&x), 0.0);
    let (f, x) = functional(0.0, 1.25);
    assert!((f.value(&x) - 16.0 * 0.0625).abs() < 1e-12);
    // a folded centre (t = 1.5: α = 1 − t = −0.5 < 0) is penalized, and finitely
    let (f, x) = functional(1.5, 0.1);
    let v = f.value(&x);
    assert!((v - 4.0 * 0.6f64.powi(2)).abs() < 1e-12, "{v}");
}

#[test]
fn bad_parameters_are_typed_errors() {
    assert!(IvanenkoConvex::new(0.0).is_err());
    assert!(IvanenkoConvex::new(f64::NAN).is_err());
    assert!(IvanenkoConvex::relative(0.01, -1.0).is_err());
    assert!((IvanenkoConvex::relative(0.01, 2.0).unwrap().eps() - 0.02).abs() < 1e-15);
    // no ideal value (0 on the ideal grid): normalization is refused, not silently divided by 0
    let k = KernelExpr::from(IvanenkoConvex::new(0.5).unwrap());
    assert!(k.normalized(16, 1.0).is_err());
}

#[test]
fn derivatives_match_finite_differences_off_the_kink() {
    // a perturbed 6 × 5 grid, ε between α values (≥ 0.01ᾱ from each), checked by central
    // differences of the value (gradient) and of the gradient (Hessian, CSR and products)
    let noise: Vec<f64> = (0..64).map(|i| ((i * 41 + 3) % 64) as f64 / 63.0).collect();
    for amp in [0.3, 1.6] {
        let g = common::grid2(6, 5, amp, &noise);
        let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
        let x = topo.initial_x();
        let mut a = vec![0.0; topo.num_triangles()];
        topo.alphas(&x, &mut a);
        let ab = topo.alpha_bar();
        let eps = (10..=200)
            .map(|i| 0.01 * i as f64 * ab)
            .find(|e| {
                a.iter().all(|v| (v - e).abs() > 0.01 * ab)
                    && a.iter().any(|v| v < e)
                    && a.iter().any(|v| v > e)
            })
            .expect("a gap in the α values");
        let below = a.iter().filter(|&&v| v < eps).count();
        assert!(below > 0 && below < a.len(), "both branches exercised");
        let f = QuadFunctional::new(topo, KernelExpr::from(IvanenkoConvex::new(eps).unwrap()));
        common::check_problem("ivanenko", &f, &x, 2e-5).unwrap();
    }
}
