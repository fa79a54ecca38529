//! Criterion benchmarks of the whole job, through the facade a user adds (`unamalla-core`):
//!
//! * `mesh/<region>/<cells>`: [`Mesher::mesh`] with the default options on a bundled region
//!   (`fixtures/regions/`) at several sizes — kiwi-bird at 2,000, 5,000 and 20,000 cells and
//!   texas at 20,000 — so the time can be read against the cell count (region loading is
//!   outside the timed part; every mesh is checked to have no non-convex cell);
//! * `decompose/<region>/20000`: the layout choice alone ([`choose_layout`]: the candidate
//!   layouts, their predicted quality and the re-splits) on the region the mesher meshes
//!   ([`Mesher::prepare_region`]) for 20,000 cells, texas and chesapeake-bay;
//! * `hex/sphere20`: the hexahedral product with its default options (Algorithm A, then B) on
//!   the perturbed sphere with 20³ nodes (`unamalla hex sphere`; grid construction outside the
//!   timed part);
//! * `smooth/sinusoidal_c2f/<N>`: the pipeline's smoother ([`default_smooth_options`]) through
//!   the coarse-to-fine levels ([`smooth_coarse_to_fine`]) on the sinusoidal TFI grid with `N²`
//!   nodes (amplitude 0.1, two waves), N = 300 and 1000 — the time-to-quality case of the
//!   smoothing issue (its quality against a converged reference is printed by the example
//!   `sinusoidal_quality`).
//!
//! ```sh
//! cargo bench -p unamalla-workspace --bench whole_job                 # everything
//! cargo bench -p unamalla-workspace --bench whole_job -- mesh/kiwi    # one group
//! ```
//!
//! Results and the machine's load: `docs/benchmarks.md`, "Whole job (criterion)".
// criterion_group! defines an undocumented `pub fn`; a bench has no public API to document.
#![allow(missing_docs)]

use std::path::PathBuf;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion};
use unamalla_core::decompose::DecomposeOptions;
use unamalla_core::io::input::{load_region, LoadOptions};
use unamalla_core::mesh::Region;
use unamalla_core::optim::fixtures::sinusoidal;
use unamalla_core::optim::{smooth_coarse_to_fine, CoarseToFineOptions, NullObserver};
use unamalla_core::pipeline::{choose_layout, default_smooth_options, MeshSize, Mesher};
use unamalla_hex::{run_hex, HexCase, HexRunOptions};

fn region(name: &str) -> Region {
    let path: PathBuf = [env!("CARGO_MANIFEST_DIR"), "fixtures", "regions", name]
        .iter()
        .collect();
    load_region(&path, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .region
}

fn bench_mesh(c: &mut Criterion) {
    let mut group = c.benchmark_group("mesh");
    group.sample_size(10);
    group.warm_up_time(Duration::from_secs(1));
    group.measurement_time(Duration::from_secs(10));
    for (name, cells) in [
        ("kiwi-bird", 2_000),
        ("kiwi-bird", 5_000),
        ("kiwi-bird", 20_000),
        ("texas", 20_000),
    ] {
        let r = region(&format!("{name}.geojson"));
        group.bench_with_input(BenchmarkId::new(name, cells), &r, |b, r| {
            b.iter(|| {
                let m = Mesher::new().cells(cells).mesh(r).expect("mesh");
                assert_eq!(m.report.non_convex_cells, 0);
                m
            })
        });
    }
    group.finish();
}

fn bench_decompose(c: &mut Criterion) {
    let mut group = c.benchmark_group("decompose");
    group.sample_size(10);
    group.warm_up_time(Duration::from_secs(1));
    group.measurement_time(Duration::from_secs(6));
    let cells = 20_000;
    for name in ["texas", "chesapeake-bay"] {
        let prepared = Mesher::new()
            .cells(cells)
            .prepare_region(&region(&format!("{name}.geojson")))
            .expect("prepare");
        let r = prepared.mesh_region;
        // as the pipeline does: the chord layouts sample the boundary at the cell size
        let opts = DecomposeOptions::default().cell_size(Some((r.area() / cells as f64).sqrt()));
        group.bench_with_input(BenchmarkId::new(name, cells), &r, |b, r| {
            b.iter(|| choose_layout(r, &opts, MeshSize::Cells(cells)).expect("layout"))
        });
    }
    group.finish();
}

fn bench_hex(c: &mut Criterion) {
    let mut group = c.benchmark_group("hex");
    group.sample_size(10);
    group.warm_up_time(Duration::from_secs(1));
    group.measurement_time(Duration::from_secs(8));
    let case = HexCase::Sphere;
    let dims = (20, 20, 20);
    let mut start = case.initial_grid(dims).expect("sphere grid");
    case.default_perturbation(dims)
        .apply(&mut start, 1)
        .expect("perturbation");
    let opts = HexRunOptions::default();
    group.bench_function("sphere20", |b| {
        b.iter_batched(
            || start.clone(),
            |mut g| {
                let r = run_hex(&mut g, &opts, &mut NullObserver).expect("hex run");
                assert_eq!(r.non_convex_cells, 0);
                r
            },
            BatchSize::LargeInput,
        )
    });
    group.finish();
}

fn bench_smooth(c: &mut Criterion) {
    let mut group = c.benchmark_group("smooth/sinusoidal_c2f");
    group.sample_size(10);
    group.warm_up_time(Duration::from_secs(1));
    group.measurement_time(Duration::from_secs(20));
    for n in [300usize, 1000] {
        let g0 = sinusoidal(n, n, 0.1, 2.0).expect("sinusoidal grid");
        let opts = CoarseToFineOptions::default().smooth(default_smooth_options());
        group.bench_with_input(BenchmarkId::from_parameter(n), &g0, |b, g0| {
            b.iter_batched(
                || g0.clone(),
                |mut g| smooth_coarse_to_fine(&mut g, &opts, &mut NullObserver).expect("c2f"),
                BatchSize::LargeInput,
            )
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    bench_mesh,
    bench_decompose,
    bench_hex,
    bench_smooth
);
criterion_main!(benches);
