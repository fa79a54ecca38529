//! Tensor-product B-spline maps `x(ξ, η) = Σ_i Σ_j P_{i,j} B^k_i(ξ) B^k_j(η)` of order 2
//! (bilinear, (6)) and 3 (biquadratic, (27)) on the clamped uniform knots of [`crate::knots`]
//! ([Abelló et al., §1.1–§1.3]).
//!
//! # Fast per-patch evaluation
//! On construction every patch `U_{ij}` is converted to Bézier form (step 1 of our working-out of
//! Observation 3, by the usual knot-insertion formulas): in each direction the local control points
//! `P_a, P_{a+1}, P_{a+2}` of a quadratic segment `[t_μ, t_{μ+1}]` (0-based span `μ`, `a = μ − 2`)
//! become `b₀ = ((t_{μ+1} − t_μ)P_a + (t_μ − t_{μ−1})P_{a+1})/(t_{μ+1} − t_{μ−1})`, `b₁ = P_{a+1}`,
//! `b₂ = ((t_{μ+2} − t_{μ+1})P_{a+1} + (t_{μ+1} − t_μ)P_{a+2})/(t_{μ+2} − t_μ)` (linear segments
//! are already Bézier). Points and derivatives are then Bernstein sums over 3×3 (2×2) points.
//!
//! # Jacobian
//! `det J = x_ξ y_η − x_η y_ξ` (3). Per patch it is a polynomial of bidegree `(2d−1, 2d−1)` (`d`
//! the degree; the paper's "bicubic spline" is bicubic per patch, but in general only C⁰ across
//! breakpoints), stored as Bernstein coefficients (step 2, for any degree `d`):
//! `c_ab = d²/(Δξ Δη) Σ_{k+k'=a} Σ_{l+l'=b} [C(d−1,k)C(d,k')/C(2d−1,a)]·[C(d,l)C(d−1,l')/C(2d−1,b)]·
//! det[Δ^u b_{k,l}, Δ^v b_{k',l'}]` with `Δ^u b_{k,l} = b_{k+1,l} − b_{k,l}`,
//! `Δ^v b_{k,l} = b_{k,l+1} − b_{k,l}` and the patch widths `Δξ, Δη` (step 3, `1/Δξ = n − 2` for
//! uniform biquadratic knots). For `d = 1` the four coefficients are the four triangle
//! determinants of Prop 1; for `d = 2` they are the 16 coefficients of Observation 3. They are
//! also kept in the power basis for the fast sampler ([`crate::sample`]).
//!
//! # Closed forms (for checking)
//! [`TensorMap::det_j_closed_form`] evaluates the paper's formulas literally, with these
//! corrections:
//! * bilinear, Prop 1 with the factor `(n−1)(m−1)` multiplying (the printed (14) divides by it:
//!   (19)–(20) invert `1/(ξ_{i+1} − ξ_i) = n − 1`):
//!   `det J = (n−1)(m−1) Σ_{r=i}^{i+1} Σ_{s=j}^{j+1} det[h_{i,s} | v_{r,j}] B²_r(ξ) B²_s(η)`;
//! * biquadratic, Prop 2 (39) with `α_{r',s'} = γ_{r'} δ_{s'}` (the table (40) is garbled
//!   in print; this reading agrees with finite differences):
//!   `det J = (n−2)(m−2) Σ_{r=i}^{i+2} Σ_{s=j}^{j+2} Σ_{r'=i}^{i+1} Σ_{s'=j}^{j+1} γ_{r'} δ_{s'}
//!   det[h_{r',s} | v_{r,s'}] B³_r(ξ) B³_s(η) B²_{r'+1}(ξ) B²_{s'+1}(η)`,
//!   the `B²` being order-2 B-splines on the same knots (23) and
//!   `γ_r = 2Δ/(t_{r+3} − t_{r+1})` (the general form of (37), valid for `n = 3` too).

use glam::DVec2;

use crate::error::BsplineError;
use crate::knots::KnotVector;
use crate::net::ControlNet;

/// The degree of a tensor-product map.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Degree {
    /// Order 2 × 2 (§1.2).
    Bilinear,
    /// Order 3 × 3 (§1.3).
    Biquadratic,
}

