//! Criterion benchmark of problem (5.10) on generated grid decompositions with 10, 100 and 1000 blocks:
//! assembly, the default MILP path (microlp, including the network-flow optimality certificate), the exact
//! network-flow path, and — with `--features cbc` — the Cbc backend.
//!
//! Run: `cargo bench -p unamalla-compat-ilp --bench compat_ilp`
// criterion_group! defines an undocumented `pub fn`; a bench has no public API to document.
#![allow(missing_docs)]

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use unamalla_compat_ilp::fixtures::grid_decomposition;
use unamalla_compat_ilp::{solve, CompatSystem, Method, MilpBackend, SolveOptions};

/// (blocks, rows, cols)
const SIZES: [(usize, usize, usize); 3] = [(10, 2, 5), (100, 10, 10), (1000, 25, 40)];

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("compat_ilp");
    group.sample_size(10);
    for (blocks, rows, cols) in SIZES {
        let problem = grid_decomposition(rows, cols, 42);
        let opts = SolveOptions::density(2);
        // sanity: both paths agree before timing
        let a = solve(&problem, &opts).expect("milp");
        let b = solve(&problem, &opts.with_method(Method::NetworkFlow)).expect("flow");
        assert_eq!(a.objective, b.objective);
        eprintln!(
            "{blocks} blocks: {} curves, {} cuts, objective {}, milp path {} (rejected {:?})",
            problem.curves.len(),
            problem.cuts.len(),
            a.objective,
            a.path,
            a.rejected
        );
        group.bench_with_input(BenchmarkId::new("assemble", blocks), &problem, |bch, p| {
            bch.iter(|| CompatSystem::assemble(black_box(p)).unwrap())
        });
        group.bench_with_input(
            BenchmarkId::new("network_flow", blocks),
            &problem,
            |bch, p| {
                let o = opts.with_method(Method::NetworkFlow);
                bch.iter(|| solve(black_box(p), &o).unwrap())
            },
        );
        group.bench_with_input(
            BenchmarkId::new("milp_microlp", blocks),
            &problem,
            |bch, p| {
                let o = opts.with_method(Method::Milp(MilpBackend::Microlp));
                bch.iter(|| solve(black_box(p), &o).unwrap())
            },
        );
        #[cfg(feature = "cbc")]
        group.bench_with_input(BenchmarkId::new("milp_cbc", blocks), &problem, |bch, p| {
            let o = opts.with_method(Method::Milp(MilpBackend::Cbc));
            bch.iter(|| solve(black_box(p), &o).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
