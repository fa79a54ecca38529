//! Shared helpers: random grids and finite-difference checks (independent of the crate's
//! derivative code: only `value` / `value_grad` are differentiated numerically).
#![allow(dead_code, clippy::needless_range_loop)]

use unamalla_functionals::prelude::*;
use unamalla_functionals::Csr;
use unamalla_mesh::{DVec2, DVec3, StructuredGrid2, StructuredGrid3};

/// An `m × n` grid on `[0, m-1] × [0, n-1]·aspect`, interior nodes moved by `amp·(r − ½)`
/// (units of one cell), `r` taken cyclically from `noise`.
pub fn grid2(m: usize, n: usize, amp: f64, noise: &[f64]) -> StructuredGrid2 {
    let mut k = 0;
    StructuredGrid2::from_fn(m, n, |i, j| {
        let mut p = DVec2::new(i as f64, 0.8 * j as f64 + 0.1 * i as f64);
        if i > 0 && j > 0 && i + 1 < m && j + 1 < n {
            let rx = noise[k % noise.len()] - 0.5;
            let ry = noise[(k + 1) % noise.len()] - 0.5;
            k += 2;
            p += amp * DVec2::new(rx, ry);
        }
        p
    })
    .unwrap()
}

/// A 3D grid on a box, interior nodes perturbed like [`grid2`].
pub fn grid3(m: usize, n: usize, p: usize, amp: f64, noise: &[f64]) -> StructuredGrid3 {
    let mut k = 0;
    StructuredGrid3::from_fn(m, n, p, |i, j, l| {
        let mut q = DVec3::new(i as f64, 0.9 * j as f64, 1.1 * l as f64 + 0.1 * i as f64);
        if i > 0 && j > 0 && l > 0 && i + 1 < m && j + 1 < n && l + 1 < p {
            let r = |o: usize| noise[(k + o) % noise.len()] - 0.5;
            q += amp * DVec3::new(r(0), r(1), r(2));
            k += 3;
        }
        q
    })
    .unwrap()
}

fn close(a: f64, b: f64, tol: f64, scale: f64) -> bool {
    (a - b).abs() <= tol * (scale + a.abs().max(b.abs()))
}

/// Checks gradient and Hessian against central differences, the CSR Hessian against the
/// matrix-free product, the local models against the global gradient / Hessian blocks, and the
/// value against `value_grad`'s value.
pub fn check_problem<P: Problem>(name: &str, p: &P, x: &[f64], tol: f64) -> Result<(), String> {
    let n = p.num_vars();
    let mut g = vec![0.0; n];
    let f0 = p.value_grad(x, &mut g);
    let fv = p.value(x);
    if !(f0.is_finite()) {
        return Err(format!("{name}: value not finite: {f0}"));
    }
    if f0.to_bits() != fv.to_bits() {
        return Err(format!("{name}: value {fv} != value_grad value {f0}"));
    }
    let gscale = g.iter().fold(0.0f64, |m, v| m.max(v.abs())) + f0.abs() * 1e-3;
    let mut xp = x.to_vec();
    for i in 0..n {
        let h = 1e-6 * (1.0 + x[i].abs());
        xp[i] = x[i] + h;
        let fp = p.value(&xp);
        xp[i] = x[i] - h;
        let fm = p.value(&xp);
        xp[i] = x[i];
        let fd = (fp - fm) / (2.0 * h);
        if !close(fd, g[i], tol, gscale) {
            return Err(format!("{name}: gradient[{i}] = {} but FD = {fd}", g[i]));
        }
    }
    let mut h: Csr = p.hessian_pattern();
    p.hessian(x, &mut h);
    let dense = h.to_dense();
    let hscale = dense.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    // column i of the Hessian by central differences of the gradient with step `rel`
    let mut fd_column = |i: usize, rel: f64| -> Vec<f64> {
        let (mut gp, mut gm) = (vec![0.0; n], vec![0.0; n]);
        let hh = rel * (1.0 + x[i].abs());
        xp[i] = x[i] + hh;
        p.value_grad(&xp, &mut gp);
        xp[i] = x[i] - hh;
        p.value_grad(&xp, &mut gm);
        xp[i] = x[i];
        (0..n).map(|r| (gp[r] - gm[r]) / (2.0 * hh)).collect()
    };
    for i in 0..n {
        let fd = fd_column(i, 1e-6);
        for r in 0..n {
            if close(fd[r], dense[r][i], tol, hscale) {
                continue;
            }
            // φ_ω (H_ω, [Méndez 2023, §6.4.2]) is only C¹: where an element sits within the
            // step of its switch point α = ω the central difference straddles the jump of the
            // second derivative and is wrong; a smaller step on the same side must agree
            let retry = [1e-7, 1e-8]
                .iter()
                .any(|&rel| close(fd_column(i, rel)[r], dense[r][i], tol, hscale));
            if !retry {
                return Err(format!(
                    "{name}: hessian[{r}][{i}] = {} but FD = {}",
                    dense[r][i], fd[r]
                ));
            }
        }
    }
    for r in 0..n {
        for c in 0..n {
            if dense[r][c].to_bits() != dense[c][r].to_bits()
                && !close(dense[r][c], dense[c][r], 1e-12, hscale)
            {
                return Err(format!("{name}: hessian not symmetric at ({r},{c})"));
            }
        }
    }
    // Hessian-vector product
    let v: Vec<f64> = (0..n)
        .map(|i| ((i * 7 + 3) % 11) as f64 / 11.0 - 0.4)
        .collect();
    let mut hv = vec![0.0; n];
    let mut hv2 = vec![0.0; n];
    p.hess_vec(x, &v, &mut hv);
    h.mul_vec(&v, &mut hv2);
    for i in 0..n {
        if !close(hv[i], hv2[i], 1e-10, hscale) {
            return Err(format!(
                "{name}: hess_vec[{i}] = {} vs CSR {}",
                hv[i], hv2[i]
            ));
        }
    }
    // local models
    let d = p.dim();
    for (j, &node) in p.free_nodes().iter().enumerate() {
        let m = p
            .local(x, node)
            .ok_or_else(|| format!("{name}: no local model for free node {node}"))?;
        assert_eq!(p.var_of(node), Some(j));
        let lv = p
            .local_value(x, node)
            .ok_or_else(|| format!("{name}: no local value for free node {node}"))?;
        if !close(lv, m.value, 1e-12, m.value.abs()) {
            return Err(format!(
                "{name}: local_value {lv} vs local model value {} at node {node}",
                m.value
            ));
        }
        for a in 0..d {
            if !close(m.grad[a], g[d * j + a], 1e-10, gscale) {
                return Err(format!("{name}: local grad of node {node} differs"));
            }
            for b in 0..d {
                if !close(m.hess[a][b], dense[d * j + a][d * j + b], 1e-10, hscale) {
                    return Err(format!("{name}: local hessian of node {node} differs"));
                }
            }
        }
        // local value: the part of F that depends on the node, so moving the node changes F by
        // the same amount as the local value
        let mut xs = x.to_vec();
        xs[d * j] += 1e-3;
        let df = p.value(&xs) - f0;
        let m2 = p.local(&xs, node).unwrap();
        if !close(df, m2.value - m.value, 1e-8, f0.abs()) {
            return Err(format!(
                "{name}: local value change {} vs global {df}",
                m2.value - m.value
            ));
        }
    }
    Ok(())
}
