//! Evaluation of [`HexFunctional`]: the cell kernel and the problem traits (value, gradient,
//! node-block Hessian assembly, pointwise model, element measures).

use glam::DVec3;
use rayon::prelude::*;

use super::terms::{face_term, face_term_blocks, tet_term, tet_term_blocks, CellBlocks};
#[cfg(doc)]
use super::HexTopology;
use super::{HexFunctional, HEX_QUAD_FACES};
use crate::assembly::{SyncPtr, FIXED};
use crate::csr::Csr;
use crate::problem::{
    Cost, ElementMeasures, Gradient, Hessian, LocalModel, PointwiseModel, Variables,
};

impl HexFunctional {
    /// The ten Jacobian determinants of cell `c` at `x` (scaled as configured).
    fn tet_dets(&self, p: &[DVec3; 8]) -> [f64; 10] {
        self.tets.map(|t| {
            let c: [DVec3; 3] = std::array::from_fn(|a| {
                (0..4).fold(DVec3::ZERO, |acc, j| acc + t.w[a][j] * p[t.nodes[j]])
            });
            c[0].dot(c[1].cross(c[2]))
        })
    }

    /// Value of cell `c`, adding its gradient (and Hessian) to the local arrays; with
    /// `only = Some(i)` terms not involving local node `i` are skipped.
    #[inline(always)]
    fn cell_eval(
        &self,
        c: usize,
        p: &[DVec3; 8],
        only: Option<usize>,
        g: &mut [DVec3; 8],
        mut h: Option<&mut [[f64; 24]; 24]>,
    ) -> f64 {
        let mut v = 0.0;
        if let Some(w) = self.omega {
            for t in &self.tets {
                if let Some(i) = only {
                    if !t.nodes.contains(&i) {
                        continue;
                    }
                }
                v += tet_term(t, p, w, self.h_scale, g, h.as_deref_mut());
            }
        }
        if let Some(cp) = self.coplanarity {
            if self.topo.interior[c] {
                for f in HEX_QUAD_FACES {
                    if let Some(i) = only {
                        if !f.contains(&i) {
                            continue;
                        }
                    }
                    v += face_term(f, p, cp, g, h.as_deref_mut());
                }
            }
        }
        v
    }

    /// Value of cell `c`, adding its gradient and (if asked) its node-block Hessian.
    #[inline(always)]
    fn cell_eval_blocks(
        &self,
        c: usize,
        p: &[DVec3; 8],
        g: &mut [DVec3; 8],
        mut hb: Option<&mut CellBlocks>,
    ) -> f64 {
        let mut v = 0.0;
        if let Some(w) = self.omega {
            for t in &self.tets {
                v += tet_term_blocks(t, p, w, self.h_scale, g, hb.as_deref_mut());
            }
        }
        if let Some(cp) = self.coplanarity {
            if self.topo.interior[c] {
                for f in HEX_QUAD_FACES {
                    v += face_term_blocks(f, p, cp, g, hb.as_deref_mut());
                }
            }
        }
        v
    }

    /// The Hessian by the original per-tetrahedron assembly: each term's column Hessian is
    /// spread over a 24×24 cell matrix (`scatter_hess3`), whose entries are then located in the
    /// CSR rows by binary search. The fallback of the node-block [`Hessian::hessian`] when its
    /// slot table cannot be built, and the reference the tests check it against (same values up
    /// to rounding); `h` must come from [`Hessian::hessian_pattern`].
    ///
    /// # Panics
    /// If `x` or `h` do not fit the mesh.
    pub(super) fn hessian_scatter(&self, x: &[f64], h: &mut Csr) {
        assert_eq!(x.len(), self.num_vars(), "hessian: x has the wrong length");
        assert!(
            self.topo.asm.matches_pattern(3, h),
            "hessian: matrix does not come from hessian_pattern"
        );
        let Csr {
            row_offsets,
            values,
            ..
        } = h;
        crate::csr::par_zero(values);
        let hp = SyncPtr::new(values);
        let ro: &[usize] = row_offsets;
        let asm = &self.topo.asm;
        asm.run_colored(|c| {
            let (p, vars) = self.topo.cell_points(x, c);
            let mut lg = [DVec3::ZERO; 8];
            let mut lh = [[0.0; 24]; 24];
            self.cell_eval(c, &p, None, &mut lg, Some(&mut lh));
            for i in 0..8 {
                let vi = vars[i];
                if vi == FIXED {
                    continue;
                }
                for jn in 0..8 {
                    let vj = vars[jn];
                    if vj == FIXED {
                        continue;
                    }
                    let k = asm.nbr_pos(vi, vj);
                    for dx in 0..3 {
                        let base = ro[3 * vi as usize + dx] + 3 * k;
                        for dy in 0..3 {
                            // SAFETY: row of a node of this cell; see `assembly`.
                            unsafe { hp.add(base + dy, lh[3 * i + dx][3 * jn + dy]) };
                        }
                    }
                }
            }
            0.0
        });
    }
}
impl Variables for HexFunctional {
    fn dim(&self) -> usize {
        3
    }
    fn num_vars(&self) -> usize {
        self.topo.num_vars()
    }
    fn free_nodes(&self) -> &[usize] {
        self.topo.free_nodes()
    }
    fn var_of(&self, node: usize) -> Option<usize> {
        self.topo.var_of(node)
    }
}

