//! Criterion benchmark: our CSR Hessian against `nalgebra_sparse::CsrMatrix` (feature
//! `nalgebra-sparse`) for what the solvers do with it, on Winslow's functional on a
//! `(cells + 1)²` grid of the unit square with interior nodes moved by up to 0.15 h
//! (deterministic), 100² and 300² cells:
//!
//! * `refresh/ours`: `Hessian::hessian`, the values refreshed in place (parallel);
//! * `refresh/ours+copy-into-nalgebra`: the same, then [`Csr::copy_values_into`] an existing
//!   `CsrMatrix` of the same pattern (how a nalgebra-sparse user keeps one up to date);
//! * `refresh/ours+convert-to-nalgebra`: the same, then a fresh [`Csr::to_nalgebra_sparse`];
//! * `spmv/ours`: `Csr::mul_vec` (parallel over rows); `spmv/nalgebra`: `&CsrMatrix * &DVector`.
//!
//! `cargo bench -p unamalla-functionals --bench csr_nalgebra`
// criterion_group! defines an undocumented `pub fn`; a bench has no public API to document.
#![allow(missing_docs)]

use std::sync::Arc;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::DVector;
use unamalla_functionals::*;
use unamalla_mesh::{DVec2, StructuredGrid2};

fn grid(cells: usize) -> StructuredGrid2 {
    let m = cells + 1;
    let h = 1.0 / cells as f64;
    StructuredGrid2::from_fn(m, m, |i, j| {
        let inner = i > 0 && j > 0 && i < cells && j < cells;
        let k = (j * m + i) as f64;
        let d = if inner {
            DVec2::new((k * 0.618).fract() - 0.5, (k * 0.414).fract() - 0.5) * (0.3 * h)
        } else {
            DVec2::ZERO
        };
        DVec2::new(i as f64 * h, j as f64 * h) + d
    })
    .expect("grid")
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("csr_nalgebra");
    group.sample_size(20);
    for cells in [100usize, 300] {
        let g = grid(cells);
        let topo = Arc::new(QuadTopology::from_mesh(&g).expect("topology"));
        let x = topo.initial_x();
        let f = QuadFunctional::new(topo, Smoothness::new());
        let mut h = f.hessian_pattern();
        f.hessian(&x, &mut h);
        let mut m = h.to_nalgebra_sparse().expect("valid CSR");
        group.bench_with_input(BenchmarkId::new("refresh/ours", cells), &cells, |b, _| {
            b.iter(|| f.hessian(&x, &mut h))
        });
        group.bench_with_input(
            BenchmarkId::new("refresh/ours+copy-into-nalgebra", cells),
            &cells,
            |b, _| {
                b.iter(|| {
                    f.hessian(&x, &mut h);
                    h.copy_values_into(&mut m).expect("same pattern")
                })
            },
        );
        group.bench_with_input(
            BenchmarkId::new("refresh/ours+convert-to-nalgebra", cells),
            &cells,
            |b, _| {
                b.iter(|| {
                    f.hessian(&x, &mut h);
                    h.to_nalgebra_sparse().expect("valid CSR")
                })
            },
        );
        let v: Vec<f64> = (0..x.len()).map(|k| (k as f64 * 0.37).sin()).collect();
        let dv = DVector::from_vec(v.clone());
        let mut out = vec![0.0; x.len()];
        group.bench_with_input(BenchmarkId::new("spmv/ours", cells), &cells, |b, _| {
            b.iter(|| h.mul_vec(&v, &mut out))
        });
        group.bench_with_input(BenchmarkId::new("spmv/nalgebra", cells), &cells, |b, _| {
            b.iter(|| &m * &dv)
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
