//! Criterion benchmark: untangle + smooth ((6.8), ε = 0.01) the TFI grid of the sinusoidal
//! four-sided region (sample size 10), with the tolerance of `studies/large_grid.rs`
//! (FTOL 1e-9, GTOL off, MAXITER 500; the same for every size).
//!
//! * `smooth_sinusoidal/<solver>/<n>`: each solver from the TFI grid at 100² and 301² nodes
//!   (pointwise Newton at 100² only: minutes per sample at 301²); truncated Newton with the
//!   multigrid preconditioner;
//! * `coarse_to_fine/tn-tr-multigrid/<n>`: [`smooth_coarse_to_fine`] (ratio 3) with TN-TR and
//!   the multigrid preconditioner at 100² and 301², and 1000² when the environment variable
//!   `UNAMALLA_BENCH_1000` is set (ten samples of minutes each on a loaded machine).
//!
//! `cargo bench -p unamalla-optim --bench smooth [-- FILTER]`
// criterion_group! defines an undocumented `pub fn`; a bench has no public API to document.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use unamalla_optim::fixtures::sinusoidal;
use unamalla_optim::{
    smooth, smooth_coarse_to_fine, CoarseToFineOptions, NullObserver, Preconditioner,
    SmoothOptions, Solver, SolverOptions,
};

fn options(s: Solver) -> SmoothOptions {
    SmoothOptions::default().solver(
        SolverOptions::new(s)
            .max_iter(500)
            .ftol(1e-9)
            .gtol(0.0)
            .preconditioner(Preconditioner::Multigrid),
    )
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("smooth_sinusoidal");
    group.sample_size(10);
    for n in [100usize, 301] {
        let g0 = sinusoidal(n, n, 0.1, 2.0).expect("region");
        for s in Solver::ALL {
            if s == Solver::Pointwise && n > 100 {
                continue;
            }
            let opts = options(s);
            group.bench_with_input(BenchmarkId::new(s.name(), n), &n, |b, _| {
                b.iter(|| {
                    let mut g = g0.clone();
                    smooth(&mut g, &opts, &mut NullObserver).expect("smooth")
                })
            });
        }
    }
    group.finish();
    let mut group = c.benchmark_group("coarse_to_fine");
    group.sample_size(10);
    let mut sizes = vec![100usize, 301];
    if std::env::var_os("UNAMALLA_BENCH_1000").is_some() {
        sizes.push(1000);
    }
    for n in sizes {
        let g0 = sinusoidal(n, n, 0.1, 2.0).expect("region");
        let co = CoarseToFineOptions::default().smooth(options(Solver::TnTr));
        group.bench_with_input(BenchmarkId::new("tn-tr-multigrid", n), &n, |b, _| {
            b.iter(|| {
                let mut g = g0.clone();
                smooth_coarse_to_fine(&mut g, &co, &mut NullObserver).expect("c2f")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
