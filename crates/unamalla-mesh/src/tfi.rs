//! Transfinite interpolation (discrete Coons patches) in 2D and 3D.
//!
//! **2D** ([Méndez 2023, §6.1]): with bottom/top points `B_i, T_i` (`i = 0..m`,
//! left to right), left/right points `L_j, R_j` (`j = 0..n`, bottom to top), corners
//! `P00 = B_0, P10 = B_{m−1}, P01 = T_0, P11 = T_{m−1}` and parameters `ξ_i, η_j` in `[0, 1]`:
//!
//! ```text
//! p_ij = (1−η_j) B_i + η_j T_i + (1−ξ_i) L_j + ξ_i R_j
//!        − [(1−ξ_i)(1−η_j) P00 + ξ_i(1−η_j) P10 + (1−ξ_i) η_j P01 + ξ_i η_j P11]
//! ```
//!
//! Any partitions with `ξ_0 = η_0 = 0` and `ξ_{m−1} = η_{n−1} = 1` reproduce the four boundary
//! point lists exactly. [`TfiParams::Uniform`] uses `ξ_i = i/(m−1)`; [`TfiParams::ArcLength`]
//! uses the mean of the normalised cumulative arc lengths of the two opposite sides
//! (`ξ_i = ½(s_b(i) + s_t(i))`, `η_j = ½(s_l(j) + s_r(j))`), which keeps the interior spacing
//! close to the boundary spacing when the boundary points are not uniform.
//!
//! **3D** (used but not printed by [Cortés Aguirre 2012, §2.2.1]; the standard form, after
//! [Knupp & Steinberg 1993]): the Boolean sum
//! `X = U + V + W − UV − UW − VW + UVW` of the linear blends between opposite faces, edges and
//! corners, with uniform parameters `ξ_i = i/(m−1)` etc.

use glam::{DVec2, DVec3};

use crate::error::MeshError;
use crate::grid::{StructuredGrid2, StructuredGrid3};
use crate::resample::{cumulative_lengths, resample_arc_length};

/// How TFI chooses the logical parameters of the boundary points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TfiParams {
    /// `ξ_i = i/(m−1)`, `η_j = j/(n−1)` (the thesis's choice).
    #[default]
    Uniform,
    /// Mean normalised arc length of the two opposite sides.
    ArcLength,
}

fn check_corner(a: DVec2, b: DVec2, corner: &'static str, tol: f64) -> Result<(), MeshError> {
    let d = a.distance(b);
    if d > tol {
        return Err(MeshError::CornerMismatch {
            corner,
            distance: d,
        });
    }
    Ok(())
}

fn params(a: &[DVec2], b: &[DVec2], kind: TfiParams) -> Result<Vec<f64>, MeshError> {
    let k = a.len();
    match kind {
        TfiParams::Uniform => Ok((0..k).map(|i| i as f64 / (k - 1) as f64).collect()),
        TfiParams::ArcLength => {
            let (ca, cb) = (cumulative_lengths(a), cumulative_lengths(b));
            let (la, lb) = (ca[k - 1], cb[k - 1]);
            if la <= 0.0 || lb <= 0.0 {
                return Err(MeshError::Degenerate(
                    "a TFI side has zero length; arc-length parameters are undefined".into(),
                ));
            }
            let mut t: Vec<f64> = (0..k).map(|i| 0.5 * (ca[i] / la + cb[i] / lb)).collect();
            t[0] = 0.0;
            t[k - 1] = 1.0;
            Ok(t)
        }
    }
}

