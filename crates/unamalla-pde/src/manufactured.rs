//! Manufactured solutions for verifying the solver: pick `U`, set `g = L U` analytically and
//! `U` itself as Dirichlet data, solve, and compare the discrete solution with `U` at the
//! nodes.
//!
//! * [`Manufactured::sin_cosh`]: `U = sin(πx)·cosh(y)`, `U_xx = −π²U`, `U_yy = U`,
//!   `U_xy = π cos(πx) sinh(y)`. With the Laplacian (`a = c = 1`) the source is
//!   `g = (1 − π²)U` — note that `U` is not harmonic; it is for the anisotropic operator
//!   `U_xx + π²U_yy` (`a = 1, c = π²`, `g = 0`).
//! * [`Manufactured::polynomial`]: the cubic
//!   `U = 1 + 2x − 3y + x² − 2xy + 1.5y² + 0.5x³ − x²y + 0.7xy² − 0.4y³` (every monomial of
//!   degree ≤ 3 present), `U_xx = 2 + 3x − 2y`, `U_xy = −2 − 2x + 1.4y`,
//!   `U_yy = 3 + 1.4x − 2.4y`. The scheme is exact for it on affine grids (crate docs of
//!   [`unamalla_pde`](crate)), so on curved grids the whole error is the metric's.
//!
//! Both are written in coordinates of size about 1: on a map in kilometres `cosh y` overflows.
//! [`Manufactured::in_frame`] evaluates them in the scaled coordinates `p̂ = (p − o)/L` (for
//! instance the mesh's bounding box mapped into the unit square, [`Manufactured::on_box`]):
//! `Û(p) = U(p̂)`, and by the chain rule `Û_xx = U_x̂x̂ / L²`, `Û_xy = U_x̂ŷ / L²`,
//! `Û_yy = U_ŷŷ / L²`.

use std::sync::Arc;

use unamalla_mesh::DVec2;

use super::{Equation, SideValue, Source};

/// A closed-form `U` with its second derivatives.
#[derive(Debug, Clone, Copy)]
pub struct Manufactured {
    /// A short name (`sin-cosh`, `poly`).
    pub name: &'static str,
    u: fn(DVec2) -> f64,
    /// `(U_xx, U_xy, U_yy)`.
    hess: fn(DVec2) -> (f64, f64, f64),
    /// The frame `(o, L)`: `U` is evaluated at `(p − o)/L` (identity: `o = 0`, `L = 1`).
    origin: DVec2,
    scale: f64,
}

fn sc_u(p: DVec2) -> f64 {
    (std::f64::consts::PI * p.x).sin() * p.y.cosh()
}
fn sc_h(p: DVec2) -> (f64, f64, f64) {
    let pi = std::f64::consts::PI;
    let u = sc_u(p);
    (-pi * pi * u, pi * (pi * p.x).cos() * p.y.sinh(), u)
}
fn poly_u(p: DVec2) -> f64 {
    let (x, y) = (p.x, p.y);
    1.0 + 2.0 * x - 3.0 * y + x * x - 2.0 * x * y + 1.5 * y * y + 0.5 * x * x * x - x * x * y
        + 0.7 * x * y * y
        - 0.4 * y * y * y
}
fn poly_h(p: DVec2) -> (f64, f64, f64) {
    let (x, y) = (p.x, p.y);
    (
        2.0 + 3.0 * x - 2.0 * y,
        -2.0 - 2.0 * x + 1.4 * y,
        3.0 + 1.4 * x - 2.4 * y,
    )
}

impl Manufactured {
    /// `U = sin(πx)·cosh(y)`.
    pub fn sin_cosh() -> Self {
        Self {
            name: "sin-cosh",
            u: sc_u,
            hess: sc_h,
            origin: DVec2::ZERO,
            scale: 1.0,
        }
    }

    /// The cubic polynomial of the module docs.
    pub fn polynomial() -> Self {
        Self {
            name: "poly",
            u: poly_u,
            hess: poly_h,
            origin: DVec2::ZERO,
            scale: 1.0,
        }
    }

    /// By name: `sin-cosh` or `poly`.
    pub fn by_name(name: &str) -> Option<Self> {
        match name {
            "sin-cosh" => Some(Self::sin_cosh()),
            "poly" => Some(Self::polynomial()),
            _ => None,
        }
    }

    /// The same solution evaluated in the frame `p̂ = (p − origin)/scale` (module docs).
    ///
    /// # Panics
    /// If `scale` is not finite and positive (a programming error: [`on_box`](Self::on_box)
    /// builds the frame of a mesh).
    pub fn in_frame(self, origin: DVec2, scale: f64) -> Self {
        assert!(
            scale.is_finite() && scale > 0.0,
            "frame scale {scale} must be finite and positive"
        );
        Self {
            origin,
            scale,
            ..self
        }
    }

