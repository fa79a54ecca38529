//! Per-cell quality metrics of a hexahedron `[P0, …, P7]` in VTK order (`0..4` the bottom face
//! counter-clockwise seen from above, `4..8` the nodes above them).
//!
//! Three families:
//!
//! * **Verdict** metrics ([Verdict, `V_HexMetric.cpp`]): Jacobian, scaled Jacobian,
//!   condition, shape, skew, taper, Oddy, written with the corner matrices
//!   `A0 = (L0, L3, L4)`, `A1 = (L1, −L0, L5)`, `A2 = (L2, −L1, L6)`, `A3 = (−L3, −L2, L7)`,
//!   `A4 = (L11, L8, −L4)`, `A5 = (−L8, L9, −L5)`, `A6 = (−L9, L10, −L6)`,
//!   `A7 = (−L10, −L11, −L7)` and the centre matrix `A8 = (X1, X2, X3)`, where
//!   `L0 = P1−P0, L1 = P2−P1, L2 = P3−P2, L3 = P3−P0, L4..L7 = P4−P0, P5−P1, P6−P2, P7−P3,
//!   L8 = P5−P4, L9 = P6−P5, L10 = P7−P6, L11 = P7−P4` and `X1, X2, X3` are the sums of the
//!   four parallel edges. `αi = det Ai`.
//! * the **10-tetrahedra** split of [Cortés Aguirre 2012, §3.2] ([`HEX_TETS`]) and its convexity
//!   test;
//! * the **face-planarity** cosine of [Cortés Aguirre 2012, §4.1, (4.2)] ([`face_planarity`]).
//!
//! Degenerate input never panics and never gives NaN for finite coordinates; the Verdict
//! fallbacks are documented on each function.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::quad::{DBL_MAX, DBL_MIN};

/// The ten tetrahedra of a hex (Azarenok's split, [Cortés Aguirre 2012, §3.2]; the text names
/// 1245, 6572, 8547, 5861 and the interior tet 7425, the full list is its Fig. 3.9), 0-based
/// VTK vertex ids `[P, Q, R, S]`, oriented so that `V = (S − P)·((Q − P) × (R − P)) > 0` on the
/// unit cube.
///
/// Rows 0–4 are decomposition A (1-based: corner tets 1245, 3427, 6572, 8547 and the interior
/// tet 7425), rows 5–9 decomposition B (corner tets 2316, 4138, 5861, 7683 and the interior
/// tet 1386). Rows 4 and 9 are the interior tets (see [`HEX_TET_INTERIOR`]). Each
/// decomposition alone tiles the hex when it is convex, so the volumes of rows 0–4 (and of rows
/// 5–9) sum to the volume of a parallelepiped cell.
pub const HEX_TETS: [[usize; 4]; 10] = [
    [0, 1, 3, 4], // 1245
    [2, 3, 1, 6], // 3427
    [5, 4, 6, 1], // 6572
    [7, 4, 3, 6], // 8547
    [6, 3, 1, 4], // 7425 (interior)
    [1, 2, 0, 5], // 2316
    [3, 0, 2, 7], // 4138
    [4, 7, 5, 0], // 5861
    [6, 5, 7, 2], // 7683
    [0, 2, 7, 5], // 1386 (interior)
];

/// `true` for the two interior tetrahedra of [`HEX_TETS`] (rows 4 and 9).
pub const HEX_TET_INTERIOR: [bool; 10] = [
    false, false, false, false, true, false, false, false, false, true,
];

/// The six faces used by the planarity test ([Cortés Aguirre 2012, §4.1]), 0-based VTK ids; 1-based
/// they are (1234), (5678), (1265), (4378), (1485), (2376). Each is a cycle around the face.
pub const PLANARITY_FACES: [[usize; 4]; 6] = [
    [0, 1, 2, 3],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [3, 2, 6, 7],
    [0, 3, 7, 4],
    [1, 2, 6, 5],
];

/// `V = (S − P)·((Q − P) × (R − P))` of the tetrahedron `(P, Q, R, S)`: six times its signed
/// volume ([Cortés Aguirre 2012, (3.21)]).
#[inline]
pub fn tet_det(p: DVec3, q: DVec3, r: DVec3, s: DVec3) -> f64 {
    (s - p).dot((q - p).cross(r - p))
}

