//! Wall and CPU time of modified-area simplification of the 100,000-vertex benchmark ring
//! (the ring of `benches/simplify.rs`), split into the simplification proper (removal and
//! final validation, `SimplifyResult::elapsed`) and the whole `simplify_region` call (which
//! also computes the Hausdorff distance and area change). CPU time comes from
//! `/proc/self/stat`, so the figure is meaningful on a loaded machine.
//!
//! ```text
//! cargo run --release -p unamalla-contour --example ring_100k
//! ```

use std::time::{Duration, Instant};

use unamalla_contour::{simplify_region, Method, Preset, SimplifyOptions};
use unamalla_mesh::{DVec2, Region};

/// The benchmark ring (same as `benches/simplify.rs`).
fn ring(n: usize) -> Vec<DVec2> {
    let mut s = 0x9E37_79B9_7F4A_7C15u64;
    (0..n)
        .map(|k| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let noise = ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.02;
            let t = std::f64::consts::TAU * k as f64 / n as f64;
            let r = 1000.0 * (1.0 + 0.25 * (7.0 * t).sin() + 0.1 * (23.0 * t).cos()) + noise;
            DVec2::new(r * t.cos(), r * t.sin())
        })
        .collect()
}

/// User + system CPU time of this process (Linux; `None` elsewhere).
fn cpu_time() -> Option<Duration> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: u64 = f.get(11)?.parse::<u64>().ok()? + f.get(12)?.parse::<u64>().ok()?;
    Some(Duration::from_millis(ticks * 10)) // USER_HZ = 100 on Linux
}

fn main() {
    let region = Region::new(ring(100_000), vec![]).expect("valid ring");
    let opts = SimplifyOptions::new(Method::ModifiedAreas, Preset::Clean);
    let runs = 20;
    let mut elapsed = Duration::ZERO;
    let cpu0 = cpu_time();
    let t0 = Instant::now();
    let mut after = 0;
    for _ in 0..runs {
        let res = simplify_region(&region, &opts).expect("simplifies");
        elapsed += res.elapsed;
        after = res.vertices_after;
    }
    let wall = t0.elapsed();
    let cpu = cpu_time().zip(cpu0).map(|(a, b)| a - b);
    println!("100000 -> {after} vertices, {runs} runs");
    println!(
        "simplification (removal + validation), wall: {:.1} ms/run",
        elapsed.as_secs_f64() * 1e3 / runs as f64
    );
    println!(
        "whole simplify_region (with metrics), wall: {:.1} ms/run",
        wall.as_secs_f64() * 1e3 / runs as f64
    );
    if let Some(cpu) = cpu {
        println!(
            "whole simplify_region (with metrics), CPU: {:.1} ms/run",
            cpu.as_secs_f64() * 1e3 / runs as f64
        );
    }
}
