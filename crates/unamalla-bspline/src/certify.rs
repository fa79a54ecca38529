//! Injectivity certificates ([Abelló et al., Theorem 1, Theorem 2, Observation 3]).
//!
//! * [`theorem1`]: a **convex** control net (every cell's four diagonal triangles have positive
//!   doubled area, Definition 1) makes the **bilinear** map injective: on each cell `det J` is a
//!   bilinear B-spline whose four coefficients are `(n−1)(m−1)` times those doubled areas
//!   (Prop 1 with the factor multiplying, not dividing as printed in (14); the proof's labels
//!   `t¹` and `t³` are swapped, which changes nothing as all four must be positive).
//! * [`theorem2`]: the biquadratic map is injective if all **36 determinants**
//!   `det[h_{r',s} | v_{r,s'}]` (`r ∈ {i,i+1,i+2}`, `r' ∈ {i,i+1}`, `s ∈ {j,j+1,j+2}`,
//!   `s' ∈ {j,j+1}`) of every patch `U_{ij}` are positive (41). Since the basis products of (39)
//!   sum to 1 on a patch, `det J ≥ (n−2)(m−2)·min(γ_{r'}δ_{s'}·D)` there, which is reported as a
//!   certified lower bound. Of the 36 pairs, the 16 with `r ∈ {r', r'+1}` and
//!   `s ∈ {s', s'+1}` are diagonal-triangle areas of the four control quads (Observation 1);
//!   failures are counted separately for those "geometric" pairs and the 20 others.
//! * [`bernstein_test`]: Observation 3, which the paper proposes but does not develop, worked
//!   out here: `det J` on a
//!   patch is `Σ c_ab B_a(u) B_b(v)` ([`crate::map`]); if all `c_ab > 0` then `det J > 0` on
//!   the patch (and `min c_ab` is a lower bound). Otherwise the patch is split in four by de
//!   Casteljau at `u = v = ½` (the coefficients of each half are again Bernstein coefficients
//!   on it), up to a maximum depth. A corner coefficient equals the value at that corner, so a
//!   corner coefficient `≤ 0` **refutes** positivity with a witness point.
//!
//! With `det J > 0` on all of `U` and `x|∂U` a bijection onto the simple closed curve `∂Ω` the
//! map is a bijection `U → Ω` (a standard degree argument; the paper's convex-hull argument of
//! §1.1 does not cover the biquadratic case, whose neighbouring patches have overlapping hulls).

use crate::map::{Degree, TensorMap};
use crate::net::ControlNet;

/// Outcome of Theorem 1 on a net.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Theorem1Report {
    /// Every cell is convex, so the bilinear map is injective.
    pub holds: bool,
    /// Minimum doubled triangle area `α₋`.
    pub min_alpha: f64,
    /// `α₋/ᾱ`.
    pub min_alpha_rel: f64,
    /// Cells `(i, j)` (0-based) with a non-positive triangle.
    pub nonconvex_cells: usize,
    /// The cell with the smallest triangle.
    pub worst_cell: (usize, usize),
    /// The certified lower bound `(n−1)(m−1)·α₋` of `det J` of the bilinear map when `holds`
    /// (the `B²_r B²_s` sum to 1 on a cell).
    pub det_j_lower_bound: Option<f64>,
}

/// Theorem 1 ([Abelló et al., §1.2]): convex net ⇒ injective bilinear map.
pub fn theorem1(net: &ControlNet) -> Theorem1Report {
    let c = net.convexity();
    let holds = c.convex();
    let f = (net.n() - 1) as f64 * (net.m() - 1) as f64;
    Theorem1Report {
        holds,
        min_alpha: c.min_alpha,
        min_alpha_rel: c.min_alpha_rel(),
        nonconvex_cells: c.nonconvex_cells,
        worst_cell: c.worst_cell,
        det_j_lower_bound: holds.then_some(f * c.min_alpha),
    }
}

/// One of the 36 determinants of a patch.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Determinant36 {
    /// Patch `(i, j)` (0-based; the paper's `U_{i+1, j+1}`).
    pub patch: (usize, usize),
    /// `r'` of `h_{r',s}` (0-based).
    pub r_prime: usize,
    /// `s` of `h_{r',s}`.
    pub s: usize,
    /// `r` of `v_{r,s'}`.
    pub r: usize,
    /// `s'` of `v_{r,s'}`.
    pub s_prime: usize,
    /// `det[h_{r',s} | v_{r,s'}]`.
    pub value: f64,
    /// One of the 16 diagonal-triangle pairs (`r ∈ {r', r'+1}`, `s ∈ {s', s'+1}`).
    pub geometric: bool,
}