/// The ten values `V = (S − P)·((Q − P) × (R − P))` of [`HEX_TETS`], i.e. **6 × signed volume**
/// for every tet, corner or interior. On the unit cube: 1 for the eight corner tets
/// (volume 1/6) and 2 for the two interior tets (volume 1/3).
///
/// The thesis's own Jacobian of an interior tet (from the volume-averaged gradient,
/// `r_ξ = ½(r7 + r2 − r5 − r4)`, …) equals `3 × volume`, i.e. half of this value; see
/// [`hex_tet_jacobians`]. Signs agree, so either serves the convexity test.
pub fn hex_tet_dets(h: &[DVec3; 8]) -> [f64; 10] {
    std::array::from_fn(|t| {
        let [a, b, c, d] = HEX_TETS[t];
        tet_det(h[a], h[b], h[c], h[d])
    })
}

/// Signed volumes of the ten tetrahedra: [`hex_tet_dets`] / 6.
pub fn hex_tet_volumes(h: &[DVec3; 8]) -> [f64; 10] {
    hex_tet_dets(h).map(|v| v / 6.0)
}

/// The thesis's tetrahedron Jacobians `V` ([Cortés Aguirre 2012, §3.2]): `6 × volume` for the
/// corner tets (`r_ξ = Q − P`, `r_η = R − P`, `r_ζ = S − P`) and `3 × volume` for the interior
/// tets (their volume-averaged gradient gives `3 ×`, not the `6 ×` the thesis states for all).
/// All equal 1 on the unit cube.
pub fn hex_tet_jacobians(h: &[DVec3; 8]) -> [f64; 10] {
    let mut v = hex_tet_dets(h);
    for (t, x) in v.iter_mut().enumerate() {
        if HEX_TET_INTERIOR[t] {
            *x *= 0.5;
        }
    }
    v
}

/// The 10-tetrahedra convexity test of [Cortés Aguirre 2012, §3.2.1, (3.24)] with a threshold:
/// `true` iff every [`hex_tet_dets`] value is `> threshold` (6 × volume units). The thesis's
/// test is `threshold = 0`; its ε-convexity test (3.35) calls a cell with some `V ≤ ε·v̄`
/// non-convex, for which pass `threshold = ε·v̄`.
pub fn hex_is_convex_10tet(h: &[DVec3; 8], threshold: f64) -> bool {
    hex_tet_dets(h).iter().all(|&v| v > threshold)
}

/// `|cos θ|` of one face `ABCD` ([Cortés Aguirre 2012, (4.2)]): `N = AB × AD`,
/// `k = |N·AC| / (‖N‖‖AC‖)`, maximised over the four rotations of the face (each leaves one
/// vertex out of the plane triple: vertex `A` with neighbours `B, D` spans the plane, the
/// opposite vertex `C` is tested). 0 for a planar face; a rotation whose triple is degenerate
/// (`‖N‖` or `‖AC‖` below `DBL_MIN`) contributes 0, since four points with three collinear, or
/// two coincident, are coplanar. Scale-invariant: `N·AC = ±6 × (tet volume)`.
pub fn face_cosine(v: [DVec3; 4]) -> f64 {
    let mut worst: f64 = 0.0;
    for k in 0..4 {
        let a = v[k];
        let b = v[(k + 1) % 4];
        let c = v[(k + 2) % 4];
        let d = v[(k + 3) % 4];
        let n = (b - a).cross(d - a);
        let ac = c - a;
        let (nn, nac) = (n.length(), ac.length());
        if nn < DBL_MIN || nac < DBL_MIN {
            continue;
        }
        worst = worst.max((n.dot(ac).abs() / (nn * nac)).min(1.0));
    }
    worst
}

/// Criterion 1 of face planarity (Cortés Aguirre 2012, §4.1 eq. (4.1); the criterion Table 4.1
/// rejects): the volume `|V_l|` of the tetrahedron on the four vertices of the face `ABCD`,
/// `|det(B − A, D − A, C − A)|/6`. 0 for a planar face. Unlike [`face_cosine`] (criterion 2,
/// eq. (4.2)) it scales with the cube of the mesh size, so one tolerance (the thesis's
/// `ε_v = 10⁻⁶`) means different things on different regions (Table 4.1: Yacimiento 2, with
/// coordinates of order 10⁴, has max `|V_l|` ≈ 5·10⁴ while its max `|cos|` is below 10⁻²).
pub fn face_volume(v: [DVec3; 4]) -> f64 {
    tet_det(v[0], v[1], v[3], v[2]).abs() / 6.0
}

