//! The fast 2D evaluator: the four corner triangles of a cell computed together as four SIMD
//! lanes, with precomputed per-cell index tables.
//!
//! # Formulas (the same exact chain rule as the reference path in [`super`])
//! For cell `[v₀, v₁, v₂, v₃]` with edges `e_k = v_{k+1} − v_k`, corner `k` has legs
//! `a_k = e_k`, `b_k = −e_{k−1}` ([Méndez 2023, Fig 6.12]; [González Flores, Fig 2.19]), so the
//! lane scalars are `α_k = a_k × b_k`, `la_k = |e_k|²`, `lb_k = |e_{k−1}|²` (the squared edge
//! lengths are computed once per cell and shared by two corners) and `o_k = a_k·b_k`.
//! With the kernel partials `d = ∂f/∂(α, la, lb, o)` of every lane,
//!
//! * `∂f/∂a = d_α J₂b + 2 d_la a + d_o b`, `∂f/∂b = −d_α J₂a + 2 d_lb b + d_o a`
//!   (`J₂w = (w_y, −w_x)`);
//! * edge `e_k` collects `∂f_k/∂a_k − ∂f_{k+1}/∂b_{k+1}` (one lane rotation) and node `v_i`
//!   receives `g_{e_{i−1}} − g_{e_i}`;
//! * the leg Hessian of a lane is `H_u = Jᵀ (∂²f/∂s²) J + Σ_s f_s ∇²_u s` with
//!   `J = ∂(α, la, lb, o)/∂(aₓ, a_y, bₓ, b_y)`; writing it in 2×2 leg blocks `A = H_aa`,
//!   `B = H_ab`, `C = H_bb`, the node blocks of corner `P = v_k`, `Q = v_{k+1}`, `R = v_{k−1}`
//!   (`a = Q − P`, `b = R − P`) are `H_QQ = A`, `H_RR = C`, `H_QR = B`,
//!   `H_PP = A + B + Bᵀ + C`, `H_PQ = −(A + Bᵀ)`, `H_PR = −(B + C)` and their transposes.
//!
//! # Memory traffic
//! Every `(cell, node)` gradient contribution and every `(cell, node pair)` Hessian block knows
//! from a table built once whether it is the **first** one to reach its entry in the
//! deterministic schedule ([`crate::assembly`]); the first one stores, later ones add. So the
//! gradient and the 36-million-entry Hessian of a 1000² grid need no zeroing pass, and the
//! result is the one of "zero, then add in schedule order" (bit for bit, up to the sign of a
//! zero). The CSR position of each Hessian block is precomputed per cell as the position of the
//! column node in the row node's neighbour list (`u16`, 32 bytes per cell).
//!
//! # SIMD
//! The lane arithmetic is written on `[f64; 4]` arrays; on x86-64 the chunk loops are compiled
//! twice, for the baseline target and with AVX2 enabled, and the AVX2 copy is chosen at run time
//! when the CPU has it. Only element-wise IEEE operations are used (no FMA contraction, no
//! reassociation), so both copies give bit-identical results.

use glam::DVec2;

use super::{scalars, QuadTopology, LEGS};
use crate::assembly::{SyncPtr, FIXED, FIXED_BIT};
use crate::kernel::{CornerLanes, Order, Terms, TriKernel};

/// Flag bit of a Hessian slot entry: this contribution is the first to reach its block.
pub(crate) const SLOT_FIRST: u16 = 1 << 15;
/// Largest neighbour-list position a slot entry can hold.
pub(crate) const SLOT_MAX: usize = (SLOT_FIRST - 1) as usize;

/// A 2×2 node block `[xx, xy, yx, yy]`.
pub(crate) type Block = [f64; 4];

