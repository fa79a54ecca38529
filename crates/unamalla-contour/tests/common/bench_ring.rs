//! The benchmark ring, shared by `benches/simplify.rs`, `studies/ring_100k.rs` and
//! `tests/baseline.rs` (included with `#[path]`): the timed input and its regression test are
//! the same curve.

use unamalla_mesh::DVec2;

/// A wavy, slightly noisy closed curve with `n` vertices (deterministic): radius
/// `1000·(1 + 0.25·sin 7t + 0.1·cos 23t)` plus noise of ±0.01 from a fixed LCG.
pub fn ring(n: usize) -> Vec<DVec2> {
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