/// 2D TFI from four boundary point lists. `bottom` and `top` run left to right and must have
/// the same number `m ≥ 2` of points; `left` and `right` run bottom to top with `n ≥ 2` points.
/// The lists must meet at the four corners (within `1e-9` of the boundary's size).
pub fn tfi2(
    bottom: &[DVec2],
    right: &[DVec2],
    top: &[DVec2],
    left: &[DVec2],
    kind: TfiParams,
) -> Result<StructuredGrid2, MeshError> {
    let (m, n) = (bottom.len(), left.len());
    if top.len() != m {
        return Err(MeshError::SideCountMismatch {
            which: "bottom/top",
            a: m,
            b: top.len(),
        });
    }
    if right.len() != n {
        return Err(MeshError::SideCountMismatch {
            which: "left/right",
            a: n,
            b: right.len(),
        });
    }
    if m < 2 || n < 2 {
        return Err(MeshError::InvalidSize(format!(
            "TFI needs at least 2 × 2 points, got {m} × {n}"
        )));
    }
    for (k, p) in bottom
        .iter()
        .chain(right)
        .chain(top)
        .chain(left)
        .enumerate()
    {
        if !p.is_finite() {
            return Err(MeshError::NonFinite { node: k });
        }
    }
    let scale = bottom
        .iter()
        .chain(top)
        .chain(left)
        .chain(right)
        .fold(0.0f64, |s, p| s.max(p.abs().max_element()))
        .max(1.0);
    let tol = 1e-9 * scale;
    check_corner(bottom[0], left[0], "bottom-left", tol)?;
    check_corner(bottom[m - 1], right[0], "bottom-right", tol)?;
    check_corner(top[m - 1], right[n - 1], "top-right", tol)?;
    check_corner(top[0], left[n - 1], "top-left", tol)?;
    let xi = params(bottom, top, kind)?;
    let eta = params(left, right, kind)?;
    let (p00, p10, p01, p11) = (bottom[0], bottom[m - 1], top[0], top[m - 1]);
    StructuredGrid2::from_fn(m, n, |i, j| {
        if j == 0 {
            return bottom[i];
        }
        if j == n - 1 {
            return top[i];
        }
        if i == 0 {
            return left[j];
        }
        if i == m - 1 {
            return right[j];
        }
        let (x, e) = (xi[i], eta[j]);
        (1.0 - e) * bottom[i] + e * top[i] + (1.0 - x) * left[j] + x * right[j]
            - ((1.0 - x) * (1.0 - e) * p00
                + x * (1.0 - e) * p10
                + (1.0 - x) * e * p01
                + x * e * p11)
    })
}

/// Splits a counter-clockwise ring at four corner indices `c0 < c1 < c2 < c3` (cyclically
/// increasing, i.e. in counter-clockwise order) into the bottom `c0→c1`, right `c1→c2`, top and
/// left sides, resamples bottom/top with `m` points and left/right with `n` points by arc
/// length, and returns `[bottom, right, top, left]` oriented as [`tfi2`] expects (top left to
/// right, left bottom to top).
pub fn sides_from_ring(
    ring: &[DVec2],
    corners: [usize; 4],
    m: usize,
    n: usize,
) -> Result<[Vec<DVec2>; 4], MeshError> {
    let len = ring.len();
    if corners.iter().any(|&c| c >= len) {
        return Err(MeshError::InvalidSize(format!(
            "corner indices {corners:?} out of range for a ring of {len} points"
        )));
    }
    // corners must be distinct and in cyclic counter-clockwise order
    let rel: Vec<usize> = corners
        .iter()
        .map(|&c| (c + len - corners[0]) % len)
        .collect();
    if !(rel[0] < rel[1] && rel[1] < rel[2] && rel[2] < rel[3]) {
        return Err(MeshError::InvalidSize(format!(
            "corners {corners:?} must be distinct and in counter-clockwise order along the ring"
        )));
    }
    let arc = |a: usize, b: usize| ring_arc(ring, a, b);
    let bottom = resample_arc_length(&arc(corners[0], corners[1]), m)?;
    let right = resample_arc_length(&arc(corners[1], corners[2]), n)?;
    let mut top = resample_arc_length(&arc(corners[2], corners[3]), m)?;
    top.reverse();
    let mut left = resample_arc_length(&arc(corners[3], corners[0]), n)?;
    left.reverse();
    Ok([bottom, right, top, left])
}