/// The smallest height and the smallest face area of the tetrahedron on the four vertices of
/// a face (App. B.6 of Cortés Aguirre 2012: "minimum heights and areas of the tetrahedra formed
/// on each cell face"; small heights mean a nearly planar face, tight areas a regular one).
/// The height of vertex `i` is `3·vol / area(opposite triangle)`; a degenerate opposite
/// triangle (area below `DBL_MIN`) gives height 0. Returns `(min height, min area)`.
pub fn face_height_area(v: [DVec3; 4]) -> (f64, f64) {
    let vol = face_volume(v);
    let mut hmin = f64::INFINITY;
    let mut amin = f64::INFINITY;
    for i in 0..4 {
        let [a, b, c] = [(i + 1) % 4, (i + 2) % 4, (i + 3) % 4].map(|k| v[k]);
        let area = 0.5 * (b - a).cross(c - a).length();
        amin = amin.min(area);
        hmin = hmin.min(if area < DBL_MIN {
            0.0
        } else {
            3.0 * vol / area
        });
    }
    (hmin, amin)
}

/// [`face_volume`] of the six [`PLANARITY_FACES`] of a hex.
pub fn face_volumes(h: &[DVec3; 8]) -> [f64; 6] {
    PLANARITY_FACES.map(|f| face_volume([h[f[0]], h[f[1]], h[f[2]], h[f[3]]]))
}

/// [`face_cosine`] of the six [`PLANARITY_FACES`] of a hex.
pub fn face_planarity(h: &[DVec3; 8]) -> [f64; 6] {
    PLANARITY_FACES.map(|f| face_cosine([h[f[0]], h[f[1]], h[f[2]], h[f[3]]]))
}

/// The largest face `|cos θ|` of a hex (0 when all six faces are planar).
pub fn max_face_cosine(h: &[DVec3; 8]) -> f64 {
    face_planarity(h).into_iter().fold(0.0, f64::max)
}

/// The nine Verdict matrices `A0..A7` (corners) and `A8 = (X1, X2, X3)` (centre), as column
/// triples.
pub fn corner_matrices(h: &[DVec3; 8]) -> [[DVec3; 3]; 9] {
    let l = [
        h[1] - h[0],
        h[2] - h[1],
        h[3] - h[2],
        h[3] - h[0],
        h[4] - h[0],
        h[5] - h[1],
        h[6] - h[2],
        h[7] - h[3],
        h[5] - h[4],
        h[6] - h[5],
        h[7] - h[6],
        h[7] - h[4],
    ];
    let (x1, x2, x3) = axes(h);
    [
        [l[0], l[3], l[4]],
        [l[1], -l[0], l[5]],
        [l[2], -l[1], l[6]],
        [-l[3], -l[2], l[7]],
        [l[11], l[8], -l[4]],
        [-l[8], l[9], -l[5]],
        [-l[9], l[10], -l[6]],
        [-l[10], -l[11], -l[7]],
        [x1, x2, x3],
    ]
}

/// Principal axes: each the sum of the four parallel edges (Verdict `calc_hex_efg` 1, 2, 3).
fn axes(h: &[DVec3; 8]) -> (DVec3, DVec3, DVec3) {
    (
        (h[1] - h[0]) + (h[2] - h[3]) + (h[5] - h[4]) + (h[6] - h[7]),
        (h[3] - h[0]) + (h[2] - h[1]) + (h[7] - h[4]) + (h[6] - h[5]),
        (h[4] - h[0]) + (h[5] - h[1]) + (h[6] - h[2]) + (h[7] - h[3]),
    )
}

#[inline]
fn det3(a: &[DVec3; 3]) -> f64 {
    a[0].dot(a[1].cross(a[2]))
}

/// Verdict hex **Jacobian** (`hex_jacobian`): `min{α0, …, α7, α8/64}`; 1 for the unit cube.
pub fn jacobian(h: &[DVec3; 8]) -> f64 {
    let m = corner_matrices(h);
    let mut j = det3(&m[8]) / 64.0;
    for a in &m[..8] {
        j = j.min(det3(a));
    }
    j.clamp(-DBL_MAX, DBL_MAX)
}

