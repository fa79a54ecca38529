//! Criterion benchmarks of map evaluation, the dense det J sampler and the Bernstein test on the
//! S3 star lake at 35×35 (the paper's Titicaca/Havana size).
//!
//! ```sh
//! cargo bench -p unamalla-bspline --bench bspline
//! ```
// criterion_group! defines an undocumented `pub fn`; a bench has no public API to document.
#![allow(missing_docs)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use unamalla_bspline::synthetic::Synthetic;
use unamalla_bspline::{
    bernstein_test, optimize_interior, sample_det_j, ControlNet, Degree, InteriorOptions, TensorMap,
};

fn star_map(degree: Degree) -> TensorMap {
    let b = Synthetic::S3Star.boundary(35, 35).unwrap();
    let mut net = ControlNet::from_boundary(&b).unwrap();
    optimize_interior(&mut net, &InteriorOptions::default()).unwrap();
    TensorMap::new(degree, net).unwrap()
}

fn bench(c: &mut Criterion) {
    let map = star_map(Degree::Biquadratic);
    let pts: Vec<(f64, f64)> = (0..1000)
        .map(|k| ((k as f64 * 0.618_034) % 1.0, (k as f64 * 0.414_214) % 1.0))
        .collect();
    c.bench_function("biquadratic eval ×1000 (Bézier per patch)", |b| {
        b.iter(|| {
            pts.iter()
                .map(|&(x, y)| map.eval(black_box(x), y))
                .fold(0.0, |s, p| s + p.x)
        })
    });
    c.bench_function("biquadratic det J ×1000 (partials)", |b| {
        b.iter(|| {
            pts.iter()
                .map(|&(x, y)| map.det_j(black_box(x), y))
                .sum::<f64>()
        })
    });
    c.bench_function("biquadratic eval ×1000 (Cox–de Boor reference)", |b| {
        b.iter(|| {
            pts.iter()
                .map(|&(x, y)| map.eval_cox_de_boor(black_box(x), y))
                .fold(0.0, |s, p| s + p.x)
        })
    });
    let mut g = c.benchmark_group("sampler");
    g.sample_size(10);
    g.bench_function("sample det J 1000×1000", |b| {
        b.iter(|| sample_det_j(&map, 1000, 1000).unwrap().min)
    });
    g.bench_function("Bernstein test depth 4 (35×35 net)", |b| {
        b.iter(|| bernstein_test(&map, 4).certified())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