    /// The frame that maps the bounding box of `nodes` into the unit square: origin the box's
    /// lower-left corner, `L` its larger side (the same factor on both axes, so the operator's
    /// coefficients keep their meaning). `None` for no nodes or a box of zero or non-finite
    /// size.
    pub fn on_box(self, nodes: &[DVec2]) -> Option<Self> {
        let lo = nodes
            .iter()
            .fold(DVec2::splat(f64::INFINITY), |a, p| a.min(*p));
        let hi = nodes
            .iter()
            .fold(DVec2::splat(f64::NEG_INFINITY), |a, p| a.max(*p));
        let l = (hi - lo).max_element();
        (l.is_finite() && l > 0.0).then(|| self.in_frame(lo, l))
    }

    /// The frame `(origin, L)` of [`in_frame`](Self::in_frame).
    pub fn frame(&self) -> (DVec2, f64) {
        (self.origin, self.scale)
    }

    fn local(&self, p: DVec2) -> DVec2 {
        (p - self.origin) / self.scale
    }

    /// `U(p)` (in the frame).
    pub fn exact(&self, p: DVec2) -> f64 {
        (self.u)(self.local(p))
    }

    /// `(U_xx, U_xy, U_yy)` at `p` with respect to the mesh coordinates (chain rule of the
    /// frame, module docs).
    pub fn second_derivatives(&self, p: DVec2) -> (f64, f64, f64) {
        let (a, b, c) = (self.hess)(self.local(p));
        let l2 = self.scale * self.scale;
        (a / l2, b / l2, c / l2)
    }

    /// The equation with coefficients `a, b, c, d` whose source is `g = a U_xx + 2b U_xy +
    /// c U_yy + d U`.
    pub fn equation(&self, a: f64, b: f64, c: f64, d: f64) -> Equation {
        let m = *self;
        let g = move |p: DVec2| {
            let (uxx, uxy, uyy) = m.second_derivatives(p);
            a * uxx + 2.0 * b * uxy + c * uyy + d * m.exact(p)
        };
        Equation::new(a, b, c, d, Source::Function(Arc::new(g)))
    }

    /// `U` as Dirichlet data.
    pub fn boundary(&self) -> SideValue {
        let m = *self;
        SideValue::Function(Arc::new(move |p: DVec2| m.exact(p)))
    }

    /// `[U; 4]` for the four sides of a structured grid.
    pub fn sides(&self) -> [SideValue; 4] {
        let b = self.boundary();
        [b.clone(), b.clone(), b.clone(), b]
    }

    /// The nodal error of a discrete solution `u` on `nodes`.
    pub fn error(&self, nodes: &[DVec2], u: &[f64]) -> ErrorNorms {
        let mut max: f64 = 0.0;
        let mut s2 = 0.0;
        let mut umax: f64 = 0.0;
        for (p, v) in nodes.iter().zip(u) {
            let exact = self.exact(*p);
            let e = (v - exact).abs();
            max = max.max(e);
            umax = umax.max(exact.abs());
            s2 += e * e;
        }
        ErrorNorms {
            max,
            rms: (s2 / nodes.len().max(1) as f64).sqrt(),
            exact_max: umax,
        }
    }
}

/// Discrete error norms over the nodes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorNorms {
    /// `max |u_h − U|`.
    pub max: f64,
    /// `√(mean (u_h − U)²)`.
    pub rms: f64,
    /// `max |U|` over the nodes (the scale for a relative error: `max / exact_max`).
    pub exact_max: f64,
}

/// The observed order `log(e_coarse/e_fine)/log(h_coarse/h_fine)`.
pub fn observed_order(e_coarse: f64, e_fine: f64, h_ratio: f64) -> f64 {
    (e_coarse / e_fine).ln() / h_ratio.ln()
}