/// Verdict hex **scaled Jacobian** (`hex_scaled_jacobian`): `min_{i=0..8} det Âi` (columns
/// normalised); 1 for a cube (any box), in `[−1, 1]`, negative for an inverted corner.
/// Verdict's fallback: if a column of some `Ai` has squared length `≤ DBL_MIN`, the result
/// is `f64::MAX` (sic; a degenerate hex therefore looks perfect on this metric alone —
/// check [`jacobian`] too).
pub fn scaled_jacobian(h: &[DVec3; 8]) -> f64 {
    let mut best = DBL_MAX;
    for a in corner_matrices(h) {
        let (l1, l2, l3) = (
            a[0].length_squared(),
            a[1].length_squared(),
            a[2].length_squared(),
        );
        if l1 <= DBL_MIN || l2 <= DBL_MIN || l3 <= DBL_MIN {
            return DBL_MAX;
        }
        best = best.min(det3(&a) / (l1 * l2 * l3).sqrt());
    }
    best.clamp(-DBL_MAX, DBL_MAX)
}

/// `|A|·|adj A| / det A` (Verdict `condition_comp`), `f64::MAX` if `det A ≤ DBL_MIN`;
/// `|adj A|² = Σ‖vj × vk‖²`.
fn condition_comp(a: &[DVec3; 3]) -> f64 {
    let det = det3(a);
    if det <= DBL_MIN {
        return DBL_MAX;
    }
    let t1 = a[0].length_squared() + a[1].length_squared() + a[2].length_squared();
    let t2 = a[0].cross(a[1]).length_squared()
        + a[1].cross(a[2]).length_squared()
        + a[2].cross(a[0]).length_squared();
    ((t1 * t2).sqrt() / det).min(DBL_MAX)
}

/// Verdict hex **condition** in the legacy "max aspect Frobenius" form (`hex_condition` =
/// `hex_max_aspect_frobenius`): `⅓·max_{i=0..7} |Ai|·|adj Ai| / αi` over the eight **corner**
/// matrices (the centre matrix is not used, as in Verdict's code); 1 for a cube, `f64::MAX` if
/// any `αi ≤ DBL_MIN`. (Verdict's newer "tet aspect Frobenius" form is not implemented.)
pub fn condition(h: &[DVec3; 8]) -> f64 {
    let m = corner_matrices(h);
    let mut worst: f64 = 0.0;
    for a in &m[..8] {
        let c = condition_comp(a);
        if c >= DBL_MAX {
            return DBL_MAX;
        }
        worst = worst.max(c);
    }
    worst / 3.0
}

/// Verdict hex **shape** (`hex_shape`): `min_{i=0..7} 3·αi^(2/3) / |Ai|²` over the eight
/// corners; 1 for a cube, 0 if any `αi ≤ DBL_MIN` (and values below `DBL_MIN` are set to 0).
pub fn shape(h: &[DVec3; 8]) -> f64 {
    let m = corner_matrices(h);
    let mut best: f64 = 1.0;
    for a in &m[..8] {
        let det = det3(a);
        if det <= DBL_MIN {
            return 0.0;
        }
        let f = a[0].length_squared() + a[1].length_squared() + a[2].length_squared();
        best = best.min(3.0 * det.powf(2.0 / 3.0) / f);
    }
    if best <= DBL_MIN {
        0.0
    } else {
        best
    }
}

/// Verdict hex **skew** (`hex_skew`): `max |X̂i · X̂j|` over the three pairs of principal
/// axes; 0 for a box, `f64::MAX` if an axis has length `≤ DBL_MIN` (Verdict).
pub fn skew(h: &[DVec3; 8]) -> f64 {
    let (x1, x2, x3) = axes(h);
    let (n1, n2, n3) = (x1.length(), x2.length(), x3.length());
    if n1 <= DBL_MIN || n2 <= DBL_MIN || n3 <= DBL_MIN {
        return DBL_MAX;
    }
    let (u1, u2, u3) = (x1 / n1, x2 / n2, x3 / n3);
    u1.dot(u2)
        .abs()
        .max(u1.dot(u3).abs())
        .max(u2.dot(u3).abs())
        .min(1.0)
}

