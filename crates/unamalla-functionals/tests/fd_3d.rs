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

/// Regression (a proptest draw of 2026-11-22): a folded grid where one tetrahedron of the
/// parametric H_ω case sits within the 10⁻⁶ FD step of the switch point α = ω of the C¹ φ_ω;
/// the analytic Hessian entry (0.48805…) is confirmed by the smaller-step differences.
#[test]
fn folded_grid_with_an_element_at_the_switch_point() {
    let noise = [
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.9633810814198187,
        0.6558128343904687,
        0.8765310753776369,
        0.1401998314063137,
        0.021269597964277534,
        0.9434121907937844,
        0.9694121769994176,
        0.9673288768698349,
        0.30757422458239464,
        0.3849540780210499,
        0.6174060313440384,
        0.49822804279121197,
        0.13140067460607813,
        0.0006070090854115955,
        0.5635955267422064,
        0.1507468324004321,
        0.3717570779304971,
        0.9263530045874392,
        0.7912980639038749,
        0.12161969433418271,
        0.232706867898816,
        0.7150698870558263,
        0.34663325341890244,
        0.10776212972344199,
        0.0748599586722627,
        0.8675613252911623,
        0.8180076000994574,
        0.2911173093447352,
        0.10877097467088458,
        0.9180943736151539,
        0.2842437011510522,
        0.6447666550642125,
        0.5131105197375034,
        0.3648945362423513,
        0.10875317543603705,
        0.7034111075182599,
        0.33245453637447575,
        0.9399225364677377,
        0.8432671455446902,
        0.288539909794839,
        0.22952695542112656,
        0.6510225159911344,
        0.6252098650967994,
        0.6205393897631589,
        0.15595928786374935,
        0.40616780668252045,
        0.05649713169802359,
        0.6737619002557844,
        0.6535240035372359,
        0.13435862884199784,
        0.5857281199244728,
        0.3186462533739362,
        0.5299446011063286,
        0.03528718079975936,
        0.9634356145657803,
        0.32300085693980807,
        0.8939988930202868,
        0.056907673031159435,
        0.8202214456160913,
        0.5967805737176209,
        0.34028355010174016,
        0.48386674276941843,
        0.10453249227442192,
        0.28834982880865334,
        0.12926087304100814,
        0.9483455875449932,
        0.3148249452629612,
        0.41854421128003955,
        0.3803489512448135,
        0.2132349339541063,
        0.09074316883244347,
        0.22751185470155494,
        0.48371451892373307,
        0.8647208614008661,
        0.057787901901129604,
    ];
    run(1.6, &noise, (4, 5, 5)).unwrap();
}
