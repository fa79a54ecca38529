//! [`HexFunctional`]: the functional, its constructors and parameter checks.

use std::sync::Arc;

use super::terms::ScaledTet;
use super::{hex_tets, HexTopology, Scaling3};
use crate::error::FunctionalError;

/// The 3D functional `h_scale·Σ_cells Σ_tets λφ_ω(V) + C·Σ_interior cells Σ_faces k²`
/// ([Cortés Aguirre 2012, (3.27), (4.4)]); either term can be switched off.
#[derive(Debug, Clone)]
pub struct HexFunctional {
    pub(super) topo: Arc<HexTopology>,
    pub(super) tets: [ScaledTet; 10],
    pub(super) omega: Option<f64>,
    pub(super) h_scale: f64,
    pub(super) coplanarity: Option<f64>,
}

impl HexFunctional {
    /// `H_ω` with the thesis' normalization `1/(10N_c)` (3.27), `ω > 0`.
    pub fn h_omega(
        topo: Arc<HexTopology>,
        omega: f64,
        scaling: Scaling3,
    ) -> Result<Self, FunctionalError> {
        check_pos("omega", omega)?;
        let f = scaling.factors()?;
        let tets = hex_tets().map(|t| {
            ScaledTet::new(
                t.nodes,
                std::array::from_fn(|a| t.stencil[a].map(|v| v * f[t.dirs[a]])),
            )
        });
        let h_scale = 1.0 / (10.0 * topo.num_cells() as f64);
        Ok(Self {
            topo,
            tets,
            omega: Some(omega),
            h_scale,
            coplanarity: None,
        })
    }
    /// Only the coplanarity penalty `C·Σk²`, `C ≥ 0` (Algorithm B uses `C = 1/(2μ)`).
    pub fn coplanarity(topo: Arc<HexTopology>, c: f64) -> Result<Self, FunctionalError> {
        let mut f = Self::h_omega(topo, 1.0, Scaling3::Index)?;
        f.omega = None;
        f.set_coplanarity(Some(c))?;
        Ok(f)
    }
    /// Adds (or replaces) the coplanarity penalty with weight `C ≥ 0`.
    pub fn with_coplanarity(mut self, c: f64) -> Result<Self, FunctionalError> {
        self.set_coplanarity(Some(c))?;
        Ok(self)
    }
    /// Sets or removes the coplanarity penalty.
    pub fn set_coplanarity(&mut self, c: Option<f64>) -> Result<(), FunctionalError> {
        if let Some(c) = c {
            if !(c.is_finite() && c >= 0.0) {
                return Err(FunctionalError::InvalidParameter {
                    name: "C",
                    value: c,
                    reason: "the penalty weight must be finite and ≥ 0".into(),
                });
            }
        }
        self.coplanarity = c;
        Ok(())
    }
    /// Sets `ω` of the `H_ω` term (Algorithm A halves it), or switches the term off.
    pub fn set_omega(&mut self, omega: Option<f64>) -> Result<(), FunctionalError> {
        if let Some(w) = omega {
            check_pos("omega", w)?;
        }
        self.omega = omega;
        Ok(())
    }
    /// Replaces the factor of the `H_ω` sum (default `1/(10N_c)`; 1 gives the plain sum).
    pub fn set_h_scale(&mut self, s: f64) -> Result<(), FunctionalError> {
        self.h_scale = check_finite("h_scale", s)?;
        Ok(())
    }
    /// The topology.
    pub fn topology(&self) -> &Arc<HexTopology> {
        &self.topo
    }
    /// Current `ω`.
    pub fn omega(&self) -> Option<f64> {
        self.omega
    }
}

fn check_pos(name: &'static str, v: f64) -> Result<f64, FunctionalError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(FunctionalError::InvalidParameter {
            name,
            value: v,
            reason: "must be finite and > 0".into(),
        })
    }
}

fn check_finite(name: &'static str, v: f64) -> Result<f64, FunctionalError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(FunctionalError::InvalidParameter {
            name,
            value: v,
            reason: "must be finite".into(),
        })
    }
}
