//! Unit tests of the algebraic multigrid preconditioner.

use super::*;
use crate::linalg::{dot, norm};

fn rng(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
}

/// Bilinear (Q1) finite-element Laplacian `L` on the `k × k` interior nodes of a uniform
/// grid with Dirichlet boundary (stencil: 8/3 at the centre, −1/3 at the 8 neighbours; it is
/// the Q1 element stiffness matrix summed over the 4 cells around a node), for `dim`
/// coordinates per node: `A = L ⊗ B` with `B = (1−c)·I + c·J` (`J` all ones), SPD for
/// `0 ≤ c < 1` because the eigenvalues of a Kronecker product are the products of the
/// eigenvalues. This is the structure of the smoothing Hessians (9-point node graph, dense
/// coupled node blocks).
fn q1_laplacian(k: usize, dim: usize, c: f64) -> Csr {
    let nb = k * k;
    let mut row_offsets = vec![0];
    let mut col_indices = Vec::new();
    let mut values = Vec::new();
    for j in 0..k {
        for i in 0..k {
            for a in 0..dim {
                for dj in -1i64..=1 {
                    for di in -1i64..=1 {
                        let (ii, jj) = (i as i64 + di, j as i64 + dj);
                        if ii < 0 || jj < 0 || ii >= k as i64 || jj >= k as i64 {
                            continue;
                        }
                        let v = jj as usize * k + ii as usize;
                        let w = if di == 0 && dj == 0 {
                            8.0 / 3.0
                        } else {
                            -1.0 / 3.0
                        };
                        for b in 0..dim {
                            let val = if a == b { w } else { c * w };
                            col_indices.push((v * dim + b) as u32);
                            values.push(val);
                        }
                    }
                }
                row_offsets.push(col_indices.len());
            }
        }
    }
    Csr {
        nrows: nb * dim,
        ncols: nb * dim,
        row_offsets,
        col_indices,
        values,
    }
}

/// Geometric mean of the residual reduction per V-cycle of the stationary iteration
/// `x ← x + M⁻¹(b − A x)` over `cycles` cycles from `x = 0`.
fn vcycle_factor(k: usize, cycles: usize) -> f64 {
    let a = q1_laplacian(k, 2, 0.5);
    let mg = Multigrid::build(&a, 2, &MultigridOptions::default());
    let n = a.nrows;
    let mut r = rng(k as u64);
    let b: Vec<f64> = (0..n).map(|_| r()).collect();
    let mut x = vec![0.0; n];
    let mut res = b.clone();
    let mut z = vec![0.0; n];
    let r0 = norm(&res);
    for _ in 0..cycles {
        mg.apply(&a, &res, &mut z);
        x.iter_mut().zip(&z).for_each(|(x, z)| *x += z);
        residual(&a, &b, &x, &mut res);
    }
    (norm(&res) / r0).powf(1.0 / cycles as f64)
}

#[test]
fn vcycle_reduction_is_independent_of_the_size() {
    // sizes with 1, 2 and 3 coarse levels (coarse_size 600 unknowns = 300 nodes)
    let f: Vec<f64> = [20, 60, 180].iter().map(|&k| vcycle_factor(k, 8)).collect();
    eprintln!("V-cycle residual reduction per cycle (20², 60², 180² nodes): {f:?}");
    let mg = Multigrid::build(&q1_laplacian(180, 2, 0.5), 2, &MultigridOptions::default());
    assert!(mg.num_levels() >= 3, "levels {:?}", mg.level_sizes());
    for (k, v) in [20, 60, 180].iter().zip(&f) {
        // smoothed aggregation with one damped-Jacobi sweep: ≈ 0.3–0.5 per cycle
        assert!(*v < 0.6, "k = {k}: reduction factor {v} (all: {f:?})");
    }
    // size independence: the factor on 32 400 nodes is within 0.15 of the one on 400
    assert!(f[2] < f[0] + 0.15, "factors {f:?}");
}

#[test]
fn preconditioner_is_symmetric_positive_definite() {
    let a = q1_laplacian(70, 2, 0.5);
    let mg = Multigrid::build(&a, 2, &MultigridOptions::default());
    assert!(mg.num_levels() >= 2);
    let n = a.nrows;
    let mut r = rng(7);
    for _ in 0..10 {
        let x: Vec<f64> = (0..n).map(|_| r()).collect();
        let y: Vec<f64> = (0..n).map(|_| r()).collect();
        let (mut mx, mut my) = (vec![0.0; n], vec![0.0; n]);
        mg.apply(&a, &x, &mut mx);
        mg.apply(&a, &y, &mut my);
        // xᵀ M⁻¹ x > 0
        assert!(dot(&x, &mx) > 0.0);
        // yᵀ M⁻¹ x = xᵀ M⁻¹ y to rounding
        let (p, q) = (dot(&y, &mx), dot(&x, &my));
        let scale = norm(&x) * norm(&my).max(norm(&mx));
        assert!((p - q).abs() <= 1e-10 * scale, "{p} vs {q}");
    }
}

