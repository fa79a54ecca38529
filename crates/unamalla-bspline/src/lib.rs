//! # unamalla-bspline
//!
//! B-spline tensor-product parametrizations `x: [0,1]² → Ω` of planar regions with irregular
//! boundary, built from convex control nets, with injectivity certificates, after [Abelló et al.]
//! (Abelló, Hernández, Barrera, González, "Parametrización B-spline de regiones planas con
//! frontera irregular"; the references are listed in `docs/references.md` of the repository).
//! Several printed formulas of the paper have typos (indices, one inverted factor); the
//! corrected forms are used throughout and each module says which correction it applies.
//!
//! | module | what | paper |
//! |---|---|---|
//! | [`knots`] | clamped uniform knots (4)/(5), (23)/(24), any order; Cox–de Boor; derivatives (33); Greville abscissae | §1.1–§1.3 |
//! | [`curve`] | B-spline curves and their derivative curves | §2.1, (42)–(43) |
//! | [`net`] | control nets, edge vectors (15)/(16), convexity (Defs 1–2), boundary curves and Lemma 4 assembly with validation | §1.2, §2.1, §2.2 |
//! | [`map`] | bilinear/biquadratic tensor maps, per-patch Bézier evaluation, partials, `det J` (Bernstein and power form) and the corrected closed forms Prop 1 / Prop 2 (39) | §1.2–§1.3 |
//! | [`interior`] | interior control points minimizing `½S_{ω,ε} + ½F_AO` with `unamalla-functionals` / `unamalla-optim` from a TFI start | §2.2 |
//! | [`certify`] | Theorem 1, Theorem 2 (36 determinants per patch), Bernstein test with subdivision | §1.2–§1.3, Observation 3 |
//! | [`sample`] | dense parallel `det J` sampler (min/max and where) | §3, Table 1 |
//! | [`export`] | isoparametric curves (SVG, VTK), control net and Jacobian field (VTK) | §3, Figs 8–11 |
//! | [`synthetic`] | the synthetic regions S1–S5 (ours: the paper's regions have no coordinates) | – |
//!
//! The whole method (the paper's §2) is [`parametrize`]: validate the four boundary control
//! polygons, assemble the boundary of the net (Lemma 4), start the interior by TFI, optimize it,
//! build the map and certify it.
//!
//! ```
//! use unamalla_bspline::{parametrize, synthetic::Synthetic, Degree, ParametrizeOptions};
//!
//! let boundary = Synthetic::S2Wavy.boundary(12, 12)?;
//! let opts = ParametrizeOptions::default().degree(Degree::Biquadratic).samples(200);
//! let p = parametrize(&boundary, &opts)?;
//! assert!(p.interior.convex);                  // the optimized net is convex …
//! assert!(p.certificates.theorem1.holds);      // … so its bilinear map is injective (Thm 1)
//! assert!(p.certificates.sample.min > 0.0);    // sampled det J of the biquadratic map
//! // Lemma 4: the map's boundary is the south boundary curve
//! let south = unamalla_bspline::BSplineCurve::clamped_uniform(3, boundary.south.clone())?;
//! assert!((p.map.eval(0.3, 0.0) - south.eval(0.3)).length() < 1e-12);
//! # Ok::<(), unamalla_bspline::BsplineError>(())
//! ```

#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]
// Index loops mirror the subscripts of the formulas (i, j, r, s, k, l as in the docs).
#![allow(clippy::needless_range_loop)]

pub mod certify;
pub mod curve;
pub mod error;
pub mod export;
pub mod fit;
pub mod interior;
pub mod knots;
pub mod map;
pub mod net;
pub mod sample;
pub mod synthetic;

use std::time::Instant;

pub use certify::{
    bernstein_test, certify_map, theorem1, theorem2, BernsteinOutcome, BernsteinReport,
    Certificates, Theorem1Report, Theorem2Report,
};
pub use curve::BSplineCurve;
pub use error::BsplineError;
pub use fit::{fit_polyline, Fairing, FitParameters, FitReport, FAIRING_LADDER};
pub use interior::{optimize_interior, InteriorOptions, InteriorReport};
pub use knots::KnotVector;
pub use map::{Degree, TensorMap};
pub use net::{BoundaryCurves, ControlNet, NetConvexity, RingFit};
pub use sample::{sample_det_j, JacobianSample};

/// Options of [`parametrize`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ParametrizeOptions {
    /// Bilinear or biquadratic map.
    pub degree: Degree,
    /// The interior optimization.
    pub interior: InteriorOptions,
    /// Samples per direction of the dense `det J` sample (the paper: 10⁴).
    pub samples: usize,
    /// Maximum subdivision depth of the Bernstein test.
    pub subdivision: usize,
}

impl Default for ParametrizeOptions {
    fn default() -> Self {
        Self {
            degree: Degree::Biquadratic,
            interior: InteriorOptions::default(),
            samples: 1000,
            subdivision: 4,
        }
    }
}

impl ParametrizeOptions {
    /// Sets [`degree`](Self::degree): bilinear or biquadratic map.
    #[must_use]
    pub fn degree(mut self, degree: Degree) -> Self {
        self.degree = degree;
        self
    }

    /// Sets [`interior`](Self::interior): the interior optimization.
    #[must_use]
    pub fn interior(mut self, interior: InteriorOptions) -> Self {
        self.interior = interior;
        self
    }

    /// Sets [`samples`](Self::samples): samples per direction of the dense `det J` sample (the
    /// paper: 10⁴).
    #[must_use]
    pub fn samples(mut self, samples: usize) -> Self {
        self.samples = samples;
        self
    }

    /// Sets [`subdivision`](Self::subdivision): maximum subdivision depth of the Bernstein test.
    #[must_use]
    pub fn subdivision(mut self, subdivision: usize) -> Self {
        self.subdivision = subdivision;
        self
    }
}

/// The result of [`parametrize`].
#[derive(Debug, Clone)]
pub struct Parametrization {
    /// The map.
    pub map: TensorMap,
    /// What the interior optimization did.
    pub interior: InteriorReport,
    /// The certificates and the sample.
    pub certificates: Certificates,
    /// Total wall-clock seconds.
    pub seconds: f64,
}

/// The whole method ([Abelló et al., §2]): boundary validation and Lemma 4 assembly
/// ([`ControlNet::from_boundary`]), TFI start, interior optimization
/// ([`optimize_interior`]), the map of `opts.degree` and all certificates
/// ([`certify_map`]).
pub fn parametrize(
    boundary: &BoundaryCurves,
    opts: &ParametrizeOptions,
) -> Result<Parametrization, BsplineError> {
    let t0 = Instant::now();
    let mut net = ControlNet::from_boundary(boundary)?;
    let interior = optimize_interior(&mut net, &opts.interior)?;
    let map = TensorMap::new(opts.degree, net)?;
    let certificates = certify_map(&map, opts.samples, opts.subdivision)?;
    Ok(Parametrization {
        map,
        interior,
        certificates,
        seconds: t0.elapsed().as_secs_f64(),
    })
}