impl QuadTopology {
    /// Coordinates of the four vertices of cell `c` (lane `i` = vertex `i`) and their
    /// variable-node indices ([`FIXED`] for fixed vertices).
    #[inline(always)]
    pub(crate) fn cell_xy(&self, x: &[f64], c: usize) -> ([f64; 4], [f64; 4], [u32; 4]) {
        let src = self.asm.src[c];
        let mut px = [0.0; 4];
        let mut py = [0.0; 4];
        let mut vars = [FIXED; 4];
        for i in 0..4 {
            let s = src[i];
            if s & FIXED_BIT == 0 {
                let j = 2 * s as usize;
                px[i] = x[j];
                py[i] = x[j + 1];
                vars[i] = s;
            } else {
                let q = self.base[(s & !FIXED_BIT) as usize];
                px[i] = q.x;
                py[i] = q.y;
            }
        }
        (px, py, vars)
    }
}

/// Leg components of the four corners: `(ax, ay, bx, by)` lanes.
pub(crate) struct Legs {
    pub ax: [f64; 4],
    pub ay: [f64; 4],
    pub bx: [f64; 4],
    pub by: [f64; 4],
}

/// Lane scalars of the four corner triangles of a cell (see the module docs).
#[inline(always)]
pub(crate) fn corner_lanes(px: &[f64; 4], py: &[f64; 4], c: usize) -> (CornerLanes, Legs) {
    let mut ex = [0.0; 4];
    let mut ey = [0.0; 4];
    for k in 0..4 {
        ex[k] = px[(k + 1) & 3] - px[k];
        ey[k] = py[(k + 1) & 3] - py[k];
    }
    let mut l2 = [0.0; 4];
    for k in 0..4 {
        l2[k] = ex[k] * ex[k] + ey[k] * ey[k];
    }
    let mut bx = [0.0; 4];
    let mut by = [0.0; 4];
    let mut lb = [0.0; 4];
    for k in 0..4 {
        bx[k] = -ex[(k + 3) & 3];
        by[k] = -ey[(k + 3) & 3];
        lb[k] = l2[(k + 3) & 3];
    }
    let mut alpha = [0.0; 4];
    let mut o = [0.0; 4];
    for k in 0..4 {
        alpha[k] = ex[k] * by[k] - ey[k] * bx[k];
        o[k] = ex[k] * bx[k] + ey[k] * by[k];
    }
    (
        CornerLanes {
            alpha,
            la: l2,
            lb,
            o,
            cell: c,
        },
        Legs {
            ax: ex,
            ay: ey,
            bx,
            by,
        },
    )
}

#[inline(always)]
fn points(px: &[f64; 4], py: &[f64; 4]) -> [DVec2; 4] {
    [
        DVec2::new(px[0], py[0]),
        DVec2::new(px[1], py[1]),
        DVec2::new(px[2], py[2]),
        DVec2::new(px[3], py[3]),
    ]
}

/// Value of the terms of cell `c`.
#[inline(always)]
pub(crate) fn cell_value<K: TriKernel>(
    k: &K,
    t: Terms,
    px: &[f64; 4],
    py: &[f64; 4],
    c: usize,
) -> f64 {
    let mut v = 0.0;
    if t.corners {
        let (s, _) = corner_lanes(px, py, c);
        let vl = k.corners_value(&s);
        for q in 0..4 {
            v += vl[q];
        }
    }
    if t.diagonal {
        let (_, _, s) = scalars(&points(px, py), c, 4);
        v += k.value(&s);
    }
    v
}

