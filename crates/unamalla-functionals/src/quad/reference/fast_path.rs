//! The fast evaluator (corner lanes, precomputed slots, first-contribution stores, the plan
//! chosen for the `KernelExpr`, AVX2 dispatch) agrees with the reference per-triangle path
//! (`QuadFunctional::*_reference`, [`super`]) to rounding — value, gradient, Hessian and Hessian-vector
//! product — on random convex and folded grids and on unstructured quad meshes, for every
//! kind of kernel (fused, general, nested, custom, per-cell weighted, diagonal pair).
#![allow(clippy::needless_range_loop)]

#[path = "../../../tests/common/mod.rs"]
mod common;

use std::sync::Arc;

use proptest::prelude::*;
use unamalla_functionals::*;
use unamalla_mesh::{DVec2, HasNodes, QuadMesh};

/// `|a − b| ≤ tol·(scale + max(|a|, |b|))`: the two paths do the same operations in a
/// different order, so they agree to a few ulps of the largest term that enters a sum.
fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-11 * (scale + a.abs().max(b.abs()))
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Compares fast and reference paths of one functional at `x`.
fn compare(name: &str, f: &QuadFunctional, x: &[f64]) -> Result<(), String> {
    let n = f.num_vars();
    let (mut g_fast, mut g_ref) = (vec![0.0; n], vec![0.0; n]);
    // garbage in the output buffers: the fast path must overwrite, not accumulate
    g_fast.iter_mut().for_each(|v| *v = f64::NAN);
    let v_fast = f.value_grad(x, &mut g_fast);
    let v_ref = f.value_grad_reference(x, &mut g_ref);
    if !close(v_fast, v_ref, 0.0) {
        return Err(format!("{name}: value {v_fast} vs reference {v_ref}"));
    }
    if !close(f.value(x), f.value_reference(x), 0.0) {
        return Err(format!("{name}: value() differs from the reference"));
    }
    let gs = max_abs(&g_ref);
    for i in 0..n {
        if !close(g_fast[i], g_ref[i], gs) {
            return Err(format!(
                "{name}: gradient[{i}] {} vs reference {}",
                g_fast[i], g_ref[i]
            ));
        }
    }
    let mut h_fast = f.hessian_pattern();
    h_fast.values.iter_mut().for_each(|v| *v = f64::NAN);
    let mut h_ref = f.hessian_pattern();
    f.hessian(x, &mut h_fast);
    f.hessian_reference(x, &mut h_ref);
    let hs = max_abs(&h_ref.values);
    for (e, (a, b)) in h_fast.values.iter().zip(&h_ref.values).enumerate() {
        if !close(*a, *b, hs) {
            return Err(format!("{name}: Hessian entry {e}: {a} vs reference {b}"));
        }
    }
    // a second refresh into the same matrix gives the same values
    let first = h_fast.values.clone();
    f.hessian(x, &mut h_fast);
    if first
        .iter()
        .zip(&h_fast.values)
        .any(|(a, b)| a.to_bits() != b.to_bits())
    {
        return Err(format!("{name}: a second refresh changed the Hessian"));
    }
    let v: Vec<f64> = (0..n)
        .map(|i| ((i * 31 % 17) as f64) / 17.0 - 0.4)
        .collect();
    let (mut hv_fast, mut hv_ref) = (vec![f64::NAN; n], vec![0.0; n]);
    f.hess_vec(x, &v, &mut hv_fast);
    f.hess_vec_reference(x, &v, &mut hv_ref);
    let mut hv_csr = vec![0.0; n];
    h_fast.mul_vec(&v, &mut hv_csr);
    let s = max_abs(&hv_ref) + hs;
    for i in 0..n {
        if !close(hv_fast[i], hv_ref[i], s) || !close(hv_csr[i], hv_ref[i], s) {
            return Err(format!(
                "{name}: (Hv)[{i}] fast {} / CSR {} vs reference {}",
                hv_fast[i], hv_csr[i], hv_ref[i]
            ));
        }
    }
    Ok(())
}

