//! Unit tests of the hex functional: the energy variants, the node-block Hessian against the
//! per-tetrahedron reference assembly and `hess_vec`, the block slots and the ten tetrahedra.

use std::sync::Arc;

use glam::DVec3;

use super::{energy_variants, hex_tets, unit_cube, HexFunctional, HexTopology, Scaling3};
use crate::problem::{Cost, Hessian, Variables};

/// An `m × n × p`-node grid of the unit-spaced box with every interior node moved by a
/// deterministic pseudo-random offset of size up to `amp` (amp > ~0.5 folds cells).
fn grid(m: usize, n: usize, p: usize, amp: f64) -> HexTopology {
    let id = |i: usize, j: usize, k: usize| i + m * (j + n * k);
    let mut nodes = Vec::new();
    let mut fixed = Vec::new();
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for k in 0..p {
        for j in 0..n {
            for i in 0..m {
                let b = i == 0 || j == 0 || k == 0 || i == m - 1 || j == n - 1 || k == p - 1;
                let mut q = DVec3::new(i as f64, j as f64, 1.3 * k as f64);
                if !b {
                    q += amp * DVec3::new(rnd(), rnd(), rnd());
                }
                nodes.push(q);
                fixed.push(b);
            }
        }
    }
    let mut cells = Vec::new();
    for k in 0..p - 1 {
        for j in 0..n - 1 {
            for i in 0..m - 1 {
                cells.push([
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ]);
            }
        }
    }
    HexTopology::new(nodes, cells, fixed).unwrap()
}

/// The eight vertices of the unit cube's image under `x ↦ A·x` (VTK order).
fn affine_cell(a: [DVec3; 3]) -> [DVec3; 8] {
    std::array::from_fn(|v| {
        let u = unit_cube(v);
        a[0] * u.x + a[1] * u.y + a[2] * u.z
    })
}

/// Hand values of [`energy_variants`] ([Cortés Aguirre 2012, (3.22)] and its readings).
#[test]
fn energy_variants_hand_values() {
    // congruent cubes of side 0.25: every tetrahedron Jacobian is a similarity, E = 1
    let cube = affine_cell([DVec3::X * 0.25, DVec3::Y * 0.25, DVec3::Z * 0.25]);
    let e = energy_variants(&[cube, cube], Scaling3::Index).unwrap();
    assert!((e.printed - 1.0).abs() < 1e-14, "{e:?}");
    assert!((e.per_decomposition - 2.0).abs() < 1e-14);
    assert!((e.volume_weighted - 2.0).abs() < 1e-14);
    // interior tets with raw face-diagonal legs: s = 6h², V = 2h³ → E = √2
    let raw = (8.0 + 2.0 * 2f64.sqrt()) / 10.0;
    assert!((e.interior_raw - raw).abs() < 1e-14, "{e:?}");
    assert_eq!(e.non_positive, 0);
    // box stretched 2× along x: every Jacobian diag(2,1,1), E = (6/3)^{3/2}/2 = √2;
    // the raw interior legs have s = 5 + 2 + 5 = 12 and V = 2·2 = 4, E = 8/4 = 2
    let stretched = affine_cell([DVec3::X * 2.0, DVec3::Y, DVec3::Z]);
    let e = energy_variants(&[stretched], Scaling3::Index).unwrap();
    assert!((e.printed - 2f64.sqrt()).abs() < 1e-14, "{e:?}");
    assert!((e.per_decomposition - 2.0 * 2f64.sqrt()).abs() < 1e-14);
    assert!((e.volume_weighted - 2.0 * 2f64.sqrt()).abs() < 1e-14);
    assert!((e.interior_raw - (8.0 * 2f64.sqrt() + 4.0) / 10.0).abs() < 1e-14);
    // parametric factors (2, 1, 1) of a 3 × 2 × 2-node grid double the x column again:
    // Jacobian diag(4, 1, 1), E = (18/3)^{3/2}/4
    let e = energy_variants(&[stretched], Scaling3::Parametric { m: 3, n: 2, p: 2 }).unwrap();
    assert!((e.printed - 6f64.powf(1.5) / 4.0).abs() < 1e-12, "{e:?}");
    // per_decomposition is exactly twice the printed normalisation on any mesh
    let topo = Arc::new(grid(4, 4, 4, 0.3));
    let cells: Vec<[DVec3; 8]> = (0..topo.num_cells())
        .map(|c| topo.cell_points(&topo.initial_x(), c).0)
        .collect();
    let e = energy_variants(&cells, Scaling3::Index).unwrap();
    assert!((e.per_decomposition - 2.0 * e.printed).abs() < 1e-12 * e.printed);
    assert!(e.printed > 1.0);
    // and `printed` is what H_ω evaluates once ω is below every V
    let h = HexFunctional::h_omega(topo.clone(), 1e-9, Scaling3::Index).unwrap();
    let hv = h.value(&topo.initial_x());
    assert!((hv - e.printed).abs() < 1e-12 * hv, "{hv} vs {}", e.printed);
}