/// Verdict hex **taper** (`hex_taper`): `max ‖Xij‖ / min(‖Xi‖, ‖Xj‖)` with the cross
/// derivatives `X12 = P0 + P2 + P4 + P6 − P1 − P3 − P5 − P7`,
/// `X13 = P0 + P3 + P5 + P6 − P1 − P2 − P4 − P7`, `X23 = P0 + P1 + P6 + P7 − P2 − P3 − P4 − P5`;
/// 0 for any parallelepiped, `f64::MAX` where a denominator is `< DBL_MIN` (Verdict
/// `safe_ratio`).
pub fn taper(h: &[DVec3; 8]) -> f64 {
    let (x1, x2, x3) = axes(h);
    let x12 = h[0] + h[2] + h[4] + h[6] - h[1] - h[3] - h[5] - h[7];
    let x13 = h[0] + h[3] + h[5] + h[6] - h[1] - h[2] - h[4] - h[7];
    let x23 = h[0] + h[1] + h[6] + h[7] - h[2] - h[3] - h[4] - h[5];
    let ratio = |num: f64, den: f64| {
        if den < DBL_MIN {
            DBL_MAX
        } else {
            (num / den).min(DBL_MAX)
        }
    };
    let (n1, n2, n3) = (x1.length(), x2.length(), x3.length());
    ratio(x12.length(), n1.min(n2))
        .max(ratio(x13.length(), n1.min(n3)))
        .max(ratio(x23.length(), n2.min(n3)))
}

/// Verdict `oddy_comp`: `(|AᵀA|² − ⅓|A|⁴) / det(A)^(4/3)`, `f64::MAX` if `det A ≤ DBL_MIN`.
fn oddy_comp(a: &[DVec3; 3]) -> f64 {
    let det = det3(a);
    if det <= DBL_MIN {
        return DBL_MAX;
    }
    let g11 = a[0].length_squared();
    let g22 = a[1].length_squared();
    let g33 = a[2].length_squared();
    let g12 = a[0].dot(a[1]);
    let g13 = a[0].dot(a[2]);
    let g23 = a[1].dot(a[2]);
    let g2 = g11 * g11 + g22 * g22 + g33 * g33 + 2.0 * (g12 * g12 + g13 * g13 + g23 * g23);
    let j2 = g11 + g22 + g33;
    ((g2 - j2 * j2 / 3.0) / det.powf(4.0 / 3.0)).min(DBL_MAX)
}

/// Verdict hex **Oddy** (`hex_oddy`): `max_{i=0..8} (|AiᵀAi|² − ⅓|Ai|⁴) / αi^(4/3)` over the
/// eight corners and the centre; 0 for a cube, `f64::MAX` if some `αi ≤ DBL_MIN`.
pub fn oddy(h: &[DVec3; 8]) -> f64 {
    corner_matrices(h).iter().map(oddy_comp).fold(0.0, f64::max)
}

/// All per-cell metrics of one hex, computed at once (see the functions of this module).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HexMetrics {
    /// Verdict Jacobian.
    pub jacobian: f64,
    /// Verdict scaled Jacobian.
    pub scaled_jacobian: f64,
    /// Verdict condition (legacy max-aspect-Frobenius form over the 8 corners).
    pub condition: f64,
    /// Verdict shape.
    pub shape: f64,
    /// Verdict skew.
    pub skew: f64,
    /// Verdict taper.
    pub taper: f64,
    /// Verdict Oddy.
    pub oddy: f64,
    /// The ten tetrahedron values `V = 6 × signed volume` ([`hex_tet_dets`]).
    pub tet_dets: [f64; 10],
    /// Face planarity `|cos θ|` of the six [`PLANARITY_FACES`].
    pub face_cos: [f64; 6],
    /// Face planarity by volume (criterion 1, [`face_volume`]) of the six faces.
    pub face_vol: [f64; 6],
}

impl HexMetrics {
    /// Evaluates every metric of the hex `h` (VTK order).
    pub fn compute(h: &[DVec3; 8]) -> Self {
        Self {
            jacobian: jacobian(h),
            scaled_jacobian: scaled_jacobian(h),
            condition: condition(h),
            shape: shape(h),
            skew: skew(h),
            taper: taper(h),
            oddy: oddy(h),
            tet_dets: hex_tet_dets(h),
            face_cos: face_planarity(h),
            face_vol: face_volumes(h),
        }
    }

    /// Smallest of the ten tetrahedron values.
    pub fn min_tet_det(&self) -> f64 {
        self.tet_dets.iter().copied().fold(DBL_MAX, f64::min)
    }

    /// `true` iff all ten tetrahedra are positive (the thesis's convexity test, threshold 0).
    pub fn convex_10tet(&self) -> bool {
        self.tet_dets.iter().all(|&v| v > 0.0)
    }

