//! The per-tetrahedron term `λφ_ω(V)` and the per-face coplanarity term `k²` with their
//! gradients and closed-form 3×3 node blocks of the Hessian (see the module docs of [`super`]).

use glam::DVec3;

#[cfg(doc)]
use super::HexTopology;
use crate::kernel::phi_omega;

/// A tet with its stencil already multiplied by the scaling factors, and the two stencil
/// invariants of its node-block Hessian (see [`tet_term_blocks`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct ScaledTet {
    pub(super) nodes: [usize; 4],
    pub(super) w: [[f64; 4]; 3],
    /// `gram[j][l] = Σ_a w_aj w_al`.
    gram: [[f64; 4]; 4],
    /// `wx[j][l] = w_j × w_l` with `w_j = (w_0j, w_1j, w_2j)`.
    wx: [[DVec3; 4]; 4],
}

impl ScaledTet {
    pub(super) fn new(nodes: [usize; 4], w: [[f64; 4]; 3]) -> Self {
        let col = |j: usize| DVec3::new(w[0][j], w[1][j], w[2][j]);
        Self {
            nodes,
            w,
            gram: std::array::from_fn(|j| std::array::from_fn(|l| col(j).dot(col(l)))),
            wx: std::array::from_fn(|j| std::array::from_fn(|l| col(j).cross(col(l)))),
        }
    }
}

/// The Hessian of one cell as 8×8 node blocks (`[a][b]` = the 3×3 block of local vertices `a`,
/// `b`, row-major), the form the CSR slots of [`HexTopology::block_slots`] are written from.
pub(super) type CellBlocks = [[[f64; 9]; 8]; 8];

/// Adds the 3×3 block `blk` at `(a, b)` and its transpose at `(b, a)` (once if `a == b`; the
/// diagonal blocks built here are symmetric).
#[inline(always)]
fn add_block_sym(hb: &mut CellBlocks, a: usize, b: usize, blk: &[f64; 9]) {
    if a == b {
        for (o, v) in hb[a][a].iter_mut().zip(blk) {
            *o += v;
        }
    } else {
        for x in 0..3 {
            for y in 0..3 {
                hb[a][b][3 * x + y] += blk[3 * x + y];
                hb[b][a][3 * y + x] += blk[3 * x + y];
            }
        }
    }
}

/// `M(w)_{ij} = ε_{ijk} w_k`.
#[inline(always)]
fn eps_mat(w: DVec3) -> [[f64; 3]; 3] {
    [[0.0, w.z, -w.y], [-w.z, 0.0, w.x], [w.y, -w.x, 0.0]]
}

/// Hessian blocks of `det[c₀, c₁, c₂]`: `[a][b] = ε_{abc} M(c_c)`.
#[inline(always)]
fn det_hess(c: &[DVec3; 3]) -> [[[[f64; 3]; 3]; 3]; 3] {
    let mut h = [[[[0.0; 3]; 3]; 3]; 3];
    let m0 = eps_mat(c[0]);
    let m1 = eps_mat(c[1]);
    let m2 = eps_mat(c[2]);
    for i in 0..3 {
        for j in 0..3 {
            h[0][1][i][j] = m2[i][j];
            h[1][0][i][j] = -m2[i][j];
            h[1][2][i][j] = m0[i][j];
            h[2][1][i][j] = -m0[i][j];
            h[2][0][i][j] = m1[i][j];
            h[0][2][i][j] = -m1[i][j];
        }
    }
    h
}

/// Adds `sa·sb·H[a][b]` for three "legs" to the cell Hessian; `legs[a]` lists the `(node,
/// coefficient)` pairs of leg `a`.
#[inline(always)]
pub(super) fn scatter_hess3(
    legs: &[[(usize, f64); 4]; 3],
    hc: &[[[[f64; 3]; 3]; 3]; 3],
    h: &mut [[f64; 24]; 24],
) {
    for a in 0..3 {
        for &(na, wa) in &legs[a] {
            if wa == 0.0 {
                continue;
            }
            for b in 0..3 {
                for &(nb, wb) in &legs[b] {
                    if wb == 0.0 {
                        continue;
                    }
                    let s = wa * wb;
                    for i in 0..3 {
                        for j in 0..3 {
                            h[3 * na + i][3 * nb + j] += s * hc[a][b][i][j];
                        }
                    }
                }
            }
        }
    }
}