/// Outcome of Theorem 2 on a biquadratic net.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Theorem2Report {
    /// All 36 determinants of every patch are positive (41).
    pub holds: bool,
    /// Number of patches `(n−2)(m−2)`.
    pub patches: usize,
    /// Patches with at least one non-positive determinant.
    pub failing_patches: usize,
    /// Non-positive determinants over all patches (each patch counted separately).
    pub failing_determinants: usize,
    /// … of which among the 16 geometric pairs.
    pub failing_geometric: usize,
    /// … of which among the 20 non-geometric pairs.
    pub failing_nongeometric: usize,
    /// The smallest determinant over all patches.
    pub min: Determinant36,
    /// `(n−2)(m−2)·min_{patches, pairs} γ_{r'}δ_{s'}·D`: a certified lower bound of `det J`
    /// when `holds` (the bound of the proof of Theorem 2).
    pub det_j_lower_bound: Option<f64>,
}

/// Theorem 2 ([Abelló et al., §1.3, (41)]): the 36 determinants of every biquadratic patch. Needs
/// `n, m ≥ 3`; returns `None` for smaller nets.
pub fn theorem2(net: &ControlNet) -> Option<Theorem2Report> {
    let (n, m) = (net.n(), net.m());
    if n < 3 || m < 3 {
        return None;
    }
    let map_gamma = |count: usize, r: usize| -> f64 {
        // γ_r = 2Δ/(t_{r+3} − t_{r+1}) on the uniform knots (23): 2 at both ends, 1 inside
        if r == 0 || r == count - 2 {
            2.0
        } else {
            1.0
        }
    };
    let f = (n - 2) as f64 * (m - 2) as f64;
    let mut rep = Theorem2Report {
        holds: true,
        patches: (n - 2) * (m - 2),
        failing_patches: 0,
        failing_determinants: 0,
        failing_geometric: 0,
        failing_nongeometric: 0,
        min: Determinant36 {
            patch: (0, 0),
            r_prime: 0,
            s: 0,
            r: 0,
            s_prime: 0,
            value: f64::INFINITY,
            geometric: true,
        },
        det_j_lower_bound: None,
    };
    let mut min_weighted = f64::INFINITY;
    for j in 0..m - 2 {
        for i in 0..n - 2 {
            let mut bad = false;
            for rp in i..=i + 1 {
                for s in j..=j + 2 {
                    let h = net.h(rp, s);
                    for r in i..=i + 2 {
                        for sp in j..=j + 1 {
                            let d = h.perp_dot(net.v(r, sp));
                            let geometric = (r == rp || r == rp + 1) && (s == sp || s == sp + 1);
                            if d.is_nan() || d <= 0.0 {
                                bad = true;
                                rep.failing_determinants += 1;
                                if geometric {
                                    rep.failing_geometric += 1;
                                } else {
                                    rep.failing_nongeometric += 1;
                                }
                            }
                            let w = map_gamma(n, rp) * map_gamma(m, sp) * d;
                            min_weighted = min_weighted.min(w);
                            if d < rep.min.value || d.is_nan() {
                                rep.min = Determinant36 {
                                    patch: (i, j),
                                    r_prime: rp,
                                    s,
                                    r,
                                    s_prime: sp,
                                    value: d,
                                    geometric,
                                };
                            }
                        }
                    }
                }
            }
            if bad {
                rep.failing_patches += 1;
            }
        }
    }
    rep.holds = rep.failing_determinants == 0;
    if rep.holds {
        rep.det_j_lower_bound = Some(f * min_weighted);
    }
    Some(rep)
}

/// The decision of the Bernstein test.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(tag = "outcome", rename_all = "snake_case")]
pub enum BernsteinOutcome {
    /// `det J > 0` on all of `U` (every (sub)patch has positive coefficients).
    Certified {
        /// A certified lower bound: the smallest coefficient over the final subpatches.
        lower_bound: f64,
    },
    /// `det J ≤ 0` at a (sub)patch corner.
    Refuted {
        /// The witness `(ξ, η)`.
        at: (f64, f64),
        /// `det J` there.
        value: f64,
    },
    /// Some subpatch still has a non-positive coefficient at the maximum depth.
    Inconclusive {
        /// How many subpatches were left undecided.
        undecided: usize,
    },
}

/// Result of [`bernstein_test`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BernsteinReport {
    /// The decision.
    pub outcome: BernsteinOutcome,
    /// Maximum subdivision depth allowed.
    pub max_depth: usize,
    /// Patches certified without subdivision.
    pub certified_at_depth0: usize,
    /// Patches that needed subdivision and were certified.
    pub certified_by_subdivision: usize,
    /// Total patches.
    pub patches: usize,
    /// Smallest coefficient over all patches before subdivision (for the record).
    pub min_coefficient_depth0: f64,
}

