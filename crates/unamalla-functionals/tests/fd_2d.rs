//! Gradients, Hessians, Hessian-vector products and local models of every 2D functional agree
#![allow(clippy::needless_range_loop)]
//! with central finite differences on random convex and random folded grids.

mod common;

use std::sync::Arc;

use proptest::prelude::*;
use unamalla_functionals::*;
use unamalla_mesh::{HasNodes, QuadMesh};

/// Every 2D functional, with parameters adapted to the grid so that all are finite at `x`.
fn all_kernels(topo: &QuadTopology, x: &[f64]) -> Vec<(&'static str, KernelExpr)> {
    let s = topo.alpha_summary(x);
    let abar = topo.alpha_bar();
    let amin = s.min;
    let min_abs = {
        let mut a = vec![0.0; topo.num_triangles()];
        topo.alphas(x, &mut a);
        a.iter().fold(f64::INFINITY, |m, v| m.min(v.abs()))
    };
    let k = -amin + 0.5 * abar;
    let ah = amin + 0.5 * (abar - amin); // above α₋: exercises the quadratic branch
    let eps_c = (0.5 * abar).max(-amin + 0.3 * abar);
    let rho: Vec<f64> = (0..topo.num_cells())
        .map(|c| 0.5 + 0.1 * (c % 7) as f64)
        .collect();
    let dens = topo.boundary_density(3.0, 1);
    let mut v: Vec<(&'static str, KernelExpr)> = vec![
        ("length", KernelExpr::from(Length)),
        (
            "weighted-length",
            KernelExpr::from(WeightedLength::new(0.3).unwrap()),
        ),
        ("area", KernelExpr::from(Area)),
        ("castillo", KernelExpr::from(CastilloArea)),
        ("a4p", KernelExpr::from(A4P::new(abar).unwrap())),
        ("orthogonality", KernelExpr::from(Orthogonality)),
        ("area-orthogonality", KernelExpr::from(AreaOrthogonality)),
        (
            "regularized-smoothness",
            KernelExpr::from(RegularizedSmoothness::new(eps_c).unwrap()),
        ),
        (
            "regularized-smoothness-spacing",
            KernelExpr::from(
                RegularizedSmoothness::new(eps_c)
                    .unwrap()
                    .spacing(SpacingWeights::from_ratios(rho.clone()).unwrap()),
            ),
        ),
        (
            "regularized-inverse-area",
            KernelExpr::from(RegularizedInverseArea::new(eps_c).unwrap()),
        ),
        (
            "generic-area",
            KernelExpr::custom(GenericArea::new(move |a: f64| {
                let t = a / abar;
                [
                    t.exp() + t * t * t,
                    t.exp() / abar + 3.0 * t * t / abar,
                    t.exp() / (abar * abar) + 6.0 * t / (abar * abar),
                ]
            })),
        ),
        (
            "k-smoothness",
            KernelExpr::from(KSmoothness::new(k, None).unwrap()),
        ),
        (
            "k-smoothness-reg",
            KernelExpr::from(KSmoothness::new(k, Some(ah)).unwrap()),
        ),
        ("k-area", KernelExpr::from(KArea::new(k, None).unwrap())),
        (
            "k-area-reg",
            KernelExpr::from(KArea::new(k, Some(ah)).unwrap()),
        ),
        (
            "s-omega-eps",
            KernelExpr::from(SOmegaEps::new(5.0, 0.05, abar, SArgument::ScaleInvariant).unwrap()),
        ),
        (
            "s-omega-eps-literal",
            KernelExpr::from(SOmegaEps::new(3.0 / abar, 0.05, abar, SArgument::Literal).unwrap()),
        ),
        (
            "h-omega",
            KernelExpr::from(HOmega::new(0.7 * abar).unwrap()),
        ),
        (
            "ao-h-omega (fused)",
            KernelExpr::convex(
                0.9,
                AreaOrthogonality.into(),
                HOmega::new(0.5 * abar).unwrap().into(),
            )
            .unwrap(),
        ),
        (
            "weighted-ao-h-omega (6.9)",
            KernelExpr::weighted_sum([
                (
                    0.9,
                    KernelExpr::from(AreaOrthogonality)
                        .cell_weighted(dens.clone())
                        .unwrap(),
                ),
                (0.1, HOmega::new(0.5 * abar).unwrap().into()),
            ]),
        ),
        (
            "castillo+length+k-area normalized",
            KernelExpr::weighted_sum(vec![
                (0.5, KernelExpr::from(CastilloArea)),
                (0.3, KernelExpr::from(Length)),
                (0.2, KernelExpr::from(KArea::new(k, None).unwrap())),
            ])
            .normalized(topo.num_triangles(), abar)
            .unwrap(),
        ),
        (
            "cell-weighted area",
            KernelExpr::from(Area).cell_weighted(dens).unwrap(),
        ),
    ];
    // Ivanenko's ((ε − α)₊)²: ε placed at least 0.05ᾱ away from every α of the grid, so the
    // finite differences never straddle the kink of f″ at α = ε
    let mut alphas = vec![0.0; topo.num_triangles()];
    topo.alphas(x, &mut alphas);
    if let Some(eps) = (6..=30).map(|i| 0.05 * i as f64 * abar).find(|e| {
        alphas.iter().all(|a| (a - e).abs() > 0.05 * abar) && alphas.iter().any(|a| a < e)
    }) {
        v.push((
            "ivanenko",
            KernelExpr::from(IvanenkoConvex::new(eps).unwrap()),
        ));
    }
    if min_abs > 0.05 * abar {
        v.push(("smoothness", KernelExpr::from(Smoothness::new())));
        v.push((
            "smoothness-spacing",
            KernelExpr::from(Smoothness::with_spacing(
                SpacingWeights::from_ratios(rho).unwrap(),
            )),
        ));
    }
    v
}

