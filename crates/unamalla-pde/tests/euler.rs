//! The Euler finite-volume solver (`unamalla_pde::euler`, the application of Cortés
//! Aguirre 2012, chapter 5): Sod's shock tube against the exact Riemann solution, and the
//! source's blast in a closed ball — conservation, positivity and the mesh's mirror symmetry.

use unamalla_mesh::hexgen::ellipsoid_grid;
use unamalla_mesh::{DVec3, StructuredGrid3};
use unamalla_pde::euler::{primitive, EulerOptions, EulerSolver};

const GAMMA: f64 = 1.4;

/// Toro's exact solution of the Riemann problem (Toro 2009, *Riemann Solvers and Numerical
/// Methods for Fluid Dynamics*, §4.2–4.5): the density at `s = x/t` for left and right states
/// `(ρ, u, p)`. The star pressure solves `f_L(p) + f_R(p) + u_R − u_L = 0` by bisection
/// (`f` increasing in `p`).
fn exact_density(l: (f64, f64, f64), r: (f64, f64, f64), s: f64) -> f64 {
    let g = GAMMA;
    let c = |(rho, _, p): (f64, f64, f64)| (g * p / rho).sqrt();
    let fk = |p: f64, (rho, _, pk): (f64, f64, f64)| {
        if p > pk {
            let a = 2.0 / ((g + 1.0) * rho);
            let b = (g - 1.0) / (g + 1.0) * pk;
            (p - pk) * (a / (p + b)).sqrt()
        } else {
            2.0 * c((rho, 0.0, pk)) / (g - 1.0) * ((p / pk).powf((g - 1.0) / (2.0 * g)) - 1.0)
        }
    };
    let (mut lo, mut hi) = (1e-10, 100.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if fk(mid, l) + fk(mid, r) + r.1 - l.1 > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let ps = 0.5 * (lo + hi);
    let us = 0.5 * (l.1 + r.1) + 0.5 * (fk(ps, r) - fk(ps, l));
    let gm = (g - 1.0) / (g + 1.0);
    let star = |(rho, _, pk): (f64, f64, f64)| {
        if ps > pk {
            rho * (ps / pk + gm) / (gm * ps / pk + 1.0)
        } else {
            rho * (ps / pk).powf(1.0 / g)
        }
    };
    if s <= us {
        let cl = c(l);
        if ps > l.2 {
            let sl = l.1 - cl * ((g + 1.0) / (2.0 * g) * ps / l.2 + (g - 1.0) / (2.0 * g)).sqrt();
            if s <= sl {
                l.0
            } else {
                star(l)
            }
        } else {
            let head = l.1 - cl;
            let tail = us - cl * (ps / l.2).powf((g - 1.0) / (2.0 * g));
            if s <= head {
                l.0
            } else if s > tail {
                star(l)
            } else {
                l.0 * (2.0 / (g + 1.0) + (g - 1.0) / ((g + 1.0) * cl) * (l.1 - s))
                    .powf(2.0 / (g - 1.0))
            }
        }
    } else {
        let cr = c(r);
        if ps > r.2 {
            let sr = r.1 + cr * ((g + 1.0) / (2.0 * g) * ps / r.2 + (g - 1.0) / (2.0 * g)).sqrt();
            if s >= sr {
                r.0
            } else {
                star(r)
            }
        } else {
            let head = r.1 + cr;
            let tail = us + cr * (ps / r.2).powf((g - 1.0) / (2.0 * g));
            if s >= head {
                r.0
            } else if s <= tail {
                star(r)
            } else {
                r.0 * (2.0 / (g + 1.0) - (g - 1.0) / ((g + 1.0) * cr) * (r.1 - s))
                    .powf(2.0 / (g - 1.0))
            }
        }
    }
}

/// The L1 density error of Sod's problem at t = 0.2 on `n` cells of a tube [0, 1] × [0, 0.02]²
/// (one cell across, solid walls all round; the waves stay inside [0.26, 0.85] until then).
fn sod_error(n: usize) -> f64 {
    let w = 0.02;
    let g = StructuredGrid3::from_fn(n + 1, 2, 2, |i, j, k| {
        DVec3::new(i as f64 / n as f64, w * j as f64, w * k as f64)
    })
    .unwrap();
    let s = EulerSolver::new(&g).unwrap();
    let (l, r) = ((1.0, 0.0, 1.0), (0.125, 0.0, 0.1));
    let mut q = s.initial_state(GAMMA, |c| {
        let (rho, _, p) = if c.x < 0.5 { l } else { r };
        (rho, DVec3::ZERO, p)
    });
    let rep = s.run(&mut q, &EulerOptions::until(0.2)).unwrap();
    assert!((rep.time - 0.2).abs() < 1e-12);
    q.iter()
        .zip(s.centroids())
        .map(|(st, c)| {
            let rho = primitive(GAMMA, st).0;
            (rho - exact_density(l, r, (c.x - 0.5) / 0.2)).abs() / n as f64
        })
        .sum()
}

/// The exact solver itself on Sod's problem: Toro's Table 4.3 star values (p* = 0.30313,
/// ρ*L = 0.42632, ρ*R = 0.26557) and the shock at s = 1.75216.
#[test]
fn the_exact_riemann_solution_has_toros_star_states() {
    let (l, r) = ((1.0, 0.0, 1.0), (0.125, 0.0, 0.1));
    // between the contact (u* = 0.92745) and the shock: ρ*R
    assert!((exact_density(l, r, 1.2) - 0.26557).abs() < 1e-4);
    // between the rarefaction tail and the contact: ρ*L
    assert!((exact_density(l, r, 0.5) - 0.42632).abs() < 1e-4);
    assert_eq!(exact_density(l, r, 1.76), 0.125);
    assert!(exact_density(l, r, 1.74) > 0.2);
    assert_eq!(exact_density(l, r, -1.2), 1.0);
}

/// First order: the L1 error of the density falls as the tube is refined (by more than 1.3×
/// per halving; discontinuities limit a first-order scheme to rates of about ½–1) and is
/// small in absolute terms.
#[test]
fn sod_converges_to_the_exact_solution() {
    let e = [sod_error(100), sod_error(200), sod_error(400)];
    eprintln!("Sod L1(ρ): {e:?}");
    assert!(e[0] < 0.05, "{e:?}");
    assert!(e[0] / e[1] > 1.3 && e[1] / e[2] > 1.3, "{e:?}");
}

/// The source's blast (Cortés Aguirre 2012, §5.1): a closed unit ball, p = 5 inside radius 0.2
/// about (0, 0, −0.4), p = 1 elsewhere, ρ = 1, u = 0, solid walls. Mass and energy are
/// conserved to rounding (no flux crosses a wall), the state stays physical, the blast
/// spreads (the peak pressure falls below 5), and the solution keeps the mirror symmetry
/// x → −x of the mesh and of the data.
#[test]
fn the_blast_in_a_ball_conserves_and_stays_symmetric() {
    let n = 13;
    let g = ellipsoid_grid((n, n, n), DVec3::ONE, DVec3::ZERO).unwrap();
    let s = EulerSolver::new(&g).unwrap();
    let centre = DVec3::new(0.0, 0.0, -0.4);
    let mut q = s.initial_state(GAMMA, |c| {
        let p = if c.distance(centre) < 0.2 { 5.0 } else { 1.0 };
        (1.0, DVec3::ZERO, p)
    });
    let rep = s.run(&mut q, &EulerOptions::until(0.2)).unwrap();
    let rel = |a: [f64; 2]| ((a[1] - a[0]) / a[0]).abs();
    assert!(rel(rep.mass) < 1e-12 && rel(rep.energy) < 1e-12, "{rep:?}");
    assert!(rep.max_p < 5.0 && rep.min_rho_p[0] > 0.0 && rep.min_rho_p[1] > 0.0);
    let p = s.pressure(GAMMA, &q);
    let w = n - 1;
    for k in 0..w {
        for j in 0..w {
            for i in 0..w {
                let a = p[i + w * (j + w * k)];
                let b = p[(w - 1 - i) + w * (j + w * k)];
                assert!((a - b).abs() < 1e-9 * a, "({i},{j},{k}): {a} vs {b}");
            }
        }
    }
}
