//! Modified-area simplification of a 100,000-vertex ring (criterion; target < 100 ms).
//!
//! Timed: one whole `simplify_region` call on an already validated `Region` (removal with the
//! topology check, building the output region with `Region::from_simple_rings`, Hausdorff
//! distance and area change). Not timed: building and validating the input `Region`. Single-threaded.
//!
//! ```text
//! RAYON_NUM_THREADS=1 cargo bench -p unamalla-contour --bench simplify
//! ```
// criterion_group! defines an undocumented `pub fn`; a bench has no public API to document.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion};
use unamalla_contour::{simplify_region, Method, Preset, SimplifyOptions};
use unamalla_mesh::Region;

#[path = "../tests/common/bench_ring.rs"]
mod bench_ring;
use bench_ring::ring;

fn bench(c: &mut Criterion) {
    let region = Region::new(ring(100_000), vec![]).expect("valid ring");
    let opts = SimplifyOptions::new(Method::ModifiedAreas, Preset::Clean);
    let res = simplify_region(&region, &opts).expect("simplifies");
    eprintln!(
        "modified-areas eps={}: {} -> {} vertices; elapsed (removal + output region) {:?}",
        res.epsilon, res.vertices_before, res.vertices_after, res.elapsed
    );
    let mut g = c.benchmark_group("contour");
    g.sample_size(10);
    g.bench_function("modified_areas_100k", |b| {
        b.iter(|| simplify_region(&region, &opts).expect("simplifies"))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