/// The six boundary faces of a logically hexahedral region, as point arrays.
///
/// * `i_min`, `i_max` (faces `i = 0`, `i = m−1`): `n × p` points, index `k * n + j`;
/// * `j_min`, `j_max` (faces `j = 0`, `j = n−1`): `m × p` points, index `k * m + i`;
/// * `k_min`, `k_max` (faces `k = 0`, `k = p−1`): `m × n` points, index `j * m + i`.
#[derive(Debug, Clone, PartialEq)]
pub struct HexFaces {
    /// Nodes per direction `(m, n, p)`.
    pub dims: (usize, usize, usize),
    /// Face `i = 0`.
    pub i_min: Vec<DVec3>,
    /// Face `i = m−1`.
    pub i_max: Vec<DVec3>,
    /// Face `j = 0`.
    pub j_min: Vec<DVec3>,
    /// Face `j = n−1`.
    pub j_max: Vec<DVec3>,
    /// Face `k = 0` (bottom).
    pub k_min: Vec<DVec3>,
    /// Face `k = p−1` (top).
    pub k_max: Vec<DVec3>,
}

impl HexFaces {
    /// The six faces of an existing grid.
    pub fn of_grid(g: &StructuredGrid3) -> Self {
        let (m, n, p) = g.dims();
        let face = |a: usize, b: usize, f: &dyn Fn(usize, usize) -> DVec3| {
            let mut v = Vec::with_capacity(a * b);
            for y in 0..b {
                for x in 0..a {
                    v.push(f(x, y));
                }
            }
            v
        };
        Self {
            dims: (m, n, p),
            i_min: face(n, p, &|j, k| g.node(0, j, k)),
            i_max: face(n, p, &|j, k| g.node(m - 1, j, k)),
            j_min: face(m, p, &|i, k| g.node(i, 0, k)),
            j_max: face(m, p, &|i, k| g.node(i, n - 1, k)),
            k_min: face(m, n, &|i, j| g.node(i, j, 0)),
            k_max: face(m, n, &|i, j| g.node(i, j, p - 1)),
        }
    }

    /// Boundary point `(i, j, k)` (at least one index on the boundary), read from a face.
    fn boundary(&self, i: usize, j: usize, k: usize) -> DVec3 {
        let (m, n, p) = self.dims;
        if i == 0 {
            self.i_min[k * n + j]
        } else if i == m - 1 {
            self.i_max[k * n + j]
        } else if j == 0 {
            self.j_min[k * m + i]
        } else if j == n - 1 {
            self.j_max[k * m + i]
        } else if k == 0 {
            self.k_min[j * m + i]
        } else {
            debug_assert_eq!(k, p - 1);
            self.k_max[j * m + i]
        }
    }