impl Cost for HexFunctional {
    fn value(&self, x: &[f64]) -> f64 {
        assert_eq!(x.len(), self.num_vars(), "value: x has the wrong length");
        self.topo.asm.run_value(|c| {
            let (p, _) = self.topo.cell_points(x, c);
            let mut g = [DVec3::ZERO; 8];
            self.cell_eval(c, &p, None, &mut g, None)
        })
    }
}

impl Gradient for HexFunctional {
    fn value_grad(&self, x: &[f64], g: &mut [f64]) -> f64 {
        assert_eq!(
            x.len(),
            self.num_vars(),
            "value_grad: x has the wrong length"
        );
        assert_eq!(
            g.len(),
            self.num_vars(),
            "value_grad: g has the wrong length"
        );
        crate::csr::par_zero(g);
        let gp = SyncPtr::new(g);
        self.topo.asm.run_colored(|c| {
            let (p, vars) = self.topo.cell_points(x, c);
            let mut lg = [DVec3::ZERO; 8];
            let v = self.cell_eval(c, &p, None, &mut lg, None);
            for i in 0..8 {
                if vars[i] != FIXED {
                    let j = 3 * vars[i] as usize;
                    // SAFETY: node of this cell; see `assembly` (colouring).
                    unsafe {
                        gp.add(j, lg[i].x);
                        gp.add(j + 1, lg[i].y);
                        gp.add(j + 2, lg[i].z);
                    }
                }
            }
            v
        })
    }
}

impl Hessian for HexFunctional {
    fn hessian_pattern(&self) -> Csr {
        self.topo.hessian_pattern()
    }

    /// Node-block assembly: per cell the Hessian w.r.t. its eight vertices is built
    /// as 8×8 closed-form 3×3 blocks (`tet_term_blocks`, `face_term_blocks`, see the module docs) and added at
    /// the CSR positions precomputed once with the pattern ([`HexTopology::block_slots`]).
    /// Cells run in the deterministic chunk colouring of `assembly` (bit-identical for any
    /// thread count). Falls back to the per-tetrahedron scatter assembly (private) when the
    /// slot table cannot be built (more than `u32::MAX` entries).
    fn hessian(&self, x: &[f64], h: &mut Csr) {
        assert_eq!(x.len(), self.num_vars(), "hessian: x has the wrong length");
        assert_eq!(
            h.nrows,
            self.num_vars(),
            "hessian: matrix has the wrong size"
        );
        assert!(
            self.topo.asm.matches_pattern(3, h),
            "hessian: matrix does not come from hessian_pattern"
        );
        let Some(slots) = self.topo.block_slots() else {
            self.hessian_scatter(x, h);
            return;
        };
        let values = &mut h.values;
        crate::csr::par_zero(values);
        let hp = SyncPtr::new(values);
        let topo = &*self.topo;
        topo.asm.run_colored(|c| {
            let (p, vars) = topo.cell_points(x, c);
            let mut lg = [DVec3::ZERO; 8];
            let mut hb: CellBlocks = [[[0.0; 9]; 8]; 8];
            self.cell_eval_blocks(c, &p, &mut lg, Some(&mut hb));
            let sl = &slots[c];
            for a in 0..8 {
                if vars[a] == FIXED {
                    continue;
                }
                let rl = topo.row_len(vars[a]);
                for b in 0..8 {
                    let s0 = sl[8 * a + b];
                    if s0 == u32::MAX {
                        continue;
                    }
                    let blk = &hb[a][b];
                    for dx in 0..3 {
                        let base = s0 as usize + dx * rl;
                        for dy in 0..3 {
                            // SAFETY: a block of two nodes of this cell (slot table built from
                            // the same pattern, checked by `matches_pattern`); see `assembly`.
                            unsafe { hp.add(base + dy, blk[3 * dx + dy]) };
                        }
                    }
                }
            }
            0.0
        });
    }