/// Run-time kernels covering every leaf and combinator, with parameters that keep them finite.
fn kernels(topo: &QuadTopology, x: &[f64]) -> Vec<(&'static str, KernelExpr)> {
    let s = topo.alpha_summary(x);
    let abar = topo.alpha_bar();
    let k = -s.min + 0.5 * abar;
    let ah = s.min + 0.5 * (abar - s.min);
    let eps_c = (0.5 * abar).max(-s.min + 0.3 * abar);
    let n = topo.num_triangles();
    let rho: Vec<f64> = (0..topo.num_cells())
        .map(|c| 0.5 + 0.1 * (c % 7) as f64)
        .collect();
    let dens = topo.boundary_density(3.0, 1);
    let ao = KernelExpr::from(AreaOrthogonality)
        .normalized(n, abar)
        .unwrap();
    let h = KernelExpr::from(HOmega::new(0.5 * abar).unwrap())
        .normalized(n, abar)
        .unwrap();
    vec![
        // the pipeline's form of [Méndez 2023, (6.8)]: routed to the fused kernel
        (
            "nested normalized ao + h-omega",
            KernelExpr::weighted_sum(vec![(0.9, ao), (0.1, h)]),
        ),
        (
            "h-omega + ao (reversed)",
            KernelExpr::convex(
                0.2,
                KernelExpr::from(HOmega::new(0.7 * abar).unwrap()),
                KernelExpr::from(AreaOrthogonality),
            )
            .unwrap(),
        ),
        ("length", KernelExpr::from(Length)),
        (
            "weighted-length",
            KernelExpr::from(WeightedLength::new(0.3).unwrap()),
        ),
        ("area", KernelExpr::from(Area)),
        ("a4p", KernelExpr::from(A4P::new(abar).unwrap())),
        ("orthogonality", KernelExpr::from(Orthogonality)),
        (
            "regularized-smoothness-spacing",
            KernelExpr::from(
                RegularizedSmoothness::new(eps_c)
                    .unwrap()
                    .spacing(SpacingWeights::from_ratios(rho).unwrap()),
            ),
        ),
        (
            "regularized-inverse-area",
            KernelExpr::from(RegularizedInverseArea::new(eps_c).unwrap()),
        ),
        (
            "k-smoothness-reg",
            KernelExpr::from(KSmoothness::new(k, Some(ah)).unwrap()),
        ),
        ("k-area", KernelExpr::from(KArea::new(k, None).unwrap())),
        (
            "s-omega-eps",
            KernelExpr::from(SOmegaEps::new(5.0, 0.05, abar, SArgument::ScaleInvariant).unwrap()),
        ),
        (
            "custom generic-area",
            KernelExpr::custom(GenericArea::new(move |a: f64| {
                let t = a / abar;
                [t * t * t, 3.0 * t * t / abar, 6.0 * t / (abar * abar)]
            })),
        ),
        (
            "castillo + length + k-area",
            KernelExpr::weighted_sum(vec![
                (0.5, KernelExpr::from(CastilloArea)),
                (0.3, KernelExpr::from(Length)),
                (0.2, KernelExpr::from(KArea::new(k, None).unwrap())),
            ]),
        ),
        (
            "cell-weighted area",
            KernelExpr::from(Area).cell_weighted(dens).unwrap(),
        ),
    ]
}

fn check_all(topo: &Arc<QuadTopology>) -> Result<(), String> {
    let x = topo.initial_x();
    let abar = topo.alpha_bar();
    // the fused plan (w₁F_AO + w₂H_ω) and nested groupings
    let fused = QuadFunctional::new(
        topo.clone(),
        KernelExpr::convex(
            0.9,
            AreaOrthogonality.into(),
            HOmega::new(0.5 * abar).unwrap().into(),
        )
        .unwrap(),
    );
    compare("fused ao + h-omega", &fused, &x)?;
    let weighted = QuadFunctional::new(
        topo.clone(),
        KernelExpr::nested_sum([
            (
                0.9,
                KernelExpr::from(AreaOrthogonality)
                    .cell_weighted(topo.boundary_density(3.0, 1))
                    .unwrap(),
            ),
            (
                0.1,
                KernelExpr::nested_sum([(2.0, HOmega::new(0.5 * abar).unwrap().into())]),
            ),
        ]),
    );
    compare("nested weighted (6.9)", &weighted, &x)?;
    compare(
        "castillo + area",
        &QuadFunctional::new(
            topo.clone(),
            KernelExpr::convex(0.5, CastilloArea.into(), Area.into()).unwrap(),
        ),
        &x,
    )?;
    for (name, k) in kernels(topo, &x) {
        compare(name, &QuadFunctional::new(topo.clone(), k), &x)?;
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 10, ..ProptestConfig::default() })]

    #[test]
    fn fast_path_matches_reference_on_random_convex_grids(
        noise in prop::collection::vec(0.0f64..1.0, 64),
        m in 3usize..9, n in 3usize..9,
    ) {
        let g = common::grid2(m, n, 0.3, &noise);
        let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
        check_all(&topo).map_err(TestCaseError::fail)?;
    }

    #[test]
    fn fast_path_matches_reference_on_random_folded_grids(
        noise in prop::collection::vec(0.0f64..1.0, 64),
        m in 3usize..9, n in 3usize..9,
    ) {
        let g = common::grid2(m, n, 1.8, &noise);
        let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
        check_all(&topo).map_err(TestCaseError::fail)?;
    }
}