impl Degree {
    /// The polynomial degree `d` (1 or 2).
    pub fn degree(self) -> usize {
        match self {
            Degree::Bilinear => 1,
            Degree::Biquadratic => 2,
        }
    }
    /// The order `d + 1`.
    pub fn order(self) -> usize {
        self.degree() + 1
    }
    /// From a polynomial degree 1 or 2.
    pub fn from_degree(d: usize) -> Result<Self, BsplineError> {
        match d {
            1 => Ok(Degree::Bilinear),
            2 => Ok(Degree::Biquadratic),
            _ => Err(BsplineError::Order {
                order: d + 1,
                reason: "tensor-product maps are bilinear (degree 1) or biquadratic (degree 2)",
            }),
        }
    }
}

/// One patch in Bézier form with its Jacobian polynomial.
#[derive(Debug, Clone, PartialEq)]
pub struct Patch {
    /// Bézier points `b[k][l]`, `k` along ξ, `l` along η (`0..=d`).
    pub bezier: [[DVec2; 3]; 3],
    /// Bernstein coefficients `c[a][b]` of `det J` (global parameters), `0..=2d−1`.
    pub jac: [[f64; 4]; 4],
    /// The same polynomial in the local power basis: `det J = Σ p[a][b] u^a v^b`.
    pub jac_power: [[f64; 4]; 4],
    /// `[ξ₀, ξ₁]` of the patch.
    pub xi: (f64, f64),
    /// `[η₀, η₁]` of the patch.
    pub eta: (f64, f64),
}

/// A tensor-product B-spline map from a control net.
#[derive(Debug, Clone)]
pub struct TensorMap {
    degree: Degree,
    net: ControlNet,
    kx: KnotVector,
    ky: KnotVector,
    npx: usize,
    npy: usize,
    patches: Vec<Patch>,
}

const BINOM: [[f64; 4]; 4] = [
    [1.0, 0.0, 0.0, 0.0],
    [1.0, 1.0, 0.0, 0.0],
    [1.0, 2.0, 1.0, 0.0],
    [1.0, 3.0, 3.0, 1.0],
];

/// Bernstein polynomials of degree `d ≤ 3` at `u`.
#[inline]
pub fn bernstein(d: usize, u: f64) -> [f64; 4] {
    let w = 1.0 - u;
    match d {
        0 => [1.0, 0.0, 0.0, 0.0],
        1 => [w, u, 0.0, 0.0],
        2 => [w * w, 2.0 * u * w, u * u, 0.0],
        _ => [w * w * w, 3.0 * u * w * w, 3.0 * u * u * w, u * u * u],
    }
}

/// Bernstein → power conversion matrix for degree `e ≤ 3`: `B^e_a(u) = Σ_p M[a][p] u^p`,
/// `M[a][p] = (−1)^{p−a} C(e,p) C(p,a)` for `p ≥ a`.
fn bern_to_power(e: usize) -> [[f64; 4]; 4] {
    let mut m = [[0.0; 4]; 4];
    for a in 0..=e {
        for p in a..=e {
            let s = if (p - a) % 2 == 0 { 1.0 } else { -1.0 };
            m[a][p] = s * BINOM[e][p] * BINOM[p][a];
        }
    }
    m
}

/// 1-D Bézier extraction: `b = E·(P_{μ−d}, …, P_μ)` for the span `μ` of order-`d+1` knots.
fn extraction(k: &KnotVector, mu: usize) -> [[f64; 3]; 3] {
    let t = k.knots();
    match k.degree() {
        1 => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0; 3]],
        _ => {
            let d0 = t[mu + 1] - t[mu - 1];
            let d2 = t[mu + 2] - t[mu];
            let e0 = if d0 > 0.0 {
                [(t[mu + 1] - t[mu]) / d0, (t[mu] - t[mu - 1]) / d0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            };
            let e2 = if d2 > 0.0 {
                [0.0, (t[mu + 2] - t[mu + 1]) / d2, (t[mu + 1] - t[mu]) / d2]
            } else {
                [0.0, 1.0, 0.0]
            };
            [e0, [0.0, 1.0, 0.0], e2]
        }
    }
}