fn run(amp: f64, noise: &[f64], m: usize, n: usize) -> Result<(), TestCaseError> {
    let g = common::grid2(m, n, amp, noise);
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let x = topo.initial_x();
    for (name, k) in all_kernels(&topo, &x) {
        let f = QuadFunctional::new(topo.clone(), k);
        common::check_problem(name, &f, &x, 2e-5).map_err(TestCaseError::fail)?;
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    #[test]
    fn derivatives_match_fd_on_random_convex_grids(
        noise in prop::collection::vec(0.0f64..1.0, 64),
        m in 4usize..6, n in 4usize..6,
    ) {
        run(0.25, &noise, m, n)?;
    }

    #[test]
    fn derivatives_match_fd_on_random_folded_grids(
        noise in prop::collection::vec(0.0f64..1.0, 64),
        m in 4usize..6, n in 4usize..6,
    ) {
        run(1.8, &noise, m, n)?;
    }
}

#[test]
fn folded_grids_are_really_folded() {
    // the folded generator does produce non-convex cells (so the proptest exercises them)
    let noise: Vec<f64> = (0..64)
        .map(|i| ((i * 37 + 11) % 64) as f64 / 63.0)
        .collect();
    let g = common::grid2(5, 5, 1.8, &noise);
    let topo = QuadTopology::from_mesh(&g).unwrap();
    let s = topo.alpha_summary(&topo.initial_x());
    assert!(s.nonconvex_cells > 0, "{s:?}");
}

#[test]
fn unstructured_mesh_with_irregular_node_gives_same_derivative_quality() {
    // an unstructured mesh: a 3×3-cell grid with a cell order permuted and one extra free node
    // of valence 3 (a "pole"), checked like the grids
    let noise: Vec<f64> = (0..64).map(|i| ((i * 29 + 5) % 64) as f64 / 63.0).collect();
    let g = common::grid2(5, 4, 0.5, &noise);
    let q = QuadMesh::from_grid(&g);
    let mut cells = q.cells().to_vec();
    cells.reverse();
    let mesh = QuadMesh::new(q.nodes().to_vec(), cells).unwrap();
    let topo = Arc::new(QuadTopology::from_mesh(&mesh).unwrap());
    let x = topo.initial_x();
    for (name, k) in all_kernels(&topo, &x) {
        let f = QuadFunctional::new(topo.clone(), k);
        common::check_problem(name, &f, &x, 2e-5).unwrap();
    }
}