#[test]
fn fast_path_matches_reference_on_unstructured_meshes() {
    // (1) a perturbed grid whose cells are listed in reverse order (so chunks and colours
    // differ from the structured numbering)
    let noise: Vec<f64> = (0..64).map(|i| ((i * 29 + 5) % 64) as f64 / 63.0).collect();
    let g = common::grid2(9, 7, 0.5, &noise);
    let q = QuadMesh::from_grid(&g);
    let mut cells = q.cells().to_vec();
    cells.reverse();
    let mesh = QuadMesh::new(q.nodes().to_vec(), cells).unwrap();
    check_all(&Arc::new(QuadTopology::from_mesh(&mesh).unwrap())).unwrap();

    // (2) a triangle split into three quads around a free node of valence 3, each quad split
    // again into four (free nodes of valence 3, 4 and 6-ish mixtures)
    let a = DVec2::new(0.0, 0.0);
    let b = DVec2::new(2.0, 0.0);
    let c = DVec2::new(1.0, 1.8);
    let ctr = (a + b + c) / 3.0 + DVec2::new(0.05, -0.03);
    let coarse = [
        [a, (a + b) / 2.0, ctr, (a + c) / 2.0],
        [b, (b + c) / 2.0, ctr, (a + b) / 2.0],
        [c, (a + c) / 2.0, ctr, (b + c) / 2.0],
    ];
    let mut nodes: Vec<DVec2> = Vec::new();
    let id = |p: DVec2, nodes: &mut Vec<DVec2>| -> usize {
        match nodes.iter().position(|q| (*q - p).length() < 1e-12) {
            Some(i) => i,
            None => {
                nodes.push(p);
                nodes.len() - 1
            }
        }
    };
    let mut cells = Vec::new();
    for quad in &coarse {
        let m = (quad[0] + quad[1] + quad[2] + quad[3]) / 4.0;
        let e: Vec<DVec2> = (0..4)
            .map(|k| (quad[k] + quad[(k + 1) % 4]) / 2.0)
            .collect();
        for k in 0..4 {
            let p = [quad[k], e[k], m, e[(k + 3) % 4]];
            cells.push(p.map(|p| id(p, &mut nodes)));
        }
    }
    let mesh = QuadMesh::new(nodes, cells).unwrap();
    let topo = Arc::new(QuadTopology::from_mesh(&mesh).unwrap());
    assert!(topo.num_vars() >= 8, "{} variables", topo.num_vars());
    check_all(&topo).unwrap();
}

#[test]
fn fast_path_is_bit_identical_across_thread_counts_on_a_multi_chunk_grid() {
    let noise: Vec<f64> = (0..300)
        .map(|i| ((i * 7919 + 3) % 997) as f64 / 996.0)
        .collect();
    let g = common::grid2(110, 100, 0.4, &noise);
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let x = topo.initial_x();
    let abar = topo.alpha_bar();
    let f = QuadFunctional::new(
        topo.clone(),
        KernelExpr::convex(
            0.9,
            KernelExpr::from(AreaOrthogonality),
            KernelExpr::from(HOmega::new(0.5 * abar).unwrap()),
        )
        .unwrap(),
    );
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut g = vec![0.0; f.num_vars()];
            let v = f.value_grad(&x, &mut g);
            let mut h = f.hessian_pattern();
            f.hessian(&x, &mut h);
            let mut hv = vec![0.0; f.num_vars()];
            f.hess_vec(&x, &g, &mut hv);
            let bits = |s: &[f64]| s.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            (v.to_bits(), bits(&g), bits(&h.values), bits(&hv))
        })
    };
    let one = run(1);
    // the single-threaded loop with the same chunked summation gives the same value
    assert_eq!(one.0, f.value_serial(&x).to_bits());
    assert!(one == run(2));
    assert!(one == run(3));
    // and the fast path agrees with the reference here too
    compare("multi-chunk grid", &f, &x).unwrap();
}