    fn hess_vec(&self, x: &[f64], v: &[f64], out: &mut [f64]) {
        let n = self.num_vars();
        assert_eq!(x.len(), n, "hess_vec: x has the wrong length");
        assert_eq!(v.len(), n, "hess_vec: v has the wrong length");
        assert_eq!(out.len(), n, "hess_vec: out has the wrong length");
        out.par_iter_mut().with_min_len(4096).for_each(|o| *o = 0.0);
        let op = SyncPtr::new(out);
        self.topo.asm.run_colored(|c| {
            let (p, vars) = self.topo.cell_points(x, c);
            let mut lg = [DVec3::ZERO; 8];
            let mut hb: CellBlocks = [[[0.0; 9]; 8]; 8];
            self.cell_eval_blocks(c, &p, &mut lg, Some(&mut hb));
            let mut lv = [DVec3::ZERO; 8];
            for b in 0..8 {
                if vars[b] != FIXED {
                    let j = 3 * vars[b] as usize;
                    lv[b] = DVec3::new(v[j], v[j + 1], v[j + 2]);
                }
            }
            for a in 0..8 {
                if vars[a] == FIXED {
                    continue;
                }
                let mut acc = [0.0; 3];
                for b in 0..8 {
                    if vars[b] == FIXED {
                        continue;
                    }
                    let blk = &hb[a][b];
                    for dx in 0..3 {
                        acc[dx] += blk[3 * dx] * lv[b].x
                            + blk[3 * dx + 1] * lv[b].y
                            + blk[3 * dx + 2] * lv[b].z;
                    }
                }
                let j = 3 * vars[a] as usize;
                for dx in 0..3 {
                    // SAFETY: node of this cell; see `assembly`.
                    unsafe { op.add(j + dx, acc[dx]) };
                }
            }
            0.0
        });
    }
}

impl PointwiseModel for HexFunctional {
    fn local(&self, x: &[f64], node: usize) -> Option<LocalModel> {
        self.topo.var_of(node)?;
        assert_eq!(x.len(), self.num_vars(), "local: x has the wrong length");
        let asm = &self.topo.asm;
        let mut m = LocalModel {
            value: 0.0,
            grad: [0.0; 3],
            hess: [[0.0; 3]; 3],
            dim: 3,
        };
        for &c in &asm.inc[asm.inc_offsets[node]..asm.inc_offsets[node + 1]] {
            let c = c as usize;
            let i = asm.cells[c].iter().position(|&v| v as usize == node)?;
            let (p, _) = self.topo.cell_points(x, c);
            let mut lg = [DVec3::ZERO; 8];
            let mut lh = [[0.0; 24]; 24];
            m.value += self.cell_eval(c, &p, Some(i), &mut lg, Some(&mut lh));
            let gi = lg[i].to_array();
            for dx in 0..3 {
                m.grad[dx] += gi[dx];
                for dy in 0..3 {
                    m.hess[dx][dy] += lh[3 * i + dx][3 * i + dy];
                }
            }
        }
        Some(m)
    }
}

impl ElementMeasures for HexFunctional {
    fn num_elements(&self) -> usize {
        10 * self.topo.num_cells()
    }

    fn element_measures(&self, x: &[f64], out: &mut [f64]) {
        assert_eq!(
            out.len(),
            self.num_elements(),
            "element_measures: wrong length"
        );
        assert_eq!(
            x.len(),
            self.num_vars(),
            "element_measures: x has the wrong length"
        );
        out.par_chunks_mut(10).enumerate().for_each(|(c, o)| {
            let (p, _) = self.topo.cell_points(x, c);
            o.copy_from_slice(&self.tet_dets(&p));
        });
    }
    fn element_nodes(&self, e: usize, out: &mut Vec<usize>) {
        out.extend(self.topo.asm.cells[e / 10].iter().map(|&v| v as usize));
    }
}
