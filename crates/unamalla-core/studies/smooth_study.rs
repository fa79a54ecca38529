//! Smoothing candidates side by side: every region is meshed once per
//! candidate with the same pipeline and the table gives, per run, the global smoothing
//! iterations (counted by the observer), the smooth stage's wall time, the process CPU time
//! (user + sys, from `/proc/self/stat`), the μ ≥ 0.8 share, α₋/ᾱ and the status.
//!
//! ```text
//! cargo run --release -p unamalla-core --example smooth_study -- CELLS REGION.geojson...
//! ```
//!
//! Candidates (`UNAMALLA_STUDY=name,name` selects some):
//! * `default` — the pipeline's defaults: [`default_smooth_options`] ((6.8) at σ =
//!   `DEFAULT_SIGMA` = 0.5 with window FTOL + quality plateau, cap 1000) with
//!   `unamalla_core::multilevel::DEFAULT_COARSE_LEVELS` coarse levels;
//! * `tfi` — the same options smoothed from the transfinite start (no coarse level; the
//!   default before the coarse levels);
//! * `c2f1` / `c2f2` / `c2f3` — one, two or three coarse levels (a quarter of the cells each);
//! * `converged` — the default functional without the σ continuation, same stop rules;
//! * `cap1000` — the stop rules off (FTOL 10⁻¹⁰, GTOL 10⁻⁶, cap 1000): what the old
//!   smoother reached after 1000 iterations without its clock;
//! * `plateau` — the quality plateau alone (no window FTOL);
//! * `sigma1` — σ continuation: 30 iterations at σ = 1 (H_ω only, Winslow-type), then
//!   (6.8) σ = 0.1 with the default stop rules;
//! * `sigma05` — the same with a first stage at σ = 0.5;
//! * `mg` — `default` with the smoothed-aggregation multigrid preconditioner
//!   (`Preconditioner::Multigrid`) in the inner CG instead of block-Jacobi;
//! * `cg20` / `cg80` — `default` with the inner CG capped at 20 or 80 iterations instead of 40;
//! * `final02` / `final03` / `final05` — the default options with the final σ = 0.2, 0.3 or
//!   0.5 instead of 0.1 (no coarse level).
//!
//! With `UNAMALLA_STUDY_TRACE=1` every observer call prints a line `trace N PHASE F α₋/ᾱ μ-share
//! non-convex elapsed` on stderr.
//!
//! With `UNAMALLA_STUDY_PNG=DIR` every run also writes its μ band picture
//! (`unamalla_core::render::quality_png`, 800 px) to `DIR/REGION-CANDIDATE.png`.
//!
//! All candidates but `default` and `c2f*` run without coarse levels. The progress line of the
//! coarse levels (cells and iterations per level) is printed under the table row.

use std::sync::{Arc, Mutex};
use std::time::Instant;

use unamalla_core::io::{read_region_geojson, PartSelector};
use unamalla_core::multilevel::DEFAULT_COARSE_LEVELS;
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

fn candidates() -> Vec<(&'static str, SmoothOptions, usize)> {
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
    let d = default_smooth_options();
    let mut mg = d.clone();
    mg.solver.preconditioner = unamalla_core::optim::Preconditioner::Multigrid;
    let cg = |n: usize| {
        let mut o = default_smooth_options();
        o.solver.cg_max_iter = n;
        o
    };
    let final_sigma = |sigma: f64| {
        let mut o = default_smooth_options();
        o.functional = unamalla_core::optim::SmoothFunctional::block_smoothing(sigma);
        o
    };
    let all = vec![
        ("final02", final_sigma(0.2), 0),
        ("final03", final_sigma(0.3), 0),
        ("final05", final_sigma(0.5), 0),
        (
            "default05",
            {
                let mut o = final_sigma(0.5);
                o.sigma_continuation.clear();
                o
            },
            DEFAULT_COARSE_LEVELS,
        ),
        ("final07", final_sigma(0.7), 0),
        ("final10", final_sigma(1.0), 0),
        ("default", d.clone(), DEFAULT_COARSE_LEVELS),
        ("tfi", d.clone(), 0),
        ("c2f1", d.clone(), 1),
        ("c2f2", d.clone(), 2),
        ("c2f3", d, 3),
        ("converged", conv, 0),
        ("cap1000", cap, 0),
        ("plateau", plateau, 0),
        ("sigma1", s1, 0),
        ("sigma05", s05, 0),
        ("mg", mg, DEFAULT_COARSE_LEVELS),
        ("cg20", cg(20), DEFAULT_COARSE_LEVELS),
        ("cg80", cg(80), DEFAULT_COARSE_LEVELS),
    ];
    match std::env::var("UNAMALLA_STUDY") {
        Ok(sel) => {
            let names: Vec<&str> = sel.split(',').collect();
            all.into_iter()
                .filter(|(n, _, _)| names.contains(n))
                .collect()
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
        for (cand, opts, levels) in candidates() {
            let mut iterations = 0usize;
            let trace = std::env::var_os("UNAMALLA_STUDY_TRACE").is_some();
            let mut count = |m: &Monitor| {
                iterations += 1;
                if trace {
                    eprintln!(
                        "trace {iterations} {:?} F {:.6e} a {:.4e} mu {:?} inocon {} t {:.2}",
                        m.phase,
                        m.f,
                        m.alfamin_rel(),
                        m.mu,
                        m.inocon,
                        m.elapsed.as_secs_f64()
                    );
                }
                Control::Continue
            };
            let cpu0 = cpu_seconds();
            let t0 = Instant::now();
            let coarse_line = Arc::new(Mutex::new(String::new()));
            let line = coarse_line.clone();
            let r = Mesher::new()
                .cells(cells)
                .smooth_options(opts)
                .coarse_levels(levels)
                .on_progress(move |stage, msg| {
                    if stage == Stage::Smooth && msg.starts_with("coarse levels") {
                        *line.lock().unwrap_or_else(|e| e.into_inner()) = msg.to_string();
                    }
                })
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
                    if let Ok(dir) = std::env::var("UNAMALLA_STUDY_PNG") {
                        let png = unamalla_core::render::quality_png(&r.mesh, None, 800);
                        match png.map(|b| std::fs::write(format!("{dir}/{name}-{cand}.png"), b)) {
                            Ok(Ok(())) => {}
                            Ok(Err(e)) => eprintln!("{name} {cand}: png not written: {e}"),
                            Err(e) => eprintln!("{name} {cand}: png not made: {e}"),
                        }
                    }
                    println!(
                        "| {name} | {cand} | {} | {iterations} | {smooth_s:.2} | {cpu:.1} | {:.2} | {:.4} | {} |",
                        rep.cells, rep.mu_ge_0_8_percent, rep.min_alpha_over_mean, rep.smoothing
                    );
                }
                Err(e) => println!("| {name} | {cand} | error: {e} |"),
            }
            let line = coarse_line.lock().unwrap_or_else(|e| e.into_inner());
            if !line.is_empty() {
                eprintln!("  {name} {cand}: {line}");
            }
        }
    }
}
