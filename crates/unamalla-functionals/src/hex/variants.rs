//! [`EnergyVariants`]: the energy under the readings of the thesis's discretisation.

use glam::DVec3;

#[cfg(doc)]
use super::HexFunctional;
use super::{hex_tets, Scaling3};
use crate::error::FunctionalError;

/// The harmonic energy `E = λ/V` of a mesh under the readings of the thesis's discretisation
/// that could explain a reported value ([Cortés Aguirre 2012, §3.2, (3.21)–(3.22), (3.27)]; the
/// sphere of §3.4.3 ends at `f = 2.26543`). All are evaluated at `ω → 0`, i.e.
/// where `H_ω` *is* the energy (`φ_ω(V) = 1/V` for `V ≥ ω`); `E ≥ 1` per tetrahedron (AM–GM),
/// `= 1` iff its Jacobian is a similarity. See [`energy_variants`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnergyVariants {
    /// (3.22)/(3.27) as printed: `(1/N_c) Σ_cells Σ_{10 tets} (1/10)·E` — what
    /// [`HexFunctional::h_omega`] computes (the mean over all tetrahedra).
    pub printed: f64,
    /// Each of the two five-tetrahedra decompositions ("dodecaedros", §3.2) averaged on its
    /// own and the two averages added: `(1/N_c) Σ_cells [(1/5)Σ_A E + (1/5)Σ_B E]`
    /// = `2·printed` exactly.
    pub per_decomposition: f64,
    /// Volume quadrature of Azarenok's split: within each decomposition a corner tetrahedron
    /// weighs `1/6` and the interior one `1/3` of the cell (their volume shares), the two
    /// decompositions added (weights sum to 2 per cell, like `per_decomposition`).
    pub volume_weighted: f64,
    /// `printed`, but the two interior tetrahedra (7425, 1386) use the generic corner form
    /// `r_ξ = Q−P, r_η = R−P, r_ζ = S−P` on their own vertices (the mislabelled (3.33) read
    /// literally; these columns are face diagonals, `E = √2` on a cube). Raw differences, so
    /// only comparable with the others when `m = n = p` (the scaling is then uniform and `E`
    /// is scale-free).
    pub interior_raw: f64,
    /// Number of tetrahedra with `V ≤ 0` (then `E` is undefined and those terms are skipped).
    pub non_positive: usize,
}

/// Evaluates [`EnergyVariants`] on the cells `cells` (eight vertices each, VTK order) with
/// the Jacobian scaling `scaling` ([Cortés Aguirre 2012, §3.2]; [`Scaling3`]).
///
/// Hand values on a mesh of congruent cubes (every Jacobian a similarity): `printed = 1`,
/// `per_decomposition = volume_weighted = 2`, `interior_raw = (8 + 2√2)/10`.
pub fn energy_variants(
    cells: &[[DVec3; 8]],
    scaling: Scaling3,
) -> Result<EnergyVariants, FunctionalError> {
    let f = scaling.factors()?;
    let tets = hex_tets();
    let energy = |c: [DVec3; 3]| -> Option<f64> {
        let v = c[0].dot(c[1].cross(c[2]));
        let s = c[0].length_squared() + c[1].length_squared() + c[2].length_squared();
        (v > 0.0).then(|| (s / 3.0).powf(1.5) / v)
    };
    let mut out = EnergyVariants {
        printed: 0.0,
        per_decomposition: 0.0,
        volume_weighted: 0.0,
        interior_raw: 0.0,
        non_positive: 0,
    };
    for p in cells {
        for t in &tets {
            let col = |a: usize| {
                (0..4).fold(DVec3::ZERO, |acc, j| acc + t.stencil[a][j] * p[t.nodes[j]])
                    * f[t.dirs[a]]
            };
            let Some(e) = energy([col(0), col(1), col(2)]) else {
                out.non_positive += 1;
                continue;
            };
            out.printed += e / 10.0;
            out.per_decomposition += e / 5.0;
            out.volume_weighted += if t.interior { e / 3.0 } else { e / 6.0 };
            if t.interior {
                let [a, b, c, d] = t.nodes.map(|v| p[v]);
                if let Some(er) = energy([b - a, c - a, d - a]) {
                    out.interior_raw += er / 10.0;
                }
            } else {
                out.interior_raw += e / 10.0;
            }
        }
    }
    let n = cells.len().max(1) as f64;
    out.printed /= n;
    out.per_decomposition /= n;
    out.volume_weighted /= n;
    out.interior_raw /= n;
    Ok(out)
}