impl BernsteinReport {
    /// `true` if certified.
    pub fn certified(&self) -> bool {
        matches!(self.outcome, BernsteinOutcome::Certified { .. })
    }
}

/// de Casteljau split of Bernstein coefficients (degree `e ≤ 3`) at `½`: `(left, right)`.
fn split(c: [f64; 4], e: usize) -> ([f64; 4], [f64; 4]) {
    let mut l = [0.0; 4];
    let mut r = [0.0; 4];
    let mut w = c;
    for step in 0..=e {
        l[step] = w[0];
        r[e - step] = w[e - step];
        for a in 0..e - step {
            w[a] = 0.5 * (w[a] + w[a + 1]);
        }
    }
    (l, r)
}

type Coeffs = [[f64; 4]; 4];

fn split_u(c: &Coeffs, e: usize) -> (Coeffs, Coeffs) {
    let mut l = [[0.0; 4]; 4];
    let mut r = [[0.0; 4]; 4];
    for b in 0..=e {
        let col = [c[0][b], c[1][b], c[2][b], c[3][b]];
        let (a1, a2) = split(col, e);
        for a in 0..=e {
            l[a][b] = a1[a];
            r[a][b] = a2[a];
        }
    }
    (l, r)
}

fn split_v(c: &Coeffs, e: usize) -> (Coeffs, Coeffs) {
    let mut l = [[0.0; 4]; 4];
    let mut r = [[0.0; 4]; 4];
    for a in 0..=e {
        let (a1, a2) = split(c[a], e);
        l[a] = a1;
        r[a] = a2;
    }
    (l, r)
}

/// The Bernstein-coefficient Jacobian test (Observation 3) with subdivision up to `max_depth`
/// levels (0 = no subdivision). Works for both degrees (for bilinear maps depth 0 is exactly
/// Theorem 1).
pub fn bernstein_test(map: &TensorMap, max_depth: usize) -> BernsteinReport {
    let e = 2 * map.degree().degree() - 1;
    let (npx, npy) = map.num_patches();
    let mut rep = BernsteinReport {
        outcome: BernsteinOutcome::Certified {
            lower_bound: f64::INFINITY,
        },
        max_depth,
        certified_at_depth0: 0,
        certified_by_subdivision: 0,
        patches: npx * npy,
        min_coefficient_depth0: f64::INFINITY,
    };
    let mut lower = f64::INFINITY;
    let mut undecided = 0usize;
    let mut refuted: Option<((f64, f64), f64)> = None;
    let min_of = |c: &Coeffs| {
        let mut mn = f64::INFINITY;
        for row in c.iter().take(e + 1) {
            for &x in row.iter().take(e + 1) {
                mn = if x.is_nan() {
                    f64::NEG_INFINITY
                } else {
                    mn.min(x)
                };
            }
        }
        mn
    };
    for py in 0..npy {
        for px in 0..npx {
            let p = map.patch(px, py);
            let m0 = min_of(&p.jac);
            rep.min_coefficient_depth0 = rep.min_coefficient_depth0.min(m0);
            if m0 > 0.0 {
                rep.certified_at_depth0 += 1;
                lower = lower.min(m0);
                continue;
            }
            // (coefficients, depth, u0, v0, size) in local patch coordinates
            let mut stack = vec![(p.jac, 0usize, 0.0f64, 0.0f64, 1.0f64)];
            let mut patch_ok = true;
            while let Some((c, depth, u0, v0, sz)) = stack.pop() {
                let mn = min_of(&c);
                if mn > 0.0 {
                    lower = lower.min(mn);
                    continue;
                }
                // corner coefficients are values
                let corners = [
                    (c[0][0], 0.0, 0.0),
                    (c[e][0], 1.0, 0.0),
                    (c[0][e], 0.0, 1.0),
                    (c[e][e], 1.0, 1.0),
                ];
                if let Some(&(val, cu, cv)) =
                    corners.iter().find(|(v, _, _)| v.is_nan() || *v <= 0.0)
                {
                    let u = u0 + cu * sz;
                    let v = v0 + cv * sz;
                    let xi = p.xi.0 + u * (p.xi.1 - p.xi.0);
                    let eta = p.eta.0 + v * (p.eta.1 - p.eta.0);
                    if refuted.is_none_or(|(_, w)| val < w) {
                        refuted = Some(((xi, eta), val));
                    }
                    patch_ok = false;
                    break;
                }
                if depth >= max_depth {
                    undecided += 1;
                    patch_ok = false;
                    continue;
                }
                let h = 0.5 * sz;
                let (cl, cr) = split_u(&c, e);
                let (cll, clr) = split_v(&cl, e);
                let (crl, crr) = split_v(&cr, e);
                stack.push((cll, depth + 1, u0, v0, h));
                stack.push((clr, depth + 1, u0, v0 + h, h));
                stack.push((crl, depth + 1, u0 + h, v0, h));
                stack.push((crr, depth + 1, u0 + h, v0 + h, h));
            }
            if patch_ok {
                rep.certified_by_subdivision += 1;
            }
        }
    }
    rep.outcome = if let Some((at, value)) = refuted {
        BernsteinOutcome::Refuted { at, value }
    } else if undecided > 0 {
        BernsteinOutcome::Inconclusive { undecided }
    } else {
        BernsteinOutcome::Certified { lower_bound: lower }
    };
    rep
}

