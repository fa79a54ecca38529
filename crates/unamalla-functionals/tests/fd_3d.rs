//! Gradients, Hessians, Hessian-vector products and local models of the 3D functionals agree
#![allow(clippy::needless_range_loop)]
//! with central finite differences on random convex and random folded hex grids.

mod common;

use std::sync::Arc;

use proptest::prelude::*;
use unamalla_functionals::*;

fn run(amp: f64, noise: &[f64], dims: (usize, usize, usize)) -> Result<(), TestCaseError> {
    let g = common::grid3(dims.0, dims.1, dims.2, amp, noise);
    let topo = Arc::new(HexTopology::from_mesh(&g).unwrap());
    let x = topo.initial_x();
    let param = Scaling3::Parametric {
        m: dims.0,
        n: dims.1,
        p: dims.2,
    };
    let cases: Vec<(&str, HexFunctional)> = vec![
        (
            "h-omega index",
            HexFunctional::h_omega(topo.clone(), 0.8, Scaling3::Index).unwrap(),
        ),
        (
            "h-omega small ω",
            HexFunctional::h_omega(topo.clone(), 0.05, Scaling3::Index).unwrap(),
        ),
        (
            "h-omega parametric",
            HexFunctional::h_omega(topo.clone(), 20.0, param).unwrap(),
        ),
        (
            "coplanarity",
            HexFunctional::coplanarity(topo.clone(), 2.0).unwrap(),
        ),
        (
            "h-omega + coplanarity",
            HexFunctional::h_omega(topo.clone(), 0.5, Scaling3::Custom([1.0, 2.0, 0.5]))
                .unwrap()
                .with_coplanarity(0.7)
                .unwrap(),
        ),
    ];
    for (name, f) in cases {
        common::check_problem(name, &f, &x, 2e-5).map_err(TestCaseError::fail)?;
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 6, ..ProptestConfig::default() })]

    #[test]
    fn derivatives_match_fd_on_random_convex_hex_grids(
        noise in prop::collection::vec(0.0f64..1.0, 96),
        p in 4usize..6,
    ) {
        run(0.2, &noise, (4, 5, p))?;
    }

    #[test]
    fn derivatives_match_fd_on_random_folded_hex_grids(
        noise in prop::collection::vec(0.0f64..1.0, 96),
        p in 4usize..6,
    ) {
        run(1.6, &noise, (4, 5, p))?;
    }
}

#[test]
fn folded_hex_grids_have_negative_tets() {
    let noise: Vec<f64> = (0..96)
        .map(|i| ((i * 37 + 11) % 96) as f64 / 95.0)
        .collect();
    let g = common::grid3(4, 5, 5, 1.6, &noise);
    let topo = Arc::new(HexTopology::from_mesh(&g).unwrap());
    let f = HexFunctional::h_omega(topo.clone(), 1.0, Scaling3::Index).unwrap();
    let x = topo.initial_x();
    let mut v = vec![0.0; f.num_elements()];
    f.element_measures(&x, &mut v);
    assert!(v.iter().any(|&t| t <= 0.0));
}