/// Value and gradient (`gx`, `gy` per vertex, overwritten) of the terms of cell `c`.
#[inline(always)]
pub(crate) fn cell_grad<K: TriKernel>(
    k: &K,
    t: Terms,
    px: &[f64; 4],
    py: &[f64; 4],
    c: usize,
    gx: &mut [f64; 4],
    gy: &mut [f64; 4],
) -> f64 {
    let mut v = 0.0;
    *gx = [0.0; 4];
    *gy = [0.0; 4];
    if t.corners {
        let (s, l) = corner_lanes(px, py, c);
        let d = k.corners_value_grad(&s);
        for q in 0..4 {
            v += d.v[q];
        }
        let (da, dla, dlb, dob) = (&d.g[0], &d.g[1], &d.g[2], &d.g[3]);
        let mut gax = [0.0; 4];
        let mut gay = [0.0; 4];
        let mut gbx = [0.0; 4];
        let mut gby = [0.0; 4];
        for q in 0..4 {
            let (ta, tb) = (2.0 * dla[q], 2.0 * dlb[q]);
            gax[q] = da[q] * l.by[q] + ta * l.ax[q] + dob[q] * l.bx[q];
            gay[q] = da[q] * -l.bx[q] + ta * l.ay[q] + dob[q] * l.by[q];
            gbx[q] = da[q] * -l.ay[q] + tb * l.bx[q] + dob[q] * l.ax[q];
            gby[q] = da[q] * l.ax[q] + tb * l.by[q] + dob[q] * l.ay[q];
        }
        // edge e_q = a_q = −b_{q+1}
        let mut gex = [0.0; 4];
        let mut gey = [0.0; 4];
        for q in 0..4 {
            gex[q] = gax[q] - gbx[(q + 1) & 3];
            gey[q] = gay[q] - gby[(q + 1) & 3];
        }
        for i in 0..4 {
            gx[i] = gex[(i + 3) & 3] - gex[i];
            gy[i] = gey[(i + 3) & 3] - gey[i];
        }
    }
    if t.diagonal {
        let (a, b, s) = scalars(&points(px, py), c, 4);
        let (val, dg) = k.value_grad(&s);
        v += val;
        let ga = dg[0] * DVec2::new(b.y, -b.x) + (2.0 * dg[1]) * a + dg[3] * b;
        let gb = dg[0] * DVec2::new(-a.y, a.x) + (2.0 * dg[2]) * b + dg[3] * a;
        let lg = LEGS[4];
        gx[lg[1]] += ga.x;
        gy[lg[1]] += ga.y;
        gx[lg[0]] -= ga.x;
        gy[lg[0]] -= ga.y;
        gx[lg[3]] += gb.x;
        gy[lg[3]] += gb.y;
        gx[lg[2]] -= gb.x;
        gy[lg[2]] -= gb.y;
    }
    v
}

/// `H += c·(g_s g_tᵀ + g_t g_sᵀ)` (`c·g_s g_sᵀ` if `same`) on the upper triangle, lane-wise,
/// skipping the products outside the supports `sup_s`, `sup_t` of the two gradients.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn sym_outer_add(
    hu: &mut [[[f64; 4]; 4]; 4],
    c: &[f64; 4],
    gs: &[[f64; 4]; 4],
    gt: &[[f64; 4]; 4],
    sup_s: &[bool; 4],
    sup_t: &[bool; 4],
    same: bool,
) {
    for u in 0..4 {
        for w in u..4 {
            let st = sup_s[u] && sup_t[w];
            let ts = !same && sup_t[u] && sup_s[w];
            if st || ts {
                for q in 0..4 {
                    let mut p = 0.0;
                    if st {
                        p += gs[u][q] * gt[w][q];
                    }
                    if ts {
                        p += gt[u][q] * gs[w][q];
                    }
                    hu[u][w][q] += c[q] * p;
                }
            }
        }
    }
}

#[inline(always)]
fn add_block(dst: &mut Block, s: f64, b: &Block) {
    for e in 0..4 {
        dst[e] += s * b[e];
    }
}