impl TensorMap {
    /// The map of `degree` on the clamped uniform knots (4)/(5) or (23)/(24) for `net`
    /// (needs `n, m ≥ degree + 1`).
    pub fn new(degree: Degree, net: ControlNet) -> Result<Self, BsplineError> {
        let kx = KnotVector::clamped_uniform(degree.order(), net.n())?;
        let ky = KnotVector::clamped_uniform(degree.order(), net.m())?;
        let d = degree.degree();
        let npx = net.n() - d;
        let npy = net.m() - d;
        let mut map = Self {
            degree,
            net,
            kx,
            ky,
            npx,
            npy,
            patches: Vec::with_capacity(npx * npy),
        };
        for py in 0..npy {
            for px in 0..npx {
                let p = map.build_patch(px, py);
                map.patches.push(p);
            }
        }
        Ok(map)
    }

    /// Shorthand for a bilinear map.
    pub fn bilinear(net: ControlNet) -> Result<Self, BsplineError> {
        Self::new(Degree::Bilinear, net)
    }

    /// Shorthand for a biquadratic map (needs `n, m ≥ 3`).
    pub fn biquadratic(net: ControlNet) -> Result<Self, BsplineError> {
        Self::new(Degree::Biquadratic, net)
    }

    fn build_patch(&self, px: usize, py: usize) -> Patch {
        let d = self.degree.degree();
        let (mux, muy) = (px + d, py + d);
        let ex = extraction(&self.kx, mux);
        let ey = extraction(&self.ky, muy);
        let mut b = [[DVec2::ZERO; 3]; 3];
        for (k, exk) in ex.iter().enumerate().take(d + 1) {
            for (l, eyl) in ey.iter().enumerate().take(d + 1) {
                let mut s = DVec2::ZERO;
                for a in 0..=d {
                    for c in 0..=d {
                        let w = exk[a] * eyl[c];
                        if w != 0.0 {
                            s += w * self.net.get(px + a, py + c);
                        }
                    }
                }
                b[k][l] = s;
            }
        }
        let tx = self.kx.knots();
        let ty = self.ky.knots();
        let xi = (tx[mux], tx[mux + 1]);
        let eta = (ty[muy], ty[muy + 1]);
        let scale = (d * d) as f64 / ((xi.1 - xi.0) * (eta.1 - eta.0));
        let e = 2 * d - 1;
        let mut c = [[0.0; 4]; 4];
        for k in 0..d {
            for kp in 0..=d {
                let a = k + kp;
                let wu = BINOM[d - 1][k] * BINOM[d][kp] / BINOM[e][a];
                for l in 0..=d {
                    for lp in 0..d {
                        let bb = l + lp;
                        let wv = BINOM[d][l] * BINOM[d - 1][lp] / BINOM[e][bb];
                        let du = b[k + 1][l] - b[k][l];
                        let dv = b[kp][lp + 1] - b[kp][lp];
                        c[a][bb] += scale * wu * wv * du.perp_dot(dv);
                    }
                }
            }
        }
        let mtx = bern_to_power(e);
        let mut p = [[0.0; 4]; 4];
        for a in 0..=e {
            for bb in 0..=e {
                if c[a][bb] == 0.0 {
                    continue;
                }
                for pa in a..=e {
                    for pb in bb..=e {
                        p[pa][pb] += c[a][bb] * mtx[a][pa] * mtx[bb][pb];
                    }
                }
            }
        }
        Patch {
            bezier: b,
            jac: c,
            jac_power: p,
            xi,
            eta,
        }
    }

    /// The degree.
    pub fn degree(&self) -> Degree {
        self.degree
    }
    /// The control net.
    pub fn net(&self) -> &ControlNet {
        &self.net
    }
    /// The ξ knots.
    pub fn knots_xi(&self) -> &KnotVector {
        &self.kx
    }
    /// The η knots.
    pub fn knots_eta(&self) -> &KnotVector {
        &self.ky
    }
    /// Number of patches along ξ and η: `(n − d, m − d)`.
    pub fn num_patches(&self) -> (usize, usize) {
        (self.npx, self.npy)
    }
    /// Patch `(px, py)` (0-based; the paper's `U_{px+1, py+1}`).
    pub fn patch(&self, px: usize, py: usize) -> &Patch {
        &self.patches[py * self.npx + px]
    }
    /// All patches, `py·npx + px` order.
    pub fn patches(&self) -> &[Patch] {
        &self.patches
    }