    /// Largest face `|cos θ|`.
    pub fn max_face_cos(&self) -> f64 {
        self.face_cos.iter().copied().fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Criterion 1 and the App. B.6 face measures by hand: the unit square with vertex C
    /// lifted by δ.
    #[test]
    fn face_volume_height_area_by_hand() {
        let d = 0.1;
        let f = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, d),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        // det(B−A, D−A, C−A) = det(e1, e2, (1, 1, δ)) = δ, volume δ/6
        assert_relative_eq!(face_volume(f), d / 6.0, epsilon = 1e-15);
        // triangle areas: DAB = 1/2; ABC = CDA = √(1 + δ²)/2;
        // BCD = |(C − B) × (D − B)|/2 = |(0, 1, δ) × (−1, 1, 0)|/2 = |(−δ, −δ, 1)|/2
        let bcd = (1.0 + 2.0 * d * d).sqrt() / 2.0;
        let (h, a) = face_height_area(f);
        assert_relative_eq!(a, 0.5, epsilon = 1e-15);
        // heights 3V/area: C over ABD = δ; A over BCD = (δ/2)/bcd, the smallest
        assert_relative_eq!(h, (d / 2.0) / bcd, epsilon = 1e-15);
        assert!(h < d);
        // a planar face: volume and min height 0, scale: volume ∝ s³
        let flat = [f[0], f[1], DVec3::new(1.0, 1.0, 0.0), f[3]];
        assert_eq!(face_volume(flat), 0.0);
        assert_eq!(face_height_area(flat).0, 0.0);
        let big = f.map(|p| p * 10.0);
        assert_relative_eq!(face_volume(big), 1000.0 * d / 6.0, epsilon = 1e-12);
        assert_relative_eq!(face_cosine(big), face_cosine(f), epsilon = 1e-15);
    }

    fn unit_cube() -> [DVec3; 8] {
        [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(0.0, 1.0, 1.0),
        ]
    }

    #[test]
    fn unit_cube_has_verdict_ideals() {
        let m = HexMetrics::compute(&unit_cube());
        assert_relative_eq!(m.jacobian, 1.0);
        assert_relative_eq!(m.scaled_jacobian, 1.0);
        assert_relative_eq!(m.condition, 1.0, epsilon = 1e-14);
        assert_relative_eq!(m.shape, 1.0, epsilon = 1e-14);
        assert_eq!(m.skew, 0.0);
        assert_eq!(m.taper, 0.0);
        assert_relative_eq!(m.oddy, 0.0, epsilon = 1e-14);
        assert_eq!(m.face_cos, [0.0; 6]);
        assert!(m.convex_10tet());
    }

    #[test]
    fn box_scaled_and_translated() {
        let (a, b, c) = (2.0, 0.5, 3.0);
        let h = unit_cube().map(|p| p * DVec3::new(a, b, c) + DVec3::new(1.0, -4.0, 2.0));
        // corner Jacobian abc, centre (4a)(4b)(4c)/64 = abc
        assert_relative_eq!(jacobian(&h), a * b * c, epsilon = 1e-12);
        assert_relative_eq!(scaled_jacobian(&h), 1.0, epsilon = 1e-14);
        assert_eq!(skew(&h), 0.0);
        assert_eq!(taper(&h), 0.0);
        // condition at a corner: √((a²+b²+c²)(a²b²+b²c²+c²a²))/(3abc)
        let expect = ((a * a + b * b + c * c) * (a * a * b * b + b * b * c * c + c * c * a * a))
            .sqrt()
            / (3.0 * a * b * c);
        assert_relative_eq!(condition(&h), expect, epsilon = 1e-12);
        // shape: 3(abc)^(2/3)/(a²+b²+c²)
        let s = 3.0 * (a * b * c).powf(2.0 / 3.0) / (a * a + b * b + c * c);
        assert_relative_eq!(shape(&h), s, epsilon = 1e-12);
    }