/// One tet term `wt·λ·φ_ω(V)`; adds gradient (and Hessian) to the cell arrays.
#[inline(always)]
pub(super) fn tet_term(
    t: &ScaledTet,
    p: &[DVec3; 8],
    omega: f64,
    wt: f64,
    g: &mut [DVec3; 8],
    h: Option<&mut [[f64; 24]; 24]>,
) -> f64 {
    let mut c = [DVec3::ZERO; 3];
    for (a, ca) in c.iter_mut().enumerate() {
        for j in 0..4 {
            *ca += t.w[a][j] * p[t.nodes[j]];
        }
    }
    let s = c[0].length_squared() + c[1].length_squared() + c[2].length_squared();
    let r = (s / 3.0).sqrt();
    let lam = r * r * r;
    let dv = [c[1].cross(c[2]), c[2].cross(c[0]), c[0].cross(c[1])];
    let v = c[0].dot(dv[0]);
    let phi = phi_omega(omega, v);
    let val = wt * lam * phi[0];
    let mut gc = [DVec3::ZERO; 3];
    for a in 0..3 {
        gc[a] = wt * (phi[0] * r * c[a] + lam * phi[1] * dv[a]);
        for j in 0..4 {
            g[t.nodes[j]] += t.w[a][j] * gc[a];
        }
    }
    if let Some(h) = h {
        let vh = det_hess(&c);
        let inv3r = if r > 0.0 { 1.0 / (3.0 * r) } else { 0.0 };
        let mut hc = [[[[0.0; 3]; 3]; 3]; 3];
        for a in 0..3 {
            let la = (r * c[a]).to_array();
            let va = dv[a].to_array();
            let ca = c[a].to_array();
            for b in 0..3 {
                let lb = (r * c[b]).to_array();
                let vb = dv[b].to_array();
                let cb = c[b].to_array();
                for i in 0..3 {
                    for j in 0..3 {
                        let mut lh = ca[i] * cb[j] * inv3r;
                        if a == b && i == j {
                            lh += r;
                        }
                        hc[a][b][i][j] = wt
                            * (phi[0] * lh
                                + phi[1] * (la[i] * vb[j] + va[i] * lb[j])
                                + lam * phi[2] * va[i] * vb[j]
                                + lam * phi[1] * vh[a][b][i][j]);
                    }
                }
            }
        }
        let legs: [[(usize, f64); 4]; 3] =
            std::array::from_fn(|a| std::array::from_fn(|j| (t.nodes[j], t.w[a][j])));
        scatter_hess3(&legs, &hc, h);
    }
    val
}

/// One tet term `wt·λ·φ_ω(V)` in node-block form; adds the gradient to `g` and, if asked,
/// the Hessian w.r.t. the tet's four vertices to the cell blocks `hb`.
///
/// With the columns `c_a = Σ_j w_aj X_j`, `α_j = Σ_a w_aj c_a`, `β_j = Σ_a w_aj ∂V/∂c_a`,
/// `G_jl = Σ_a w_aj w_al` and `w_j = (w_0j, w_1j, w_2j)`, the chain rule
/// `H_jl = Σ_ab w_aj w_bl ∂²f/∂c_a∂c_b` applied to the column Hessian of [`tet_term`]
/// (`∂²λ = rI + c_a c_bᵀ/(3r)`, `∂²V/∂c_a∂c_b = ε_abc M(c_c)`) gives, in closed form,
///
/// `H_jl = wt·[φ·(r G_jl I + α_j α_lᵀ/(3r)) + φ'·r(α_j β_lᵀ + β_j α_lᵀ) + λφ''·β_j β_lᵀ
///          + λφ'·M(Σ_c (w_j × w_l)_c c_c)]`
///
/// (`Σ_ab w_aj w_bl ε_abc = (w_j × w_l)_c`). Only the ten blocks `j ≤ l` are computed; the
/// others are their transposes. Checked against [`tet_term`] (the 24×24 reference) in tests.
#[inline(always)]
pub(super) fn tet_term_blocks(
    t: &ScaledTet,
    p: &[DVec3; 8],
    omega: f64,
    wt: f64,
    g: &mut [DVec3; 8],
    hb: Option<&mut CellBlocks>,
) -> f64 {
    let mut c = [DVec3::ZERO; 3];
    for (a, ca) in c.iter_mut().enumerate() {
        for j in 0..4 {
            *ca += t.w[a][j] * p[t.nodes[j]];
        }
    }
    let s = c[0].length_squared() + c[1].length_squared() + c[2].length_squared();
    let r = (s / 3.0).sqrt();
    let lam = r * r * r;
    let dv = [c[1].cross(c[2]), c[2].cross(c[0]), c[0].cross(c[1])];
    let v = c[0].dot(dv[0]);
    let phi = phi_omega(omega, v);
    let val = wt * lam * phi[0];
    let al: [DVec3; 4] =
        std::array::from_fn(|j| t.w[0][j] * c[0] + t.w[1][j] * c[1] + t.w[2][j] * c[2]);
    let be: [DVec3; 4] =
        std::array::from_fn(|j| t.w[0][j] * dv[0] + t.w[1][j] * dv[1] + t.w[2][j] * dv[2]);
    let (kg, kb) = (wt * phi[0] * r, wt * lam * phi[1]);
    for j in 0..4 {
        g[t.nodes[j]] += kg * al[j] + kb * be[j];
    }
    if let Some(hb) = hb {
        let inv3r = if r > 0.0 { 1.0 / (3.0 * r) } else { 0.0 };
        let k0 = wt * phi[0] * r;
        let k1 = wt * phi[0] * inv3r;
        let k2 = wt * phi[1] * r;
        let k3 = wt * lam * phi[2];
        let k4 = kb;
        // H_jl = k0 G_jl I + α_j P_lᵀ + β_j Q_lᵀ + M(z_jl)
        let pp: [DVec3; 4] = std::array::from_fn(|l| k1 * al[l] + k2 * be[l]);
        let qq: [DVec3; 4] = std::array::from_fn(|l| k2 * al[l] + k3 * be[l]);
        for j in 0..4 {
            let aj = al[j].to_array();
            let bj = be[j].to_array();
            for l in j..4 {
                let pl = pp[l].to_array();
                let ql = qq[l].to_array();
                let mut blk = [0.0; 9];
                for x in 0..3 {
                    for y in 0..3 {
                        blk[3 * x + y] = aj[x] * pl[y] + bj[x] * ql[y];
                    }
                }
                let d = k0 * t.gram[j][l];
                blk[0] += d;
                blk[4] += d;
                blk[8] += d;
                if j != l {
                    let wx = t.wx[j][l];
                    let z = k4 * (wx.x * c[0] + wx.y * c[1] + wx.z * c[2]);
                    // M(z)_{xy} = ε_{xyk} z_k
                    blk[1] += z.z;
                    blk[2] -= z.y;
                    blk[3] -= z.z;
                    blk[5] += z.x;
                    blk[6] += z.y;
                    blk[7] -= z.x;
                }
                add_block_sym(hb, t.nodes[j], t.nodes[l], &blk);
            }
        }
    }
    val
}