/// Value and the 16 node blocks `blk[i][j]` (`∂²F/∂v_i∂v_j`, overwritten) of the terms of
/// cell `c` (see the module docs for the block formulas).
#[inline(always)]
pub(crate) fn cell_hess<K: TriKernel>(
    k: &K,
    t: Terms,
    px: &[f64; 4],
    py: &[f64; 4],
    c: usize,
    blk: &mut [[Block; 4]; 4],
) -> f64 {
    let mut v = 0.0;
    if !t.corners {
        *blk = [[[0.0; 4]; 4]; 4];
    }
    if t.corners {
        let (s, l) = corner_lanes(px, py, c);
        let d = k.corners_hessian(&s);
        for q in 0..4 {
            v += d.v[q];
        }
        // ∇ᵤs per lane (u = (aₓ, a_y, bₓ, b_y)) with its structural support, and
        // H_u = Σ_{s,t} (∂²f/∂s∂t) ∇ᵤs ∇ᵤtᵀ over the non-zero pattern `sp` of the kernel
        // (a constant for typed kernels: the skipped pairs cost nothing).
        let sp = k.hessian_sparsity();
        let mut nbx = [0.0; 4];
        let mut nay = [0.0; 4];
        let mut tax = [0.0; 4];
        let mut tay = [0.0; 4];
        let mut tbx = [0.0; 4];
        let mut tby = [0.0; 4];
        for q in 0..4 {
            nbx[q] = -l.bx[q];
            nay[q] = -l.ay[q];
            tax[q] = 2.0 * l.ax[q];
            tay[q] = 2.0 * l.ay[q];
            tbx[q] = 2.0 * l.bx[q];
            tby[q] = 2.0 * l.by[q];
        }
        let z = [0.0; 4];
        let grads = [
            [l.by, nbx, nay, l.ax],
            [tax, tay, z, z],
            [z, z, tbx, tby],
            [l.bx, l.by, l.ax, l.ay],
        ];
        const ALL: [bool; 4] = [true; 4];
        const SUP: [[bool; 4]; 4] = [
            ALL,
            [true, true, false, false],
            [false, false, true, true],
            ALL,
        ];
        let mut hu = [[[0.0; 4]; 4]; 4];
        macro_rules! pair {
            ($s:literal, $t:literal) => {
                if sp[$s][$t] {
                    sym_outer_add(
                        &mut hu,
                        &d.h[$s][$t],
                        &grads[$s],
                        &grads[$t],
                        &SUP[$s],
                        &SUP[$t],
                        $s == $t,
                    );
                }
            };
        }
        pair!(0, 0);
        pair!(0, 1);
        pair!(0, 2);
        pair!(0, 3);
        pair!(1, 1);
        pair!(1, 2);
        pair!(1, 3);
        pair!(2, 2);
        pair!(2, 3);
        pair!(3, 3);
        for q in 0..4 {
            let (fa, fla, flb, fo) = (d.g[0][q], d.g[1][q], d.g[2][q], d.g[3][q]);
            hu[0][3][q] += fa;
            hu[1][2][q] -= fa;
            hu[0][0][q] += 2.0 * fla;
            hu[1][1][q] += 2.0 * fla;
            hu[2][2][q] += 2.0 * flb;
            hu[3][3][q] += 2.0 * flb;
            hu[0][2][q] += fo;
            hu[1][3][q] += fo;
        }
        // Leg blocks per lane, entry e of [xx, xy, yx, yy]: A = H_aa, B = H_ab, Bᵀ, C = H_bb.
        let a = [hu[0][0], hu[0][1], hu[0][1], hu[1][1]];
        let b = [hu[0][2], hu[0][3], hu[1][2], hu[1][3]];
        let bt = [hu[0][2], hu[1][2], hu[0][3], hu[1][3]];
        let cc = [hu[2][2], hu[2][3], hu[2][3], hu[3][3]];
        // Node blocks, lane-wise (lane i = node i, `rot(x, s)[i] = x[i − s]`):
        //   H_ii       = (A + B + Bᵀ + C)[i] + A[i−1] + C[i+1]   (P, Q and R roles of node i)
        //   H_i,i+1    = −(A + Bᵀ)[i] − (Bᵀ + C)[i+1]             (P–Q of corner i, R–P of i+1)
        //   H_i,i+2    = B[i−1] + Bᵀ[i+1]                          (Q–R of corners i∓1)
        let mut diag = [[0.0; 4]; 4];
        let mut adj = [[0.0; 4]; 4];
        let mut opp = [[0.0; 4]; 4];
        for e in 0..4 {
            for i in 0..4 {
                let (im, ip) = ((i + 3) & 3, (i + 1) & 3);
                diag[e][i] = (a[e][i] + b[e][i] + bt[e][i] + cc[e][i]) + a[e][im] + cc[e][ip];
                adj[e][i] = -(a[e][i] + bt[e][i]) - (bt[e][ip] + cc[e][ip]);
                opp[e][i] = b[e][im] + bt[e][ip];
            }
        }
        for i in 0..4 {
            let (ip, i2, im) = ((i + 1) & 3, (i + 2) & 3, (i + 3) & 3);
            blk[i][i] = [diag[0][i], diag[1][i], diag[2][i], diag[3][i]];
            blk[i][ip] = [adj[0][i], adj[1][i], adj[2][i], adj[3][i]];
            // H_i,i−1 = (H_i−1,i)ᵀ
            blk[i][im] = [adj[0][im], adj[2][im], adj[1][im], adj[3][im]];
            blk[i][i2] = [opp[0][i], opp[1][i], opp[2][i], opp[3][i]];
        }
    }
    if t.diagonal {
        let (a, b, s) = scalars(&points(px, py), c, 4);
        let d = k.eval(&s, Order::Hessian);
        v += d.v;
        let hu = super::leg_hessian(a, b, &d);
        let lg = LEGS[4];
        let ends = [
            (lg[1], 1.0, 0usize),
            (lg[0], -1.0, 0),
            (lg[3], 1.0, 1),
            (lg[2], -1.0, 1),
        ];
        for &(ni, si, li) in &ends {
            for &(nj, sj, lj) in &ends {
                let sg = si * sj;
                let h = [
                    hu[2 * li][2 * lj],
                    hu[2 * li][2 * lj + 1],
                    hu[2 * li + 1][2 * lj],
                    hu[2 * li + 1][2 * lj + 1],
                ];
                add_block(&mut blk[ni][nj], sg, &h);
            }
        }
    }
    v
}

