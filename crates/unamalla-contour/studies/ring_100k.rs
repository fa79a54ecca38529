//! Wall and CPU time of modified-area simplification of the 100,000-vertex benchmark ring
//! (the ring of `benches/simplify.rs`; target < 100 ms). Timed: one `simplify_region`
//! call on an already validated `Region` — the topology-safe removal, building the output
//! region (`Region::from_simple_rings`, O(n) checks) and the metrics (Hausdorff distance, area change); **not**
//! timed: building and validating the input region. Prints the best and median wall time
//! over the runs (default 21, after one warm-up call), the same for
//! `SimplifyResult::elapsed` (without the metrics), and the mean CPU time of the thread
//! (meaningful on a loaded machine). Single-threaded (modified areas uses no rayon).
//!
//! ```text
//! RAYON_NUM_THREADS=1 cargo run --release -p unamalla-contour --example ring_100k [-- runs]
//! perf stat -e task-clock target/release/examples/ring_100k   # CPU time of the process
//! ```

use std::time::{Duration, Instant};

use unamalla_contour::{simplify_region, Method, Preset, SimplifyOptions};
use unamalla_mesh::Region;

#[path = "../tests/common/bench_ring.rs"]
mod bench_ring;
use bench_ring::ring;

/// CPU time consumed by this thread so far (Linux `/proc/thread-self/schedstat`, first field,
/// nanoseconds; `None` elsewhere). Its resolution may be a scheduler tick, so it is summed over
/// all runs.
fn thread_cpu() -> Option<Duration> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(Duration::from_nanos(
        s.split_whitespace().next()?.parse().ok()?,
    ))
}

fn main() {
    let runs: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(21);
    let region = Region::new(ring(100_000), vec![]).expect("valid ring");
    let opts = SimplifyOptions::new(Method::ModifiedAreas, Preset::Clean);
    // warm-up call (page faults of the first allocations), not timed
    let first = simplify_region(&region, &opts).expect("simplifies");
    let mut walls = Vec::with_capacity(runs);
    let mut elapsed = Vec::with_capacity(runs);
    let cpu0 = thread_cpu();
    for _ in 0..runs {
        let t = Instant::now();
        let res = simplify_region(&region, &opts).expect("simplifies");
        walls.push(t.elapsed());
        elapsed.push(res.elapsed);
    }
    let cpu = thread_cpu().zip(cpu0).map(|(a, b)| a - b);
    walls.sort();
    elapsed.sort();
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    println!(
        "modified-areas eps = {}: {} -> {} vertices, Hausdorff {:.6}, area change {:.3e}; {runs} timed runs",
        first.epsilon,
        first.vertices_before,
        first.vertices_after,
        first.hausdorff,
        first.relative_area_change
    );
    println!(
        "whole simplify_region call, wall: best {:.1} ms, median {:.1} ms",
        ms(walls[0]),
        ms(walls[runs / 2])
    );
    println!(
        "simplification without metrics (SimplifyResult::elapsed), wall: best {:.1} ms, median {:.1} ms",
        ms(elapsed[0]),
        ms(elapsed[runs / 2])
    );
    if let Some(cpu) = cpu {
        println!(
            "whole simplify_region call, CPU of this thread: mean {:.1} ms",
            ms(cpu) / runs as f64
        );
    }
}
