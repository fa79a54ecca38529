//! The convexity-guaranteeing kernels: `S_{ω,ε}` and `H_ω`.

use super::{
    check_finite, check_pos, l_times_phi_lanes, lane_grad, n_times_phi, of_alpha, phi_omega,
    phi_omega_lanes, s_function, SP_ALPHA, SP_L_PHI,
};
use crate::error::FunctionalError;
use crate::kernel::{CornerLanes, LaneGrad, LanePartials, Order, Partials, TriKernel, TriScalars};

/// How the argument of `f` in `S_{ω,ε}` is formed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SArgument {
    /// `t = ω(α/ᾱ − ε)` — the scale-invariant reading of [Abelló et al., (55)] (as printed, the
    /// threshold shrinks as ω grows, which does not fit the paper's "ω large ⇒ ε-convex"); equals
    /// the `ω(α − ε)` of [Méndez 2023, §6.4.2] after scaling so that `ᾱ = 1`.
    #[default]
    ScaleInvariant,
    /// `t = ωα − εᾱ`, [Abelló et al., (55)] as printed.
    Literal,
}

/// `S_{ω,ε} = Σ f(t(α))` with `f` of (56) ([`s_function`]) (Barrera et al., as given in
/// [Abelló et al., §2.2] and [Méndez 2023, §6.4.2]). Finite for any mesh.
#[derive(Debug, Clone, Copy)]
pub struct SOmegaEps {
    omega: f64,
    eps: f64,
    alpha_bar: f64,
    arg: SArgument,
}
impl SOmegaEps {
    /// `ω > 0`, `ε` finite, `ᾱ > 0` (mean α of the mesh).
    pub fn new(
        omega: f64,
        eps: f64,
        alpha_bar: f64,
        arg: SArgument,
    ) -> Result<Self, FunctionalError> {
        Ok(Self {
            omega: check_pos("omega", omega)?,
            eps: check_finite("eps", eps)?,
            alpha_bar: check_pos("alpha_bar", alpha_bar)?,
            arg,
        })
    }
}
impl TriKernel for SOmegaEps {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_ALPHA
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        let (t, dt) = match self.arg {
            SArgument::ScaleInvariant => {
                let d = self.omega / self.alpha_bar;
                (d * s.alpha - self.omega * self.eps, d)
            }
            SArgument::Literal => (self.omega * s.alpha - self.eps * self.alpha_bar, self.omega),
        };
        let f = s_function(t);
        of_alpha([f[0], f[1] * dt, f[2] * dt * dt], order)
    }
}

/// Quasi-harmonic `H_ω` ([Méndez 2023, §6.4.2] with the C¹ `φ_ω`; [Cortés Aguirre 2012, (1.42)],
/// printed `Σλ/φ_ω`, read as the product `Σλ·φ_ω`):
/// `l·φ_ω(α)` with [`phi_omega`]. Finite for any mesh; equals Winslow's `l/α` where `α ≥ ω`.
#[derive(Debug, Clone, Copy)]
pub struct HOmega {
    omega: f64,
}
impl HOmega {
    /// `ω > 0`.
    pub fn new(omega: f64) -> Result<Self, FunctionalError> {
        Ok(Self {
            omega: check_pos("omega", omega)?,
        })
    }
    /// The parameter `ω`.
    pub fn omega(&self) -> f64 {
        self.omega
    }
}
impl TriKernel for HOmega {
    #[inline(always)]
    fn hessian_sparsity(&self) -> [[bool; 4]; 4] {
        SP_L_PHI
    }
    #[inline(always)]
    fn eval(&self, s: &TriScalars, order: Order) -> Partials {
        n_times_phi(1.0, 1.0, 0.0, phi_omega(self.omega, s.alpha), s, order)
    }
    #[inline(always)]
    fn corners_value(&self, s: &CornerLanes) -> [f64; 4] {
        let phi = phi_omega_lanes(self.omega, &s.alpha, false);
        let mut v = [0.0; 4];
        for q in 0..4 {
            v[q] = (s.la[q] + s.lb[q]) * phi[0][q];
        }
        v
    }
    #[inline(always)]
    fn corners_value_grad(&self, s: &CornerLanes) -> LaneGrad {
        lane_grad(l_times_phi_lanes(
            s,
            &phi_omega_lanes(self.omega, &s.alpha, false),
            false,
        ))
    }
    #[inline(always)]
    fn corners_hessian(&self, s: &CornerLanes) -> LanePartials {
        l_times_phi_lanes(s, &phi_omega_lanes(self.omega, &s.alpha, true), true)
    }
}