    #[test]
    fn ten_tets_of_unit_cube() {
        let d = hex_tet_dets(&unit_cube());
        for (t, &v) in d.iter().enumerate() {
            // corner tet: det = 6·(1/6) = 1; interior tet (regular, edge √2): det = 6·(1/3) = 2
            let expect = if HEX_TET_INTERIOR[t] { 2.0 } else { 1.0 };
            assert_relative_eq!(v, expect, epsilon = 1e-14);
        }
        let vol = hex_tet_volumes(&unit_cube());
        // each decomposition tiles the cube: 4·(1/6) + 1/3 = 1
        assert_relative_eq!(vol[..5].iter().sum::<f64>(), 1.0, epsilon = 1e-14);
        assert_relative_eq!(vol[5..].iter().sum::<f64>(), 1.0, epsilon = 1e-14);
        // thesis convention: interior Jacobian = 3·vol = 1, corner = 6·vol = 1
        assert_eq!(hex_tet_jacobians(&unit_cube()), [1.0; 10]);
        // structure of the table: a corner tet is a vertex (listed first) with its three
        // hex-edge neighbours; an interior tet has only face diagonals as edges; the corners of
        // decomposition A ({0,2,5,7}) are the vertices of B's interior tet and vice versa.
        let hex_edges: Vec<(usize, usize)> = vec![
            (0, 1),
            (1, 2),
            (2, 3),
            (0, 3),
            (4, 5),
            (5, 6),
            (6, 7),
            (4, 7),
            (0, 4),
            (1, 5),
            (2, 6),
            (3, 7),
        ];
        let is_edge = |a: usize, b: usize| hex_edges.contains(&(a.min(b), a.max(b)));
        for (tet, &interior) in HEX_TETS.iter().zip(&HEX_TET_INTERIOR) {
            if interior {
                for a in 0..4 {
                    for b in a + 1..4 {
                        assert!(!is_edge(tet[a], tet[b]), "{tet:?}");
                    }
                }
            } else {
                assert!(tet[1..].iter().all(|&v| is_edge(tet[0], v)), "{tet:?}");
            }
        }
        let corners = |r: std::ops::Range<usize>| {
            let mut c: Vec<usize> = HEX_TETS[r].iter().map(|t| t[0]).collect();
            c.sort_unstable();
            c
        };
        let sorted = |t: [usize; 4]| {
            let mut t = t;
            t.sort_unstable();
            t.to_vec()
        };
        assert_eq!(corners(0..4), vec![0, 2, 5, 7]);
        assert_eq!(corners(5..9), vec![1, 3, 4, 6]);
        assert_eq!(sorted(HEX_TETS[4]), corners(5..9));
        assert_eq!(sorted(HEX_TETS[9]), corners(0..4));
    }

    #[test]
    fn ten_tets_of_parallelepipeds_tile_the_cell() {
        // affine images x ↦ M x + b with det M > 0: every tet is positive, and each
        // decomposition's volumes sum to det M (the cell's volume).
        let mats = [
            [
                DVec3::new(1.0, 0.3, -0.2),
                DVec3::new(0.1, 2.0, 0.4),
                DVec3::new(-0.5, 0.2, 0.7),
            ],
            [
                DVec3::new(3.0, 0.0, 0.0),
                DVec3::new(1.5, 0.2, 0.0),
                DVec3::new(0.0, 0.0, 5.0),
            ],
        ];
        for cols in mats {
            let det = cols[0].dot(cols[1].cross(cols[2]));
            assert!(det > 0.0);
            let h = unit_cube().map(|p| cols[0] * p.x + cols[1] * p.y + cols[2] * p.z + 0.3);
            assert!(hex_is_convex_10tet(&h, 0.0));
            let vol = hex_tet_volumes(&h);
            assert_relative_eq!(vol[..5].iter().sum::<f64>(), det, epsilon = 1e-12);
            assert_relative_eq!(vol[5..].iter().sum::<f64>(), det, epsilon = 1e-12);
            // a parallelepiped has planar faces and zero taper
            assert!(max_face_cosine(&h) < 1e-14);
            assert!(taper(&h) < 1e-14);
        }
    }

    #[test]
    fn dented_hex_fails_10_tet_test() {
        // P6 pulled from (1,1,1) to (0.2,0.2,0.2). Tet 7683 = [6,5,7,2]:
        // Q−P = (.8,−.2,.8), R−P = (−.2,.8,.8), S−P = (.8,.8,−.2);
        // (Q−P)×(R−P) = (−.16−.64, −.16−.64, .64−.04) = (−.8, −.8, .6);
        // V = .8·(−.8) + .8·(−.8) + (−.2)·.6 = −1.4.
        let mut h = unit_cube();
        h[6] = DVec3::splat(0.2);
        let d = hex_tet_dets(&h);
        assert_relative_eq!(d[8], -1.4, epsilon = 1e-12);
        assert!(!hex_is_convex_10tet(&h, 0.0));
        assert!(!HexMetrics::compute(&h).convex_10tet());
        assert!(scaled_jacobian(&h) < 0.0);
        assert_eq!(condition(&h), DBL_MAX);
    }