    /// Checks sizes, finiteness, and that faces sharing an edge agree on it (within `1e-9` of
    /// the geometry's size).
    pub fn validate(&self) -> Result<(), MeshError> {
        let (m, n, p) = self.dims;
        if m < 2 || n < 2 || p < 2 {
            return Err(MeshError::InvalidSize(format!(
                "a hexahedral region needs at least 2 × 2 × 2 nodes, got {m} × {n} × {p}"
            )));
        }
        let faces: [(&str, &Vec<DVec3>, usize); 6] = [
            ("i_min", &self.i_min, n * p),
            ("i_max", &self.i_max, n * p),
            ("j_min", &self.j_min, m * p),
            ("j_max", &self.j_max, m * p),
            ("k_min", &self.k_min, m * n),
            ("k_max", &self.k_max, m * n),
        ];
        let mut scale = 1.0f64;
        for (name, f, want) in faces {
            if f.len() != want {
                return Err(MeshError::InvalidSize(format!(
                    "face {name} has {} points, expected {want}",
                    f.len()
                )));
            }
            if let Some(v) = f.iter().position(|q| !q.is_finite()) {
                return Err(MeshError::NonFinite { node: v });
            }
            scale = f.iter().fold(scale, |s, q| s.max(q.abs().max_element()));
        }
        let tol = 1e-9 * scale;
        // every boundary node that lies on two or three faces must agree on all of them
        let check = |i: usize, j: usize, k: usize| -> Result<(), MeshError> {
            let mut vals: Vec<DVec3> = Vec::with_capacity(3);
            if i == 0 {
                vals.push(self.i_min[k * n + j]);
            }
            if i == m - 1 {
                vals.push(self.i_max[k * n + j]);
            }
            if j == 0 {
                vals.push(self.j_min[k * m + i]);
            }
            if j == n - 1 {
                vals.push(self.j_max[k * m + i]);
            }
            if k == 0 {
                vals.push(self.k_min[j * m + i]);
            }
            if k == p - 1 {
                vals.push(self.k_max[j * m + i]);
            }
            for w in vals.windows(2) {
                let d = w[0].distance(w[1]);
                if d > tol {
                    return Err(MeshError::CornerMismatch {
                        corner: "shared face edge",
                        distance: d,
                    });
                }
            }
            Ok(())
        };
        for k in 0..p {
            for j in 0..n {
                for i in 0..m {
                    let on = [
                        i == 0 || i == m - 1,
                        j == 0 || j == n - 1,
                        k == 0 || k == p - 1,
                    ];
                    if on.iter().filter(|&&b| b).count() >= 2 {
                        check(i, j, k)?;
                    }
                }
            }
        }
        Ok(())
    }
}

/// 3D TFI (Boolean sum) from six face grids; boundary nodes are copied exactly.
pub fn tfi3(faces: &HexFaces) -> Result<StructuredGrid3, MeshError> {
    faces.validate()?;
    let (m, n, p) = faces.dims;
    let b = |i, j, k| faces.boundary(i, j, k);
    let (mi, nj, pk) = (m - 1, n - 1, p - 1);
    StructuredGrid3::from_fn(m, n, p, |i, j, k| {
        if i == 0 || j == 0 || k == 0 || i == mi || j == nj || k == pk {
            return b(i, j, k);
        }
        let x = i as f64 / mi as f64;
        let y = j as f64 / nj as f64;
        let z = k as f64 / pk as f64;
        let fx = [1.0 - x, x];
        let fy = [1.0 - y, y];
        let fz = [1.0 - z, z];
        let ii = [0, mi];
        let jj = [0, nj];
        let kk = [0, pk];
        let mut r = DVec3::ZERO;
        for a in 0..2 {
            r += fx[a] * b(ii[a], j, k) + fy[a] * b(i, jj[a], k) + fz[a] * b(i, j, kk[a]);
        }
        for a in 0..2 {
            for c in 0..2 {
                r -= fx[a] * fy[c] * b(ii[a], jj[c], k);
                r -= fx[a] * fz[c] * b(ii[a], j, kk[c]);
                r -= fy[a] * fz[c] * b(i, jj[a], kk[c]);
            }
        }
        for a in 0..2 {
            for c in 0..2 {
                for d in 0..2 {
                    r += fx[a] * fy[c] * fz[d] * b(ii[a], jj[c], kk[d]);
                }
            }
        }
        r
    })
}

/// The vertices of `ring` from index `a` to index `b` inclusive, following the ring forward
/// (cyclically): the polyline of one block side between two corners. `a == b` gives `[ring[a]]`.
///
/// Panics if `a` or `b` is not an index of `ring` (callers check corner indices first).
pub fn ring_arc(ring: &[DVec2], a: usize, b: usize) -> Vec<DVec2> {
    let len = ring.len();
    let mut v = vec![ring[a]];
    let mut k = a;
    while k != b {
        k = (k + 1) % len;
        v.push(ring[k]);
    }
    v
}