#[test]
fn pcg_iterations_stay_bounded() {
    // PCG to a relative residual of 1e-8: multigrid needs about the same count on both
    // sizes; the condition number of A grows like k², so unpreconditioned counts grow
    // like k (checked with the block-Jacobi preconditioner: ≥ 2× more on the larger grid)
    let count = |k: usize, mgp: bool| {
        let a = q1_laplacian(k, 2, 0.5);
        let mut pre = PrecondApply::default();
        pre.build(
            if mgp {
                Preconditioner::Multigrid
            } else {
                Preconditioner::BlockJacobi
            },
            &a,
            2,
        );
        let n = a.nrows;
        let b = vec![1.0; n];
        let (mut x, mut r, mut z, mut ap) = (vec![0.0; n], b.clone(), vec![0.0; n], vec![0.0; n]);
        pre.apply_with(&a, &r, &mut z);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        for it in 1..1000 {
            a.mul_vec(&p, &mut ap);
            let al = rz / dot(&p, &ap);
            for i in 0..n {
                x[i] += al * p[i];
                r[i] -= al * ap[i];
            }
            if norm(&r) <= 1e-8 * norm(&b) {
                return it;
            }
            pre.apply_with(&a, &r, &mut z);
            let rz2 = dot(&r, &z);
            for i in 0..n {
                p[i] = z[i] + rz2 / rz * p[i];
            }
            rz = rz2;
        }
        1000
    };
    let (m1, m2) = (count(40, true), count(160, true));
    let (j1, j2) = (count(40, false), count(160, false));
    eprintln!("PCG iterations 40² → 160²: multigrid {m1} → {m2}, block-Jacobi {j1} → {j2}");
    // measured: multigrid 12 → 18 (16× the unknowns, two more levels), block-Jacobi
    // grows ≈ 4× (∝ k)
    assert!(m2 <= 2 * m1 && m2 <= 25, "multigrid PCG: {m1} → {m2}");
    assert!(j2 >= 2 * j1, "block-Jacobi PCG: {j1} → {j2}");
}

#[test]
fn sparse_products_match_dense() {
    let mut r = rng(3);
    let mut random = |rows: usize, cols: usize| {
        let mut row_offsets = vec![0];
        let (mut ci, mut vs) = (Vec::new(), Vec::new());
        for _ in 0..rows {
            for c in 0..cols {
                if r() > 0.2 {
                    ci.push(c as u32);
                    vs.push(r());
                }
            }
            row_offsets.push(ci.len());
        }
        Csr {
            nrows: rows,
            ncols: cols,
            row_offsets,
            col_indices: ci,
            values: vs,
        }
    };
    let a = random(7, 5);
    let b = random(5, 6);
    let c = spgemm(&a, &b);
    let (da, db, dc) = (a.to_dense(), b.to_dense(), c.to_dense());
    for i in 0..7 {
        for j in 0..6 {
            let e: f64 = (0..5).map(|k| da[i][k] * db[k][j]).sum();
            assert!((dc[i][j] - e).abs() < 1e-14, "({i},{j})");
        }
    }
    let t = transpose(&a).to_dense();
    for i in 0..7 {
        for j in 0..5 {
            assert_eq!(t[j][i], da[i][j]);
        }
    }
    // rows sorted
    for row in 0..c.nrows {
        let s = &c.col_indices[c.row_offsets[row]..c.row_offsets[row + 1]];
        assert!(s.windows(2).all(|w| w[0] < w[1]));
    }
}

#[test]
fn aggregates_of_a_structured_grid_are_about_three_by_three() {
    // phase 1 on the 9-point graph takes a node and its 8 neighbours: 30 × 30 nodes give
    // 100 aggregates of 9 when roots fall on a stride-3 lattice (greedy in row order does
    // exactly that); phases 2/3 only act at the border, so ≈ 100 aggregates
    let a = q1_laplacian(30, 2, 0.5);
    let (agg, nagg) = aggregate(&a, 2, 0.0);
    assert_eq!(agg.len(), 900);
    assert_eq!(nagg, 100);
}

#[test]
fn indefinite_coarse_matrix_is_shifted() {
    // a 2 × 2 indefinite matrix: the Cholesky factor of A + δ·max|a_ii|·I exists
    let a = Csr {
        nrows: 2,
        ncols: 2,
        row_offsets: vec![0, 2, 4],
        col_indices: vec![0, 1, 0, 1],
        values: vec![1.0, 3.0, 3.0, 1.0],
    };
    // eigenvalues 4 and −2, max|a_ii| = 1: the shifts 1e-12, 1e-11, …, 1 fail, 10 is the
    // first with A + dI positive definite
    let c = dense_cholesky_shifted(&a);
    let l = c.l();
    let shifted = &l * l.transpose();
    let d = shifted[(0, 0)] - 1.0;
    assert!((d - 10.0).abs() < 1e-9, "shift {d}");
    assert!((shifted[(0, 1)] - 3.0).abs() < 1e-12);
    let mut x = nalgebra::DVector::from_vec(vec![1.0, 1.0]);
    c.solve_mut(&mut x);
    // (A + dI) x = (1, 1), an eigenvector of A (eigenvalue 4): x = (1, 1)/(4 + d)
    for v in x.iter() {
        assert!((v - 1.0 / 14.0).abs() < 1e-12, "{v}");
    }
}
