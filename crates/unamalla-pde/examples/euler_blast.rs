//! The application of Cortés Aguirre (2012, chapter 5) with the first-order Euler solver of
//! `unamalla_pde::euler`: a pressure blast in a closed ball (§5.1) or ellipsoid (§5.2)
//! meshed by the hexahedral product's radial grid, written as a `.vtu` of hexahedra with the
//! cell pressure and density.
//!
//! ```text
//! cargo run --release -p unamalla-pde --example euler_blast -- [sphere|ellipsoid] [N] [T] [OUT.vtu]
//! ```
//!
//! * `sphere` (default): the unit ball, p = 5 inside radius 0.2 about (0, 0, −0.4);
//!   `ellipsoid`: semi-axes 0.5, 1, 0.5, p = 5 inside radius 0.1 about (0, 0, −0.4) — the
//!   source's two cases (ρ = 1, u = 0, p = 1 elsewhere, solid walls);
//! * `N` nodes per direction (default 25, the source's 25³ including ghost cells);
//! * `T` the end time (default 0.4);
//! * `OUT.vtu` (default `/tmp/euler-blast.vtu`).
//!
//! Prints the run's report (steps, mass and energy at start and end, pressure range) and the
//! wall time.

use std::time::Instant;

use unamalla_mesh::hexgen::ellipsoid_grid;
use unamalla_mesh::DVec3;
use unamalla_pde::euler::{primitive, EulerOptions, EulerSolver};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let case = args.first().map(String::as_str).unwrap_or("sphere");
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(25);
    let end_time: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0.4);
    let out = args
        .get(3)
        .cloned()
        .unwrap_or_else(|| "/tmp/euler-blast.vtu".to_string());
    let (axes, radius) = match case {
        "sphere" => (DVec3::ONE, 0.2),
        "ellipsoid" => (DVec3::new(0.5, 1.0, 0.5), 0.1),
        other => return Err(format!("unknown case {other}: sphere or ellipsoid").into()),
    };
    let grid = ellipsoid_grid((n, n, n), axes, DVec3::ZERO)?;
    let solver = EulerSolver::new(&grid)?;
    let opts = EulerOptions::until(end_time);
    let centre = DVec3::new(0.0, 0.0, -0.4);
    let mut q = solver.initial_state(opts.gamma, |c| {
        let p = if c.distance(centre) < radius {
            5.0
        } else {
            1.0
        };
        (1.0, DVec3::ZERO, p)
    });
    let t0 = Instant::now();
    let rep = solver.run(&mut q, &opts)?;
    let secs = t0.elapsed().as_secs_f64();
    println!(
        "{case}, {n}³ nodes ({} cells), t = {:.4}: {} steps in {secs:.2} s",
        solver.volumes().len(),
        rep.time,
        rep.steps
    );
    println!(
        "mass {:.12} -> {:.12}, energy {:.12} -> {:.12}",
        rep.mass[0], rep.mass[1], rep.energy[0], rep.energy[1]
    );
    println!(
        "density ≥ {:.4}, pressure in [{:.4}, {:.4}]",
        rep.min_rho_p[0], rep.min_rho_p[1], rep.max_p
    );
    let p = solver.pressure(opts.gamma, &q);
    let rho: Vec<f64> = q.iter().map(|s| primitive(opts.gamma, s).0).collect();
    unamalla_io::write_vtu_hexes(
        &out,
        &grid,
        &[("pressure", p.as_slice()), ("density", rho.as_slice())],
    )?;
    println!("wrote {out}");
    Ok(())
}