    #[test]
    fn twisted_hex_fails_10_tet_test() {
        // top face rotated by φ about the vertical axis through the centre
        let twist = |phi: f64| {
            let mut h = unit_cube();
            for p in &mut h[4..] {
                let (x, y) = (p.x - 0.5, p.y - 0.5);
                let (s, c) = phi.sin_cos();
                p.x = 0.5 + c * x - s * y;
                p.y = 0.5 + s * x + c * y;
            }
            h
        };
        assert!(hex_is_convex_10tet(&twist(0.0), 0.0));
        assert!(hex_is_convex_10tet(&twist(0.2), 0.0));
        // At φ = 90° the top vertices move one place on (P4 → (1,0,1), P5 → (1,1,1), …).
        // By hand, all eight corner tets then have V = 1, e.g. 1245 = [0,1,3,4]:
        // (Q−P)×(R−P) = x̂ × ŷ = ẑ and S − P = (1,0,1) give V = 1, while the interior tet
        // 7425 = [6,3,1,4] has Q−P = (0,0,−1), R−P = (1,−1,−1), S−P = (1,−1,0),
        // (Q−P)×(R−P) = (−1,−1,0), V = 0 (flat), and likewise 1386. Past 90° the interior
        // tets invert while the corner tets (= Verdict's eight corner Jacobians) stay positive:
        // the case the 8-corner test misses ([Cortés Aguirre 2012, §3.2.1, Fig. 3.7]).
        let h = twist(95f64.to_radians());
        let d = hex_tet_dets(&h);
        for t in 0..10 {
            if HEX_TET_INTERIOR[t] {
                assert!(d[t] < 0.0, "interior tet {t}: {}", d[t]);
            } else {
                assert!(d[t] > 0.0, "corner tet {t}: {}", d[t]);
            }
        }
        assert!(!hex_is_convex_10tet(&h, 0.0));
        assert!(jacobian(&h) > 0.0);
        // large twist inverts corner tets too
        assert!(!hex_is_convex_10tet(&twist(2.5), 0.0));
        // a threshold makes the test stricter
        let small = twist(0.2);
        let min = hex_tet_dets(&small).into_iter().fold(f64::MAX, f64::min);
        assert!(!hex_is_convex_10tet(&small, min));
    }

    #[test]
    fn face_planarity_cosine() {
        assert_eq!(max_face_cosine(&unit_cube()), 0.0);
        // lift P6 by hh: the top face (4,5,6,7) is warped; the side faces (1,2,6,5) (x = 1)
        // and (3,2,6,7) (y = 1) stay planar. Rotation A = P4: N = x̂ × ŷ = ẑ, AC = (1,1,hh),
        // |cos| = hh/√(2 + hh²); the other rotations give hh/√(2(1+hh²)) (twice) and
        // hh/√((1+2hh²)(2+hh²)), all smaller.
        let hh = 0.1;
        let mut h = unit_cube();
        h[6].z += hh;
        let f = face_planarity(&h);
        let expect = hh / (2.0 + hh * hh).sqrt();
        assert_relative_eq!(f[1], expect, epsilon = 1e-14);
        for (k, &v) in f.iter().enumerate() {
            if k != 1 {
                assert!(v < 1e-15, "face {k}: {v}");
            }
        }
        assert_relative_eq!(max_face_cosine(&h), expect, epsilon = 1e-14);
        // scale invariance
        let big = h.map(|p| p * 1000.0);
        assert_relative_eq!(max_face_cosine(&big), expect, epsilon = 1e-12);
        // degenerate face (all points equal) is planar, not NaN
        assert_eq!(face_cosine([DVec3::ONE; 4]), 0.0);
    }

    #[test]
    fn degenerate_hex_gives_fallbacks_not_nan() {
        let h = [DVec3::ZERO; 8];
        let m = HexMetrics::compute(&h);
        assert_eq!(m.jacobian, 0.0);
        assert_eq!(m.scaled_jacobian, DBL_MAX);
        assert_eq!(m.condition, DBL_MAX);
        assert_eq!(m.shape, 0.0);
        assert_eq!(m.skew, DBL_MAX);
        assert_eq!(m.taper, DBL_MAX);
        assert_eq!(m.oddy, DBL_MAX);
        assert!(!m.convex_10tet());
        assert_eq!(m.max_face_cos(), 0.0);
    }
}
