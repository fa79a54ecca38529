//! Diagnostics: times the multigrid setup and one V-cycle on the (6.8) Hessian of the
//! sinusoidal region's TFI grid, and the CG iterations to a relative residual of 1e-6 with
//! block-Jacobi and with multigrid.
//!
//! `cargo run --release -p unamalla-optim --example mg_probe -- 301`

use std::sync::Arc;
use std::time::Instant;

use unamalla_functionals::prelude::*;
use unamalla_functionals::{AreaOrthogonality, HOmega, KernelExpr, QuadFunctional, QuadTopology};
use unamalla_optim::fixtures::sinusoidal;
use unamalla_optim::linalg::{dot, norm, PrecondApply};
use unamalla_optim::multigrid::{Multigrid, MultigridOptions};
use unamalla_optim::Preconditioner;

fn pcg(h: &unamalla_functionals::Csr, pre: &PrecondApply, b: &[f64], maxit: usize) -> usize {
    let n = b.len();
    let mut x = vec![0.0; n];
    let mut r = b.to_vec();
    let mut z = vec![0.0; n];
    pre.apply_with(h, &r, &mut z);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let b0 = norm(b);
    let mut hp = vec![0.0; n];
    for it in 0..maxit {
        h.mul_vec(&p, &mut hp);
        let php = dot(&p, &hp);
        if php <= 0.0 {
            println!("  negative curvature at CG iteration {it}");
            return it;
        }
        let a = rz / php;
        for i in 0..n {
            x[i] += a * p[i];
            r[i] -= a * hp[i];
        }
        if norm(&r) <= 1e-6 * b0 {
            return it + 1;
        }
        pre.apply_with(h, &r, &mut z);
        let rz2 = dot(&r, &z);
        let beta = rz2 / rz;
        rz = rz2;
        for i in 0..n {
            p[i] = z[i] + beta * p[i];
        }
    }
    maxit
}

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(301, |s| s.parse().expect("size"));
    let g = sinusoidal(n, n, 0.1, 2.0).expect("region");
    let topo = Arc::new(QuadTopology::from_mesh(&g).expect("topology"));
    let x = topo.initial_x();
    let nt = topo.num_triangles();
    let s = topo.alpha_summary(&x);
    let ab = s.mean;
    let ao = KernelExpr::from(AreaOrthogonality)
        .normalized(nt, ab)
        .expect("ao");
    let h = KernelExpr::from(HOmega::new(0.01 * ab).expect("omega"))
        .normalized(nt, ab)
        .expect("h");
    let p = QuadFunctional::new(
        topo.clone(),
        KernelExpr::weighted_sum(vec![(0.9, ao), (0.1, h)]),
    );
    let mut hm = p.hessian_pattern();
    let t = Instant::now();
    p.hessian(&x, &mut hm);
    println!(
        "hessian refresh: {:.3}s ({} rows, {} nnz)",
        t.elapsed().as_secs_f64(),
        hm.nrows,
        hm.nnz()
    );
    let mut g0 = vec![0.0; x.len()];
    let t = Instant::now();
    p.value_grad(&x, &mut g0);
    println!("value_grad: {:.3}s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let mg = Multigrid::build(&hm, 2, &MultigridOptions::default());
    println!(
        "mg build: {:.3}s, levels {:?}, operator complexity {:.2}",
        t.elapsed().as_secs_f64(),
        mg.level_sizes(),
        mg.operator_complexity()
    );
    let mut z = vec![0.0; x.len()];
    let t = Instant::now();
    mg.apply(&hm, &g0, &mut z);
    println!("one V-cycle: {:.4}s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    hm.mul_vec(&g0, &mut z);
    println!("one matvec: {:.4}s", t.elapsed().as_secs_f64());
    for pk in [Preconditioner::BlockJacobi, Preconditioner::Multigrid] {
        let t = Instant::now();
        let mut pre = PrecondApply::default();
        pre.build(pk, &hm, 2);
        let tb = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let it = pcg(&hm, &pre, &g0, 2000);
        println!(
            "{pk:?}: build {tb:.3}s, PCG to 1e-6: {it} it, {:.3}s",
            t.elapsed().as_secs_f64()
        );
    }
}
