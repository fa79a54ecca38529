//! Criterion benchmark: untangle + smooth ((6.8), ε = 0.01) the TFI grid of the sinusoidal
//! four-sided region with each solver at 100² and 300² nodes (sample size 10). The 1000² case
//! is measured once by `cargo run --release -p unamalla-optim --example large_grid -- 1000`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use unamalla_optim::fixtures::sinusoidal;
use unamalla_optim::{smooth, NullObserver, SmoothOptions, Solver, SolverOptions};

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("smooth_sinusoidal");
    group.sample_size(10);
    for n in [100usize, 300] {
        let g0 = sinusoidal(n, n, 0.1, 2.0).expect("region");
        for s in Solver::ALL {
            if s == Solver::Pointwise && n > 100 {
                // ≈ 5 minutes per sample at 300² (see docs/benchmarks.md)
                continue;
            }
            let opts = SmoothOptions {
                solver: SolverOptions {
                    max_iter: 500,
                    ..SolverOptions::new(s)
                },
                ..SmoothOptions::default()
            };
            group.bench_with_input(BenchmarkId::new(s.name(), n), &n, |b, _| {
                b.iter(|| {
                    let mut g = g0.clone();
                    smooth(&mut g, &opts, &mut NullObserver).expect("smooth")
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
