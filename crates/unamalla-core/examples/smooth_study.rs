//! Smoothing candidates side by side (issue #23 item 3): every region is meshed once per
//! candidate with the same pipeline and the table gives, per run, the global smoothing
//! iterations (counted by the observer), the smooth stage's wall time, the process CPU time
//! (user + sys, from `/proc/self/stat`), the μ ≥ 0.8 share, α₋/ᾱ and the status.
//!
//! ```text
//! cargo run --release -p unamalla-core --example smooth_study -- CELLS REGION.geojson...
//! ```
//!
//! Candidates (`UNAMALLA_STUDY=name,name` selects some):
//! * `default` — [`default_smooth_options`] (σ = 0.5 first stage, then σ = 0.1 with window
//!   FTOL + quality plateau, cap 1000);
//! * `converged` — σ = 0.1 alone with the same stop rules;
//! * `cap1000` — the stop rules off (FTOL 10⁻¹⁰, GTOL 10⁻⁶, cap 1000): what the old
//!   smoother reached after 1000 iterations without its clock;
//! * `plateau` — the quality plateau alone (no window FTOL);
//! * `sigma1` — σ continuation: 30 iterations at σ = 1 (H_ω only, Winslow-type), then
//!   (6.8) σ = 0.1 with the default stop rules;
//! * `sigma05` — the same with a first stage at σ = 0.5.

use std::time::Instant;

use unamalla_core::io::{read_region_geojson, PartSelector};
use unamalla_core::optim::{Control, Monitor, SmoothOptions, StopRules};
use unamalla_core::pipeline::{default_smooth_options, Mesher, Stage};

/// User + system CPU seconds of this process so far (Linux `/proc/self/stat`, 100 ticks/s).
fn cpu_seconds() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let rest = s.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = rest.split_whitespace().collect();
    let tick = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    // fields after the command name: state is index 0, utime 11, stime 12
    (tick(11) + tick(12)) / 100.0
}

fn candidates() -> Vec<(&'static str, SmoothOptions)> {
    let mut conv = default_smooth_options();
    conv.sigma_continuation.clear();
    let mut cap = conv.clone();
    cap.solver.stop = StopRules::default();
    let mut plateau = conv.clone();
    plateau.solver.stop.window_ftol = 0.0;
    let mut s1 = default_smooth_options();
    s1.sigma_continuation = vec![1.0];
    s1.continuation_iter = 30;
    let mut s05 = default_smooth_options();
    s05.sigma_continuation = vec![0.5];
    s05.continuation_iter = 30;
    let all = vec![
        ("default", default_smooth_options()),
        ("converged", conv),
        ("cap1000", cap),
        ("plateau", plateau),
        ("sigma1", s1),
        ("sigma05", s05),
    ];
    match std::env::var("UNAMALLA_STUDY") {
        Ok(sel) => {
            let names: Vec<&str> = sel.split(',').collect();
            all.into_iter().filter(|(n, _)| names.contains(n)).collect()
        }
        Err(_) => all,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let cells: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(20_000);
    println!(
        "| region | candidate | cells | iterations | smooth s | CPU s | μ≥0.8 % | α₋/ᾱ | status |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for path in &args[2.min(args.len())..] {
        let name = std::path::Path::new(path)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let region = match read_region_geojson(path, PartSelector::Largest) {
            Ok(r) => r,
            Err(e) => {
                println!("| {name} | error: {e} |");
                continue;
            }
        };
        for (cand, opts) in candidates() {
            let mut iterations = 0usize;
            let mut count = |_: &Monitor| {
                iterations += 1;
                Control::Continue
            };
            let cpu0 = cpu_seconds();
            let t0 = Instant::now();
            let r = Mesher::new()
                .cells(cells)
                .smooth_options(opts)
                .mesh_observed(&region, &mut count);
            let cpu = cpu_seconds() - cpu0;
            let _wall = t0.elapsed();
            match r {
                Ok(r) => {
                    let rep = &r.report;
                    let smooth_s = rep
                        .stage_seconds
                        .iter()
                        .find(|(s, _)| *s == Stage::Smooth)
                        .map_or(f64::NAN, |(_, t)| *t);
                    println!(
                        "| {name} | {cand} | {} | {iterations} | {smooth_s:.2} | {cpu:.1} | {:.2} | {:.4} | {} |",
                        rep.cells, rep.mu_ge_0_8_percent, rep.min_alpha_over_mean, rep.smoothing
                    );
                }
                Err(e) => println!("| {name} | {cand} | error: {e} |"),
            }
        }
    }
}