/// A curved test region as a smooth family of grids: the quarter annulus
/// `1 ≤ r ≤ 2 + 0.2·sin(4θ)`, `0 ≤ θ ≤ π/2` (wavy outer arc), `m × n` nodes by TFI (uniform
/// parameters) of the analytic sides sampled uniformly in their parameter — bottom `θ = 0`,
/// right the outer arc, top `θ = π/2`, left the inner arc. The grids of different sizes are
/// samples of one smooth map, as a convergence study needs.
pub fn curved_grid(
    m: usize,
    n: usize,
) -> Result<unamalla_mesh::StructuredGrid2, unamalla_mesh::MeshError> {
    use std::f64::consts::FRAC_PI_2;
    let outer = |t: f64| {
        let th = FRAC_PI_2 * t;
        let r = 2.0 + 0.2 * (4.0 * th).sin();
        DVec2::new(r * th.cos(), r * th.sin())
    };
    let inner = |t: f64| {
        let th = FRAC_PI_2 * t;
        DVec2::new(th.cos(), th.sin())
    };
    let s = |k: usize, len: usize| k as f64 / (len - 1).max(1) as f64;
    let bottom: Vec<DVec2> = (0..m).map(|i| DVec2::new(1.0 + s(i, m), 0.0)).collect();
    let top: Vec<DVec2> = (0..m).map(|i| DVec2::new(0.0, 1.0 + s(i, m))).collect();
    let right: Vec<DVec2> = (0..n).map(|j| outer(s(j, n))).collect();
    let left: Vec<DVec2> = (0..n).map(|j| inner(s(j, n))).collect();
    unamalla_mesh::tfi2(
        &bottom,
        &right,
        &top,
        &left,
        unamalla_mesh::TfiParams::Uniform,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Second derivatives by central differences of U (step 1e-4, error O(1e-8)).
    fn fd_hess(m: &Manufactured, p: DVec2) -> (f64, f64, f64) {
        let h = 1e-4;
        let f = |dx: f64, dy: f64| m.exact(p + DVec2::new(dx, dy));
        let uxx = (f(h, 0.0) - 2.0 * f(0.0, 0.0) + f(-h, 0.0)) / (h * h);
        let uyy = (f(0.0, h) - 2.0 * f(0.0, 0.0) + f(0.0, -h)) / (h * h);
        let uxy = (f(h, h) - f(h, -h) - f(-h, h) + f(-h, -h)) / (4.0 * h * h);
        (uxx, uxy, uyy)
    }

    #[test]
    fn hessians_match_finite_differences() {
        for m in [Manufactured::sin_cosh(), Manufactured::polynomial()] {
            for p in [
                DVec2::new(0.3, 0.7),
                DVec2::new(-1.2, 0.4),
                DVec2::new(0.9, -0.5),
            ] {
                let (a, b, c) = (m.hess)(p);
                let (x, y, z) = fd_hess(&m, p);
                assert!((a - x).abs() < 1e-5, "{} uxx {a} {x}", m.name);
                assert!((b - y).abs() < 1e-5, "{} uxy {b} {y}", m.name);
                assert!((c - z).abs() < 1e-5, "{} uyy {c} {z}", m.name);
            }
        }
    }

    #[test]
    fn a_frame_scales_the_solution_and_its_derivatives_by_the_chain_rule() {
        // Û(p) = U((p − o)/L): Û at o + L·q is U(q); the second derivatives of Û by central
        // differences (step 1e-4·L) are U's divided by L²
        let (o, l) = (DVec2::new(480.0, -3100.0), 250.0);
        for m in [Manufactured::sin_cosh(), Manufactured::polynomial()] {
            let f = m.in_frame(o, l);
            assert_eq!(f.frame(), (o, l));
            for q in [DVec2::new(0.3, 0.7), DVec2::new(0.9, 0.1)] {
                let p = o + l * q;
                assert!((f.exact(p) - m.exact(q)).abs() < 1e-12);
                let h = 1e-4 * l;
                let u = |dx: f64, dy: f64| f.exact(p + DVec2::new(dx, dy));
                let uxx = (u(h, 0.0) - 2.0 * u(0.0, 0.0) + u(-h, 0.0)) / (h * h);
                let uyy = (u(0.0, h) - 2.0 * u(0.0, 0.0) + u(0.0, -h)) / (h * h);
                let uxy = (u(h, h) - u(h, -h) - u(-h, h) + u(-h, -h)) / (4.0 * h * h);
                let (a, b, c) = f.second_derivatives(p);
                let (ea, eb, ec) = m.second_derivatives(q);
                for (got, want, fd) in [(a, ea, uxx), (b, eb, uxy), (c, ec, uyy)] {
                    assert!((got * l * l - want).abs() < 1e-12 * (1.0 + want.abs()));
                    assert!((got - fd).abs() < 1e-5 / (l * l), "{} {got} {fd}", m.name);
                }
            }
        }
    }

    #[test]
    fn the_box_frame_maps_the_larger_side_to_one() {
        let nodes = [
            DVec2::new(500.0, 3000.0),
            DVec2::new(900.0, 3100.0),
            DVec2::new(700.0, 3050.0),
        ];
        let f = Manufactured::sin_cosh().on_box(&nodes).unwrap();
        assert_eq!(f.frame(), (DVec2::new(500.0, 3000.0), 400.0));
        // sin(π·1)·cosh(0.25) at the far corner of the x side: sin(π) ≈ 1.2e-16
        assert!(f.exact(DVec2::new(900.0, 3100.0)).abs() < 1e-15);
        let mid = f.exact(DVec2::new(700.0, 3000.0));
        assert!((mid - 1.0).abs() < 1e-15, "sin(π/2)·cosh(0) = 1, got {mid}");
        assert!(Manufactured::sin_cosh().on_box(&[]).is_none());
        assert!(Manufactured::sin_cosh()
            .on_box(&[DVec2::new(1.0, 2.0)])
            .is_none());
    }

    #[test]
    fn sin_cosh_is_harmonic_for_the_anisotropic_operator() {
        // U_xx + π² U_yy = −π²U + π²U = 0
        let m = Manufactured::sin_cosh();
        let eq = m.equation(1.0, 0.0, std::f64::consts::PI.powi(2), 0.0);
        let Source::Function(g) = eq.g else { panic!() };
        assert!(g(DVec2::new(0.37, 0.81)).abs() < 1e-12);
    }
}
