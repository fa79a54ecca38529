//! The Hessians as `nalgebra_sparse::CsrMatrix` (feature `nalgebra-sparse`): every entry of the
//! converted matrix equals the matrix-free Hessian-vector product `Problem::hess_vec` with unit
//! vectors, nalgebra-sparse's products equal ours, and the conversion back is the identity.
#![cfg(feature = "nalgebra-sparse")]

mod common;

use std::sync::Arc;

use nalgebra::DVector;
use nalgebra_sparse::CsrMatrix;
use unamalla_functionals::*;

/// Column `j` of the Hessian from `hess_vec(x, e_j)` against the converted matrix's column `j`
/// (both triangles are stored, so the row of `j` is compared with `H e_j`).
fn check_entries<P: Problem>(p: &P, x: &[f64], cols: &[usize]) {
    let mut h = p.hessian_pattern();
    p.hessian(x, &mut h);
    let m = h.to_nalgebra_sparse().unwrap();
    assert_eq!((m.nrows(), m.ncols(), m.nnz()), (h.nrows, h.ncols, h.nnz()));
    let n = p.num_vars();
    let mut e = vec![0.0; n];
    let mut col = vec![0.0; n];
    let scale = h.values.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for &j in cols {
        e[j] = 1.0;
        p.hess_vec(x, &e, &mut col);
        e[j] = 0.0;
        for (i, &c) in col.iter().enumerate() {
            let entry = m.get_entry(i, j).map_or(0.0, |v| v.into_value());
            assert!(
                (entry - c).abs() <= 1e-11 * scale,
                "({i}, {j}): CsrMatrix {entry} vs hess_vec {c}"
            );
        }
    }
    // nalgebra-sparse's product equals ours, and the conversion back is the identity
    let v: Vec<f64> = (0..n)
        .map(|k| ((k * 7919) % 113) as f64 / 113.0 - 0.5)
        .collect();
    let theirs = &m * &DVector::from_vec(v.clone());
    let mut ours = vec![0.0; n];
    h.mul_vec(&v, &mut ours);
    for (a, b) in ours.iter().zip(theirs.iter()) {
        assert!((a - b).abs() <= 1e-12 * scale, "{a} vs {b}");
    }
    assert_eq!(Csr::try_from(&m).unwrap(), h);
    let mut m2 = CsrMatrix::try_from(&h).unwrap();
    h.copy_values_into(&mut m2).unwrap();
    assert_eq!(m2, m);
}

#[test]
fn quad_hessians_as_csr_matrix_equal_the_matrix_free_products() {
    let noise = [0.13, 0.71, 0.42, 0.93, 0.27, 0.58, 0.05, 0.84];
    let g = common::grid2(7, 6, 0.3, &noise);
    let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
    let x = topo.initial_x();
    let cols: Vec<usize> = (0..topo.initial_x().len()).collect();
    check_entries(
        &QuadFunctional::new(topo.clone(), Smoothness::new()),
        &x,
        &cols,
    );
    check_entries(
        &QuadFunctional::new(topo.clone(), AreaOrthogonality),
        &x,
        &cols,
    );
    check_entries(
        &QuadFunctional::new(topo, HOmega::new(0.5).unwrap()),
        &x,
        &cols,
    );
}

#[test]
fn hex_hessian_as_csr_matrix_equals_the_matrix_free_products() {
    let noise = [0.31, 0.77, 0.12, 0.64, 0.49, 0.95, 0.22];
    let g = common::grid3(4, 4, 5, 0.25, &noise);
    let topo = Arc::new(HexTopology::from_mesh(&g).unwrap());
    let x = topo.initial_x();
    let f = HexFunctional::h_omega(topo, 0.8, Scaling3::Index).unwrap();
    let cols: Vec<usize> = (0..x.len()).collect();
    check_entries(&f, &x, &cols);
}
