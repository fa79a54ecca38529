//! Timing of `0.9·F_AO + 0.1·H_ω` ([Méndez 2023, (6.8)], σ = 0.1, ω = ᾱ/2) on an `n × n`-cell grid:
//! value + gradient, Hessian refresh, matrix-free Hessian-vector product and CSR SpMV, with the
//! evaluator's fused plan (`KernelExpr::convex(0.9, F_AO, H_ω)`) and, for comparison, the general
//! plan (the same sum wrapped in a one-part `nested_sum`, which the evaluator does not fuse).
//!
//! ```text
//! cargo run --release -p unamalla-functionals --example time_eval -- [cells=1000] [reps=10]
//! RAYON_NUM_THREADS=1 .../time_eval 1000 21     # one core
//! ```
//!
//! For every operation it prints the best wall time and the best **CPU time** of one call (CPU
//! time of the whole process, read from `/proc/self/task/*/schedstat` in nanoseconds, so it is
//! meaningful on a loaded machine where wall time is not). The criterion benchmarks in
//! `benches/` give the statistics.

use std::sync::Arc;
use std::time::Instant;

use unamalla_functionals::*;
use unamalla_mesh::{DVec2, StructuredGrid2};

/// CPU time of all threads of this process in nanoseconds (Linux; 0 elsewhere).
fn cpu_ns() -> u64 {
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else {
        return 0;
    };
    dir.filter_map(|e| e.ok())
        .filter_map(|e| std::fs::read_to_string(e.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .sum()
}

/// Best wall and best CPU milliseconds of `reps` calls of `f`.
fn time(reps: usize, mut f: impl FnMut()) -> (f64, f64) {
    let (mut wall, mut cpu) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..reps {
        let c0 = cpu_ns();
        let t = Instant::now();
        f();
        wall = wall.min(t.elapsed().as_secs_f64() * 1e3);
        cpu = cpu.min((cpu_ns() - c0) as f64 * 1e-6);
    }
    (wall, cpu)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let cells: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(1000);
    let reps: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(10);
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
    let homega = HOmega::new(0.5 * abar).expect("ω > 0");
    let sum = KernelExpr::convex(0.9, AreaOrthogonality.into(), homega.into()).expect("σ");
    let f = QuadFunctional::new(topo.clone(), sum.clone());
    let fd = QuadFunctional::new(topo.clone(), KernelExpr::nested_sum([(1.0, sum)]));
    let x = topo.initial_x();
    let n = f.num_vars();
    let mut grad = vec![0.0; n];
    let mut out = vec![0.0; n];
    let tri = topo.num_triangles() as f64;
    let threads = rayon::current_num_threads();
    println!(
        "{cells}x{cells} cells, {} triangles, {} colours, {threads} rayon thread(s), best of {reps}:",
        topo.num_triangles(),
        topo.num_colors(),
    );
    let report = |name: &str, (wall, cpu): (f64, f64)| {
        println!(
            "  {name:<28} wall {wall:8.2} ms  cpu {cpu:8.2} ms  ({:.1} M triangles/s wall)",
            tri / wall / 1e3
        );
    };
    let mut v = 0.0;
    report(
        "value_grad (fused)",
        time(reps, || v = f.value_grad(&x, &mut grad)),
    );
    report(
        "value_grad (general)",
        time(reps, || v = fd.value_grad(&x, &mut grad)),
    );
    report("value (fused)", time(reps, || v = f.value(&x)));
    let mut hm = f.hessian_pattern();
    report(
        "hessian refresh (fused)",
        time(reps, || f.hessian(&x, &mut hm)),
    );
    report(
        "hessian refresh (general)",
        time(reps, || fd.hessian(&x, &mut hm)),
    );
    report(
        "hess_vec matrix-free",
        time(reps, || f.hess_vec(&x, &grad, &mut out)),
    );
    report("CSR mul_vec", time(reps, || hm.mul_vec(&grad, &mut out)));
    println!("  value = {v}, Hessian nnz = {}", hm.nnz());
}
