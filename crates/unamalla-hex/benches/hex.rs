//! Criterion benchmarks of the structured hexahedral pipeline ([Cortés Aguirre 2012]; the
//! references are listed in `docs/references.md` of the repository; the results are in
//! `docs/benchmarks.md`, "Structured hexahedral meshes"):
//!
//! * `hex/algorithm_a/sphere20`: Algorithm A (`run_hex` with the default options, A only) on
//!   the perturbed sphere 20³ of the thesis (seed 1; grid construction and perturbation are
//!   outside the timed part);
//! * `hex/hessian/node_block/{20,50}`: one Hessian refresh of `H_ω` (ω = 10⁻³·v̄, parametric
//!   scaling) on the perturbed sphere with 20³ / 50³ nodes, with the node-block assembly used
//!   by the solvers (the per-tetrahedron assembly it replaced is private to
//!   `unamalla-functionals` now, where the tests check the two against each other).
//!
//! ```sh
//! CARGO_TARGET_DIR=... cargo bench -p unamalla-hex --bench hex
//! RAYON_NUM_THREADS=1 cargo bench -p unamalla-hex --bench hex -- hessian   # one core
//! ```
// criterion_group! defines an undocumented `pub fn`; a bench has no public API to document.
#![allow(missing_docs)]

use std::sync::Arc;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion, Throughput};
use unamalla_functionals::prelude::*;
use unamalla_functionals::{HexFunctional, HexTopology, Scaling3};
use unamalla_hex::{run_hex, HexAlgorithm, HexCase, HexRunOptions};
use unamalla_mesh::StructuredGrid3;
use unamalla_optim::NullObserver;

fn sphere(nodes: usize) -> StructuredGrid3 {
    let case = HexCase::Sphere;
    let dims = (nodes, nodes, nodes);
    let mut g = case.initial_grid(dims).expect("sphere grid");
    case.default_perturbation(dims)
        .apply(&mut g, 1)
        .expect("perturbation");
    g
}

fn bench_algorithm_a(c: &mut Criterion) {
    let mut group = c.benchmark_group("hex/algorithm_a");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(6));
    let start = sphere(20);
    let opts = HexRunOptions::default().algorithm(HexAlgorithm::A);
    group.bench_function("sphere20", |b| {
        b.iter_batched(
            || start.clone(),
            |mut g| {
                let r = run_hex(&mut g, &opts, &mut NullObserver).expect("run");
                assert_eq!(r.non_convex_cells, 0);
                r
            },
            BatchSize::LargeInput,
        )
    });
    group.finish();
}

fn bench_hessian(c: &mut Criterion) {
    let mut group = c.benchmark_group("hex/hessian");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(4));
    for nodes in [20usize, 50] {
        let g = sphere(nodes);
        let topo = Arc::new(HexTopology::from_mesh(&g).expect("topology"));
        let x = topo.initial_x();
        let scaling = Scaling3::Parametric {
            m: nodes,
            n: nodes,
            p: nodes,
        };
        // ω relative to the mean Jacobian in the same (parametric) scaling
        let f1 = HexFunctional::h_omega(topo.clone(), 1.0, scaling).expect("f");
        let mut v = vec![0.0; f1.num_elements()];
        f1.element_measures(&x, &mut v);
        let vbar_p = v.iter().sum::<f64>() / v.len() as f64;
        let f = HexFunctional::h_omega(topo.clone(), 1e-3 * vbar_p, scaling).expect("f");
        let mut h = f.hessian_pattern();
        f.hessian(&x, &mut h); // builds the slot table once
        group.throughput(Throughput::Elements(10 * topo.num_cells() as u64));
        group.bench_with_input(BenchmarkId::new("node_block", nodes), &nodes, |b, _| {
            b.iter(|| f.hessian(&x, &mut h))
        });
    }
    group.finish();
}

criterion_group!(benches, bench_algorithm_a, bench_hessian);
criterion_main!(benches);