// ---------------------------------------------------------------------------------------------
// chunk loops (compiled for the baseline target and, on x86-64, with AVX2)

/// Value of cells `start..end`, summed from 0.0 in cell order.
#[inline(always)]
fn value_range<K: TriKernel>(
    topo: &QuadTopology,
    k: &K,
    t: Terms,
    x: &[f64],
    start: usize,
    end: usize,
) -> f64 {
    let mut s = 0.0;
    for c in start..end {
        let (px, py, _) = topo.cell_xy(x, c);
        s += cell_value(k, t, &px, &py, c);
    }
    s
}

/// Value and gradient of cells `start..end`; gradient entries are written through `g` with the
/// first-contribution flags of [`QuadTopology::gfirst`].
#[inline(always)]
fn grad_range<K: TriKernel>(
    topo: &QuadTopology,
    k: &K,
    t: Terms,
    x: &[f64],
    g: SyncPtr,
    start: usize,
    end: usize,
) -> f64 {
    let mut s = 0.0;
    let mut gx = [0.0; 4];
    let mut gy = [0.0; 4];
    for c in start..end {
        let (px, py, vars) = topo.cell_xy(x, c);
        s += cell_grad(k, t, &px, &py, c, &mut gx, &mut gy);
        let first = topo.gfirst[c];
        for i in 0..4 {
            let j = vars[i];
            if j != FIXED {
                let j = 2 * j as usize;
                let f = (first >> i) & 1 != 0;
                // SAFETY: `j + 1 < num_vars = g.len()` (variable indices come from the topology
                // and `value_grad` checked `g.len()`); entries of a node of this cell are only
                // touched by this chunk within its colour (see `assembly`).
                unsafe {
                    g.put(j, gx[i], f);
                    g.put(j + 1, gy[i], f);
                }
            }
        }
    }
    s
}

/// Hessian blocks of cells `start..end` written into CSR `values` through `h` at the
/// precomputed slots (`ro` = the CSR row offsets, validated against the pattern).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn hess_range<K: TriKernel>(
    topo: &QuadTopology,
    k: &K,
    t: Terms,
    x: &[f64],
    slots: &[[u16; 16]],
    ro: &[usize],
    h: SyncPtr,
    start: usize,
    end: usize,
) {
    let mut blk = [[[0.0; 4]; 4]; 4];
    for c in start..end {
        let (px, py, vars) = topo.cell_xy(x, c);
        cell_hess(k, t, &px, &py, c, &mut blk);
        let sl = &slots[c];
        for i in 0..4 {
            let vi = vars[i];
            if vi == FIXED {
                continue;
            }
            let r0 = ro[2 * vi as usize];
            let r1 = ro[2 * vi as usize + 1];
            for jn in 0..4 {
                if vars[jn] == FIXED {
                    continue;
                }
                let e = sl[4 * i + jn];
                let kk = 2 * (e & !SLOT_FIRST) as usize;
                let f = e & SLOT_FIRST != 0;
                let b = &blk[i][jn];
                // SAFETY: `kk/2` is the position of `vars[jn]` in the neighbour list of `vi`
                // (built from the same lists as the pattern, which `matches_pattern` checked),
                // so `r0 + kk + 1 < r1` and `r1 + kk + 1 < row_offsets[2vi + 2] ≤ nnz`; rows of
                // a node of this cell are only touched by this chunk within its colour.
                unsafe {
                    h.put(r0 + kk, b[0], f);
                    h.put(r0 + kk + 1, b[1], f);
                    h.put(r1 + kk, b[2], f);
                    h.put(r1 + kk + 1, b[3], f);
                }
            }
        }
    }
}

