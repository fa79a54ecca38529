//! Foundation benchmarks: region validation (exact predicates + R*-tree) and TFI, at several
//! sizes so the scaling is visible. Run: `cargo bench -p unamalla-mesh --bench mesh`.
// criterion_group! defines an undocumented `pub fn`; a bench has no public API to document.
#![allow(missing_docs)]

use std::f64::consts::TAU;

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use unamalla_mesh::quality::QualityReport;
use unamalla_mesh::{tfi2, DVec2, Region, TfiParams};

fn wavy_ring(n: usize) -> Vec<DVec2> {
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64 * TAU;
            let r = 10.0 + 0.5 * (37.0 * t).sin() + 0.2 * (301.0 * t).cos();
            DVec2::new(r * t.cos(), r * t.sin())
        })
        .collect()
}

fn region_validation(c: &mut Criterion) {
    let mut g = c.benchmark_group("region_validate");
    g.sample_size(10);
    for n in [1_000usize, 10_000, 100_000] {
        let ring = wavy_ring(n);
        g.bench_with_input(BenchmarkId::from_parameter(n), &ring, |b, ring| {
            b.iter(|| Region::new(black_box(ring.clone()), vec![]).unwrap())
        });
    }
    g.finish();
}

fn sinusoidal_sides(m: usize, n: usize) -> [Vec<DVec2>; 4] {
    let f = |s: f64| 0.1 * (2.0 * TAU * s).sin();
    let b = (0..m)
        .map(|i| {
            let s = i as f64 / (m - 1) as f64;
            DVec2::new(s, f(s))
        })
        .collect();
    let t = (0..m)
        .map(|i| {
            let s = i as f64 / (m - 1) as f64;
            DVec2::new(s, 1.0 + f(s))
        })
        .collect();
    let l = (0..n)
        .map(|j| {
            let s = j as f64 / (n - 1) as f64;
            DVec2::new(f(s), s)
        })
        .collect();
    let r = (0..n)
        .map(|j| {
            let s = j as f64 / (n - 1) as f64;
            DVec2::new(1.0 + f(s), s)
        })
        .collect();
    [b, r, t, l]
}

fn tfi(c: &mut Criterion) {
    let mut g = c.benchmark_group("tfi2_arclength");
    g.sample_size(10);
    for k in [100usize, 300, 1000] {
        let [b, r, t, l] = sinusoidal_sides(k, k);
        g.bench_function(BenchmarkId::from_parameter(k), |bench| {
            bench.iter(|| tfi2(&b, &r, &t, &l, TfiParams::ArcLength).unwrap())
        });
    }
    g.finish();
    let mut g = c.benchmark_group("quality_report");
    g.sample_size(10);
    for k in [100usize, 300, 1000] {
        let [b, r, t, l] = sinusoidal_sides(k, k);
        let grid = tfi2(&b, &r, &t, &l, TfiParams::ArcLength).unwrap();
        g.bench_function(BenchmarkId::from_parameter(k), |bench| {
            bench.iter(|| QualityReport::for_quads(black_box(&grid)))
        });
    }
    g.finish();
}

criterion_group!(benches, region_validation, tfi);
criterion_main!(benches);
