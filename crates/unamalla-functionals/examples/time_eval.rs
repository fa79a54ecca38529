//! Quick wall-clock timing of value + gradient of `0.9·F_AO + 0.1·H_ω` on an `n × n`-cell grid
//! (default 1000, repeated `reps` times, default 10): `cargo run --release --example time_eval -- 1000 10`. Use `RAYON_NUM_THREADS=1`
//! for one core. The criterion benchmarks in `benches/` are the reference numbers.

use std::sync::Arc;
use std::time::Instant;

use unamalla_functionals::*;
use unamalla_mesh::{DVec2, StructuredGrid2};

fn main() {
    let cells: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1000);
    let m = cells + 1;
    let h = 1.0 / cells as f64;
    let g = StructuredGrid2::from_fn(m, m, |i, j| {
        let inner = i > 0 && j > 0 && i < cells && j < cells;
        let d = if inner {
            0.3 * h
                * DVec2::new(
                    ((i * 7 + j * 13) as f64).sin(),
                    ((i * 3 + j * 5) as f64).cos(),
                )
        } else {
            DVec2::ZERO
        };
        DVec2::new(i as f64 * h, j as f64 * h) + d
    })
    .expect("valid grid");
    let topo = Arc::new(QuadTopology::from_mesh(&g).expect("valid mesh"));
    let abar = topo.alpha_bar();
    let f = QuadFunctional::new(
        topo.clone(),
        Sum::convex(
            0.9,
            AreaOrthogonality,
            HOmega::new(0.5 * abar).expect("ω > 0"),
        )
        .expect("σ"),
    );
    let x = topo.initial_x();
    let mut grad = vec![0.0; f.num_vars()];
    let mut best = f64::INFINITY;
    let mut v = 0.0;
    let reps: usize = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(10);
    for _ in 0..reps {
        let t = Instant::now();
        v = f.value_grad(&x, &mut grad);
        best = best.min(t.elapsed().as_secs_f64());
    }
    println!(
        "{cells}x{cells} cells, {} triangles, {} colours: value_grad best of {reps} = {:.2} ms ({:.1} M triangles/s), value = {v}",
        topo.num_triangles(),
        topo.num_colors(),
        best * 1e3,
        topo.num_triangles() as f64 / best / 1e6
    );
}