/// `out += H v` restricted to cells `start..end` (matrix-free), with the gradient's
/// first-contribution flags.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn hess_vec_range<K: TriKernel>(
    topo: &QuadTopology,
    k: &K,
    t: Terms,
    x: &[f64],
    v: &[f64],
    out: SyncPtr,
    start: usize,
    end: usize,
) {
    let mut blk = [[[0.0; 4]; 4]; 4];
    for c in start..end {
        let (px, py, vars) = topo.cell_xy(x, c);
        cell_hess(k, t, &px, &py, c, &mut blk);
        let mut lx = [0.0; 4];
        let mut ly = [0.0; 4];
        for i in 0..4 {
            if vars[i] != FIXED {
                let j = 2 * vars[i] as usize;
                lx[i] = v[j];
                ly[i] = v[j + 1];
            }
        }
        let first = topo.gfirst[c];
        for i in 0..4 {
            if vars[i] == FIXED {
                continue;
            }
            let mut ox = 0.0;
            let mut oy = 0.0;
            for jn in 0..4 {
                let b = &blk[i][jn];
                ox += b[0] * lx[jn] + b[1] * ly[jn];
                oy += b[2] * lx[jn] + b[3] * ly[jn];
            }
            let j = 2 * vars[i] as usize;
            let f = (first >> i) & 1 != 0;
            // SAFETY: as in `grad_range` (`out.len() == num_vars` was checked by the caller).
            unsafe {
                out.put(j, ox, f);
                out.put(j + 1, oy, f);
            }
        }
    }
}

/// Defines a dispatcher that runs a chunk loop through its AVX2 copy when the CPU has AVX2.
macro_rules! simd_dispatch {
    ($name:ident, $avx:ident, $inner:ident, $ret:ty, ($($arg:ident : $ty:ty),*)) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        #[allow(clippy::too_many_arguments)]
        fn $avx<K: TriKernel>($($arg: $ty),*) -> $ret {
            $inner($($arg),*)
        }

        #[allow(clippy::too_many_arguments)]
        pub(crate) fn $name<K: TriKernel>($($arg: $ty),*) -> $ret {
            #[cfg(target_arch = "x86_64")]
            {
                if std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: the CPU supports AVX2 (checked just above), the only requirement
                    // of calling a `#[target_feature(enable = "avx2")]` function.
                    return unsafe { $avx($($arg),*) };
                }
            }
            $inner($($arg),*)
        }
    };
}

simd_dispatch!(value_chunk, value_chunk_avx2, value_range, f64,
    (topo: &QuadTopology, k: &K, t: Terms, x: &[f64], start: usize, end: usize));
simd_dispatch!(grad_chunk, grad_chunk_avx2, grad_range, f64,
    (topo: &QuadTopology, k: &K, t: Terms, x: &[f64], g: SyncPtr, start: usize, end: usize));
simd_dispatch!(hess_chunk, hess_chunk_avx2, hess_range, (),
    (topo: &QuadTopology, k: &K, t: Terms, x: &[f64], slots: &[[u16; 16]], ro: &[usize],
     h: SyncPtr, start: usize, end: usize));
simd_dispatch!(hess_vec_chunk, hess_vec_chunk_avx2, hess_vec_range, (),
    (topo: &QuadTopology, k: &K, t: Terms, x: &[f64], v: &[f64], out: SyncPtr, start: usize,
     end: usize));