#[test]
fn node_block_hessian_equals_the_reference_assembly_and_hess_vec() {
    // convex and folded starts; every term kind (both ω branches, coplanarity only, both)
    for amp in [0.3, 1.4] {
        let topo = Arc::new(grid(6, 5, 5, amp));
        let x = topo.initial_x();
        let fs = [
            HexFunctional::h_omega(topo.clone(), 0.7, Scaling3::Index).unwrap(),
            HexFunctional::h_omega(topo.clone(), 40.0, Scaling3::Custom([1.0, 2.0, 0.5])).unwrap(),
            HexFunctional::coplanarity(topo.clone(), 3.0).unwrap(),
            HexFunctional::h_omega(topo.clone(), 0.2, Scaling3::Parametric { m: 6, n: 5, p: 5 })
                .unwrap()
                .with_coplanarity(0.9)
                .unwrap(),
        ];
        for (fi, f) in fs.iter().enumerate() {
            let mut h = f.hessian_pattern();
            let mut r = f.hessian_pattern();
            f.hessian(&x, &mut h);
            f.hessian_scatter(&x, &mut r);
            let scale = r.values.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(scale > 0.0);
            for (k, (a, b)) in h.values.iter().zip(&r.values).enumerate() {
                // the same sums in another order: rounding-level differences only
                assert!(
                    (a - b).abs() <= 1e-12 * scale,
                    "f{fi} amp {amp} entry {k}: {a} vs {b}"
                );
            }
            // the assembled matrix is symmetric
            for row in 0..h.nrows {
                for e in h.row_offsets[row]..h.row_offsets[row + 1] {
                    let col = h.col_indices[e] as usize;
                    assert!((h.values[e] - h.get(col, row)).abs() <= 1e-12 * scale);
                }
            }
            // the matrix-free product equals the CSR product
            let v: Vec<f64> = (0..f.num_vars())
                .map(|i| ((i * 7919) % 13) as f64 - 6.0)
                .collect();
            let mut hv = vec![0.0; v.len()];
            let mut mv = vec![0.0; v.len()];
            f.hess_vec(&x, &v, &mut hv);
            h.mul_vec(&v, &mut mv);
            for (a, b) in hv.iter().zip(&mv) {
                assert!((a - b).abs() <= 1e-10 * scale, "{a} vs {b}");
            }
        }
    }
}

#[test]
fn block_slots_point_at_the_block_entries() {
    let topo = grid(5, 5, 4, 0.2);
    let f = HexFunctional::h_omega(Arc::new(grid(5, 5, 4, 0.2)), 1.0, Scaling3::Index).unwrap();
    let h = f.hessian_pattern();
    let slots = topo.block_slots().unwrap();
    for (c, sl) in slots.iter().enumerate() {
        for a in 0..8 {
            for b in 0..8 {
                let (va, vb) = (
                    topo.var_of(topo.asm.cells[c][a] as usize),
                    topo.var_of(topo.asm.cells[c][b] as usize),
                );
                match (va, vb) {
                    (Some(va), Some(vb)) => {
                        let s0 = sl[8 * a + b] as usize;
                        // row 3va + dx, column 3vb + dy
                        for dx in 0..3 {
                            let rl = 3 * (topo.asm.nbr_offsets[va + 1] - topo.asm.nbr_offsets[va]);
                            for dy in 0..3 {
                                let e = s0 + dx * rl + dy;
                                assert!(
                                    e >= h.row_offsets[3 * va + dx]
                                        && e < h.row_offsets[3 * va + dx + 1]
                                );
                                assert_eq!(h.col_indices[e] as usize, 3 * vb + dy);
                            }
                        }
                    }
                    _ => assert_eq!(sl[8 * a + b], u32::MAX),
                }
            }
        }
    }
}

#[test]
fn all_ten_tets_are_positive_on_the_unit_cube_and_interior_ones_have_v_3vol() {
    let p: [DVec3; 8] = std::array::from_fn(unit_cube);
    for t in hex_tets() {
        let c: [DVec3; 3] = std::array::from_fn(|a| {
            (0..4).fold(DVec3::ZERO, |acc, j| acc + t.stencil[a][j] * p[t.nodes[j]])
        });
        let v = c[0].dot(c[1].cross(c[2]));
        // every column is a unit logical direction on the unit cube, so V = ±1 → must be +1
        assert!((v - 1.0).abs() < 1e-12, "tet {:?} has V = {v}", t.nodes);
        let q = t.nodes.map(|i| p[i]);
        let vol6 = (q[1] - q[0]).dot((q[2] - q[0]).cross(q[3] - q[0])).abs();
        if t.interior {
            // V = 3·vol = vol6 / 2
            assert!((vol6 / 2.0 - v).abs() < 1e-12);
        } else {
            assert!((vol6 - v).abs() < 1e-12);
        }
        let mut dirs = t.dirs;
        dirs.sort_unstable();
        assert_eq!(dirs, [0, 1, 2]);
    }
}
