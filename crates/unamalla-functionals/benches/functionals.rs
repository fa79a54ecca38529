//! Criterion benchmarks: value + gradient and Hessian refresh of `0.9·F_AO + 0.1·H_ω`
//! ([Méndez 2023, (6.8)], σ = 0.1) on quad grids and of `H_ω` (10 tets per hex) on hex grids.
//! Throughput is reported in triangles (2D, 4 per cell) or tetrahedra (3D, 10 per cell) per second.
//! Run once with `RAYON_NUM_THREADS=1` (one core) and once without.
//!
//! Sizes can be restricted with the environment variable `UNAMALLA_BENCH_SIZES`, e.g.
//! `UNAMALLA_BENCH_SIZES=q100,q300,q1000,h20,h50,h100` (the default is all of them).
// criterion_group! defines an undocumented `pub fn`; a bench has no public API to document.
#![allow(missing_docs)]

use std::sync::Arc;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use unamalla_functionals::*;
use unamalla_mesh::{DVec2, DVec3, StructuredGrid2, StructuredGrid3};

fn wanted(tag: &str) -> bool {
    match std::env::var("UNAMALLA_BENCH_SIZES") {
        Ok(s) => s.split(',').any(|t| t.trim() == tag),
        Err(_) => true,
    }
}

/// Deterministic pseudo-random numbers in [−½, ½).
fn noise(i: usize) -> f64 {
    let mut z = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z ^= z >> 31;
    z = z.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z ^= z >> 29;
    (z >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}

fn quad_grid(cells: usize) -> StructuredGrid2 {
    let m = cells + 1;
    StructuredGrid2::from_fn(m, m, |i, j| {
        let h = 1.0 / cells as f64;
        let inner = i > 0 && j > 0 && i < cells && j < cells;
        let d = if inner {
            DVec2::new(noise(2 * (j * m + i)), noise(2 * (j * m + i) + 1)) * (0.3 * h)
        } else {
            DVec2::ZERO
        };
        DVec2::new(i as f64 * h, j as f64 * h) + d
    })
    .unwrap()
}

fn hex_grid(cells: usize) -> StructuredGrid3 {
    let m = cells + 1;
    StructuredGrid3::from_fn(m, m, m, |i, j, k| {
        let h = 1.0 / cells as f64;
        let inner = i > 0 && j > 0 && k > 0 && i < cells && j < cells && k < cells;
        let id = 3 * ((k * m + j) * m + i);
        let d = if inner {
            DVec3::new(noise(id), noise(id + 1), noise(id + 2)) * (0.2 * h)
        } else {
            DVec3::ZERO
        };
        DVec3::new(i as f64, j as f64, k as f64) * h + d
    })
    .unwrap()
}

fn bench_2d(c: &mut Criterion) {
    let mut group = c.benchmark_group("quad_ao_homega");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(3));
    for cells in [100usize, 300, 1000] {
        if !wanted(&format!("q{cells}")) {
            continue;
        }
        let g = quad_grid(cells);
        let topo = Arc::new(QuadTopology::from_mesh(&g).unwrap());
        let abar = topo.alpha_bar();
        let sum = KernelExpr::convex(
            0.9,
            AreaOrthogonality.into(),
            HOmega::new(0.5 * abar).unwrap().into(),
        )
        .unwrap();
        let f = QuadFunctional::new(topo.clone(), sum.clone());
        let x = topo.initial_x();
        let mut grad = vec![0.0; f.num_vars()];
        group.throughput(Throughput::Elements(topo.num_triangles() as u64));
        group.bench_with_input(BenchmarkId::new("value_grad", cells), &cells, |b, _| {
            b.iter(|| f.value_grad(&x, &mut grad))
        });
        if cells == 1000 {
            // the general (not fused) plan on the same functional, for comparison
            let fd = QuadFunctional::new(topo.clone(), KernelExpr::nested_sum([(1.0, sum)]));
            group.bench_with_input(BenchmarkId::new("value_grad_dyn", cells), &cells, |b, _| {
                b.iter(|| fd.value_grad(&x, &mut grad))
            });
        }
        let mut h = f.hessian_pattern();
        group.bench_with_input(BenchmarkId::new("hessian", cells), &cells, |b, _| {
            b.iter(|| f.hessian(&x, &mut h))
        });
        // the two ways of a Hessian-vector product for CG: matrix-free and CSR SpMV
        let v = grad.clone();
        let mut out = vec![0.0; f.num_vars()];
        group.bench_with_input(
            BenchmarkId::new("hess_vec_matrix_free", cells),
            &cells,
            |b, _| b.iter(|| f.hess_vec(&x, &v, &mut out)),
        );
        group.bench_with_input(BenchmarkId::new("csr_mul_vec", cells), &cells, |b, _| {
            b.iter(|| h.mul_vec(&v, &mut out))
        });
    }
    group.finish();
}

fn bench_3d(c: &mut Criterion) {
    let mut group = c.benchmark_group("hex_homega");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(3));
    for cells in [20usize, 50, 100] {
        if !wanted(&format!("h{cells}")) {
            continue;
        }
        let g = hex_grid(cells);
        let topo = Arc::new(HexTopology::from_mesh(&g).unwrap());
        let f = HexFunctional::h_omega(
            topo.clone(),
            0.5,
            Scaling3::Parametric {
                m: cells + 1,
                n: cells + 1,
                p: cells + 1,
            },
        )
        .unwrap();
        let x = topo.initial_x();
        let mut grad = vec![0.0; f.num_vars()];
        group.throughput(Throughput::Elements(10 * topo.num_cells() as u64));
        group.bench_with_input(BenchmarkId::new("value_grad", cells), &cells, |b, _| {
            b.iter(|| f.value_grad(&x, &mut grad))
        });
        let mut h = f.hessian_pattern();
        group.bench_with_input(BenchmarkId::new("hessian", cells), &cells, |b, _| {
            b.iter(|| f.hessian(&x, &mut h))
        });
    }
    group.finish();
}

criterion_group!(benches, bench_2d, bench_3d);
criterion_main!(benches);