    /// Patch indices and local coordinates `(u, v) ∈ [0,1]²` of `(ξ, η)` (clamped to `U`).
    #[inline]
    pub fn locate(&self, xi: f64, eta: f64) -> (usize, usize, f64, f64) {
        let d = self.degree.degree();
        let mux = self.kx.span(xi);
        let muy = self.ky.span(eta);
        let (px, py) = (mux - d, muy - d);
        let p = &self.patches[py * self.npx + px];
        let u = ((xi.clamp(0.0, 1.0) - p.xi.0) / (p.xi.1 - p.xi.0)).clamp(0.0, 1.0);
        let v = ((eta.clamp(0.0, 1.0) - p.eta.0) / (p.eta.1 - p.eta.0)).clamp(0.0, 1.0);
        (px, py, u, v)
    }

    /// `x(ξ, η)` (per-patch Bézier evaluation).
    pub fn eval(&self, xi: f64, eta: f64) -> DVec2 {
        let (px, py, u, v) = self.locate(xi, eta);
        let d = self.degree.degree();
        let p = &self.patches[py * self.npx + px];
        let (bu, bv) = (bernstein(d, u), bernstein(d, v));
        let mut s = DVec2::ZERO;
        for k in 0..=d {
            for l in 0..=d {
                s += bu[k] * bv[l] * p.bezier[k][l];
            }
        }
        s
    }

    /// `(x, x_ξ, x_η)` at `(ξ, η)` (per-patch Bézier evaluation).
    pub fn partials(&self, xi: f64, eta: f64) -> (DVec2, DVec2, DVec2) {
        let (px, py, u, v) = self.locate(xi, eta);
        let d = self.degree.degree();
        let p = &self.patches[py * self.npx + px];
        let (bu, bv) = (bernstein(d, u), bernstein(d, v));
        let (bu1, bv1) = (bernstein(d - 1, u), bernstein(d - 1, v));
        let mut x = DVec2::ZERO;
        let mut xu = DVec2::ZERO;
        let mut xv = DVec2::ZERO;
        for k in 0..=d {
            for l in 0..=d {
                x += bu[k] * bv[l] * p.bezier[k][l];
            }
        }
        for k in 0..d {
            for l in 0..=d {
                xu += bu1[k] * bv[l] * (p.bezier[k + 1][l] - p.bezier[k][l]);
            }
        }
        for k in 0..=d {
            for l in 0..d {
                xv += bu[k] * bv1[l] * (p.bezier[k][l + 1] - p.bezier[k][l]);
            }
        }
        let df = d as f64;
        (
            x,
            df * xu / (p.xi.1 - p.xi.0),
            df * xv / (p.eta.1 - p.eta.0),
        )
    }

    /// `det J = x_ξ y_η − x_η y_ξ` (3) from [`partials`](Self::partials).
    pub fn det_j(&self, xi: f64, eta: f64) -> f64 {
        let (_, a, b) = self.partials(xi, eta);
        a.perp_dot(b)
    }

    /// `det J` from the patch's Bernstein coefficients (must equal [`det_j`](Self::det_j)).
    pub fn det_j_bernstein(&self, xi: f64, eta: f64) -> f64 {
        let (px, py, u, v) = self.locate(xi, eta);
        let e = 2 * self.degree.degree() - 1;
        let p = &self.patches[py * self.npx + px];
        let (bu, bv) = (bernstein(e, u), bernstein(e, v));
        let mut s = 0.0;
        for a in 0..=e {
            for b in 0..=e {
                s += p.jac[a][b] * bu[a] * bv[b];
            }
        }
        s
    }

    /// `x(ξ, η)` by the definition (2): the double sum over **all** control points with the
    /// literal Cox–de Boor recursion. Slow; the reference the fast paths are tested against.
    pub fn eval_cox_de_boor(&self, xi: f64, eta: f64) -> DVec2 {
        let mut s = DVec2::ZERO;
        for j in 0..self.net.m() {
            let bj = self.ky.basis(j, eta);
            if bj == 0.0 {
                continue;
            }
            for i in 0..self.net.n() {
                s += self.kx.basis(i, xi) * bj * self.net.get(i, j);
            }
        }
        s
    }