/// One face term `C·k²` in node-block form (the same derivatives as [`face_term`]; the legs
/// `B−A, D−A, C−A` have stencil `+1` on their own vertex and `−1` on `A`, so the blocks are
/// `H_{k l} = h_{kl}`, `H_{A l} = −Σ_k h_{kl}`, `H_{A A} = Σ_{kl} h_{kl}`).
#[inline(always)]
pub(super) fn face_term_blocks(
    f: [usize; 4],
    p: &[DVec3; 8],
    cpen: f64,
    g: &mut [DVec3; 8],
    hb: Option<&mut CellBlocks>,
) -> f64 {
    let want_h = hb.is_some();
    let Some((val, gy, hc)) = face_parts(f, p, cpen, want_h) else {
        return 0.0;
    };
    let (a, b, cc, d) = (f[0], f[1], f[2], f[3]);
    let leg_node = [b, d, cc];
    for k in 0..3 {
        g[leg_node[k]] += gy[k];
        g[a] -= gy[k];
    }
    if let (Some(hb), Some(hc)) = (hb, hc) {
        let flat =
            |k: usize, l: usize| -> [f64; 9] { std::array::from_fn(|e| hc[k][l][e / 3][e % 3]) };
        let mut row_sum = [[0.0; 9]; 3]; // Σ_k h_{kl}, per l
        let mut aa = [0.0; 9];
        for k in 0..3 {
            for l in k..3 {
                let blk = flat(k, l);
                add_block_sym(hb, leg_node[k], leg_node[l], &blk);
            }
            for l in 0..3 {
                let blk = flat(k, l);
                for e in 0..9 {
                    row_sum[l][e] += blk[e];
                    aa[e] += blk[e];
                }
            }
        }
        for l in 0..3 {
            let neg: [f64; 9] = std::array::from_fn(|e| -row_sum[l][e]);
            add_block_sym(hb, a, leg_node[l], &neg);
        }
        add_block_sym(hb, a, a, &aa);
    }
    val
}

/// Leg-Hessian blocks `h[k][l]` (3×3) of a face term w.r.t. its legs `B−A, D−A, C−A`.
type LegHess = [[[[f64; 3]; 3]; 3]; 3];