/// Theorem 1 or 2 as appropriate for a map's degree: `Some(true/false)`, or `None` when it
/// does not apply (Theorem 2 on a net smaller than 3 × 3).
pub fn theorem_for(map: &TensorMap) -> Option<bool> {
    match map.degree() {
        Degree::Bilinear => Some(theorem1(map.net()).holds),
        Degree::Biquadratic => theorem2(map.net()).map(|r| r.holds),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn de_casteljau_halves_reproduce_the_polynomial() {
        // p(u) = Σ c_a B³_a(u); the left half at s ∈ [0,1] is p(s/2), the right p((1+s)/2)
        let c = [1.0, -2.0, 0.5, 3.0];
        let p = |c: &[f64; 4], u: f64| {
            let b = crate::map::bernstein(3, u);
            (0..4).map(|a| c[a] * b[a]).sum::<f64>()
        };
        let (l, r) = split(c, 3);
        for k in 0..=10 {
            let s = k as f64 / 10.0;
            assert!((p(&l, s) - p(&c, 0.5 * s)).abs() < 1e-14);
            assert!((p(&r, s) - p(&c, 0.5 + 0.5 * s)).abs() < 1e-14);
        }
    }
}

/// All certificates of a map at once ([`certify_map`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Certificates {
    /// The map's degree.
    pub degree: Degree,
    /// Theorem 1 on the control net (the certificate of the bilinear map; for a biquadratic
    /// map it only says whether the net is convex).
    pub theorem1: Theorem1Report,
    /// Theorem 2 (biquadratic maps only).
    pub theorem2: Option<Theorem2Report>,
    /// The Bernstein-coefficient test.
    pub bernstein: BernsteinReport,
    /// The dense sample of `det J`.
    pub sample: crate::sample::JacobianSample,
    /// A certificate proves `det J > 0` on `U`: Theorem 1 (bilinear), Theorem 2 (biquadratic)
    /// or the Bernstein test.
    pub certified: bool,
    /// Seconds spent on Theorems 1–2 and the Bernstein test.
    pub seconds_certificates: f64,
    /// Seconds spent sampling.
    pub seconds_sampling: f64,
}

impl Certificates {
    /// The applicable theorem's outcome: Theorem 1 for bilinear maps, Theorem 2 for biquadratic
    /// ones (`None` if it does not apply).
    pub fn theorem(&self) -> Option<bool> {
        match self.degree {
            Degree::Bilinear => Some(self.theorem1.holds),
            Degree::Biquadratic => self.theorem2.as_ref().map(|t| t.holds),
        }
    }
}

/// Runs Theorem 1, Theorem 2 (biquadratic), the Bernstein test with subdivision depth
/// `max_depth` and a `samples × samples` dense sample of `det J`.
pub fn certify_map(
    map: &TensorMap,
    samples: usize,
    max_depth: usize,
) -> Result<Certificates, crate::BsplineError> {
    let t0 = std::time::Instant::now();
    let t1 = theorem1(map.net());
    let t2 = match map.degree() {
        Degree::Bilinear => None,
        Degree::Biquadratic => theorem2(map.net()),
    };
    let bern = bernstein_test(map, max_depth);
    let sc = t0.elapsed().as_secs_f64();
    let t0 = std::time::Instant::now();
    let sample = crate::sample::sample_det_j(map, samples, samples)?;
    let ss = t0.elapsed().as_secs_f64();
    let theorem_ok = match map.degree() {
        Degree::Bilinear => t1.holds,
        Degree::Biquadratic => t2.as_ref().is_some_and(|t| t.holds),
    };
    Ok(Certificates {
        degree: map.degree(),
        certified: theorem_ok || bern.certified(),
        theorem1: t1,
        theorem2: t2,
        bernstein: bern,
        sample,
        seconds_certificates: sc,
        seconds_sampling: ss,
    })
}