    /// `(x_ξ, x_η)` by the definition with the derivative formula (33) (reference path).
    pub fn partials_cox_de_boor(&self, xi: f64, eta: f64) -> (DVec2, DVec2) {
        let mut a = DVec2::ZERO;
        let mut b = DVec2::ZERO;
        for j in 0..self.net.m() {
            let (bj, dbj) = (self.ky.basis(j, eta), self.ky.basis_derivative(j, eta));
            for i in 0..self.net.n() {
                let (bi, dbi) = (self.kx.basis(i, xi), self.kx.basis_derivative(i, xi));
                let p = self.net.get(i, j);
                a += dbi * bj * p;
                b += bi * dbj * p;
            }
        }
        (a, b)
    }

    /// `γ_r = 2Δ/(t_{r+3} − t_{r+1})` (0-based `r`, `Δ = 1/(n−2)`), the general form of (37)
    /// for the ξ knots of a biquadratic map; `γ = 1` for a bilinear map.
    pub fn gamma(&self, r: usize) -> f64 {
        gamma_of(&self.kx, r)
    }

    /// `δ_s` of (38): [`gamma`](Self::gamma) for the η knots.
    pub fn delta(&self, s: usize) -> f64 {
        gamma_of(&self.ky, s)
    }

    /// `det J` by the paper's closed forms, corrected (module docs): Prop 1
    /// with the factor `(n−1)(m−1)` for bilinear maps, Prop 2 (39) with `α = γδ` for
    /// biquadratic ones. Uses the literal Cox–de Boor recursion for the `B³` and `B²`.
    pub fn det_j_closed_form(&self, xi: f64, eta: f64) -> f64 {
        let net = &self.net;
        let det = |a: DVec2, b: DVec2| a.perp_dot(b);
        match self.degree {
            Degree::Bilinear => {
                let i = self.kx.span(xi) - 1;
                let j = self.ky.span(eta) - 1;
                let f = (net.n() - 1) as f64 * (net.m() - 1) as f64;
                let mut s = 0.0;
                for r in i..=i + 1 {
                    for sj in j..=j + 1 {
                        s += det(net.h(i, sj), net.v(r, j))
                            * self.kx.basis(r, xi)
                            * self.ky.basis(sj, eta);
                    }
                }
                f * s
            }
            Degree::Biquadratic => {
                let i = self.kx.span(xi) - 2;
                let j = self.ky.span(eta) - 2;
                let f = (net.n() - 2) as f64 * (net.m() - 2) as f64;
                let mut s = 0.0;
                for r in i..=i + 2 {
                    let br = self.kx.basis(r, xi);
                    for sj in j..=j + 2 {
                        let bs = self.ky.basis(sj, eta);
                        for rp in i..=i + 1 {
                            let b2r = self.kx.basis_of_order(rp + 1, 2, xi);
                            for sp in j..=j + 1 {
                                let b2s = self.ky.basis_of_order(sp + 1, 2, eta);
                                let alpha = self.gamma(rp) * self.delta(sp);
                                s += alpha * det(net.h(rp, sj), net.v(r, sp)) * br * bs * b2r * b2s;
                            }
                        }
                    }
                }
                f * s
            }
        }
    }

    /// The image of the parameter boundary `∂U` as the four control polygons' curves (for
    /// Lemma 4 checks): `x(ξ, 0)`, `x(1, η)`, `x(ξ, 1)`, `x(0, η)`.
    pub fn boundary_point(&self, side: usize, t: f64) -> DVec2 {
        match side {
            0 => self.eval(t, 0.0),
            1 => self.eval(1.0, t),
            2 => self.eval(t, 1.0),
            _ => self.eval(0.0, t),
        }
    }
}

fn gamma_of(k: &KnotVector, r: usize) -> f64 {
    if k.order() != 3 {
        return 1.0;
    }
    let t = k.knots();
    let delta = 1.0 / (k.num_basis() - 2) as f64;
    let den = t[r + 3] - t[r + 1];
    if den > 0.0 {
        2.0 * delta / den
    } else {
        0.0
    }
}