/// Value, leg gradients (w.r.t. `B−A, D−A, C−A`) and, with `want_h`, leg Hessian of the face
/// term `C·k²` of the hex-local face `f`; `None` for a degenerate face (`n₂w₂ = 0`).
#[inline(always)]
fn face_parts(
    f: [usize; 4],
    p: &[DVec3; 8],
    cpen: f64,
    want_h: bool,
) -> Option<(f64, [DVec3; 3], Option<LegHess>)> {
    let (a, b, cc, d) = (f[0], f[1], f[2], f[3]);
    // legs: u = B − A, v = D − A, w = C − A
    let y = [p[b] - p[a], p[d] - p[a], p[cc] - p[a]];
    let (u, v, w) = (y[0], y[1], y[2]);
    let uv = u.dot(v);
    let (uu, vv) = (u.length_squared(), v.length_squared());
    let n2 = uu * vv - uv * uv;
    let w2 = w.length_squared();
    let dd = n2 * w2;
    if dd.is_nan() || dd <= 0.0 {
        return None;
    }
    let dt = [v.cross(w), w.cross(u), u.cross(v)];
    let t = u.dot(dt[0]);
    let val = cpen * t * t / dd;
    // partials of g = t²/D
    let gt = cpen * 2.0 * t / dd;
    let gd = -cpen * t * t / (dd * dd);
    let dn2 = [
        2.0 * vv * u - 2.0 * uv * v,
        2.0 * uu * v - 2.0 * uv * u,
        DVec3::ZERO,
    ];
    let dw2 = [DVec3::ZERO, DVec3::ZERO, 2.0 * w];
    let d_den: [DVec3; 3] = std::array::from_fn(|k| w2 * dn2[k] + n2 * dw2[k]);
    let gy: [DVec3; 3] = std::array::from_fn(|k| gt * dt[k] + gd * d_den[k]);
    if !want_h {
        return Some((val, gy, None));
    }
    {
        let gtt = cpen * 2.0 / dd;
        let gtd = -cpen * 2.0 * t / (dd * dd);
        let gdd = cpen * 2.0 * t * t / (dd * dd * dd);
        let th = det_hess(&[u, v, w]);
        // Hessian of n2 (blocks uu, uv, vu, vv) and w2 (ww)
        let ua = u.to_array();
        let va = v.to_array();
        let mut n2h = [[[[0.0; 3]; 3]; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                let dij = if i == j { 1.0 } else { 0.0 };
                n2h[0][0][i][j] = 2.0 * vv * dij - 2.0 * va[i] * va[j];
                n2h[1][1][i][j] = 2.0 * uu * dij - 2.0 * ua[i] * ua[j];
                n2h[0][1][i][j] = 4.0 * ua[i] * va[j] - 2.0 * va[i] * ua[j] - 2.0 * uv * dij;
                n2h[1][0][j][i] = n2h[0][1][i][j];
            }
        }
        let mut hc = [[[[0.0; 3]; 3]; 3]; 3];
        for k in 0..3 {
            let tk = dt[k].to_array();
            let dk = d_den[k].to_array();
            let nk = dn2[k].to_array();
            let wk = dw2[k].to_array();
            for l in 0..3 {
                let tl = dt[l].to_array();
                let dl = d_den[l].to_array();
                let nl = dn2[l].to_array();
                let wl = dw2[l].to_array();
                for i in 0..3 {
                    for j in 0..3 {
                        let mut ddh = w2 * n2h[k][l][i][j] + nk[i] * wl[j] + wk[i] * nl[j];
                        if k == 2 && l == 2 && i == j {
                            ddh += 2.0 * n2;
                        }
                        hc[k][l][i][j] = gtt * tk[i] * tl[j]
                            + gtd * (tk[i] * dl[j] + dk[i] * tl[j])
                            + gdd * dk[i] * dl[j]
                            + gt * th[k][l][i][j]
                            + gd * ddh;
                    }
                }
            }
        }
        Some((val, gy, Some(hc)))
    }
}

/// One face term `C·k²` for the hex-local face `f` (24×24 reference form).
#[inline(always)]
pub(super) fn face_term(
    f: [usize; 4],
    p: &[DVec3; 8],
    cpen: f64,
    g: &mut [DVec3; 8],
    h: Option<&mut [[f64; 24]; 24]>,
) -> f64 {
    let Some((val, gy, hc)) = face_parts(f, p, cpen, h.is_some()) else {
        return 0.0;
    };
    let (a, b, cc, d) = (f[0], f[1], f[2], f[3]);
    g[b] += gy[0];
    g[d] += gy[1];
    g[cc] += gy[2];
    g[a] -= gy[0] + gy[1] + gy[2];
    if let (Some(h), Some(hc)) = (h, hc) {
        let legs = [
            [(b, 1.0), (a, -1.0), (a, 0.0), (a, 0.0)],
            [(d, 1.0), (a, -1.0), (a, 0.0), (a, 0.0)],
            [(cc, 1.0), (a, -1.0), (a, 0.0), (a, 0.0)],
        ];
        scatter_hess3(&legs, &hc, h);
    }
    val
}
